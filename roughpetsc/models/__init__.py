"""Statistical contact models of the dissertation (chapters 2.5, 4, 5, 6, 8; appendices D, E).

Dimensionless conventions (docs/conventions.md): separation ``d* = d / sqrt(m0^h)``,
pressure ``p* = pbar / sqrt(m0^p) = pbar / (E* sqrt(m2^h / 2))``, mean gap
``g* = gbar / sqrt(m0^h)``, contact ratio ``A*``; bandwidths ``alpha^h`` (2.16)
and ``alpha^p`` (2.54).

The entry points and their equations: docs/models.md, "Entry points (`models/__init__.py`)".
"""

from . import crack, hertz, pdfs, quadrature, sphere_adhesion, wavy_adhesion
from .adhesion import CRACK_LAWS, AdhesiveCrack, AdhesiveGW, JKRCrack, jkr_G, jkr_pmin, jkr_pstar, jkr_radius, jkr_volume, nonadhesive_area, nonadhesive_radius, nonadhesive_volume
from .complete import COMPLETE_MODELS, complete
from .curvefit import ALPHA_P_TABLE_8_3, BGT_SLOPE, CURVEFIT_MODEL, TABLE_8_4, bootstrap_curvefit, correction, curvefit_area, curvefit_reference, curvefit_slope_at_zero, fit_curvefit
from .early import EARLY_MODELS, TABLE_4_1, TABLE_4_1_SEPARATIONS, early, early_area, early_separation
from .persson import fractal_moments, persson_area, persson_gap, psd_amplitude

__all__ = ["early", "early_area", "early_separation", "complete", "persson_area", "persson_gap", "psd_amplitude",
           "fractal_moments", "curvefit_area", "curvefit_reference", "curvefit_slope_at_zero", "CURVEFIT_MODEL",
           "fit_curvefit", "bootstrap_curvefit", "correction", "TABLE_8_4", "ALPHA_P_TABLE_8_3", "BGT_SLOPE",
           "EARLY_MODELS", "TABLE_4_1", "TABLE_4_1_SEPARATIONS", "COMPLETE_MODELS", "hertz", "crack", "pdfs",
           "quadrature", "AdhesiveCrack", "AdhesiveGW", "JKRCrack", "CRACK_LAWS", "jkr_pstar", "jkr_pmin",
           "jkr_radius", "jkr_G", "jkr_volume", "nonadhesive_radius", "nonadhesive_area", "nonadhesive_volume"]
