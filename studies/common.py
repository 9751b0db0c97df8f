"""What the solver studies share: the test surface, the presets of solvers/, one timed solve.

Import after ``petsc4py.init`` (``init()`` does it). Every study script runs
with the project's Python: ``.venv/bin/python studies/<script>.py``.
"""

import glob
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUTPUT = os.path.join(ROOT, "studies", "output")
sys.path.insert(0, ROOT)


def init():
    import petsc4py

    petsc4py.init([sys.argv[0]])


def group1_problem(n, seed=1, comm=None, effort="FFTW_MEASURE"):
    """The default surface of the project, group #1 of Table 7.1 ((k_l, k_s, H) = (16, 64, 0.8), m2 = 2e-4)."""
    from petsc4py import PETSc

    from roughpetsc.contact import ContactProblem
    from roughpetsc.surfaces import Grid, fractal

    grid = Grid(n, n)
    return ContactProblem(grid, fractal(grid, 16, 64, 0.8, 2e-4, seed), 1.0, comm or PETSc.COMM_SELF,
                          fft_effort=effort)


def read_preset(path):
    """``(name, options)`` of a solvers/*.opts file: options as a dict without the leading dash."""
    options = {}
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            key, _, value = line.partition(" ")
            options[key.lstrip("-")] = value.strip()
    return os.path.splitext(os.path.basename(path))[0], options


def presets(names=None):
    """The presets of solvers/, in file-name order, or those named."""
    found = dict(read_preset(p) for p in sorted(glob.glob(os.path.join(ROOT, "solvers", "*.opts"))))
    if names:
        missing = [n for n in names if n not in found]
        if missing:
            raise SystemExit(f"no preset solvers/{missing[0]}.opts")
        return {n: found[n] for n in names}
    return found


def load_controls(options):
    """Whether a preset solves load control directly (PK, ALMM) rather than through a root find."""
    return options.get("tao_type", "") in ("", "almm")


class options_set:
    """Context manager: PETSc options set on entry and removed on exit (the rest of the database untouched)."""

    def __init__(self, options):
        self.options = {k: v for k, v in options.items() if k != "kkt_rtol"}

    def __enter__(self):
        from petsc4py import PETSc

        for key, value in self.options.items():
            PETSc.Options().setValue(key, value)
        return self

    def __exit__(self, *args):
        from petsc4py import PETSc

        from roughpetsc.options import unused_options

        unused = set(unused_options()) & set(self.options)
        for key in self.options:
            PETSc.Options().delValue(key)
        if unused and args[0] is None:
            raise SystemExit("options nothing read (misspelled?): " + ", ".join("-" + k for k in sorted(unused)))
        return False


def solve(problem, options, rtol, control="load", monitor=None, **load):
    """One cold solve with a preset's options: ``(Result, pressure field, wall seconds including set-up)``.

    ``monitor(tao)``, if given, is added to the TAO's monitors.
    """
    from roughpetsc.control import Solver

    start = time.perf_counter()
    with options_set(options):
        solver = Solver(problem, control, options.get("tao_type") or None, rtol)
        try:
            if monitor is not None:
                tao = getattr(solver.backend, "tao", None) or solver.backend.qp.tao
                tao.setMonitor(monitor)
            result = solver.solve(**load)
            field = solver.fields()[0].copy()
        finally:
            solver.destroy()
    return result, field, time.perf_counter() - start


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


def save_figure(fig, folder, name):
    """Lay out, write (PNG, 110 dpi) and close a matplotlib figure; returns ``name``."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(os.path.join(folder, name), dpi=110)
    plt.close(fig)
    return name
