"""``-mode solve``: one surface, a list of loads solved in order by one Solver, the files of the run.

The loads, physics and :data:`SETTINGS_OPTIONS` are read into the frozen :class:`SolveSettings`; the solvers
read their own options. PETSc is imported only when the mode runs (``-help`` prints before PETSc starts).
"""

from dataclasses import fields, make_dataclass
import functools
import os
import sys

import numpy as np

from . import adhesion_options as adhesive_options
from ..errors import UserError
from .terminal import printer
from .settings import (FFT_EFFORT, FFT_THREADS, GENERAL_OPTIONS, KKT_RTOL, OUTPUT, QUIET, check_fft, check_modulus,
                       check_rtol, options_named, read_table)

# Read by read_settings into SolveSettings (besides the loads -pstar, -pbar, -gbar, -pstar_list).
SETTINGS_OPTIONS = [
    KKT_RTOL,
    ("json", "", "write a JSON summary (surface statistics, one entry per load step) to PATH"),
    OUTPUT,
    ("output_fields", "last", "pressure and gap fields in -output: last (of the last step) | all (also every "
                              "step's, in steps/NNN/) | none"),
    ("resume", False, "continue the load path saved in -output: its converged steps for the same problem and "
                      "loads are kept, the rest solved from the last saved pressure"),
    ("plot", "", "write a figure to PATH (.png, .pdf, .svg, ...): pressure and gap maps of the last step, A* "
                 "against p* of a load path"),
    ("progress", "auto", "progress lines of a running load step (its step, inner solve, iteration, KKT residual, "
                         "seconds): auto (only when a person watches: rank 0's output is a terminal, not a pipe or "
                         "a file, also under mpiexec) | on | off"),
    ("progress_interval", 3.0, "seconds between progress lines (> 0)"),
    FFT_THREADS,
    FFT_EFFORT,
    ("fft_wisdom", "", "FFTW wisdom cache that makes measured plans, and so the iterates, repeat from run to run: "
                       "PATH, none, or empty for ~/.cache/roughpetsc/fftw-wisdom-<cpu>.json"),
    QUIET,
]

# The physics beyond the periodic elastic half-space (read into SolveSettings).
PHYSICS_OPTIONS = [
    ("boundary", "periodic", "periodic (the cell repeats, Westergaard (3.33)) | free (an isolated body: Love's "
                             "coefficients (3.31) by FFT on the zero-padded 2N x 2N grid)"),
    ("hardness", 0.0, "hardness H, pressure units: perfect plasticity as the cap 0 <= p <= H (0: no cap); the "
                      "plastic area fraction A_plastic is reported"),
    ("stress_depths", "", "comma-separated depths (length units) at which the six subsurface stresses, the von "
                          "Mises stress and its maximum are computed for the last step and written to -output "
                          "(/stresses; nothing is computed without this option)"),
    ("nu", 0.3, "Poisson's ratio of the body, for -stress_depths"),
] + adhesive_options.OPTIONS

PROGRESS_CHOICES = ("auto", "on", "off")

LOAD_OPTIONS = [
    ("pstar", 0.5, "load control: p* = pbar / sqrt(m0^p) (the default load)"),
    ("pbar", "", "load control: mean pressure pbar, pressure units"),
    ("gbar", "", "displacement control: prescribed mean gap (rigid separation) d, length units"),
    ("pstar_list", "", "load control: p* values solved in order with warm starts: comma-separated, @FILE (numbers "
                       "separated by commas, blanks or lines; # comments), or 'history' (the 95 steps of (7.11), "
                       "D1 = 0.2/30)"),
    ("pbar_list", "", "load control: mean pressures pbar (pressure units) solved in order with warm starts: "
                      "comma-separated or @FILE"),
    ("gbar_list", "", "displacement control: mean gaps (length units) solved in order with warm starts: "
                      "comma-separated or @FILE (an approach and retraction with -adhesion)"),
]

# Each load option: the load it sets (a keyword of Solver.solve); the *_list options give several.
LOAD_KINDS = {"pstar": "pstar", "pbar": "pbar", "gbar": "gbar", "pstar_list": "pstar", "pbar_list": "pbar",
              "gbar_list": "gbar"}

OPTIONS = LOAD_OPTIONS + PHYSICS_OPTIONS + SETTINGS_OPTIONS


def solver_options():
    """The options of the stopping rule and of each backend (imports PETSc: call it once PETSc is initialised)."""
    from ..solvers import cascade, option_tables, stopping

    return stopping.OPTIONS + cascade.OPTIONS + [option for table in option_tables().values() for option in table]

SOLVER_HELP = """Solvers (PETSc options):
  (no -tao_type)          Polonsky-Keer projected CG (TAO type python) with the bound-constrained active set
                          (-pk_active_set bccg), preconditioned by the inverse Westergaard symbol (-pk_pc fourier);
                          load control (-pstar/-pbar) or displacement control (-gbar)
  -tao_type <bound type>  blmvm bqnls bncg bqnkls bqnktr bnls bntr tron gpcg: displacement control directly;
                          load control in the gap, whose gradient is the pressure of the load (-bound_load gap;
                          every type but bncg on the periodic cell without -hardness), by an augmented Lagrangian
                          on the mean pressure inside the solve (-bound_load al; bncg, and where the gap form
                          does not apply), or a safeguarded root find on the mean gap (-bound_load rootfind)
  -tao_type almm          load control by TAO ALMM (-tao_almm_subsolver_tao_type bqnls|blmvm|...)
  with -adhesion          the projected CG on the gap (no -tao_type, or gapcg), or -tao_type almm with the
                          mean-gap equality; displacement control (-gbar, -gbar_list)
  -tao_monitor, -tao_view, -log_view and every other TAO/KSP/PC option work as usual."""


# What ``-mode solve`` was asked to do, checked; fields are named as the options are. ``steps`` are the loads
# ``(kind, value)`` in solve order, ``kind`` one of ``pstar``, ``pbar``, ``gbar``; ``load_option`` the option that
# gave them; ``tao_type`` None for Polonsky-Keer; ``hardness`` None for no cap; the rest as read_physics gives them.
SolveSettings = make_dataclass(
    "SolveSettings",
    [("steps", tuple), ("load_option", str)]
    + [(name, type(default)) for name, default, _ in GENERAL_OPTIONS + SETTINGS_OPTIONS if name != "mode"]
    + [("tao_type", object), ("surface_file", str), ("boundary", str), ("hardness", float),
       ("stress_depths", tuple), ("nu", float), ("adhesion", object), ("adhesion_curvature", bool)],
    frozen=True, namespace={
        # "displacement" for a prescribed mean gap, "load" otherwise.
        "control": property(lambda self: "displacement" if self.steps[0][0] == "gbar" else "load"),
        # Whether each step's pressure and gap are gathered on rank 0 (a plot or fields in -output).
        "gather_fields": property(lambda self: bool(self.plot) or bool(self.stress_depths)
                                  or (bool(self.output) and self.output_fields != "none"))})


def load_steps(reader):
    """The list of loads: ``("pstar" | "pbar" | "gbar", value)`` in the order to solve, and the option."""
    given = [name for name in LOAD_KINDS if reader.hasName(name)]
    if len(given) > 1:
        raise UserError(f"give only one of {', '.join('-' + name for name in LOAD_KINDS)}; got "
                        + ", ".join("-" + g for g in given))
    name = given[0] if given else "pstar"
    kind = LOAD_KINDS[name]
    if name == "pstar_list" and reader.getString(name, "").strip().lower() == "history":
        from ..contact import loads

        return [(kind, float(v)) for v in loads.history()], name
    if name.endswith("_list"):
        return [(kind, v) for v in reader.reals(name)], name
    return [(kind, reader.getReal(name, 0.5))], name


def read_settings(reader, general_options=GENERAL_OPTIONS):
    """The :class:`SolveSettings` of the options database; :class:`UserError` naming the option for a bad value."""
    from ..store.path_record import OUTPUT_FIELDS

    steps, load_option = load_steps(reader)
    for _, value in steps:
        if not (value > 0 and np.isfinite(value)):
            raise UserError(f"-{load_option} must be positive and finite, got {value}")
    names = {field.name for field in fields(SolveSettings)}
    values = {name: value for name, value in read_table(reader, general_options + SETTINGS_OPTIONS).items()
              if name in names}
    settings = SolveSettings(steps=tuple(steps), load_option=load_option,
                             tao_type=reader.getString("tao_type", "") or None,
                             surface_file=reader.getString("surface_file", ""), **values, **read_physics(reader))
    check_rtol(settings.kkt_rtol)
    check_modulus(settings.E_star)
    if settings.output_fields not in OUTPUT_FIELDS:
        raise UserError(f"-output_fields: unknown value '{settings.output_fields}' (one of {', '.join(OUTPUT_FIELDS)})")
    if settings.resume and not settings.output:
        raise UserError("-resume needs -output: the file of the run to continue")
    check_fft(settings.fft_threads, settings.fft_effort)
    if settings.progress not in PROGRESS_CHOICES:
        raise UserError(f"-progress: unknown value '{settings.progress}' (one of {', '.join(PROGRESS_CHOICES)})")
    if not (settings.progress_interval > 0 and np.isfinite(settings.progress_interval)):
        raise UserError(f"-progress_interval must be a positive number of seconds, got {settings.progress_interval} "
                        "(-progress off turns the lines off)")
    if settings.adhesion is not None:
        adhesive_options.check(settings)
    return settings


def read_physics(reader):
    """The values of :data:`PHYSICS_OPTIONS`, checked (``hardness`` None: no cap)."""
    from ..contact.problem import BOUNDARIES
    from ..elastic.stresses import check_depths, check_poisson

    values = read_table(reader, PHYSICS_OPTIONS)
    if values["boundary"] not in BOUNDARIES:
        raise UserError(f"-boundary: unknown boundary '{values['boundary']}' (one of {', '.join(BOUNDARIES)})")
    hardness = values["hardness"]
    if not (hardness >= 0 and np.isfinite(hardness)):
        raise UserError(f"-hardness must be a positive pressure (0: no cap), got {hardness}")
    depths = tuple(reader.reals("stress_depths")) if reader.hasName("stress_depths") else ()
    with options_named():
        if depths:
            check_depths(depths)
        check_poisson(values["nu"])
    return {"boundary": values["boundary"], "hardness": hardness or None, "stress_depths": depths,
            "nu": values["nu"],
            "adhesion": adhesive_options.read_law(values, {name for name in values if reader.hasName(name)}),
            "adhesion_curvature": values["adhesion_curvature"]}


def check_files(settings, comm):
    """Refuse, on every rank, outputs that exist (without -overwrite), overwrite the input or cannot be written.

    Under ``-resume`` the -output file and the -json summary of that load path are meant to exist.
    """
    from ..fft import plans as fftw
    from ..store import outputs as io

    def check():
        may_exist = ("output",) if settings.resume else ()
        if settings.resume and is_summary_of(settings.json, settings.output):
            may_exist += ("json",)
        io.check_outputs(outputs, settings.overwrite, [("surface_file", settings.surface_file)], may_exist)
        fftw.check_wisdom_path(settings.fft_wisdom, "fft_wisdom")

    outputs = [("json", settings.json), ("output", settings.output), ("plot", settings.plot)]
    io.on_root(comm, check)  # checked on rank 0, refused on every rank
    if settings.plot:
        io.check_figure_format(settings.plot, "plot")


def is_summary_of(json_path, h5_path):
    """True if ``json_path`` is a solve-mode summary written by a run whose -output was ``h5_path``."""
    import json

    if not (json_path and h5_path and os.path.isfile(json_path)):
        return False
    try:
        with open(json_path) as handle:
            document = json.load(handle)
        recorded = document["options"]["output"]
    except (OSError, ValueError, KeyError, TypeError):
        return False
    return isinstance(document.get("steps"), list) and isinstance(recorded, str) and \
        os.path.realpath(recorded) == os.path.realpath(h5_path)


class StepLines:
    """The lines of finished steps: with ``hold`` (output files) each waits for the checkpoint that writes it,
    so an interrupted run has written every step it printed."""

    def __init__(self, say, hold):
        self.say, self.hold, self.pending = say, hold, []

    def add(self, text):
        if self.hold:
            self.pending.append(text)
        else:
            self.say(text)

    def flush(self):
        """Print the lines held so far (their steps are now in the files)."""
        for text in self.pending:
            self.say(text)
        self.pending = []


def progress_printer(settings, comm):
    """The progress lines of a running step on rank 0, or None (``-progress auto``: when a person watches)."""
    from .progress import Progress
    from .terminal import watched

    if comm.Get_rank() != 0 or settings.quiet or settings.progress == "off":
        return None
    if settings.progress == "auto" and not watched(sys.stdout):
        return None
    return Progress(settings.progress_interval, sys.stdout)


def run(reader, comm):
    """Solve the loads of the options on the surface of the options; the exit status (0, 3 or 130).

    Ctrl-C and SIGTERM stop every rank at the same iteration; the files keep every step whose line was printed.
    """
    from .interrupts import StopRequests

    settings = read_settings(reader)
    check_files(settings, comm)
    with StopRequests() as requests:
        return solve_settings(settings, reader, comm, requests)


def build_problem(settings, reader, comm):
    """``(grid, heights, problem, levelling)`` of the options; ``levelling`` None for a generated surface."""
    from petsc4py import PETSc

    from ..fft import plans as fftw
    from . import surface_options
    from ..contact.problem import ContactProblem
    from ..parallel import row_split

    effort = fftw.planner_effort(settings.fft_effort)
    wisdom = fftw.wisdom_path(settings.fft_wisdom)
    if not settings.surface_file:
        # Before the surface is built: a grid with fewer rows than ranks is refused by name.
        row_split(surface_options.grid_from_options(reader).n0, comm.Get_size())
    levelling = []
    grid, heights = surface_options.from_options(reader, notes=levelling)
    with fftw.remembered_plans(comm, wisdom, effort), options_named():
        problem = ContactProblem(grid, heights, settings.E_star, PETSc.COMM_WORLD, settings.fft_threads, effort,
                                 boundary=settings.boundary, hardness=settings.hardness)
    return grid, heights, problem, (levelling[0] if levelling else None)


def solve_settings(settings, reader, comm, requests):
    """:func:`run` once the settings and files are checked; ``requests`` the :class:`StopRequests` of the run."""
    from ..store import outputs as io
    from .. import store
    from . import surface_options
    from .options import check_unused
    from ..store.path_record import PathRecord
    from ..surface.moments import surface_moments

    say = printer(settings.quiet, comm)
    grid, heights, problem, levelling = build_problem(settings, reader, comm)
    solver = None
    try:
        problem.stop_requested = requests.is_set
        problem.progress = progress_printer(settings, comm)
        statistics = surface_moments(grid, heights, settings.E_star)
        solver = make_solver(settings, problem)
        unusable = solver.unusable_options()
        check_unused(final=False, unusable=unusable)  # misspellings fail now; those read after a solve, then
        summary = {"grid": [grid.n0, grid.n1], "length": [grid.l0, grid.l1], "E_star": settings.E_star,
                   "surface": statistics,
                   "surface_parameters": dict(surface_options.parameters(reader), surface_L=grid.l1),
                   "sqrt_m0h": problem.sqrt_m0h, "sqrt_m0p": problem.sqrt_m0p,
                   "solver": solver.name, "control": settings.control, "kkt_rtol": settings.kkt_rtol,
                   "boundary": settings.boundary, "hardness": settings.hardness or 0.0,
                   "adhesion": adhesive_options.summary(settings.adhesion, statistics, settings.E_star),
                   "ranks": comm.Get_size(), **io.provenance()}
        if levelling is not None:
            summary["surface_levelling"] = levelling.record()
        # Fields written by every rank into its rows where h5py is the parallel build (store.write_distributed).
        distributed = bool(settings.output) and settings.output_fields != "none" and store.parallel_hdf5(comm)
        rows = problem.local_rows
        record = PathRecord(summary, heights, settings.output_fields,
                            *((rows.start, rows.stop - rows.start) if distributed else ()))
        if settings.resume and os.path.exists(settings.output):
            start_resumed_path(settings, record, problem, solver)
        announce = functools.partial(report_interruption, settings, record)
        if comm.Get_rank() == 0 and (settings.output or settings.json):
            # Printed as soon as a signal comes: once it is, no file is replaced (StopRequests). Without
            # files, a step that finishes after the signal is printed, so the line waits for the stop.
            requests.announcement = announce
            requests.announce_once()
        say_header(settings, grid, problem, solver, statistics, summary, say)
        if levelling is not None:
            report_levelling(levelling, settings.surface_file, say, comm)
        for step in record.steps:
            say(step_line(step) + f"  (from {settings.output})")
        lines = StepLines(say, hold=bool(settings.output or settings.json))
        if solve_path(settings, solver, record, comm, lines, requests, problem.progress):
            io.on_root(comm, requests.request_stop, announce)
            return 130
        if settings.adhesion is not None:
            adhesive_options.close_cycle(record, lines.add)
        whole = whole_last_fields(record, comm, distributed, settings)
        if settings.stress_depths:
            for text in io.on_root(comm, record_stresses, settings, record, grid, whole) or ():
                lines.add(text)
        if not write_files(settings, record, comm, requests):  # a stop was requested before they were replaced
            io.on_root(comm, requests.request_stop, announce)
            return 130
        io.on_root(comm, plot_outputs, settings, record, grid, whole)
        lines.flush()
        return 0 if all(step["converged"] for step in record.steps) else 3
    finally:
        if solver is not None:
            solver.destroy()
        problem.destroy()


def start_resumed_path(settings, record, problem, solver):
    """Take the steps of -output that -resume continues, and start the next solve where they end.

    A contact path starts from the last saved pressure (a warm start; the solution does not depend on it). An
    adhesive path continues from the gap of the last step taken, exactly: which branch it follows depends on
    its history, so a file without that gap is refused rather than restarted from the rigid gap.
    """
    pressure, gap = record.resume_from(settings.output, list(settings.steps), settings.load_option)
    if settings.adhesion is None:
        if pressure is not None:  # the next solve scales it to its load (Solver's warm start)
            problem.local(solver.pressure)[...] = pressure[problem.local_rows] / problem.pressure_scale
        return
    if not record.steps:
        return  # nothing taken: the path starts afresh, from the rigid gap
    if gap is None:
        raise UserError(f"-resume: {settings.output} does not hold the gap of step {len(record.steps)}, the last "
                        "one taken, and an adhesive path continues from it (its branch depends on its history). "
                        "The gap is kept with -output_fields all, or with -output_fields last once every step "
                        "converged")
    solver.resume(gap[problem.local_rows])


def say_header(settings, grid, problem, solver, statistics, summary, say):
    """The header of the step table: the problem, the solver, the surface's bandwidths, the column names."""
    cap = f", hardness {settings.hardness:g}" if settings.hardness else ""
    say(f"roughpetsc: {grid.n0}x{grid.n1} grid ({settings.boundary}{cap}) on {problem.mpi.Get_size()} rank(s), "
        f"solver {solver.name}, E*={settings.E_star:g}, sqrt(m0h)={problem.sqrt_m0h:.4g}, "
        f"sqrt(m0p)={problem.sqrt_m0p:.4g}, alpha_h={statistics['alpha_h']:.4g}, "
        f"alpha_p={statistics['alpha_p']:.4g}")
    if settings.adhesion is not None:
        say(adhesive_options.header(settings.adhesion, summary["adhesion"]))
    say(f"{'p*':>10} {'A*':>10} {'A*corr':>10} {'g*':>11} {'KKT nat':>9} {'its':>6} {'Kapps':>6} "
        f"{'time s':>8}  reason")


def report_levelling(levelling, path, say, comm):
    """Rank 0: what levelling a surface file did (stdout) and its warnings (stderr), one line each."""
    for note in levelling.notes:
        if note.startswith("warning: ") and comm.Get_rank() == 0:
            print(f"roughpetsc: warning: -surface_file {path}: {note[len('warning: '):]}", file=sys.stderr, flush=True)
        elif not note.startswith("warning: "):
            say(f"  surface: {note}")


def report_interruption(settings, record):
    """Rank 0: the one line of an interrupted run, naming what the files hold (nothing is written after it)."""
    files = " and ".join(path for path in (settings.output, settings.json) if path)
    held = record.written
    if files and held:
        kept = f"; {files} {'keep' if ' and ' in files else 'keeps'} them"
        kept += " (rerun with -resume to continue)" if settings.output else ""
    else:
        kept = "; nothing was written" if files else ""
    unsaved = len(record.steps) - held if files else 0
    if unsaved > 0:
        kept += f"; {unsaved} later step(s) finished but not yet saved are solved again by a rerun"
    print(f"roughpetsc: interrupted after {held if files else len(record.steps)} of {len(settings.steps)} "
          f"step(s){kept}", file=sys.stderr, flush=True)


def make_solver(settings, problem):
    """The Solver of ``-tao_type`` for the problem of the options: ``problem``, or its adhesive one (``-adhesion``)."""
    from ..contact.adhesive import AdhesiveProblem
    from ..solvers import Solver

    with options_named():
        physics = problem if settings.adhesion is None else AdhesiveProblem(problem, settings.adhesion)
        if settings.adhesion is not None:
            physics.check_curvature = settings.adhesion_curvature
        return Solver(physics, settings.control, settings.tao_type, settings.kkt_rtol)


def whole_last_fields(record, comm, distributed, settings):
    """The last step's whole pressure and gap on rank 0 (collective), for the figure and the stresses."""
    from ..parallel import gather_rows

    if not distributed:
        return record.last_fields
    if not (settings.plot or settings.stress_depths) or not record.last_fields:
        return {}
    return {name: gather_rows(comm, array) for name, array in record.last_fields.items()}


def record_stresses(settings, record, grid, fields):
    """The subsurface stresses of the last step at ``settings.stress_depths`` into ``record`` (rank 0); their lines."""
    from ..elastic.stresses import free_stresses, periodic_stresses

    pressure = fields.get("pressure")
    if pressure is None:
        raise UserError("-stress_depths: the last step's pressure field is not available (all steps taken from a "
                        "file without fields)")
    if settings.boundary == "periodic":
        depths = periodic_stresses(pressure, (grid.l0, grid.l1), settings.stress_depths, settings.nu,
                                   settings.fft_effort)
    else:
        depths = free_stresses(pressure, (grid.l0 / grid.n0, grid.l1 / grid.n1), settings.stress_depths,
                               settings.nu, settings.fft_effort)
    record.stresses = list(depths)
    return [f"  stresses at depth {depth.depth:.4g}: max von Mises {depth.max_von_mises:.4g} at node "
            f"{depth.max_location}" for depth in record.stresses]


def plot_outputs(settings, record, grid, fields):
    """The figure of the run on rank 0; ``fields``: the last step's whole fields."""
    from . import plots

    if settings.plot and not fields:  # every step taken from a file without fields
        print(f"roughpetsc: -plot: no fields to plot in {settings.output} (-output_fields none)", file=sys.stderr)
    elif settings.plot:
        adhesion = record.summary["adhesion"] if settings.adhesion is not None else None
        plots.plot_solution(settings.plot, grid, fields["pressure"], fields["gap"], record.steps, adhesion)


def step_line(step):
    """The table row of a step summary."""
    flag = "" if step["converged"] else "  NOT CONVERGED"
    plastic = f"  A_plastic {step['A_plastic']:.5g}" if step.get("A_plastic") else ""
    coarse = step.get("cascade_applications")
    cascade = f"  + {coarse:.1f} Kapps of the coarse start (in fine-grid Kapps)" if coarse else ""
    split = step.get("split_applications")
    cascade += f"  + {split:.2f} Kapps of the split corrections (in fine-grid Kapps)" if split else ""
    return (f"{step['pstar']:10.5g} {step['A']:10.5g} {step['A_corrected']:10.5g} {step['gstar']:11.5g} "
            f"{step['kkt']['natural']:9.2e} {step['iterations']:6d} {step['operator_applications']:6d} "
            f"{step['time_s']:8.3f}  {step['reason']}{flag}{plastic}{cascade}")


def solve_path(settings, solver, record, comm, lines, requests, progress=None):
    """Solve the loads of ``settings.steps`` not yet in ``record``, recording each and checkpointing the files.

    Fields are gathered on rank 0 (``settings.gather_fields``) or kept as this rank's rows
    (``record.first_row``). Unused options are refused after the first solve, before any file is written.
    Returns True when a stop was requested on any rank: the running step is dropped, nothing more written.
    """
    from .interrupts import agreed
    from .options import check_unused
    from ..parallel import gather_rows
    from ..solvers import drive

    steps = settings.steps
    state = {"checked": False}

    class Stopped(Exception):
        """A stop was requested: the step that was running is dropped, nothing more is written."""

    def starting(index, kind, value):
        if agreed(comm, requests.is_set()):
            raise Stopped
        if progress is not None:
            progress.start_step(index, len(steps), kind, value)

    def finished(index, kind, value, result):
        if agreed(comm, requests.is_set()) and not result.converged:
            raise Stopped  # stopped by the request: solved again by a rerun
        solver_ran = not result.reason.startswith("COMPLETE_CONTACT")  # the exact answer runs no TAO
        if not state["checked"]:
            # Once a TAO solve has run, every option must have been read; before, only those that are
            # not read during or after a solve (a path wholly beyond complete contact runs none).
            check_unused(final=solver_ran)
            state["checked"] = solver_ran
        if record.first_row is not None:
            fields = [field.copy() for field in solver.fields()]
        elif settings.gather_fields:
            fields = [gather_rows(comm, field) for field in solver.fields()]
        else:
            fields = [None, None]
        record.add(dict(result.summary(), load_option=kind, load_value=value), result.history, *fields)
        lines.add(step_line(result.summary()))
        # Not before every option is known to be used: a run refused for an unused option writes nothing.
        if state["checked"] and index < len(steps) - 1 and checkpoint(settings, record, comm, requests):
            lines.flush()

    try:
        for _ in drive(solver, steps, on_step=finished, first=len(record.steps), on_start=starting):
            pass
    except Stopped:
        return True
    return False


def checkpoint(settings, record, comm, requests):
    """Rewrite -output and -json with the steps so far when rank 0's clock says so, not after a stop request;
    True if they were written. Every rank takes part."""
    if not (settings.output or settings.json) or not comm.bcast(record.due() and not requests.is_set(), root=0):
        return False
    return write_files(settings, record, comm, requests)


def write_files(settings, record, comm, requests):
    """Write -output and -json with the steps so far (every rank its rows, else rank 0); True if replaced."""
    from ..store import outputs as io

    if record.first_row is not None:
        replaced = record.write(settings.output, settings.json, requests, comm=comm)
    else:
        replaced = io.on_root(comm, record.write, settings.output, settings.json, requests)
    return comm.bcast(replaced, root=0)
