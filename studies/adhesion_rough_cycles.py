"""Adhesive BEM approach-retraction cycles on rough surfaces, a grid sequence, against the adhesive GW model.

    nice -n 10 .venv/bin/python studies/adhesion_rough_cycles.py [--group 1] [--seeds 1 ... 10]
        [--sizes 512 1024] [--ratios 20 50 100] [--pmax 2] [--hours H] [--report] [--resolve-through STEP]

Issue 36, item 4 (c)-(d). Surface: group ``--group`` of Table 7.1 (group #1 is the surface of section 6.6:
m0^p* = 1e-4), band-limited (k_s = 64 cycles per cell), so one surface exists independently of the grid: it
is generated on 512^2 by the preset's generator (xu) and sampled on every N of ``--sizes`` by spectral
padding (``grid_convergence.band_limited_surface``, exact for a band-limited surface). E* = 1, the Dugdale
law at sigma0 / E* = 1 / ratio with the range z0 = 0.33 sqrt(m0^h) (``adhesion_chapter6.Z0_OVER_RMS``: 0.3 nm
over the 0.91 nm rms height of Table 6.2), so w = sigma0 z0 as in (6.56).

The cycle (displacement control: :class:`roughpetsc.contact.AdhesiveProblem` solved by the
:class:`roughpetsc.solvers.Solver` facade (its default backend, the projected CG on the gap) along the load-path
driver ``roughpetsc.solvers.drive``, natural residual 1e-8, each solve warm-started from the last): the mean gap g* = gbar / sqrt(m0^h) decreases from out of contact
(``(max h + z0) / sqrt(m0^h) + 0.2``, computed on the 512^2 samples, the same path on every grid) by
steps of 0.15 (0.45 z0: a retraction step must stay below the range of the law) down to 0.6, then
geometrically by 0.8 per step until p* = pbar / sqrt(m0^p) reaches ``--pmax`` (approach); then the same gaps
are retraced upwards, and the retraction goes on by 0.15 until the contact has let go (retraction). Every
step records g*, p*, 1 - A* (node count, and with the perimeter correction), the number of non-contact
nodes and of non-contact clusters (periodic 4-connected labelling), and the solve's certificate (natural
residual, mean-gap error, reason, iterations, operator applications, seconds).

Files: one HDF5 per case in studies/output/adhesion/rough/ (``g01_n1024_s03_r20_p2.h5``), written when the
cycle is complete, with the process CPU seconds it cost (summed over resumed runs). A killed run resumes:
finished cases are skipped, and an unfinished one restarts from its last checkpoint (rough/checkpoints/,
the rows and the gap field, written at most every two minutes). Cases run seed by seed (so that an
interrupted campaign leaves complete grid sequences), then in the order of ``--sizes``, then of ``--ratios``;
``--hours`` stops starting new cases after that many hours. ``--report`` (or the end of a run) writes the
tables and figures (``adhesion_rough_report.py``).
"""

import argparse
import math
import os
import sys
import time

import numpy as np

import common

OUT = os.path.join(common.OUTPUT, "adhesion", "rough")
CHECKPOINTS = os.path.join(OUT, "checkpoints")
LINEAR_STEP = 0.15       # g* step out to 0.6 (0.45 z0 with z0 = 0.33 sqrt(m0^h))
GEOMETRIC_FROM = 0.6
GEOMETRIC_RATIO = 0.8
SMALLEST_GAP = 1e-8      # g* below which an approach that never reaches pmax stops
EXTRA_RETRACTION = 40    # steps of LINEAR_STEP beyond the start before a retraction that still sticks stops
CHECKPOINT_SECONDS = 120.0
COARSE = 512
FIELDS = ("gstar", "pstar", "non_contact", "non_contact_corrected", "open_nodes", "clusters", "stage",
          "converged", "natural", "load_error", "iterations", "applications", "seconds")


PROTOCOLS = ("partial", "full")


def case_name(group, n, seed, ratio, pmax, protocol):
    return f"g{group:02d}_n{n}_s{seed:02d}_r{ratio:g}_p{pmax:g}_{protocol}"


def periodic_clusters(open_nodes):
    """Number of 4-connected clusters of ``open_nodes`` (bool, 2-D) on the periodic cell."""
    from scipy import ndimage

    labels, count = ndimage.label(open_nodes)
    if count == 0:
        return 0
    parent = np.arange(count + 1)

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for first, last in ((labels[0, :], labels[-1, :]), (labels[:, 0], labels[:, -1])):
        both = (first > 0) & (last > 0)
        for a, b in set(zip(first[both].tolist(), last[both].tolist())):
            ra, rb = root(a), root(b)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    return sum(1 for i in range(1, count + 1) if root(i) == i)


def approach_gaps(gstar_start):
    """The approach's linear part: g* from gstar_start down to GEOMETRIC_FROM (included) by LINEAR_STEP."""
    steps = int(math.ceil((gstar_start - GEOMETRIC_FROM) / LINEAR_STEP - 1e-9))
    return list(GEOMETRIC_FROM + LINEAR_STEP * np.arange(steps, -1, -1))


class Cycle:
    """One approach-retraction cycle: the rows, where it turned, and the gaps still to solve.

    ``full``: the retraction goes back to ``gstar_start`` and on until the contact lets go; otherwise it
    stops at GEOMETRIC_FROM (the "partial" protocol)."""

    def __init__(self, gstar_start, pmax, full):
        self.linear = approach_gaps(gstar_start)
        self.full = full
        self.pmax = pmax
        self.rows = []
        self.turn = -1        # index of the last approach row, once p* >= pmax

    def add(self, row):
        """Keep a solved row; the approach turns at the first p* >= pmax."""
        self.rows.append(row)
        if self.turn < 0 and (row["pstar"] >= self.pmax or row["gstar"] < SMALLEST_GAP):
            self.turn = len(self.rows) - 1

    def next_gap(self):
        """The next g* to solve, or None when the cycle is complete."""
        rows = self.rows
        if self.turn < 0:
            i = len(rows)
            return self.linear[i] if i < len(self.linear) else \
                GEOMETRIC_FROM * GEOMETRIC_RATIO ** (i - len(self.linear) + 1)
        back = len(rows) - 1 - self.turn          # retraction rows solved so far
        if back < self.turn and (self.full or rows[self.turn - 1 - back]["gstar"] <= GEOMETRIC_FROM * 1.0001):
            return rows[self.turn - 1 - back]["gstar"]
        last = rows[-1]
        if self.full and last["open_nodes"] < last["nodes"] and back - self.turn < EXTRA_RETRACTION:
            return last["gstar"] + LINEAR_STEP
        return None


def step_row(solver, result, gstar, stage):
    """The row of one certified solve at g*."""
    gap = solver.fields()[1]
    open_nodes = gap > 0
    return {"gstar": gstar, "pstar": result.pstar, "non_contact": 1.0 - result.A,
            "non_contact_corrected": 1.0 - result.A_corrected, "open_nodes": int(open_nodes.sum()),
            "nodes": int(open_nodes.size), "clusters": periodic_clusters(open_nodes), "stage": stage,
            "converged": bool(result.converged), "natural": result.kkt.natural,
            "load_error": result.kkt.load_error, "iterations": result.iterations,
            "applications": result.operator_applications, "seconds": result.time_s, "reason": result.reason}


def write_rows(path, rows, attrs, gap=None):
    """The rows (one dataset per field, the reasons as strings) and attributes, atomically."""
    import h5py

    temporary = path + ".tmp"
    with h5py.File(temporary, "w") as f:
        for field in FIELDS:
            f.create_dataset(field, data=np.array([row[field] for row in rows]))
        f.create_dataset("reason", data=np.array([row["reason"] for row in rows], dtype=h5py.string_dtype()))
        for key, value in attrs.items():
            f.attrs[key] = value
        if gap is not None:
            # Compressed (losslessly) because a checkpoint of an unfinished 2048^2 case is committed at the end of
            # a session, and the contact's zero gaps shrink to nothing.
            f.create_dataset("gap", data=gap, compression="gzip", shuffle=True)
    os.replace(temporary, path)


def read_rows(path):
    """(rows, attrs, gap or None) of a case file or checkpoint."""
    import h5py

    with h5py.File(path, "r") as f:
        columns = {field: f[field][()] for field in FIELDS}
        reasons = [r.decode() if isinstance(r, bytes) else r for r in f["reason"][()]]
        attrs = dict(f.attrs)
        gap = f["gap"][()] if "gap" in f else None
    rows = []
    for i, reason in enumerate(reasons):
        row = {field: columns[field][i].item() for field in FIELDS}
        row["reason"] = reason
        row["nodes"] = int(attrs["n"]) ** 2
        rows.append(row)
    return rows, attrs, gap


def build_case(group_number, seed, n, ratio, pmax, rtol, protocol):
    """(problem, solver, cycle, moments) of one case, before any step: the caller destroys the first two."""
    from roughpetsc import ContactProblem, Grid, fractal_group, surface_moments
    from roughpetsc.contact import AdhesiveProblem, Dugdale
    from roughpetsc.solvers import Solver
    from adhesion_chapter6 import Z0_OVER_RMS
    from grid_convergence import band_limited_surface

    group = fractal_group(group_number)
    coarse = band_limited_surface(group, seed, COARSE, COARSE)
    heights = coarse if n == COARSE else band_limited_surface(group, seed, COARSE, n)
    grid = Grid(n, n, group["length"], group["length"])
    moments = surface_moments(grid, heights, 1.0)
    rms = math.sqrt(moments["m0h"])
    cycle = Cycle(coarse.max() / rms + Z0_OVER_RMS + 0.2, pmax, protocol == "full")
    problem = ContactProblem(grid, heights, 1.0)
    solver = Solver(AdhesiveProblem(problem, Dugdale(Z0_OVER_RMS * rms / ratio, 1.0 / ratio)), "displacement",
                    rtol=rtol)
    return problem, solver, cycle, moments


def resolve_approach(group_number, seed, n, ratio, pmax, rtol, protocol, last):
    """Re-solve a case's approach through step ``last`` (0-based) with today's solver, printing each step's
    certificate; no file is written. It checks a stop listed in a case file solved by an earlier solver."""
    from roughpetsc.solvers import drive

    problem, solver, cycle, _ = build_case(group_number, seed, n, ratio, pmax, rtol, protocol)
    name = case_name(group_number, n, seed, ratio, pmax, protocol)
    try:
        gstars = cycle.linear[:last + 1]
        for step, (gstar, result) in enumerate(zip(gstars, drive(solver, [("gbar", g * problem.sqrt_m0h)
                                                                            for g in gstars]))):
            print(f"{name} step {step} g* {gstar:.4g}: p* {result.pstar:+.4f} {result.operator_applications} "
                  f"applications {result.time_s:.1f} s natural residual {result.kkt.natural:.2g} "
                  f"{result.reason}", flush=True)
    finally:
        solver.destroy()
        problem.destroy()


def run_case(group_number, seed, n, ratio, pmax, rtol, protocol):
    """Run (or resume) one cycle and write its case file."""
    from roughpetsc.contact import dissipated_energy
    from roughpetsc.solvers import drive
    from adhesion_chapter6 import Z0_OVER_RMS

    name = case_name(group_number, n, seed, ratio, pmax, protocol)
    problem, solver, cycle, moments = build_case(group_number, seed, n, ratio, pmax, rtol, protocol)
    checkpoint = os.path.join(CHECKPOINTS, name + ".h5")
    cpu_before, wall_before, gap = 0.0, 0.0, None
    if os.path.exists(checkpoint):
        cycle.rows, attrs, gap = read_rows(checkpoint)
        cycle.turn = int(attrs["turn"])
        cpu_before, wall_before = float(attrs["cpu_seconds"]), float(attrs["wall_seconds"])
    attrs = {"group": group_number, "seed": seed, "n": n, "ratio": ratio, "pmax": pmax, "rtol": rtol,
             "z0_over_rms": Z0_OVER_RMS, "protocol": protocol, "gstar_start": cycle.linear[0],
             "sqrt_m0h": problem.sqrt_m0h,
             "sqrt_m0p": problem.sqrt_m0p, **{k: float(v) for k, v in moments.items()}}
    cpu_start, wall_start, saved_at = time.process_time(), time.perf_counter(), time.perf_counter()
    requested = []

    def steps():
        """The cycle's mean gaps, each chosen after the previous step's row is in (drive asks lazily)."""
        for gstar in iter(cycle.next_gap, None):
            requested.append(gstar)
            yield "gbar", gstar * problem.sqrt_m0h

    try:
        if gap is not None:
            solver.resume(gap[problem.local_rows])  # shifted to the next mean gap by the solver
        for result in drive(solver, steps()):
            row = step_row(solver, result, requested[-1], 1 if cycle.turn < 0 else -1)
            cycle.add(row)
            print(f"{name} {'approach' if row['stage'] > 0 else 'retraction'} g* {row['gstar']:.4g}: "
                  f"p* {row['pstar']:+.4f} "
                  f"1-A* {row['non_contact']:.3e} ({row['open_nodes']} nodes, {row['clusters']} clusters) "
                  f"{row['applications']} applications {row['seconds']:.1f} s {row['reason']}", flush=True)
            if time.perf_counter() - saved_at > CHECKPOINT_SECONDS:
                os.makedirs(CHECKPOINTS, exist_ok=True)
                write_rows(checkpoint, cycle.rows, {
                    **attrs, "turn": cycle.turn, "cpu_seconds": cpu_before + time.process_time() - cpu_start,
                    "wall_seconds": wall_before + time.perf_counter() - wall_start},
                    gap=solver.fields()[1])
                saved_at = time.perf_counter()
    finally:
        solver.destroy()
        problem.destroy()
    rows = cycle.rows
    gstars, pstars = np.array([r["gstar"] for r in rows]), np.array([r["pstar"] for r in rows])
    retraction = np.array([r["stage"] < 0 for r in rows])
    attrs.update(turn=cycle.turn, cpu_seconds=cpu_before + time.process_time() - cpu_start,
                 wall_seconds=wall_before + time.perf_counter() - wall_start,
                 dissipated_energy_star=dissipated_energy(gstars, pstars),
                 pulloff_pstar=float(pstars[retraction].min()),
                 let_go=bool(rows[-1]["open_nodes"] == rows[-1]["nodes"]),
                 all_converged=bool(all(r["converged"] for r in rows)))
    write_rows(os.path.join(OUT, name + ".h5"), rows, attrs)
    if os.path.exists(checkpoint):
        os.remove(checkpoint)
    print(f"{name}: {len(rows)} steps, all converged {attrs['all_converged']}, pull-off p* "
          f"{attrs['pulloff_pstar']:+.4f}, dissipated {attrs['dissipated_energy_star']:.4g}, "
          f"{attrs['cpu_seconds'] / 3600:.3f} core-hours", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--group", type=int, default=1)
    parser.add_argument("--seeds", type=int, nargs="+", default=list(range(1, 11)))
    parser.add_argument("--sizes", type=int, nargs="+", default=[512, 1024])
    parser.add_argument("--ratios", type=float, nargs="+", default=[20.0, 50.0, 100.0])
    parser.add_argument("--pmax", type=float, default=2.0)
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--protocol", choices=PROTOCOLS, default="partial",
                        help="partial: the retraction stops at g* = 0.6; full: it goes on until the contact "
                             "lets go (both approach from out of contact)")
    parser.add_argument("--hours", type=float, default=0.0, help="start no new case after this many hours (0: none)")
    parser.add_argument("--report", action="store_true", help="only rewrite the report from the case files")
    parser.add_argument("--resolve-through", type=int, metavar="STEP",
                        help="only re-solve each case's approach through step STEP (0-based) with today's solver "
                             "and print it (checks a listed stop; no file written)")
    args = parser.parse_args()
    if any(n % COARSE for n in args.sizes):
        parser.error(f"--sizes must be multiples of {COARSE} (the surfaces are generated on {COARSE}^2)")
    if not args.pmax > 0:
        parser.error("--pmax must be positive")
    if args.resolve_through is not None and args.resolve_through < 0:
        parser.error("--resolve-through must be a step number, 0 or more")
    common.init()
    if args.resolve_through is not None:
        for seed in args.seeds:
            for n in args.sizes:
                for ratio in args.ratios:
                    resolve_approach(args.group, seed, n, ratio, args.pmax, args.rtol, args.protocol,
                                     args.resolve_through)
        return
    os.makedirs(OUT, exist_ok=True)
    if not args.report:
        started = time.perf_counter()
        for seed in args.seeds:
            for n in args.sizes:
                for ratio in args.ratios:
                    if os.path.exists(os.path.join(OUT, case_name(args.group, n, seed, ratio, args.pmax,
                                                                  args.protocol) + ".h5")):
                        continue
                    if args.hours and time.perf_counter() - started > args.hours * 3600:
                        print(f"--hours {args.hours:g} reached: no new case started", flush=True)
                        return
                    run_case(args.group, seed, n, ratio, args.pmax, args.rtol, args.protocol)
    import adhesion_rough_report

    adhesion_rough_report.report(args.group, args.pmax)


if __name__ == "__main__":
    sys.exit(main())
