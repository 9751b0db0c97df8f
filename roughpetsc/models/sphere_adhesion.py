"""Adhesive contact of an elastic sphere and a flat: JKR, DMT and Maugis-Dugdale.

Reference solutions for adhesive boundary-element runs: a rigid paraboloid ``z = r^2 / (2 R)`` on a half-space
of composite modulus ``E_star`` (1.6), work of adhesion ``w``.

Units: ``a``, ``c``, ``R`` and the approach ``delta`` (positive = interpenetration) [length], ``E_star`` and
``sigma0`` [pressure], ``w`` [energy/area], loads ``P`` [force], positive compressive.

Sources ([JKR], [DMT], [M92], [JG97]) and the Maugis-Dugdale equations in the notation of [M92]/[JG97]
(scales a_s, P_s, d_s; lambda; [M92] (6.17)): docs/models.md.
"""

import numpy as np
from scipy.optimize import minimize_scalar

__all__ = ["maugis_parameter", "md_scales",
           "jkr_load", "jkr_approach", "jkr_contact_radius", "jkr_pressure",
           "jkr_pulloff_load_control", "jkr_pulloff_displacement_control",
           "dmt_load", "dmt_approach", "dmt_pulloff",
           "md_cohesive_ratio", "md_dimensionless", "md_zero_contact",
           "md_pulloff_dimensionless", "md_curve", "md_pressure", "md_pulloff"]


def _K(E_star):
    return 4.0 * E_star / 3.0


# ---------------------------------------------------------------------- JKR
def jkr_load(a, R, E_star, w):
    """JKR load P(a) = 4 E* a^3/(3 R) - sqrt(8 pi w E* a^3) [force], [JKR]."""
    a = np.asarray(a, float)
    return 4.0 * E_star * a ** 3 / (3.0 * R) - np.sqrt(8.0 * np.pi * w * E_star * a ** 3)


def jkr_approach(a, R, E_star, w):
    """JKR approach delta(a) = a^2/R - sqrt(2 pi w a / E*) [length], [JKR]."""
    a = np.asarray(a, float)
    return a ** 2 / R - np.sqrt(2.0 * np.pi * w * a / E_star)


def jkr_contact_radius(P, R, E_star, w):
    """Stable-branch JKR contact radius [length] at load P >= -3/2 pi w R (else NaN), [JKR]:
    a^3 = (R/K) [P + 3 pi w R + sqrt(6 pi w R P + (3 pi w R)^2)]."""
    P = np.asarray(P, float)
    q = 3.0 * np.pi * w * R
    disc = 6.0 * np.pi * w * R * P + q * q
    disc = np.where((disc < 0) & (disc > -1e-12 * q * q), 0.0, disc)    # round-off at pull-off
    with np.errstate(invalid="ignore"):
        a3 = R / _K(E_star) * (P + q + np.sqrt(disc))
    return np.where(disc >= 0, np.cbrt(a3), np.nan)


def jkr_pressure(r, a, R, E_star, w):
    """JKR contact pressure [pressure] for r < a (0 outside): Hertz (2 E* a/(pi R)) sqrt(1 - r^2/a^2) minus the
    flat-punch term sqrt(2 E* w/(pi a)) / sqrt(1 - r^2/a^2)."""
    r = np.asarray(r, float)
    inside = np.abs(r) < a
    s = np.sqrt(np.where(inside, 1.0 - (r / a) ** 2, 1.0))
    p = 2.0 * E_star * a / (np.pi * R) * s - np.sqrt(2.0 * E_star * w / (np.pi * a)) / s
    return np.where(inside, p, 0.0)


def jkr_pulloff_load_control(R, E_star, w):
    """Load-control pull-off of JKR, the minimum of P(a): P = -3/2 pi w R at a^3 = 9 pi w R^2 / (8 E*) [JKR],
    returned as (P, a, delta)."""
    a = np.cbrt(9.0 * np.pi * w * R ** 2 / (8.0 * E_star))
    return -1.5 * np.pi * w * R, a, float(jkr_approach(a, R, E_star, w))


def jkr_pulloff_displacement_control(R, E_star, w):
    """Displacement-control separation point of JKR, the minimum of delta(a), as (P, a, delta):
    a^3 = pi w R^2 / (8 E*), P = -5/6 pi w R, delta = -(3/4) (pi^2 w^2 R / E*^2)^(1/3)."""
    a = np.cbrt(np.pi * w * R ** 2 / (8.0 * E_star))
    return -5.0 / 6.0 * np.pi * w * R, a, -0.75 * np.cbrt(np.pi ** 2 * w ** 2 * R / E_star ** 2)


# ---------------------------------------------------------------------- DMT
def dmt_load(a, R, E_star, w):
    """DMT load P = 4 E* a^3/(3 R) - 2 pi w R [force], [DMT]."""
    return 4.0 * E_star * np.asarray(a, float) ** 3 / (3.0 * R) - 2.0 * np.pi * w * R


def dmt_approach(a, R):
    """DMT approach = Hertz approach a^2/R [length]."""
    return np.asarray(a, float) ** 2 / R


def dmt_pulloff(R, w):
    """DMT pull-off load -2 pi w R [force] (at a = 0)."""
    return -2.0 * np.pi * w * R


# ----------------------------------------------------------- Maugis-Dugdale
def maugis_parameter(R, E_star, w, sigma0):
    """Maugis' transition parameter lambda = 2 sigma0 (R/(pi w K^2))^(1/3), K = 4E*/3 [-]; [M92], [JG97]."""
    return 2.0 * sigma0 * np.cbrt(R / (np.pi * w * _K(E_star) ** 2))


def md_scales(R, E_star, w):
    """Maugis' units of A, Pbar, Delta: a_s = (pi w R^2/K)^(1/3), P_s = pi w R, d_s = (pi^2 w^2 R/K^2)^(1/3)."""
    K = _K(E_star)
    return (np.cbrt(np.pi * w * R ** 2 / K), np.pi * w * R,
            np.cbrt(np.pi ** 2 * w ** 2 * R / K ** 2))


def _t1(mu):
    """mu + (mu^2 - 1) arctan mu (= mu + (m^2 - 2) arctan mu), cancellation-free."""
    mu = np.asarray(mu, float)
    small = mu < 0.1
    ms = np.where(small, mu, 0.0)
    series = sum((-1) ** (k + 1) * 4.0 * k / (4.0 * k * k - 1) * ms ** (2 * k + 1)
                 for k in range(1, 10))
    return np.where(small, series, mu + (mu * mu - 1.0) * np.arctan(mu))


def _t2(mu):
    """mu arctan mu - m + 1 with m = sqrt(1 + mu^2)."""
    mu = np.asarray(mu, float)
    return mu * np.arctan(mu) - mu * mu / (1.0 + np.sqrt(1.0 + mu * mu))


def _md_residual(mu, A, lam):
    """Left side minus right side of [M92] (6.17); increasing in mu, -1 at mu = 0."""
    return 0.5 * lam * A * A * _t1(mu) + 4.0 / 3.0 * lam * lam * A * _t2(mu) - 1.0


def _solve_mu(A, lam):
    """mu = sqrt(m^2 - 1) > 0 of [M92] (6.17), vectorised bisection in ln mu."""
    A = np.asarray(A, float)
    if np.any(A <= 0):
        raise ValueError("A must be positive (see md_zero_contact for A -> 0)")
    lo = np.full(A.shape, np.log(1e-30))
    hi = np.zeros(A.shape)
    while True:
        bad = _md_residual(np.exp(hi), A, lam) < 0
        if not bad.any():
            break
        hi = np.where(bad, hi + 2.0, hi)
    for _ in range(120):
        mid = 0.5 * (lo + hi)
        neg = _md_residual(np.exp(mid), A, lam) < 0
        lo, hi = np.where(neg, mid, lo), np.where(neg, hi, mid)
    return np.exp(0.5 * (lo + hi))


def md_cohesive_ratio(A, lam):
    """m = c/a >= 1 solving Maugis' equation [M92] (6.17) for A > 0 and lambda > 0 (unique root)."""
    mu = _solve_mu(np.atleast_1d(np.asarray(A, float)), lam)
    return np.sqrt(1.0 + mu * mu)


def md_dimensionless(A, lam):
    """Maugis-Dugdale curve (Pbar, Delta, m = c/a) in Maugis' units (:func:`md_scales`) at A > 0 [M92]/[JG97]."""
    A = np.atleast_1d(np.asarray(A, float))
    mu = _solve_mu(A, lam)
    m = np.sqrt(1.0 + mu * mu)
    P = A ** 3 - lam * A * A * (mu + m * m * np.arctan(mu))
    D = A * A - 4.0 / 3.0 * lam * A * mu
    return P, D, m


def md_zero_contact(lam):
    """Limit A -> 0 of the Maugis-Dugdale curve, Dugdale zone of radius C = A m: (Pbar, Delta, C).

    [M92] (6.17) for m -> inf: (pi lambda/4) C^2 + (4 lambda^2/3)(pi/2 - 1) C = 1, Pbar -> -(pi lambda/2) C^2,
    Delta -> -(4/3) lambda C.
    """
    qa, qb = np.pi * lam / 4.0, 4.0 * lam * lam / 3.0 * (np.pi / 2.0 - 1.0)
    C = 2.0 / (qb + np.sqrt(qb * qb + 4.0 * qa))
    return -np.pi * lam / 2.0 * C * C, -4.0 / 3.0 * lam * C, C


def md_pulloff_dimensionless(lam, A_max=4.0, n=400):
    """Load-control pull-off (Pbar_c, A_c): the minimum over the Maugis-Dugdale curve for A in (0, A_max] and its
    A -> 0 end (A_c = 0); from -2 (DMT, lambda -> 0) to -3/2 (JKR, lambda -> inf)."""
    A = np.geomspace(1e-4, A_max, n)
    P = md_dimensionless(A, lam)[0]
    P0 = md_zero_contact(lam)[0]
    i = int(np.argmin(P))
    best = (P0, 0.0)
    if 0 < i < n - 1:
        f = lambda x: md_dimensionless(np.exp(x), lam)[0][0]
        res = minimize_scalar(f, bounds=(np.log(A[i - 1]), np.log(A[i + 1])), method="bounded",
                              options={"xatol": 1e-10})
        if res.fun < P0:
            best = (float(res.fun), float(np.exp(res.x)))
    elif P[i] < P0:
        best = (float(P[i]), float(A[i]))
    return best


def md_curve(a, R, E_star, w, sigma0):
    """Maugis-Dugdale load, approach and Dugdale-zone radius at contact radius a.

    Parameters
    ----------
    a : array_like
        Contact radius [length], > 0.
    R, E_star, w, sigma0 : float
        Sphere radius [length], composite modulus [pressure], work of adhesion [energy/area], Dugdale stress
        [pressure] (range h0 = w/sigma0).

    Returns
    -------
    P, delta, c : ndarray
        Load [force], approach and Dugdale-zone radius [length].
    """
    lam = maugis_parameter(R, E_star, w, sigma0)
    a_s, P_s, d_s = md_scales(R, E_star, w)
    a = np.atleast_1d(np.asarray(a, float))
    P, D, m = md_dimensionless(a / a_s, lam)
    return P * P_s, D * d_s, m * a


def md_pressure(r, a, c, R, E_star, sigma0):
    """Maugis-Dugdale surface pressure [pressure] at radius r for the radii a, c of :func:`md_curve` [M92]:
    Hertz(a) - (2 sigma0/pi) arctan sqrt((c^2 - a^2)/(a^2 - r^2)) in r < a, -sigma0 in a < r < c, 0 beyond."""
    r = np.abs(np.asarray(r, float))
    inside = r < a
    d = np.where(inside, a * a - r * r, 1.0)
    p_in = (2.0 * E_star / (np.pi * R) * np.sqrt(d)
            - 2.0 * sigma0 / np.pi * np.arctan(np.sqrt((c * c - a * a) / d)))
    return np.where(inside, p_in, np.where(r <= c, -sigma0, 0.0))


def md_pulloff(R, E_star, w, sigma0):
    """Load-control pull-off load of the Maugis-Dugdale model [force], between -2 pi w R and -3/2 pi w R."""
    lam = maugis_parameter(R, E_star, w, sigma0)
    return np.pi * w * R * md_pulloff_dimensionless(lam)[0]
