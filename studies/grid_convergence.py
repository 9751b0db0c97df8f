"""Grid convergence of the contact area and the mean gap (issue 14, item 2).

    .venv/bin/python studies/grid_convergence.py [--groups 1 18] [--seeds 1 2] [--sizes 256 512 1024 2048 4096]
                                                 [--pstars 0.05 0.5 2] [--rtol 1e-8] [--report]

Each surface is band-limited (k_s = 64 cycles per cell for groups 1 and 18), so one surface exists
independently of the grid: it is generated once on the coarsest grid of ``--sizes`` with the group's
generator (xu) and sampled on every finer grid by spectral interpolation (its Fourier modes padded with
zeros), which is exact for a band-limited surface. The same surface is then solved at each N under load
control (preconditioned Polonsky-Keer along the p* of ``--pstars``, rtol ``--rtol``), and A* by node
count (3.45), A* with the perimeter correction and g* are recorded.

For every (group, seed, p*) the observed order of convergence is p = log2((A_{N/4} - A_{N/2}) / (A_{N/2} -
A_N)) over the three finest grids, and the Richardson value A_N + (A_N - A_{N/2}) / (2^p - 1) with the
error bar |A_N - A_{N/2}| / (2^p - 1); where the differences do not shrink monotonically the order is
not defined and is reported as such. Rows go to studies/output/grid_convergence/grid_convergence.json
after every solve (a killed run resumes); ``--report`` writes grid_convergence.md and .png. Under
``mpiexec -n 2`` each grid is split over the ranks (8192^2 fits this machine only so) and rank 0 writes
the rows.
"""

import argparse
import json
import math
import os
import time

import numpy as np

import common

OUT = os.path.join(common.OUTPUT, "grid_convergence")
ROWS = os.path.join(OUT, "grid_convergence.json")


def band_limited_surface(group, seed, n_coarse, n):
    """The group's surface of ``seed`` generated on ``n_coarse``^2 and sampled on ``n``^2 (spectral padding)."""
    from roughpetsc import Grid, fractal

    heights = fractal(Grid(n_coarse, n_coarse, group["length"], group["length"]), group["k_l"], group["k_s"],
                      group["hurst"], group["m2"], seed, generator="xu")
    if n == n_coarse:
        return heights
    coarse = np.fft.rfft2(heights)
    fine = np.zeros((n, n // 2 + 1), dtype=complex)
    half = n_coarse // 2
    # The coarse Nyquist row and column carry no mode of a band-limited surface with k_s < n_coarse / 2.
    fine[:half, :half] = coarse[:half, :half]
    fine[-half + 1:, :half] = coarse[-half + 1:, :half]
    return np.fft.irfft2(fine, s=(n, n)) * (n / n_coarse) ** 2


def load_rows():
    if os.path.exists(ROWS):
        with open(ROWS) as f:
            return json.load(f)
    return []


def save_rows(rows):
    os.makedirs(OUT, exist_ok=True)
    temporary = ROWS + ".tmp"
    with open(temporary, "w") as f:
        json.dump(rows, f, indent=1)
    os.replace(temporary, ROWS)


def run(args):
    from petsc4py import PETSc

    from roughpetsc import ContactProblem, Grid, fractal_group, load_path

    root = PETSc.COMM_WORLD.getRank() == 0  # under mpiexec every rank solves its rows; rank 0 keeps the file
    rows = load_rows()
    done = {(r["group"], r["seed"], r["N"], r["pstar"]) for r in rows}
    n_coarse = min(args.sizes)
    for n in sorted(args.sizes):
        for number in args.groups:
            group = fractal_group(number)
            for seed in args.seeds:
                wanted = [p for p in args.pstars if (number, seed, n, p) not in done]
                if not wanted:
                    continue
                heights = band_limited_surface(group, seed, n_coarse, n)
                grid = Grid(n, n, group["length"], group["length"])
                problem = ContactProblem(grid, heights, 1.0)
                start = time.perf_counter()
                for pstar, result in zip(wanted, load_path(problem, pstars=wanted, rtol=args.rtol)):
                    rows.append({"group": number, "seed": seed, "N": n, "pstar": pstar, "A": result.A,
                                 "A_corrected": result.A_corrected, "gstar": result.gstar,
                                 "natural": result.kkt.natural, "converged": result.converged,
                                 "reason": result.reason, "time_s": result.time_s})
                    if root:
                        save_rows(rows)
                        print(f"group {number} seed {seed} N {n} p* {pstar}: A {result.A:.5f} corrected "
                              f"{result.A_corrected:.5f} g* {result.gstar:.5f} ({result.time_s:.1f} s, "
                              f"{result.reason})", flush=True)
                problem.destroy()
                if root:
                    print(f"  N {n}: {time.perf_counter() - start:.0f} s", flush=True)


def richardson(sizes, values):
    """(order, extrapolated value, error bar) over the three finest grids, whose sizes must grow by one ratio r:
    values[-1] + d / (r^p - 1) with d the last change; order None if not monotone."""
    if len(values) < 3:
        return None, values[-1], float("nan")
    ratio = sizes[-1] / sizes[-2]
    if not math.isclose(sizes[-2] / sizes[-3], ratio):
        raise ValueError(f"Richardson extrapolation needs grids of one ratio, got {sizes[-3:]}")
    a, b, c = values[-3:]
    d1, d2 = b - a, c - b
    if d1 == 0 or d2 == 0 or np.sign(d1) != np.sign(d2) or abs(d2) >= abs(d1):
        return None, c, abs(d2)
    order = math.log(d1 / d2) / math.log(ratio)
    error = abs(d2) / (ratio ** order - 1)
    return order, c + d2 / (ratio ** order - 1), error


def report():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = load_rows()
    keys = sorted({(r["group"], r["pstar"]) for r in rows})
    lines = ["# Grid convergence of A* and g* (one band-limited surface per seed, sampled on every grid)", "",
             "Generated by `.venv/bin/python studies/grid_convergence.py` (module docstring). Values are means "
             "over the seeds; the order and the Richardson value are those of the seed mean over the three "
             "finest grids.", "",
             "| group | p* | quantity | " + " | ".join(f"N={n}" for n in sorted({r['N'] for r in rows}))
             + " | order | extrapolated +- error |", ""]
    lines[-1] = "|" + "---|" * (lines[-2].count("|") - 1)
    figure, axes = plt.subplots(1, len(keys), figsize=(3.2 * len(keys), 3.2), squeeze=False)
    for axis, (group, pstar) in zip(axes[0], keys):
        selected = [r for r in rows if r["group"] == group and r["pstar"] == pstar]
        sizes = sorted({r["N"] for r in selected})
        for quantity, style in (("A", "o-"), ("A_corrected", "s--"), ("gstar", None)):
            means = [np.mean([r[quantity] for r in selected if r["N"] == n]) for n in sizes]
            order, value, error = richardson(sizes, means)
            order_text = f"{order:.2f}" if order is not None else "not monotone"
            lines.append(f"| {group} | {pstar} | {quantity} | " + " | ".join(f"{m:.5f}" for m in means)
                         + f" | {order_text} | {value:.5f} +- {error:.1e} |")
            if style:
                axis.plot([1 / n for n in sizes], means, style, label=quantity)
        axis.set_title(f"group {group}, p* = {pstar}", fontsize=9)
        axis.set_xlabel("1 / N")
        axis.set_xscale("log")
    axes[0][0].set_ylabel("A*")
    axes[0][0].legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(os.path.join(OUT, "grid_convergence.png"), dpi=120)
    with open(os.path.join(OUT, "grid_convergence.md"), "w") as f:
        f.write("\n".join(lines) + "\n\n![A* against 1/N](grid_convergence.png)\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--groups", type=int, nargs="+", default=[1, 18])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024, 2048, 4096])
    parser.add_argument("--pstars", type=float, nargs="+", default=[0.05, 0.5, 2.0])
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    common.init()
    if not args.report:
        run(args)
    from petsc4py import PETSc

    if PETSc.COMM_WORLD.getRank() == 0:
        report()


if __name__ == "__main__":
    main()
