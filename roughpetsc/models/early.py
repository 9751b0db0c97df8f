"""Statistical models of early contact (the dissertation, chapter 4).

Dimensionless variables as in :mod:`roughpetsc.models`; every model depends on the bandwidth ``alpha^h`` (2.16) only.
"""

import numpy as np
from scipy.special import erfc, erfcinv

from . import hertz
from .asperity import CurvatureRule, height_integrals

__all__ = ["EARLY_MODELS", "TABLE_4_1", "TABLE_4_1_SEPARATIONS", "early", "early_area", "early_separation"]

EARLY_MODELS = ("gw", "nayak_bush", "greenwood", "bgt", "bgt_asymptotic")

TABLE_4_1_SEPARATIONS = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
# Tables 4.1/4.2, the "Dissertation" columns: (A*, sqrt(pi/2) p*) at the separations d* above, by
# (model, alpha^h).
TABLE_4_1 = {
    ("bgt", 2.0): ([1.644e-1, 1.080e-1, 6.039e-2, 2.750e-2, 9.940e-3, 2.824e-3, 6.301e-4],
                   [2.270e-1, 1.368e-1, 7.102e-2, 3.060e-2, 1.066e-2, 2.962e-3, 6.519e-4]),
    ("greenwood", 2.0): ([1.674e-1, 1.098e-1, 6.129e-2, 2.785e-2, 1.004e-2, 2.848e-3, 6.341e-4],
                         [2.218e-1, 1.339e-1, 6.967e-2, 3.010e-2, 1.052e-2, 2.931e-3, 6.463e-4]),
    ("bgt", 10.0): ([2.040e-1, 1.174e-1, 5.809e-2, 2.415e-2, 8.269e-3, 2.297e-3, 5.120e-4],
                    [3.680e-1, 1.950e-1, 8.940e-2, 3.471e-2, 1.120e-2, 2.956e-3, 6.308e-4]),
    # Table 4.1 prints 8.403e-2 for Greenwood, alpha 10, d* = 2: a typo (the [16] column says 8.403e-3).
    ("greenwood", 10.0): ([2.079e-1, 1.195e-1, 5.912e-2, 2.456e-2, 8.403e-3, 2.333e-3, 5.194e-4],
                          [3.588e-1, 1.902e-1, 8.730e-2, 3.393e-2, 1.096e-2, 2.896e-3, 6.188e-4]),
    ("nayak_bush", 2.0): ([1.449e-1, 9.593e-2, 5.425e-2, 2.507e-2, 9.210e-3, 2.657e-3, 6.003e-4],
                          [2.089e-1, 1.266e-1, 6.624e-2, 2.881e-2, 1.014e-2, 2.844e-3, 6.307e-4]),
    ("nayak_bush", 10.0): ([1.785e-1, 1.030e-1, 5.121e-2, 2.139e-2, 7.367e-3, 2.059e-3, 4.617e-4],
                           [3.361e-1, 1.785e-1, 8.209e-2, 3.198e-2, 1.036e-2, 2.745e-3, 5.883e-4]),
}

_KIND = {"gw": "xi", "nayak_bush": "km", "greenwood": "kg", "bgt": "k1k2"}


def _coefficients(name, alpha):
    """Prefactors of A* and p* in (4.23)/(4.25), (4.26)-(4.31)."""
    if name == "gw":
        return np.sqrt(np.pi) / (16 * np.sqrt(3)) * np.sqrt(alpha), alpha ** 0.75 / (9 * np.pi ** 0.75)
    return np.sqrt(alpha) / (6 * np.sqrt(3)), 2 * np.sqrt(2) / (9 * np.sqrt(3) * np.pi) * alpha ** 0.75


def _weights(name, rule, e_method):
    """Curvature weights of the area and load integrands."""
    if name == "gw":
        return None, None
    if name in ("nayak_bush", "greenwood"):
        k = rule.k[0]
        return 1.0 / k, k ** -0.5
    e = hertz.e_exact(rule.y) if e_method == "exact" else hertz.e_fit(rule.y)
    f1, f2 = hertz.F1(e), hertz.F2(e)
    kg = np.sqrt(rule.k[0] * rule.k[1])
    return f1 ** 2 / f2 / kg, f2 ** -1.5 / np.sqrt(kg)


def _evaluate(name, dstar, alpha_h, elements, e_method, slope):
    d = np.atleast_1d(np.asarray(dstar, dtype=float))
    if name == "bgt_asymptotic":
        A = 0.25 * erfc(d / np.sqrt(2))                                          # (4.32)
        p = erfc(d / np.sqrt(2)) / (2 * np.sqrt(2 * np.pi))                      # (4.34)
        dp = -np.exp(-0.5 * d ** 2) / (2 * np.pi)
        return A, p, dp
    if name not in _KIND:
        raise ValueError("unknown early-contact model %r; choose from %s" % (name, ", ".join(EARLY_MODELS)))
    rule = CurvatureRule(_KIND[name], alpha_h, elements)
    wA, wP = _weights(name, rule, e_method)
    terms = [(1.0, wA), (1.5, wP)] + ([(0.5, wP)] if slope else [])
    I = height_integrals(rule, d, terms)
    cA, cP = _coefficients(name, alpha_h)
    return cA * I[0], cP * I[1], (-1.5 * cP * I[2] if slope else None)


def early(name, dstar, alpha_h, elements=None, e_method="exact"):
    """Contact ratio and pressure of an early-contact model as functions of d*.

    Parameters
    ----------
    name : {"gw", "nayak_bush", "greenwood", "bgt", "bgt_asymptotic"}
        Adapted GW (4.23)/(4.25), Nayak-Bush (4.26)-(4.27), Greenwood (4.28)-(4.29), BGT (4.30)-(4.31) or
        asymptotic BGT (4.32)/(4.34).
    dstar, alpha_h : array_like, float
        Separation d* = d / sqrt(m0^h) [-], any real value, and bandwidth alpha^h (2.16), > 3/2.
    elements : tuple of int, optional
        Gauss-Legendre elements per dimension.
    e_method : {"exact", "fit"}
        BGT: eccentricity from the root of (4.10) (reproduces Table 4.1) or the fit (4.11) (up to ~2e-5 apart).

    Returns
    -------
    A, pstar : ndarray
        A* [-] and p* = pbar / sqrt(m0^p) [-].
    """
    A, p, _ = _evaluate(name, dstar, alpha_h, elements, e_method, False)
    return A, p


def early_separation(name, pstar, alpha_h, elements=None, e_method="exact", iterations=60):
    """Invert p*(d*) of an early-contact model: (d*, A*) at p* > 0, by safeguarded Newton on ln p*."""
    p_t = np.atleast_1d(np.asarray(pstar, dtype=float))
    if np.any(~np.isfinite(p_t)) or np.any(p_t <= 0):
        raise ValueError("p* must be positive and finite")
    if name == "bgt_asymptotic":                       # closed-form inverse of (4.34)
        if np.any(p_t >= 1.0 / np.sqrt(2.0 * np.pi)):
            raise ValueError("asymptotic BGT: p* must be below 1/sqrt(2 pi)")
        d = np.sqrt(2.0) * erfcinv(2.0 * np.sqrt(2.0 * np.pi) * p_t)
        return d, _evaluate(name, d, alpha_h, elements, e_method, False)[0]
    grid = np.linspace(-3.0, 7.0, 41)
    _, pg, _ = _evaluate(name, grid, alpha_h, elements, e_method, False)
    lp = np.log(pg)
    d = np.interp(-np.log(p_t), -lp, grid)
    lo = np.full_like(d, -np.inf)
    hi = np.full_like(d, np.inf)
    for _ in range(iterations):
        A, p, dp = _evaluate(name, d, alpha_h, elements, e_method, True)
        f = np.log(p) - np.log(p_t)
        hi = np.where(f < 0, np.minimum(hi, d), hi)          # p decreases with d
        lo = np.where(f > 0, np.maximum(lo, d), lo)
        step = f / (dp / p)
        new = d - step
        bad = (new <= lo) | (new >= hi)
        mid = 0.5 * (np.where(np.isfinite(lo), lo, d - 1) + np.where(np.isfinite(hi), hi, d + 1))
        new = np.where(bad, mid, new)
        if np.all(np.abs(new - d) < 1e-13 * (1 + np.abs(d))):
            d = new
            break
        d = new
    A, p, _ = _evaluate(name, d, alpha_h, elements, e_method, False)
    return d, A


def early_area(name, pstar, alpha_h, elements=None, e_method="exact"):
    """Contact ratio A*(p*) of an early-contact model by inversion of p*(d*)."""
    return early_separation(name, pstar, alpha_h, elements, e_method)[1]
