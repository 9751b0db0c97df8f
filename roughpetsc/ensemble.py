"""``-mode ensemble``: many random surfaces along one load path, in one resumable HDF5 file.

    mpiexec -n 2 python -m roughpetsc -mode ensemble -options_file options/group18.opts \\
        -ensemble_size 50 -output group18.h5

What it does (seed ch. 7.3 and 8; SPEC component 6):

* Surface ``i`` (``i = 0 .. size-1``) is the fractal surface of the ``-surface_*``
  options with the seed :func:`surface_seed` ``(master, i)`` derived from
  ``-ensemble_seed`` by ``numpy.random.SeedSequence(master).spawn(...)[i]``
  (a 31-bit integer, so ``-mode solve -surface_seed SEED`` rebuilds that one
  surface).
* Every surface is solved along the loads of ``-ensemble_loads`` (the history
  (7.11) of :mod:`roughpetsc.loads` by default) in order, each step warm-started
  from the previous one (load control, the solver of the PETSc options).
* COMM_WORLD is split into groups of ``-ensemble_group_ranks`` ranks; each
  group solves whole surfaces on its own communicator. Surfaces are dealt
  dynamically: the group leaders draw the next unfinished surface from an
  atomic counter on world rank 0 (MPI one-sided ``Fetch_and_op``; if the MPI
  library offers no usable window, requests to rank 0 by message instead).
* World rank 0 owns the file. Leaders send each finished surface to rank 0
  (non-blocking), which looks for them between its own load steps and rewrites
  the whole file after every finished surface: written to a hidden temporary
  in the same folder, flushed, fsync'ed, and renamed over the file. A kill at
  any moment leaves the previous or the new complete file, never a partial
  one.
* Resume: rerunning with an existing ``-output`` keeps the finished surfaces
  in it (if the file was made by the same configuration) and solves only the
  others. Surfaces are stored in index (seed) order and the statistics are
  taken in that order, so a resumed run ends with the same numbers as an
  uninterrupted one (wall times, run numbers and the run log excepted:
  :data:`VOLATILE`).

HDF5 layout (``n`` finished surfaces in index order, ``m`` load steps)::

    /                  attrs: format, complete, ensemble_size, n_finished, ensemble_seed, solver, kkt_rtol,
                              E_star, grid, conventions, config (JSON), command, options (JSON),
                              versions (JSON), runs (JSON: one entry per run, the surfaces it solved)
    /pstar_target      (m,)   the prescribed p* of every step
    /surfaces/<name>   (n,)   index, seed, m0h m2h m4h m6h, m0p m2p m4p, alpha_h, alpha_p, sqrt_m0h,
                              sqrt_m0p, converged_steps, run, time_s
    /steps/<name>      (n, m) pstar, pbar, A, A_corrected, gstar, gbar, separation, rms_gap_contact,
                              kkt_natural, kkt_complementarity, kkt_min_p, kkt_min_g, kkt_load_error,
                              iterations, operator_applications, converged, time_s, reason (strings)
    /statistics/<q>_mean, <q>_std (m,) for q in pstar, A, A_corrected, gstar, gbar (sample std,
                              ddof = 1); converged_count (m,); alpha_h_mean/_std, alpha_p_mean/_std (scalars)
    /models            (only when complete) the statistical models at the mean alpha^h, alpha^p:
        pstar (m,); early/<model>/{A, dstar} (NaN above p* = 0.2, the early stage; g* ~ d* there);
        complete/<model>/{A, gstar}; persson/{A, gstar}; kappa/<curve> = dA*/dp* (finite
        differences on the steps): kappa/bem_A, kappa/bem_A_corrected, kappa/early_<model>, ...
"""

from io import BytesIO
import json
import math
import os
import sys
import time
import traceback

import numpy as np

from .errors import UserError

FORMAT = "roughpetsc-ensemble-1"

OPTIONS = [
    ("ensemble_size", 50, "number of surfaces (indices 0..size-1; an existing file can be extended)"),
    ("ensemble_seed", 1, "master seed; surface i gets SeedSequence(master).spawn(...)[i] (31-bit, see the file)"),
    ("ensemble_group_ranks", 1, "MPI ranks per group; each group solves whole surfaces (must divide the ranks)"),
    ("ensemble_loads", "history", "p* steps: 'history' (7.11, 95 steps, D1 = 0.2/30) or a comma list"),
    ("ensemble_models", "all", "statistical models stored beside the BEM: all | none | comma list of "
                               "gw,nayak_bush,greenwood,bgt,bgt_asymptotic,ciavarella,persson"),
    ("output", "ensemble.h5", "the ensemble's HDF5 file; rerunning with an existing file resumes it"),
    ("kkt_rtol", 1e-8, "stop when the natural KKT residual <= this (and the load error)"),
    ("fft_threads", 1, "FFTW threads per rank"),
    ("fft_effort", "FFTW_MEASURE", "FFTW planner effort"),
    ("quiet", False, "print nothing but errors"),
]

SURFACE_FIELDS = ("index", "seed", "m0h", "m2h", "m4h", "m6h", "m0p", "m2p", "m4p", "alpha_h", "alpha_p",
                  "sqrt_m0h", "sqrt_m0p", "converged_steps", "run", "time_s")
INTEGER_SURFACE_FIELDS = ("index", "seed", "converged_steps", "run")
STEP_FIELDS = ("pstar", "pbar", "A", "A_corrected", "gstar", "gbar", "separation", "rms_gap_contact",
               "kkt_natural", "kkt_complementarity", "kkt_min_p", "kkt_min_g", "kkt_load_error",
               "iterations", "operator_applications", "converged", "time_s")
INTEGER_STEP_FIELDS = ("iterations", "operator_applications", "converged")
STATISTICS = ("pstar", "A", "A_corrected", "gstar", "gbar")
EARLY = ("gw", "nayak_bush", "greenwood", "bgt", "bgt_asymptotic")
COMPLETE = ("gw", "nayak_bush", "greenwood", "ciavarella")
MODEL_NAMES = ("gw", "nayak_bush", "greenwood", "bgt", "bgt_asymptotic", "ciavarella", "persson")
EARLY_PMAX = 0.2           # the early-contact stage of sec. 7.3
# What differs between two runs of the same command: excluded when files are compared.
VOLATILE = ("@runs", "@fftw_wisdom", "surfaces/run", "surfaces/time_s", "steps/time_s")
# Options that do not change the numbers of a surface (not part of the configuration a resume must match).
_NOT_NUMBERS = ("mode", "ensemble_size", "ensemble_group_ranks", "ensemble_models", "output", "quiet",
                "fft_threads", "fft_effort", "help", "options_left", "malloc_debug", "malloc_dump")
_NOT_CONFIG = ("monitor", "view", "log", "converged_reason", "options_left", "info", "history")

TAG_RECORD, TAG_NEXT, TAG_ITEM = 11, 12, 13
IDLE_SLEEP = 0.01          # seconds between looks for messages when a rank has nothing else to do


# ----------------------------------------------------------------------------
# Seeds, settings
# ----------------------------------------------------------------------------

def surface_seed(master, index):
    """Seed of surface ``index``: the first word of ``SeedSequence(master).spawn(index + 1)[index]``, 31 bits."""
    sequence = np.random.SeedSequence(master, spawn_key=(index,))
    return int(sequence.generate_state(1, np.uint32)[0] & 0x7FFFFFFF)


def parse_models(text):
    text = (text or "").strip().lower()
    if text == "all":
        return list(MODEL_NAMES)
    if text in ("none", ""):
        return []
    names = [item.strip() for item in text.split(",") if item.strip()]
    for name in names:
        if name not in MODEL_NAMES:
            raise UserError(f"-ensemble_models: unknown model '{name}' (all, none, or a list of "
                            f"{', '.join(MODEL_NAMES)})")
    return names


def read_settings(reader, size):
    """Read and check every option of the mode (same on all ranks); raise :class:`UserError` naming it."""
    from . import io, loads, surfaces
    from .slab import row_split

    s = {"size": reader.int("ensemble_size", 50), "seed": reader.int("ensemble_seed", 1),
         "group_ranks": reader.int("ensemble_group_ranks", 1),
         "loads": loads.parse(reader.string("ensemble_loads", "history"), "ensemble_loads"),
         "loads_spec": reader.string("ensemble_loads", "history"),
         "models": parse_models(reader.string("ensemble_models", "all")),
         "output": reader.string("output", "ensemble.h5"), "rtol": reader.real("kkt_rtol", 1e-8),
         "E_star": reader.real("E_star", 1.0), "threads": reader.int("fft_threads", 1),
         "effort": reader.string("fft_effort", "FFTW_MEASURE"), "quiet": reader.bool("quiet", False),
         "tao_type": reader.string("tao_type", "") or None}
    if s["size"] < 1:
        raise UserError(f"-ensemble_size must be at least 1, got {s['size']}")
    if s["seed"] < 0:
        raise UserError(f"-ensemble_seed must be a non-negative integer, got {s['seed']}")
    if s["group_ranks"] < 1 or size % s["group_ranks"]:
        raise UserError(f"-ensemble_group_ranks {s['group_ranks']} must be a positive divisor of the "
                        f"number of MPI ranks ({size})")
    if not 0 < s["rtol"] < 1:
        raise UserError(f"-kkt_rtol must lie in (0, 1), got {s['rtol']}")
    if not (s["E_star"] > 0 and math.isfinite(s["E_star"])):
        raise UserError(f"-E_star must be a positive, finite modulus, got {s['E_star']}")
    if s["threads"] < 1:
        raise UserError(f"-fft_threads must be at least 1, got {s['threads']}")
    if s["effort"] not in ("FFTW_ESTIMATE", "FFTW_MEASURE", "FFTW_PATIENT", "FFTW_EXHAUSTIVE"):
        raise UserError(f"-fft_effort: unknown planner effort '{s['effort']}'")
    if not s["output"]:
        raise UserError("-output: give the path of the ensemble's HDF5 file")
    io.check_writable(s["output"], "output")
    if reader.string("surface_file", ""):
        raise UserError("-surface_file: an ensemble needs random surfaces (-surface_type fractal)")
    if reader.string("surface_type", "fractal") != "fractal":
        raise UserError("-surface_type: an ensemble needs random surfaces (-surface_type fractal)")
    if reader.has("surface_seed"):
        raise UserError("-surface_seed is not used by -mode ensemble: the seeds derive from -ensemble_seed")
    grid = surfaces.grid_from_options(reader)
    surface = {"type": "fractal", "N0": grid.n0, "N": grid.n1, "L": grid.l1,
               "kl": reader.real("surface_kl", 16.0), "ks": reader.real("surface_ks", 64.0),
               "H": reader.real("surface_H", 0.8), "m2": reader.real("surface_m2", 2e-4)}
    surfaces.check_fractal_parameters(grid, surface["kl"], surface["ks"], surface["H"], surface["m2"])
    row_split(grid.n0, s["group_ranks"])  # every rank of a group needs at least one row
    s["grid"], s["surface"] = grid, surface
    return s


def probe_solver(s):
    """Build the solver once on a tiny problem (rank-local): checks -tao_type and reads the TAO options.

    Returns the solver's name. After this, ``check_unused`` sees every option
    a real solve would read, so misspellings fail before any work.
    """
    from petsc4py import PETSc

    from .contact import ContactProblem
    from .control import Solver
    from .surfaces import Grid, wave

    grid = Grid(2, 8, 0.25, 1.0)
    problem = ContactProblem(grid, wave(grid, 1.0, 1.0), s["E_star"], PETSc.COMM_SELF, 1, "FFTW_ESTIMATE")
    try:
        solver = Solver(problem, "load", s["tao_type"], s["rtol"])
        name = solver.name
        solver.destroy()
    finally:
        problem.destroy()
    return name


def configuration(s, solver_name):
    """Everything that determines the numbers of a surface (a resumed file must match it).

    The resolved surface, modulus, seed, loads and tolerance, the solver's
    name, and every other option given (solver options such as ``-tao_*``,
    ``-pk_*``, ``-bound_pc``, ``-solve_max_time``) except those that cannot
    change a surface's numbers (:data:`_NOT_NUMBERS`, monitors, viewers, logs).
    """
    from petsc4py import PETSc

    resolved = ("E_star", "kkt_rtol", "ensemble_seed", "ensemble_loads", "tao_type")
    solver_options = {name: value for name, value in sorted(PETSc.Options().getAll().items())
                      if name not in _NOT_NUMBERS and name not in resolved and not name.startswith("surface_")
                      and not any(word in name for word in _NOT_CONFIG)}
    config = {"surface": s["surface"], "E_star": s["E_star"], "ensemble_seed": s["seed"],
              "pstar_target": [float(v) for v in s["loads"]], "kkt_rtol": s["rtol"], "solver": solver_name,
              "solver_options": solver_options, "control": "load"}
    return json.loads(json.dumps(config))


# ----------------------------------------------------------------------------
# Work distribution
# ----------------------------------------------------------------------------

class WorkCounter:
    """The next work item for the group leaders: an atomic counter on world rank 0.

    One-sided (``MPI.Win.Allocate`` + ``Fetch_and_op``) when the MPI library
    supports it; otherwise leaders ask rank 0 by message and rank 0 answers in
    :meth:`Ensemble.poll` (between its load steps).
    """

    def __init__(self, comm, items, use_window=True):
        from mpi4py import MPI

        self.comm, self.items = comm, items
        self.window = None
        self.next_local = 0                      # rank 0's counter in message mode
        self.leaders_done = 0                    # message mode: leaders told "no more work"
        if use_window:
            try:
                self.window = MPI.Win.Allocate(8 if comm.Get_rank() == 0 else 0, 8, comm=comm)
            except MPI.Exception:
                self.window = None
        if not comm.allreduce(self.window is not None, op=MPI.LAND) and self.window is not None:
            self.window.Free()
            self.window = None
        if self.window is not None and comm.Get_rank() == 0:
            self.window.Lock(0, MPI.LOCK_EXCLUSIVE)
            self.window.Put([np.zeros(1, np.int64), MPI.INT64_T], 0)
            self.window.Unlock(0)
        comm.Barrier()
        self.mode = "one-sided" if self.window is not None else "messages"

    def next(self):
        """Called by a group leader: the next item (an index into ``items``) or -1 when none is left."""
        from mpi4py import MPI

        if self.window is not None:
            one, value = np.ones(1, np.int64), np.zeros(1, np.int64)
            self.window.Lock(0, MPI.LOCK_SHARED)
            self.window.Fetch_and_op([one, MPI.INT64_T], [value, MPI.INT64_T], 0, 0, MPI.SUM)
            self.window.Unlock(0)
            k = int(value[0])
        elif self.comm.Get_rank() == 0:
            k, self.next_local = self.next_local, self.next_local + 1
        else:
            self.comm.send(None, dest=0, tag=TAG_NEXT)
            k = self.comm.recv(source=0, tag=TAG_ITEM)
        return k if k < len(self.items) else -1

    def exhaust(self):
        """Rank 0: no more items for anybody (the run stops after the surfaces under way).

        Returns how many items had been handed out.
        """
        from mpi4py import MPI

        handed = self.next_local
        if self.window is not None:
            end, old = np.array([len(self.items)], np.int64), np.zeros(1, np.int64)
            self.window.Lock(0, MPI.LOCK_EXCLUSIVE)
            self.window.Fetch_and_op([end, MPI.INT64_T], [old, MPI.INT64_T], 0, 0, MPI.REPLACE)
            self.window.Unlock(0)
            handed = int(old[0])
        self.next_local = max(self.next_local, len(self.items))
        return min(handed, len(self.items))

    def answer(self, source):
        """Rank 0, message mode: give ``source`` its next item."""
        k, self.next_local = self.next_local, self.next_local + 1
        if k >= len(self.items):
            self.leaders_done += 1
        self.comm.send(k, dest=source, tag=TAG_ITEM)

    def free(self):
        if self.window is not None:
            self.window.Free()


def share_fftw_wisdom(comm, group, s, stored):
    """Make every rank, in this run and in any resumed run, use the same FFTW plans.

    FFTW_MEASURE picks plans by timing, so two processes may transform with
    different algorithms and round differently (1e-13 relative differences in
    g*). Here group 0 plans the transforms of the grid once (from the wisdom
    stored in the file, if any), world rank 0 exports its wisdom, and every
    other rank forgets its own and imports that one before any surface is
    built. Returns the wisdom (base64 JSON) to store in the file.
    """
    import base64

    import pyfftw
    from petsc4py import PETSc

    from .contact import ContactProblem
    from .surfaces import wave

    stored = comm.bcast(stored, root=0)
    if stored:
        pyfftw.forget_wisdom()
        pyfftw.import_wisdom(tuple(base64.b64decode(w) for w in json.loads(stored)))
    if comm.Get_rank() < group.Get_size():       # group 0
        grid = s["grid"]
        problem = ContactProblem(grid, wave(grid, 1.0, grid.l1), s["E_star"], PETSc.Comm(group), s["threads"],
                                 s["effort"])
        problem.destroy()
    wisdom = None
    if comm.Get_rank() == 0:
        wisdom = json.dumps([base64.b64encode(w).decode() for w in pyfftw.export_wisdom()])
    wisdom = comm.bcast(wisdom, root=0)
    if comm.Get_rank() != 0:
        pyfftw.forget_wisdom()
        pyfftw.import_wisdom(tuple(base64.b64decode(w) for w in json.loads(wisdom)))
    return wisdom


# ----------------------------------------------------------------------------
# Records and the file
# ----------------------------------------------------------------------------

def solve_surface(reader, s, index, seed, group, run_id, between_steps):
    """Solve one surface on the group communicator; the record (leader) or None (other ranks)."""
    from petsc4py import PETSc

    from . import surfaces
    from .cli import surface_statistics
    from .contact import ContactProblem
    from .control import Solver

    start = time.perf_counter()
    grid, heights = surfaces.from_options(reader, seed=seed)
    problem = ContactProblem(grid, heights, s["E_star"], PETSc.Comm(group), s["threads"], s["effort"])
    solver = None
    try:
        solver = Solver(problem, "load", s["tao_type"], s["rtol"])
        results, reasons = [], []
        for pstar in s["loads"]:
            result = solver.solve(pstar=float(pstar))
            kkt = result.kkt
            results.append([result.pstar, result.pbar, result.A, result.A_corrected, result.gstar, result.gbar,
                            result.separation, result.rms_gap_contact, kkt.natural, kkt.complementarity,
                            kkt.min_p, kkt.min_g, np.nan if kkt.load_error is None else kkt.load_error,
                            result.iterations, result.operator_applications, int(bool(result.converged)),
                            result.time_s])
            reasons.append(str(result.reason))
            between_steps()
    finally:
        if solver is not None:
            solver.destroy()
        problem.destroy()
    if group.Get_rank() != 0:
        return None
    table = np.array(results, dtype=float)
    steps = {name: table[:, j] for j, name in enumerate(STEP_FIELDS)}
    for name in INTEGER_STEP_FIELDS:
        steps[name] = steps[name].astype(np.int64)
    statistics = surface_statistics(grid, heights, s["E_star"])
    surface = {name: float(statistics[name]) for name in SURFACE_FIELDS if name in statistics}
    surface.update(index=index, seed=seed, sqrt_m0h=float(problem.sqrt_m0h), sqrt_m0p=float(problem.sqrt_m0p),
                   converged_steps=int(steps["converged"].sum()), run=run_id,
                   time_s=time.perf_counter() - start)
    return {"surface": surface, "steps": steps, "reason": reasons}


def _statistics(records, n_steps):
    out = {}
    n = len(records)
    for name in STATISTICS:
        table = np.array([r["steps"][name] for r in records], dtype=float).reshape(n, n_steps)
        out[name + "_mean"] = table.mean(axis=0) if n else np.full(n_steps, np.nan)
        out[name + "_std"] = table.std(axis=0, ddof=1) if n > 1 else np.full(n_steps, np.nan)
    out["converged_count"] = np.array([r["steps"]["converged"] for r in records],
                                      dtype=np.int64).reshape(n, n_steps).sum(axis=0)
    for name in ("alpha_h", "alpha_p"):
        values = np.array([r["surface"][name] for r in records], dtype=float)
        out[name + "_mean"] = values.mean() if n else np.nan
        out[name + "_std"] = values.std(ddof=1) if n > 1 else np.nan
    return out


def _kappa(pstar, area):
    """dA*/dp* by second-order finite differences on the (increasing) steps; NaN where undefined."""
    kappa = np.full(pstar.shape, np.nan)
    ok = np.isfinite(area)
    p, a = pstar[ok], area[ok]
    if p.size >= 2 and np.all(np.diff(p) > 0):
        kappa[ok] = np.gradient(a, p, edge_order=2 if p.size >= 3 else 1)
    return kappa


def compute_models(pstar, alpha_h, alpha_p, surface, E_star, names, statistics):
    """The statistical models at the steps' p* with the ensemble's mean bandwidths, and kappa = dA*/dp*."""
    from . import models

    out = {"pstar": pstar, "early": {}, "complete": {}, "kappa": {}, "notes": {}}
    early_steps = pstar <= EARLY_PMAX
    for name in EARLY:
        if name not in names:
            continue
        A, d = np.full(pstar.shape, np.nan), np.full(pstar.shape, np.nan)
        try:
            if early_steps.any():
                d[early_steps], A[early_steps] = models.early_separation(name, pstar[early_steps], alpha_h)
        except ValueError as error:
            out["notes"]["early_" + name] = str(error)
        out["early"][name] = {"A": A, "dstar": d}
        out["kappa"]["early_" + name] = _kappa(pstar, A)
    for name in COMPLETE:
        if name not in names:
            continue
        try:
            A, g = models.complete(name, pstar, alpha_p, alpha_h)
        except ValueError as error:
            out["notes"]["complete_" + name] = str(error)
            A, g = np.full(pstar.shape, np.nan), np.full(pstar.shape, np.nan)
        out["complete"][name] = {"A": A, "gstar": g}
        out["kappa"]["complete_" + name] = _kappa(pstar, A)
    if "persson" in names:
        A = models.persson_area(pstar)
        g = models.persson_gap(pstar, surface["kl"], surface["ks"], surface["H"], surface["m2"], E_star)
        out["persson"] = {"A": A, "gstar": g}
        out["kappa"]["persson"] = _kappa(pstar, A)
    out["kappa"]["bem_A"] = _kappa(pstar, statistics["A_mean"])
    out["kappa"]["bem_A_corrected"] = _kappa(pstar, statistics["A_corrected_mean"])
    return out


def write_file(path, attrs, pstar_target, records, models=None):
    """Write the whole ensemble file to a hidden temporary beside ``path``, fsync it, rename it over ``path``."""
    import h5py

    from . import io

    records = sorted(records, key=lambda r: r["surface"]["index"])
    n, m = len(records), len(pstar_target)
    # Built in memory, then written as bytes: a full disk is then a plain OSError of the write (HDF5
    # writing to a full disk leaves objects whose clean-up prints tracebacks of its own).
    image = BytesIO()
    with h5py.File(image, "w") as f:
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
            data = np.array([r["steps"][field] for r in records], dtype=dtype).reshape(n, m)
            group.create_dataset(field, data=data)
        group.create_dataset("reason", data=np.array([r["reason"] for r in records], dtype=object).reshape(n, m),
                             dtype=h5py.string_dtype())
        group = f.create_group("statistics")
        for key, value in _statistics(records, m).items():
            group.create_dataset(key, data=value)
        if models is not None:
            group = f.create_group("models")
            group.attrs["conventions"] = "p* = pbar/sqrt(m0^p), g* = gbar/sqrt(m0^h), d* = d/sqrt(m0^h)"
            group.attrs["alpha_h"], group.attrs["alpha_p"] = models["alpha_h"], models["alpha_p"]
            group.attrs["early_pmax"] = EARLY_PMAX
            group.attrs["notes"] = json.dumps(models["notes"])
            group.create_dataset("pstar", data=models["pstar"])
            for family in ("early", "complete"):
                for model, curves in models[family].items():
                    for key, value in curves.items():
                        group.create_dataset(f"{family}/{model}/{key}", data=value)
            if "persson" in models:
                for key, value in models["persson"].items():
                    group.create_dataset(f"persson/{key}", data=value)
            for key, value in models["kappa"].items():
                group.create_dataset(f"kappa/{key}", data=value)
    with io.atomic_path(path, durable=True) as temporary, open(temporary, "wb") as f:
        f.write(image.getbuffer())


def read_records(path, config):
    """Finished surfaces of an existing ensemble file (checked against ``config``), its run log and FFTW wisdom.

    Raises :class:`UserError` naming ``-output`` if the file is not an
    ensemble file, cannot be read, or was made by another configuration.
    """
    import h5py

    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") != FORMAT:
                raise UserError(f"-output {path}: the file exists and is not a roughpetsc ensemble file; "
                                f"refusing to overwrite it")
            old = json.loads(f.attrs["config"])
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
    records = []
    for k in range(len(surfaces["index"])):
        surface = {field: (int(surfaces[field][k]) if field in INTEGER_SURFACE_FIELDS else float(surfaces[field][k]))
                   for field in SURFACE_FIELDS}
        record_steps = {field: steps[field][k].copy() for field in STEP_FIELDS}
        reason = [r.decode() if isinstance(r, bytes) else str(r) for r in reasons[k]]
        records.append({"surface": surface, "steps": record_steps, "reason": reason})
    return records, runs, wisdom


def read(path):
    """A whole ensemble file as a flat dict ``{"group/name": value, "@attr": value}`` (for tests and studies)."""
    import h5py

    out = {}
    with h5py.File(path, "r") as f:
        for key, value in f.attrs.items():
            out["@" + key] = value

        def visit(name, item):
            if isinstance(item, h5py.Dataset):
                out[name] = item[()]
            for key, value in item.attrs.items():
                out[f"{name}@{key}"] = value

        f.visititems(visit)
    return out


_RESIDUALS = ("steps/kkt_natural", "steps/kkt_complementarity", "steps/kkt_min_p", "steps/kkt_min_g",
              "steps/kkt_load_error")


def compare(a, b):
    """The largest scaled difference of each quantity of two ensemble files (paths or :func:`read` dicts).

    :data:`VOLATILE` entries, the command and the options are left out. A
    difference is divided by the largest magnitude of its dataset (a standard
    deviation by that of its mean); the scale-free KKT residuals, which are
    round-off noise at a solution, are compared absolutely, and the rms gap in
    contact relative to sqrt(m0^h). Different names, shapes, NaN patterns,
    integers or strings count as ``inf``. "Equal to 1e-12" means every value
    is <= 1e-12.
    """
    a = read(a) if isinstance(a, (str, os.PathLike)) else a
    b = read(b) if isinstance(b, (str, os.PathLike)) else b
    skip = set(VOLATILE) | {"@command", "@options"}
    out = {name: math.inf for name in (set(a) ^ set(b)) - skip}
    for name in sorted((set(a) & set(b)) - skip):
        x, y = a[name], b[name]
        if isinstance(x, np.ndarray) and x.dtype.kind == "f" and np.shape(y) == x.shape:
            if not np.array_equal(np.isnan(x), np.isnan(y)):
                out[name] = math.inf
                continue
            if name in _RESIDUALS:
                scale = 1.0
            elif name == "steps/rms_gap_contact":
                scale = a["surfaces/sqrt_m0h"][:, None]
            else:
                base = name[:-4] + "_mean" if name.startswith("statistics/") and name.endswith("_std") else name
                scale = np.nanmax(np.abs(a[base])) if np.size(a[base]) and np.any(np.isfinite(a[base])) else 1.0
                scale = scale if scale > 0 else 1.0
            difference = np.abs(x - y) / scale
            out[name] = float(np.nanmax(difference)) if np.any(~np.isnan(difference)) else 0.0
        elif isinstance(x, np.ndarray):
            out[name] = 0.0 if np.shape(y) == x.shape and np.array_equal(x, y) else math.inf
        elif isinstance(x, float) and isinstance(y, float):
            same_nan = math.isnan(x) and math.isnan(y)
            out[name] = 0.0 if same_nan else abs(x - y) / (abs(x) or 1.0)
        else:
            out[name] = 0.0 if x == y else math.inf
    return out


# ----------------------------------------------------------------------------
# The run
# ----------------------------------------------------------------------------

def _duration(seconds):
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds}s"
    if seconds < 3600:
        return f"{seconds // 60}m{seconds % 60:02d}s"
    return f"{seconds // 3600}h{seconds // 60 % 60:02d}m"


class Ensemble:
    """State of one ensemble run on every rank; the file and the progress on world rank 0."""

    def __init__(self, reader, comm, s, config):
        from . import io

        self.started = time.perf_counter()
        self.reader, self.s, self.config = reader, s, config
        self.comm = comm.Dup()               # our own messages never meet PETSc's or mpi4py-fft's
        self.rank, self.size = self.comm.Get_rank(), self.comm.Get_size()
        self.quiet = s["quiet"]
        self.records, self.runs, self.wisdom, error = [], [], "", None
        if self.rank == 0:
            try:
                if os.path.exists(s["output"]):
                    self.records, self.runs, self.wisdom = read_records(s["output"], config)
                    io.remove_stale_temporaries(s["output"])
                    beyond = [r["surface"]["index"] for r in self.records if r["surface"]["index"] >= s["size"]]
                    if beyond:
                        raise UserError(f"-ensemble_size {s['size']}: the file {s['output']} already holds "
                                        f"surface index {max(beyond)}; give at least {max(beyond) + 1}")
            except UserError as exc:
                error = str(exc)
        error = self.comm.bcast(error, root=0)
        if error:
            self.comm.Free()
            raise UserError(error)
        finished = set(self.comm.bcast(sorted(r["surface"]["index"] for r in self.records), root=0))
        self.todo = [i for i in range(s["size"]) if i not in finished]
        self.run_id = self.comm.bcast(len(self.runs), root=0)
        self.group_ranks = s["group_ranks"]
        self.groups = self.size // self.group_ranks
        self.group = self.comm.Split(self.rank // self.group_ranks, self.rank)
        self.leader = self.group.Get_rank() == 0
        self.wisdom = share_fftw_wisdom(self.comm, self.group, s, self.wisdom)
        self.counter = WorkCounter(self.comm, self.todo, use_window=os.environ.get(
            "ROUGHPETSC_ENSEMBLE_COUNTER", "window") != "messages")
        self.received = 0              # records of this run that reached rank 0
        self.write_error = None        # rank 0: why the file could not be written (then the run winds down)
        self.expected = len(self.todo)  # rank 0: records to wait for (fewer once the run winds down)
        self.sends = []
        if self.rank == 0:
            provenance = io.provenance()
            grid = s["grid"]
            self.runs.append({"run": self.run_id, "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
                              "ranks": self.size, "group_ranks": self.group_ranks, "command": provenance["command"],
                              "counter": self.counter.mode, "solved": []})
            self.attrs = {
                "format": FORMAT, "ensemble_size": s["size"], "ensemble_seed": s["seed"],
                "seed_rule": "seed_i = SeedSequence(ensemble_seed, spawn_key=(i,)).generate_state(1, uint32)[0] "
                             "& 0x7fffffff; surface = -surface_seed seed_i",
                "loads": s["loads_spec"], "solver": config["solver"], "kkt_rtol": s["rtol"], "E_star": s["E_star"],
                "grid": json.dumps([grid.n0, grid.n1, grid.l0, grid.l1]),
                "conventions": "p* = pbar/sqrt(m0^p), g* = gbar/sqrt(m0^h); A by node count (3.45), A_corrected "
                               "with the perimeter correction; std with ddof = 1",
                "config": json.dumps(config, sort_keys=True), "fftw_wisdom": self.wisdom,
                "command": provenance["command"],
                "options": json.dumps(provenance["options"], sort_keys=True),
                "versions": json.dumps(provenance["versions"], sort_keys=True)}
        io.on_root(self.comm, self.write)  # a file rank 0 cannot write stops every rank, not rank 0 alone

    # --- rank 0: file and progress -------------------------------------------
    def say(self, text):
        if not self.quiet and self.rank == 0:
            print(text, flush=True)

    def write(self, models=None):
        attrs = dict(self.attrs, complete=len(self.records) == self.s["size"], runs=json.dumps(self.runs))
        write_file(self.s["output"], attrs, self.s["loads"], self.records, models)

    def accept(self, record, group):
        """Rank 0: a finished surface (from any group) into the file, and one line of progress."""
        surface = record["surface"]
        self.records.append(record)
        self.runs[-1]["solved"].append(surface["index"])
        self.received += 1
        if self.write_error is None:
            try:
                self.write()
            except UserError as error:  # disk full, say: stop handing out work; the file keeps what it had
                self.write_error = str(error)
                self.expected = self.counter.exhaust()
        elapsed = time.perf_counter() - self.started
        left = len(self.todo) - self.received
        eta = _duration(elapsed / self.received * left) if left else "0s"
        m = len(self.s["loads"])
        flag = "" if surface["converged_steps"] == m else "  SOME STEPS NOT CONVERGED"
        self.say(f"surface {surface['index']:4d} seed {surface['seed']:10d}  group {group:3d}  "
                 f"{surface['time_s']:8.2f} s  {surface['converged_steps']}/{m} steps converged  "
                 f"alpha_h {surface['alpha_h']:.4g} alpha_p {surface['alpha_p']:.4g}  "
                 f"[{len(self.records)}/{self.s['size']} done, ETA {eta}]{flag}")

    def poll(self):
        """Rank 0: take in finished surfaces and work requests from the other groups; True if there were any."""
        from mpi4py import MPI

        status, got = MPI.Status(), False
        while self.comm.Iprobe(MPI.ANY_SOURCE, MPI.ANY_TAG, status):
            source, tag = status.Get_source(), status.Get_tag()
            message = self.comm.recv(source=source, tag=tag)
            if tag == TAG_RECORD:
                self.accept(message, source // self.group_ranks)
            elif tag == TAG_NEXT:
                self.counter.answer(source)
            got = True
        return got

    def _others_pending(self):
        messages = self.counter.mode == "messages" and self.counter.leaders_done < self.groups - 1
        return self.received < self.expected or messages

    # --- every rank ------------------------------------------------------------
    def work(self):
        """Solve surfaces until none is left; rank 0 also collects and writes."""
        between = self.poll if self.rank == 0 else (lambda: None)
        while True:
            k = self.counter.next() if self.leader else None
            k = self.group.bcast(k, root=0)
            if k < 0:
                break
            index = self.todo[k]
            record = solve_surface(self.reader, self.s, index, surface_seed(self.s["seed"], index), self.group,
                                   self.run_id, between)
            if self.rank == 0:
                self.accept(record, 0)
            elif self.leader:
                # Stay until rank 0 has taken the record (it looks between its load steps, so this lasts at
                # most one of its steps). Rank 0 receives with a blocking recv as soon as it sees the message,
                # and a large (rendezvous) message only moves while its sender is inside MPI: a send left
                # pending while this rank solves its next surface kept rank 0 spinning in that recv for the
                # whole surface (half the throughput of a 2-rank run). Test + sleep: no busy wait here either.
                request = self.comm.isend(record, dest=0, tag=TAG_RECORD)
                while not request.Test():
                    time.sleep(IDLE_SLEEP)
        if self.rank == 0:
            while self._others_pending():
                if not self.poll():
                    time.sleep(IDLE_SLEEP)
        # Wait for the others without spinning (a blocking MPI call busy-waits and would take a core
        # from a group still at work when the machine is full).
        requests = self.sends + [self.comm.Ibarrier()]
        while not all(request.Test() for request in requests):
            time.sleep(IDLE_SLEEP)
        self.sends = []

    def finish(self):
        """Rank 0: the final file with statistics and models; returns the exit status on every rank."""
        status = 0
        if self.rank == 0 and self.write_error is not None:
            print(f"roughpetsc: error: {self.write_error}; {self.s['output']} keeps the surfaces it had, and a "
                  "rerun resumes from them", file=sys.stderr, flush=True)
            status = 2
        elif self.rank == 0:
            m = len(self.s["loads"])
            self.records.sort(key=lambda r: r["surface"]["index"])
            models = None
            if len(self.records) == self.s["size"]:
                statistics = _statistics(self.records, m)
                models = compute_models(np.asarray(self.s["loads"], dtype=float), statistics["alpha_h_mean"],
                                        statistics["alpha_p_mean"], self.s["surface"], self.s["E_star"],
                                        self.s["models"], statistics)
                models["alpha_h"], models["alpha_p"] = statistics["alpha_h_mean"], statistics["alpha_p_mean"]
            self.runs[-1]["seconds"] = round(time.perf_counter() - self.started, 3)
            self.write(models)
            bad = sum(m - r["surface"]["converged_steps"] for r in self.records)
            total = m * len(self.records)
            self.say(f"ensemble: {len(self.records)}/{self.s['size']} surfaces, solved {self.received} in this run "
                     f"({_duration(time.perf_counter() - self.started)}); "
                     + (f"all {total} steps converged" if not bad else f"{bad} of {total} steps NOT CONVERGED")
                     + f"; wrote {self.s['output']}")
            status = 3 if bad else 0
        return self.comm.bcast(status, root=0)

    def free(self):
        self.counter.free()
        self.group.Free()
        self.comm.Free()


def run(reader, comm):
    """Entry point of ``python -m roughpetsc -mode ensemble``; returns the exit status (0, or 3 if a step failed)."""
    from .options import check_unused

    s = read_settings(reader, comm.Get_size())
    solver_name = probe_solver(s)
    check_unused()
    config = configuration(s, solver_name)
    ensemble = Ensemble(reader, comm, s, config)
    try:
        ensemble.say(f"ensemble: {s['size']} surfaces ({s['size'] - len(ensemble.todo)} finished in "
                     f"{s['output']}, {len(ensemble.todo)} to solve), {len(s['loads'])} load steps, "
                     f"{s['grid'].n0}x{s['grid'].n1} grid, solver {solver_name}, {ensemble.groups} group(s) of "
                     f"{s['group_ranks']} rank(s), work counter {ensemble.counter.mode}, run {ensemble.run_id}")
        try:
            ensemble.work()
            return ensemble.finish()
        except Exception:     # a failure inside one group would leave the others waiting for ever
            traceback.print_exc()
            sys.stderr.flush()
            comm.Abort(1)
    finally:
        ensemble.free()
