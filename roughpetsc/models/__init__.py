"""Statistical contact models of the dissertation (chapters 2.5, 4, 5, 6, 8; appendices D, E).

Dimensionless conventions (docs/conventions.md): separation ``d* = d / sqrt(m0^h)``,
pressure ``p* = pbar / sqrt(m0^p) = pbar / (E* sqrt(m2^h / 2))``, mean gap
``g* = gbar / sqrt(m0^h)``, contact ratio ``A*``; bandwidths ``alpha^h`` (2.16)
and ``alpha^p`` (2.54).

Entry points
------------
early(name, dstar, alpha_h) -> (A, pstar)
    name in "gw", "nayak_bush", "greenwood", "bgt", "bgt_asymptotic" (chapter 4).
early_area(name, pstar, alpha_h) -> A ; early_separation(...) -> (dstar, A)
    Inversion of p*(d*).
complete(name, pstar, alpha_p, alpha_h) -> (A, gstar)
    name in "gw", "nayak_bush", "greenwood", "ciavarella" (chapter 5.3).
persson_area(pstar), persson_gap(pstar, k_l, k_s, H, m2, E_star)
    Persson (5.59) and appendix E.
curvefit_area(pstar, alpha_p, b, c, d, model="gw"), fit_curvefit(pstar, A, alpha_p, model="gw")
    Eqs. (8.2)-(8.3) with a = -c; Table 8.4 in ``TABLE_8_4``; I(p*) by default the adapted GW model (5.37)
    with the PDF (2.42), the one that reproduces Table 8.4 (``curvefit_reference``; erratum of section 8.5).
hertz, crack
    Hertz elliptical contact (4.6)-(4.17); pressurised elliptical/penny crack (5.15)-(5.32).
AdhesiveCrack(sigma0), JKRCrack(), AdhesiveGW(..., crack_law), jkr_*
    Penny-shaped adhesive crack (6.1)-(6.39) and adhesive adapted GW (6.40)-(6.54).
sphere_adhesion, wavy_adhesion
    Closed forms that validate the adhesive BEM: a sphere (JKR, DMT, Maugis-Dugdale) and Johnson's wavy
    surface (JKR, and a Maugis-Dugdale counterpart, ``WavyMaugisDugdale``).
"""

from . import crack, hertz, pdfs, quadrature, sphere_adhesion, wavy_adhesion
from .adhesion import CRACK_LAWS, AdhesiveCrack, AdhesiveGW, JKRCrack, jkr_G, jkr_pmin, jkr_pstar, jkr_radius, jkr_volume, nonadhesive_area, nonadhesive_radius, nonadhesive_volume
from .complete import COMPLETE_MODELS, complete
from .curvefit import ALPHA_P_TABLE_8_3, BGT_SLOPE, CURVEFIT_MODEL, TABLE_8_4, bootstrap_curvefit, correction, curvefit_area, curvefit_reference, curvefit_slope_at_zero, fit_curvefit
from .early import EARLY_MODELS, TABLE_4_1, TABLE_4_1_SEPARATIONS, early, early_area, early_separation
from .persson import fractal_moments, persson_area, persson_gap, psd_amplitude

__all__ = ["early", "early_area", "early_separation", "complete", "persson_area",
           "persson_gap", "psd_amplitude", "fractal_moments", "curvefit_area", "curvefit_reference",
           "curvefit_slope_at_zero", "CURVEFIT_MODEL", "fit_curvefit", "bootstrap_curvefit", "correction", "TABLE_8_4", "ALPHA_P_TABLE_8_3", "BGT_SLOPE",
           "EARLY_MODELS", "TABLE_4_1", "TABLE_4_1_SEPARATIONS", "COMPLETE_MODELS", "hertz", "crack", "pdfs", "quadrature",
           "AdhesiveCrack", "AdhesiveGW", "JKRCrack", "CRACK_LAWS", "jkr_pstar", "jkr_pmin", "jkr_radius",
           "jkr_G", "jkr_volume", "nonadhesive_radius", "nonadhesive_area",
           "nonadhesive_volume"]
