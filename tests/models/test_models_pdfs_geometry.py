"""Asperity densities, Hertz elliptical contact and elliptical crack geometry."""

import numpy as np
import pytest
from scipy.integrate import dblquad, quad
from scipy.special import ellipe, gamma

from roughpetsc.models import crack, hertz, pdfs
from roughpetsc.models.quadrature import gauss_legendre, semi_infinite


@pytest.mark.parametrize("alpha", [2.0, 10.0])
def test_densities_are_consistent_marginals(alpha):
    """(2.42) integrates to one; (2.39), (2.40), (2.41) integrate to (2.42) over the
    curvatures; (2.40) integrates over xi to (7.8) -- by adaptive quadrature."""
    assert abs(quad(lambda x: pdfs.phi_xi(x, alpha), -np.inf, np.inf)[0] - 1) < 1e-10
    for xi in (-1.0, 0.7, 2.5):
        ref = pdfs.phi_xi(xi, alpha)
        km = quad(lambda k: pdfs.phi_xi_km(xi, k, alpha), 0, np.inf, epsrel=1e-11)[0]
        kg = quad(lambda k: pdfs.phi_xi_kg(xi, k, alpha), 0, np.inf, epsrel=1e-11)[0]
        assert abs(km / ref - 1) < 1e-8 and abs(kg / ref - 1) < 1e-8
    k12 = dblquad(lambda k1, k2: pdfs.phi_xi_k1k2(0.7, k1, k2, alpha), 0, np.inf, 0,
                  lambda k2: k2, epsrel=1e-9)[0]
    assert abs(k12 / pdfs.phi_xi(0.7, alpha) - 1) < 1e-7
    for k in (0.3, 1.2):
        v = quad(lambda x: pdfs.phi_xi_km(x, k, alpha), -np.inf, np.inf, epsrel=1e-11)[0]
        assert abs(v / pdfs.phi_km(k) - 1) < 1e-9


def test_shared_rule_exactness_and_convergence():
    x, w = gauss_legendre(3, 4, -1.0, 2.0)
    assert abs(np.sum(w * x ** 7) - (2 ** 8 - 1) / 8) < 1e-12
    t, w = semi_infinite(12, 8, power=2)
    assert abs(np.sum(w * t ** 1.5 * np.exp(-t * t)) - 0.5 * gamma(1.25)) < 1e-10


def test_hertz_eccentricity_fit_against_root():
    """Fig. 4.2: the fit (4.11) against the exact root of (4.10), ratios 1e-3..1."""
    y = np.logspace(-3, 0, 61)
    e = hertz.e_exact(y)
    assert np.allclose(hertz.ratio_from_e(e), y, rtol=1e-10)
    assert np.max(np.abs(hertz.e_fit(y) - e)) < 1e-3
    assert hertz.e_exact(np.array([1.0]))[0] == 0.0


def test_hertz_limits():
    """F1(0) = F2(0) = 1; circular contact when k1 = k2; F1, F2 < 1 otherwise."""
    assert np.allclose(hertz.F1(np.array([0.0, 1e-5])), 1.0, atol=1e-9)
    assert np.allclose(hertz.F2(np.array([0.0, 1e-5])), 1.0, atol=1e-9)
    A, P = hertz.elliptical(0.01, 2.0, 2.0, 3.0)
    Ac, Pc = hertz.circular(0.01, 2.0, 3.0)
    assert np.isclose(A, Ac, rtol=1e-12) and np.isclose(P, Pc, rtol=1e-12)
    # Johnson's exact check: contact area pi a b with a, b from the semi-axes relation
    # b/a = sqrt(1 - e^2) and (4.10): at y = 1/10 the elliptical area exceeds neither bound
    Ag, _ = hertz.mildly_elliptical_geometric(0.01, 0.2, 2.0)
    Am, _ = hertz.mildly_elliptical_mean(0.01, 0.2, 2.0)
    Ae, _ = hertz.elliptical(0.01, 0.2, 2.0)
    assert Am < Ae < Ag


def test_crack_eccentricity_fit_against_root():
    """Fig. 5.6: the fit (5.16) against the exact root of (5.15), ratios 1e-3..1."""
    y = np.logspace(-3, 0, 61)
    e = crack.e_exact(y)
    assert np.allclose(crack.ratio_from_e(e), y, rtol=1e-10)
    # the dissertation's empirical fit is good to 1.5e-3 in e (worst near y = 0.8), see NOTES
    assert np.max(np.abs(crack.e_fit(y) - e)) < 2e-3


def test_crack_integrals_and_penny_limits():
    """Martin's integrals as (1/2) int_0^{2pi} cos(m t) cos(n t) sqrt(1 - e^2 sin^2 t) dt
    (independent check of (5.10)-(5.12)), and the penny limits F1 = F2 = 1 of
    (5.17)/(5.23) -> (5.27)/(5.28).

    The reference is the trapezoidal rule over the whole period: the integrand is periodic and analytic in a
    strip of half-width acosh(1/e) (0.47 at e = 0.9), so 512 nodes are exact to round-off, where adaptive
    quadrature at this tolerance warns of round-off instead."""
    t = np.linspace(0.0, 2.0 * np.pi, 512, endpoint=False)
    for e in (0.005, 0.3, 0.9):
        def I(mm, nn):
            return np.pi * np.mean(np.cos(mm * t) * np.cos(nn * t) * np.sqrt(1 - e * e * np.sin(t) ** 2))
        assert np.isclose(crack.I00(e), I(0, 0), rtol=1e-12)
        assert np.isclose(crack.I02(e), I(0, 2), rtol=1e-8)
        assert np.isclose(crack.I22(e), I(2, 2), rtol=1e-8)
    y = np.array([1.0 - 1e-12, 1.0 - 1e-8])
    e = crack.e_exact(y)
    assert np.allclose(crack.F1(e, y), 1.0, atol=1e-6)
    assert np.allclose(crack.F2(e, y), 1.0, atol=1e-6)
    A, V = crack.elliptical(0.3, 2.0, 2.0 * (1 + 1e-12), 5.0)
    Ap, Vp = crack.penny(0.3, 2.0, 5.0)
    assert np.isclose(A, Ap, rtol=1e-6) and np.isclose(V, Vp, rtol=1e-6)


def test_crack_volume_from_opening():
    """(5.22) is (5.20) with the opening (5.19) and perimeter (5.21) (adaptive quad)."""
    p0, k1, k2, Es = 0.2, 0.5, 1.5, 2.0
    A, V = crack.elliptical(p0, k1, k2, Es)
    e = crack.e_exact(np.array(k1 / k2))
    ab = A / np.pi
    b = np.sqrt(ab * np.sqrt(1 - e ** 2))
    a = b / np.sqrt(1 - e ** 2)
    E = ellipe(e ** 2)
    K = k1 * a * a + k2 * b * b
    g = lambda r: 2 * b / (9 * E * Es) * (9 * p0 - 0.5 * K * (1 + 2 * (r / b) ** 2)) * np.sqrt(1 - (r / b) ** 2)
    Vq = quad(lambda r: g(r) * 4 * r / np.sqrt(1 - e ** 2) * E, 0, b, epsrel=1e-12)[0]
    assert np.isclose(V, Vq, rtol=1e-9)
