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
    """Contact ratio A* and mean gap g* of a nearly-complete-contact model at p* >= 0 (A* < 0 at small p* possible).

    ``name``: adapted GW (5.37)-(5.38), Nayak-Bush (5.41)-(5.42), Greenwood (5.45)-(5.46), Ciavarella asymptotic
    (5.53)-(5.54) (no alpha_p). alpha_p (2.54) and alpha_h (2.16) > 3/2.
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
