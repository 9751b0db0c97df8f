"""Stress table of the adhesive solvers: hard adhesive cases, each answer checked independently (issue 15, item 5).

    .venv/bin/python studies/adhesion_stress.py [--sizes 64 256] [--max-time 20 60]

Cells: solver {gapcg, almm} x N in ``--sizes`` x case x natural-residual tolerance {1e-8, 1e-10, 1e-12} on the
fractal surface of studies/stress_grid.py. Cases, in the surface's scales (range over sqrt(m0^h), peak stress
over sqrt(m0^p)):

* ``strong exponential``: range 0.2, peak 1, at g* = 1;
* ``short exponential``: range 0.01, peak 1 (a range far below the height change between neighbours), g* = 1;
* ``strong dugdale``: range 0.2, peak 1, g* = 1;
* ``near pull-off``: the strong Dugdale law on a retraction from g* = 0.5, the step of least (most tensile)
  mean pressure of 12 steps up to g* = 2.5.

The answer is checked with numpy alone (``stress_grid.independent``: the gap must be K p plus a constant for
the returned pressure), and the natural residual is measured from the returned fields (:func:`check`).
Verdicts as in the stress grid: ``converged`` (the measured residual and the mean gap's error within twice
the tolerance), ``named stop`` (the reason names the residual it reached, and the measured residual equals
the reported one), ``SILENT`` (anything else). Each solve has a time limit
(``--max-time`` per size). Output: studies/output/adhesion/stress.md, and stress.json, rewritten after every cell:
a rerun skips the cells it holds (delete it to rerun them all), ``--report`` only rewrites the table.
"""

import argparse
import os
import re
import time

import numpy as np

import common
from stress_grid import independent, surface

RTOLS = (1e-8, 1e-10, 1e-12)
CASES = {"strong exponential": ("exponential", 0.2, 1.0), "short exponential": ("exponential", 0.01, 1.0),
         "strong dugdale": ("dugdale", 0.2, 1.0), "near pull-off": ("dugdale", 0.2, 1.0)}
NAMED = re.compile(r"best (of )?natural residual|time limit|stagnation|round-off|no decrease")


def make_law(kind, problem, range_, peak):
    from roughpetsc.contact.laws import Dugdale, Exponential

    range_ *= problem.sqrt_m0h
    peak *= problem.sqrt_m0p
    return Exponential(peak * range_, range_) if kind == "exponential" else Dugdale(peak * range_, peak)


def check(grid, heights, law, gbar, pressure, gap, result, rtol):
    """The verdict of one solve and the independently measured residuals.

    ``natural`` is max |min(g / sqrt(m0^h), (p + phi'(g)) / sqrt(m0^p))| from the returned fields alone (p the
    total pressure: p + phi'(g) is the contact pressure in contact and the equilibrium error out of it).
    """
    numpy_check = independent(grid, heights, 1.0, pressure, gap)
    scale = numpy_check["sqrt_m0p"]
    sqrt_m0h = float(np.sqrt(np.mean((heights - heights.mean()) ** 2)))
    excess = (pressure + law.force(gap)) / scale
    natural = float(np.abs(np.minimum(gap / sqrt_m0h, excess)).max())
    out = gap > 0
    row = {"natural": natural, "equilibrium": float(np.abs(excess[out]).max(initial=0.0)),
           "negative_contact": float(max(-excess[~out].min(initial=0.0), 0.0)),
           "mean_gap_error": float(abs(gap.mean() - gbar) / sqrt_m0h), "gap_mismatch": numpy_check["gap_mismatch"]}
    consistent = row["gap_mismatch"] <= 1e-8
    if result.converged:
        good = consistent and natural <= 2 * rtol and row["mean_gap_error"] <= 2 * rtol
        row["verdict"] = "converged" if good else "SILENT"
    else:
        agrees = abs(natural - result.kkt.natural) <= 1e-6 * natural + 1e-13
        named = NAMED.search(result.reason) is not None
        row["verdict"] = "named stop" if named and consistent and agrees else "SILENT"
    return row


def run_cell(problem, grid, heights, solver, case, rtol, max_time):
    from roughpetsc.contact import AdhesiveProblem
    from roughpetsc.solvers import Solver

    kind, range_, peak = CASES[case]
    law = make_law(kind, problem, range_, peak)
    adhesive = Solver(AdhesiveProblem(problem, law), "displacement", solver, rtol=rtol,
                      options={"solve_max_time": max_time})
    start = time.perf_counter()
    try:
        if case == "near pull-off":
            results = []
            for gstar in np.linspace(0.5, 2.5, 13):
                result = adhesive.solve(gbar=gstar * problem.sqrt_m0h)
                results.append((result.pbar, gstar, result, [a.copy() for a in adhesive.fields()]))
            _, gstar, result, (pressure, gap) = min(results, key=lambda item: item[0])
        else:
            gstar = 1.0
            result = adhesive.solve(gbar=gstar * problem.sqrt_m0h)
            pressure, gap = (a.copy() for a in adhesive.fields())
    finally:
        adhesive.destroy()
    row = {"solver": solver, "case": case, "rtol": rtol, "gstar": float(gstar), "reason": result.reason,
           "converged": bool(result.converged), "reported_natural": result.kkt.natural,
           "seconds": round(time.perf_counter() - start, 2), "pstar": result.pstar, "A": result.A}
    row.update(check(grid, heights, law, gstar * problem.sqrt_m0h, pressure, gap, result, rtol))
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 256])
    parser.add_argument("--max-time", type=float, nargs="+", default=[20.0, 60.0])
    out = os.path.join(common.OUTPUT, "adhesion")
    args, path, rows = common.start_resumable(parser, out, "stress", "only rewrite the table from stress.json")
    from roughpetsc import ContactProblem

    done = {key_of(r) for r in rows}
    for n, max_time in zip(args.sizes, args.max_time) if not args.report else ():
        grid, heights = surface("fractal", n)
        problem = ContactProblem(grid, heights, 1.0)
        for solver in ("gapcg", "almm"):
            for case in CASES:
                for rtol in RTOLS:
                    if key_of({"solver": solver, "N": n, "case": case, "rtol": rtol}) in done:
                        continue
                    row = dict(run_cell(problem, grid, heights, solver, case, rtol, max_time), N=n)
                    rows.append(row)
                    common.save_rows(path, rows)
                    print(f"{solver:6s} N {n:4d} {case:18s} {rtol:g}: {row['verdict']:10s} "
                          f"natural {row['natural']:.1e} {row['seconds']:6.1f} s  {row['reason']}", flush=True)
        problem.destroy()
    write(rows, args, out)


def key_of(row):
    return f"{row['solver']}|{row['N']}|{row['case']}|{row['rtol']:g}"


def write(rows, args, out):
    counts = {v: sum(r["verdict"] == v for r in rows) for v in ("converged", "named stop", "SILENT")}
    lines = ["# Adhesive stress table", "",
             f"Generated by `.venv/bin/python studies/adhesion_stress.py --sizes {' '.join(map(str, args.sizes))} "
             f"--max-time {' '.join(f'{t:g}' for t in args.max_time)}` (cells and checks in its docstring).", "",
             f"{len(rows)} cells: {counts['converged']} converged, {counts['named stop']} named stops, "
             f"{counts['SILENT']} SILENT.", "",
             "| solver | N | case | rtol | verdict | measured natural | reported natural | g* | p* | A | s "
             "| reason |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['solver']} | {r['N']} | {r['case']} | {r['rtol']:g} | {r['verdict']} | "
                     f"{r['natural']:.1e} | {r['reported_natural']:.1e} | {r['gstar']:.3g} | {r['pstar']:+.4f} | "
                     f"{r['A']:.4f} | {r['seconds']} | {r['reason']} |")
    with open(os.path.join(out, "stress.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
