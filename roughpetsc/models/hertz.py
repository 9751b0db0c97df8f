"""Hertz contact of one parabolic asperity (the dissertation, section 4.2).

Units: penetration ``delta`` [length], curvatures [1/length], ``E_star`` [pressure];
area [length^2], load [force].
"""

import numpy as np
from scipy.special import ellipe, ellipk

from .ellipse import elliptic_KE, fit_sqrt1me2, invert_ratio, ratio_of_eccentricity

__all__ = ["ratio_from_e", "e_exact", "e_fit", "F1", "F2", "elliptical",
           "circular", "mildly_elliptical_geometric", "mildly_elliptical_mean"]


def _ratio_of_z(z):
    K, E, p = elliptic_KE(z)
    return (K - E) / (E / p - K)


def ratio_from_e(e):
    """Curvature ratio kappa_1/kappa_2 of a Hertz contact of eccentricity e, Eq. (4.10)."""
    return ratio_of_eccentricity(_ratio_of_z, e)


def e_exact(ratio):
    """Eccentricity e = sqrt(1 - b^2/a^2) from the exact root of Eq. (4.10)."""
    return invert_ratio(_ratio_of_z, ratio)


def e_fit(ratio):
    """Eccentricity from the fit of Xu et al., Eq. (4.11)."""
    return fit_sqrt1me2(ratio, 0.006709, 0.6692)


def F1(e):
    """Correction F1(e) of Eq. (4.8) (F1(0) = 1)."""
    e = np.asarray(e, dtype=float)
    m = e ** 2
    K, E = ellipk(m), ellipe(m)
    small = e < 1e-3
    ms = np.where(small, 0.5, m)
    prod = (E / (1 - ms) - K) * (K - E)
    prod = np.where(small, 1.0, np.abs(prod))
    f3 = 4.0 / np.pi / np.where(small, 1.0, ms) * (1 - ms) ** 0.75 * np.sqrt(prod)
    # series: (E/(1-m) - K)(K - E) = (pi m / 4)^2 (1 + 3m/4 + ...)  ->  F1^3 = 1 + O(m)
    f3 = np.where(small, (1 - m) ** 0.75 * (1 + 0.375 * m), f3)
    return np.cbrt(f3)


def F2(e):
    """Correction F2(e) of Eq. (4.9) (F2(0) = 1)."""
    e = np.asarray(e, dtype=float)
    return 2.0 / np.pi * (1 - e ** 2) ** 0.25 / F1(e) * ellipk(e ** 2)


def elliptical(delta, k1, k2, E_star=1.0, method="exact"):
    """Hertz elliptical contact area A and load P, Eqs. (4.6)-(4.7), for curvatures 0 < k1 <= k2; the eccentricity
    from the root of (4.10) (``method="exact"``) or the fit (4.11)."""
    k1, k2 = np.asarray(k1, float), np.asarray(k2, float)
    e = e_exact(k1 / k2) if method == "exact" else e_fit(k1 / k2)
    kg = np.sqrt(k1 * k2)
    f1, f2 = F1(e), F2(e)
    return (np.pi / kg * delta * f1 ** 2 / f2,
            4.0 / 3.0 * E_star / np.sqrt(kg) * np.asarray(delta) ** 1.5 * f2 ** -1.5)


def circular(delta, kappa, E_star=1.0):
    """Hertz circular contact, Eqs. (4.12)-(4.13): returns (A [length^2], P [force])."""
    delta = np.asarray(delta, float)
    return np.pi / kappa * delta, 4.0 / 3.0 * E_star / np.sqrt(kappa) * delta ** 1.5


def mildly_elliptical_geometric(delta, k1, k2, E_star=1.0):
    """Mildly elliptical contact with the geometric curvature, Eqs. (4.14)-(4.15)."""
    return circular(delta, np.sqrt(np.asarray(k1) * k2), E_star)


def mildly_elliptical_mean(delta, k1, k2, E_star=1.0):
    """Mildly elliptical contact with the mean curvature, Eqs. (4.16)-(4.17)."""
    return circular(delta, 0.5 * (np.asarray(k1) + k2), E_star)
