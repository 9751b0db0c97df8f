"""Eccentricity of elliptical contacts and cracks from a curvature ratio.

Shared by the Hertz contact (4.10)-(4.11) and the crack (5.15)-(5.16): both give ``y = kappa_1/kappa_2`` in
(0, 1] as a monotone function of ``e``, inverted by bisection in ``z = ln(1 - e^2)``.
"""

import numpy as np
from scipy.special import ellipe, ellipkm1

__all__ = ["elliptic_KE", "ratio_of_eccentricity", "invert_ratio", "fit_sqrt1me2"]


def elliptic_KE(z):
    """Complete elliptic integrals K(e), E(e) for ``1 - e^2 = exp(z)`` (``ellipkm1``: K accurate as e -> 1)."""
    p = np.exp(z)                      # 1 - e^2
    return ellipkm1(p), ellipe(1.0 - p), p


def ratio_of_eccentricity(ratio_of_z, e):
    """The curvature ratio ``ratio_of_z(ln(1 - e^2))`` at eccentricity ``e``; 1 for the circle e = 0."""
    e = np.asarray(e, dtype=float)
    z = np.log1p(-e ** 2)
    return np.where(e == 0, 1.0, ratio_of_z(np.where(e == 0, -1.0, z)))


def invert_ratio(ratio_of_z, ratio, z_min=-80.0, iterations=80):
    """e solving ``ratio_of_z(z) = ratio``, z = ln(1 - e^2), ``ratio_of_z`` increasing from 0 to 1 (z = 0)."""
    ratio = np.asarray(ratio, dtype=float)
    if np.any((ratio <= 0) | (ratio > 1)):
        raise ValueError("curvature ratio kappa_1/kappa_2 must lie in (0, 1]")
    lo = np.full(ratio.shape, z_min)
    hi = np.zeros(ratio.shape)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        below = ratio_of_z(mid) < ratio
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    z = 0.5 * (lo + hi)
    e = np.sqrt(-np.expm1(z))
    return np.where(ratio == 1.0, 0.0, e)


def fit_sqrt1me2(ratio, c2, c1):
    """Empirical fits (4.11)/(5.16): sqrt(1 - e^2) = exp(c2 ln^2 y + c1 ln y); returns e."""
    ly = np.log(np.asarray(ratio, dtype=float))
    s = np.exp(c2 * ly ** 2 + c1 * ly)
    return np.sqrt(np.clip(1.0 - s ** 2, 0.0, 1.0))
