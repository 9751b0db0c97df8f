"""Fig. 3.3: the bisinusoid (3.52) against the asymptotes of Johnson, Greenwood and Higginson (3.53)-(3.55).

    .venv/bin/python studies/bisinusoid_fig33.py [--points 128]

h = Delta cos(2 pi x / lambda) cos(2 pi y / lambda) on one period (lambda = 1, Delta = 0.02, E* = 220, as
Table 3.1 up to units), loaded by Polonsky-Keer from pbar/p* = 0.002 to 0.995 with warm starts. Early
contact: two Hertz contacts per cell with R = 1/(Delta alpha^2) and F = pbar lambda^2 / 2; near complete
contact: (3.54) and (3.55). Writes studies/output/bisinusoid_fig33.png and .md.
"""

import argparse
import math
import os
import sys

import petsc4py

petsc4py.init([sys.argv[0]])
import numpy as np  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from roughpetsc import ContactProblem, Grid, Solver, bisinusoid  # noqa: E402

E_STAR, DELTA = 220.0, 0.02


def hertz_area(ratio, p_star):
    radius = 1 / (DELTA * (2 * math.pi) ** 2)
    a = (3 * (ratio * p_star / 2) * radius / (4 * E_STAR)) ** (1 / 3)
    return 2 * math.pi * a ** 2


def jgh_area(ratio):
    return 1 - 3 / (2 * math.pi) * (1 - ratio)


def jgh_gap(ratio):
    return 16 / (15 * math.pi ** 2) * 1.5 ** 1.5 * (1 - ratio) ** 2.5


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--points", type=int, default=128)
    args = parser.parse_args()
    grid = Grid(args.points, args.points)
    problem = ContactProblem(grid, bisinusoid(grid, DELTA, 1.0, 1.0), E_STAR, PETSc.COMM_SELF)
    p_star = 0.5 * E_STAR * math.hypot(2 * math.pi, 2 * math.pi) * DELTA
    ratios = np.concatenate([np.geomspace(0.002, 0.1, 12), np.linspace(0.15, 0.95, 17), [0.97, 0.98, 0.99, 0.995]])
    solver = Solver(problem, "load", None, 1e-10)
    rows = []
    for ratio in ratios:
        result = solver.solve(pbar=ratio * p_star)
        rows.append((ratio, result.A, result.A_corrected, result.gbar / DELTA, result.converged))
    solver.destroy()
    problem.destroy()
    rows = np.array(rows, dtype=float)
    os.makedirs("studies/output", exist_ok=True)
    lines = ["| pbar/p* | A* | A* corrected | Hertz A* | (3.54) A* | gbar/Delta | (3.55) gbar/Delta | converged |",
             "|---|---|---|---|---|---|---|---|"]
    for ratio, area, corrected, gap, converged in rows:
        lines.append(f"| {ratio:.4g} | {area:.5f} | {corrected:.5f} | {hertz_area(ratio, p_star):.5f} | "
                     f"{jgh_area(ratio):.5f} | {gap:.4e} | {jgh_gap(ratio):.4e} | {bool(converged)} |")
    with open("studies/output/bisinusoid_fig33.md", "w") as f:
        f.write(f"# Bisinusoid (3.52), {args.points}^2 nodes per period, against (3.53)-(3.55)\n\n")
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fine = np.linspace(0.001, 1, 400)
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    left.plot(rows[:, 0], rows[:, 1], "o", ms=3, label="BEM (node count)")
    left.plot(rows[:, 0], rows[:, 2], "s", ms=3, mfc="none", label="BEM (perimeter-corrected)")
    left.plot(fine, [hertz_area(r, p_star) for r in fine], "-", label="Hertz (early contact)")
    left.plot(fine, jgh_area(fine), "--", label="(3.54)")
    left.set(xlabel="pbar / p*", ylabel="A*", ylim=(0, 1.02))
    left.legend()
    right.semilogy(rows[:, 0], rows[:, 3], "o", ms=3, label="BEM")
    right.semilogy(fine, jgh_gap(fine), "--", label="(3.55)")
    right.set(xlabel="pbar / p*", ylabel="gbar / Delta")
    right.legend()
    fig.suptitle("Bisinusoid (3.52): BEM against the asymptotes (cf. Fig. 3.3)")
    fig.tight_layout()
    fig.savefig("studies/output/bisinusoid_fig33.png", dpi=120)


if __name__ == "__main__":
    main()
