"""Asperity probability densities of an isotropic Gaussian surface (the dissertation, 2.5, 7.2.2).

In the variables of Eq. (2.34), ``xi = xi^h / sqrt(m0)``, ``kappa = kappa^h / sqrt(m4)``, normalised per
asperity; they depend on ``alpha`` (2.16) > 3/2 only, ``alpha^p`` for the pressure surface (section 2.6).
"""

import numpy as np
from scipy.special import erf, erfc, erfcx

__all__ = ["c1", "phi_xi", "phi_xi_km", "phi_xi_kg", "phi_xi_k1k2",
           "phi_xi_km_kd", "phi_km"]


def _check_alpha(alpha):
    if not np.all(np.asarray(alpha) > 1.5):
        raise ValueError("bandwidth parameter alpha must exceed 3/2, got %r" % (alpha,))


def c1(alpha):
    """C1 = alpha / (2 alpha - 3) of Eq. (2.35)."""
    _check_alpha(alpha)
    return alpha / (2.0 * alpha - 3.0)


def phi_xi_km_kd(xi, km, kd, alpha):
    """Joint density of summit height, mean and semi-difference curvature, Eq. (2.38), 0 <= kd <= km."""
    C1 = c1(alpha)
    val = (27.0 / (2.0 * np.pi) * np.sqrt(C1)
           * np.exp(-C1 * (xi - 1.5 * km / np.sqrt(alpha)) ** 2
                    - 0.75 * km ** 2 - 1.5 * kd ** 2)
           * (km ** 2 - kd ** 2) * kd)
    return np.where((kd >= 0) & (kd <= km), val, 0.0)


def phi_xi_k1k2(xi, k1, k2, alpha):
    """Joint density of summit height and principal curvatures, Eq. (2.39), 0 <= k1 <= k2."""
    C1 = c1(alpha)
    val = (27.0 / (8.0 * np.pi) * np.sqrt(C1)
           * np.exp(-C1 * (xi - 0.75 * (k1 + k2) / np.sqrt(alpha)) ** 2
                    - 9.0 / 16.0 * (k1 ** 2 + k2 ** 2 - 2.0 / 3.0 * k1 * k2))
           * k1 * k2 * (k2 - k1))
    return np.where((k1 >= 0) & (k1 <= k2), val, 0.0)


def phi_xi_km(xi, km, alpha):
    """Joint density of summit height and mean curvature, Eq. (2.40), C2 = C1 sqrt(12/alpha)."""
    C1 = c1(alpha)
    C2 = C1 * np.sqrt(12.0 / alpha)
    bracket = 3.0 * km ** 2 - 2.0 + 2.0 * np.exp(-1.5 * km ** 2)
    # -expm1 keeps the O(km^4) cancellation of the bracket accurate near km = 0
    bracket = np.where(km < 0.1, 3.0 * km ** 2 + 2.0 * np.expm1(-1.5 * km ** 2), bracket)
    return (1.5 * np.sqrt(C1) / np.pi * bracket
            * np.exp(-C1 * xi ** 2 - 0.5 * (3.0 * C1 * km ** 2 - np.sqrt(3.0) * C2 * km * xi)))


def phi_xi_kg(xi, kg, alpha):
    """Joint density of summit height and geometric curvature, Eq. (2.41) (through ``erfcx``, no overflow)."""
    _check_alpha(alpha)
    mu = np.sqrt(0.5 * (alpha - 1.0) / (2.0 * alpha - 3.0))
    x = mu * (3.0 * kg - xi * np.sqrt(alpha) / (alpha - 1.0))
    expo = -alpha * xi ** 2 / (2.0 * (alpha - 1.0)) + 1.5 * kg ** 2
    xp = np.maximum(x, 0.0)
    tail = np.where(x > 0, erfcx(xp) * np.exp(expo - xp ** 2),
                    erfc(np.minimum(x, 0.0)) * np.exp(np.minimum(expo, 700.0)))
    return 4.5 / np.sqrt(2.0 * np.pi) * np.sqrt(alpha / (alpha - 1.0)) * kg ** 3 * tail


def phi_xi(xi, alpha):
    """Density of the summit height alone, Eq. (2.42) (Greenwood's corrected form)."""
    C1 = c1(alpha)
    beta = xi * np.sqrt(1.5 / (2.0 * alpha - 3.0))
    gamma = xi * np.sqrt(alpha / (2.0 * (alpha - 1.0) * (2.0 * alpha - 3.0)))
    return (1.5 / np.pi * np.sqrt(2.0 * alpha - 3.0) / alpha * xi * np.exp(-C1 * xi ** 2)
            + 3.0 * np.sqrt(3.0) / (2.0 * np.sqrt(2.0 * np.pi)) / alpha * (xi ** 2 - 1.0)
            * np.exp(-0.5 * xi ** 2) * (1.0 + erf(beta))
            + np.sqrt(alpha / (2.0 * np.pi * (alpha - 1.0)))
            * np.exp(-alpha * xi ** 2 / (2.0 * (alpha - 1.0))) * (1.0 + erf(gamma)))


def phi_km(km):
    """Density of the summit mean curvature alone, Eq. (7.8) (independent of alpha)."""
    return 1.5 / np.sqrt(np.pi) * ((3.0 * km ** 2 - 2.0) * np.exp(-0.75 * km ** 2)
                                    + 2.0 * np.exp(-2.25 * km ** 2))
