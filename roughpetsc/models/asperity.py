"""Integrals over summit height and curvature shared by the models of Eqs. (4.21)-(4.31), (5.35)-(5.46).

Every model of chapters 4 and 5 is a sum of terms I_j(d) = int_d^inf int (xi - d)**a_j W_j(kappa) Phi(xi, kappa)
dkappa dxi with a density Phi of section 2.5, evaluated on d-independent nodes in ``t = xi - d``.
"""

import numpy as np

from . import pdfs
from .quadrature import semi_infinite, unit_interval

__all__ = ["CurvatureRule", "height_integrals", "DEFAULT_ELEMENTS"]

# (height, curvature[, ratio]) elements of 8 points: Tables 4.1/4.2 with a large margin (see tests).
DEFAULT_ELEMENTS = {"xi": (10,), "km": (14, 14), "kg": (14, 14), "k1k2": (10, 8, 14)}


class CurvatureRule:
    """Nodes, weights and density (``kind`` "xi", "km", "kg", "k1k2": (2.42), (2.40), (2.41), (2.39))."""

    def __init__(self, kind, alpha, elements=None, order=8):
        if kind not in DEFAULT_ELEMENTS:
            raise ValueError("unknown asperity density %r" % kind)
        pdfs.c1(alpha)
        self.kind, self.alpha = kind, float(alpha)
        el = DEFAULT_ELEMENTS[kind] if elements is None else tuple(elements)
        self.t, self.wt = semi_infinite(el[0], order, scale=1.0, power=2)
        if kind == "xi":
            self.k, self.wk = (), np.ones(1)
        elif kind in ("km", "kg"):
            k, w = semi_infinite(el[1], order, scale=1.0, power=2)
            self.k, self.wk = (k,), w
        else:
            # y = kappa_1/kappa_2 = w^2 in (0, 1], kappa_2 semi-infinite; d kappa_1 = kappa_2 dy
            y, wy = unit_interval(el[1], order, power=2)
            k2, w2 = semi_infinite(el[2], order, scale=1.0, power=2)
            Y, K2 = np.meshgrid(y, k2, indexing="ij")
            self.y = Y.ravel()
            self.k = (Y.ravel() * K2.ravel(), K2.ravel())
            self.wk = (wy[:, None] * w2[None, :] * K2).ravel()

    def density(self, xi):
        """Phi(xi[:, None], kappa[None, :]) on the curvature nodes, shape (nt, nk)."""
        x = xi[:, None]
        if self.kind == "xi":
            return pdfs.phi_xi(x, self.alpha)
        if self.kind == "km":
            return pdfs.phi_xi_km(x, self.k[0][None, :], self.alpha)
        if self.kind == "kg":
            return pdfs.phi_xi_kg(x, self.k[0][None, :], self.alpha)
        return pdfs.phi_xi_k1k2(x, self.k[0][None, :], self.k[1][None, :], self.alpha)


def height_integrals(rule, d, terms):
    """``I_j(d)``, shape (len(terms), len(d)), for ``terms`` (a_j, W_j on ``rule.k`` or None for 1)."""
    d = np.atleast_1d(np.asarray(d, dtype=float))
    hw = np.stack([rule.wt * rule.t ** a for a, _ in terms])             # (J, nt)
    kw = np.stack([rule.wk * (1.0 if W is None else W) for _, W in terms])  # (J, nk)
    out = np.empty((len(terms), d.size))
    for i, di in enumerate(d):
        F = rule.density(di + rule.t)                                    # (nt, nk)
        out[:, i] = np.sum((hw @ F) * kw, axis=1)
    return out
