"""The time limit of a solve on two ranks whose clocks disagree: rank 0's clock decides for both, mid-solve.

Each rank gets a clock of its own (rank 0's runs one second per reading, rank 1's stands still), so that the
limit lands on rank 0 alone, at an iteration that no machine's speed moves. Ranks that each read their own clock
would leave the solve at different iterations and hang in the next collective.
"""

import json
import os
import sys

import pytest

from conftest import MPI_ENV, ROOT, run_process

SCRIPT = """
import json
import sys
import petsc4py
petsc4py.init(sys.argv[:1])
from mpi4py import MPI
from roughpetsc import ContactProblem, Grid, Solver, fractal
from roughpetsc.solvers import stopping


class Clock:
    # one second per reading on rank 0, none on the others
    def __init__(self, step):
        self.now, self.step = 0.0, step

    def perf_counter(self):
        self.now += self.step
        return self.now


tao_type, limit = sys.argv[1], float(sys.argv[2])
grid = Grid(64, 64, 1.0, 1.0)
problem = ContactProblem(grid, fractal(grid, 2, 16, 0.8, 1e-3, 7), 1.0, fft_effort="FFTW_ESTIMATE")
stopping.time = Clock(1.0 if MPI.COMM_WORLD.rank == 0 else 0.0)
solver = Solver(problem, "load", rtol=1e-13, options={"tao_type": tao_type, "solve_max_time": limit})
result = solver.solve(pstar=0.5)
# a file per rank: the launcher may interleave two ranks' lines on one stdout
with open(f"end_{MPI.COMM_WORLD.rank}.json", "w") as out:
    json.dump([result.converged, result.reason, result.iterations, result.kkt.natural], out)
solver.destroy()
"""


@pytest.mark.mpi
@pytest.mark.parametrize("tao_type", ["pk", "bqnls"])
def test_two_ranks_leave_at_rank_zeros_limit_together(tmp_path, tao_type):
    script = tmp_path / "limit.py"
    script.write_text(SCRIPT)
    env = dict(os.environ, **MPI_ENV, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    ends = {}
    for limit in (20.0, 0.0):
        command = ["mpiexec", "-n", "2", "--oversubscribe", sys.executable, str(script), tao_type, str(limit)]
        done = run_process(command, env=env, cwd=tmp_path, timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]
        ends[limit] = [json.loads((tmp_path / f"end_{rank}.json").read_text()) for rank in (0, 1)]
        assert ends[limit][0] == ends[limit][1], ends[limit]  # one verdict for both
    converged, reason, iterations, natural = ends[20.0][0]
    unlimited = ends[0.0][0]
    assert unlimited[0] and unlimited[3] <= 1e-13
    assert not converged and reason.startswith("DIVERGED_USER") and natural > 1e-13
    assert 1 < iterations < unlimited[2]  # mid-solve, not at its start
