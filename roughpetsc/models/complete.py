"""Statistical models of nearly complete contact (the dissertation, chapter 5.3).

The multi-crack analogues of chapter 4 on the pressure surface (``alpha^p`` (2.54)); g* also depends on ``alpha^h``.
"""

import numpy as np
from scipy.special import erfc

from .asperity import CurvatureRule, height_integrals
from .quadrature import semi_infinite

__all__ = ["COMPLETE_MODELS", "complete"]

COMPLETE_MODELS = ("gw", "nayak_bush", "greenwood", "ciavarella")
_KIND = {"gw": "xi", "nayak_bush": "km", "greenwood": "kg"}


def _ciavarella(p, alpha_h, n_elements=12):
    """(5.54) and the gap integral (5.53) (line integral on the shared rule)."""
    t, w = semi_infinite(n_elements, scale=1.0, power=2)
    xi = p[:, None] + t[None, :]
    I = np.sum(w * np.sqrt(xi) * t ** 2.5 * np.exp(-0.5 * xi ** 2), axis=1)
    g = 12.0 / (5.0 * np.sqrt(2.0) * np.pi ** 1.5) / np.sqrt(alpha_h) * I
    return 1.0 - 0.75 * erfc(p / np.sqrt(2.0)), g


def complete(name, pstar, alpha_p, alpha_h, elements=None):
    """Contact ratio and mean gap of a nearly-complete-contact model.

    Parameters
    ----------
    name : {"gw", "nayak_bush", "greenwood", "ciavarella"}
        Adapted GW (5.37)-(5.38), Nayak-Bush (5.41)-(5.42), Greenwood (5.45)-(5.46), Ciavarella (5.53)-(5.54).
    pstar : array_like
        p* = pbar / sqrt(m0^p) >= 0 [-].
    alpha_p, alpha_h : float
        Bandwidths of the pressure surface (2.54) and of the surface (2.16), > 3/2 (no alpha_p in "ciavarella").
    elements : tuple of int, optional
        Gauss-Legendre elements per dimension.

    Returns
    -------
    A, gstar : ndarray
        A* [-] (may be < 0 at small p*, outside the model's range) and g* = gbar / sqrt(m0^h) [-].
    """
    p = np.atleast_1d(np.asarray(pstar, dtype=float))
    if not np.all(np.isfinite(p)):
        raise ValueError("p* must be finite")
    if not alpha_h > 1.5:
        raise ValueError("alpha_h must exceed 3/2")
    if name == "ciavarella":
        return _ciavarella(p, alpha_h)
    if name not in _KIND:
        raise ValueError("unknown complete-contact model %r; choose from %s"
                         % (name, ", ".join(COMPLETE_MODELS)))
    rule = CurvatureRule(_KIND[name], alpha_p, elements)
    if name == "gw":
        I = height_integrals(rule, p, [(1.0, None), (2.5, None)])
        cA = np.sqrt(3.0) / 16.0 * np.sqrt(np.pi) * np.sqrt(alpha_p)                # (5.37)
        cG = 3.0 / (20.0 * np.sqrt(2.0)) * np.pi ** -0.25                           # (5.38)
    else:
        k = rule.k[0]
        I = height_integrals(rule, p, [(1.0, 1.0 / k), (2.5, k ** -1.5)])
        cA = np.sqrt(alpha_p) / (2.0 * np.sqrt(3.0))                                # (5.41)/(5.45)
        cG = 4.0 * np.sqrt(3.0) / (15.0 * np.pi)                                    # (5.42)/(5.46)
    cG = cG * alpha_p ** 0.25 / np.sqrt(alpha_h)
    return 1.0 - cA * I[0], cG * I[1]
