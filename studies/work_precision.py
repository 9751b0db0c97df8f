"""Run time against error (work-precision) for every solver preset, one plot per regime.

    .venv/bin/python studies/work_precision.py [--n 512] [--pstars 0.05 0.5 2 3.5] [--presets pk bnls ...]
                                               [--tolerances 1e-2 ... 1e-10] [--max-time 20]

Group #1 surface (the dissertation, 1). For each regime p*, a reference is solved to natural KKT residual 1e-13 by the
default solver (preconditioned PK with the BCCG active set) and checked against the published PK
(``pk_plain``) to 1e-12, an independent algorithm. Each preset then solves the same problem from a
cold start to each tolerance of ``--tolerances`` in turn; the error of A*, of gbar and of the pressure
field against the reference is plotted against the wall time of the solve. Load-controlled presets
(PK, ALMM) solve the load; the TAO bound types solve the displacement-controlled QP at the reference
separation, so that every preset meets the same solution. A preset's ladder stops at its first
non-converged solve (time limit ``--max-time`` or a named failure): tighter tolerances would not do
better.

Errors: |A* - A*_ref| / A*_ref, |gbar - gbar_ref| / gbar_ref and ||p - p_ref||_2 / ||p_ref||_2. An
error of exactly zero (A* counts nodes) is drawn at 1e-16.

Writes studies/output/work_precision/: one PNG per p*, work_precision.md, work_precision.json.
"""

import argparse
import json
import math
import os

import numpy as np

import common

OUT = os.path.join(common.OUTPUT, "work_precision")
FLOOR = 1e-16
QUANTITIES = (("A", "A*"), ("gbar", "gbar"), ("pressure", "pressure field (L2)"))


def relative(value, reference):
    return abs(value - reference) / abs(reference)


def reference_solution(problem, pstar):
    """(Result, pressure field) to natural residual 1e-13, and its distance to published PK at 1e-12."""
    reference, field, _ = common.solve(problem, common.presets(["pk"])["pk"], 1e-13, pstar=pstar)
    check, check_field, _ = common.solve(problem, common.presets(["pk_plain"])["pk_plain"], 1e-12, pstar=pstar)
    if not (reference.converged and check.converged):
        raise SystemExit(f"p*={pstar}: the reference did not converge ({reference.reason}, {check.reason})")
    agreement = {"A": relative(check.A, reference.A), "gbar": relative(check.gbar, reference.gbar),
                 "pressure": float(np.linalg.norm(check_field - field) / np.linalg.norm(field)),
                 "natural": reference.kkt.natural}
    return reference, field, agreement


def ladder(problem, name, options, tolerances, reference, reference_field, pstar, max_time):
    """The preset's solves at each tolerance: a list of dicts (rtol, seconds, errors, ...)."""
    options = dict(options, solve_max_time=str(max_time))
    rows = []
    for rtol in tolerances:
        if common.load_controls(options):
            result, field, _ = common.solve(problem, options, rtol, pstar=pstar)
        else:
            result, field, _ = common.solve(problem, options, rtol, "displacement", gbar=reference.separation)
        row = {"preset": name, "pstar": pstar, "rtol": rtol, "seconds": result.time_s,
               "applications": result.operator_applications, "iterations": result.iterations,
               "natural": result.kkt.natural, "converged": result.converged, "reason": result.reason,
               "A": relative(result.A, reference.A), "gbar": relative(result.gbar, reference.gbar),
               "pressure": float(np.linalg.norm(field - reference_field) / np.linalg.norm(reference_field))}
        rows.append(row)
        print(f"p*={pstar} {name} rtol={rtol:g}: {result.time_s:.2f} s, {result.iterations} its, natural "
              f"{result.kkt.natural:.1e}, errors A* {row['A']:.1e} gbar {row['gbar']:.1e} p {row['pressure']:.1e}"
              f"{'' if result.converged else ' (' + result.reason + ')'}", flush=True)
        if not result.converged:
            break
    return rows


def plot(rows, n, pstar):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), sharex=True)
    names = list(dict.fromkeys(r["preset"] for r in rows))
    for index, name in enumerate(names):
        mine = [r for r in rows if r["preset"] == name and r["converged"]]
        if not mine:
            continue
        style = "o-" if name.startswith("pk") else "s--" if name == "almm" else "^:"
        for axis, (key, _) in zip(axes, QUANTITIES):
            axis.loglog([r["seconds"] for r in mine], [max(r[key], FLOOR) for r in mine], style,
                        color=plt.cm.tab20(index % 20), label=name, ms=4)
    for axis, (_, label) in zip(axes, QUANTITIES):
        axis.set_xlabel("wall time of the solve [s]")
        axis.set_ylabel(f"relative error of {label}")
        axis.grid(alpha=0.3, which="both")
    axes[2].legend(fontsize=7, ncol=2)
    fig.suptitle(f"Work-precision, group #1, N = {n}, p* = {pstar:g}: one point per tolerance "
                 "(solid PK, dashed ALMM, dotted TAO bound types at the reference separation)")
    return common.save_figure(fig, OUT, f"work_precision_p{pstar:g}.png")


def time_to(rows, name, pstar, key, level):
    """Wall time of the fastest converged solve of a preset whose error in ``key`` is <= level."""
    times = [r["seconds"] for r in rows if r["preset"] == name and r["pstar"] == pstar and r["converged"]
             and r[key] <= level]
    return min(times) if times else None


def write_report(args, rows, references, figures):
    with open(os.path.join(OUT, "work_precision.json"), "w") as f:
        json.dump({"rows": rows, "references": references}, f)
    text = ["# Run time against error (work-precision)", "",
            f"Group #1 surface (the dissertation, 1), N = {args.n}, one process, cold starts. Each point is one solve to a "
            "natural KKT residual tolerance; errors are against a reference solved to 1e-13 by preconditioned "
            "PK (BCCG), itself checked against the published PK to 1e-12. Load-controlled presets (pk, pk_plain, "
            "almm) solve the load; the TAO bound types solve the displacement-controlled QP at the reference "
            "separation. Shared 2-core machine: compare times within a regime.", "",
            "## References", "",
            common.markdown_table(["p*", "A*", "gbar / rms", "natural residual", "published PK vs reference: A*",
                                   "gbar", "pressure"],
                                  [[p, f"{ref['A_value']:.6f}", f"{ref['gstar']:.8f}", f"{ref['natural']:.1e}",
                                    f"{ref['A']:.1e}", f"{ref['gbar']:.1e}", f"{ref['pressure']:.1e}"]
                                   for p, ref in references.items()]), ""]
    for level in (1e-3, 1e-6):
        text += [f"## Wall time [s] to a relative error <= {level:g} (fastest per regime in bold)", ""]
        table = []
        for pstar in references:
            names = list(dict.fromkeys(r["preset"] for r in rows if r["pstar"] == pstar))
            for key, label in QUANTITIES:
                times = {name: time_to(rows, name, pstar, key, level) for name in names}
                reached = [t for t in times.values() if t is not None]
                best = min(reached) if reached else None
                table.append([pstar, label] + [("**%.3f**" if t == best else "%.3f") % t if t is not None else "-"
                                               for t in times.values()])
        header_names = list(dict.fromkeys(r["preset"] for r in rows))
        text += [common.markdown_table(["p*", "error of"] + header_names, table), ""]
    text += ["## Figures", ""] + [f"![{name}]({name})" for name in figures] + [
        "", "## Every solve", "",
        common.markdown_table(["p*", "preset", "rtol", "s", "its", "FFT pairs", "natural", "err A*", "err gbar",
                               "err p", "reason"],
                              [[r["pstar"], r["preset"], f"{r['rtol']:g}", f"{r['seconds']:.3f}", r["iterations"],
                                r["applications"], f"{r['natural']:.1e}", f"{r['A']:.1e}", f"{r['gbar']:.1e}",
                                f"{r['pressure']:.1e}", r["reason"]] for r in rows]),
        "", "Regenerate: `.venv/bin/python studies/work_precision.py --n %d --pstars %s --max-time %g`"
        % (args.n, " ".join(f"{p:g}" for p in args.pstars), args.max_time), ""]
    with open(os.path.join(OUT, "work_precision.md"), "w") as f:
        f.write("\n".join(text))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=512)
    parser.add_argument("--pstars", type=float, nargs="*", default=[0.05, 0.5, 2.0, 3.5])
    parser.add_argument("--presets", nargs="*", default=None)
    parser.add_argument("--tolerances", type=float, nargs="*",
                        default=[1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10])
    parser.add_argument("--max-time", type=float, default=20.0)
    args = parser.parse_args()
    common.init()
    os.makedirs(OUT, exist_ok=True)
    presets = common.presets(args.presets)
    problem = common.group1_problem(args.n)
    rows, references, figures = [], {}, []
    try:
        for pstar in args.pstars:
            if pstar * math.sqrt(problem.m0p_scaled) >= problem.complete_contact_pbar:
                print(f"p*={pstar}: beyond complete contact (exact answer, no iterations); skipped", flush=True)
                continue
            reference, field, agreement = reference_solution(problem, pstar)
            references[pstar] = dict(agreement, A_value=reference.A, gstar=reference.gstar)
            print(f"p*={pstar}: reference A*={reference.A:.6f} natural {reference.kkt.natural:.1e}; published PK "
                  f"differs by {agreement['pressure']:.1e} in pressure", flush=True)
            block = []
            for name, options in presets.items():
                block += ladder(problem, name, options, args.tolerances, reference, field, pstar, args.max_time)
            rows += block
            figures.append(plot(block, args.n, pstar))
            write_report(args, rows, references, figures)  # after every regime: a partial run leaves a report
    finally:
        problem.destroy()


if __name__ == "__main__":
    main()
