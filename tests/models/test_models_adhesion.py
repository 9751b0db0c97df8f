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
