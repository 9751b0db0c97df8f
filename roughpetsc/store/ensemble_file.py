"""The file of ``-mode ensemble -output``: layout, writer, resume reader and comparison.

HDF5 layout (``n`` finished surfaces in index order, ``m`` load steps)::

    /                  attrs: format, complete, ensemble_size, n_finished, ensemble_seed, seed_rule, loads,
                              solver, kkt_rtol, E_star, grid, conventions, config (JSON), fftw_wisdom,
                              command, options (JSON), versions (JSON), runs (JSON: one entry per run,
                              the surfaces it solved)
    /pstar_target      (m,)   the prescribed p* of every step
    /surfaces/<name>   (n,)   :data:`SURFACE_FIELDS`: index, seed, spectral moments m0h m2h m4h m6h,
                              m0p m2p m4p, bandwidths alpha_h, alpha_p (spectral) and alpha_h_fd,
                              alpha_p_fd (finite differences (7.6)/(7.7)), sqrt_m0h, sqrt_m0p,
                              converged_steps, run, time_s
    /steps/<name>      (n, m) :data:`STEP_COLUMNS` (and ``reason``, strings)
    /statistics/       :func:`roughpetsc.ensemble.statistics.step_statistics`: <q>_mean, <q>_std (m,),
                              converged_count (m,), <alpha>_mean/_std (scalars)
    /models            (only when complete) :func:`roughpetsc.ensemble.statistics.compute_models`:
        pstar (m,); early/<model>/{A, dstar} (NaN above p* = 0.2); complete/<model>/{A, gstar};
        persson/{A, gstar}; kappa/<curve> = dA*/dp*; attrs alpha_h, alpha_p, early_pmax, notes

A format-1 file (without the finite-difference bandwidths and rms gap statistics) reads but does not resume.
"""

import json
import math
import operator
import os

import numpy as np

from ..errors import UserError
from . import read, write as write_file

FORMAT = "roughpetsc-ensemble-2"
OLD_FORMATS = ("roughpetsc-ensemble-1",)

SURFACE_FIELDS = ("index", "seed", "m0h", "m2h", "m4h", "m6h", "m0p", "m2p", "m4p", "alpha_h", "alpha_p",
                  "alpha_h_fd", "alpha_p_fd", "sqrt_m0h", "sqrt_m0p", "converged_steps", "run", "time_s")
INTEGER_SURFACE_FIELDS = ("index", "seed", "converged_steps", "run")
# Per-step datasets and the :class:`roughpetsc.contact.Result` attribute each is read from.
STEP_COLUMNS = (("pstar", "pstar"), ("pbar", "pbar"), ("A", "A"), ("A_corrected", "A_corrected"),
                ("gstar", "gstar"), ("gbar", "gbar"), ("separation", "separation"),
                ("rms_gap_contact", "rms_gap_contact"), ("kkt_natural", "kkt.natural"),
                ("kkt_complementarity", "kkt.complementarity"), ("kkt_min_p", "kkt.min_p"),
                ("kkt_min_g", "kkt.min_g"), ("kkt_load_error", "kkt.load_error"), ("iterations", "iterations"),
                ("operator_applications", "operator_applications"), ("converged", "converged"),
                ("time_s", "time_s"))
STEP_FIELDS = tuple(name for name, _ in STEP_COLUMNS)
INTEGER_STEP_FIELDS = ("iterations", "operator_applications", "converged")
# What differs between two runs of the same command: excluded when files are compared.
VOLATILE = ("@runs", "@fftw_wisdom", "surfaces/run", "surfaces/time_s", "steps/time_s")
MODELS_CONVENTIONS = "p* = pbar/sqrt(m0^p), g* = gbar/sqrt(m0^h), d* = d/sqrt(m0^h)"


def step_row(result):
    """The values of :data:`STEP_COLUMNS` of a :class:`roughpetsc.contact.Result` as floats (None as NaN)."""
    row = []
    for _, attribute in STEP_COLUMNS:
        value = operator.attrgetter(attribute)(result)
        row.append(np.nan if value is None else float(value))
    return row


def steps_table(rows):
    """``{name: (m,) array}`` of :data:`STEP_FIELDS` from the rows of :func:`step_row` (integers as int64)."""
    table = np.array(rows, dtype=float).reshape(len(rows), len(STEP_COLUMNS))
    steps = {name: table[:, j] for j, name in enumerate(STEP_FIELDS)}
    for name in INTEGER_STEP_FIELDS:
        steps[name] = steps[name].astype(np.int64)
    return steps


def _write_models(group, models):
    group.attrs["conventions"] = MODELS_CONVENTIONS
    group.attrs["alpha_h"], group.attrs["alpha_p"] = models["alpha_h"], models["alpha_p"]
    group.attrs["early_pmax"] = models["early_pmax"]
    group.attrs["notes"] = json.dumps(models["notes"])
    group.create_dataset("pstar", data=models["pstar"])
    for family in ("early", "complete"):
        for model, curves in models[family].items():
            for key, value in curves.items():
                group.create_dataset(f"{family}/{model}/{key}", data=value)
    for key, value in models.get("persson", {}).items():
        group.create_dataset(f"persson/{key}", data=value)
    for key, value in models["kappa"].items():
        group.create_dataset(f"kappa/{key}", data=value)


def write(path, attrs, pstar_target, records, statistics, models=None):
    """Write the whole ensemble file atomically (:func:`roughpetsc.store.write`).

    ``records``: ``{"surface": {field: value}, "steps": {field: (m,)}, "reason": [str] * m}`` in any order;
    ``models``: those of :func:`roughpetsc.ensemble.statistics.compute_models`, or None.
    """
    import h5py

    records = sorted(records, key=lambda r: r["surface"]["index"])
    n, m = len(records), len(pstar_target)

    def build(f):
        for key, value in attrs.items():
            f.attrs[key] = value
        f.attrs["n_finished"] = n
        f.create_dataset("pstar_target", data=np.asarray(pstar_target, dtype=float))
        group = f.create_group("surfaces")
        for field in SURFACE_FIELDS:
            dtype = np.int64 if field in INTEGER_SURFACE_FIELDS else float
            group.create_dataset(field, data=np.array([r["surface"][field] for r in records], dtype=dtype))
        group = f.create_group("steps")
        for field in STEP_FIELDS:
            dtype = np.int64 if field in INTEGER_STEP_FIELDS else float
            group.create_dataset(field, data=np.array([r["steps"][field] for r in records], dtype=dtype).reshape(n, m))
        group.create_dataset("reason", data=np.array([r["reason"] for r in records], dtype=object).reshape(n, m),
                             dtype=h5py.string_dtype())
        group = f.create_group("statistics")
        for key, value in statistics.items():
            group.create_dataset(key, data=value)
        if models is not None:
            _write_models(f.create_group("models"), models)

    write_file(path, build)


def _records_from(surfaces, steps, reasons):
    records = []
    for k in range(len(surfaces["index"])):
        surface = {field: (int(surfaces[field][k]) if field in INTEGER_SURFACE_FIELDS else float(surfaces[field][k]))
                   for field in SURFACE_FIELDS}
        record_steps = {field: steps[field][k].copy() for field in STEP_FIELDS}
        reason = [r.decode() if isinstance(r, bytes) else str(r) for r in reasons[k]]
        records.append({"surface": surface, "steps": record_steps, "reason": reason})
    return records


def stored_config(config, options):
    """The configuration JSON of a file as a dict; an older file's fractal surface gets the generator of its options."""
    from ..surface.generators import DEFAULT_GENERATOR

    config = json.loads(config)
    surface = config.get("surface", {})
    if surface.get("type") == "fractal" and "generator" not in surface:
        given = json.loads(options) if options else {}
        surface["generator"] = given.get("surface_generator", DEFAULT_GENERATOR)
    return config


def read_records(path, config):
    """Finished surfaces of an existing ensemble file (checked against ``config``), its run log and FFTW wisdom.

    Raises :class:`UserError` naming ``-output`` for another file, format or configuration, or a failed read.
    """
    import h5py

    try:
        with h5py.File(path, "r") as f:
            found = f.attrs.get("format")
            if found in OLD_FORMATS:
                raise UserError(f"-output {path}: the file is an ensemble of an older roughpetsc ({found}, without "
                                f"the finite-difference bandwidths) and cannot be resumed; give a new -output "
                                f"(the studies still read the old file)")
            if found != FORMAT:
                raise UserError(f"-output {path}: the file exists and is not a roughpetsc ensemble file; "
                                f"refusing to overwrite it")
            old = stored_config(f.attrs["config"], f.attrs.get("options"))
            runs = json.loads(f.attrs["runs"])
            wisdom = str(f.attrs.get("fftw_wisdom", ""))
            surfaces = {field: f["surfaces"][field][()] for field in SURFACE_FIELDS}
            steps = {field: f["steps"][field][()] for field in STEP_FIELDS}
            reasons = f["steps"]["reason"][()]
    except UserError:
        raise
    except Exception as error:   # any reader failure is the file's fault
        raise UserError(f"-output {path}: cannot read the existing file to resume it "
                        f"({type(error).__name__}: {error}); move it away to start afresh") from None
    if old != config:
        differ = sorted(key for key in set(old) | set(config) if old.get(key) != config.get(key))
        raise UserError(f"-output {path}: the file holds an ensemble of another configuration (differs in "
                        f"{', '.join(differ)}); use another -output or the same options")
    return _records_from(surfaces, steps, reasons), runs, wisdom


def flat(contents):
    """A :func:`roughpetsc.store.read` dict of an ensemble file, given its path or that dict."""
    return read(contents) if isinstance(contents, (str, os.PathLike)) else contents


def records_of(contents):
    """The records of a :func:`roughpetsc.store.read` dict (surface fields the file lacks are left out)."""
    n = int(contents["@n_finished"])
    m = np.size(contents["pstar_target"])
    records = []
    for k in range(n):
        surface = {field: contents[f"surfaces/{field}"][k] for field in SURFACE_FIELDS
                   if f"surfaces/{field}" in contents}
        steps = {field: np.asarray(contents[f"steps/{field}"]).reshape(n, m)[k] for field in STEP_FIELDS}
        records.append({"surface": surface, "steps": steps})
    return records


# --- Comparison

_RESIDUALS = ("steps/kkt_natural", "steps/kkt_complementarity", "steps/kkt_min_p", "steps/kkt_min_g",
              "steps/kkt_load_error")
_IN_SQRT_M0H = ("statistics/rms_gap_star_mean", "statistics/rms_gap_star_std")


def _scale(contents, name):
    """What a difference of dataset ``name`` is divided by (see :func:`compare`)."""
    if name in _RESIDUALS or name in _IN_SQRT_M0H:
        return 1.0
    if name == "steps/rms_gap_contact":
        return contents["surfaces/sqrt_m0h"][:, None]
    base = name[:-4] + "_mean" if name.startswith("statistics/") and name.endswith("_std") else name
    values = contents[base]
    scale = np.nanmax(np.abs(values)) if np.size(values) and np.any(np.isfinite(values)) else 1.0
    return scale if scale > 0 else 1.0


def _difference(contents, name, x, y):
    if isinstance(x, np.ndarray) and x.dtype.kind == "f" and np.shape(y) == x.shape:
        if not np.array_equal(np.isnan(x), np.isnan(y)):
            return math.inf
        difference = np.abs(x - y) / _scale(contents, name)
        return float(np.nanmax(difference)) if np.any(~np.isnan(difference)) else 0.0
    if isinstance(x, np.ndarray):
        return 0.0 if np.shape(y) == x.shape and np.array_equal(x, y) else math.inf
    if isinstance(x, float) and isinstance(y, float):
        return 0.0 if math.isnan(x) and math.isnan(y) else abs(x - y) / (abs(x) or 1.0)
    return 0.0 if x == y else math.inf


def compare(a, b):
    """The largest scaled difference of each quantity of two ensemble files (paths or :func:`read` dicts).

    :data:`VOLATILE` entries, the command and the options are left out. A difference is divided by the largest
    magnitude of its dataset (a std by that of its mean); KKT residuals are compared absolutely, the rms gap in
    contact relative to sqrt(m0^h). Different names, shapes, NaN patterns, integers or strings count as ``inf``.
    """
    a, b = flat(a), flat(b)
    skip = set(VOLATILE) | {"@command", "@options"}
    out = {name: math.inf for name in (set(a) ^ set(b)) - skip}
    for name in sorted((set(a) & set(b)) - skip):
        out[name] = _difference(a, name, a[name], b[name])
    return out
