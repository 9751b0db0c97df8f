"""Penny-shaped adhesive crack and the adhesive adapted GW model (the dissertation, chapter 6).

Dimensionless groups of Eqs. (6.4)-(6.6): ``p* = p0 / P``, ``b* = b / L``,
``m = c / b``, ``G* = G / w``, ``A* = A / L^2``, ``V* = V / (3 w / (2 kappa))``,
``sigma0* = sigma0 / P`` with ``P = (pi^2 E*^2 w^2 kappa / 72)^(1/5)`` and
``L = (81 pi E* w / (16 kappa^2))^(1/5)``.

The Maugis-Dugdale solution set as one curve in m, the closed-form trapped volume and the JKR limit
(:class:`JKRCrack`, ``AdhesiveGW(..., crack_law="jkr")``): docs/models.md.
"""

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from . import pdfs
from .quadrature import gauss_legendre, semi_infinite

__all__ = ["jkr_pstar", "jkr_pmin", "jkr_radius", "jkr_G", "jkr_volume",
           "nonadhesive_radius", "nonadhesive_area", "nonadhesive_volume",
           "AdhesiveCrack", "JKRCrack", "AdhesiveGW", "CRACK_LAWS"]


# --------------------------------------------------------------------- limits
def nonadhesive_radius(p):
    """b* = sqrt(2 p* / 3), Eq. (6.8)."""
    return np.sqrt(2.0 * np.maximum(np.asarray(p, float), 0.0) / 3.0)


def nonadhesive_area(p):
    """A* = 2 pi p* / 3, Eq. (6.9)."""
    return 2.0 * np.pi / 3.0 * np.maximum(np.asarray(p, float), 0.0)


def nonadhesive_volume(p):
    """V* = (8 sqrt 6 / 45) pi p*^(5/2): (5.28) in the groups (6.4)-(6.5) (the printed (6.10) is sqrt 2 larger)."""
    return 8.0 * np.sqrt(6.0) / 45.0 * np.pi * np.maximum(np.asarray(p, float), 0.0) ** 2.5


def jkr_pstar(b):
    """JKR-limit load of a crack of radius b*, Eq. (6.14)."""
    b = np.asarray(b, float)
    return 1.5 * b ** 2 + np.sqrt(2.0 / b)


def jkr_pmin():
    """Minimum p* of the JKR limit, Eq. (6.15) (about 2.3602)."""
    r = np.sqrt(2.0) / 6.0
    return 1.5 * r ** 0.8 + np.sqrt(2.0) * r ** -0.2


def jkr_radius(p, branch="stable"):
    """Crack radius b* of the JKR limit at p*: the larger root (6.17) of (6.14) for ``branch="stable"``, else the
    smaller; NaN below p*_min."""
    p = np.atleast_1d(np.asarray(p, float))
    bmin = (np.sqrt(2.0) / 6.0) ** 0.4           # argmin of (6.14)
    out = np.full(p.shape, np.nan)
    for i, pi in enumerate(p):
        if pi < jkr_pmin():
            continue
        f = lambda b: jkr_pstar(b) - pi
        if branch == "stable":
            hi = max(2 * bmin, np.sqrt(pi))
            out[i] = bmin if f(bmin) >= 0 else brentq(f, bmin, hi, xtol=1e-15, rtol=1e-15)
        else:
            out[i] = bmin if f(bmin) >= 0 else brentq(f, min(1e-12, 2.0 / pi ** 2), bmin,
                                                      xtol=1e-16, rtol=1e-15)
    return out


def jkr_G(b, p):
    """Energy release rate G* of the JKR limit, Eq. (6.16)."""
    return b / 8.0 * (2.0 * p - 3.0 * b ** 2) ** 2


def jkr_volume(b, p):
    """Trapped volume V* of the JKR limit, Eq. (6.21)."""
    return 2.0 * np.pi * b ** 3 * (p - 0.9 * b ** 2)


class JKRCrack:
    """Penny-shaped adhesive crack in the JKR limit, Eqs. (6.11)-(6.21), with its load history.

    The limit sigma0* -> inf of :class:`AdhesiveCrack` at a fixed w (docs/models.md), with its interface, m = 1
    and ``sigma = inf``; ``points`` holds only B, the snap-in point (6.15).
    """

    sigma = np.inf

    def __init__(self):
        b_min = (np.sqrt(2.0) / 6.0) ** 0.4                                   # d p*/d b* = 0 in (6.14)
        self.points = {"B": (float(jkr_pmin()), float(b_min), 1.0)}

    def breakpoints(self):
        """The p* at which a crack's state changes with its history: B only."""
        return [self.points["B"][0]]

    def stable(self, p):
        """b* on the stable branch (6.17) of (6.14) at p* >= p*_min (NaN below).

        The larger root of 3/2 t^5 - p t + sqrt 2 = 0 (t = sqrt b*) by Newton's method from t = (2 p / 3)^(1/4):
        the polynomial is convex there, so the iterates decrease monotonically to the root.
        """
        p = np.atleast_1d(np.asarray(p, float))
        ok = p >= self.points["B"][0]
        pp = np.where(ok, p, self.points["B"][0])
        t = (pp / 1.5) ** 0.25
        for _ in range(200):
            f = 1.5 * t ** 5 - pp * t + np.sqrt(2.0)
            slope = 7.5 * t ** 4 - pp
            step = np.where(f > 0, f / np.where(slope > 0, slope, np.inf), 0.0)
            t = t - step
            if np.all(step <= 1e-15 * t):
                break
        return np.where(ok, t * t, np.nan)

    def state(self, p, p_min=None):
        """Crack radius and m (= 1) after a load history, as :meth:`AdhesiveCrack.state`; a crack that closed
        (below p*_B) stays closed, its reopening point E (6.38) is at infinity."""
        p = np.atleast_1d(np.asarray(p, float))
        pm = p if p_min is None else np.minimum(np.atleast_1d(np.asarray(p_min, float)), p)
        b = np.where(pm >= self.points["B"][0], self.stable(np.maximum(p, self.points["B"][0])), 0.0)
        return b, np.ones_like(b)

    def area(self, b):
        """A* = pi b*^2, Eq. (6.18)."""
        return np.pi * np.asarray(b) ** 2

    def volume(self, p, b, m=None):
        """Trapped volume V*, Eq. (6.21) (0 for a closed crack)."""
        return jkr_volume(b, p)


# ------------------------------------------------------------ Maugis-Dugdale
class AdhesiveCrack:
    """Maugis-Dugdale penny-shaped adhesive crack for one sigma0* (6.22)-(6.39); ``points``: B, C, E, F, G ->
    (p*, b*, m) of Figs. 6.2-6.3."""

    Q_MAX = 60.0          # m = 1 - exp(-q), q in [0, Q_MAX]

    def __init__(self, sigma0):
        if not sigma0 > 0:
            raise ValueError("sigma0* must be positive")
        self.sigma = float(sigma0)
        q = np.linspace(0.0, self.Q_MAX, 6001)
        p = self.p_of_q(q)
        i = int(np.argmin(p))
        if i == 0:
            qB = 0.0
        else:
            lo, hi = q[max(i - 1, 0)], q[min(i + 1, q.size - 1)]
            qB = minimize_scalar(self.p_of_q, bounds=(lo, hi), method="bounded",
                                 options={"xatol": 1e-13}).x
        self.qB = qB
        q_table = qB + (self.Q_MAX - qB) * np.linspace(0.0, 1.0, 2001) ** 2     # p*(q) on the stable branch
        self._table = (q_table, self.p_of_q(q_table))
        s = self.sigma
        pB, bB, mB = self.p_of_q(qB), self.b_of_q(qB), self.m_of_q(qB)
        pF, bF = s + 1.5 * s ** (-2.0 / 3.0), s ** (-1.0 / 3.0)            # (6.39)
        bC = 0.0 if pB <= s else float(nonadhesive_radius(pB - s))         # closure or (6.36)
        qG = self._stable_q(np.array([pF]))[0]
        self.points = {"B": (pB, bB, mB), "C": (pB, bC, 0.0), "E": (s, 0.0, 0.0),
                       "F": (pF, bF, 0.0), "G": (pF, self.b_of_q(qG), self.m_of_q(qG))}

    def breakpoints(self):
        """The p* at which the state of a crack changes with its history: B, E (6.38) and F (6.39)."""
        return sorted({self.points["B"][0], self.sigma, self.points["F"][0]})

    # curve parametrisation --------------------------------------------------
    @staticmethod
    def m_of_q(q):
        return -np.expm1(-np.asarray(q, float))

    def b_of_q(self, q):
        """Unique positive root b*(m) of s^3 b^3 + sigma m (1-m) b - 1/sigma = 0."""
        m = self.m_of_q(q)
        s3 = (1.0 - m * m) ** 1.5
        P = self.sigma * m * np.exp(-np.asarray(q, float))       # sigma m (1 - m)
        Q = 1.0 / self.sigma
        with np.errstate(divide="ignore"):
            b = np.minimum(np.cbrt(Q / s3), np.where(P > 0, Q / np.where(P > 0, P, 1), np.inf))
        for _ in range(200):                                     # monotone Newton from above
            f = s3 * b ** 3 + P * b - Q
            step = f / (3 * s3 * b ** 2 + P)
            b = b - step
            if np.all(np.abs(step) <= 1e-15 * b):
                break
        return b

    def p_of_q(self, q):
        m = self.m_of_q(q)
        return 1.5 * self.b_of_q(q) ** 2 + self.sigma * np.sqrt(1.0 - m * m)

    def _stable_q(self, p):
        """q on the stable branch (q >= qB) with p*(q) = p: a bracket from the table of p*(q), then the Illinois
        regula falsi (safe at B, where the slope vanishes)."""
        q_table, p_table = self._table
        i = np.clip(np.searchsorted(p_table, p), 1, q_table.size - 1)
        lo, hi = q_table[i - 1], q_table[i]
        f_lo, f_hi = p_table[i - 1] - p, p_table[i] - p
        side = np.zeros(p.shape)
        q = lo
        for _ in range(100):
            with np.errstate(invalid="ignore", divide="ignore"):
                q = np.where(f_hi != f_lo, (lo * f_hi - hi * f_lo) / (f_hi - f_lo), 0.5 * (lo + hi))
            q = np.clip(q, lo, hi)
            f = self.p_of_q(q) - p
            below = f < 0
            # Illinois: halve the value kept at the end that stays, after it stayed twice
            f_hi = np.where(below, np.where(side < 0, 0.5 * f_hi, f_hi), f)
            f_lo = np.where(below, f, np.where(side > 0, 0.5 * f_lo, f_lo))
            lo, hi = np.where(below, q, lo), np.where(below, hi, q)
            side = np.where(below, -1.0, 1.0)
            if np.all((np.abs(f) <= 1e-15 * np.abs(p)) | (hi - lo <= 4e-16 * hi)):
                break
        return q

    def curve(self, n=2001, q_max=12.0):
        """The Maugis-Dugdale solution curve (p*, b*, m) from F (m = 0) towards A, q in [0, q_max]."""
        q = np.linspace(0.0, q_max, n)
        return self.p_of_q(q), self.b_of_q(q), self.m_of_q(q)

    def solution_set(self, n=4001, q_max=12.0):
        """Every equilibrium state (p*, b*, m, V*): the full-adhesion branch (6.36) from E (6.38) to F (``n // 4``
        states), then :meth:`curve` from F towards A (``n``)."""
        p_full = np.linspace(self.sigma, self.points["F"][0], n // 4)
        p_md, b_md, m_md = self.curve(n, q_max)
        p = np.concatenate([p_full, p_md])
        b = np.concatenate([nonadhesive_radius(p_full - self.sigma), b_md])
        m = np.concatenate([np.zeros_like(p_full), m_md])
        return p, b, m, self.volume(p, b, m)

    # equilibrium quantities -----------------------------------------------------
    def stable(self, p):
        """(b*, m) on the stable Maugis-Dugdale branch at p* >= p*_B (NaN below)."""
        p = np.atleast_1d(np.asarray(p, float))
        q = self._stable_q(p)
        ok = p >= self.points["B"][0]
        return np.where(ok, self.b_of_q(q), np.nan), np.where(ok, self.m_of_q(q), np.nan)

    def state(self, p, p_min=None):
        """Crack radius and m after a load history (Figs. 6.2-6.3).

        Parameters
        ----------
        p : array_like
            Current p* [-].
        p_min : array_like, optional
            Smallest p* reached so far [-] (default ``p``: loading). Loading: stable branch down to B, then closure
            (p_B <= sigma0*) or full adhesion (6.36) down to E. Unloading after ``p_min < p_B``: closed below E
            (6.38), full adhesion from E to F (6.39), jump to G.

        Returns
        -------
        b, m : ndarray
            Crack radius and m [-].
        """
        p = np.atleast_1d(np.asarray(p, float))
        pm = p if p_min is None else np.minimum(np.atleast_1d(np.asarray(p_min, float)), p)
        pB, pF, s = self.points["B"][0], self.points["F"][0], self.sigma
        b_md, m_md = self.stable(np.maximum(p, pB))
        reversible = (pm >= pB) | (p >= pF)
        full = (~reversible) & (p >= s)
        b = np.where(reversible, b_md, np.where(full, nonadhesive_radius(p - s), 0.0))
        m = np.where(reversible, m_md, 0.0)
        return b, m

    def area(self, b):
        """A* = pi b*^2, Eq. (6.18)."""
        return np.pi * np.asarray(b) ** 2

    def volume(self, p, b, m):
        """Trapped volume V* of (6.24) integrated in closed form (docs/models.md)."""
        return 2.0 * np.pi * b ** 3 * (p - 0.9 * b ** 2 - self.sigma * (1.0 - m * m) ** 1.5)

    def G(self, p, b, m):
        """Energy release rate G*, Eq. (6.30)."""
        s = np.sqrt(1.0 - m * m)
        return (self.sigma * (p * s - (1 - m) * self.sigma) * b
                - 0.5 * self.sigma * s * (2 * m * m + 1) * b ** 3)

    def dG_db(self, p, b, m):
        """Fixed-load derivative dG*/db*, Eqs. (6.31)-(6.32); <= 0 means stable."""
        sg = self.sigma
        s = np.sqrt(1.0 - m * m)
        dm = 3 * b / (m * sg ** 2) * (p - 1.5 * b ** 2)
        return (sg * (p * s - (1 - m) * sg) + sg * b * (sg - p * m / s) * dm
                - 1.5 * sg * s * (2 * m * m + 1) * b ** 2
                + 0.5 * sg * m / s * dm * (2 * m * m + 1) * b ** 3
                - 2 * sg * m * s * b ** 3 * dm)


# -------------------------------------------------------- adhesive GW model
CRACK_LAWS = ("maugis-dugdale", "jkr")


class AdhesiveGW:
    """Adhesive adapted GW model of nearly complete contact, Eqs. (6.40)-(6.54), in p* = pbar/sqrt(m0^p),
    g* = gbar/sqrt(m0^h).

    Parameters
    ----------
    m0h, m2h, m4h, m6h : float
        Spectral moments of the surface [length^2], [-], [1/length^2], [1/length^4].
    sigma0_over_E : float
        Dugdale stress over E* [-].
    z0 : float
        Range of adhesion [length]; the surface energy is w = sigma0 z0 (the convention of (6.56)).
    n_elements : int
        Gauss-Legendre elements per interval between the crack's breakpoints and on the tail.
    crack_law : {"maugis-dugdale", "jkr"}
        :class:`AdhesiveCrack` at the sigma0* of (6.6), or :class:`JKRCrack` ("JKR limit" of Figs. 6.9-6.10).
    """

    XI_CUT = 12.0   # the summit-height density (2.42) is below exp(-C1 xi^2) <= exp(-72) beyond xi* = 12

    def __init__(self, m0h, m2h, m4h, m6h, sigma0_over_E, z0, n_elements=16, crack_law="maugis-dugdale"):
        if min(m0h, m2h, m4h, m6h, sigma0_over_E, z0) <= 0:
            raise ValueError("moments, sigma0/E* and z0 must be positive")
        if crack_law not in CRACK_LAWS:
            raise ValueError(f"crack_law is one of {', '.join(CRACK_LAWS)}, got {crack_law!r}")
        self.m0h = m0h
        self.m0p, self.m2p, self.m4p = m2h / 2.0, m4h / 3.0, 0.3 * m6h        # (2.53), over E*^2
        self.alpha_p = self.m0p * self.m4p / self.m2p ** 2                    # (2.54)
        pdfs.c1(self.alpha_p)
        w = sigma0_over_E * z0                                                # E* = 1 units
        self.kappa = 8.0 / 3.0 * np.sqrt(self.m4p / np.pi)                     # (6.43)
        self.eta = self.m4p / (6.0 * np.sqrt(3.0) * np.pi * self.m2p)          # (6.42)
        Pscale = (np.pi ** 2 * w ** 2 * self.kappa / 72.0) ** 0.2             # (6.4)
        Lscale = (81.0 * np.pi * w / (16.0 * self.kappa ** 2)) ** 0.2
        self.sigma_star = sigma0_over_E / Pscale                              # (6.6)
        self.C = np.sqrt(self.m0p) / Pscale                                   # (6.45)
        self.C1 = self.eta * Lscale ** 2                                      # (6.48)
        self.C2 = self.eta / np.sqrt(m0h) * 1.5 * w / self.kappa              # (6.49)
        self.crack = AdhesiveCrack(self.sigma_star) if crack_law == "maugis-dugdale" else JKRCrack()
        self.n_elements = n_elements

    def _integrate(self, pbar, pbar_max):
        """1 - A* and g* at pbar after a loading history that reached pbar_max >= pbar."""
        c = self.crack
        breaks = c.breakpoints()
        shift = pbar - pbar_max            # local p* = (xi - pbar) C, its history minimum p + shift C
        # Breakpoints beyond the summit heights that carry weight are dropped: a far one (E and F recede
        # as sigma0* grows) would stretch the elements of the last interval over the whole density.
        cut = (max(pbar, 0.0) + self.XI_CUT) * self.C
        edges = [0.0] + [bk for bk in breaks if bk > 0] + \
                [bk - shift * self.C for bk in breaks if bk - shift * self.C > 0] + [cut]
        edges = np.unique(np.array([e for e in edges if e <= cut]))
        nodes, weights = [], []
        for a, b in zip(edges[:-1], edges[1:]):
            # p = a + (b - a) u^2: the radius grows as sqrt(p - a) from B (6.15) and from E (6.36), and
            # the map makes such a start smooth in u.
            u, w = gauss_legendre(self.n_elements, 8, 0.0, 1.0)
            nodes.append(a + (b - a) * u * u)
            weights.append(2.0 * (b - a) * u * w)
        t, w = semi_infinite(self.n_elements, 8, scale=self.C, power=2)
        nodes.append(edges[-1] + t)
        weights.append(w)
        pl = np.concatenate(nodes)
        wl = np.concatenate(weights) / self.C        # d xi = d p / C
        b, m = c.state(pl, np.maximum(pl + shift * self.C, 0.0))
        phi = pdfs.phi_xi(pbar + pl / self.C, self.alpha_p)
        one_minus_A = self.C1 * np.sum(wl * c.area(b) * phi)                   # (6.46)
        g = self.C2 * np.sum(wl * c.volume(pl, b, m) * phi)                    # (6.47)
        return one_minus_A, g

    def loading(self, pstar):
        """(A*, g*) along a monotone loading path, Eqs. (6.50)-(6.51)."""
        p = np.atleast_1d(np.asarray(pstar, float))
        out = np.array([self._integrate(pi, pi) for pi in p])
        return 1.0 - out[:, 0], out[:, 1]

    def unloading(self, pstar, pstar_max):
        """(A*, g*) when unloading from pstar_max down to pstar, Eqs. (6.53)-(6.54)."""
        p = np.atleast_1d(np.asarray(pstar, float))
        if np.any(p > pstar_max):
            raise ValueError("unloading p* must not exceed pstar_max")
        out = np.array([self._integrate(pi, pstar_max) for pi in p])
        return 1.0 - out[:, 0], out[:, 1]

    def dissipated_energy(self, pstar_max, pstar_min=0.0, n_elements=24):
        """Area between the loading and unloading g*(p*) curves over [pstar_min, pstar_max] (Fig. 6.11(b)): the
        energy per unit area dissipated in the cycle, over sqrt(m0^p) sqrt(m0^h)."""
        if not pstar_max > pstar_min:
            raise ValueError("pstar_max must exceed pstar_min")
        p, w = gauss_legendre(n_elements, 8, pstar_min, pstar_max)
        return float(np.sum(w * (self.loading(p)[1] - self.unloading(p, pstar_max)[1])))
