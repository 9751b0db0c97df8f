"""The dissertation's formulas written out afresh from its text, evaluated by adaptive quadrature: references for
the tests that are independent of roughpetsc.models (its PDFs, its Gauss-Legendre rules, its fit)."""

import numpy as np
from scipy.integrate import quad
from scipy.special import erf


def summit_height_pdf(xi, alpha):
    """Phi(xi*) of Eq. (2.42), the PDF of the asperity height alone (bandwidth ``alpha`` > 3/2)."""
    c1 = alpha / (2 * alpha - 3)
    beta = xi * np.sqrt(3 / (2 * (2 * alpha - 3)))
    gamma = xi * np.sqrt(alpha / (2 * (alpha - 1) * (2 * alpha - 3)))
    return (3 / (2 * np.pi) * np.sqrt(2 * alpha - 3) / alpha * xi * np.exp(-c1 * xi ** 2)
            + 3 * np.sqrt(3) / (2 * np.sqrt(2 * np.pi)) / alpha * (xi ** 2 - 1) * np.exp(-xi ** 2 / 2)
            * (1 + erf(beta))
            + np.sqrt(alpha / (2 * np.pi * (alpha - 1))) * np.exp(-alpha * xi ** 2 / (2 * (alpha - 1)))
            * (1 + erf(gamma)))


def adapted_gw_complete_area(pstar, alpha_p):
    """A*(p*) of the adapted GW model of nearly complete contact, Eq. (5.37), with the PDF (2.42) at alpha^p."""
    tail = quad(lambda xi: (xi - pstar) * summit_height_pdf(xi, alpha_p), pstar, np.inf, epsabs=1e-13,
                epsrel=1e-12)[0]
    return 1 - np.sqrt(3) / 16 * np.sqrt(np.pi) * np.sqrt(alpha_p) * tail


def curve_fit_area(pstar, alpha_p, b, c, d):
    """Eq. (8.2) with f of (8.3), a = -c, and I the adapted GW model (5.37)."""
    area = adapted_gw_complete_area(pstar, alpha_p)
    return area * c * (np.exp(d * pstar) - np.exp(b * pstar)) if pstar <= 2 else area
