"""Convergence of every solver preset: natural KKT residual against iterations, FFT pairs and wall time.

    .venv/bin/python studies/convergence.py [--sizes 256 512 1024 2048] [--pstars 0.05 0.5 2 3.5]
                                            [--presets pk pk_plain ...] [--rtol 1e-10] [--max-time 60]

Group #1 surface (the dissertation, 1) at each N and p*. The load-controlled presets (PK, ALMM) solve the load;
the bound-constrained TAO types solve the displacement-controlled QP at the separation of that load
(found first by preconditioned PK to 1e-12), so that every preset meets the same solution. Each solve
runs from a cold start to ``--rtol`` or ``--max-time`` seconds (``-solve_max_time``).

The dissertation's composite criterion (3.47), (3.48), (3.51) is evaluated alongside on PK runs with a TAO
monitor (a separate, untimed run, since the monitor computes a fresh gap): the table gives the
iteration at which it first holds and the natural residual there.

Writes studies/output/convergence/: one PNG per (N, p*), convergence.md, convergence.json.
"""

import argparse
import json
import math
import os

import numpy as np

import common

OUT = os.path.join(common.OUTPUT, "convergence")


def first_reaching(history, level):
    """(iteration, FFT pairs, seconds) at which the natural residual first is <= level, or None."""
    hits = np.flatnonzero(history[:, 1] <= level) if len(history) else []
    if len(hits) == 0:
        return None
    row = history[hits[0]]
    return int(row[0]), int(row[2] - history[0, 2]), float(row[3])


def composite_run(problem, options, pstar):
    """PK with the composite-criterion monitor: (iteration where (3.47)+(3.48)+(3.51) hold, natural there)."""
    from roughpetsc.contact.certificate import CompositeCriterion, report

    scratch = problem.vec()
    target = problem.scaled_pbar(pstar=pstar)

    def gap_of(x):
        problem.operator.displacement(x, scratch)
        gap = problem.local(scratch)
        gap -= problem.local(problem.heights, readonly=True)
        gap += problem.contact_separation(x, gap)
        return gap.ravel()

    def natural_of(x, g):
        return report(problem.mpi, x.getArray(readonly=True), g, problem.n, target).natural

    monitor = CompositeCriterion(problem.mpi, problem.n, gap_of, natural_of)
    common.solve(problem, options, 1e-10, monitor=monitor, pstar=pstar)
    scratch.destroy()
    if monitor.first is None:
        return None, None
    natural = next(row[5] for row in monitor.rows if row[0] == monitor.first)
    return monitor.first, natural


def plot(records, n, pstar):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5), sharey=True)
    for record in records:
        history = np.array(record["history"])
        if not len(history):
            continue
        style = "-" if record["preset"].startswith("pk") else "--" if record["control"] == "load" else ":"
        for axis, column, offset in ((axes[0], 0, 0), (axes[1], 2, history[0, 2]), (axes[2], 3, 0)):
            axis.semilogy(history[:, column] - offset, history[:, 1], style, label=record["preset"])
    for axis, label in zip(axes, ("iterations", "FFT pairs (operator + preconditioner)", "wall time [s]")):
        axis.set_xlabel(label)
        axis.axhline(1e-8, color="grey", lw=0.5)
        axis.grid(alpha=0.3)
    axes[0].set_ylabel("natural KKT residual")
    axes[2].legend(fontsize=7, ncol=2)
    fig.suptitle(f"Group #1, N = {n}, p* = {pstar}: solid PK (load control), dashed ALMM (load), "
                 "dotted TAO bound types (displacement control at the same solution)")
    return common.save_figure(fig, OUT, f"convergence_N{n}_p{pstar:g}.png")


def growth_exponent(sizes, counts):
    """Least-squares exponent e of counts ~ N^e."""
    ok = [(s, c) for s, c in zip(sizes, counts) if c]
    if len(ok) < 2:
        return float("nan")
    x, y = np.log([s for s, _ in ok]), np.log([c for _, c in ok])
    return float(np.polyfit(x, y, 1)[0])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[256, 512, 1024, 2048])
    parser.add_argument("--pstars", type=float, nargs="*", default=[0.05, 0.5, 2.0, 3.5])
    parser.add_argument("--presets", nargs="*", default=None)
    parser.add_argument("--rtol", type=float, default=1e-10)
    parser.add_argument("--max-time", type=float, default=60.0)
    parser.add_argument("--large-presets", nargs="*", default=["pk", "pk_plain", "blmvm", "bncg", "tron", "bnls"],
                        help="presets run at N >= 512 (the others stall or take too long there)")
    parser.add_argument("--composite-max-n", type=int, default=1024,
                        help="evaluate the composite criterion (an extra FFT per iteration) up to this N")
    parser.add_argument("--huge-presets", nargs="*", default=["pk", "pk_plain", "tron"],
                        help="presets run at N >= 2048")
    args = parser.parse_args()
    common.init()
    os.makedirs(OUT, exist_ok=True)
    presets = common.presets(args.presets)
    records, figures, composite_rows = [], [], []
    for n in args.sizes:
        problem = common.group1_problem(n)
        for pstar in args.pstars:
            reference, _, _ = common.solve(problem, {"pk_pc": "fourier"}, 1e-12, pstar=pstar)
            if pstar * math.sqrt(problem.m0p_scaled) >= problem.complete_contact_pbar:
                print(f"N={n} p*={pstar}: beyond complete contact (exact answer, no iterations)", flush=True)
                continue
            runs = []
            for name, options in presets.items():
                if (n >= 2048 and name not in args.huge_presets) or (n >= 512 and name not in args.large_presets):
                    continue
                options = dict(options, solve_max_time=str(args.max_time))
                if common.load_controls(options):
                    result, _, _ = common.solve(problem, options, args.rtol, pstar=pstar)
                else:
                    result, _, _ = common.solve(problem, options, args.rtol, "displacement",
                                                gbar=reference.separation)
                record = {"n": n, "pstar": pstar, "preset": name, "control": result.control,
                          "iterations": result.iterations, "applications": result.operator_applications,
                          "seconds": result.time_s, "natural": result.kkt.natural, "reason": result.reason,
                          "converged": result.converged, "A": result.A, "gstar": result.gstar,
                          "to_1e-8": first_reaching(result.history, 1e-8),
                          "history": result.history.tolist()}
                runs.append(record)
                print(f"N={n} p*={pstar} {name}: {result.iterations} its, {result.operator_applications} FFT pairs, "
                      f"{result.time_s:.2f} s, natural {result.kkt.natural:.1e}, {result.reason}", flush=True)
            figures.append(plot(runs, n, pstar))
            records += runs
            write_report(args, records, figures, composite_rows)  # after every block: partial runs leave a report
            for name in ("pk", "pk_plain"):
                if name in presets and n <= args.composite_max_n:
                    first, natural = composite_run(problem, presets[name], pstar)
                    composite_rows.append([n, pstar, name, first if first is not None else "never",
                                           f"{natural:.1e}" if natural is not None else "-"])
        problem.destroy()
    write_report(args, records, figures, composite_rows)


def write_report(args, records, figures, composite_rows):
    with open(os.path.join(OUT, "convergence.json"), "w") as f:
        json.dump(records, f)
    rows = []
    for r in records:
        hit = r["to_1e-8"]
        rows.append([r["n"], r["pstar"], r["preset"], r["control"],
                     *(hit if hit else ("-", "-", "-")), r["iterations"], f"{r['natural']:.1e}", r["reason"]])
    table = common.markdown_table(["N", "p*", "preset", "control", "its to 1e-8", "FFT pairs to 1e-8",
                                   "s to 1e-8", "its (final)", "final natural", "reason"],
                                  [[*row[:6], f"{row[6]:.2f}" if isinstance(row[6], float) else row[6], *row[7:]]
                                   for row in rows])
    growth = []
    for name in ("pk", "pk_plain", "blmvm", "tron", "bnls"):
        for pstar in args.pstars:
            pairs = [(r["n"], r["to_1e-8"][0]) for r in records
                     if r["preset"] == name and r["pstar"] == pstar and r["to_1e-8"]]
            if len(pairs) >= 2:
                sizes, counts = zip(*sorted(pairs))
                growth.append([name, pstar, " / ".join(str(c) for c in counts) + f" at N = {'/'.join(map(str, sizes))}",
                               f"{growth_exponent(sizes, counts):.2f}"])
    text = [
        "# Convergence of the solver presets",
        "",
        f"Group #1 surface (the dissertation, 1), natural KKT residual ||min(p/pbar, g/sqrt(m0h))||_inf; every solve from a "
        f"cold start to {args.rtol:g} or {args.max_time:g} s. Load-controlled presets (pk, pk_plain, almm) solve "
        "the load; the TAO bound types solve the displacement-controlled QP at the separation of the same load. "
        "FFT pairs count compliance and preconditioner applications. Shared 2-core machine: times are "
        "indicative, compare within a row of N.",
        "",
        "## Iterations to natural residual 1e-8 against N (exponent of a power-law fit)",
        "",
        common.markdown_table(["preset", "p*", "iterations", "exponent"], growth),
        "",
        "## The dissertation's composite criterion (3.47)+(3.48)+(3.51) on PK runs",
        "",
        "Iteration at which it first holds, and the natural KKT residual of that iterate:",
        "",
        common.markdown_table(["N", "p*", "preset", "iteration", "natural residual there"], composite_rows),
        "",
        "## Every run",
        "",
        table,
        "",
        "## Figures",
        "",
        *[f"![{f}]({f})" for f in figures],
        "",
        f"Regenerate: `.venv/bin/python studies/convergence.py --sizes {' '.join(map(str, args.sizes))} "
        f"--pstars {' '.join(f'{p:g}' for p in args.pstars)} --max-time {args.max_time:g} --rtol {args.rtol:g}"
        + (f" --presets {' '.join(args.presets)}" if args.presets else "")
        + f" --large-presets {' '.join(args.large_presets)} --huge-presets {' '.join(args.huge_presets)}`",
        "",
    ]
    with open(os.path.join(OUT, "convergence.md"), "w") as f:
        f.write("\n".join(text))
    print("\n".join(text[:12]))


if __name__ == "__main__":
    main()
