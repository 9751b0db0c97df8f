"""The command line: options database in, a run out.

    mpiexec -n 2 python -m roughpetsc                     # the embedded default problem
    mpiexec -n 2 python -m roughpetsc -tao_type bqnls     # load control: root find around BQNLS
    python -m roughpetsc -pstar_list 0.1,0.5,1 -json out.json -output out.h5

Exit status: 0 success, 2 bad input (one message, no traceback, no output
file), 3 a solve did not converge (reported as such; files are written and
flag it).
"""

import sys
import time

import numpy as np

from .errors import UserError

MODES = ("solve", "stats", "models", "ensemble")

GENERAL_OPTIONS = [
    ("mode", "solve", "solve | stats | models | ensemble"),
    ("E_star", 1.0, "composite modulus E* (1.6), pressure units"),
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
    ("output", "", "write an HDF5 file with heights, pressure and gap fields of the last step to PATH"),
    ("pk_pc", "fourier", "Polonsky-Keer preconditioner: fourier (inverse symbol pi E*|k| on the contact set) | none"),
    ("pk_active_set", "bccg", "Polonsky-Keer active set: bccg (overlapping nodes join the free set, Polak-Ribiere "
                              "without restarts) | pk (as published: nodes enter after the step, CG restarts)"),
    ("pk_refresh", 50, "Polonsky-Keer: recompute K p from scratch at least every this many iterations"),
    ("bound_pc", "", "TAO bnls/bntr/bntl/tron/gpcg: fourier (inverse symbol on the free set; default of the BNK "
                     "types) | none (default of tron, gpcg) | options (-tao_*pc_type decides)"),
    ("fft_threads", 1, "FFTW threads on one rank"),
    ("fft_effort", "FFTW_MEASURE", "FFTW planner effort: FFTW_ESTIMATE | FFTW_MEASURE | FFTW_PATIENT"),
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


def print_help(tables):
    from .options import format_help
    from .surfaces import SURFACE_OPTIONS

    blocks = [format_help("roughpetsc options (python -m roughpetsc [options]):", GENERAL_OPTIONS),
              format_help("Surface:", SURFACE_OPTIONS), format_help("Mode solve:", SOLVE_OPTIONS), SOLVER_HELP]
    for mode, module in tables.items():
        blocks.append(format_help(f"Mode {mode}:", module.OPTIONS))
    print("\n".join(blocks), flush=True)


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

    from . import io, surfaces
    from .contact import ContactProblem
    from .control import Solver
    from .options import check_unused

    steps, load_option = load_steps(reader)
    _check_loads(steps, load_option)
    rtol = reader.real("kkt_rtol", 1e-8)
    if not 0 < rtol < 1:
        raise UserError(f"-kkt_rtol must lie in (0, 1), got {rtol}")
    E_star = reader.real("E_star", 1.0)
    json_path, h5_path = reader.string("json", ""), reader.string("output", "")
    for path, option in ((json_path, "json"), (h5_path, "output")):
        if path:
            io.check_writable(path, option)
    threads = reader.int("fft_threads", 1)
    effort = reader.string("fft_effort", "FFTW_MEASURE")
    if effort not in ("FFTW_ESTIMATE", "FFTW_MEASURE", "FFTW_PATIENT", "FFTW_EXHAUSTIVE"):
        raise UserError(f"-fft_effort: unknown planner effort '{effort}'")
    tao_type = reader.string("tao_type", "") or None

    if not reader.string("surface_file", ""):
        rows = surfaces.grid_from_options(reader).n0
        if rows % comm.Get_size():
            raise UserError(f"-surface_N0/-surface_N: {rows} grid rows cannot be shared evenly by "
                            f"{comm.Get_size()} MPI ranks (use a multiple of the number of ranks)")
    grid, heights = surfaces.from_options(reader)
    problem = ContactProblem(grid, heights, E_star, PETSc.COMM_WORLD, threads, effort)
    statistics = surface_statistics(grid, heights, E_star)
    control = "displacement" if steps[0][0] == "gbar" else "load"
    solver = Solver(problem, control, tao_type, rtol)
    try:
        check_unused()
        say(f"roughpetsc: {grid.n0}x{grid.n1} grid on {comm.Get_size()} rank(s), solver {solver.name}, "
            f"E*={E_star:g}, sqrt(m0h)={problem.sqrt_m0h:.4g}, sqrt(m0p)={problem.sqrt_m0p:.4g}, "
            f"alpha_h={statistics['alpha_h']:.4g}, alpha_p={statistics['alpha_p']:.4g}")
        say(f"{'p*':>10} {'A*':>10} {'A*corr':>10} {'g*':>11} {'KKT nat':>9} {'its':>6} {'Kapps':>6} "
            f"{'time s':>8}  reason")
        results = []
        for kind, value in steps:
            result = solver.solve(**{kind: value})
            results.append(result)
            flag = "" if result.converged else "  NOT CONVERGED"
            say(f"{result.pstar:10.5g} {result.A:10.5g} {result.A_corrected:10.5g} {result.gstar:11.5g} "
                f"{result.kkt.natural:9.2e} {result.iterations:6d} {result.operator_applications:6d} "
                f"{result.time_s:8.3f}  {result.reason}{flag}")
        summary = {"grid": [grid.n0, grid.n1], "length": [grid.l0, grid.l1], "E_star": E_star,
                   "surface": statistics, "sqrt_m0h": problem.sqrt_m0h, "sqrt_m0p": problem.sqrt_m0p,
                   "solver": solver.name, "control": control, "kkt_rtol": rtol, "ranks": comm.Get_size(),
                   "steps": [r.summary() for r in results], **io.provenance()}
        if h5_path:  # the fields are gathered only for the file (rank 0's memory)
            pressure, gap = solver.fields()
            pressure, gap = _gather_rows(comm, pressure), _gather_rows(comm, gap)
            if comm.Get_rank() == 0:
                io.write_h5(h5_path, summary, {"heights": heights, "pressure": pressure, "gap": gap},
                            {i: r.history for i, r in enumerate(results)})
        if json_path and comm.Get_rank() == 0:
            io.write_json(json_path, summary)
        return 0 if all(r.converged for r in results) else 3
    finally:
        solver.destroy()
        problem.destroy()


def main(argv=None):
    import petsc4py

    petsc4py.init(sys.argv if argv is None else argv)
    from petsc4py import PETSc

    from .options import Reader, check_names

    comm = PETSc.COMM_WORLD.tompi4py()
    reader = Reader()
    quiet = False

    def say(text):
        if not quiet and comm.Get_rank() == 0:
            print(text, flush=True)

    try:
        tables = _mode_modules()
        if reader.has("help"):
            if comm.Get_rank() == 0:
                print_help(tables)
            return 0
        check_names(all_option_names(tables))
        quiet = reader.bool("quiet", False)
        mode = reader.string("mode", "solve")
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


if __name__ == "__main__":
    sys.exit(main())
