"""Early-contact models against Tables 4.1/4.2 of the dissertation, asymptotics and
adaptive quadrature (an independent algorithm)."""

import numpy as np
import pytest
from scipy.integrate import dblquad, quad
from scipy.special import erfc

import roughpetsc.models as M
from roughpetsc.models import hertz, pdfs

D = M.TABLE_4_1_SEPARATIONS
TABLE = M.TABLE_4_1
# The one entry whose converged value does not round to the Dissertation column:
# BGT, alpha 2, d* = 2.5, A*: 2.82452e-3 (also by adaptive dblquad below), i.e.
# 0.52 units of the 4th digit from 2.824e-3; it rounds to the [16] value 2.825e-3.
EXCEPTION = {("bgt", 2.0, 5, "A"): 2.825e-3}


def rounds_to(x, table):
    """True if x agrees with the 4-significant-digit table value (half a unit)."""
    unit = 10.0 ** (np.floor(np.log10(abs(table))) - 3)
    return abs(x - table) <= 0.5 * unit


@pytest.mark.parametrize("key", sorted(TABLE))
def test_tables_4_1_4_2(key):
    name, alpha = key
    A, p = M.early(name, D, alpha)
    P = np.sqrt(np.pi / 2) * p
    tA, tP = TABLE[key]
    for i in range(D.size):
        refA = EXCEPTION.get((name, alpha, i, "A"), tA[i])
        assert rounds_to(A[i], refA), (name, alpha, D[i], A[i], refA)
        assert rounds_to(P[i], tP[i]), (name, alpha, D[i], P[i], tP[i])


def test_bgt_exception_by_adaptive_quadrature():
    """BGT area at alpha 2, d* = 2.5 by scipy dblquad (xi integral in closed form)."""
    a, d = 2.0, 2.5
    C1 = pdfs.c1(a)

    def inner(k2, y):
        k1 = y * k2
        z = d - 0.75 * (k1 + k2) / np.sqrt(a)
        G = np.exp(-C1 * z * z) / (2 * C1) - z * np.sqrt(np.pi / (4 * C1)) * erfc(np.sqrt(C1) * z)
        return (G * 27 / (8 * np.pi) * np.sqrt(C1) * k1 * k2 * (k2 - k1) / np.sqrt(k1 * k2) * k2
                * np.exp(-9 / 16 * (k1 * k1 + k2 * k2 - 2 / 3 * k1 * k2)))

    def outer(y):
        e = hertz.e_exact(np.array([y]))
        w = float(hertz.F1(e)[0] ** 2 / hertz.F2(e)[0])
        return w * quad(inner, 0, 30, args=(y,), epsabs=1e-14, epsrel=1e-10)[0]

    ref = np.sqrt(a) / (6 * np.sqrt(3)) * quad(outer, 0, 1, epsabs=1e-13, epsrel=1e-9, limit=200)[0]
    A = M.early("bgt", [d], a)[0][0]
    assert abs(A / ref - 1) < 2e-6
    assert not rounds_to(ref, 2.824e-3) and rounds_to(ref, 2.825e-3)


@pytest.mark.parametrize("alpha", [2.0, 10.0])
def test_gl_against_adaptive_quad(alpha):
    """Fixed Gauss-Legendre rule against scipy quad/dblquad at a few d*."""
    for d in (0.0, 1.3, 2.7):
        A, p = M.early("gw", [d], alpha)
        refA = np.sqrt(np.pi) / (16 * np.sqrt(3)) * np.sqrt(alpha) * quad(
            lambda x: (x - d) * pdfs.phi_xi(x, alpha), d, np.inf, epsabs=0, epsrel=1e-12)[0]
        refP = alpha ** 0.75 / (9 * np.pi ** 0.75) * quad(
            lambda x: (x - d) ** 1.5 * pdfs.phi_xi(x, alpha), d, np.inf, epsabs=0, epsrel=1e-12)[0]
        assert abs(A[0] / refA - 1) < 1e-7 and abs(p[0] / refP - 1) < 1e-7
        for name, phi in (("nayak_bush", pdfs.phi_xi_km), ("greenwood", pdfs.phi_xi_kg)):
            A, p = M.early(name, [d], alpha)
            refA = np.sqrt(alpha) / (6 * np.sqrt(3)) * dblquad(
                lambda k, x: (x - d) / k * phi(x, k, alpha), d, d + 12, 0, 12,
                epsabs=1e-13, epsrel=1e-10)[0]
            assert abs(A[0] / refA - 1) < 1e-6, (name, d)


def test_asymptotic_bgt_and_large_separation():
    """(4.35): A* = sqrt(pi/2) p* for the asymptotic model; BGT and Greenwood tend
    to it as d* grows (slowly, Fig. 4.6), alpha 2."""
    d = np.array([1.0, 3.0, 5.0, 7.0])
    A, p = M.early("bgt_asymptotic", d, 2.0)
    assert np.allclose(A, np.sqrt(np.pi / 2) * p, rtol=1e-14)
    for name in ("bgt", "greenwood"):
        A, p = M.early(name, d, 2.0)
        dev = np.abs(A / (np.sqrt(np.pi / 2) * p) - 1)
        assert np.all(np.diff(dev) < 0) and dev[-1] < 0.05, (name, dev)


def test_inversion():
    p = np.array([1e-3, 0.02, 0.15, 0.35])
    for name in ("gw", "nayak_bush", "greenwood", "bgt_asymptotic"):
        d, A = M.early_separation(name, p, 2.0)
        A2, p2 = M.early(name, d, 2.0)
        assert np.allclose(p2, p, rtol=1e-10) and np.allclose(A, A2, rtol=1e-12)
        assert np.allclose(M.early_area(name, p, 2.0), A, rtol=1e-12)
    with pytest.raises(ValueError):
        M.early_area("gw", [-1.0], 2.0)


def test_bad_input():
    with pytest.raises(ValueError):
        M.early("nope", [1.0], 2.0)
    with pytest.raises(ValueError):
        M.early("gw", [1.0], 1.2)
