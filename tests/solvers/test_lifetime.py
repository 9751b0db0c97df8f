"""A script that never destroys its solvers exits cleanly: the TAOs and shell Mats with Python callbacks are
destroyed while the interpreter still runs, not at PETSc's finalize after it (where their Python destroy crashed
the process with SIGSEGV: the python TAOs first, then a BQNLS or ALMM solver kept alive)."""

import os
import sys

import pytest

from conftest import MPI_ENV, ROOT, run_process

SCRIPT = """
import sys
import petsc4py
petsc4py.init(sys.argv[:1])
from roughpetsc import ContactProblem, Grid, Solver, fractal
from roughpetsc.contact import AdhesiveProblem, Dugdale

grid = Grid(32, 32, 1.0, 1.0)
problem = ContactProblem(grid, fractal(grid, 2, 8, 0.8, 1e-3, 1), 1.0, fft_effort="FFTW_ESTIMATE")
kept = Solver(problem, "load", rtol=1e-8)          # alive at exit, as the two below
print(kept.solve(pbar=0.1 * problem.sqrt_m0p).converged)
quasi_newton = Solver(problem, "load", "bqnls", rtol=1e-8)
print(quasi_newton.solve(pstar=0.5).converged)
augmented = Solver(problem, "load", "almm", rtol=1e-8)
print(augmented.solve(pstar=0.5).converged)


def dropped():                                      # collected before exit, never destroyed
    solver = Solver(AdhesiveProblem(problem, Dugdale(0.1 * problem.sqrt_m0h, 0.01)), "displacement", rtol=1e-8)
    return solver.solve(gbar=1.0 * problem.sqrt_m0h).converged


print(dropped())
"""


@pytest.mark.parametrize("ranks", [1, 2])
def test_solvers_left_alive_exit_cleanly(tmp_path, ranks):
    script = tmp_path / "undestroyed.py"
    script.write_text(SCRIPT)
    command = [sys.executable, str(script)]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), "--oversubscribe", *command]
    env = dict(os.environ, **MPI_ENV, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    process = run_process(command, env=env, cwd=tmp_path)
    assert process.returncode == 0, process.stderr[-2000:]
    # Every rank prints both results; their lines may interleave.
    assert process.stdout.count("True") == 4 * ranks and "False" not in process.stdout, process.stdout
