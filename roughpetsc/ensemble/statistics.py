"""What an ensemble file stores beside the surfaces: step statistics, the statistical models, kappa.

The models are evaluated at the steps' p* with the ensemble's mean bandwidths (sec. 7.3): early-contact
models (ch. 4) on p* <= :data:`EARLY_PMAX`, nearly-complete-contact models (ch. 5) everywhere, Persson's (5.59)
and App. E, and kappa = dA*/dp* of every curve and of the BEM means.
"""

import numpy as np

STATISTICS = ("pstar", "A", "A_corrected", "gstar", "gbar", "rms_gap_star")
SURFACE_STATISTICS = ("alpha_h", "alpha_p", "alpha_h_fd", "alpha_p_fd")
EARLY = ("gw", "nayak_bush", "greenwood", "bgt", "bgt_asymptotic")
COMPLETE = ("gw", "nayak_bush", "greenwood", "ciavarella")
MODEL_NAMES = ("gw", "nayak_bush", "greenwood", "bgt", "bgt_asymptotic", "ciavarella", "persson")
EARLY_PMAX = 0.2           # the end of the early-contact stage of the load history (7.11)


def _per_step(records, name, n_steps):
    """``(surfaces, steps)`` table of a per-step quantity; ``rms_gap_star`` is (3.50) over sqrt(m0^h)."""
    if name == "rms_gap_star":
        rows = [np.asarray(r["steps"]["rms_gap_contact"], float) / r["surface"]["sqrt_m0h"] for r in records]
    else:
        rows = [r["steps"][name] for r in records]
    return np.array(rows, dtype=float).reshape(len(records), n_steps)


def step_statistics(records, n_steps):
    """Means and sample std (ddof = 1) over the surfaces, in the order of ``records`` (NaN where undefined).

    ``<q>_mean``, ``<q>_std`` (n_steps,) of :data:`STATISTICS`, ``converged_count`` (n_steps,), and scalars of
    the :data:`SURFACE_STATISTICS` every record has.
    """
    out = {}
    n = len(records)
    for name in STATISTICS:
        table = _per_step(records, name, n_steps)
        out[name + "_mean"] = table.mean(axis=0) if n else np.full(n_steps, np.nan)
        out[name + "_std"] = table.std(axis=0, ddof=1) if n > 1 else np.full(n_steps, np.nan)
    out["converged_count"] = np.array([r["steps"]["converged"] for r in records],
                                      dtype=np.int64).reshape(n, n_steps).sum(axis=0)
    for name in SURFACE_STATISTICS:
        if not all(name in r["surface"] for r in records):
            continue
        values = np.array([r["surface"][name] for r in records], dtype=float)
        out[name + "_mean"] = values.mean() if n else np.nan
        out[name + "_std"] = values.std(ddof=1) if n > 1 else np.nan
    return out


def kappa(pstar, area):
    """dA*/dp* by second-order finite differences on the (increasing) steps; NaN where undefined."""
    slope = np.full(pstar.shape, np.nan)
    ok = np.isfinite(area)
    p, a = pstar[ok], area[ok]
    if p.size >= 2 and np.all(np.diff(p) > 0):
        slope[ok] = np.gradient(a, p, edge_order=2 if p.size >= 3 else 1)
    return slope


def _early_curves(pstar, alpha_h, name, notes):
    from .. import models

    area, separation = np.full(pstar.shape, np.nan), np.full(pstar.shape, np.nan)
    early_steps = pstar <= EARLY_PMAX
    try:
        if early_steps.any():
            separation[early_steps], area[early_steps] = models.early_separation(name, pstar[early_steps], alpha_h)
    except ValueError as error:
        notes["early_" + name] = str(error)
    return {"A": area, "dstar": separation}


def _complete_curves(pstar, alpha_p, alpha_h, name, notes):
    from .. import models

    try:
        area, gap = models.complete(name, pstar, alpha_p, alpha_h)
    except ValueError as error:
        notes["complete_" + name] = str(error)
        area, gap = np.full(pstar.shape, np.nan), np.full(pstar.shape, np.nan)
    return {"A": area, "gstar": gap}


def compute_models(pstar, alpha_h, alpha_p, surface, E_star, names, statistics):
    """The statistical models at the steps' p* with the ensemble's mean bandwidths, and kappa = dA*/dp*.

    Parameters
    ----------
    pstar : ndarray (m,)
        The steps' p* = pbar / sqrt(m0^p) [-], increasing.
    alpha_h, alpha_p : float
        The ensemble's mean bandwidths (2.16), (2.54) [-].
    surface, E_star : dict, float
        The fractal ``kl, ks, H, m2`` (Persson's gap, App. E) and the composite modulus E* (1.6) [pressure].
    names, statistics : iterable of str, dict
        The models to compute (:data:`MODEL_NAMES`); :func:`step_statistics` (kappa of the BEM means).

    Returns
    -------
    dict
        ``{"pstar", "alpha_h", "alpha_p", "early_pmax", "early": {model: {"A", "dstar"}}, "complete": {model: {"A",
        "gstar"}}, "persson": {"A", "gstar"}, "kappa": {curve: (m,)}, "notes": {curve: why NaN}}``.
    """
    from .. import models

    out = {"pstar": pstar, "alpha_h": alpha_h, "alpha_p": alpha_p, "early_pmax": EARLY_PMAX, "early": {},
           "complete": {}, "kappa": {}, "notes": {}}
    for name in (name for name in EARLY if name in names):
        out["early"][name] = _early_curves(pstar, alpha_h, name, out["notes"])
        out["kappa"]["early_" + name] = kappa(pstar, out["early"][name]["A"])
    for name in (name for name in COMPLETE if name in names):
        out["complete"][name] = _complete_curves(pstar, alpha_p, alpha_h, name, out["notes"])
        out["kappa"]["complete_" + name] = kappa(pstar, out["complete"][name]["A"])
    if "persson" in names:
        area = models.persson_area(pstar)
        gap = models.persson_gap(pstar, surface["kl"], surface["ks"], surface["H"], surface["m2"], E_star)
        out["persson"] = {"A": area, "gstar": gap}
        out["kappa"]["persson"] = kappa(pstar, area)
    out["kappa"]["bem_A"] = kappa(pstar, statistics["A_mean"])
    out["kappa"]["bem_A_corrected"] = kappa(pstar, statistics["A_corrected_mean"])
    return out


# --- Reading them back (studies): as stored, completed for older or unfinished files

def stored_statistics(contents, say=print):
    """``{name: value}`` of ``/statistics`` of an ensemble file (a path or a :func:`roughpetsc.store.read` dict).

    Quantities a format-1 file lacks are computed from its steps, and ``say`` tells which.
    """
    from ..store import ensemble_file

    contents = ensemble_file.flat(contents)
    stored = {name.split("/", 1)[1]: value for name, value in contents.items()
              if name.startswith("statistics/") and "@" not in name}
    if all(f"{q}_mean" in stored for q in STATISTICS + SURFACE_STATISTICS):
        return stored
    computed = step_statistics(ensemble_file.records_of(contents), np.size(contents["pstar_target"]))
    missing = sorted(set(computed) - set(stored))
    if missing:
        say(f"{contents.get('@format')}: statistics {', '.join(missing)} not in the file; computed from its steps")
    return dict(computed, **stored)


def stored_models(contents, statistics=None, say=print):
    """The ``/models`` of an ensemble file as :func:`compute_models` returns them; computed (every model) for an
    unfinished ensemble, and ``say`` tells so."""
    import json

    from ..store import ensemble_file

    contents = ensemble_file.flat(contents)
    if "models/pstar" not in contents:
        statistics = statistics or stored_statistics(contents, say)
        config = json.loads(contents["@config"])
        say(f"{contents.get('@format')}: no /models (unfinished ensemble, {int(contents['@n_finished'])} of "
            f"{int(contents['@ensemble_size'])} surfaces); models computed at its mean bandwidths")
        return compute_models(np.asarray(contents["pstar_target"], float), float(statistics["alpha_h_mean"]),
                              float(statistics["alpha_p_mean"]), config["surface"], config["E_star"], MODEL_NAMES,
                              statistics)
    out = {"pstar": contents["models/pstar"], "alpha_h": float(contents["models@alpha_h"]),
           "alpha_p": float(contents["models@alpha_p"]), "early_pmax": float(contents["models@early_pmax"]),
           "early": {}, "complete": {}, "kappa": {},
           "notes": json.loads(contents["models@notes"])}
    for name, value in contents.items():
        parts = name.split("/")
        if parts[0] != "models" or len(parts) < 3 or "@" in name:
            continue
        if parts[1] in ("early", "complete"):
            out[parts[1]].setdefault(parts[2], {})[parts[3]] = value
        elif parts[1] == "persson":
            out.setdefault("persson", {})[parts[2]] = value
        elif parts[1] == "kappa":
            out["kappa"][parts[2]] = value
    return out
