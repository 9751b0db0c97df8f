"""The stress grid: every solver preset on every kind of surface, load and tolerance, each answer checked
independently; zero silent failures is the target.

    .venv/bin/python studies/stress_grid.py [--sizes 64 256 1024] [--presets ...] [--max-time 20 60 120]

Cells: every preset of solvers/ x N in --sizes x p* in {0.01, 0.5, 3, 0.98 of complete contact} x natural-
residual tolerance in {1e-8, 1e-10, 1e-12} x six surfaces: a group-#1-like fractal (k_l = N/16 up to 16,
k_s = N/4 up to 64, H = 0.8), the Westergaard wave, the bisinusoid (3.52), the fractal with its highest
10 % cut to a plateau of equal heights, and the fractal scaled to 1e-9 and to 1e6 rms. Load control throughout
(the bound types through the root find on the separation). Each solve has a time limit (--max-time, per size).
Wall seconds (the limit's clock) and CPU seconds are both recorded: a run paused or starved by other jobs shows
a wall time past its limit with CPU time within it.

The answer is checked with numpy alone: the gap of the returned pressure through numpy's FFT and the symbol
1 / (pi E* |k|), the separation taken from the solver's gap (their difference must be a constant to 1e-8
rms heights), the load from numpy's pressure surface. Verdicts:

* ``converged``: the solver says converged and the independent natural residual and load error are within
  twice the tolerance;
* ``exact``: beyond complete contact, p = pbar + p_c to 1e-10;
* ``named stop``: the solver says not converged and names why and the residual it reached (a floor, a time
  limit, stagnation, a load error), and that residual agrees with the independent one;
* ``SILENT``: anything else (a convergence claim the check rejects, an unnamed stop, an exception).

Rows go to studies/output/stress/stress_grid.json after every cell (rerunning skips finished cells, so a
killed run resumes); studies/output/stress/stress_grid.md and stress_grid.png (one heat map per N) are
rewritten at the end and by ``--report``. ``--shard NAME`` writes to stress_grid.NAME.json instead, so two
processes on disjoint sizes or presets can share a 2-core machine; every run skips the cells of every file and the
report merges them.
"""

import argparse
import glob
import os
import re
import time

import numpy as np

import common
from roughpetsc import Grid, bisinusoid, fractal, fractal_group, pressure_surface, wave  # PETSc-free names

OUT = os.path.join(common.OUTPUT, "stress")
LOADS = ("0.01", "0.5", "3", "near complete")
RTOLS = (1e-8, 1e-10, 1e-12)
SURFACES = ("fractal", "wave", "bisinusoid", "plateau", "scaled 1e-9", "scaled 1e6")
VERDICTS = ("converged", "exact", "named stop", "SILENT")
NAMED = re.compile(r"best (of )?natural residual|time limit|stagnation|load error|floor")


def surface(kind, n):
    """The surface ``kind`` of :data:`SURFACES` on an ``n x n`` unit cell: ``(grid, heights)``."""
    grid = Grid(n, n)
    group = fractal_group(1)  # group #1 of Table 7.1, its wavenumbers capped for the small grids
    rough = fractal(grid, min(group["k_l"], n // 16), min(group["k_s"], n // 4), group["hurst"], group["m2"], 5)
    if kind == "fractal":
        return grid, rough
    if kind == "wave":
        return grid, wave(grid, 1e-3, 0.5)
    if kind == "bisinusoid":
        return grid, bisinusoid(grid, 1e-3, 0.5, 0.5)
    if kind == "plateau":
        return grid, np.minimum(rough, np.quantile(rough, 0.9))
    scale = 1e-9 if kind == "scaled 1e-9" else 1e6
    return grid, rough * scale / np.sqrt(np.mean(rough ** 2))


def independent(grid, heights, E_star, pressure, gap):
    """Natural residual, load and complete-contact check of a returned field, with numpy's FFT (and the pressure
    surface (2.47) of :func:`roughpetsc.pressure_surface`, numpy's FFT too)."""
    n0, n1 = grid.shape
    k = np.hypot(np.fft.fftfreq(n0, grid.l0 / n0)[:, None], np.fft.rfftfreq(n1, grid.l1 / n1)[None, :])
    with np.errstate(divide="ignore"):
        compliance = np.where(k > 0, 1.0 / (np.pi * E_star * k), 0.0)
    h = heights - heights.mean()
    sqrt_m0h = np.sqrt(np.mean(h ** 2))
    complete_pressure = pressure_surface(grid, h, E_star)
    sqrt_m0p = np.sqrt(np.mean(complete_pressure ** 2))
    elastic = np.fft.irfft2(compliance * np.fft.rfft2(pressure), s=grid.shape) - h
    separation = np.mean(gap - elastic)
    ours = elastic + separation
    return {"sqrt_m0p": sqrt_m0p, "pressure_surface": complete_pressure,
            "gap_mismatch": float(np.abs(ours - gap).max() / sqrt_m0h), "gap": ours / sqrt_m0h}


def run_cell(problem, grid, heights, preset, options, pstar, rtol, max_time):
    row = {"pstar": pstar}
    start, cpu_start = time.perf_counter(), time.process_time()
    solver = common.preset_solver(problem, dict(options, solve_max_time=max_time), rtol)
    try:
        result = solver.solve(pstar=pstar)
        pressure, gap = (a.copy() for a in solver.fields())
    finally:
        solver.destroy()
    row.update(seconds=round(time.perf_counter() - start, 3), cpu_seconds=round(time.process_time() - cpu_start, 3),
               reason=result.reason, converged=bool(result.converged),
               reported_natural=result.kkt.natural, iterations=result.iterations, A=result.A)
    check = independent(grid, heights, problem.E_star, pressure, gap)
    pbar = pstar * check["sqrt_m0p"]
    natural = float(np.abs(np.minimum(pressure / pbar, check["gap"])).max())
    load_error = float(abs(pressure.mean() - pbar) / pbar)
    row.update(natural=natural, load_error=load_error, gap_mismatch=check["gap_mismatch"])
    if result.reason.startswith("COMPLETE_CONTACT"):
        error = np.abs(pressure - (pbar + check["pressure_surface"])).max() / pbar
        row["verdict"] = "exact" if error <= 1e-10 and result.converged else "SILENT"
    elif result.converged:
        good = natural <= 2 * rtol and load_error <= 2 * rtol and check["gap_mismatch"] <= 1e-8
        row["verdict"] = "converged" if good else "SILENT"
    else:
        agrees = abs(natural - result.kkt.natural) <= 1e-6 * max(natural, 1e-300) + 1e-13
        row["verdict"] = "named stop" if NAMED.search(result.reason) and agrees else "SILENT"
    return row


def key_of(row):
    return f"{row['preset']}|{row['N']}|{row['surface']}|{row['load']}|{row['rtol']:g}"


def heat_map(rows, presets, sizes, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap

    colours = ListedColormap(["#2e7d32", "#81c784", "#fbc02d", "#c62828", "#dddddd"])
    code = {v: i for i, v in enumerate(VERDICTS)}
    by_key = {key_of(r): r for r in rows}
    columns = [(s, load, rtol) for s in SURFACES for load in LOADS for rtol in RTOLS]
    fig, axes = plt.subplots(len(sizes), 1, figsize=(16, 2.2 + 0.32 * len(presets) * len(sizes)), squeeze=False)
    for ax, n in zip(axes[:, 0], sizes):
        grid = np.full((len(presets), len(columns)), 4)
        for i, preset in enumerate(presets):
            for j, (s, load, rtol) in enumerate(columns):
                row = by_key.get(f"{preset}|{n}|{s}|{load}|{rtol:g}")
                if row:
                    grid[i, j] = code[row["verdict"]]
        ax.imshow(grid, cmap=colours, vmin=-0.5, vmax=4.5, aspect="auto", interpolation="nearest")
        ax.set_yticks(range(len(presets)), presets, fontsize=7)
        ax.set_xticks([j * len(LOADS) * len(RTOLS) + 5.5 for j in range(len(SURFACES))], SURFACES, fontsize=8)
        for j in range(1, len(SURFACES)):
            ax.axvline(j * len(LOADS) * len(RTOLS) - 0.5, color="k", lw=1)
        ax.set_title(f"N = {n}: columns per surface are p* in {', '.join(LOADS)}, each at rtol 1e-8, 1e-10, 1e-12",
                     fontsize=9)
    handles = [plt.Rectangle((0, 0), 1, 1, color=colours(i)) for i in range(5)]
    fig.legend(handles, list(VERDICTS) + ["not run"], loc="upper right", ncol=5, fontsize=8)
    common.save_figure(fig, os.path.dirname(path), os.path.basename(path))


def report(rows, presets, sizes):
    counts = {v: sum(r["verdict"] == v for r in rows) for v in VERDICTS}
    lines = ["# Stress grid: every preset x surface x load x tolerance", "",
             "Generated by `.venv/bin/python studies/stress_grid.py` (see its docstring for the cells and the "
             "independent checks). Load control; time limit per solve as given by `--max-time`.", "",
             f"{len(rows)} cells run: " + ", ".join(f"{counts[v]} {v}" for v in VERDICTS) + ".", "",
             "![heat map](stress_grid.png)", "", "## Per preset and N", ""]
    table = []
    for preset in presets:
        for n in sizes:
            cells = [r for r in rows if r["preset"] == preset and r["N"] == n]
            if not cells:
                continue
            stops = [r for r in cells if r["verdict"] == "named stop"]
            cpu = [r["cpu_seconds"] for r in cells if "cpu_seconds" in r]  # rows of earlier stops lack it
            floor = max((r["natural"] for r in stops), default=float("nan"))
            table.append([preset, n, len(cells)] + [sum(r["verdict"] == v for r in cells) for v in VERDICTS]
                         + [f"{floor:.1e}" if stops else "", f"{max(r['seconds'] for r in cells):.1f}",
                            f"{max(cpu):.1f}" if cpu else ""])
    lines.append(common.markdown_table(["preset", "N", "cells"] + list(VERDICTS)
                                       + ["worst stopped residual", "max s", "max CPU s"], table))
    silent = [r for r in rows if r["verdict"] == "SILENT"]
    lines += ["", "## Silent failures", ""]
    lines.append(common.markdown_table(["cell", "natural", "load err", "reported", "reason"],
                                       [[key_of(r), f"{r['natural']:.1e}", f"{r['load_error']:.1e}",
                                         f"{r['reported_natural']:.1e}", r["reason"]] for r in silent])
                 if silent else "None.")
    lines += ["", "## Named stops", ""]
    stops = [r for r in rows if r["verdict"] == "named stop"]
    lines.append(common.markdown_table(["cell", "natural", "its", "s", "CPU s", "reason"],
                                       [[key_of(r), f"{r['natural']:.1e}", r["iterations"], r["seconds"],
                                         r.get("cpu_seconds", ""), r["reason"]] for r in stops]) if stops else "None.")
    with open(os.path.join(OUT, "stress_grid.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    heat_map(rows, presets, sizes, os.path.join(OUT, "stress_grid.png"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[64, 256, 1024])
    parser.add_argument("--max-time", type=float, nargs="*", default=[20.0, 60.0, 120.0])
    parser.add_argument("--presets", nargs="*", default=None)
    parser.add_argument("--shard", default=None,
                        help="write this run's rows to stress_grid.SHARD.json, so that two processes (disjoint "
                             "--sizes or --presets) can share the machine; the report merges every shard")
    args, path, rows = common.start_resumable(parser, OUT, "stress_grid", "only rewrite the report from the JSON")
    shards = sorted(glob.glob(os.path.join(OUT, "stress_grid.*.json")))
    others = [r for shard in shards if shard != path_of(args.shard) for r in common.load_rows(shard)]
    if args.shard:
        others += rows
        path = path_of(args.shard)
        rows = common.load_rows(path)
    from petsc4py import PETSc

    from roughpetsc import ContactProblem

    presets = list(common.presets(args.presets))
    done = {key_of(r) for r in rows + others}
    for n, max_time in zip(args.sizes, args.max_time) if not args.report else ():
        for kind in SURFACES:
            grid, heights = surface(kind, n)
            problem = ContactProblem(grid, heights, 1.0, PETSc.COMM_SELF, fft_effort="FFTW_ESTIMATE")
            complete = problem.complete_contact_pbar * problem.pressure_scale / problem.sqrt_m0p
            try:
                for load in LOADS:
                    pstar = 0.98 * complete if load == "near complete" else float(load)
                    for rtol in RTOLS:
                        for preset in presets:
                            cell = {"preset": preset, "N": n, "surface": kind, "load": load, "rtol": rtol}
                            if key_of(cell) in done:
                                continue
                            options = common.presets([preset])[preset]
                            try:
                                cell.update(run_cell(problem, grid, heights, preset, options, pstar, rtol, max_time))
                            except Exception as error:  # noqa: BLE001 - a crash is a verdict here
                                cell.update(verdict="SILENT", reason=f"exception: {error!r}", natural=float("nan"),
                                            load_error=float("nan"), reported_natural=float("nan"), seconds=0.0,
                                            iterations=0, pstar=pstar)
                            rows.append(cell)
                            print(f"{key_of(cell):60s} {cell['verdict']:10s} natural {cell['natural']:.1e} "
                                  f"{cell['seconds']:7.2f} s  {cell['reason']}", flush=True)
                            common.save_rows(path, rows)
            finally:
                problem.destroy()
    merged = list({key_of(r): r for r in others + rows}.values())
    report(merged, presets, sorted({r["N"] for r in merged}))


def path_of(shard):
    """The JSON file of a shard's rows (None: the main file)."""
    return os.path.join(OUT, f"stress_grid.{shard}.json" if shard else "stress_grid.json")


if __name__ == "__main__":
    main()
