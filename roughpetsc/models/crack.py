"""Pressurised elliptical and penny-shaped cracks (the dissertation, section 5.2).

A non-contact island of the nearly complete contact is a crack loaded by p2 = p0 - kappa_1 x^2/2 - kappa_2 y^2/2
(5.4). Units: p0, E* [pressure], curvatures [pressure/length^2], area [length^2], volume [length^3].
"""

import numpy as np
from scipy.special import ellipe, ellipk

from .ellipse import elliptic_KE, fit_sqrt1me2, invert_ratio, ratio_of_eccentricity

__all__ = ["ratio_from_e", "e_exact", "e_fit", "I00", "I02", "I22", "F1", "F2",
           "elliptical", "penny", "mildly_elliptical_geometric", "mildly_elliptical_mean"]


def _ratio_of_z(z):
    K, E, p = elliptic_KE(z)                       # p = 1 - e^2
    e2 = 1.0 - p
    return p * ((2 * e2 - 1) * E + p * K) / ((1 + e2) * E - p * K)


def ratio_from_e(e):
    """Curvature ratio kappa_1^p/kappa_2^p of a crack of eccentricity e, Eq. (5.15)."""
    return ratio_of_eccentricity(_ratio_of_z, e)


def e_exact(ratio):
    """Crack eccentricity from the exact root of Eq. (5.15) (zero SIF, (5.13))."""
    return invert_ratio(_ratio_of_z, ratio)


def e_fit(ratio):
    """Crack eccentricity from the fit (5.16)."""
    return fit_sqrt1me2(ratio, -0.00681, 0.3953)


def I00(e):
    """Martin's integral I_00^c = 2 E(e), Eq. (5.10)."""
    return 2.0 * ellipe(np.asarray(e, float) ** 2)


def I02(e):
    """I_02^c(e), Eq. (5.11) (series pi e^2/8 (1 + e^2/4) below e = 1e-2)."""
    e = np.asarray(e, float)
    m = e ** 2
    ms = np.where(e < 1e-2, 0.25, m)
    full = 2.0 / (3.0 * ms) * ((2 - ms) * ellipe(ms) - 2 * (1 - ms) * ellipk(ms))
    return np.where(e < 1e-2, np.pi * m / 8.0 * (1 + m / 4.0), full)


def I22(e):
    """I_22^c(e), Eq. (5.12) (series pi/2 (1 - e^2/4) below e = 1e-2)."""
    e = np.asarray(e, float)
    m = e ** 2
    ms = np.where(e < 1e-2, 0.25, m)
    full = 1.0 / (15.0 * ms ** 2) * ((14 * ms ** 2 + 16 * ms - 16) * ellipe(ms)
                                      + 8 * (2 - ms) * (1 - ms) * ellipk(ms))
    return np.where(e < 1e-2, np.pi / 2.0 * (1 - m / 4.0), full)


def F1(e, ratio):
    """Area correction F1 of Eq. (5.18), as printed, with Martin's I_20^c = I_02^c in Omega = I00 I22 - I02 I20.

    (Eliminating B2 = 0 from (5.8) and (5.14) gives I02^2 instead of the printed I02 in the bracket.)"""
    a00, a02, a22 = I00(e), I02(e), I22(e)
    omega = a00 * a22 - a02 * a02
    sr = np.sqrt(ratio)
    return 5.0 / (1.5 + a00 * a22 / omega - a02) / (sr + (1 - np.asarray(e) ** 2) / sr)


def F2(e, ratio):
    """Volume correction F2 of Eq. (5.24)."""
    e = np.asarray(e, float)
    f1 = F1(e, ratio)
    sr = np.sqrt(ratio)
    q = 1 - e ** 2
    return 2.5 * q ** 0.25 * f1 ** 1.5 * (1 - 0.3 * f1 / np.sqrt(q) * (sr + q / sr))


def elliptical(p0, k1, k2, E_star=1.0, method="exact"):
    """Elliptical crack area A and trapped volume V, Eqs. (5.17) and (5.23), for the peak tension p0 = xi^p - pbar
    and curvatures 0 < k1 <= k2; e from the root of (5.15) (``method="exact"``) or the fit (5.16)."""
    k1, k2 = np.asarray(k1, float), np.asarray(k2, float)
    y = k1 / k2
    e = e_exact(y) if method == "exact" else e_fit(y)
    kg = np.sqrt(k1 * k2)
    p0 = np.asarray(p0, float)
    return (3 * np.pi / kg * p0 * F1(e, y),
            16 * np.sqrt(3) / (5 * E_star) * kg ** -1.5 * p0 ** 2.5 * F2(e, y))


def penny(p0, kappa, E_star=1.0):
    """Penny-shaped crack, Eqs. (5.27)-(5.28): returns (A [length^2], V [length^3])."""
    p0 = np.asarray(p0, float)
    return 3 * np.pi / kappa * p0, 16 * np.sqrt(3) / (5 * E_star) * kappa ** -1.5 * p0 ** 2.5


def mildly_elliptical_geometric(p0, k1, k2, E_star=1.0):
    """Mildly elliptical crack with the geometric curvature, Eqs. (5.29)-(5.30)."""
    return penny(p0, np.sqrt(np.asarray(k1) * k2), E_star)


def mildly_elliptical_mean(p0, k1, k2, E_star=1.0):
    """Mildly elliptical crack with the mean curvature, Eqs. (5.31)-(5.32)."""
    return penny(p0, 0.5 * (np.asarray(k1) + k2), E_star)
