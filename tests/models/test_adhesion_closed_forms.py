"""Closed-form adhesive references: JKR/DMT/Maugis-Dugdale sphere and the JKR /
Maugis-Dugdale wave.  Each check uses a route independent of the formula it
tests (direct quadrature of the elastic fields, limits, literature formulas)."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq, minimize_scalar
from scipy.special import ellipk

from roughpetsc.models import sphere_adhesion as S
from roughpetsc.models import wavy_adhesion as WA

R, E, W = 1.3, 2.0, 0.07            # sphere radius, E*, work of adhesion (arbitrary units)


# ------------------------------------------------------------------ sphere
def test_jkr_dmt_pulloff():
    """JKR: numerical minimum of P(a) is -3/2 pi w R; minimum of delta(a) (rigid grips)
    is at P = -5/6 pi w R; P(a) inverts; DMT: -2 pi w R."""
    f = lambda a: S.jkr_load(a, R, E, W)
    res = minimize_scalar(f, bounds=(1e-4, 2.0), method="bounded", options={"xatol": 1e-12})
    P, a, d = S.jkr_pulloff_load_control(R, E, W)
    assert np.isclose(res.fun, -1.5 * np.pi * W * R, rtol=1e-12) and np.isclose(P, res.fun)
    assert np.isclose(res.x, a, rtol=1e-6) and np.isclose(d, S.jkr_approach(a, R, E, W))
    g = lambda a: S.jkr_approach(a, R, E, W)
    res = minimize_scalar(g, bounds=(1e-6, a), method="bounded", options={"xatol": 1e-13})
    P2, a2, d2 = S.jkr_pulloff_displacement_control(R, E, W)
    assert np.isclose(res.fun, d2, rtol=1e-12) and np.isclose(res.x, a2, rtol=1e-6)
    assert np.isclose(S.jkr_load(a2, R, E, W), P2, rtol=1e-12)
    assert np.isclose(P2, -5 / 6 * np.pi * W * R)
    aa = np.array([a, 1.1 * a, 2 * a, 5 * a])                       # stable branch a >= a_c
    assert np.allclose(S.jkr_contact_radius(S.jkr_load(aa, R, E, W), R, E, W), aa, rtol=1e-10)
    assert np.isclose(S.dmt_load(0.0, R, E, W), S.dmt_pulloff(R, W)) and \
        np.isclose(S.dmt_pulloff(R, W), -2 * np.pi * W * R)


def test_maugis_parameter_and_scales():
    """lambda = 2 sigma0 (R/(pi w K^2))^(1/3) = sigma0 (9R/(2 pi w E*^2))^(1/3), and the
    physical MD curve is the dimensionless one in Maugis' units."""
    s0 = 0.4
    lam = S.maugis_parameter(R, E, W, s0)
    assert np.isclose(lam, s0 * np.cbrt(9 * R / (2 * np.pi * W * E ** 2)), rtol=1e-14)
    a_s, P_s, d_s = S.md_scales(R, E, W)
    a = np.array([0.1, 0.3, 0.6])
    P, d, c = S.md_curve(a, R, E, W, s0)
    Pd, Dd, m = S.md_dimensionless(a / a_s, lam)
    assert np.allclose(P, Pd * P_s) and np.allclose(d, Dd * d_s) and np.allclose(c, m * a)
    # the physical forms P = K a^3/R - 2 sigma0 [a sqrt(c^2-a^2) + c^2 arccos(a/c)],
    # delta = a^2/R - 2 sigma0 sqrt(c^2-a^2)/E*
    K = 4 * E / 3
    q = np.sqrt(c * c - a * a)
    assert np.allclose(P, K * a ** 3 / R - 2 * s0 * (a * q + c * c * np.arccos(a / c)), rtol=1e-12)
    assert np.allclose(d, a * a / R - 2 * s0 * q / E, rtol=1e-12)


@pytest.mark.parametrize("s0", [0.15, 1.2])          # lambda = 0.45 and 3.6
def test_maugis_dugdale_by_quadrature(s0):
    """Independent check of the MD equations: the MD pressure field, integrated with
    the axisymmetric Boussinesq kernel u(r) = 4/(pi E*) int p(t) t/(r+t) K(k) dt,
    carries the load P, conforms to the sphere inside the contact with approach delta,
    and opens the gap to exactly h0 = w/sigma0 at the edge c of the Dugdale zone."""
    a = 0.25
    P, d, c = (v[0] for v in S.md_curve(a, R, E, W, s0))
    p = lambda r: S.md_pressure(r, a, c, R, E, s0)

    def u(r):
        f = lambda t: p(t) * t / (r + t) * ellipk(4 * r * t / (r + t) ** 2)
        return 4 / (np.pi * E) * quad(f, 0, c, points=sorted({r, a} - {0.0, c}) or None,
                                      limit=400, epsabs=1e-14)[0]

    u0 = 2 / E * quad(p, 0, c, points=[a], epsabs=1e-15)[0]
    assert np.isclose(u0, d, rtol=1e-9, atol=1e-13)
    assert np.isclose(2 * np.pi * quad(lambda r: p(r) * r, 0, c, points=[a], epsabs=1e-15)[0], P,
                      rtol=1e-9, atol=1e-13)
    for r in (0.1, 0.2):
        assert abs(r * r / (2 * R) - u0 + u(r)) < 1e-10
    assert np.isclose(c * c / (2 * R) - u0 + u(c), W / s0, rtol=1e-8)


def test_maugis_dugdale_limits():
    """lambda -> 0: DMT; lambda -> inf: JKR (curves and pull-off).  Observed
    convergence: JKR errors ~ lambda^-2, DMT load ~ lambda, DMT approach ~ lambda^(1/2)."""
    A = np.array([0.5, 1.0, 2.0])
    P, D, _ = S.md_dimensionless(A, 1e3)
    assert np.allclose(P, A ** 3 - np.sqrt(6 * A ** 3), atol=1e-5)
    assert np.allclose(D, A ** 2 - 2 / 3 * np.sqrt(6 * A), atol=1e-5)
    P, D, _ = S.md_dimensionless(A, 1e-4)
    assert np.allclose(P, A ** 3 - 2, atol=2e-3)
    assert np.allclose(D, A ** 2, atol=2e-2)
    assert abs(S.md_pulloff_dimensionless(1e-3)[0] + 2) < 1e-4
    assert abs(S.md_pulloff_dimensionless(1e3)[0] + 1.5) < 1e-6
    # the A -> 0 end of the curve
    Pz, Dz, C = S.md_zero_contact(0.7)
    Pn, Dn, m = S.md_dimensionless([1e-7], 0.7)
    assert np.isclose(Pn[0], Pz, rtol=1e-6) and np.isclose(Dn[0], Dz, rtol=1e-5)
    assert np.isclose(1e-7 * m[0], C, rtol=1e-6)
    # physical units
    lam = S.maugis_parameter(R, E, W, 5e3)
    assert np.isclose(S.md_pulloff(R, E, W, 5e3), -1.5 * np.pi * W * R, rtol=1e-5), lam


def test_maugis_dugdale_pulloff_against_fit():
    """MD pull-off vs lambda against the fit of Carpick, Ogletree & Salmeron, J. Colloid
    Interface Sci. 211 (1999) 395: Pbar_c = -7/4 + 1/4 (4.04 l^1.4 - 1)/(4.04 l^1.4 + 1)
    (an empirical fit to Maugis' curve, not a printed table; the largest deviation
    found here is 1.7 % near lambda = 0.3).  Also: monotone from -2 to -3/2."""
    lams = np.array([0.1, 0.3, 1.0, 3.0, 10.0])
    Pc = np.array([S.md_pulloff_dimensionless(l)[0] for l in lams])
    x = 4.04 * lams ** 1.4
    fit = -7 / 4 + 0.25 * (x - 1) / (x + 1)
    assert np.all(np.abs(Pc / fit - 1) < 0.02)
    assert np.all(np.diff(Pc) > 0) and np.all((Pc > -2) & (Pc < -1.5))


# ------------------------------------------------------------------- wave
LAM, H, EW = 2.0, 0.03, 3.0


def _w_of_alpha(alpha):
    return alpha ** 2 * np.pi ** 2 * EW * H * H / (2 * LAM)


def test_wavy_jkr_westergaard_limit():
    """w = 0: pbar = p* sin^2(pi a/lam) (Westergaard), gbar = h (1 - P + P ln P); the
    pressure field has mean pbar and vanishes at the contact edge."""
    a = np.array([0.05, 0.3, 0.7, 0.95])
    ps = WA.full_contact_pressure(LAM, H, EW)
    P = np.sin(np.pi * a / LAM) ** 2
    assert np.allclose(WA.jkr_mean_pressure(a, LAM, H, EW, 0.0), ps * P, rtol=1e-14)
    assert np.allclose(WA.jkr_mean_gap(a, LAM, H, EW, 0.0), H * (1 - P + P * np.log(P)), rtol=1e-12)
    assert np.allclose(WA.jkr_stress_intensity(a, ps * P, LAM, H, EW), 0.0)
    for ai in (0.3, 0.7):
        mean = quad(lambda x: WA.westergaard_pressure(x, ai, LAM, H, EW), -ai, ai, epsabs=1e-14)[0] / LAM
        assert np.isclose(mean, ps * np.sin(np.pi * ai / LAM) ** 2, rtol=1e-10)
        punch = quad(lambda x: WA.punch_pressure(x, ai, LAM), -ai, ai, epsabs=1e-13)[0] / LAM
        assert np.isclose(punch, 1.0, rtol=1e-8)


def test_wavy_jkr_alpha_thresholds_and_pulloff():
    """Jump into full contact at zero load for alpha >= 3^(3/4)/4 = 0.5699 (J95's 0.57);
    stationary points merge at ALPHA_FOLD; small alpha: isolated JKR cylinders."""
    assert abs(WA.ALPHA_SPONTANEOUS - 0.5699) < 1e-4
    psi = np.linspace(1e-6, np.pi / 2 - 1e-6, 200001)
    f = lambda al: np.sin(psi) ** 2 - al * np.sqrt(np.tan(psi))
    assert abs(np.max(f(WA.ALPHA_SPONTANEOUS)[psi > 0.4])) < 1e-9                # touches 0 at pi/3
    w = _w_of_alpha(WA.ALPHA_SPONTANEOUS)
    pmax, amax = WA.jkr_jump_in(LAM, H, EW, w)
    assert abs(pmax) < 1e-14 and np.isclose(amax, LAM / 3)
    for al in (0.1, 0.4, 0.9):
        w = _w_of_alpha(al)
        assert np.isclose(WA.johnson_alpha(LAM, H, EW, w), al)
        ps = WA.full_contact_pressure(LAM, H, EW)
        pmin, amin = WA.jkr_pulloff_load_control(LAM, H, EW, w)
        small = psi < WA.jkr_stationary_points(al)[1]
        assert np.isclose(pmin, ps * f(al)[small].min(), rtol=1e-8)
        assert (WA.jkr_jump_in(LAM, H, EW, w)[0] > 0) == (al < WA.ALPHA_SPONTANEOUS)
    lo, hi = WA.jkr_stationary_points(WA.ALPHA_FOLD * (1 - 1e-8))
    assert abs(lo - hi) < 1e-3 and np.isnan(WA.jkr_stationary_points(1.07)[0])
    # alpha -> 0: pbar_min lam -> JKR cylinder of radius lam^2/(4 pi^2 h), per unit length
    # -(3/4)(4 pi E* R w^2)^(1/3) (2-D JKR, Barquins 1988 form)
    for al, tol in ((1e-3, 2e-4), (1e-2, 2e-3)):
        w = _w_of_alpha(al)
        Rc = LAM ** 2 / (4 * np.pi ** 2 * H)
        cyl = -0.75 * np.cbrt(4 * np.pi * EW * Rc * w * w)
        assert np.isclose(WA.jkr_pulloff_load_control(LAM, H, EW, w)[0] * LAM, cyl, rtol=tol)


def test_wavy_jkr_displacement_control():
    """Under mean-gap control the contacts snap off at the maximum of gbar(a)."""
    w = _w_of_alpha(0.3)
    p, a, g = WA.jkr_pulloff_displacement_control(LAM, H, EW, w)
    aa = np.linspace(1e-6, a * 3, 20001)
    assert np.isclose(g, WA.jkr_mean_gap(aa, LAM, H, EW, w).max(), rtol=1e-9)
    assert WA.jkr_pulloff_load_control(LAM, H, EW, w)[0] < p < 0


def _wave_fields(a, pbar, w=None):
    """Pieces of the elastic state (contact half-width a, mean pressure pbar,
    Westergaard + Koiter pressure) by direct quadrature with the periodic kernel:
    mean pressure, int p h cos(2 pi x/lam) dx and the mean gap d = h - u(0),
    u(x) = -(2/(pi E*)) int p(t) ln|2 sin(pi (x - t)/lam)| dt."""
    b = np.sin(np.pi * a / LAM)
    xphi = lambda ph: LAM / np.pi * np.arcsin(b * np.sin(ph))          # smooths the edges
    jac = lambda ph: LAM / np.pi * b * np.cos(ph) / np.sqrt(1 - (b * np.sin(ph)) ** 2)
    pj = lambda ph: WA.jkr_pressure(xphi(ph), a, pbar, LAM, H, EW) * jac(ph)
    t, wt = np.polynomial.legendre.leggauss(80)
    ph, wt = 0.5 * np.pi * t, 0.5 * np.pi * wt
    mean = np.sum(wt * pj(ph)) / LAM
    icos = np.sum(wt * pj(ph) * np.cos(2 * np.pi * xphi(ph) / LAM))
    f = lambda q: pj(q) * np.log(abs(2 * np.sin(np.pi * xphi(q) / LAM)))
    u0 = -4 / (np.pi * EW) * quad(f, 0, np.pi / 2, limit=200, epsabs=1e-15, epsrel=1e-13)[0]
    return mean, icos, H - u0


@pytest.mark.parametrize("a0", [0.1, 0.6])
def test_wavy_jkr_energy_release(a0):
    """Energy route, independent of the stress-intensity formula: at fixed mean pressure,
    the mechanical energy per period of the constrained states (contact |x| < a, any a),
    Pi(a) = U_el + pbar lam gbar = 1/2 h int p cos(2 pi x/lam) dx + 1/2 pbar lam gbar
    (the gap vanishes in the contact, so U_el needs no double integral), satisfies
    dPi/da = 2 w (two contact edges per period) at Johnson's pbar, and 0 at
    Westergaard's.  The quadratures also confirm the mean pressure and [CM04]'s gbar."""
    w = 0.004
    Pi = lambda a, p: 0.5 * H * _wave_fields(a, p)[1] + 0.5 * p * LAM * _wave_fields(a, p)[2]
    da = 1e-4
    pj = float(WA.jkr_mean_pressure(a0, LAM, H, EW, w))
    mean, _, gbar = _wave_fields(a0, pj)
    assert np.isclose(mean, pj, rtol=1e-10)
    assert np.isclose(gbar, WA.jkr_mean_gap(a0, LAM, H, EW, w), rtol=1e-10)
    assert np.isclose((Pi(a0 + da, pj) - Pi(a0 - da, pj)) / (2 * da), 2 * w, rtol=1e-6)
    pw = float(WA.westergaard_mean_pressure(a0, LAM, H, EW))
    assert abs((Pi(a0 + da, pw) - Pi(a0 - da, pw)) / (2 * da)) < 1e-7 * w
    # the same through Irwin-Kies with the quadrature compliance of the flat punch
    C = lambda a: (_wave_fields(a, float(WA.westergaard_mean_pressure(a, LAM, H, EW)) + 1.0)[2]
                   - _wave_fields(a, float(WA.westergaard_mean_pressure(a, LAM, H, EW)))[2])
    assert np.isclose(C(a0), -WA.punch_compliance(a0, LAM, EW), rtol=1e-9)
    dC = (C(a0 + da) - C(a0 - da)) / (2 * da)
    assert np.isclose(LAM / 4 * (pw - pj) ** 2 * abs(dC), w, rtol=1e-6)


# --------------------------------------------------------- Maugis-Dugdale wave
def _md_check_by_quadrature(m, a, beta):
    """Pressure field of state (a, beta) integrated with the periodic kernel: mean
    pressure, conformity in the contact, gap h0 at x = c, mean gap."""
    c = m.cohesive_end(a, beta)
    p = lambda x: m.pressure(x, a, beta)
    half = m.lam / 2
    pts = sorted({-c, -a, a, c} - {-half, half})
    mean = quad(p, -half, half, points=pts, limit=400, epsabs=1e-14)[0] / m.lam

    def u(x0):
        f = lambda x: p(x) * np.log(abs(2 * np.sin(np.pi * (x0 - x) / m.lam)))
        return -2 / (np.pi * m.E) * quad(f, -half, half, points=sorted(set(pts) | {x0}),
                                         limit=400, epsabs=1e-14)[0]

    u0 = u(0.0)
    d = m.h - u0
    gap = lambda x: d - m.h * np.cos(2 * np.pi * x / m.lam) + u(x)
    return mean, d, gap(0.6 * a), (gap(c) if c < half * (1 - 1e-12) else None), gap(half)


def test_wavy_md_by_quadrature():
    m = WA.WavyMaugisDugdale(1.0, 0.05, 1.0, 0.002, 0.05)          # h0 = 0.04 ~ h
    a = 0.15
    betas = m.states_at(a)
    assert len(betas) == 1 and betas[0] < np.pi / 2
    mean, d, g_in, g_c, _ = _md_check_by_quadrature(m, a, betas[0])
    st = m.state(a, betas[0])
    assert np.isclose(mean, st["pbar"], rtol=1e-9)
    assert np.isclose(d, st["gbar"], rtol=1e-9)
    assert abs(g_in) < 1e-12 and np.isclose(g_c, m.h0, rtol=1e-9)
    # a saturated state: pbar = p* sin^2 - sigma0, gbar = Westergaard's, max gap <= h0
    a = 0.3
    assert a > m.a_saturation() and np.pi / 2 in m.states_at(a)
    mean, d, g_in, _, g_half = _md_check_by_quadrature(m, a, np.pi / 2)
    assert np.isclose(mean, m.pstar * np.sin(np.pi * a) ** 2 - m.sigma0, rtol=1e-9)
    assert np.isclose(d, WA.westergaard_mean_gap(a, 1.0, 0.05), rtol=1e-9)
    assert abs(g_in) < 1e-12 and g_half <= m.h0
    # saturated branch joins the unsaturated one; gap(a=0) decreases with a at fixed beta
    assert np.isclose(m.a_of_beta(np.pi / 2 - 1e-7), m.a_saturation(), atol=1e-5)
    for bt in (0.7, 1.2):
        g = [m.gap_at_cohesive_end(ai, bt) for ai in np.linspace(0, 0.499, 40)]
        assert np.all(np.diff(g) < 0)


def test_wavy_md_jkr_limit():
    """sigma0 -> inf at fixed w: Johnson's JKR wave (errors observed ~ sigma0^-2)."""
    lam, h, E, w = 1.0, 0.05, 1.0, 0.002
    m = WA.WavyMaugisDugdale(lam, h, E, w, 8.0)                     # h0 = h / 200
    for a in (0.05, 0.3):
        bt = m.states_at(a)[0]
        assert abs(m.mean_pressure(a, bt) - WA.jkr_mean_pressure(a, lam, h, E, w)) < 5e-5 * m.pstar
        assert abs(m.mean_gap(a, bt) - WA.jkr_mean_gap(a, lam, h, E, w)) < 2e-4 * h
    p, a, bt = m.pulloff()
    pj, aj = WA.jkr_pulloff_load_control(lam, h, E, w)
    assert np.isclose(p, pj, rtol=1e-5) and np.isclose(a, aj, rtol=1e-3)


def test_wavy_md_cylinder_limit():
    """a, c << lam: the MD wave tends to Baney & Hui's MD cylinder [J. Adhes. Sci.
    Technol. 11 (1997) 393, Eq. (23) and the load], radius R = lam^2/(4 pi^2 h), load
    per length pbar lam:  lambda_BH = 4 sigma0/(pi^2 E*^2 w/R)^(1/3),
    A = a/(2 (w R^2/(pi E*))^(1/3)), P in units (pi E* w^2 R)^(1/3),
    lambda A^2/2 (m mu - ln(m+mu)) + lambda^2 A/2 (mu ln(m+mu) - m ln m) = 1,
    P = A^2 - lambda A mu.  Fixed R, w, sigma0 and growing lam: the deviation falls
    as lam^-2 (the load is a near-cancelling difference, hence the size at lam = 1)."""
    E, w, s0 = 1.0, 1e-5, 0.01
    Rc = 1.0 / (4 * np.pi ** 2 * 0.05)
    lbh = 4 * s0 / np.cbrt(np.pi ** 2 * E ** 2 * w / Rc)
    a_s = 2 * np.cbrt(w * Rc ** 2 / (np.pi * E))
    dev = {}
    for lam in (2.0, 4.0):
        m = WA.WavyMaugisDugdale(lam, lam ** 2 / (4 * np.pi ** 2 * Rc), E, w, s0)
        for A in (0.3, 1.0):
            f = lambda mm: (lbh * A * A / 2 * (mm * np.sqrt(mm * mm - 1) - np.arccosh(mm))
                            + lbh ** 2 * A / 2 * (np.sqrt(mm * mm - 1) * np.arccosh(mm)
                                                  - mm * np.log(mm)) - 1)
            mm = brentq(f, 1.0, 1e6, xtol=1e-14)
            Pbh = (A * A - lbh * A * np.sqrt(mm * mm - 1)) * np.cbrt(np.pi * E * w * w * Rc)
            a = A * a_s
            bt = m.states_at(a)[0]
            dev[lam, A] = (m.mean_pressure(a, bt) * lam / Pbh - 1, m.cohesive_end(a, bt) / a / mm - 1)
    assert abs(dev[4.0, 1.0][0]) < 2e-3 and abs(dev[4.0, 0.3][0]) < 2e-3
    assert abs(dev[4.0, 1.0][1]) < 2e-4 and abs(dev[4.0, 0.3][1]) < 2e-4
    for A in (0.3, 1.0):
        assert 3.5 < dev[2.0, A][0] / dev[4.0, A][0] < 4.5


def test_wavy_md_pulloff_bounds():
    """-sigma0 <= pull-off; = -sigma0 from full contact when h0 >= 2h; the branch minimum
    is reproduced by the sampled curve."""
    m = WA.WavyMaugisDugdale(1.0, 0.01, 1.0, 0.002, 0.05)           # h0 = 0.04 >= 2h
    assert m.a_saturation() == 0.0
    assert np.isclose(m.pulloff_global()[0], -m.sigma0)
    m = WA.WavyMaugisDugdale(1.0, 0.05, 1.0, 0.002, 0.2)
    cv = m.curve(60)
    p, a, bt = m.pulloff_global()
    assert -m.sigma0 < p <= cv["pbar"].min() + 1e-12
    assert np.all(cv["pbar"] >= -m.sigma0)
    p1 = m.pulloff()[0]
    assert p <= p1 < 0
