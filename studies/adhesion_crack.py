"""The adhesive crack of the dissertation's sections 6.2-6.4 against the periodic BEM (issue 15, item 4).

    .venv/bin/python studies/adhesion_crack.py [--sigmas 0.5 1 2 5] [--sizes 256 512 1024] [--ratios 1 1.5 3]
                                               [--ellipse-sizes 256 512] [--steps 40]

The crack models of chapter 6 describe one non-contact region ("crack") of a nearly complete contact: the
surfaces are in contact except near a peak of the pressure surface -p_c, where the complete-contact traction
p(r) = p0 - kappa^p r^2 / 2 (6.1) is tensile. The BEM problem that is exactly this: a surface whose pressure
surface is the periodic paraboloid -p_c = -(kappa_1 dx^2 + kappa_2 dy^2) / 2 + const (dx, dy the periodic
distances from the cell centre; its kink at the cell edges lies deep in the contact), so that within any crack
the traction is exactly quadratic. The heights come from roughpetsc.heights_from_pressure_surface (the inverse
of (2.47) on the grid, so the discrete complete-contact pressure is p_c exactly). With the Dugdale law (sigma0,
h0 = w / sigma0) the crack's tensile load is p0 = max(-p_c) - pbar, and its radius b, the inner end c of the
Dugdale zone (gap h0) and the trapped volume V are read from the gap field: pi b^2 = the open area,
pi c^2 = the area with g > h0, V = the cell's mean gap times its area.

Penny-shaped crack (kappa_1 = kappa_2 = kappa^p): the states along a path in the mean gap (volume control:
more of the solution set is stable than under load control, and the path's jumps are where its volume turns)
are compared with :class:`roughpetsc.models.adhesion.AdhesiveCrack` in the groups (6.4)-(6.6): the Maugis-Dugdale curve
(6.28)-(6.29) joined at F (m = 0) to the full-adhesion branch b* = sqrt(2 (p* - sigma0*) / 3) (6.36), which
starts at E (p* = sigma0*, (6.38)). Reported: the largest distance of a BEM state to that set in (p*, b*), the
local maximum of p* along the path against p*_F = sigma0* + 3/2 sigma0*^(-2/3) (6.39), its local minimum
against p*_B (the snap-in of Fig. 6.2), m against the model, and V* against the closed-form volume.

Elliptical crack (section 6.4, kappa_1 = ratio x kappa_2): the crack area and volume along the same kind of
path against the penny-shaped model with kappa^p replaced by the geometric mean curvature sqrt(kappa_1
kappa_2) and by the arithmetic mean (kappa_1 + kappa_2) / 2, the two "mildly elliptical" models.

Scales: E* = 1, kappa_2 = 1, unit cell; w is chosen so that L = (81 pi E* w / (16 kappa^2))^(1/5) = 0.04 of
the cell, i.e. L = 0.04 N nodes; the cracks reach b* = 2.4 (b = 0.1: images in the periodic cell change the
crack's compliance by about (b / cell)^3 = 1e-3). The path is dense up to twice the volume of B or F, where
the turning points lie, then geometric. Output: studies/output/adhesion/crack.md, crack.png.
"""

import argparse
import math
import os

import numpy as np

import common
from roughpetsc import heights_from_pressure_surface
from roughpetsc.models.adhesion import AdhesiveCrack

E_STAR, KAPPA, LENGTH = 1.0, 1.0, 0.04
B_MAX = 2.4


def scales(kappa):
    """(w, P, L) of the groups (6.4)-(6.6) for curvature kappa at the study's work of adhesion."""
    work = 16 * KAPPA ** 2 * LENGTH ** 5 / (81 * math.pi * E_STAR)
    pressure = (math.pi ** 2 * E_STAR ** 2 * work ** 2 * kappa / 72) ** 0.2
    length = (81 * math.pi * E_STAR * work / (16 * kappa ** 2)) ** 0.2
    return work, pressure, length


def paraboloid_surface(grid, kappa_1, kappa_2):
    """Heights whose complete-contact pressure p_c is -(kappa_1 dx^2 + kappa_2 dy^2) / 2 less its mean, and
    the peak max(-p_c) [pressure]."""
    n0, n1 = grid.shape
    dx = (np.arange(n0) - n0 // 2) * grid.l0 / n0
    dy = (np.arange(n1) - n1 // 2) * grid.l1 / n1
    pressure_surface = -0.5 * (kappa_1 * dx[:, None] ** 2 + kappa_2 * dy[None, :] ** 2)
    pressure_surface -= pressure_surface.mean()
    return heights_from_pressure_surface(grid, -pressure_surface, E_STAR), float(pressure_surface.max())


def run_case(n, sigma, ratio, steps):
    """Rows (p0, b, c, V, pbar, converged) along an opening and closing path of the crack."""
    from roughpetsc import ContactProblem, Grid
    from roughpetsc.contact import AdhesiveProblem
    from roughpetsc.solvers import Solver
    from roughpetsc.contact.laws import Dugdale

    kappa_1 = ratio * KAPPA
    work, pressure, length = scales(math.sqrt(kappa_1 * KAPPA))
    stress = sigma * pressure
    grid = Grid(n, n)
    heights, peak = paraboloid_surface(grid, kappa_1, KAPPA)
    crack = AdhesiveCrack(sigma)
    volume_scale = 3 * work / (2 * math.sqrt(kappa_1 * KAPPA))
    _, b_set, m_set, v_set = crack.solution_set()
    v_max = float(v_set[np.argmin(np.abs(b_set - B_MAX))]) * volume_scale
    p_b, b_b, m_b = crack.points["B"]
    # E, F and B lie below v_turns; the set's volume falls after F, so volume control jumps there too
    v_turns = 2 * max(float(crack.volume(p_b, b_b, m_b)), float(v_set[np.argmax(m_set > 0) - 1])) * volume_scale
    opening = np.concatenate([np.linspace(0.005 * v_turns, v_turns, steps),
                              np.geomspace(v_turns, v_max, steps // 2)[1:]])
    gbars = np.concatenate([opening, opening[-2::-1]])
    problem = ContactProblem(grid, heights, E_STAR)
    adhesive = Solver(AdhesiveProblem(problem, Dugdale(work, stress)), "displacement", rtol=1e-10)
    rows = []
    try:
        for gbar in gbars:
            result = adhesive.solve(gbar=float(gbar))
            _, gap = adhesive.fields()
            cell = grid.area / grid.size
            rows.append({"gbar": float(gbar), "p0": peak - result.pbar, "pbar": result.pbar,
                         "open_area": float((gap > 0).sum() * cell),
                         "cohesive_free_area": float((gap > work / stress).sum() * cell),
                         "A_corrected": result.A_corrected, "volume": float(gap.sum() * cell),
                         "converged": result.converged, "natural": result.kkt.natural, "reason": result.reason})
    finally:
        adhesive.destroy()
        problem.destroy()
    return rows, pressure, length, volume_scale


def nearest(p, b, solution_set, crack):
    """(distance, index) of the state of ``solution_set`` nearest to (p*, b*), in (p* / p*_F, b* / b*_F)."""
    p_f, b_f = crack.points["F"][:2]
    d = np.hypot((p - solution_set[0]) / p_f, (b - solution_set[1]) / b_f)
    i = int(np.argmin(d))
    return d[i], i


def turning_points(values):
    """Indices of the interior local maxima and minima of a sequence."""
    d = np.diff(values)
    maxima = [i for i in range(1, len(values) - 1) if d[i - 1] > 0 >= d[i]]
    minima = [i for i in range(1, len(values) - 1) if d[i - 1] < 0 <= d[i]]
    return maxima, minima


def compare_penny(rows, sigma, pressure, length, volume_scale):
    """The figures of a penny-shaped case (module docstring)."""
    crack = AdhesiveCrack(sigma)
    solution_set = crack.solution_set()
    _, _, m_set, v_set = solution_set
    states = [(r["p0"] / pressure, math.sqrt(r["open_area"] / math.pi) / length,
               math.sqrt(r["cohesive_free_area"] / math.pi) / length, r["volume"] / volume_scale) for r in rows]
    distance, m_error, v_error = [], [], []
    for p, b, c, v in states:
        d, i = nearest(p, b, solution_set, crack)
        distance.append(d)
        if b > 0 and m_set[i] > 0:
            m_error.append(abs(c / b - m_set[i]))
        v_error.append(abs(v - v_set[i]) / v_set[i] if v_set[i] > 0 else np.nan)
    opening = np.array([s[0] for s in states[:len(rows) // 2 + 1]])
    maxima, minima = turning_points(opening)
    p_max = float(opening[maxima[0]]) if maxima else float("nan")
    p_min = float(min(opening[i] for i in minima if i > maxima[0])) if maxima and minima else float("nan")
    return {"states": states, "converged": sum(r["converged"] for r in rows), "steps": len(rows),
            "distance": float(max(distance)), "median_distance": float(np.median(distance)),
            "m_error": float(max(m_error, default=float("nan"))), "v_error": float(np.nanmedian(v_error)),
            "p_max": p_max, "p_F": crack.points["F"][0], "p_min": p_min, "p_B": crack.points["B"][0],
            "hysteresis": float(max(abs(a[0] - b[0]) for a, b in zip(states, states[::-1])))}


def compare_ellipse(rows, sigma, ratio):
    """Distances of an elliptical crack's states to the penny-shaped model with the geometric and the mean
    curvature (section 6.4), over the stable part (b* > b*_G) of the opening path."""
    crack = AdhesiveCrack(sigma)
    solution_set = crack.solution_set()
    v_set = solution_set[3]
    out = {}
    for name, kappa in (("geometric", math.sqrt(ratio) * KAPPA), ("mean", (1 + ratio) / 2 * KAPPA)):
        work, pressure, length = scales(kappa)
        volume_scale = 3 * work / (2 * kappa)
        distance, v_error = [], []
        for r in rows[:len(rows) // 2 + 1]:
            p, b = r["p0"] / pressure, math.sqrt(r["open_area"] / math.pi) / length
            if b < crack.points["G"][1]:
                continue
            d, i = nearest(p, b, solution_set, crack)
            distance.append(d)
            v_error.append(abs(r["volume"] / volume_scale - v_set[i]) / v_set[i])
        out[name] = (max(distance), float(np.median(v_error)))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sigmas", type=float, nargs="+", default=[0.5, 1.0, 2.0, 5.0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024])
    parser.add_argument("--ratios", type=float, nargs="+", default=[1.0, 1.5, 3.0])
    parser.add_argument("--steps", type=int, default=40)
    parser.add_argument("--ellipse-sizes", type=int, nargs="+", default=[256, 512],
                        help="the sizes of the elliptical cases (ratio != 1)")
    args = parser.parse_args()
    common.init()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = os.path.join(common.OUTPUT, "adhesion")
    os.makedirs(out, exist_ok=True)
    penny, ellipse = [], []
    figure, axes = plt.subplots(1, len(args.sigmas), figsize=(4.2 * len(args.sigmas), 3.6), squeeze=False)
    for axis, sigma in zip(axes[0], args.sigmas):
        for ratio in args.ratios:
            for n in sorted(args.sizes if ratio == 1.0 else args.ellipse_sizes):
                rows, pressure, length, volume_scale = run_case(n, sigma, ratio, args.steps)
                if ratio == 1.0:
                    c = compare_penny(rows, sigma, pressure, length, volume_scale)
                    penny.append([f"{sigma:g}", n, f"{c['converged']}/{c['steps']}", f"{c['distance']:.4f}",
                                  f"{c['median_distance']:.4f}", f"{c['m_error']:.3f}", f"{c['v_error']:.2%}",
                                  f"{c['p_max']:.4f}", f"{c['p_F']:.4f}", f"{c['p_min']:.4f}", f"{c['p_B']:.4f}",
                                  f"{c['hysteresis']:.4f}"])
                    print(" | ".join(map(str, penny[-1])), flush=True)
                    if n == max(args.sizes):
                        p_set, b_set, _, _ = AdhesiveCrack(sigma).solution_set()
                        axis.plot(p_set, b_set, "k-", lw=1, label="crack model (6.28)-(6.29), (6.36)")
                        half = len(c["states"]) // 2 + 1
                        axis.plot([s[0] for s in c["states"][:half]], [s[1] for s in c["states"][:half]], "o",
                                  ms=3, mfc="none", label=f"BEM opening, N = {n}")
                        axis.plot([s[0] for s in c["states"][half:]], [s[1] for s in c["states"][half:]], "x",
                                  ms=3, label="BEM closing")
                else:
                    c = compare_ellipse(rows, sigma, ratio)
                    ellipse.append([f"{sigma:g}", f"{ratio:g}", n, f"{sum(r['converged'] for r in rows)}/{len(rows)}",
                                    f"{c['geometric'][0]:.4f}", f"{c['geometric'][1]:.2%}",
                                    f"{c['mean'][0]:.4f}", f"{c['mean'][1]:.2%}"])
                    print(" | ".join(map(str, ellipse[-1])), flush=True)
        axis.set_xlim(0, 6)
        axis.set_ylim(0, 2)
        axis.set_xlabel("p* (6.4)")
        axis.set_title(f"sigma0* = {sigma:g}", fontsize=9)
    axes[0][0].set_ylabel("crack radius b*")
    axes[0][0].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(os.path.join(out, "crack.png"), dpi=120)
    command = (f".venv/bin/python studies/adhesion_crack.py --sigmas {' '.join(f'{v:g}' for v in args.sigmas)} "
               f"--sizes {' '.join(map(str, args.sizes))} --ratios {' '.join(f'{v:g}' for v in args.ratios)} "
               f"--ellipse-sizes {' '.join(map(str, args.ellipse_sizes))} --steps {args.steps}")
    lines = ["# The adhesive crack of sections 6.2-6.4 against the BEM", "",
             f"Generated by `{command}` (set-up in the module docstring). L = {LENGTH:g} of the cell, i.e. "
             f"{LENGTH:g} N nodes per unit of b*.", "",
             "## Penny-shaped crack (6.2-6.3)", "",
             "Distance: of a BEM state to the model's solution set in (p* / p*_F, b* / b*_F). m: largest error of "
             "c / b where the model's m > 0. V*: median relative error of the trapped volume against the closed "
             "form of roughpetsc.models.adhesion (the printed (6.33)/(6.35) differ from it). Turning points of p* "
             "along the opening path: the first local maximum (model: F, (6.39)) and the following minimum "
             "(model: B, the snap-in); they are resolved to the path's step. Loop: the largest difference of p* "
             "between opening and closing at the same mean gap. The set's volume falls after F (to a minimum near "
             "m = 0.26 at sigma0* = 2), so volume control jumps too: on opening from F to the Maugis-Dugdale "
             "branch, on closing from that minimum to the full-adhesion branch.", "",
             common.markdown_table(["sigma0*", "N", "converged", "max distance", "median distance", "m error",
                                    "V* error", "p* local max", "p*_F", "p* local min", "p*_B", "loop"], penny),
             "", "![b* against p*](crack.png)", "",
             "## Elliptical crack (6.4): the penny model with the geometric and the mean curvature", "",
             "kappa_1 = ratio x kappa_2. Largest distance in (p*, b*) of the opening path's states with b* > b*_G "
             "(the stable branch), b* = sqrt(open area / pi) / L, in the groups of each curvature; and the median "
             "error of V*.", "",
             common.markdown_table(["sigma0*", "ratio", "N", "converged", "distance (geometric)", "V* error",
                                    "distance (mean)", "V* error"], ellipse)]
    with open(os.path.join(out, "crack.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
