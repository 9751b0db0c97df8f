"""Westergaard's 1-D wave: A and gbar against the exact solution as the grid is refined.

    .venv/bin/python studies/westergaard_convergence.py [--points 256,512,1024,2048]

Profile 2h sin^2(pi x / lambda) on an N-point period (2 rows), E* = 2.5, h = 0.01, lambda = 1;
p_star = pi E* h / lambda; exact A = (2/pi) asin(sqrt(P)), gbar = h (1 - P + P ln P), P = pbar/p_star
(Johnson, Contact Mechanics, 13.2). Load control by Polonsky-Keer, displacement control by BLMVM.
Writes studies/output/westergaard_convergence.md.
"""

import argparse
import math
import os
import sys

import petsc4py

petsc4py.init([sys.argv[0]])
from petsc4py import PETSc  # noqa: E402

from roughpetsc import ContactProblem, Grid, Solver, wave  # noqa: E402

E_STAR, AMPLITUDE = 2.5, 0.01
RATIOS = (0.05, 0.3, 0.7, 0.95)


def exact(ratio):
    return (2 / math.pi) * math.asin(math.sqrt(ratio)), AMPLITUDE * (1 - ratio + ratio * math.log(ratio))


def rows_for(points):
    grid = Grid(2, points, 2.0 / points, 1.0)
    problem = ContactProblem(grid, wave(grid, AMPLITUDE, 1.0), E_STAR, PETSc.COMM_SELF)
    p_star = math.pi * E_STAR * AMPLITUDE
    rows = []
    for control, tao_type, rtol in (("load", None, 1e-10), ("displacement", "blmvm", 1e-8)):
        solver = Solver(problem, control, tao_type, rtol)
        for ratio in RATIOS:
            area, gbar = exact(ratio)
            result = solver.solve(pbar=ratio * p_star) if control == "load" else solver.solve(gbar=gbar)
            rows.append((points, control, ratio, (result.A - area) * points, (result.A_corrected - area) * points,
                         (result.gbar - gbar) / gbar, result.pbar / p_star - ratio, result.kkt.natural,
                         result.converged))
        solver.destroy()
    problem.destroy()
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--points", default="256,512,1024,2048")
    args = parser.parse_args()
    lines = ["| N | control | P | (A - A_exact) N [nodes] | (A_corr - A_exact) N | gbar rel. error | "
             "P error | KKT natural | converged |", "|---|---|---|---|---|---|---|---|---|"]
    for points in (int(p) for p in args.points.split(",")):
        for row in rows_for(points):
            line = "| {} | {} | {} | {:+.3f} | {:+.3f} | {:+.2e} | {:+.2e} | {:.1e} | {} |".format(*row)
            lines.append(line)
            print(line, flush=True)
    os.makedirs("studies/output", exist_ok=True)
    with open("studies/output/westergaard_convergence.md", "w") as f:
        f.write("# Westergaard 1-D wave against the exact solution\n\n" + "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
