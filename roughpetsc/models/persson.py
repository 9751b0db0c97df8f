"""Persson's model (the dissertation, section 5.4 and appendix E).

``psd_amplitude`` is C of the PSD (2.18) from m2^h, eq. (7.1) (:func:`roughpetsc.surfaces.fractal_amplitude`).
"""

import numpy as np
from scipy.special import erf, exp1

from ..surface.spectra import fractal_height_moment
from ..surface.generators import fractal_amplitude as psd_amplitude
from .quadrature import gauss_legendre

__all__ = ["persson_area", "persson_gap", "psd_amplitude", "fractal_moments"]


def persson_area(pstar):
    """Contact ratio A* = 1 - erfc(p*/sqrt 2) = erf(p*/sqrt 2), Eq. (5.59)."""
    return erf(np.asarray(pstar, dtype=float) / np.sqrt(2.0))


def fractal_moments(k_l, k_s, H, C):
    """Moments m0, m2, m4, m6 of the PSD (2.18) with k_r = k_l, Eq. (2.20)."""
    return tuple(fractal_height_moment(n, k_l, k_s, H, C) for n in (0, 2, 4, 6))


def persson_gap(pstar, k_l, k_s, H, m2, E_star, gamma=1.0, n_elements=32, order=8):
    """Persson's mean interfacial gap, appendix E, Eq. (E.7) (k from k_l to k_s; exact inner integral
    E1(p^2 / (2 m0p(k))) / 2, outer in v with k = k_l exp(v^2)).

    Parameters
    ----------
    pstar : array_like
        p* = pbar / sqrt(m0^p) > 0 [-], m0^p = E*^2 m2 / 2 (2.53).
    k_l, k_s : float
        Cut-off wavenumbers, 0 < k_l < k_s [cycles/length].
    H, m2 : float
        Hurst exponent, 0 < H < 1, and slope moment m2^h [-] of the whole spectrum (fixes C by (7.1)).
    E_star, gamma : float
        Composite modulus [pressure] (g* does not depend on it) and Persson's energy factor of (E.2).
    n_elements, order : int
        Gauss-Legendre elements and points per element in v.

    Returns
    -------
    ndarray
        g* = gbar / sqrt(m0^h) [-].
    """
    p = np.atleast_1d(np.asarray(pstar, dtype=float))
    if np.any(~(p > 0)) or not (0 < k_l < k_s) or not (0 < H < 1) or not (m2 > 0) or not (E_star > 0):
        raise ValueError("persson_gap needs p* > 0, 0 < k_l < k_s, 0 < H < 1, m2 > 0, E* > 0")
    C = psd_amplitude(k_l, k_s, H, m2)
    m0h = fractal_moments(k_l, k_s, H, C)[0]
    pbar = p * E_star * np.sqrt(m2 / 2.0)
    v, w = gauss_legendre(n_elements, order, 0.0, np.sqrt(np.log(k_s / k_l)))
    k = k_l * np.exp(v * v)
    m0p = E_star ** 2 / 8.0 * (2 * np.pi) ** 3 * C / (1.0 - H) * (k ** (2 - 2 * H) - k_l ** (2 - 2 * H))  # (E.4)
    S = C * k ** (-2.0 * (1.0 + H))
    inner = 0.5 * exp1(pbar[:, None] ** 2 / (2.0 * m0p[None, :]))
    integrand = k ** 2 * S * 2.0 / np.sqrt(2.0 * np.pi * m0p) * inner * k * 2.0 * v   # dk = 2 v k dv
    return E_star * np.pi ** 2 * gamma / np.sqrt(m0h) * np.sum(w * integrand, axis=1)
