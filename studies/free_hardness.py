"""The free boundary, the hardness cap and subsurface stresses (issue 16): checks and costs.

    .venv/bin/python studies/free_hardness.py [--sizes 128 256 512 1024] [--repeat 3]

Writes studies/output/free_hardness/free_hardness.md and free_hardness.png:

1. Hertz on the free boundary (sphere R = 1 in a unit cell pressed to a = 1/8; PK, load control,
   natural residual 1e-10): the contact radius (node count and perimeter-corrected), the central
   pressure, the approach and the rms error of the pressure profile against Hertz, and the observed
   order of convergence in N; beside it the periodic answer, whose approach differs (the images).
2. Periodic against free as the cell grows around the same sphere (a fixed in length units, the cell
   L = 4a ... 32a at a fixed 16 nodes per a): the relative difference of the approach and of p0.
3. Stresses below the Hertz contact (nu = 0.3): max shear and its depth on the axis against
   0.31 p0 at 0.48 a, and the surface radial stress at the edge against (1 - 2 nu) p0 / 3.
4. The hardness cap on the sphere: plastic area, contact area and load / H against the load.
5. Costs, as ratios of times measured in one run (the machine is shared; medians of --repeat):
   free / periodic solve at the same N (target <= 4.5), capped / uncapped solve (target <= 1.2, a
   group-#1 surface at p* = 0.5 with H at the 95th percentile of the uncapped pressure), and the
   stresses at 8 depths per depth in operator applications (target <= 3 each), beside their floor: the
   bare FFTs a depth needs (six inverse transforms periodic, twelve padded ones free).
"""

import argparse
import os
import statistics
import time

import numpy as np

import common

OUT = os.path.join(common.OUTPUT, "free_hardness")
NU = 0.3


def hertz_run(n, boundary="free", cell=1.0, a=1 / 8, hardness=None, load_scale=1.0):
    """Solve the sphere (R = 1) on an n x n cell of side ``cell``: (result, pressure, heights, grid, seconds)."""
    from roughpetsc import ContactProblem, Grid, Solver, hertz_sphere

    grid = Grid(n, n, cell, cell)
    load = load_scale * 4.0 / 3.0 * a ** 3
    heights = hertz_sphere(grid, 1.0)
    problem = ContactProblem(grid, heights, 1.0, boundary=boundary, hardness=hardness)
    solver = Solver(problem, "load", None, 1e-10)
    try:
        start = time.perf_counter()
        result = solver.solve(pbar=load / grid.area)
        seconds = time.perf_counter() - start
        pressure, _ = solver.fields()
        return result, pressure.copy(), heights, grid, seconds
    finally:
        solver.destroy()
        problem.destroy()


def hertz_errors(n):
    a, load = 1 / 8, 4.0 / 3.0 / 512
    p0 = 3 * load / (2 * np.pi * a ** 2)
    rows = {}
    for boundary in ("free", "periodic"):
        result, pressure, heights, grid, seconds = hertz_run(n, boundary)
        centre = n // 2
        y, x = (np.mgrid[:n, :n] - centre) / n
        profile = p0 * np.sqrt(np.clip(1 - (x * x + y * y) / a ** 2, 0, None))
        approach = (heights - heights.mean()).max() - result.separation
        rows[boundary] = {
            "N": n, "converged": result.converged, "reason": result.reason,
            "a_nodes": np.sqrt(result.A / np.pi) / a - 1, "a_corrected": np.sqrt(result.A_corrected / np.pi) / a - 1,
            "p0": pressure[centre, centre] / p0 - 1, "approach": approach / a ** 2 - 1,
            "profile_rms": float(np.sqrt(np.mean((pressure - profile) ** 2)) / p0), "seconds": seconds,
            "applications": result.operator_applications}
    return rows


def order(errors, sizes):
    """Observed orders of convergence between successive grids (log2 of the error ratios)."""
    return [float(np.log(abs(e0 / e1)) / np.log(n1 / n0)) for e0, e1, n0, n1 in zip(errors, errors[1:], sizes, sizes[1:])]


def cell_growth():
    """Periodic against free for a sphere of fixed a = 1/8 as the cell grows (16 nodes per a)."""
    rows = []
    for cells_per_a in (4, 8, 16, 32):
        n = 16 * cells_per_a
        answers = {}
        for boundary in ("free", "periodic"):
            result, pressure, heights, grid, _ = hertz_run(n, boundary, cell=cells_per_a / 8)
            approach = (heights - heights.mean()).max() - result.separation
            answers[boundary] = (approach, pressure[n // 2, n // 2])
        rows.append({"L/a": cells_per_a, "approach": answers["periodic"][0] / answers["free"][0] - 1,
                     "p0": answers["periodic"][1] / answers["free"][1] - 1})
    return rows


def hertz_stresses(n):
    from roughpetsc.elastic.stresses import free_stresses, max_shear

    a, load = 1 / 8, 4.0 / 3.0 / 512
    p0 = 3 * load / (2 * np.pi * a ** 2)
    _, pressure, _, grid, _ = hertz_run(n)
    centre = n // 2
    depths = np.linspace(0.3, 0.7, 81) * a
    spacing = (grid.l0 / n, grid.l1 / n)
    shear = [max_shear({k: v[centre:centre + 1, centre:centre + 1] for k, v in s.components.items()})[0, 0]
             for s in free_stresses(pressure, spacing, depths, NU)]
    best = int(np.argmax(shear))
    (surface,) = free_stresses(pressure, spacing, [0.0], NU)
    # The radial stress on the surface peaks (in tension) at the edge of the contact: its maximum along x.
    return {"N": n, "max_shear/p0": shear[best] / p0, "depth/a": depths[best] / a,
            "edge_radial/p0": float(surface.components["xx"][centre, centre:].max()) / p0}


def plastic_curve(n):
    a, rows = 1 / 8, []
    hertz_mean = 4.0 / 3.0 * a ** 3 / (np.pi * a ** 2)
    hardness = 1.2 * hertz_mean
    for scale in (0.25, 0.5, 1.0, 2.0, 4.0):
        result, _, _, grid, _ = hertz_run(n, hardness=hardness, load_scale=scale)
        load = scale * 4.0 / 3.0 * a ** 3
        rows.append({"load": load, "A": result.A, "A_plastic": result.A_plastic, "load/H": load / hardness,
                     "converged": result.converged})
    return rows, hardness


def median_seconds(run, repeat):
    return statistics.median(run() for _ in range(repeat))


def costs(n, repeat):
    """Time ratios measured in one run: free / periodic, capped / uncapped, stresses per depth in applications."""
    from roughpetsc import ContactProblem, Grid, Solver
    from roughpetsc.elastic.stresses import free_stresses, periodic_stresses

    grid = Grid(n, n)
    heights = common.group1_heights(grid)

    def solve(boundary="periodic", hardness=None):
        problem = ContactProblem(grid, heights, 1.0, boundary=boundary, hardness=hardness)
        solver = Solver(problem, "load", None, 1e-8)
        try:
            start = time.perf_counter()
            result = solver.solve(pstar=0.5)
            seconds = time.perf_counter() - start
            assert result.converged, result.reason
            pressure, _ = solver.fields()
            return seconds, pressure.copy(), result
        finally:
            solver.destroy()
            problem.destroy()

    _, uncapped, _ = solve()
    hardness = float(np.quantile(uncapped[uncapped > 0], 0.95))
    # Interleaved repeats, so that a change in the machine's load falls on every kind of solve alike.
    seconds = {"periodic": [], "free": [], "capped": []}
    for _ in range(repeat):
        seconds["periodic"].append(solve()[0])
        seconds["free"].append(solve("free")[0])
        capped_seconds, _, capped_result = solve(hardness=hardness)
        seconds["capped"].append(capped_seconds)
    periodic_s, free_s, capped_s = (statistics.median(seconds[kind]) for kind in ("periodic", "free", "capped"))
    application = {boundary: operator_seconds(grid, heights, boundary, max(repeat, 5))
                   for boundary in ("periodic", "free")}
    depths = np.linspace(0.0, 0.1, 8)
    periodic_depth = median_seconds(lambda: _timed_list(periodic_stresses(uncapped, (1.0, 1.0), depths, NU)),
                                    repeat) / len(depths)
    free_depth = median_seconds(lambda: _timed_list(free_stresses(uncapped, (1 / n, 1 / n), depths, NU)),
                                repeat) / len(depths)
    periodic_floor, free_floor = (transform_floor(shape, count, repeat)
                                  for shape, count in (((n, n), (0, 6)), ((2 * n, 2 * n), (6, 6))))
    return {"N": n, "free/periodic": free_s / periodic_s, "capped/uncapped": capped_s / periodic_s,
            "A_plastic": capped_result.A_plastic, "capped reason": capped_result.reason,
            "periodic stresses per depth / application": periodic_depth / application["periodic"],
            "their floor, six inverse transforms / application": periodic_floor / application["periodic"],
            "free stresses per depth / free application": free_depth / application["free"],
            "their floor, twelve padded transforms / free application": free_floor / application["free"],
            "free stresses per depth / periodic application": free_depth / application["periodic"],
            "periodic solve s": periodic_s}


def operator_seconds(grid, heights, boundary, repeat):
    """Median seconds of one application of the operator (K p) of ``boundary``."""
    from roughpetsc import ContactProblem

    problem = ContactProblem(grid, heights, 1.0, boundary=boundary)
    x, y = problem.vec(), problem.vec()
    try:
        return median_seconds(lambda: _timed(problem.operator.displacement, x, y), repeat)
    finally:
        x.destroy()
        y.destroy()
        problem.destroy()


def transform_floor(shape, counts, repeat):
    """Median seconds of ``counts = (forward, inverse)`` bare transforms on ``shape``: what the stresses of
    one depth cannot do without (the FFTW plans of :mod:`roughpetsc.stresses`, from the solves' wisdom)."""
    from roughpetsc.elastic.stresses import fft_pair

    real, spectrum, forward, backward = fft_pair(shape, "FFTW_MEASURE")
    real[...] = 1.0
    spectrum[...] = 1.0  # the inverse destroys it, into values of the same size: no refill in the timing

    def run():
        start = time.perf_counter()
        for _ in range(counts[0]):
            forward.execute()
        for _ in range(counts[1]):
            backward.execute()
        return time.perf_counter() - start

    return median_seconds(run, repeat)


def _timed(function, *args):
    start = time.perf_counter()
    function(*args)
    return time.perf_counter() - start


def _timed_list(generator):
    start = time.perf_counter()
    for _ in generator:
        pass
    return time.perf_counter() - start


def figure(path, hertz_rows, plastic_rows, hardness):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    sizes = [row["free"]["N"] for row in hertz_rows]
    for key, label in (("p0", "central pressure"), ("approach", "approach"), ("profile_rms", "profile rms / p0"),
                       ("a_corrected", "radius (perimeter-corrected)")):
        left.loglog(sizes, [abs(row["free"][key]) for row in hertz_rows], "o-", label=label)
    left.set_xlabel("N (nodes per side; a = N/8 nodes)")
    left.set_ylabel("relative error against Hertz")
    left.set_title("Hertz on the free boundary")
    left.legend(fontsize=8)
    loads = [row["load"] for row in plastic_rows]
    right.plot(loads, [row["A"] for row in plastic_rows], "o-", label="contact area A")
    right.plot(loads, [row["A_plastic"] for row in plastic_rows], "s-", label="plastic area")
    right.plot(loads, [row["load/H"] for row in plastic_rows], "k--", label="load / H (fully plastic)")
    right.set_xlabel("load P (E* = R = 1)")
    right.set_ylabel("area fraction of the unit cell")
    right.set_title(f"sphere with hardness H = {hardness:.3g}")
    right.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def table(rows, keys):
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for row in rows:
        lines.append("| " + " | ".join(f"{row[k]:.3g}" if isinstance(row[k], float) else str(row[k]) for k in keys) + " |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[128, 256, 512, 1024])
    parser.add_argument("--cost-size", type=int, default=512)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    common.init()
    os.makedirs(OUT, exist_ok=True)
    hertz_rows = [hertz_errors(n) for n in args.sizes]
    for row in hertz_rows:
        print("hertz", row["free"], flush=True)
    growth = cell_growth()
    stresses = [hertz_stresses(n) for n in args.sizes[:3]]
    plastic_rows, hardness = plastic_curve(args.sizes[1])
    cost = costs(args.cost_size, args.repeat)
    figure(os.path.join(OUT, "free_hardness.png"), hertz_rows, plastic_rows, hardness)
    keys = ["N", "a_nodes", "a_corrected", "p0", "approach", "profile_rms", "seconds", "applications", "converged"]
    free = [row["free"] for row in hertz_rows]
    orders = {key: order([row[key] for row in free], args.sizes) for key in ("p0", "approach", "profile_rms")}
    text = [
        "# Free boundary, hardness cap, subsurface stresses",
        "",
        f"Generated by `.venv/bin/python studies/free_hardness.py --sizes {' '.join(map(str, args.sizes))} "
        f"--cost-size {args.cost_size} --repeat {args.repeat}` (see its docstring).",
        "",
        "![Hertz errors and plastic areas](free_hardness.png)",
        "",
        "## Hertz on the free boundary (relative errors; a = N/8 nodes)",
        "",
        table(free, keys),
        "",
        "Observed orders of convergence between successive N: " + "; ".join(
            f"{key} {', '.join(f'{v:.2f}' for v in values)}" for key, values in orders.items()),
        "",
        "The periodic cell gives the same contact radius and central pressure to 0.3 % but an approach "
        "20 % short: its images and the rigid mode of the mean pressure (relative errors, periodic):",
        "",
        table([row["periodic"] for row in hertz_rows], ["N", "p0", "approach", "profile_rms"]),
        "",
        "## Periodic against free as the cell grows (16 nodes per a)",
        "",
        table(growth, ["L/a", "approach", "p0"]),
        "",
        "## Stresses below the Hertz contact (nu = 0.3)",
        "",
        "Johnson (1985): max shear 0.31 p0 at 0.48 a on the axis; radial stress (1 - 2 nu) p0 / 3 = 0.133 p0 at "
        "the edge (here the largest radial stress on the surface along x; the solved contact's edge is a node "
        "wide).",
        "",
        table(stresses, ["N", "max_shear/p0", "depth/a", "edge_radial/p0"]),
        "",
        f"## Hardness cap on the sphere (H = {hardness:.4g}, 1.2 x the mean Hertz pressure at a = 1/8)",
        "",
        "0 <= p <= H gives A_plastic H <= load <= A H (a fully plastic contact has A = load / H).",
        "",
        table(plastic_rows, ["load", "A", "A_plastic", "load/H", "converged"]),
        "",
        f"## Costs at N = {cost['N']} (ratios of medians measured in one run)",
        "",
        "\n".join(f"- {key}: {value:.3g}" if isinstance(value, float) else f"- {key}: {value}"
                  for key, value in cost.items()),
        "",
    ]
    with open(os.path.join(OUT, "free_hardness.md"), "w") as f:
        f.write("\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
