"""Complete-contact curve fit of A*(p*) (the dissertation, 8.5, Eqs. (8.2)-(8.3), Table 8.4).

A*(p*) = I(p*) f(p*) for p* <= 2 and I(p*) beyond, I the A* of a nearly-complete-contact model (by default the
adapted GW model (5.37) with (2.42), which reproduces Table 8.4; errata: docs/conventions.md), f(p*) = a exp(b p*)
+ c exp(d p*) with a = -c (A*(0) = 0) and c = 1 / (exp(2 d) - exp(2 b)) (continuity at p* = 2). Holding the slope
at p* = 0 at the asymptotic BGT model's sqrt(pi/2) fixes d for each b (``slope=`` of :func:`fit_curvefit`).
"""

import numpy as np
from scipy.optimize import brentq, least_squares

from .complete import COMPLETE_MODELS, complete

__all__ = ["TABLE_8_4", "ALPHA_P_TABLE_8_3", "BGT_SLOPE", "CURVEFIT_MODEL", "correction", "curvefit_reference",
           "curvefit_area", "curvefit_slope_at_zero", "fit_curvefit", "bootstrap_curvefit"]

#: Table 8.4: group -> (b, c, d); a = -c.
TABLE_8_4 = {18: (-1.923, 1.160, -0.062), 19: (-1.924, 1.150, -0.058),
             20: (-1.931, 1.138, -0.053), 21: (-1.943, 1.123, -0.047),
             22: (-1.959, 1.108, -0.040), 23: (-1.870, 1.169, -0.065),
             24: (-1.863, 1.156, -0.059), 25: (-1.873, 1.133, -0.049),
             26: (-1.897, 1.103, -0.037), 27: (-1.949, 1.065, -0.021)}
#: Table 8.3, "Num" column: alpha^p of the generated groups.
ALPHA_P_TABLE_8_3 = {18: 2.00, 19: 2.08, 20: 2.17, 21: 2.27, 22: 2.38,
                     23: 2.10, 24: 2.25, 25: 2.46, 26: 2.73, 27: 3.10}
#: The default I(p*) of (8.2): the adapted GW model of nearly complete contact (5.37) with the PDF (2.42).
CURVEFIT_MODEL = "gw"

P_SPLIT = 2.0
#: dA*/dp* of the asymptotic BGT model at p* -> 0 (section 8.5).
BGT_SLOPE = float(np.sqrt(np.pi / 2))


def correction(pstar, b, c, d):
    """f(p*) = c (exp(d p*) - exp(b p*)), Eq. (8.3) with a = -c."""
    p = np.asarray(pstar, dtype=float)
    return c * (np.exp(d * p) - np.exp(b * p))


def curvefit_reference(pstar, alpha_p, model=CURVEFIT_MODEL):
    """I(p*) of (8.2): the contact ratio of a nearly-complete-contact model.

    Parameters
    ----------
    pstar, alpha_p : array_like, float
        p* = pbar / sqrt(m0^p) >= 0 [-] and the bandwidth of the pressure surface (2.54), > 3/2.
    model : str or callable
        A name of :data:`~roughpetsc.models.complete.COMPLETE_MODELS` ("gw" (5.37), "nayak_bush" (5.41),
        "greenwood" (5.45), "ciavarella" (5.54)) or a function of p* returning A*.

    Returns
    -------
    ndarray
        I(p*) = A* of the model [-].
    """
    p = np.atleast_1d(np.asarray(pstar, dtype=float))
    if callable(model):
        return np.asarray(model(p), dtype=float)
    if model not in COMPLETE_MODELS:
        raise ValueError("unknown curve-fit model %r; choose from %s" % (model, ", ".join(COMPLETE_MODELS)))
    return complete(model, p, alpha_p, alpha_p)[0]


def curvefit_area(pstar, alpha_p, b, c, d, model=CURVEFIT_MODEL):
    """Curve-fit contact ratio A*(p*), Eq. (8.2).

    Parameters
    ----------
    pstar, alpha_p : array_like, float
        As in :func:`curvefit_reference`.
    b, c, d : float
        Parameters of (8.3) (Table 8.4), a = -c.
    model : str or callable
        I(p*) (:func:`curvefit_reference`); the default, (5.37) with (2.42), is the one of Table 8.4.

    Returns
    -------
    ndarray
        A* [-].
    """
    p = np.atleast_1d(np.asarray(pstar, dtype=float))
    I = curvefit_reference(p, alpha_p, model)
    return np.where(p <= P_SPLIT, I * correction(p, b, c, d), I)


def curvefit_slope_at_zero(alpha_p, b, c, d, model=CURVEFIT_MODEL):
    """dA*/dp* of the curve fit (8.2)-(8.3) at p* = 0: I(0) c (d - b) (section 8.5: close to :data:`BGT_SLOPE`).

    Parameters
    ----------
    alpha_p, b, c, d, model :
        As in :func:`curvefit_area`.

    Returns
    -------
    float
        The slope [-].
    """
    return float(curvefit_reference(np.zeros(1), alpha_p, model)[0]) * c * (d - b)


def _continuity_c(b, d):
    """c of (8.3) with a = -c and f(2) = 1."""
    return 1.0 / (np.exp(P_SPLIT * d) - np.exp(P_SPLIT * b))


def _d_for_slope(b, slope, I0):
    """The d != b at which the fit's slope at p* = 0, I(0) c (d - b), equals ``slope`` (one root for every b)."""
    target = slope / I0

    def excess(d):
        return (d - b) / np.expm1(P_SPLIT * (d - b)) * np.exp(-P_SPLIT * b) - target

    limit = np.exp(-P_SPLIT * b) / P_SPLIT  # the value at d = b
    if abs(limit - target) < 1e-14 * target:
        return b + 1e-9
    if limit > target:  # the root lies above b, where the excess falls to -target
        step = 1.0
        while excess(b + step) > 0:
            step *= 2
        return brentq(excess, b + 1e-12, b + step, xtol=1e-14)
    step = 1.0  # the root lies below b, where the excess grows like |d - b| exp(-2b)
    while excess(b - step) < 0:
        step *= 2
    return brentq(excess, b - step, b - 1e-12, xtol=1e-14)


def fit_curvefit(pstar, area, alpha_p, guess=(-1.9, -0.05), slope=None, model=CURVEFIT_MODEL):
    """Fit b, c, d of (8.2)-(8.3) to a curve A*(p*) (e.g. a BEM ensemble mean).

    Parameters
    ----------
    pstar, area : array_like
        The curve: p* and A* [-] at the same points.
    alpha_p, model :
        As in :func:`curvefit_area`.
    guess : (b, d)
        Start of the least squares.
    slope : float, optional
        dA*/dp* at p* = 0 to hold (e.g. :data:`BGT_SLOPE`): d follows from b, and b alone is fitted.

    Returns
    -------
    b, c, d : float
        a = -c, c from continuity at p* = 2; b and d by least squares over p* <= 2, d the larger exponent.
    """
    p = np.asarray(pstar, dtype=float)
    A = np.asarray(area, dtype=float)
    sel = (p <= P_SPLIT) & np.isfinite(A)
    if sel.sum() < 3:
        raise ValueError("need at least three points with p* <= 2 to fit b and d")
    p, A = p[sel], A[sel]
    I = curvefit_reference(p, alpha_p, model)
    if slope is None:
        def exponents(x):
            return x[0], x[1]
        start = np.asarray(guess, float)
    else:
        I0 = float(curvefit_reference(np.zeros(1), alpha_p, model)[0])

        def exponents(x):
            return x[0], _d_for_slope(x[0], slope, I0)
        start = np.asarray(guess[:1], float)

    def residual(x):
        b, d = exponents(x)
        return I * correction(p, b, _continuity_c(b, d), d) - A

    sol = least_squares(residual, start, x_scale=1.0, xtol=1e-14, ftol=1e-14, gtol=1e-14)
    b, d = sorted(exponents(sol.x))
    return float(b), float(_continuity_c(b, d)), float(d)


def bootstrap_curvefit(pstar, samples, alpha_p, resamples=400, seed=0, slope=None, model=CURVEFIT_MODEL):
    """The fit of :func:`fit_curvefit` to the mean of ``samples`` and its spread over the surfaces.

    Parameters
    ----------
    pstar, samples : (steps,) and (surfaces, steps) array_like
        The load steps p* shared by every surface and A* of each surface at each step [-].
    alpha_p, slope, model :
        As in :func:`fit_curvefit`.
    resamples, seed : int
        Bootstrap resamples (surfaces drawn with replacement, their mean refitted) and their seed.

    Returns
    -------
    fit : (b, c, d)
        The fit of the ensemble mean.
    draws : (resamples, 3) ndarray
        The refits; percentiles of its columns are confidence intervals.
    """
    samples = np.asarray(samples, dtype=float)
    fit = fit_curvefit(pstar, samples.mean(axis=0), alpha_p, slope=slope, model=model)
    rng = np.random.default_rng(seed)
    guess = (fit[0], fit[2])
    draws = np.array([fit_curvefit(pstar, samples[rng.integers(0, len(samples), len(samples))].mean(axis=0),
                                   alpha_p, guess=guess, slope=slope, model=model) for _ in range(resamples)])
    return fit, draws
