"""What the solver studies share: the test surface, the presets of solvers/, one timed solve.

Import after ``petsc4py.init`` (``init()`` does it). Every study script runs
with the project's Python, where roughpetsc is installed (editable):
``.venv/bin/python studies/<script>.py``. Studies use public names only: the
API of ``roughpetsc`` (its ``__all__``) first, a module's own public names
(``roughpetsc.contact.report``, ...) for what the API does not export. A preset's options reach its
solver through ``Solver(..., options=preset)``, under a prefix of the solver's own.
"""

import os
import sys
import time

from roughpetsc.app import presets as preset_files

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the repository
OUTPUT = os.path.join(ROOT, "studies", "output")


def init():
    import petsc4py

    petsc4py.init([sys.argv[0]])


def group1_heights(grid, seed=1):
    """A surface of group #1 of Table 7.1 (options/group01.opts: (k_l, k_s, H) = (16, 64, 0.8), m2 = 2e-4), made by
    the default generator (``filter``, as the command line's embedded surface), not the preset's ``xu``: the solver
    studies time it, and their committed tables were made with it."""
    from roughpetsc import fractal, fractal_group

    group = fractal_group(1)
    return fractal(grid, group["k_l"], group["k_s"], group["hurst"], group["m2"], seed)


def group1_problem(n, seed=1, comm=None, effort="FFTW_MEASURE"):
    """The default surface of the project, group #1 of Table 7.1, on an ``n x n`` unit cell, E* = 1."""
    from petsc4py import PETSc

    from roughpetsc import ContactProblem, Grid

    grid = Grid(n, n)
    return ContactProblem(grid, group1_heights(grid, seed), 1.0, comm or PETSc.COMM_SELF, fft_effort=effort)


def presets(names=None):
    """The presets of solvers/, in file-name order, or those named."""
    found = preset_files.presets("solvers")
    if names:
        missing = [n for n in names if n not in found]
        if missing:
            raise SystemExit(f"no preset solvers/{missing[0]}.opts")
        return {n: found[n] for n in names}
    return found


def load_controls(options):
    """Whether a preset solves load control directly (PK, ALMM) rather than through a root find."""
    return options.get("tao_type", "") in ("", "almm")


def preset_solver(problem, options, rtol, control="load"):
    """The Solver of a preset's options (its ``kkt_rtol`` aside: ``rtol`` decides), under a prefix of its own."""
    from roughpetsc import Solver

    preset = {key: value for key, value in options.items() if key != "kkt_rtol"}
    return Solver(problem, control, rtol=rtol, options=preset)


def solve(problem, options, rtol, control="load", monitor=None, **load):
    """One cold solve with a preset's options: ``(Result, pressure field, wall seconds including set-up)``.

    ``monitor(tao)``, if given, is added to the TAO's monitors.
    """
    start = time.perf_counter()
    solver = preset_solver(problem, options, rtol, control)
    try:
        if monitor is not None:
            solver.tao.setMonitor(monitor)
        result = solver.solve(**load)
        field = solver.fields()[0].copy()
    finally:
        solver.destroy()
    return result, field, time.perf_counter() - start


def start_resumable(parser, folder, name, report_help):
    """Start a resumable study: its arguments (``--report`` added), PETSc, and the rows it has saved.

    Returns ``(args, path, rows)``: the parsed arguments, the JSON file ``folder/name.json`` of its
    rows (:func:`save_rows`) and the rows already there (:func:`load_rows`).
    """
    parser.add_argument("--report", action="store_true", help=report_help)
    args = parser.parse_args()
    init()
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, name + ".json")
    return args, path, load_rows(path)


def load_rows(path):
    """The rows a resumable study saved in ``path`` (JSON), or [] for a fresh start."""
    import json

    if not os.path.exists(path):
        return []
    with open(path) as f:
        return json.load(f)


def save_rows(path, rows):
    """Rewrite the JSON rows of a resumable study atomically (a kill leaves the previous rows)."""
    import json

    with open(path + ".partial", "w") as f:
        json.dump(rows, f, indent=0)
    os.replace(path + ".partial", path)


def markdown_table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def records_table(records):
    """A markdown table of dicts with the same keys (the first one's order), floats to 4 significant digits."""
    keys = list(records[0])
    return markdown_table(keys, [[f"{r[k]:.4g}" if isinstance(r[k], float) else r[k] for k in keys] for r in records])


def save_figure(fig, folder, name):
    """Lay out, write (PNG, 110 dpi) and close a matplotlib figure; returns ``name``."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(os.path.join(folder, name), dpi=110)
    plt.close(fig)
    return name
