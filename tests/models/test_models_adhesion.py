"""Penny-shaped adhesive crack (JKR, Maugis-Dugdale, full adhesion) and the
adhesive adapted GW model (the dissertation, chapter 6)."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

import roughpetsc.models as M


def test_jkr_limit():
    """(6.15) p*_min = 2.3602, equal to the numerical minimum of (6.14); roots of
    (6.14) with G* = 1 (6.16) and the stability window (6.17)."""
    assert round(M.jkr_pmin(), 4) == 2.3602
    num = minimize_scalar(M.jkr_pstar, bounds=(0.1, 2.0), method="bounded", options={"xatol": 1e-12})
    assert abs(num.fun - M.jkr_pmin()) < 1e-10
    p = np.array([2.5, 4.0, 10.0])
    for branch, inside in (("stable", True), ("unstable", False)):
        b = M.jkr_radius(p, branch)
        assert np.allclose(M.jkr_pstar(b), p, rtol=1e-12)
        assert np.allclose(M.jkr_G(b, p), 1.0, rtol=1e-9)
        ok = (1.5 * b ** 2 <= p) & (p <= 7.5 * b ** 2)
        assert np.all(ok == inside)
    assert np.isnan(M.jkr_radius([2.0])[0])


@pytest.mark.parametrize("sigma", [0.5, 2.0, 5.0])
def test_maugis_dugdale_curve_and_points(sigma):
    c = M.AdhesiveCrack(sigma)
    p, b, m = c.curve(801)
    s = np.sqrt(1 - m * m)
    assert np.allclose(1.5 * b ** 2 + sigma * s, p, rtol=1e-12)                     # (6.28)
    t1, t2 = 0.5 * s * (2 * m * m + 1) * b ** 3, (p * s - (1 - m) * sigma) * b
    scale = np.abs(t1) + np.abs(t2) + 1 / sigma
    assert np.max(np.abs(t1 - t2 + 1 / sigma) / scale) < 1e-12                       # (6.29)
    assert np.allclose(c.G(p, b, m), 1.0, rtol=1e-7)                                 # (6.30)
    pts = c.points
    assert np.isclose(pts["E"][0], sigma)                                             # (6.38)
    assert np.isclose(pts["F"][0], sigma + 1.5 * sigma ** (-2 / 3), rtol=1e-12)       # (6.39)
    bF = np.sqrt(2 / 3 * (pts["F"][0] - sigma))                                       # (6.36)
    assert np.isclose(pts["F"][1], bF, rtol=1e-10)
    assert np.isclose(sigma * bF ** 3, 1.0, rtol=1e-10)                               # (6.37) G* = 1
    assert np.isclose(pts["G"][0], pts["F"][0]) and pts["G"][1] > pts["F"][1]
    # B, the fold of the curve, is where the fixed-load stability (6.31)-(6.32) changes sign
    for q, sign in ((c.qB * 0.97, 1), (c.qB * 1.03, -1)):
        dG = c.dG_db(c.p_of_q(q), c.b_of_q(q), c.m_of_q(q))
        assert np.sign(dG) == sign
    if pts["B"][0] <= sigma:
        assert pts["C"][1] == 0.0                                                    # snap-in closure
    else:
        assert np.isclose(pts["C"][1], np.sqrt(2 / 3 * (pts["B"][0] - sigma)))        # jump to full adhesion


def test_maugis_dugdale_limits():
    """sigma0* -> inf: the stable branch tends to JKR (6.14); sigma0* -> 0: the
    loaded crack tends to the non-adhesive limit (6.8)."""
    p = np.array([3.0, 5.0, 10.0])
    bj = M.jkr_radius(p)
    dev = [np.max(np.abs(M.AdhesiveCrack(s).stable(p)[0] / bj - 1)) for s in (30.0, 300.0, 3000.0)]
    assert dev[0] > dev[1] > dev[2] and dev[2] < 2e-3
    bn = M.nonadhesive_radius(p)
    dev = [np.max(np.abs(M.AdhesiveCrack(s).state(p)[0] / bn - 1)) for s in (0.3, 0.03, 0.003)]
    assert dev[0] > dev[1] > dev[2] and dev[2] < 1e-3


def test_volume_against_opening_quadrature():
    """V* of the Maugis-Dugdale crack against adaptive quadrature of the opening
    (6.24) in dimensional form, normalised by (6.5)."""
    Es, w, kap = 2.0, 0.3, 1.7
    P = (np.pi ** 2 * Es ** 2 * w ** 2 * kap / 72) ** 0.2
    L = (81 * np.pi * Es * w / (16 * kap ** 2)) ** 0.2
    c = M.AdhesiveCrack(2.0)
    bs, ms = c.stable(np.array([4.0]))
    ps, bs, ms = 4.0, bs[0], ms[0]
    p0, b, s0 = ps * P, bs * L, 2.0 * P
    cc = ms * b

    def g(r):
        adh = quad(lambda t: np.sqrt(t * t - cc * cc) / np.sqrt(t * t - r * r), max(r, cc), b,
                   epsrel=1e-12, limit=200)[0]
        return 4 / (np.pi * Es) * (np.sqrt(b * b - r * r) * (p0 - kap * (2 * r * r + b * b) / 9) - s0 * adh)

    V = quad(lambda r: 2 * np.pi * r * g(r), 0, b, points=[cc], epsrel=1e-10, limit=200)[0]
    assert np.isclose(c.volume(ps, bs, ms), V / (1.5 * w / kap), rtol=1e-7)
    # non-adhesive limit: (5.28) in the groups (6.4)-(6.5)
    p0 = 1.3 * P
    V528 = 16 * np.sqrt(3) / (5 * Es) * kap ** -1.5 * p0 ** 2.5
    assert np.isclose(M.nonadhesive_volume(1.3), V528 / (1.5 * w / kap), rtol=1e-12)
    b = M.nonadhesive_radius(1.3)
    assert np.isclose(M.jkr_volume(b, 1.3), M.nonadhesive_volume(1.3), rtol=1e-12)


MOM = (8.35e-19, 2e-4, 9.58e10, 6.67e25)        # Table 6.2 (m0h, m2h, m4h, m6h)


def test_adhesive_gw_groups_and_limits():
    z0, s = 3e-10, 1 / 20
    gw = M.AdhesiveGW(*MOM, s, z0)
    m4p = 0.3 * MOM[3]
    m2p, m0p = MOM[2] / 3, MOM[1] / 2
    assert np.isclose(gw.sigma_star, (3 / np.sqrt(np.pi)) ** 0.6 * z0 ** -0.4 * s ** 0.6 * m4p ** -0.1)  # (6.56)
    assert np.isclose(gw.C, (3 / np.sqrt(np.pi)) ** 0.6 * z0 ** -0.4 * s ** -0.4 * np.sqrt(m0p) * m4p ** -0.1)  # (6.57)
    # (6.58)/(6.59) as printed disagree with (6.48)/(6.49); C1 and C2 are checked
    # through the non-adhesive limit below, which fixes C1 C and C2 independently.
    p = np.array([0.5, 1.5, 3.0])
    A, g = gw.loading(p)
    Au, gu = gw.unloading(p, 3.0)
    assert np.all(Au >= A - 1e-15) and np.all(gu <= g + 1e-15)
    # non-adhesive limit (5.37)-(5.38)
    alpha_h = MOM[0] * MOM[2] / MOM[1] ** 2
    A0, g0 = M.AdhesiveGW(*MOM, 1e-10, z0).loading(p)
    Ar, gr = M.complete("gw", p, gw.alpha_p, alpha_h)
    assert np.allclose(A0, Ar, rtol=1e-6) and np.allclose(g0, gr, rtol=1e-5)
    assert np.all(A > Ar) and np.all(g < gr)


def test_solution_set_runs_from_E_through_F():
    """The set starts at E (p* = sigma0*, b* = 0, (6.38)); its two branches meet at F ((6.39): p*_F =
    sigma0* + 3/2 sigma0*^(-2/3), b*_F = sigma0*^(-1/3), m = 0), and m rises from there."""
    sigma = 2.0
    p, b, m, v = M.AdhesiveCrack(sigma).solution_set(401)
    assert p[0] == sigma and b[0] == 0 and v[0] == 0
    joint = 401 // 4
    for i in (joint - 1, joint):
        assert p[i] == pytest.approx(sigma + 1.5 * sigma ** (-2 / 3), rel=1e-12)
        assert b[i] == pytest.approx(sigma ** (-1 / 3), rel=1e-12)
        assert m[i] == 0
    assert np.all(np.diff(m[joint:]) > 0)


def jkr_radius_from_polynomial(p):
    """b* of the stable JKR branch: the largest real root t of 3/2 t^5 - p* t + sqrt 2 (footnote to (6.14)), squared."""
    roots = np.polynomial.Polynomial([np.sqrt(2.0), -p, 0.0, 0.0, 0.0, 1.5]).roots()
    return max(r.real for r in roots if abs(r.imag) < 1e-9) ** 2


def test_jkr_crack_against_the_polynomial_and_the_opening():
    """The JKR-limit crack: its radius against the roots of the footnote polynomial of (6.14) (G* = 1 by
    (6.16)), its snap-in point against (6.15), its volume against quadrature of the opening (6.24) at sigma0 = 0,
    and a closed crack stays closed however far it is unloaded (E (6.38) is at infinity)."""
    crack = M.JKRCrack()
    p_b, b_b, _ = crack.points["B"]
    assert p_b == pytest.approx(1.5 * (np.sqrt(2) / 6) ** 0.8 + np.sqrt(2) * (np.sqrt(2) / 6) ** -0.2, rel=1e-14)
    assert M.jkr_pstar(b_b) == pytest.approx(p_b, rel=1e-14)
    p = np.array([p_b * (1 + 1e-10), 2.4, 3.0, 7.0, 40.0, 1e3])
    reference = np.array([jkr_radius_from_polynomial(x) for x in p])
    assert np.allclose(crack.stable(p), reference, rtol=1e-9, atol=0)
    assert np.allclose(M.jkr_G(reference[1:], p[1:]), 1.0, rtol=1e-12)
    assert np.isnan(crack.stable([p_b * (1 - 1e-9)])[0])
    b, m = crack.state([3.0, 3.0, 1e6], p_min=[3.0, 2.0, 2.0])
    assert b[0] == pytest.approx(reference[2], rel=1e-12) and b[1] == 0 and b[2] == 0 and np.all(m == 1)
    Es, w, kap = 1.3, 0.2, 2.1
    P = (np.pi ** 2 * Es ** 2 * w ** 2 * kap / 72) ** 0.2
    L = (81 * np.pi * Es * w / (16 * kap ** 2)) ** 0.2
    p0, radius = 3.0 * P, reference[2] * L
    opening = lambda r: 4 / (np.pi * Es) * np.sqrt(radius ** 2 - r ** 2) * (p0 - kap * (2 * r * r + radius ** 2) / 9)
    volume = quad(lambda r: 2 * np.pi * r * opening(r), 0, radius, epsrel=1e-12)[0]
    assert crack.volume(3.0, reference[2]) == pytest.approx(volume / (1.5 * w / kap), rel=1e-9)


def test_maugis_dugdale_snap_in_tends_to_the_jkr_minimum():
    """sigma0* -> inf: the snap-in point B of the Maugis-Dugdale crack tends to (6.15), its cohesive zone closes
    (m_B -> 1), and the reopening point E = sigma0* (6.38) recedes."""
    errors = []
    for sigma in (3.0, 30.0, 300.0, 3000.0):
        crack = M.AdhesiveCrack(sigma)
        p_b, _, m_b = crack.points["B"]
        errors.append(abs(p_b / M.jkr_pmin() - 1))
        assert crack.points["E"][0] == sigma and 1 - m_b < 3.0 / sigma
    assert errors == sorted(errors, reverse=True) and errors[-1] < 1e-6


W_FIXED = 3e-10 / 20          # surface energy sigma0 z0 of section 6.6 at sigma0/E* = 1/20, z0 = 0.3 nm


@pytest.mark.parametrize("stage", ["loading", "unloading"])
def test_rough_jkr_limit_is_the_maugis_dugdale_model_at_infinite_sigma0(stage):
    """The rough model's JKR limit: AdhesiveGW on the Maugis-Dugdale crack, sigma0 -> inf at a fixed w (so that
    its scales C, C1, C2 stay), tends to AdhesiveGW(crack_law="jkr") in 1 - A* and g*, loading and unloading
    from p*max = 3 (Table 6.2 moments)."""
    p = np.array([0.5, 1.0, 2.0])
    jkr = M.AdhesiveGW(*MOM, 1 / 20, W_FIXED * 20, crack_law="jkr")

    def curves(model):
        return model.loading(p) if stage == "loading" else model.unloading(p, 3.0)

    reference = curves(jkr)
    errors = []
    for sigma0 in (0.05, 0.5, 5.0, 50.0):
        model = M.AdhesiveGW(*MOM, sigma0, W_FIXED / sigma0)
        assert model.C == pytest.approx(jkr.C, rel=1e-12)
        A, g = curves(model)
        errors.append(max(np.max(np.abs((1 - A) / (1 - reference[0]) - 1)), np.max(np.abs(g / reference[1] - 1))))
    assert errors == sorted(errors, reverse=True), errors
    assert errors[-1] < 1e-4, errors


def test_rough_jkr_limit_loading_tends_to_the_non_adhesive_model_as_w_vanishes():
    """The rough model's JKR limit at a vanishing surface energy w = sigma0 z0: its loading curve tends to the
    closed form (5.37)-(5.38) with the summit density (2.42), 1 - A* and g* alike, the error falling about like
    w^(1/2) (Table 6.2 moments, z0 = 0.3 nm).

    Unloading has no such limit: a JKR crack that snapped shut on loading never reopens under compression,
    whatever w, so from p*max = 3 the non-contact area stays far below the non-adhesive curve's."""
    p = np.array([0.5, 1.5, 3.0])
    z0 = 3e-10
    alpha_h = MOM[0] * MOM[2] / MOM[1] ** 2
    errors = []
    for s in (1e-4, 1e-6, 1e-8, 1e-10):
        model = M.AdhesiveGW(*MOM, s, z0, crack_law="jkr")
        A_ref, g_ref = M.complete("gw", p, model.alpha_p, alpha_h)
        A, g = model.loading(p)
        errors.append(max(np.max(np.abs((1 - A) / (1 - A_ref) - 1)), np.max(np.abs(g / g_ref - 1))))
        A_unloaded, _ = model.unloading(p[:1], 3.0)
        assert 1 - A_unloaded[0] < 0.5 * (1 - A_ref[0])
    assert errors == sorted(errors, reverse=True), errors
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 5) & (ratios < 20)), ratios    # a factor 100 in w: about 10 in the error
    assert errors[-1] < 1e-3, errors


def jkr_state(p, p_min):
    """(b*, m) of the JKR-limit crack at p* after a history minimum p_min: stable branch, or closed for good."""
    return (jkr_radius_from_polynomial(p) if p_min >= M.jkr_pmin() else 0.0), 1.0


def maugis_dugdale_state(sigma):
    """(b*, m) of the Maugis-Dugdale crack at (p*, history minimum), from the summary closing section 6.3.

    The solution curve from F (m = 0) to A (m -> 1), with m = 1 - exp(-q): its radius is the positive root of the
    cubic s^3 b^3 + sigma m (1 - m) b - 1/sigma (from (6.28)-(6.29), s = sqrt(1 - m^2)) by numpy's polynomial
    roots, p* = 3/2 b^2 + sigma s; the stable branch is the part beyond the minimum B of p*(q) (bounded
    minimisation), solved for q by brentq. History: loading the stable branch down to B, then closed (below E)
    or on the full-adhesion branch (6.36); after a minimum below B, closed below E = sigma (6.38), full
    adhesion up to F (6.39), the stable branch beyond.
    """
    from scipy.optimize import brentq

    def curve(q):
        m = -np.expm1(-q)
        roots = np.polynomial.Polynomial([-1 / sigma, sigma * m * np.exp(-q), 0.0, (1 - m * m) ** 1.5]).roots()
        b = max(r.real for r in roots if abs(r.imag) < 1e-9 * abs(r))
        return 1.5 * b * b + sigma * np.sqrt(1 - m * m), b, m

    q_b = minimize_scalar(lambda q: curve(q)[0], bounds=(0.0, 30.0), method="bounded", options={"xatol": 1e-12}).x
    p_b, p_f = curve(q_b)[0], sigma + 1.5 * sigma ** (-2 / 3)

    def stable(p):
        q = brentq(lambda q: curve(q)[0] - p, q_b, 60.0, xtol=1e-14, rtol=1e-14)
        return curve(q)[1:]

    def state(p, p_min):
        if p_min >= p_b or p >= p_f:
            return stable(p)
        return (np.sqrt(2 / 3 * (p - sigma)), 0.0) if p >= sigma else (0.0, 0.0)

    return state


@pytest.mark.parametrize("law, states", [("jkr", ((0.5, 0.5), (1.5, 1.5), (1.0, 3.0), (0.0, 4.0))),
                                          ("maugis-dugdale", ((1.5, 1.5), (0.0, 4.0)))])
def test_rough_models_against_adaptive_quadrature(law, states):
    """1 - A* (6.50), (6.53) and g* (6.51), (6.54) of both crack laws against scipy's adaptive quadrature over
    the summit height (the JKR radius from the polynomial roots), loading and unloading (p*, p*max): the model's
    fixed rule is exact to 1e-8 at sigma0/E* = 1/20 (Table 6.2 moments), where the radius starts as
    sqrt(p* - p*_B) at B."""
    from roughpetsc.models import pdfs

    model = M.AdhesiveGW(*MOM, 1 / 20, 3e-10, crack_law=law)
    crack = model.crack
    radius_and_m = jkr_state if law == "jkr" else maugis_dugdale_state(crack.sigma)

    def integrand(xi, pbar, pbar_max, volume):
        p = (xi - pbar) * model.C
        b, m = radius_and_m(p, (xi - pbar_max) * model.C)
        return (crack.volume(p, b, m) if volume else crack.area(b)) * pdfs.phi_xi(xi, model.alpha_p)

    for pbar, pbar_max in states:
        kinks = sorted(k for k in [pbar + bk / model.C for bk in crack.breakpoints()] +
                       [pbar_max + bk / model.C for bk in crack.breakpoints()] if pbar < k < pbar + 14)
        one_minus_A, gap = (scale * quad(integrand, pbar, pbar + 14, args=(pbar, pbar_max, volume), points=kinks,
                                         epsabs=0, epsrel=1e-10, limit=200)[0]
                            for scale, volume in ((model.C1, False), (model.C2, True)))
        A, g = model.loading([pbar]) if pbar == pbar_max else model.unloading([pbar], pbar_max)
        assert 1 - A[0] == pytest.approx(one_minus_A, rel=1e-8), (pbar, pbar_max)
        assert g[0] == pytest.approx(gap, rel=1e-8), (pbar, pbar_max)


def test_model_curves_at_one_twentieth_are_single_valued():
    """The model is a function of p*: at sigma0/E* = 1/20, on the moments of the group #1 surface of the 512^2
    study (seed 1), 1 - A* and g* fall strictly along loading and along unloading from p*max = 2 on a fine p*
    grid. (The jagged, folded model curves once drawn in studies/output/adhesion/chapter6.png came from
    plotting it in the BEM's step order; the BEM's p*(g*) folds for real, see tests/contact/test_adhesion.py.)"""
    moments = (1.2047024726831547e-08, 2.0064674091124703e-04, 9.146583723919058, 693876.6925952481)
    model = M.AdhesiveGW(*moments, 1 / 20, 0.33 * np.sqrt(moments[0]))
    p = np.linspace(0.5, 2.0, 31)
    for A, g in (model.loading(p), model.unloading(p, 2.0)):
        assert np.all(np.diff(1 - A) < 0) and np.all(np.diff(g) < 0)
