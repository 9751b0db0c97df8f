"""The command line: options database in, a run out.

    mpiexec -n 2 python -m roughpetsc                     # the embedded default problem
    mpiexec -n 2 python -m roughpetsc -tao_type bqnls     # load control: root find around BQNLS
    python -m roughpetsc -pstar_list 0.1,0.5,1 -json out.json -output out.h5

Exit status: 0 success, 2 bad input (one message, no traceback, no output
file), 3 a solve did not converge (reported as such; files are written and
flag it), 130 interrupted by Ctrl-C or SIGTERM (the finished steps are written;
-resume continues).
"""

import os
import signal
import sys
import time
import traceback

import numpy as np

from .errors import UserError

MODES = ("solve", "stats", "models", "ensemble")

GENERAL_OPTIONS = [
    ("mode", "solve", "solve | stats | models | ensemble"),
    ("E_star", 1.0, "composite modulus E* (1.6), pressure units"),
    ("overwrite", False, "replace existing output files (without it an existing file is refused, never replaced)"),
]

SOLVE_OPTIONS = [
    ("pstar", 0.5, "load control: p* = pbar / sqrt(m0^p) (the default load)"),
    ("pbar", "", "load control: mean pressure pbar, pressure units"),
    ("gbar", "", "displacement control: prescribed mean gap (rigid separation) d, length units"),
    ("pstar_list", "", "load control: comma-separated p* values solved in order with warm starts, or 'history' "
                       "(the 95 steps of (7.11), D1 = 0.2/30)"),
    ("kkt_rtol", 1e-8, "stop when the natural KKT residual ||min(p/pbar, g/sqrt(m0h))||_inf <= this"),
    ("solve_max_time", 0.0, "stop a solve after this many seconds, reported as DIVERGED_USER (0: no limit)"),
    ("json", "", "write a JSON summary (surface statistics, one entry per load step) to PATH"),
    ("output", "", "write an HDF5 file to PATH: heights, the fields of -output_fields, each step's results and "
                   "residual history, units and descriptions; a load path is saved as its steps finish"),
    ("output_fields", "last", "pressure and gap fields in -output: last (of the last step) | all (also every "
                              "step's, in steps/NNN/) | none"),
    ("resume", False, "continue the load path saved in -output: its converged steps for the same problem and "
                      "loads are kept, the rest solved from the last saved pressure"),
    ("plot", "", "write a figure to PATH (.png, .pdf, .svg, ...): pressure and gap maps of the last step, A* "
                 "against p* of a load path"),
    ("progress_interval", 3.0, "on a terminal, print iteration, KKT residual and elapsed time of a running solve "
                               "every this many seconds (0: never; never when stdout is not a terminal)"),
    ("pk_pc", "fourier", "Polonsky-Keer preconditioner: fourier (inverse symbol pi E*|k| on the contact set) | none"),
    ("pk_active_set", "bccg", "Polonsky-Keer active set: bccg (overlapping nodes join the free set, Polak-Ribiere "
                              "without restarts) | pk (as published: nodes enter after the step, CG restarts)"),
    ("pk_refresh", 50, "Polonsky-Keer: recompute K p from scratch at least every this many iterations"),
    ("bound_pc", "", "TAO bnls/bntr/bntl/tron/gpcg: fourier (inverse symbol on the free set; default of the BNK "
                     "types) | none (default of tron, gpcg) | options (-tao_*pc_type decides)"),
    ("fft_threads", 1, "FFTW threads on one rank"),
    ("fft_effort", "FFTW_MEASURE", "FFTW planner effort: FFTW_ESTIMATE | FFTW_MEASURE | FFTW_PATIENT "
                                   "(measured plans are remembered, see -fft_wisdom)"),
    ("fft_wisdom", "", "FFTW wisdom cache that makes measured plans, and so the iterates, repeat from run to run: "
                       "PATH, none, or empty for ~/.cache/roughpetsc/fftw-wisdom-<cpu>.json"),
    ("quiet", False, "print nothing but errors"),
]

SOLVER_HELP = """Solvers (PETSc options):
  (no -tao_type)          Polonsky-Keer projected CG (TAO type python) with the bound-constrained active set
                          (-pk_active_set bccg), preconditioned by the inverse Westergaard symbol (-pk_pc fourier);
                          load control (-pstar/-pbar) or displacement control (-gbar)
  -tao_type <bound type>  blmvm bqnls bncg bqnkls bqnktr bnls bntr tron gpcg: displacement control directly,
                          load control by a safeguarded root find on the mean gap around that type
  -tao_type almm          load control by TAO ALMM (-tao_almm_subsolver_tao_type bqnls|blmvm|...)
  -tao_monitor, -tao_view, -log_view and every other TAO/KSP/PC option work as usual."""


def _mode_modules():
    """Option tables of the other modes (their modules are imported only if present)."""
    tables = {}
    for mode, module in (("stats", "roughpetsc.stats_mode"), ("models", "roughpetsc.models.mode"),
                         ("ensemble", "roughpetsc.ensemble")):
        try:
            tables[mode] = __import__(module, fromlist=["OPTIONS"])
        except ImportError:
            pass
    return tables


def all_option_names(tables):
    from .surfaces import SURFACE_OPTIONS

    names = {name for name, _, _ in GENERAL_OPTIONS + SOLVE_OPTIONS + SURFACE_OPTIONS}
    for module in tables.values():
        names.update(name for name, _, _ in module.OPTIONS)
    return names


def format_help(title, option_table):
    """Lines of -help for a table of ``(name, default, help)``."""
    lines = [title]
    for name, default, text in option_table:
        lines.append(f"  -{name} <{default}>: {text}")
    return "\n".join(lines)


# The folder holding the package: the presets solvers/*.opts and options/*.opts live there.
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PRESET_FOLDERS = ("solvers", "options")


def presets_help():
    """The -help block listing the preset files."""
    lines = [f"Presets (-options_file FOLDER/NAME.opts; looked up in the current folder, then in {ROOT}):"]
    for folder in PRESET_FOLDERS:
        names = sorted(name[:-5] for name in os.listdir(os.path.join(ROOT, folder)) if name.endswith(".opts")) \
            if os.path.isdir(os.path.join(ROOT, folder)) else []
        lines.append(f"  {folder}/: " + (" ".join(names) or "(none installed)"))
    return "\n".join(lines)


def print_help(tables):
    """Our options and the presets. Runs before PETSc is initialised, so it comes before PETSc's own -help."""
    from .surfaces import SURFACE_OPTIONS

    blocks = [format_help("roughpetsc options (python -m roughpetsc [options]; PETSc's options follow):",
                          GENERAL_OPTIONS),
              format_help("Surface:", SURFACE_OPTIONS), format_help("Mode solve:", SOLVE_OPTIONS), SOLVER_HELP]
    for mode, module in tables.items():
        blocks.append(format_help(f"Mode {mode}:", module.OPTIONS))
    blocks.append(presets_help())
    print("\n\n".join(blocks) + "\n", flush=True)


def resolve_presets(argv):
    """``argv`` with each ``-options_file PATH`` not found here resolved against :data:`ROOT`.

    PETSc reads the files when it is initialised, so this runs before; a
    preset named from another folder (``-options_file solvers/pk.opts``) or by
    its bare name (``-options_file pk``) is found in the repository. Returns
    ``(argv, message)``: a file found nowhere is dropped from ``argv`` and
    ``message`` names it (raised once PETSc can report it on rank 0).
    """
    resolved, message = list(argv[:1]), None
    items = iter(argv[1:])
    for item in items:
        if item not in ("-options_file", "--options_file"):
            resolved.append(item)
            continue
        path = next(items, "")
        candidates = [path, os.path.join(ROOT, path)]
        candidates += [os.path.join(ROOT, folder, name) for folder in PRESET_FOLDERS
                       for name in (path, path + ".opts")]
        found = next((c for c in candidates if path and os.path.isfile(c)), None)
        if found is None:
            message = message or (f"-options_file {path}: no such file (looked in the current folder and in {ROOT}; "
                                  f"-help lists the presets)" if path else "-options_file: give a file name")
            continue
        resolved += [item, found]
    return resolved, message


def launcher_rank():
    """This process's MPI rank as the launcher tells it (MPI is not initialised yet); 0 if not under mpiexec."""
    for name in ("OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"):
        if os.environ.get(name, "").isdigit():
            return int(os.environ[name])
    return 0


# Measured peak of a solve (studies/output/memory.md): at most 40 doubles per grid point of a rank.
PEAK_BYTES_PER_POINT = 40 * 8


def available_memory():
    """MemAvailable of /proc/meminfo in bytes, or None where there is no such file."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def check_memory(reader, comm, mode):
    """Refuse, before anything is allocated, a generated surface too large for this machine's memory.

    The estimate is :data:`PEAK_BYTES_PER_POINT` per grid point held by a
    rank (a slab of the grid in a solve, a whole surface per rank in stats,
    a slab per group in an ensemble), summed over the ranks of this host.
    Surfaces read from a file are not estimated (reading it is the test).
    """
    from mpi4py import MPI

    from . import surfaces

    if mode not in ("solve", "stats", "ensemble") or reader.string("surface_file", ""):
        return
    grid = surfaces.grid_from_options(reader)
    share = {"solve": comm.Get_size(), "stats": 1, "ensemble": max(1, reader.int("ensemble_group_ranks", 1))}[mode]
    host = comm.Split_type(MPI.COMM_TYPE_SHARED)
    ranks_here = host.Get_size()
    host.Free()
    needed = PEAK_BYTES_PER_POINT * grid.n0 * grid.n1 / share * ranks_here
    available = available_memory()
    if available is not None and needed > available:
        raise UserError(f"-surface_N: a {grid.n0}x{grid.n1} grid needs about {needed / 2**30:.3g} GiB "
                        f"({ranks_here} rank(s) on this machine, {PEAK_BYTES_PER_POINT // 8} doubles per grid "
                        f"point of a rank) but {available / 2**30:.3g} GiB are available; use a smaller grid or "
                        f"more machines")


def surface_statistics(grid, heights, E_star):
    """Spectral moments of h (n = 0..6) and of p_c (n = 0..4), x/y averaged, and alpha^h, alpha^p (2.16, 2.54)."""
    from . import spectra

    mh = spectra.isotropic_mean(spectra.spectral_moments(grid, heights))
    pressure = spectra.pressure_surface(grid, heights, E_star)
    mp = spectra.isotropic_mean(spectra.spectral_moments(grid, pressure, (0, 2, 4)))
    statistics = {f"m{n}h": mh[n] for n in sorted(mh)}
    statistics.update({f"m{n}p": mp[n] for n in sorted(mp)})
    statistics["alpha_h"] = spectra.bandwidth(mh[0], mh[2], mh[4])
    statistics["alpha_p"] = spectra.bandwidth(mp[0], mp[2], mp[4])
    return statistics


def load_steps(reader):
    """The list of loads: ``("pstar" | "pbar" | "gbar", value)`` in the order to solve."""
    given = [name for name in ("pstar", "pbar", "gbar", "pstar_list") if reader.has(name)]
    if len(given) > 1:
        raise UserError("give only one of -pstar, -pbar, -gbar, -pstar_list; got " + ", ".join("-" + g for g in given))
    if given == ["pstar_list"]:
        if reader.string("pstar_list", "").strip().lower() == "history":
            from . import loads

            return [("pstar", float(v)) for v in loads.history()], "pstar_list"
        values = reader.reals("pstar_list")
        return [("pstar", v) for v in values], "pstar_list"
    name = given[0] if given else "pstar"
    value = reader.real(name, 0.5)
    return [(name, value)], name


def _check_loads(steps, option):
    for kind, value in steps:
        if not (value > 0 and np.isfinite(value)):
            raise UserError(f"-{option} must be positive and finite, got {value}")


def _gather_rows(comm, local):
    """The whole array on rank 0 (None elsewhere) from each rank's rows."""
    if comm.Get_size() == 1:
        return np.array(local)
    parts = comm.gather(np.ascontiguousarray(local), root=0)
    return np.concatenate(parts, axis=0) if comm.Get_rank() == 0 else None


def run_solve(reader, comm, say):
    from petsc4py import PETSc

    from . import fftw, io, plots, surfaces
    from .slab import row_split
    from .contact import ContactProblem
    from .control import Solver
    from .kkt import Progress
    from .options import check_unused
    from .results import OUTPUT_FIELDS, PathRecord

    steps, load_option = load_steps(reader)
    _check_loads(steps, load_option)
    rtol = reader.real("kkt_rtol", 1e-8)
    if not 0 < rtol < 1:
        raise UserError(f"-kkt_rtol must lie in (0, 1), got {rtol}")
    E_star = reader.real("E_star", 1.0)
    json_path, h5_path = reader.string("json", ""), reader.string("output", "")
    plot_path = reader.string("plot", "")
    # Checked on rank 0, refused on every rank; the file of -output is meant to exist with -resume.
    outputs = [("json", json_path), ("output", h5_path), ("plot", plot_path)]
    inputs = [("surface_file", reader.string("surface_file", ""))]
    io.on_root(comm, io.check_outputs, outputs, reader.bool("overwrite", False), inputs,
               ("output",) if reader.bool("resume", False) else ())
    if plot_path:
        io.check_figure_format(plot_path, "plot")
    keep_fields = reader.string("output_fields", "last")
    if keep_fields not in OUTPUT_FIELDS:
        raise UserError(f"-output_fields: unknown value '{keep_fields}' (one of {', '.join(OUTPUT_FIELDS)})")
    resume = reader.bool("resume", False)
    if resume and not h5_path:
        raise UserError("-resume needs -output: the file of the run to continue")
    progress_interval = reader.real("progress_interval", 3.0)
    threads = reader.int("fft_threads", 1)
    if threads < 1:
        raise UserError(f"-fft_threads must be at least 1, got {threads}")
    effort = fftw.planner_effort(reader.string("fft_effort", "FFTW_MEASURE"))
    wisdom = fftw.wisdom_path(reader.string("fft_wisdom", ""))
    tao_type = reader.string("tao_type", "") or None

    if not reader.string("surface_file", ""):
        # Before the surface is built: a grid with fewer rows than ranks is refused by name.
        row_split(surfaces.grid_from_options(reader).n0, comm.Get_size())
    grid, heights = surfaces.from_options(reader)
    with fftw.remembered_plans(comm, wisdom, effort):
        problem = ContactProblem(grid, heights, E_star, PETSc.COMM_WORLD, threads, effort)
    statistics = surface_statistics(grid, heights, E_star)
    control = "displacement" if steps[0][0] == "gbar" else "load"
    solver = Solver(problem, control, tao_type, rtol)
    rank0 = comm.Get_rank() == 0
    if progress_interval > 0 and rank0 and not reader.bool("quiet", False) and sys.stdout.isatty():
        problem.progress = Progress(progress_interval, sys.stdout)
    # A batch system's time limit (SIGTERM) ends the run like Ctrl-C: the finished steps are kept.
    previous_sigterm = signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        check_unused(final=False)  # misspellings fail now; options PETSc reads after a solve are checked then
        summary = {"grid": [grid.n0, grid.n1], "length": [grid.l0, grid.l1], "E_star": E_star,
                   "surface": statistics, "surface_parameters": dict(surfaces.parameters(reader), surface_L=grid.l1),
                   "sqrt_m0h": problem.sqrt_m0h, "sqrt_m0p": problem.sqrt_m0p,
                   "solver": solver.name, "control": control, "kkt_rtol": rtol, "ranks": comm.Get_size(),
                   **io.provenance()}
        record = PathRecord(summary, heights, keep_fields)
        if resume and os.path.exists(h5_path):
            start = record.resume_from(h5_path, steps)
            if start is not None:  # the next solve scales it to its load (Solver's warm start)
                problem.local(solver.pressure)[...] = start[problem.local_rows] / problem.pressure_scale
        say(f"roughpetsc: {grid.n0}x{grid.n1} grid on {comm.Get_size()} rank(s), solver {solver.name}, "
            f"E*={E_star:g}, sqrt(m0h)={problem.sqrt_m0h:.4g}, sqrt(m0p)={problem.sqrt_m0p:.4g}, "
            f"alpha_h={statistics['alpha_h']:.4g}, alpha_p={statistics['alpha_p']:.4g}")
        say(f"{'p*':>10} {'A*':>10} {'A*corr':>10} {'g*':>11} {'KKT nat':>9} {'its':>6} {'Kapps':>6} "
            f"{'time s':>8}  reason")
        for step in record.steps:
            say(_step_line(step) + f"  (from {h5_path})")
        try:
            gather = bool(plot_path) or (bool(h5_path) and keep_fields != "none")
            _solve_path(steps, solver, record, comm, say, h5_path, gather)
        except KeyboardInterrupt:
            if rank0 and record.steps:
                record.write(h5_path, json_path)
            if rank0:
                kept = f"; {h5_path} keeps them (rerun with -resume to continue)" if h5_path and record.steps else ""
                print(f"roughpetsc: interrupted after {len(record.steps)} of {len(steps)} step(s){kept}",
                      file=sys.stderr, flush=True)
            return 130
        def write_outputs():  # on rank 0; a failure there is every rank's error (io.on_root)
            record.write(h5_path, json_path)
            if plot_path and not record.last_fields:  # every step taken from a file without fields
                print(f"roughpetsc: -plot: no fields to plot in {h5_path} (-output_fields none)", file=sys.stderr)
            elif plot_path:
                plots.plot_solution(plot_path, grid, record.last_fields["pressure"], record.last_fields["gap"],
                                    record.steps)
        io.on_root(comm, write_outputs)
        return 0 if all(step["converged"] for step in record.steps) else 3
    finally:
        signal.signal(signal.SIGTERM, previous_sigterm)
        solver.destroy()
        problem.destroy()


def _step_line(step):
    """The table row of a step summary."""
    flag = "" if step["converged"] else "  NOT CONVERGED"
    return (f"{step['pstar']:10.5g} {step['A']:10.5g} {step['A_corrected']:10.5g} {step['gstar']:11.5g} "
            f"{step['kkt']['natural']:9.2e} {step['iterations']:6d} {step['operator_applications']:6d} "
            f"{step['time_s']:8.3f}  {step['reason']}{flag}")


def _solve_path(steps, solver, record, comm, say, h5_path, gather):
    """Solve the loads of ``steps`` not yet in ``record``, recording each and checkpointing ``h5_path``.

    ``gather``: gather the pressure and gap of each step on rank 0 for the record.
    Every option must have been used once the first solve is done (PETSc
    reads viewers and converged reasons during and after TAOSolve); the check
    runs then, before any file is written.
    """
    from petsc4py import PETSc

    from . import io
    from .options import check_unused

    checked = False
    for index, (kind, value) in enumerate(steps):
        if index < len(record.steps):
            continue
        stage = PETSc.Log.Stage(f"RP step {index:03d} {kind}={value:g}")  # -log_view: one stage per load
        stage.push()
        try:
            result = solver.solve(**{kind: value})
        finally:
            stage.pop()
        solver_ran = not result.reason.startswith("COMPLETE_CONTACT")  # the exact answer runs no TAO
        if not checked:
            # Once a TAO solve has run, every option must have been read; before, only those that are
            # not read during or after a solve (a path wholly beyond complete contact runs none).
            check_unused(final=solver_ran)
            checked = solver_ran
        say(_step_line(result.summary()))
        fields = [_gather_rows(comm, field) for field in solver.fields()] if gather else [None, None]
        record.add(dict(result.summary(), load_option=kind, load_value=value), result.history, *fields)
        if h5_path and index < len(steps) - 1:  # every rank takes part: a failed write stops them all
            io.on_root(comm, _checkpoint, record, h5_path)


def _checkpoint(record, h5_path):
    """Rewrite ``h5_path`` with the steps so far when it is time to (rank 0)."""
    if record.due():
        record.write(h5_path)


def main(argv=None):
    import petsc4py

    # Before PETSc starts: it reads the options files, and prints its own -help, as it is initialised.
    argv, preset_error = resolve_presets(sys.argv if argv is None else argv)
    if any(item in ("-help", "--help") for item in argv[1:]):
        # Help piped into `head` or `less` ends quietly when the reader stops, as any Unix tool does,
        # instead of in PETSc's SIGPIPE handler.
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
        argv = [*argv, "-no_signal_handler"]
        if launcher_rank() == 0:
            print_help(_mode_modules())
    petsc4py.init(argv)
    from petsc4py import PETSc

    from .options import Reader, check_names, translate_renamed_options

    comm = PETSc.COMM_WORLD.tompi4py()
    reader = Reader()
    quiet = False

    def say(text):
        if not quiet and comm.Get_rank() == 0:
            print(text, flush=True)

    try:
        tables = _mode_modules()
        if reader.has("help"):
            return 0
        if preset_error:
            raise UserError(preset_error)
        translate_renamed_options()
        check_names(all_option_names(tables))
        quiet = reader.bool("quiet", False)
        mode = reader.string("mode", "solve")
        check_memory(reader, comm, mode)
        if mode == "solve":
            return run_solve(reader, comm, say)
        if mode in tables:
            from .options import check_unused

            status = tables[mode].run(reader, comm)
            check_unused()
            return status if type(status) is int else 0
        raise UserError(f"-mode: unknown mode '{mode}' (one of {', '.join(['solve'] + list(tables))})")
    except UserError as error:
        if comm.Get_rank() == 0:
            print(f"roughpetsc: error: {error}", file=sys.stderr, flush=True)
        return 2
    except PETSc.Error as error:
        if comm.Get_rank() == 0:
            print(f"roughpetsc: PETSc error: {error}", file=sys.stderr, flush=True)
        return 2
    except MemoryError:
        print("roughpetsc: error: out of memory (use a smaller grid or more machines)", file=sys.stderr, flush=True)
        if comm.Get_size() > 1:  # this rank alone may have failed: stop the others rather than leave them waiting
            comm.Abort(2)
        return 2
    except Exception:
        if comm.Get_size() > 1:  # a failure on one rank (a bug): abort the run rather than hang the other ranks
            traceback.print_exc()
            sys.stderr.flush()
            comm.Abort(1)
        raise


if __name__ == "__main__":
    sys.exit(main())
