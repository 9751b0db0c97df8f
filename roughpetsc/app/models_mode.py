"""``-mode models``: curves of every statistical model to JSON and PNG."""

from dataclasses import make_dataclass
import json

import numpy as np

from ..errors import UserError
from ..store.outputs import atomic_path, check_figure_format, check_outputs, on_root
from .settings import read_table

OPTIONS = [
    ("models_alpha_h", 2.0, "bandwidth alpha^h of the surface (2.16), > 1.5"),
    ("models_alpha_p", 2.0, "bandwidth alpha^p of the pressure surface (2.54), > 1.5"),
    ("models_n", 65, "points per curve"),
    ("models_dmax", 3.0, "largest d* of the early-contact curves (d* from dmax to 0)"),
    ("models_pmax", 4.0, "largest p* of the nearly-complete-contact curves (p* from 0 to pmax)"),
    ("models_kl", 16.0, "Persson gap: long-wavelength cut-off k_l [1/length]"),
    ("models_ks", 128.0, "Persson gap: short-wavelength cut-off k_s [1/length]"),
    ("models_hurst", 0.7, "Persson gap: Hurst exponent H in (0, 1)"),
    ("models_m2", 2e-4, "Persson gap: slope moment m2^h > 0"),
    ("models_group", 18, "Table 8.4 group (18-27) for the curve fit (8.2)-(8.3)"),
    ("models_curvefit_model", "gw", "I(p*) of the curve fit (8.2): gw = adapted GW (5.37) with the PDF (2.42), "
     "whose curve Table 8.4 is; greenwood = (5.45) with (2.41), as section 8.5 names it; nayak_bush (5.41); "
     "ciavarella (5.54)"),
    ("models_json", "", "write all curves to this JSON file"),
    ("models_plot", "", "write a PNG of all curves to this file"),
]


# What ``-mode models`` was asked to do; fields are named as the options of OPTIONS are.
ModelsSettings = make_dataclass("ModelsSettings", [(name, type(default)) for name, default, _ in OPTIONS],
                                frozen=True)


def read_settings(options):
    """The :class:`ModelsSettings` of the options database, checked (:class:`UserError` naming the option)."""
    settings = ModelsSettings(**read_table(options, OPTIONS))
    _validate(settings)
    return settings


def _validate(o):
    for key in ("models_alpha_h", "models_alpha_p"):
        if not np.isfinite(getattr(o, key)) or getattr(o, key) <= 1.5:
            raise UserError("-%s must be a number > 1.5 (got %r)" % (key, getattr(o, key)))
    if o.models_n < 2 or o.models_n > 100000:
        raise UserError("-models_n must be between 2 and 100000 (got %r)" % o.models_n)
    for key in ("models_dmax", "models_pmax", "models_kl", "models_ks", "models_m2"):
        if not np.isfinite(getattr(o, key)) or getattr(o, key) <= 0:
            raise UserError("-%s must be positive and finite (got %r)" % (key, getattr(o, key)))
    if o.models_ks <= o.models_kl:
        raise UserError("-models_ks must exceed -models_kl")
    if not 0 < o.models_hurst < 1:
        raise UserError("-models_hurst must lie in (0, 1) (got %r)" % o.models_hurst)
    from ..models.complete import COMPLETE_MODELS
    from ..models.curvefit import TABLE_8_4
    if o.models_group not in TABLE_8_4:
        raise UserError("-models_group must be one of %s" % sorted(TABLE_8_4))
    if o.models_curvefit_model not in COMPLETE_MODELS:
        raise UserError("-models_curvefit_model must be one of %s (got %r)"
                        % (", ".join(COMPLETE_MODELS), o.models_curvefit_model))


def compute(o):
    """All curves as a plain dict (lists), dimensionless as in roughpetsc.models."""
    from ..models import (ALPHA_P_TABLE_8_3, COMPLETE_MODELS, EARLY_MODELS, TABLE_8_4, complete, curvefit_area, early,
                          persson_area, persson_gap)
    ah, ap, n = o.models_alpha_h, o.models_alpha_p, o.models_n
    d = np.linspace(o.models_dmax, 0.0, n)
    p = np.linspace(0.0, o.models_pmax, n)
    out = {"conventions": "d* = d/sqrt(m0^h), p* = pbar/sqrt(m0^p), g* = gbar/sqrt(m0^h)",
           "alpha_h": ah, "alpha_p": ap, "early": {}, "complete": {}}
    for name in EARLY_MODELS:
        A, ps = early(name, d, ah)
        out["early"][name] = {"dstar": d.tolist(), "A": A.tolist(), "pstar": ps.tolist()}
    for name in COMPLETE_MODELS:
        A, g = complete(name, p, ap, ah)
        out["complete"][name] = {"pstar": p.tolist(), "A": A.tolist(), "gstar": g.tolist()}
    pp = p[p > 0]
    out["persson"] = {"pstar": p.tolist(), "A": persson_area(p).tolist(),
                      "gstar_pstar": pp.tolist(),
                      "gstar": persson_gap(pp, o.models_kl, o.models_ks, o.models_hurst,
                                           o.models_m2, 1.0).tolist()}
    grp, model = o.models_group, o.models_curvefit_model
    b, c, dd = TABLE_8_4[grp]
    out["curvefit"] = {"group": grp, "model": model, "b": b, "c": c, "d": dd, "alpha_p": ALPHA_P_TABLE_8_3[grp],
                       "pstar": p.tolist(),
                       "A": curvefit_area(p, ALPHA_P_TABLE_8_3[grp], b, c, dd, model=model).tolist()}
    return out


def plot(curves, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, c in curves["early"].items():
        ax[0].plot(c["pstar"], c["A"], label="early " + name)
    for name, c in curves["complete"].items():
        ax[0].plot(c["pstar"], c["A"], "--", label="complete " + name)
        ax[1].semilogy(c["pstar"][1:], c["gstar"][1:], "--", label=name)
    ax[0].plot(curves["persson"]["pstar"], curves["persson"]["A"], "k:", label="Persson")
    ax[0].plot(curves["curvefit"]["pstar"], curves["curvefit"]["A"], "k-", lw=2,
               label="curve fit (group %d, I = %s)" % (curves["curvefit"]["group"], curves["curvefit"]["model"]))
    ax[1].semilogy(curves["persson"]["gstar_pstar"], curves["persson"]["gstar"], "k:", label="Persson")
    ax[0].set(xlabel="p*", ylabel="A*", ylim=(0, 1.02),
              title="alpha^h = %g, alpha^p = %g" % (curves["alpha_h"], curves["alpha_p"]))
    ax[1].set(xlabel="p*", ylabel="g*")
    ax[0].legend(fontsize=6)
    ax[1].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run(options, comm):
    """``-mode models``, worked on rank 0 (its errors raised on every rank); the curves on rank 0, None elsewhere."""
    o = read_settings(options)
    on_root(comm, check_outputs, [("models_json", o.models_json), ("models_plot", o.models_plot)],
            options.getBool("overwrite", False))
    if o.models_plot:  # after the path checks, which name a folder as such
        check_figure_format(o.models_plot, "models_plot")
    from .options import check_unused  # imports PETSc: only once the command line has initialised it

    check_unused()  # before any work: a run refused for an option it does not use prints and writes nothing
    return on_root(comm, _compute_and_write, o)


def _compute_and_write(o):
    """Compute, print and write the curves (rank 0)."""
    curves = compute(o)
    print("models: alpha_h = %g, alpha_p = %g" % (o.models_alpha_h, o.models_alpha_p))
    print("%-16s %10s %10s %10s" % ("early model", "d*", "p*", "A*"))
    for name, c in curves["early"].items():
        for i in (0, len(c["dstar"]) // 2, -1):
            print("%-16s %10.4f %10.4e %10.4e" % (name, c["dstar"][i], c["pstar"][i], c["A"][i]))
    print("%-16s %10s %10s %10s" % ("complete model", "p*", "A*", "g*"))
    for name, c in curves["complete"].items():
        for i in (len(c["pstar"]) // 2, -1):
            print("%-16s %10.4f %10.4e %10.4e" % (name, c["pstar"][i], c["A"][i], c["gstar"][i]))
    fit = curves["curvefit"]
    print("curve fit (8.2)-(8.3), Table 8.4 group %d (b, c, d = %g, %g, %g), I = %s at alpha_p = %g:"
          % (fit["group"], fit["b"], fit["c"], fit["d"], fit["model"], fit["alpha_p"]))
    for i in (len(fit["pstar"]) // 4, len(fit["pstar"]) // 2):
        print("%-16s %10.4f %10.4e" % ("curve fit", fit["pstar"][i], fit["A"][i]))
    if o.models_json:
        with atomic_path(o.models_json) as tmp:
            with open(tmp, "w") as fh:
                json.dump(curves, fh, indent=1)
    if o.models_plot:
        # The temporary name ends like the target, so matplotlib picks the same format.
        with atomic_path(o.models_plot) as tmp:
            plot(curves, tmp)
    return curves
