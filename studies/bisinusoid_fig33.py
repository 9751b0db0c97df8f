"""Figs. 3.3-3.6: the bisinusoid (3.52) against the asymptotes of Johnson, Greenwood and Higginson (3.53)-(3.55), and
its contact area, pressure and gap at the four contact ratios of Figs. 3.4-3.6.

    .venv/bin/python studies/bisinusoid_fig33.py [--points 128]

h = Delta cos(2 pi x / lambda) cos(2 pi y / lambda) on one period (lambda = 1, Delta = 0.02, E* = 220, as
Table 3.1 up to units), loaded by Polonsky-Keer from pbar/p* = 0.002 to 0.995 with warm starts. Early
contact: two Hertz contacts per cell with R = 1/(Delta alpha^2) and F = pbar lambda^2 / 2; near complete
contact: (3.54) and (3.55). Writes studies/output/bisinusoid_fig33.png and .md.

Figs. 3.4-3.6: the loads at which A* (node count) is the dissertation's 3.79 %, 46.44 %, 72.43 % and 89.19 %,
found from the load sweep by interpolation and Newton steps on its slope (to 0.05 %), solved and drawn as the contact
area (Fig. 3.4), the pressure p / p* with p* of (3.53) (Fig. 3.5) and the gap g / Delta (Fig. 3.6) over the
period: studies/output/bisinusoid_fig3_4.png, _fig3_5.png, _fig3_6.png; the loads reached are in the .md.
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
MAP_AREAS = (0.0379, 0.4644, 0.7243, 0.8919)  # A* of the four panels of Figs. 3.4-3.6
OUT = "studies/output"
NEWTON_STEPS = 4
P_STAR = 0.5 * E_STAR * math.hypot(2 * math.pi, 2 * math.pi) * DELTA  # (3.53) for the unit period


def hertz_area(ratio, p_star):
    radius = 1 / (DELTA * (2 * math.pi) ** 2)
    a = (3 * (ratio * p_star / 2) * radius / (4 * E_STAR)) ** (1 / 3)
    return 2 * math.pi * a ** 2


def jgh_area(ratio):
    return 1 - 3 / (2 * math.pi) * (1 - ratio)


def jgh_gap(ratio):
    return 16 / (15 * math.pi ** 2) * 1.5 ** 1.5 * (1 - ratio) ** 2.5


def load_sweep(solver, p_star):
    """(pbar/p*, A*, A* corrected, gbar/Delta, converged) along the loads of Fig. 3.3, warm-started."""
    ratios = np.concatenate([np.geomspace(0.002, 0.1, 12), np.linspace(0.15, 0.95, 17), [0.97, 0.98, 0.99, 0.995]])
    rows = []
    for ratio in ratios:
        result = solver.solve(pbar=ratio * p_star)
        rows.append((ratio, result.A, result.A_corrected, result.gbar / DELTA, result.converged))
    return np.array(rows, dtype=float)


def map_loads(solver, p_star, rows):
    """The solves at the contact ratios of Figs. 3.4-3.6: [(target A*, pbar/p*, result, pressure, gap)].

    The load is read off the sweep ``rows`` by interpolation, then corrected by up to NEWTON_STEPS Newton steps on
    the sweep's slope dA*/d(pbar/p*) (node-count A* moves in steps of one node, so the target is met to a few
    nodes)."""
    out = []
    slope = np.gradient(rows[:, 1], rows[:, 0])
    for target in MAP_AREAS:
        ratio = float(np.interp(target, rows[:, 1], rows[:, 0]))
        result = solver.solve(pbar=ratio * p_star)
        for _ in range(NEWTON_STEPS):
            if abs(result.A - target) <= 5e-4:
                break
            ratio += (target - result.A) / float(np.interp(ratio, rows[:, 0], slope))
            result = solver.solve(pbar=ratio * p_star)
        pressure, gap = solver.fields()
        out.append((target, ratio, result, pressure.copy(), gap.copy()))
    return out


def write_table(points, rows, maps):
    lines = ["| pbar/p* | A* | A* corrected | Hertz A* | (3.54) A* | gbar/Delta | (3.55) gbar/Delta | converged |",
             "|---|---|---|---|---|---|---|---|"]
    for ratio, area, corrected, gap, converged in rows:
        lines.append(f"| {ratio:.4g} | {area:.5f} | {corrected:.5f} | {hertz_area(ratio, P_STAR):.5f} | "
                     f"{jgh_area(ratio):.5f} | {gap:.4e} | {jgh_gap(ratio):.4e} | {bool(converged)} |")
    lines += ["", "## Figs. 3.4-3.6: the loads of the four maps", "",
              "| panel | dissertation A* | our A* (node count) | A* corrected | pbar/p* | max p/p* | max g/Delta | "
              "natural KKT residual | converged |", "|---|---|---|---|---|---|---|---|---|"]
    for k, (target, ratio, result, pressure, gap) in enumerate(maps):
        lines.append(f"| ({'abcd'[k]}) | {100 * target:.2f}% | {100 * result.A:.2f}% | {100 * result.A_corrected:.2f}% "
                     f"| {ratio:.4f} | {pressure.max() / P_STAR:.3f} | {gap.max() / DELTA:.4f} | "
                     f"{result.kkt.natural:.1e} | {result.converged} |")
    with open(os.path.join(OUT, "bisinusoid_fig33.md"), "w") as f:
        f.write(f"# Bisinusoid (3.52), {points}^2 nodes per period, against (3.53)-(3.55)\n\n")
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def draw_sweep(plt, rows, p_star):
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
    fig.savefig(os.path.join(OUT, "bisinusoid_fig33.png"), dpi=120)
    plt.close(fig)


def draw_maps(plt, maps, p_star):
    """Figs. 3.4 (contact area), 3.5 (p / p*) and 3.6 (g / Delta), a panel per contact ratio, over one period."""
    figures = (("3.4", "contact area (black: p > 0)", lambda pressure, gap: (pressure > 0).astype(float), "gray_r"),
               ("3.5", "contact pressure p / p*", lambda pressure, gap: pressure / p_star, "viridis"),
               ("3.6", "interfacial gap g / Delta", lambda pressure, gap: gap / DELTA, "viridis"))
    for number, what, field, colours in figures:
        fig, axes = plt.subplots(1, len(maps), figsize=(4.3 * len(maps), 4.2))
        for k, (axis, (target, ratio, result, pressure, gap)) in enumerate(zip(axes, maps)):
            image = axis.imshow(field(pressure, gap), cmap=colours, origin="lower", extent=(0, 1, 0, 1),
                                interpolation="nearest")
            if number != "3.4":
                fig.colorbar(image, ax=axis, shrink=0.75)
            axis.set_title(f"({'abcd'[k]}) A* = {100 * result.A:.2f}% (diss. {100 * target:.2f}%)\n"
                           f"pbar/p* = {ratio:.4f}", fontsize=9)
            axis.set(xlabel="x / lambda", ylabel="y / lambda")
        fig.suptitle(f"Fig. {number}: bisinusoid (3.52), {what}")
        fig.tight_layout()
        fig.savefig(os.path.join(OUT, f"bisinusoid_fig{number.replace('.', '_')}.png"), dpi=110)
        plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--points", type=int, default=128)
    args = parser.parse_args()
    grid = Grid(args.points, args.points)
    problem = ContactProblem(grid, bisinusoid(grid, DELTA, 1.0, 1.0), E_STAR, PETSc.COMM_SELF)
    solver = Solver(problem, "load", None, 1e-10)
    rows = load_sweep(solver, P_STAR)
    maps = map_loads(solver, P_STAR, rows)
    solver.destroy()
    problem.destroy()
    os.makedirs(OUT, exist_ok=True)
    write_table(args.points, rows, maps)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    draw_sweep(plt, rows, P_STAR)
    draw_maps(plt, maps, P_STAR)


if __name__ == "__main__":
    main()
