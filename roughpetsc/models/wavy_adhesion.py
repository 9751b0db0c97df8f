r"""Adhesive contact of a 1-D sinusoidal (wavy) surface and a flat, plane strain.

Reference solutions for periodic adhesive boundary-element runs. Profile h(x) = h cos(2 pi x / lam), composite
modulus ``E_star`` (1.6), work of adhesion ``w``; contact in |x| < a (mod lam). ``pbar`` is the mean pressure
(positive compressive), ``gbar`` the mean gap (the separation of the mean planes).

Units: ``x``, ``a``, ``c``, ``lam``, ``h`` [length]; ``E_star``, ``sigma0``, ``pbar``, ``p`` [pressure];
``w`` [energy/area]; stress intensity [pressure * length^(1/2)].

Sources ([J95], [W39], [K59], [CM04], [H01], [JWG16], [BH97]) and the derivation of the JKR wave and its
stationary points: docs/models.md.
"""

import numpy as np
from scipy.optimize import brentq, minimize_scalar

__all__ = ["ALPHA_SPONTANEOUS", "ALPHA_FOLD",
           "full_contact_pressure", "johnson_alpha",
           "westergaard_mean_pressure", "westergaard_mean_gap", "westergaard_pressure",
           "punch_pressure", "punch_compliance",
           "jkr_mean_pressure", "jkr_mean_gap", "jkr_stress_intensity", "jkr_pressure",
           "jkr_stationary_points", "jkr_pulloff_load_control", "jkr_jump_in",
           "jkr_pulloff_displacement_control", "WavyMaugisDugdale"]

ALPHA_SPONTANEOUS = 3.0 ** 0.75 / 4.0
ALPHA_FOLD = 4.0 * 0.375 ** 0.75 * 0.625 ** 1.25


def _psi(a, lam):
    return np.pi * np.asarray(a, float) / lam


def _fold(x, lam):
    """|x| reduced to [0, lam/2]."""
    x = np.abs(np.asarray(x, float)) % lam
    return np.minimum(x, lam - x)


def full_contact_pressure(lam, h, E_star):
    """p* = pi E* h / lam [pressure]: mean pressure of full contact [W39]."""
    return np.pi * E_star * h / lam


def johnson_alpha(lam, h, E_star, w):
    """Johnson's parameter alpha = sqrt(2 lam w / (pi^2 E* h^2)) [-], [J95]."""
    return np.sqrt(2.0 * lam * w / (np.pi ** 2 * E_star * h * h))


# -------------------------------------------------------- non-adhesive parts
def westergaard_mean_pressure(a, lam, h, E_star):
    """Westergaard: pbar = p* sin^2(pi a/lam) [pressure], [W39]."""
    return full_contact_pressure(lam, h, E_star) * np.sin(_psi(a, lam)) ** 2


def westergaard_mean_gap(a, lam, h):
    """Westergaard mean gap h [cos^2 psi + sin^2 psi ln sin^2 psi] [length], [CM04] Eq. (39) with alpha = 0."""
    psi = _psi(a, lam)
    s2 = np.sin(psi) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(s2 > 0, s2 * np.log(np.where(s2 > 0, s2, 1.0)), 0.0)
    return h * (np.cos(psi) ** 2 + t)


def westergaard_pressure(x, a, lam, h, E_star):
    """Westergaard pressure 2 p* cos(pi x/lam) sqrt(sin^2(pi a/lam) - sin^2(pi x/lam)) in |x| < a [pressure]."""
    th, tb = np.pi * _fold(x, lam) / lam, np.pi * a / lam
    d = np.sin(tb - th) * np.sin(tb + th)                    # sin^2 tb - sin^2 th
    return np.where(th < tb, 2.0 * full_contact_pressure(lam, h, E_star) * np.cos(th)
                    * np.sqrt(np.maximum(d, 0.0)), 0.0)


def punch_pressure(x, a, lam):
    """Koiter's periodic flat-punch pressure of unit mean [-] [K59]:
    cos(pi x/lam) / sqrt(sin^2(pi a/lam) - sin^2(pi x/lam)) in |x| < a, 0 outside."""
    th, tb = np.pi * _fold(x, lam) / lam, np.pi * a / lam
    d = np.sin(tb - th) * np.sin(tb + th)
    inside = th < tb
    return np.where(inside, np.cos(th) / np.sqrt(np.where(inside, d, 1.0)), 0.0)


def punch_compliance(a, lam, E_star):
    """Mean-gap change per unit mean pressure of the periodic flat punch of half-width a [length/pressure]:
    C = -(2 lam/(pi E*)) ln sin(pi a/lam); G = (lam/4) sigma^2 |dC/da| = K^2/(2 E*) (Irwin-Kies, per tip)."""
    return -2.0 * lam / (np.pi * E_star) * np.log(np.sin(_psi(a, lam)))


# ------------------------------------------------------------------ JKR wave
def jkr_mean_pressure(a, lam, h, E_star, w):
    """JKR mean pressure pbar(a) = p* [sin^2 psi - alpha sqrt(tan psi)] [pressure], [J95]."""
    psi = _psi(a, lam)
    return full_contact_pressure(lam, h, E_star) * (
        np.sin(psi) ** 2 - johnson_alpha(lam, h, E_star, w) * np.sqrt(np.tan(psi)))


def jkr_stress_intensity(a, pbar, lam, h, E_star):
    """Mode-I stress intensity K = (p* sin^2 psi - pbar) sqrt(lam cot psi) at the contact edge
    [pressure*length^0.5] (Westergaard + Koiter superposition, docs/models.md; [CM04] symmetric case)."""
    psi = _psi(a, lam)
    return ((full_contact_pressure(lam, h, E_star) * np.sin(psi) ** 2 - pbar)
            * np.sqrt(lam / np.tan(psi)))


def jkr_mean_gap(a, lam, h, E_star, w):
    """JKR mean gap gbar = h [cos^2 psi + (pbar/p*) ln sin^2 psi] [length], [CM04] (39)."""
    psi = _psi(a, lam)
    P = jkr_mean_pressure(a, lam, h, E_star, w) / full_contact_pressure(lam, h, E_star)
    return h * (np.cos(psi) ** 2 + P * np.log(np.sin(psi) ** 2))


def jkr_pressure(x, a, pbar, lam, h, E_star):
    """Contact pressure [pressure] for half-width a and any mean pressure pbar: Westergaard plus Koiter's punch
    carrying pbar - pbar_W [J95] (the JKR equilibrium is pbar = jkr_mean_pressure(a, ...))."""
    pw = westergaard_mean_pressure(a, lam, h, E_star)
    return westergaard_pressure(x, a, lam, h, E_star) + (pbar - pw) * punch_pressure(x, a, lam)


def jkr_stationary_points(alpha):
    """psi = pi a/lam of the local minimum and maximum of pbar(a): the roots of alpha = 4 sin^(3/2) psi
    cos^(5/2) psi (NaN, NaN when alpha >= ALPHA_FOLD, where pbar(a) decreases monotonically)."""
    if alpha <= 0:
        return 0.0, np.pi / 2
    if alpha >= ALPHA_FOLD:
        return np.nan, np.nan
    g = lambda p: 4.0 * np.sin(p) ** 1.5 * np.cos(p) ** 2.5 - alpha
    top = np.arctan(np.sqrt(0.6))
    return (brentq(g, 0.0, top, xtol=1e-15, rtol=1e-15),
            brentq(g, top, np.pi / 2, xtol=1e-15, rtol=1e-15))


def _jkr_stationary_state(which, lam, h, E_star, w):
    """(pbar, a) at the stationary point ``which`` (0: local minimum, 1: local maximum) of pbar(a)."""
    a = jkr_stationary_points(johnson_alpha(lam, h, E_star, w))[which] * lam / np.pi
    return float(jkr_mean_pressure(a, lam, h, E_star, w)) if np.isfinite(a) else np.nan, a


def jkr_pulloff_load_control(lam, h, E_star, w):
    """Load-control pull-off from partial contact, the local minimum of pbar(a) [J95].

    Parameters
    ----------
    lam, h : float
        Wavelength and amplitude [length].
    E_star, w : float
        Composite modulus [pressure] and work of adhesion [energy/area].

    Returns
    -------
    pbar, a : float
        Pull-off pressure [pressure] and contact half-width [length]; NaN for alpha >= ALPHA_FOLD. For
        alpha -> 0, pbar -> -3 p* (alpha/4)^(4/3) (isolated JKR cylinders); for alpha >= ALPHA_SPONTANEOUS
        the full contact reached at zero load has no finite pull-off.
    """
    return _jkr_stationary_state(0, lam, h, E_star, w)


def jkr_jump_in(lam, h, E_star, w):
    """Local maximum (pbar [pressure], a [length]) of pbar(a), above which the surfaces jump into full contact
    [J95]; pbar <= 0 iff alpha >= ALPHA_SPONTANEOUS."""
    return _jkr_stationary_state(1, lam, h, E_star, w)


def jkr_pulloff_displacement_control(lam, h, E_star, w):
    """Separation under mean-gap control, the maximum of gbar(a) below the local maximum of pbar.

    Parameters
    ----------
    lam, h, E_star, w : float
        As in :func:`jkr_pulloff_load_control`.

    Returns
    -------
    pbar, a, gbar : float
        Mean pressure [pressure], contact half-width and mean gap [length].
    """
    alpha = johnson_alpha(lam, h, E_star, w)
    top = jkr_stationary_points(alpha)[1] if alpha < ALPHA_FOLD else np.pi / 2 - 1e-9
    f = lambda p: -jkr_mean_gap(p * lam / np.pi, lam, h, E_star, w)
    grid = np.linspace(0.0, top, 401)[1:]
    i = int(np.argmin(f(grid)))
    res = minimize_scalar(f, bounds=(grid[max(i - 1, 0)] if i else 1e-12, grid[min(i + 1, 399)]),
                          method="bounded", options={"xatol": 1e-13})
    a = res.x * lam / np.pi
    return float(jkr_mean_pressure(a, lam, h, E_star, w)), a, -res.fun


# ------------------------------------------------------------ Maugis-Dugdale
def _tanh_sinh(n=40, step=None):
    """Tanh-sinh rule on [0, 1]: distances of the nodes from 0 and from 1 (accurate near the ends), weights."""
    step = step or 3.3 / n
    k = np.arange(-n, n + 1) * step
    u = 0.5 * np.pi * np.sinh(k)
    with np.errstate(over="ignore"):
        d0 = 1.0 / (1.0 + np.exp(-2.0 * u))             # (1 + tanh u)/2
        d1 = 1.0 / (1.0 + np.exp(2.0 * u))              # (1 - tanh u)/2
        wt = 0.25 * np.pi * step * np.cosh(k) / np.cosh(u) ** 2
    keep = (d0 > 0) & (d1 > 0) & (wt > 0)
    return d0[keep], d1[keep], wt[keep]


def _beta_grid(n):
    """Interior grid of (0, pi/2), geometric near 0 (where the states close to JKR are)."""
    g = np.concatenate([np.geomspace(1e-10, 2e-2, n // 4), np.linspace(0.0, np.pi / 2, n + 1)[1:-1]])
    return np.unique(g)


class WavyMaugisDugdale:
    r"""Maugis-Dugdale adhesion of the wave: Dugdale stress sigma0 acting where the
    gap is below h0 = w/sigma0.

    A state is (a, beta), sin^2 beta = (s_c^2 - b^2)/(1 - b^2) with b = sin(pi a/lam), s_c = sin(pi c/lam):
    (MD1) pbar = p* sin^2(pi a/lam) - (2 sigma0/pi) beta, (MD2) the gap at x = c is h0; beta = pi/2 is the
    saturated state (c = lam/2). Derivation, checks and the solution set: docs/models.md.

    Parameters
    ----------
    lam, h : float
        Wavelength and amplitude [length].
    E_star, sigma0 : float
        Composite modulus and Dugdale stress [pressure].
    w : float
        Work of adhesion [energy/area].
    n_quad : int
        Half-size of the tanh-sinh rule for the two integrals.
    """

    def __init__(self, lam, h, E_star, w, sigma0, n_quad=40):
        if min(lam, h, E_star, w, sigma0) <= 0:
            raise ValueError("lam, h, E_star, w and sigma0 must be positive")
        self.lam, self.h, self.E, self.w, self.sigma0 = map(float, (lam, h, E_star, w, sigma0))
        self.h0 = self.w / self.sigma0
        self.pstar = full_contact_pressure(self.lam, self.h, self.E)
        self.alpha = johnson_alpha(self.lam, self.h, self.E, self.w)
        self._nodes = _tanh_sinh(n_quad)

    # geometry ----------------------------------------------------------------
    def cohesive_end(self, a, beta):
        """Outer end c of the Dugdale zone [length]: sin^2(pi c/lam) = b^2 + (1 - b^2) sin^2 beta."""
        b2 = np.sin(np.pi * a / self.lam) ** 2
        return self.lam / np.pi * np.arcsin(np.sqrt(b2 + (1.0 - b2) * np.sin(beta) ** 2))

    def _integrate(self, tb, tc, f):
        d0, d1, wt = self._nodes
        L = tc - tb
        return L * np.sum(wt * f(d0 * L, d1 * L))

    def _J(self, tb, tc, beta):
        if beta >= np.pi / 2 or tc <= tb:
            return 0.0
        tanb = np.tan(beta)
        Y2 = np.sin(tc - tb) * np.sin(tc + tb)

        def f(dlo, dhi):                         # theta = tb + dlo = tc - dhi
            th = tb + dlo
            B = np.sqrt(np.sin(dlo) * np.sin(th + tb))          # sqrt(sin^2 th - b^2)
            Aty = np.cos(th) * tanb
            # |A y - B| = (A^2 y^2 - B^2)/(A y + B), A^2 y^2 - B^2 = (1 + tan^2 b)(s_c^2 - s^2)
            diff = (1.0 + tanb * tanb) * np.sin(dhi) * np.sin(tc + th) / (Aty + B)
            return np.log(Aty + B) - np.log(diff)
        return self._integrate(tb, tc, f) if Y2 > 0 else 0.0

    def gap_at_cohesive_end(self, a, beta):
        """Gap at x = c for a state (a, beta) (condition (MD2) is = h0) [length]."""
        tb = np.pi * a / self.lam
        tc = np.pi * self.cohesive_end(a, beta) / self.lam
        b, sc = np.sin(tb), np.sin(tc)
        Y = np.sqrt(max(np.sin(tc - tb) * np.sin(tc + tb), 0.0))
        hertz = 2.0 * self.h * (sc * Y - (b * b * np.log((sc + Y) / b) if b > 0 else 0.0))
        return hertz + 2.0 * self.sigma0 * self.lam / (np.pi ** 2 * self.E) * self._J(tb, tc, beta)

    # state quantities --------------------------------------------------------
    def mean_pressure(self, a, beta):
        """(MD1): pbar = p* sin^2(pi a/lam) - (2 sigma0/pi) beta [pressure]."""
        return self.pstar * np.sin(np.pi * np.asarray(a) / self.lam) ** 2 - 2.0 * self.sigma0 / np.pi * beta

    def mean_gap(self, a, beta):
        """Mean gap gbar [length] of the state (a, beta) (class doc)."""
        tb = np.pi * a / self.lam
        tc = np.pi * self.cohesive_end(a, beta) / self.lam
        b = np.sin(tb)
        g = float(westergaard_mean_gap(a, self.lam, self.h))
        if beta >= np.pi / 2:
            return g                                # saturated: uniform tension, no deformation
        f = lambda dlo, dhi: np.log(np.sin(tb + dlo) + np.sqrt(np.sin(dlo) * np.sin(2 * tb + dlo)))
        M = self._integrate(tb, tc, f) if tc > tb else 0.0
        lnb = np.log(b) * (tc - tb - beta) if b > 0 else 0.0
        return g + 4.0 * self.sigma0 * self.lam / (np.pi ** 2 * self.E) * (lnb - M)

    def pressure(self, x, a, beta):
        """Surface pressure [pressure] (positive compressive) of the state (a, beta)."""
        th, tb = np.pi * _fold(x, self.lam) / self.lam, np.pi * a / self.lam
        c = self.cohesive_end(a, beta)
        inside = th < tb
        d = np.where(inside, np.sin(tb - th) * np.sin(tb + th), 1.0)
        tanb = np.inf if beta >= np.pi / 2 else np.tan(beta)
        with np.errstate(invalid="ignore"):
            adh = 2.0 * self.sigma0 / np.pi * np.arctan(tanb * np.cos(th) / np.sqrt(d))
        p_in = westergaard_pressure(x, a, self.lam, self.h, self.E) - adh
        cz = th <= np.pi * c / self.lam
        return np.where(inside, p_in, np.where(cz, -self.sigma0, 0.0))

    # solution set ------------------------------------------------------------
    def a_saturation(self):
        """Smallest a [length] with the Westergaard gap at x = lam/2 <= h0 (0 if
        2h <= h0): the saturated states exist for a >= a_saturation."""
        gmax = lambda tb: 2.0 * self.h * (np.cos(tb) - np.sin(tb) ** 2
                                          * np.log((1.0 + np.cos(tb)) / np.sin(tb)))
        if 2.0 * self.h <= self.h0:
            return 0.0
        return self.lam / np.pi * brentq(lambda t: gmax(t) - self.h0, 1e-300, np.pi / 2,
                                         xtol=1e-15, rtol=1e-14)

    def a_of_beta(self, beta):
        """Contact half-width a(beta) [length] of the unsaturated state (MD2); NaN if there is none."""
        F = lambda a: self.gap_at_cohesive_end(a, beta) - self.h0
        if F(0.0) < 0:
            return np.nan
        if F(0.0) == 0:
            return 0.0
        return brentq(F, 0.0, 0.5 * self.lam * (1 - 1e-12), xtol=1e-15 * self.lam, rtol=1e-14)

    def beta_intervals(self, n=400):
        """Intervals [beta_1, beta_2] of beta with an unsaturated state (the gap at a = 0 is >= h0)."""
        F = lambda bt: self.gap_at_cohesive_end(0.0, bt) - self.h0
        grid = _beta_grid(n)
        v = np.array([F(bt) for bt in grid])
        out, start = [], None
        for i, ok in enumerate(v >= 0):
            if ok and start is None:
                start = grid[0] if i == 0 else brentq(F, grid[i - 1], grid[i], xtol=1e-15)
            if not ok and start is not None:
                out.append((start, brentq(F, grid[i - 1], grid[i], xtol=1e-15)))
                start = None
        if start is not None:
            out.append((start, np.pi / 2))
        return out

    def states_at(self, a, n=400):
        """All beta in (0, pi/2] of equilibrium states with half-width a, increasing (pi/2 = saturated)."""
        F = lambda bt: self.gap_at_cohesive_end(a, bt) - self.h0
        grid = _beta_grid(n)
        v = np.array([F(bt) for bt in grid])
        roots = [brentq(F, grid[i], grid[i + 1], xtol=1e-15)
                 for i in range(len(grid) - 1) if v[i] * v[i + 1] < 0]
        if a >= self.a_saturation():
            roots.append(np.pi / 2)
        return np.array(roots)

    def state(self, a, beta):
        """dict with a, beta, c [length], pbar [pressure], gbar [length]."""
        return {"a": a, "beta": beta, "c": self.cohesive_end(a, beta),
                "pbar": float(self.mean_pressure(a, beta)), "gbar": self.mean_gap(a, beta)}

    def curve(self, n=200):
        """The contact solution set: unsaturated branches (sampled in beta), then the saturated branch a in
        [a_saturation, lam/2].

        Returns
        -------
        dict of ndarray
            "a", "c" [length], "beta" [-], "pbar" [pressure], "gbar" [length] and "saturated" (bool).
        """
        rows = []
        for b1, b2 in self.beta_intervals():
            t = 0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, n))
            for bt in b1 + (b2 - b1) * t:
                if bt >= np.pi / 2:
                    continue
                a = self.a_of_beta(bt)
                if np.isfinite(a):
                    rows.append((a, bt, False))
        a_sat = self.a_saturation()
        for a in a_sat + (0.5 * self.lam - a_sat) * np.linspace(0.0, 1.0, n):
            rows.append((a, np.pi / 2, True))
        out = {k: [] for k in ("a", "c", "beta", "pbar", "gbar", "saturated")}
        for a, bt, sat in rows:
            s = self.state(a, bt)
            for k in ("a", "c", "beta", "pbar", "gbar"):
                out[k].append(s[k])
            out["saturated"].append(sat)
        return {k: np.array(v) for k, v in out.items()}

    def _branch_minimum(self, b1, b2, first):
        """Minimum of pbar(a(beta), beta) on [b1, b2): the first local one (first=True) or the smallest."""
        hi = min(b2, np.pi / 2 * (1 - 1e-9))
        f = lambda bt: float(self.mean_pressure(self.a_of_beta(bt), bt))
        grid = b1 + (hi - b1) * (0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, 161)))
        v = np.array([f(bt) for bt in grid])
        i = int(np.argmin(v))
        if first:
            up = np.nonzero(np.diff(v) > 0)[0]
            i = int(up[0]) if up.size else len(v) - 1
        if 0 < i < len(v) - 1:
            res = minimize_scalar(f, bounds=(grid[i - 1], grid[i + 1]), method="bounded",
                                  options={"xatol": 1e-13})
            if res.fun < v[i]:
                return float(res.fun), float(res.x)
        return float(v[i]), float(grid[i])

    def pulloff(self):
        """Load-control pull-off from partial contact, the first local minimum of pbar along the unsaturated
        branch from a = 0 (cf. :func:`jkr_pulloff_load_control`).

        Returns
        -------
        pbar, a, beta : float
            Pressure [pressure], contact half-width [length], beta [-]; NaN if there is no unsaturated branch.
        """
        iv = self.beta_intervals()
        if not iv:
            return np.nan, np.nan, np.nan
        p, bt = self._branch_minimum(*iv[0], first=True)
        return p, self.a_of_beta(bt), bt

    def pulloff_global(self):
        """Minimum mean pressure over all states, the load-control pull-off from full contact: (pbar [pressure],
        a [length], beta); >= -sigma0, = -sigma0 when h0 >= 2h."""
        a_sat = self.a_saturation()
        best = (float(self.mean_pressure(a_sat, np.pi / 2)), a_sat, np.pi / 2)
        for b1, b2 in self.beta_intervals():
            p, bt = self._branch_minimum(b1, b2, first=False)
            if p < best[0]:
                best = (p, self.a_of_beta(bt), bt)
        return best
