"""Johnson's adhesive wave: periodic BEM with the Dugdale law against the Maugis-Dugdale wave and the JKR wave
(issue 15, item 3).

    .venv/bin/python studies/adhesion_wave.py [--alphas 0.3 0.5] [--ranges 1 0.3 0.1 0.03 0.01]
                                              [--sizes 2048 8192 32768] [--steps 120] [--rtol 1e-10]
                                              [--ramp-cells 0]

A wave h(x) = -h cos(2 pi x / lam) (lam = 1, h = 1e-3, E* = 1) on a strip of 4 x N nodes (the wave along the
N nodes), Johnson's parameter alpha = sqrt(2 lam w / (pi^2 E* h^2)) in ``--alphas`` (below 0.57: the surfaces do
not jump into full contact at zero load), the Dugdale law with range h0 = w / sigma0 = ``--ranges`` x h. Each
case is an approach from gbar = 2.2 h to 0.05 h and back under displacement control (the mean gap), ``--steps``
each way or more, so that a step is at most half the range (a longer retraction step opens the contact beyond
the law's reach and the path snaps off early), solved by the gap CG to a natural residual of ``--rtol`` (1e-10;
on 4 x 131072 nodes the FFTs' round-off floor is already 1e-10, and a path there needs 1e-9).

``--ramp-cells C`` spreads the Dugdale stress's fall over gaps h0 -+ ramp / 2 with ramp = C (lam / N) 2 pi h / lam,
the change of the gap over C nodal spacings at the wave's steepest slope (``-adhesion_ramp``,
:class:`roughpetsc.contact.laws.Dugdale`): the ramp shrinks with the grid, so its paths converge to the same
Maugis-Dugdale solution. A case is identified by (alpha, h0, N, C). C need not be a whole number: cells growing
with N hold the ramp at a fixed width over h0 (C proportional to N) or shrink it slower than the grid (C
proportional to N^(1/2)); the report reads such sequences apart from those of fixed C.

Finished cases are kept in wave.json and skipped on a rerun. An unfinished path writes a checkpoint (its rows
and last gap, wave_checkpoints/) every five minutes; the same command after a kill resumes it there.

The Tabor parameter of each case is Maugis's lambda = sigma0 (9 R / (2 pi w E*^2))^(1/3) of the wave's crest,
R = lam^2 / (4 pi^2 h): small lambda is the DMT side, large lambda the JKR side. Compared per case:

* every BEM state in contact against the Maugis-Dugdale solution set of the wave
  (:class:`roughpetsc.models.wavy_adhesion.WavyMaugisDugdale`): the distance in (gbar / h, pbar / p*);
* the pull-off (least mean pressure of the path, the local minimum of pbar that load control would jump from)
  against Maugis-Dugdale's and against Johnson's JKR wave (:func:`jkr_pulloff_load_control`);
* the contact half-width against the load: Johnson's pbar(a) = p* (sin^2 psi - alpha sqrt(tan psi)) at the
  BEM's a = A lam / 2, as a largest and a median error over p*;
* the jump-in on approach: the largest mean gap at which the BEM is in contact, against the JKR value h (the
  crest touches, then the contact jumps to the JKR branch), and the snap-off on retraction, the largest mean gap
  in contact, against the JKR snap-off under displacement control (:func:`jkr_pulloff_displacement_control`).

The JKR columns should shrink as the range falls (lambda grows) and the grid refines; the Maugis-Dugdale columns
should shrink with the grid at every range. Output: studies/output/adhesion/wave.md and wave.png.
"""

import argparse
import math
import os

import numpy as np

import common
from grid_convergence import richardson
from roughpetsc.models.wavy_adhesion import WavyMaugisDugdale, jkr_mean_pressure, jkr_pulloff_displacement_control, jkr_pulloff_load_control

AMPLITUDE, WAVELENGTH, E_STAR = 1e-3, 1.0, 1.0


def parameters(alpha, range_over_amplitude):
    """(work, stress, Maugis lambda of the crest) of a case."""
    work = alpha ** 2 * math.pi ** 2 * E_STAR * AMPLITUDE ** 2 / (2 * WAVELENGTH)
    stress = work / (range_over_amplitude * AMPLITUDE)
    radius = WAVELENGTH ** 2 / (4 * math.pi ** 2 * AMPLITUDE)
    return work, stress, stress * (9 * radius / (2 * math.pi * work * E_STAR ** 2)) ** (1 / 3)


def ramp_width(n, cells):
    """The Dugdale ramp (length units) of ``cells`` nodal spacings at the wave's steepest slope 2 pi h / lam."""
    return cells * (WAVELENGTH / n) * 2 * math.pi * AMPLITUDE / WAVELENGTH


CHECKPOINT_SECONDS = 300.0


def checkpoint_path(folder, n, work, stress, cells, rtol):
    """The checkpoint of an unfinished path (its rows so far and last gap), named by what identifies it."""
    return os.path.join(folder, "wave_checkpoints", f"n{n}_w{work:.6e}_s{stress:.6e}_c{cells:.10g}_r{rtol:g}.h5")


def write_checkpoint(path, rows, gap):
    """The rows (JSON) and the gap (length units, compressed) of an unfinished path, atomically."""
    import json
    import h5py

    os.makedirs(os.path.dirname(path), exist_ok=True)
    with h5py.File(path + ".tmp", "w") as f:
        f.attrs["rows"] = json.dumps(rows)
        f.create_dataset("gap", data=gap, compression="gzip", shuffle=True)
    os.replace(path + ".tmp", path)


def read_checkpoint(path):
    """(rows, gap) of a checkpoint, or ([], None) when there is none."""
    import json
    import h5py

    if not os.path.exists(path):
        return [], None
    with h5py.File(path, "r") as f:
        return json.loads(f.attrs["rows"]), f["gap"][()]


def run_case(n, work, stress, steps, rtol, cells=0.0, folder=None):
    """The approach-retraction path of one case on 4 x n nodes: a list of dicts (the reason of a stop only).

    With ``folder``, the path writes a checkpoint there every few minutes and resumes from it after a kill (a
    path on 4 x 131072 nodes takes hours); the checkpoint is removed when the path ends.
    """
    import time
    from roughpetsc import ContactProblem, Grid
    from roughpetsc.contact import AdhesiveProblem, approach_retraction
    from roughpetsc.contact.laws import Dugdale
    from roughpetsc.solvers import Solver, drive
    from roughpetsc.surface.generators import wave

    grid = Grid(4, n, 4.0 * WAVELENGTH / n, WAVELENGTH)
    problem = ContactProblem(grid, wave(grid, AMPLITUDE, WAVELENGTH), E_STAR)
    gbars = approach_retraction(2.2 * AMPLITUDE, 0.05 * AMPLITUDE, steps)
    checkpoint = checkpoint_path(folder, n, work, stress, cells, rtol) if folder else None
    rows, gap = read_checkpoint(checkpoint) if checkpoint else ([], None)
    solver = Solver(AdhesiveProblem(problem, Dugdale(work, stress, ramp_width(n, cells))), "displacement", rtol=rtol)
    try:
        if gap is not None:
            solver.resume(gap[problem.local_rows])
            print(f"  N = {n}: resumed at step {len(rows)} / {len(gbars)}", flush=True)
        saved_at = time.perf_counter()
        for r in drive(solver, [("gbar", g) for g in gbars], first=len(rows)):
            rows.append({"gbar": float(r.gbar), "pbar": float(r.pbar), "A": float(r.A),
                         "converged": bool(r.converged), "applications": r.operator_applications,
                         "seconds": r.time_s})
            if not r.converged:
                rows[-1]["reason"] = r.reason
            if len(rows) % 24 == 0 or not r.converged:  # progress of a long path (hours at 131072 nodes)
                print(f"  N = {n}, step {len(rows)} / {len(gbars)}: gbar / h {r.gbar / AMPLITUDE:.4f}, "
                      f"pbar {r.pbar:+.4g}, {sum(row['applications'] for row in rows)} pairs, "
                      f"{sum(row['seconds'] for row in rows):.0f} s, {r.reason}", flush=True)
            if checkpoint and time.perf_counter() - saved_at > CHECKPOINT_SECONDS and len(rows) < len(gbars):
                write_checkpoint(checkpoint, rows, solver.fields()[1])
                saved_at = time.perf_counter()
    finally:
        solver.destroy()
        problem.destroy()
    if checkpoint and os.path.exists(checkpoint):
        os.remove(checkpoint)
    return rows


def compare(rows, work, stress, steps):
    """The figures of one case (see the module docstring), from its converged states."""
    model = WavyMaugisDugdale(WAVELENGTH, AMPLITUDE, E_STAR, work, stress)
    pstar = model.pstar
    curve = model.curve(2000)
    approach = [r for r in rows[:steps + 1] if r["converged"]]
    retraction = [r for r in rows[steps:] if r["converged"]]
    states = approach + retraction
    touching = [r for r in states if r["A"] > 0]
    distance = max(np.min(np.hypot((r["gbar"] - curve["gbar"]) / AMPLITUDE, (r["pbar"] - curve["pbar"]) / pstar))
                   for r in touching)
    radii = np.array([r["A"] * WAVELENGTH / 2 for r in touching if r["A"] < 1])
    jkr_loads = jkr_mean_pressure(radii, WAVELENGTH, AMPLITUDE, E_STAR, work)
    jkr_errors = np.abs(np.array([r["pbar"] for r in touching if r["A"] < 1]) - jkr_loads) / pstar
    stops = [r["reason"] for r in rows if not r["converged"]]
    return {"converged": sum(r["converged"] for r in rows), "steps": len(rows), "stops": stops,
            "md_distance": distance,
            "pulloff": min(r["pbar"] for r in states) / pstar, "md_pulloff": model.pulloff()[0] / pstar,
            "jkr_pulloff": jkr_pulloff_load_control(WAVELENGTH, AMPLITUDE, E_STAR, work)[0] / pstar,
            "jkr_max_error": float(jkr_errors.max()), "jkr_median_error": float(np.median(jkr_errors)),
            "jump_in": max(r["gbar"] for r in approach if r["A"] > 0) / AMPLITUDE,
            "snap_off": max(r["gbar"] for r in retraction if r["A"] > 0) / AMPLITUDE,
            "jkr_snap_off": jkr_pulloff_displacement_control(WAVELENGTH, AMPLITUDE, E_STAR, work)[2] / AMPLITUDE}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--alphas", type=float, nargs="+", default=[0.3, 0.5])
    parser.add_argument("--ranges", type=float, nargs="+", default=[1.0, 0.3, 0.1, 0.03, 0.01])
    parser.add_argument("--sizes", type=int, nargs="+", default=[2048, 8192, 32768])
    parser.add_argument("--steps", type=int, default=120)
    parser.add_argument("--rtol", type=float, default=1e-10, help="natural residual of every solve")
    parser.add_argument("--ramp-cells", type=float, default=0.0,
                        help="the Dugdale stress falls over this many spacings at the steepest slope (0: a step)")
    out = os.path.join(common.OUTPUT, "adhesion")
    args, path, cases = common.start_resumable(parser, out, "wave", "only rewrite the report from the JSON")
    for alpha in args.alphas if not args.report else ():
        for range_ in args.ranges:
            work, stress, _ = parameters(alpha, range_)
            steps = max(args.steps, math.ceil(2.15 / (0.5 * range_)))  # retraction steps below half the range
            for n in sorted(args.sizes):
                if any(identity(c) == (alpha, range_, n, args.ramp_cells, args.rtol) for c in cases):
                    continue
                cases.append({"alpha": alpha, "range": range_, "N": n, "steps": steps, "rtol": args.rtol,
                              "ramp_cells": args.ramp_cells,
                              "rows": run_case(n, work, stress, steps, args.rtol, args.ramp_cells, out)})
                common.save_rows(path, cases)
                print(alpha, range_, n, args.ramp_cells, "done", flush=True)
    report(cases, out, args)


# Pull-off errors between which an order is read: above 50 % a grid does not resolve the cohesive zone yet; below
# 0.01 % the path's step (0.015 h) misses the least pbar by as much. Ranges of 0.3 h and more are left out: their
# errors (0.3 % and less) stop falling on these grids (the least pbar is at the end of the path's contact).
RESOLVED = (1e-4, 0.5)
ORDER_RANGES = 0.1


def identity(case):
    """(alpha, h0 / h, N, ramp cells, rtol) of a case; the paths from before the ramp are the step law's."""
    return case["alpha"], case["range"], case["N"], case.get("ramp_cells", 0.0), case.get("rtol", 1e-10)


def tightest_per_grid(cases):
    """One path per grid, the one solved to the smallest residual, coarsest grid first."""
    tightest = {}
    for c in cases:
        if c["N"] not in tightest or identity(c)[4] < identity(tightest[c["N"]])[4]:
            tightest[c["N"]] = c
    return [tightest[n] for n in sorted(tightest)]


def order_rows(cases):
    """Per case on its second grid or finer: the pull-off's error against Maugis-Dugdale (the path's least pbar),
    its observed order in the node spacing 1 / N against the next coarser grid, and what two rates fitted to the
    two coarser grids predict for it: C h + D h^2 (first order) and h (C log(1/h) + D)."""
    rows = []
    for alpha, range_, cells in sorted({identity(c)[:2] + identity(c)[3:4] for c in cases}):
        if range_ > ORDER_RANGES:
            continue
        work, stress, _ = parameters(alpha, range_)
        reference = WavyMaugisDugdale(WAVELENGTH, AMPLITUDE, E_STAR, work, stress).pulloff()[0]
        group = tightest_per_grid(c for c in cases if identity(c)[:2] + identity(c)[3:4] == (alpha, range_, cells))
        spacing = np.array([1.0 / c["N"] for c in group])
        signed = np.array([least_pbar_error(c, reference) for c in group])
        least = np.abs(signed)
        for i in range(1, len(group)):
            if not (RESOLVED[0] < least[i] and least[i - 1] < RESOLVED[1]):
                continue
            order = math.log(least[i - 1] / least[i]) / math.log(spacing[i - 1] / spacing[i])
            predictions = ["-", "-"]
            if i >= 2 and least[i - 2] < RESOLVED[1]:
                h = spacing[i - 2:i + 1]
                for k, basis in enumerate((np.c_[h, h * h], np.c_[h * np.log(1 / h), h])):
                    predictions[k] = f"{basis[2] @ np.linalg.solve(basis[:2], least[i - 2:i]):.2%}"
            rows.append([f"{alpha:g}", f"{range_:g}", f"{cells:g}", group[i]["N"], f"{signed[i]:+.3%}",
                         f"{pulloff_scatter(group[i], reference):.3%}", f"{order:.2f}", *predictions])
    return rows


def least_pbar_error(case, reference):
    """The path's pull-off (least converged pbar on retraction) over ``reference``, less 1."""
    return min(r["pbar"] for r in case["rows"][case["steps"]:] if r["converged"]) / reference - 1


def pulloff_scatter(case, reference, window=0.1):
    """The rms scatter (over ``reference``) of a path's pbar about a quartic in gbar fitted over the retraction
    steps within ``window`` h of its least pbar: how much the contact's edge passing nodes jags the curve the
    pull-off is read from."""
    states = [r for r in case["rows"][case["steps"]:] if r["converged"]]
    gbar = np.array([r["gbar"] for r in states]) / AMPLITUDE
    pbar = np.array([r["pbar"] for r in states]) / reference
    near = np.abs(gbar - gbar[np.argmax(pbar)]) <= window
    if near.sum() < 8:
        return float("nan")
    shifted = gbar[near] - gbar[near].mean()
    return float(np.std(pbar[near] - np.polyval(np.polyfit(shifted, pbar[near], 4), shifted)))


RAMP_SCALINGS = {0.0: "held fixed", 0.5: "as h^(1/2)"}


def ramp_sequence_rows(cases):
    """Per sequence of ramped paths whose ramp over h0 falls as h^q (q in RAMP_SCALINGS; q = 1, a fixed number of
    cells, is order_rows' 'ramp cells'), on two grids or more: each grid's pull-off error against Maugis-Dugdale,
    its scatter (pulloff_scatter), the order against the next coarser grid and, on every three consecutive grids,
    the fit b + C h^p (grid_convergence.richardson: the error's changes must shrink)."""
    rows = []
    for q, scaling in RAMP_SCALINGS.items():
        sequences = {}
        for c in cases:
            alpha, range_, n, cells, _ = identity(c)
            if cells > 0:
                width = ramp_width(n, cells) / (range_ * AMPLITUDE)
                sequences.setdefault((alpha, range_, float(f"{width * n ** q:.6g}")), []).append(c)
        for (alpha, range_, _), members in sorted(sequences.items()):
            group = tightest_per_grid(members)
            if len(group) < 2:
                continue
            work, stress, _ = parameters(alpha, range_)
            reference = WavyMaugisDugdale(WAVELENGTH, AMPLITUDE, E_STAR, work, stress).pulloff()[0]
            spacing = np.array([1.0 / c["N"] for c in group])
            signed = np.array([least_pbar_error(c, reference) for c in group])
            scatter = np.array([pulloff_scatter(c, reference) for c in group])
            # An error is read where it stands out of its path's jag (twice its scatter) and of what the path's
            # step can miss (RESOLVED[0]), and the cohesive zone is resolved (RESOLVED[1]).
            readable = (np.abs(signed) > np.maximum(2 * scatter, RESOLVED[0])) & (np.abs(signed) < RESOLVED[1])
            for i, c in enumerate(group):
                order = fit = "-"
                if i >= 1:
                    order = (f"{math.log(abs(signed[i - 1] / signed[i])) / math.log(spacing[i - 1] / spacing[i]):.2f}"
                             if readable[i - 1:i + 1].all() else "not read")
                if i >= 2 and readable[i - 2:i + 1].all():
                    p, b, _ = richardson([c["N"] for c in group[i - 2:i + 1]], signed[i - 2:i + 1])
                    fit = "no single power" if p is None else f"p = {p:.2f}, b = {b:+.3%}"
                rows.append([f"{alpha:g}", f"{range_:g}", scaling,
                             f"{ramp_width(c['N'], identity(c)[3]) / (range_ * AMPLITUDE):.3f}",
                             f"{identity(c)[3]:.4g}", c["N"], f"{signed[i]:+.3%}", f"{scatter[i]:.3%}", order, fit])
    return rows


def cost(rows):
    """The operator applications and seconds of a path's solves ("-" for a path kept from before they were
    recorded)."""
    if "applications" not in rows[0]:
        return "-"
    return f"{sum(r['applications'] for r in rows)}, {sum(r['seconds'] for r in rows):.0f}"


def report(cases, out, args):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    header = ["alpha", "h0 / h", "Maugis lambda", "ramp cells", "ramp / h0", "N", "steps each way", "rtol", "converged",
              "applications, s",
              "distance to MD set",
              "pull-off / p*", "MD pull-off", "JKR pull-off", "error vs MD", "error vs JKR",
              "JKR pbar(a): max / median error", "jump-in gbar / h (JKR 1)", "snap-off gbar / h", "JKR snap-off"]
    table, stops = [], []
    alphas = sorted({c["alpha"] for c in cases})
    figure, axes = plt.subplots(1, len(alphas), figsize=(5.5 * len(alphas), 4), squeeze=False)
    pstar = math.pi * E_STAR * AMPLITUDE / WAVELENGTH
    for axis, alpha in zip(axes[0], alphas):
        for range_ in sorted({c["range"] for c in cases if c["alpha"] == alpha}, reverse=True):
            work, stress, lam = parameters(alpha, range_)
            group = sorted((c for c in cases if (c["alpha"], c["range"]) == (alpha, range_)),
                           key=lambda c: (identity(c)[3], c["N"], -identity(c)[4]))
            for case in group:
                c = compare(case["rows"], work, stress, case["steps"])
                table.append([f"{alpha:g}", f"{range_:g}", f"{lam:.2f}", f"{identity(case)[3]:g}",
                              f"{ramp_width(case['N'], identity(case)[3]) / (work / stress):.3g}", case["N"],
                              case["steps"],
                              f"{case.get('rtol', 1e-10):g}",
                              f"{c['converged']}/{c['steps']}", cost(case["rows"]), f"{c['md_distance']:.4f}",
                              f"{c['pulloff']:.4f}",
                              f"{c['md_pulloff']:.4f}", f"{c['jkr_pulloff']:.4f}",
                              f"{abs(c['pulloff'] / c['md_pulloff'] - 1):.2%}",
                              f"{abs(c['pulloff'] / c['jkr_pulloff'] - 1):.2%}",
                              f"{c['jkr_max_error']:.3f} / {c['jkr_median_error']:.4f}",
                              f"{c['jump_in']:.3f}", f"{c['snap_off']:.3f}", f"{c['jkr_snap_off']:.3f}"])
                if c["stops"]:
                    stops.append([f"{alpha:g}", f"{range_:g}", f"{identity(case)[3]:g}", case["N"], len(c["stops"]),
                                  c["stops"][0]])
            finest = max((c for c in group if not identity(c)[3]), key=lambda c: c["N"])  # the step law's
            touching = [r for r in finest["rows"] if r["converged"] and 0 < r["A"] < 1]
            axis.plot([r["A"] / 2 for r in touching], [r["pbar"] / pstar for r in touching], ".", ms=3,
                      label=f"BEM, h0/h = {range_:g} (lambda {lam:.2g}), N = {finest['N']}")
        a = np.linspace(1e-3, 0.499, 400)
        work = parameters(alpha, 1.0)[0]
        axis.plot(a, jkr_mean_pressure(a, WAVELENGTH, AMPLITUDE, E_STAR, work) / pstar, "k-", lw=1,
                  label="JKR wave (Johnson 1995)")
        axis.set_ylim(-1.5 * alpha, 1.05)
        axis.set_xlabel("contact half-width a / lam")
        axis.set_ylabel("pbar / p*")
        axis.set_title(f"alpha = {alpha:g}", fontsize=9)
        axis.legend(fontsize=6)
    figure.tight_layout()
    figure.savefig(os.path.join(out, "wave.png"), dpi=120)
    lines = ["# Johnson's adhesive wave: BEM with the Dugdale law against Maugis-Dugdale and JKR", "",
             "Generated by `.venv/bin/python studies/adhesion_wave.py` (resumable: the paths are kept in wave.json; "
             "set-up in the module docstring). The jump-in and snap-off gaps are resolved to the path's step, "
             "2.15 h / (steps each way). The comparisons use the converged states; a stop is listed below.", "",
             "The paths with applications and seconds recorded were solved after issue 39's change to the gap CG: a "
             "step across g = 0 is kept only if the projected gap's energy is lower (before, a long step could "
             "project into a wider contact of higher energy and stagnate there), and a solve whose energy still "
             "falls is not stopped as stagnant. Before it, eight paths stopped (0.5 / 0.03 / 8192: 286/289 steps, "
             "75759 applications, 73 s; after: 289/289, 52976, 58 s, run back to back). The guard alone left one "
             "stop at 0.5 / 0.01 / 8192 (step 838, the snap-off, whose descent takes 945 iterations at a natural "
             "residual of 6 to 55); counting the energy's fall as progress removed it. Seconds are wall time on a "
             "shared two-core machine; a path without them is "
             "kept from before.", "",
             common.markdown_table(header, table), "", "![pbar against a](wave.png)", "",
             "## The pull-off's order in the grid", "",
             "The pull-off's error against Maugis-Dugdale (the path's least pbar over Maugis-Dugdale's, less 1: "
             "positive where the BEM is more adhesive) on each grid past the first, its "
             "order against the next coarser grid in the node spacing, and the error two rates fitted to the two "
             "coarser grids predict: first order (C h + D h^2) and h log(1/h) + D h. An order is read where the "
             "coarser error is below 50 % (the cohesive zone resolved) and the finer above 0.01 % (what the path's "
             "step, 0.015 h, can miss of the least pbar), for h0 <= 0.1 h (at 0.3 h and 1 h the errors, 0.3 % and "
             "less, stop falling on these grids: the least pbar is at the end of the path's contact). 'ramp cells' 0 "
             "is the step law, C > 0 the ramped one (module docstring). Where a grid has paths at two residuals, the "
             "tighter one counts; the two 8192-node paths of alpha 0.5, h0 0.03 h (1e-10 and 3e-11) have equal "
             "pull-offs in the table above: the solver's tolerance is not what the error is made of. 'Scatter' is the jag "
             "of the path's pbar near its pull-off (defined under the next table): an order read from errors a few "
             "times their scatter apart is uncertain.", "",
             common.markdown_table(["alpha", "h0 / h", "ramp cells", "N", "pull-off error", "scatter", "order",
                                    "C h + D h^2 predicts", "h (C log(1/h) + D) predicts"], order_rows(cases)), "",
             "### Ramps that shrink slower than the grid", "",
             "A ramp of a fixed number of cells (the table above) shrinks with the node spacing h; here its width "
             "over h0 is held fixed or falls as h^(1/2), so its cells grow with N. Held fixed, the paths converge "
             "to the ramped law's own solution, not to Maugis-Dugdale's: the error is b + C h^p, b that of the law "
             "and C h^p the grid's. Falling as h^(1/2), they converge to Maugis-Dugdale's, with the law's share of "
             "the error falling as h if it goes as the square of the ramp. A ramp held fixed on two grids shows the "
             "grid's share alone at that width. Each row past the second fits the three "
             "grids up to it exactly (p, b; 'no single power' where the error's changes do not shrink with the grid). An order is "
             "'not read' where an error is within twice its scatter or 0.01 %, or above 50 %. 'Scatter' is "
             "the rms of the path's pbar about a quartic in gbar over the steps within 0.1 h of the pull-off, over "
             "Maugis-Dugdale's pull-off: the jag the contact's edge makes as it passes nodes (about ten per step on "
             "8192 nodes), and so what a pull-off read as the path's least pbar is uncertain by. It is an upper bound: where "
             "the curve turns sharply at the pull-off (alpha 0.3, where pbar falls by 8 % of p* within 0.1 h of it) "
             "the quartic misses part of the curve's own shape too.", "",
             common.markdown_table(["alpha", "h0 / h", "ramp over h0", "ramp / h0", "ramp cells", "N",
                                    "pull-off error", "scatter", "order",
                                    "b + C h^p through this and the two coarser grids"], ramp_sequence_rows(cases)),
             "",
             "Stops (not converged, left out of the comparisons): "
             + ("none." if not stops else ""), ""]
    if stops:
        lines.append(common.markdown_table(["alpha", "h0 / h", "ramp cells", "N", "stops", "the first one's reason"],
                                           stops))
    with open(os.path.join(out, "wave.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
