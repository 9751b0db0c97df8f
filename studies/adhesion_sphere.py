"""A sphere in adhesive contact, periodic BEM against Maugis-Dugdale, JKR and DMT (issue 15, item 3).

    .venv/bin/python studies/adhesion_sphere.py [--sizes 128 256 512 1024] [--lambdas 0.1 0.5 1 2 5] [--steps 30]
                                                [--radius 0.1]

A paraboloid h = -r^2 / (2R) (R = 1) in a unit periodic cell, E* = 1, work of adhesion w chosen so that
the JKR contact radius at zero load a0 is ``--radius`` of the cell (0.1 by default; a0^3 = 9 pi w R^2 / (2 E*)),
the Dugdale law at Maugis's lambda = sigma0 (9R / (2 pi w E*^2))^(1/3) in ``--lambdas``. Each case runs an
approach and a retraction under displacement control (the mean gap) with the gap CG, ``--steps`` each way or
more, so that a step is at most half the range w / sigma0 (a longer retraction step would snap off early);
the load P = pbar L^2 and the contact radius a = sqrt(A L^2 / pi) (perimeter-corrected A) of every step are
compared with Maugis's solution P(a) at the same a (:func:`roughpetsc.models.sphere_adhesion.md_curve`), and
the pull-off (the least P along the path) with Maugis's least P (``md_pulloff``). The same P(a) is compared with
JKR's and DMT's curves and the pull-off with their -1.5 pi w R and -2 pi w R, the limits of large and small lambda.

The errors are given for every grid of ``--sizes`` with the first-order Richardson value of the pull-off
from the two finest grids. Output: studies/output/adhesion/sphere.md and sphere.png (P against a on the
finest grid, BEM, Maugis, JKR and DMT, per lambda); the cases are kept in sphere.json, so a rerun adds only
the missing ones.
"""

import argparse
import math
import os
import time

import numpy as np

import common
from roughpetsc.models.sphere_adhesion import dmt_load, jkr_load, md_curve, md_pulloff

RADIUS, E_STAR = 1.0, 1.0


def work_of(radius_0):
    """The work of adhesion whose JKR contact radius at zero load is ``radius_0``: a0^3 = 9 pi w R^2 / (2 E*)."""
    return radius_0 ** 3 * 2 * E_STAR / (9 * math.pi * RADIUS ** 2)


def run_case(n, lam, steps, radius_0):
    from roughpetsc import ContactProblem, Grid
    from roughpetsc.contact import AdhesiveProblem, approach_retraction
    from roughpetsc.solvers import Solver
    from roughpetsc.contact.laws import Dugdale

    work = work_of(radius_0)
    stress = lam / (9 * RADIUS / (2 * math.pi * work * E_STAR ** 2)) ** (1 / 3)
    grid = Grid(n, n, 1.0, 1.0)
    x = (np.arange(n) - n / 2) / n
    xx, yy = np.meshgrid(x, x, indexing="ij")
    heights = -(xx ** 2 + yy ** 2) / (2 * RADIUS)
    top = float((heights - heights.mean()).max())
    problem = ContactProblem(grid, heights, E_STAR)
    adhesive = Solver(AdhesiveProblem(problem, Dugdale(work, stress)), "displacement", rtol=1e-9)
    range_ = work / stress
    approach = radius_0 ** 2 / RADIUS  # of the order of the JKR approach at zero load
    rows = []
    try:
        steps = max(steps, math.ceil((2 * range_ + approach) / (0.5 * range_)))  # steps below half the range
        path = top + approach_retraction(2 * range_, -approach, steps)
        started = time.perf_counter()
        for step, gbar in enumerate(path, 1):
            result = adhesive.solve(gbar=gbar)
            rows.append({"gbar": gbar, "P": result.pbar * grid.area, "A": result.A,
                         "A_corrected": result.A_corrected, "natural": result.kkt.natural,
                         "converged": result.converged, "reason": result.reason})
            print(f"  lambda {lam:g}, N {n}: step {step}/{len(path)}, P / (pi w R) "
                  f"{rows[-1]['P'] / (math.pi * work * RADIUS):+.4f}, A {result.A:.3e}, natural "
                  f"{result.kkt.natural:.1e}, {result.reason}, {time.perf_counter() - started:.0f} s", flush=True)
    finally:
        adhesive.destroy()
        problem.destroy()
    return work, stress, rows


def compare(work, stress, rows, n):
    """(errors of P at the BEM's radius, BEM pull-off, Maugis pull-off), loads over pi w R."""
    scale = math.pi * work * RADIUS
    resolved = [row for row in rows if math.sqrt(row["A_corrected"] / math.pi) > 4.0 / n]
    radii = np.array([math.sqrt(row["A_corrected"] / math.pi) for row in resolved])
    loads = md_curve(radii, RADIUS, E_STAR, work, stress)[0]
    for row, a, load in zip(resolved, radii, loads):
        row["a"], row["P_maugis"] = float(a), float(load)
    errors = [abs(row["P"] - row["P_maugis"]) / scale for row in resolved]
    return errors, min(row["P"] for row in rows) / scale, md_pulloff(RADIUS, E_STAR, work, stress) / scale


def summary(rows, lam, n, radius_0, work, stress):
    """One table row (a dict) of a case: P(a) errors against Maugis, JKR and DMT, and the pull-offs."""
    errors, bem, maugis = compare(work, stress, rows, n)
    scale = math.pi * work * RADIUS
    with_a = [row for row in rows if "a" in row]
    radii = np.array([row["a"] for row in with_a])
    loads = np.array([row["P"] for row in with_a])
    return {"lambda": lam, "N": n, "a0": radius_0, "converged": int(sum(row["converged"] for row in rows)),
            "steps": len(rows),
            "max_error": float(max(errors)), "median_error": float(np.median(errors)),
            "jkr_median_error": float(np.median(np.abs(loads - jkr_load(radii, RADIUS, E_STAR, work)) / scale)),
            "dmt_median_error": float(np.median(np.abs(loads - dmt_load(radii, RADIUS, E_STAR, work)) / scale)),
            "pulloff": float(bem), "maugis_pulloff": float(maugis),
            "curve": [[float(row["a"]), float(row["P"] / scale)] for row in with_a]}


def table(cases):
    """The markdown table of every (lambda, N) with a Richardson row per lambda."""
    header = ["lambda", "a0", "N", "steps converged", "max abs error of P(a)", "median error",
              "median error vs JKR P(a)", "median error vs DMT P(a)", "BEM pull-off", "Maugis pull-off",
              "error vs Maugis", "error vs JKR -1.5",
              "error vs DMT -2"]
    body = []
    for lam, radius_0 in sorted({(c["lambda"], c["a0"]) for c in cases}, key=lambda k: (k[0], -k[1])):
        rows = sorted((c for c in cases if (c["lambda"], c["a0"]) == (lam, radius_0)), key=lambda c: c["N"])
        for c in rows:
            body.append([f"{lam:g}", f"{radius_0:g}", c["N"], f"{c['converged']}/{c['steps']}", f"{c['max_error']:.3f}",
                         f"{c['median_error']:.3f}", f"{c['jkr_median_error']:.3f}", f"{c['dmt_median_error']:.3f}",
                         f"{c['pulloff']:.4f}", f"{c['maugis_pulloff']:.4f}",
                         relative(c["pulloff"], c["maugis_pulloff"]),
                         relative(c["pulloff"], -1.5), relative(c["pulloff"], -2.0)])
        if len(rows) > 1:
            extrapolated = 2 * rows[-1]["pulloff"] - rows[-2]["pulloff"]
            maugis = rows[-1]["maugis_pulloff"]
            body.append([f"{lam:g}", f"{radius_0:g}", "extrapolated", "", "", "", "", "", f"{extrapolated:.4f}",
                         f"{maugis:.4f}",
                         relative(extrapolated, maugis), relative(extrapolated, -1.5), relative(extrapolated, -2.0)])
    return common.markdown_table(header, body)


def relative(value, reference):
    return f"{abs(value - reference) / abs(reference):.2%}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[128, 256, 512, 1024])
    parser.add_argument("--lambdas", type=float, nargs="+", default=[0.1, 0.5, 1.0, 2.0, 5.0])
    parser.add_argument("--steps", type=int, default=30)
    parser.add_argument("--radius", type=float, default=0.1,
                        help="JKR contact radius at zero load over the cell size (the cell is 1/radius of them)")
    out = os.path.join(common.OUTPUT, "adhesion")
    args, path, cases = common.start_resumable(parser, out, "sphere", "only rewrite the report from the JSON")
    for case in cases:
        case.setdefault("a0", 0.1)
    done = {(c["lambda"], c["N"], c["a0"]) for c in cases}
    for lam in args.lambdas if not args.report else ():
        for n in sorted(args.sizes):
            if (lam, n, args.radius) in done:
                continue
            work, stress, rows = run_case(n, lam, args.steps, args.radius)
            cases.append(summary(rows, lam, n, args.radius, work, stress))
            print({k: v for k, v in cases[-1].items() if k != "curve"}, flush=True)
            common.save_rows(path, cases)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lambdas = sorted({c["lambda"] for c in cases})
    figure, axes = plt.subplots(1, len(lambdas), figsize=(3.6 * len(lambdas), 3.4), squeeze=False)
    for axis, lam in zip(axes[0], lambdas):
        finest = max((c for c in cases if c["lambda"] == lam), key=lambda c: (c["N"] * c["a0"], -c["a0"]))
        radius_0 = finest["a0"]
        work = work_of(radius_0)
        scale = math.pi * work * RADIUS
        radii = np.linspace(0.2, 1.6, 200) * radius_0
        curve = np.array(finest["curve"])
        axis.plot(curve[:, 0] / radius_0, curve[:, 1], "o", ms=3, label=f"BEM, N = {finest['N']}, a0 = {radius_0:g}")
        stress = lam / (9 * RADIUS / (2 * math.pi * work * E_STAR ** 2)) ** (1 / 3)
        axis.plot(radii / radius_0, md_curve(radii, RADIUS, E_STAR, work, stress)[0] / scale, "-",
                  label="Maugis-Dugdale")
        axis.plot(radii / radius_0, jkr_load(radii, RADIUS, E_STAR, work) / scale, ":", label="JKR")
        axis.plot(radii / radius_0, dmt_load(radii, RADIUS, E_STAR, work) / scale, "--", label="DMT")
        axis.set_ylim(-2.2, 3.0)
        axis.set_title(f"lambda = {lam:g}", fontsize=9)
        axis.set_xlabel("contact radius a / a0")
    axes[0][0].set_ylabel("P / (pi w R)")
    axes[0][0].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(os.path.join(out, "sphere.png"), dpi=120)
    lines = ["# Sphere with the Dugdale law: periodic BEM against Maugis-Dugdale, JKR and DMT", "",
             "Generated by `.venv/bin/python studies/adhesion_sphere.py` (resumable: cases run once, kept in "
             "sphere.json; `--sizes`, `--lambdas`, `--steps`, `--radius` choose them, set-up in the module "
             "docstring). Loads over "
             "pi w R; a from the perimeter-corrected area; a0, the JKR radius at zero load, is given as a fraction "
             "of the cell (a0 N nodes): a smaller a0 puts the periodic images further away. JKR's pull-off is "
             "-1.5 pi w R (the large-lambda limit), DMT's -2 pi w R (the "
             "small-lambda limit).", "", table(cases), "", "![P against a](sphere.png)"]
    with open(os.path.join(out, "sphere.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
