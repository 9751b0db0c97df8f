"""First speed figures of the BEM core, measured in one run (ratios matter; the machine is shared).

    .venv/bin/python studies/bench_core.py [--sizes 1024,2048] [--solve 512]

1. One application of the Westergaard shell Mat (MatMult) against a bare pyFFTW 2-D r2c + c2r pair on
   aligned arrays (FFTW_MEASURE), at each N of --sizes: median of repeated timings, and the ratio.
2. A load-controlled Polonsky-Keer solve of the default surface (group #1, N = --solve) at p* = 0.5 to a
   natural KKT residual of 1e-8: iterations, operator applications, seconds.
"""

import argparse
import statistics
import sys
import time

import petsc4py

petsc4py.init([sys.argv[0]])
import numpy as np  # noqa: E402
import pyfftw  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from roughpetsc import ContactProblem, Grid, Solver, Westergaard, fractal, fractal_group  # noqa: E402


def median_time(function, repeats):
    function()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def operator_ratio(n, repeats):
    real = pyfftw.empty_aligned((n, n), dtype="float64")
    spectrum = pyfftw.empty_aligned((n, n // 2 + 1), dtype="complex128")
    forward = pyfftw.FFTW(real, spectrum, axes=(0, 1), flags=("FFTW_MEASURE",))
    backward = pyfftw.FFTW(spectrum, real, axes=(0, 1), direction="FFTW_BACKWARD",
                           flags=("FFTW_MEASURE", "FFTW_DESTROY_INPUT"))
    real[...] = np.random.default_rng(0).random((n, n))

    def bare_pair():
        forward.execute()
        backward.execute()

    operator = Westergaard(Grid(n, n), 1.0, PETSc.COMM_SELF)
    mat = operator.mat()
    x, y = operator.vec(), operator.vec()
    x.setRandom()
    # Interleave so that drift of the shared machine hits both alike.
    bare, shell = [], []
    for _ in range(3):
        bare.append(median_time(bare_pair, repeats))
        shell.append(median_time(lambda: mat.mult(x, y), repeats))
    mat.destroy()
    x.destroy()
    y.destroy()
    return min(bare), min(shell)


def solve_figure(n):
    grid = Grid(n, n)
    group = fractal_group(1)
    heights = fractal(grid, group["k_l"], group["k_s"], group["hurst"], group["m2"], 1)
    problem = ContactProblem(grid, heights, 1.0, PETSc.COMM_SELF)
    solver = Solver(problem, "load", None, 1e-8)
    result = solver.solve(pstar=0.5)
    solver.destroy()
    problem.destroy()
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1024,2048")
    parser.add_argument("--solve", type=int, default=512)
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()
    for n in (int(s) for s in args.sizes.split(",")):
        bare, shell = operator_ratio(n, args.repeats)
        print(f"N={n}: bare FFTW r2c+c2r {bare * 1e3:.2f} ms, shell MatMult {shell * 1e3:.2f} ms, "
              f"ratio {shell / bare:.3f}", flush=True)
    result = solve_figure(args.solve)
    print(f"N={args.solve} p*=0.5 Polonsky-Keer: {result.iterations} iterations, "
          f"{result.operator_applications} operator applications, {result.time_s:.2f} s, "
          f"natural KKT {result.kkt.natural:.2e}, A*={result.A:.5f}, g*={result.gstar:.5f}, {result.reason}")


if __name__ == "__main__":
    main()
