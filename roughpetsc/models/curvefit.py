"""Complete-contact curve fit of A*(p*) (the dissertation, 8.5, Eqs. (8.2)-(8.3), Table 8.4).

A*(p*) = I(p*) f(p*) for p* <= 2 and I(p*) beyond, where I is the Greenwood
nearly-complete model (5.45) and f(p*) = a exp(b p*) + c exp(d p*) with a = -c
(so that A*(0) = 0; erratum of docs/conventions.md: the sentence after Table 8.4 gives the column
means of b, c, d under the names a, b, c).  Continuity at p* = 2 requires
c = 1 / (exp(2 d) - exp(2 b)).
"""

import numpy as np
from scipy.optimize import least_squares

from .complete import complete

__all__ = ["TABLE_8_4", "ALPHA_P_TABLE_8_3", "correction", "curvefit_area", "fit_curvefit"]

#: Table 8.4: group -> (b, c, d); a = -c.
TABLE_8_4 = {18: (-1.923, 1.160, -0.062), 19: (-1.924, 1.150, -0.058),
             20: (-1.931, 1.138, -0.053), 21: (-1.943, 1.123, -0.047),
             22: (-1.959, 1.108, -0.040), 23: (-1.870, 1.169, -0.065),
             24: (-1.863, 1.156, -0.059), 25: (-1.873, 1.133, -0.049),
             26: (-1.897, 1.103, -0.037), 27: (-1.949, 1.065, -0.021)}
#: Table 8.3, "Num" column: alpha^p of the generated groups.
ALPHA_P_TABLE_8_3 = {18: 2.00, 19: 2.08, 20: 2.17, 21: 2.27, 22: 2.38,
                     23: 2.10, 24: 2.25, 25: 2.46, 26: 2.73, 27: 3.10}

P_SPLIT = 2.0


def correction(pstar, b, c, d):
    """f(p*) = c (exp(d p*) - exp(b p*)), Eq. (8.3) with a = -c."""
    p = np.asarray(pstar, dtype=float)
    return c * (np.exp(d * p) - np.exp(b * p))


def curvefit_area(pstar, alpha_p, b, c, d):
    """Curve-fit contact ratio A*(p*), Eq. (8.2).

    Parameters
    ----------
    pstar : array_like
        p* = pbar / sqrt(m0^p) >= 0.
    alpha_p : float
        Bandwidth of the pressure surface (2.54), > 3/2.
    b, c, d : float
        Parameters of (8.3) (Table 8.4), a = -c.

    Returns
    -------
    ndarray
        A* [-].
    """
    p = np.atleast_1d(np.asarray(pstar, dtype=float))
    I = complete("greenwood", p, alpha_p, alpha_p)[0]
    return np.where(p <= P_SPLIT, I * correction(p, b, c, d), I)


def fit_curvefit(pstar, area, alpha_p, guess=(-1.9, -0.05)):
    """Fit b, c, d of (8.2)-(8.3) to a curve A*(p*) (e.g. a BEM ensemble mean).

    The dissertation's two boundary conditions are built in: a = -c (A*(0) = 0) and
    c = 1 / (exp(2d) - exp(2b)) (continuity at p* = 2); b and d are found by
    least squares over the points with p* <= 2.

    Returns
    -------
    b, c, d : float
    """
    p = np.asarray(pstar, dtype=float)
    A = np.asarray(area, dtype=float)
    sel = (p <= P_SPLIT) & np.isfinite(A)
    if sel.sum() < 3:
        raise ValueError("need at least three points with p* <= 2 to fit b and d")
    p, A = p[sel], A[sel]
    I = complete("greenwood", p, alpha_p, alpha_p)[0]

    def c_of(b, d):
        return 1.0 / (np.exp(2 * d) - np.exp(2 * b))

    def residual(x):
        return I * correction(p, x[0], c_of(*x), x[1]) - A

    sol = least_squares(residual, np.asarray(guess, float), x_scale=1.0,
                        xtol=1e-14, ftol=1e-14, gtol=1e-14)
    b, d = sol.x
    return float(b), float(c_of(b, d)), float(d)
