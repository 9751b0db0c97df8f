"""One shared, vectorised composite Gauss-Legendre rule (the dissertation, section 4.4).

Every integral of the statistical models is evaluated with :func:`gauss_legendre` on a finite, transformed
domain; the maps and why: docs/models.md, "Quadrature (`quadrature`)".
"""

import numpy as np

__all__ = ["gauss_legendre", "semi_infinite", "unit_interval"]

_CACHE = {}


def _reference(order):
    if order not in _CACHE:
        _CACHE[order] = np.polynomial.legendre.leggauss(order)
    return _CACHE[order]


def gauss_legendre(n_elements, order=8, a=0.0, b=1.0):
    """Composite Gauss-Legendre nodes and weights on ``[a, b]``: ``n_elements`` equal elements (the accuracy
    control, Eqs. (4.36)-(4.38)) of ``order`` points (the dissertation uses 4)."""
    if n_elements < 1 or order < 1:
        raise ValueError("n_elements and order must be positive")
    x, w = _reference(order)
    edges = np.linspace(a, b, n_elements + 1)
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    nodes = (mid[:, None] + half[:, None] * x[None, :]).ravel()
    weights = (half[:, None] * w[None, :]).ravel()
    return nodes, weights


def semi_infinite(n_elements, order=8, scale=1.0, power=2):
    """Nodes and weights for ``int_0^inf f(t) dt`` with ``t = scale * ((1 - u) / u)**power``, u in (0, 1].

    Integrands must decay faster than any power of ``t`` (the models' carry a Gaussian factor).
    """
    u, w = gauss_legendre(n_elements, order, 0.0, 1.0)
    s = (1.0 - u) / u
    t = scale * s ** power
    jac = scale * power * s ** (power - 1) / u ** 2
    return t, w * jac


def unit_interval(n_elements, order=8, power=1):
    """Nodes and weights on ``[0, 1]`` with ``y = w**power`` (``power > 1``: for a singularity at ``y = 0``)."""
    x, w = gauss_legendre(n_elements, order, 0.0, 1.0)
    return x ** power, w * power * x ** (power - 1)
