"""TAO's bound types against Polonsky-Keer under load and displacement control, before and after issue 40.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/tao_speed.py [--sizes 512 1024] [--pstars 0.05 0.5 2]
        [--solvers blmvm bqnls gpcg tron] [--variants after al before] [--max-time 600] [--profile 1024] [--report]

Group #1 surface (seed 1), natural KKT residual 1e-8, FFTW_MEASURE plans remembered in the wisdom cache (so the
iterates repeat from the second run of a size on). Per N and p*: Polonsky-Keer (the default solver) under load
control gives the separation d; every solver then solves the load (``pstar``) and the QP at d, cold. Variants:
``after``, ``-tao_type <type>`` as it is (load control in the gap for BLMVM, BQNLS, TRON and GPCG,
roughpetsc/solvers/bound_gap.py; the Fourier initial Hessian of the quasi-Newton types, fused callbacks);
``al``, load control by the augmented Lagrangian on mean(p) = pbar (``-bound_load al``, bound_qp.py; its
displacement control is ``after``'s); ``before``, the former methods as options still select them
(``-bound_load rootfind -bound_h0 none``: a root find on d around each type, PETSc's initial Hessian).
The ``before`` rows of the committed tao_speed.json and the profile were measured on the code before these
changes (commit 4c0fa30: unfused callbacks too), so they show the whole gain; a rerun of ``before`` now
measures the former methods with the fused callbacks. ``--profile N`` counts PETSc's vector operations and
times our events per iteration for PK, BLMVM and BQNLS under displacement control at N, p* = 0.5 (the
-log_view breakdown, read through petsc4py's log).

FFT pairs (operator and preconditioner applications) are deterministic; wall times on the shared, loaded
machine are not, so every ratio is from one run. Rows are kept in studies/output/tao_speed/tao_speed.json
(rerunning skips measured rows); ``--report`` writes tao_speed.md and tao_speed.png from them.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy/petsc4py load OpenBLAS (a threaded VecDot
                                                    # took 1.4 ms at 65k doubles on the loaded machine)
import argparse
import time

import common

OUT = os.path.join(common.OUTPUT, "tao_speed")
PROFILED_EVENTS = ("VecDot", "VecNorm", "VecScale", "VecCopy", "VecSet", "VecAXPY", "VecAYPX", "VecAXPBYCZ",
                   "VecWAXPY", "VecPointwiseMult", "VecReduceArith", "VecScatterBegin", "SFSetGraph", "MatSolve",
                   "TaoLSApply", "TaoObjGradEval", "RPFFTPair", "RPFourierPC", "RPKKTCheck", "RPBoundTest",
                   "RPBoundH0", "TaoSolve")
VECTOR_OPS = [e for e in PROFILED_EVENTS if e.startswith("Vec")]
PLOTTED = ("pk", "blmvm", "bqnls", "gpcg", "tron")  # the four and the default: the plot stays legible


# What was tried on load control and not kept, for the report.
TRIED = ["## Tried and not kept", "",
         "Group #1, N = 512, load control unless said; FFT pairs of BLMVM (then BQNLS) at p* = 0.05/0.5/2, "
         "against 205/201/124 (394/398/114) with the penalty 1 and recycled memory of the code before.", "",
         "- Penalty 10, 100, 1000 (`-bound_al_penalty`): BLMVM 597 / stalled at natural residual 3.3 after 3019 "
         "pairs / 139 at 10, stalled or failed line searches at 2 or 3 of the loads at 100 and 1000; charging the "
         "H0's mean-mode weight 8 to K alone (the penalty's part is exact) did not help.",
         "- Inner tolerance `-bound_al_eta` 0.5, 0.9, 0.01 instead of 0.1: BLMVM 289/197/118, 242/207/109, "
         "226/228/112.",
         "- Line searches under displacement control, p* = 0.5: armijo, gpcg, unit, owarmijo gave BLMVM a failed "
         "line search at 0.035 / 597 pairs / stagnation / stagnation, against 101 pairs with More-Thuente.",
         "- A zero start (lambda from its contact set) instead of the uniform one: BLMVM 182/293/125, BQNLS "
         "390/439/150.",
         "- Correcting the pressure with the stiffness solve's response w = K_CC^-1 1_C at the Newton step "
         "(p <- max(p - dd w, 0)): the residual after the step fell from 0.28 to 6.8e-3 at p* = 0.5, but "
         "BLMVM took 223/194/126 and BQNLS 330/342/100 pairs; with a looser first inner solve too (eta 1 or 10) "
         "solves failed after 40 inner solves.",
         "- The exact separation as the first lambda (an oracle, bounding what a better first lambda can give): "
         "BLMVM 229/156/74 from the uniform start, 160/166/77 from zero, still 1.5-3x its displacement-controlled "
         "pairs at p* <= 0.5.",
         "- lambda updated inside one TAO solve (in the convergence test): not built. The gradient's shift by a "
         "constant enters the L-BFGS pair that spans the update, and PETSc 3.18 gives no handle on BLMVM's "
         "L-BFGS matrix to reset it (TaoGetLMVMMatrix serves the BQNK types only); a restart costs one pair, so "
         "the saving is bounded by the 2-7 inner solves.",
         "- The gap form's line searches (BLMVM, N = 512, p* = 0.5): armijo stopped on a failed line search at "
         "a natural residual of 0.054, unit stagnated at 1, gpcg failed at once; More-Thuente (the default) "
         "took 124 pairs.",
         "- The gap form's compliance preconditioner for the Newton types (`-bound_pc fourier`, kept as an "
         "option), N = 256, p* = 0.05 / 0.5 against none: TRON 173 / 148 pairs against 223 / 86, GPCG 2567 / 533 "
         "against 245 / 106.",
         "- The gap form's mean-mode weight (BLMVM, N = 256, p* = 0.5): 0.3 / 1 / 3 / 8 took 239 / 201 / 162 pairs "
         "/ a failed line search; 3 is kept.",
         "- The gap form's L-BFGS memory (N = 512, p* = 0.05 / 0.5 / 2): BLMVM 95 / 114 / 54 pairs at 1 (kept), "
         "115 / 124 / 177 at 3, 126 / 128 / 870 at 5; BQNLS 109 / 120 / 49 at 1, 128 / 141 / 75 at 10.",
         "- The gap form's mean-mode weight at small loads, from the highest summit (BLMVM, N = 256, p* = 0.01 / "
         "0.05 / 0.5): 1022 / 98 / 121 pairs at 3, 419 / 127 / 153 at 0.3, 127 / 202 / 266 at 0.03; no weight "
         "served every load, and the cut start (64 / 65 / 95) replaced the search for one.",
         "- TRON's KSP tolerance in the gap form without a preconditioner (N = 512, p* = 0.05 / 0.5 / 2): 217 / "
         "97 / 60 pairs at 0.3, 206 / 95 / 53 at 0.1, 228 / 87 / 52 at 0.03, 379 / 127 / 55 at PETSc's 1e-5; "
         "with the compliance preconditioner 175 / 148 / 79 at 0.3, 165 / 142 / 70 at 0.1 (kept); at most 10 "
         "gradient-projection steps (`-tao_tron_maxgpits`, default 3) 212 / 142 / 74.",
         "- GPCG's KSP tolerance in the gap form (N = 512, p* = 0.05 / 0.5 / 2): 1e-3 stalled at a natural "
         "residual of 1.6e-7 / 1.3e-6 / 3.1e-8 with its iterate unchanged for 100 s; 1e-2 gave 329 / 90 / 69 "
         "pairs (before the cut start, 0.1 and 1e-2 stalled at three and two of the loads). PETSc's 1e-5 is "
         "kept.", ""]

# The options of the variants other than "after" (-tao_type X as it is): "before", the methods before issue 40;
# "al", load control by the augmented Lagrangian, the default before the gap form.
VARIANT_OPTIONS = {"before": {"bound_load": "rootfind", "bound_h0": "none"}, "al": {"bound_load": "al"}}


def problem_for(n):
    from petsc4py import PETSc

    from roughpetsc.fft import plans

    with plans.remembered_plans(PETSc.COMM_WORLD.tompi4py(), plans.default_wisdom_path(), "FFTW_MEASURE"):
        return common.group1_problem(n, effort="FFTW_MEASURE")


def one_solve(problem, solver, variant, control, pstar, separation, max_time, repeat=1):
    """One cold solve, timed ``repeat`` times (once if it stops unconverged); a row of the table, its seconds
    the fastest run's.

    The iterates repeat exactly (same plans, same start), so the runs differ in the machine's load only, which can
    only slow a run down: the fastest is the best estimate of the cost on an idle machine. A run that took other
    iterations or pairs than the first stops the study.
    """
    options = {"solve_max_time": str(max_time)}
    if solver != "pk":
        options["tao_type"] = solver
        options.update(VARIANT_OPTIONS.get(variant, {}))
    load = {"pstar": pstar} if control == "load" else {"gbar": separation}
    runs = []
    for _ in range(repeat):
        result, _, _ = common.solve(problem, options, 1e-8, control=control, **load)
        runs.append(round(result.time_s, 3))
        counts = (result.iterations, result.operator_applications)
        if len(runs) == 1:
            first = counts
            if not result.converged:  # a time limit or a stall: once is enough to name it
                break
        elif counts != first:
            raise RuntimeError(f"{solver} {control} p* = {pstar}: run {len(runs)} took {counts} (iterations, "
                               f"pairs) against {first}; no timing kept")
    seconds = min(runs)
    return {"iterations": result.iterations, "pairs": result.operator_applications,
            "seconds": seconds, "seconds_runs": runs,
            "ms_per_pair": round(1e3 * seconds / max(result.operator_applications, 1), 2),
            "natural": result.kkt.natural, "load_error": result.kkt.load_error, "converged": bool(result.converged),
            "reason": result.reason, "name": result.solver, "separation": result.separation}


def warm_up(solvers, variants):
    """One small solve of every backend first: the first solve of a process loads the compiled kernels."""
    problem = common.group1_problem(128)
    for variant in variants:
        for solver in ["pk"] + list(solvers):
            one_solve(problem, solver, variant, "load", 0.5, None, 60)
    problem.destroy()


def run_grid(args, path, rows):
    done = {(r["variant"], r["N"], r["pstar"], r["solver"], r["control"]) for r in rows}
    warm_up(args.solvers, args.variants)
    for n in args.sizes:
        problem = problem_for(n)
        for pstar in args.pstars:
            reference = [r for r in rows if (r["variant"], r["N"], r["pstar"], r["solver"], r["control"]) ==
                         ("after", n, pstar, "pk", "load")]
            plan = [("after", "pk", "load"), ("after", "pk", "displacement")]
            # "al" differs from "after" under load control only: its displacement-controlled row is "after"'s.
            plan += [(variant, solver, control) for variant in args.variants for solver in args.solvers
                     for control in ("load", "displacement") if (variant, control) != ("al", "displacement")]
            for variant, solver, control in plan:
                key = (variant, n, pstar, solver, control)
                if key in done:
                    continue
                separation = reference[0]["separation"] if reference else None
                row = {"variant": variant, "N": n, "pstar": pstar, "solver": solver, "control": control}
                row.update(one_solve(problem, solver, variant, control, pstar, separation, args.max_time,
                                     args.repeat))
                if key[3:] == ("pk", "load"):
                    reference = [row]
                rows.append(row)
                done.add(key)
                common.save_rows(path, rows)
                print(f"N={n} p*={pstar} {variant:6s} {solver:6s} {control:12s} its {row['iterations']:6d} "
                      f"pairs {row['pairs']:6d} {row['seconds']:8.2f} s {row['ms_per_pair']:7.1f} ms/pair "
                      f"{row['reason']}", flush=True)
        problem.destroy()


PROFILED = (("after", "pk", "displacement"), ("before", "blmvm", "displacement"), ("before", "bqnls", "displacement"),
            ("after", "blmvm", "displacement"), ("after", "bqnls", "displacement"), ("after", "pk", "load"),
            ("after", "blmvm", "load"), ("after", "bqnls", "load"))


def run_profile(n, path, max_time):
    """Vector operations per iteration and seconds per event at N, p* = 0.5, for the solves of :data:`PROFILED`
    not yet in ``path`` (rows without a control are of displacement control)."""
    from petsc4py import PETSc

    PETSc.Log.begin()
    rows = common.load_rows(path)
    done = {(r["variant"], r["solver"], r.get("control", "displacement")) for r in rows if r["N"] == n}
    todo = [key for key in PROFILED if key not in done]
    warm_up(sorted({solver for _, solver, _ in todo} - {"pk"}), sorted({variant for variant, _, _ in todo}))
    problem = problem_for(n)
    reference = one_solve(problem, "pk", "after", "load", 0.5, None, max_time)
    for variant, solver, control in todo:
        stage = PETSc.Log.Stage(f"{variant}-{solver}-{control}")
        stage.push()
        row = one_solve(problem, solver, variant, control, 0.5, reference["separation"], max_time)
        stage.pop()
        counts = {e: PETSc.Log.Event(e).getPerfInfo(stage.id) for e in PROFILED_EVENTS}
        row.update({"variant": variant, "solver": solver, "N": n, "control": control,
                    "events": {e: [info["count"], round(info["time"], 4)] for e, info in counts.items()}})
        rows.append(row)
        print(f"{variant} {solver} {control}: {row['iterations']} its, {row['pairs']} pairs, {row['seconds']} s, "
              f"{sum(counts[e]['count'] for e in VECTOR_OPS) / max(row['iterations'], 1):.1f} vector ops per "
              f"iteration", flush=True)
        common.save_rows(path, rows)
    problem.destroy()


def find(rows, **key):
    found = [r for r in rows if all(r.get(k) == v for k, v in key.items())]
    return found[0] if found else None


def load_ratio_table(rows):
    """Item 1 for every bound type: load- over displacement-controlled FFT pairs, one column per N and p*."""
    cells = sorted({(r["N"], r["pstar"]) for r in rows})
    solvers = sorted({r["solver"] for r in rows if r["solver"] != "pk"})
    header = ["type"] + [f"N = {n}, p* = {pstar:g}" for n, pstar in cells] + ["worst"]
    lines = []
    for solver in solvers:
        line, worst = [solver], 0.0
        for n, pstar in cells:
            load = find(rows, N=n, pstar=pstar, solver=solver, control="load", variant="after")
            disp = find(rows, N=n, pstar=pstar, solver=solver, control="displacement", variant="after")
            if not (load and disp):
                line.append("")
                continue
            ratio = load["pairs"] / disp["pairs"]
            worst = max(worst, ratio)
            unconverged = "" if load["converged"] and disp["converged"] else " (not converged)"
            line.append(f"{load['pairs']} / {disp['pairs']} = {ratio:.2f}{unconverged}")
        lines.append(line + [f"{worst:.2f}"])
    return common.markdown_table(header, lines)


def grid_table(rows):
    header = ["N", "p*", "solver", "control", "variant", "its", "FFT pairs", "s", "ms/pair", "x PK time",
              "x PK ms/pair", "load/disp pairs", "natural", "load err", "reason"]
    lines = []
    order = {"before": 0, "al": 1, "after": 2}
    for r in sorted(rows, key=lambda r: (r["N"], r["pstar"], r["solver"] != "pk", r["solver"], r["control"],
                                         order[r["variant"]])):
        pk = find(rows, N=r["N"], pstar=r["pstar"], solver="pk", control=r["control"])
        disp = find(rows, N=r["N"], pstar=r["pstar"], solver=r["solver"], control="displacement",
                    variant="after" if r["variant"] == "al" else r["variant"])
        ratio = f"{r['pairs'] / disp['pairs']:.2f}" if r["control"] == "load" and disp else ""
        load_error = "" if r["load_error"] is None else f"{r['load_error']:.1e}"
        lines.append([r["N"], r["pstar"], r["solver"], r["control"], r["variant"], r["iterations"], r["pairs"],
                      f"{r['seconds']:.2f}", f"{r['ms_per_pair']:.1f}", f"{r['seconds'] / pk['seconds']:.2f}",
                      f"{r['ms_per_pair'] / pk['ms_per_pair']:.2f}", ratio, f"{r['natural']:.1e}", load_error,
                      r["reason"]])
    return common.markdown_table(header, lines)


def profile_table(profile):
    header = ["N", "solver", "its", "FFT pairs", "s", "ms/pair"] + [e for e in VECTOR_OPS] + \
             ["vector ops/it", "s in vector ops", "s in FFT pairs", "s in our test", "s in our H0",
              "s in TAO's own work", "ms/pair without our work", "x PK ms/pair without our work"]
    lines = []
    for r in sorted(profile, key=lambda r: (r["N"], r["variant"] != "before", r.get("control", "displacement"),
                                            r["solver"] != "pk")):
        events = r["events"]
        its = max(r["iterations"], 1)
        vector_ops = sum(events[e][0] for e in VECTOR_OPS)
        own, bound = tao_own_work(r), ""
        pk = find(profile, N=r["N"], solver="pk", variant="after", control=r.get("control", "displacement"))
        if own is not None:
            # What a pair would cost if our callbacks did nothing but their FFT pairs: TAO's part cannot go lower.
            bound = 1e3 * (own + events["RPFFTPair"][1]) / max(r["pairs"], 1)
        lines.append([r["N"], f"{r['solver']} ({r['variant']}, {r.get('control', 'displacement')})", r["iterations"],
                      r["pairs"], f"{r['seconds']:.2f}",
                      f"{r['ms_per_pair']:.1f}"] + [f"{events[e][0] / its:.1f}" for e in VECTOR_OPS] +
                     [f"{vector_ops / its:.1f}", f"{sum(events[e][1] for e in VECTOR_OPS):.2f}",
                      f"{events['RPFFTPair'][1]:.2f}", f"{events['RPBoundTest'][1] + events['RPKKTCheck'][1]:.2f}",
                      f"{events['RPBoundH0'][1]:.2f}", "" if own is None else f"{own:.2f}",
                      "" if own is None else f"{bound:.1f}",
                      f"{bound / pk['ms_per_pair']:.2f}" if own is not None and pk else ""])
    return common.markdown_table(header, lines)


def tao_own_work(row):
    """Seconds inside TaoSolve outside our callbacks (objective and gradient, initial Hessian, convergence test):
    PETSc's vector work, line search and bookkeeping. None for PK and for rows profiled without TaoSolve."""
    events = row["events"]
    if row["solver"] == "pk" or "TaoSolve" not in events:
        return None
    ours = events["TaoObjGradEval"][1] + events["RPBoundH0"][1] + events["RPBoundTest"][1]
    return events["TaoSolve"][1] - ours


def plot(rows, folder):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pstars = sorted({r["pstar"] for r in rows})
    sizes = sorted({r["N"] for r in rows})
    fig, axes = plt.subplots(2, len(pstars), figsize=(4.2 * len(pstars), 7), squeeze=False)
    series = sorted({(r["solver"], r["control"], r["variant"]) for r in rows})
    colors = {solver: f"C{i}" for i, solver in enumerate(sorted({s for s, _, _ in series}))}
    handles = {}
    for column, pstar in enumerate(pstars):
        for solver, control, variant in series:
            chosen = sorted((r for r in rows if (r["pstar"], r["solver"], r["control"], r["variant"]) ==
                             (pstar, solver, control, variant)), key=lambda r: r["N"])
            if not chosen:
                continue
            label = f"{solver} {control[:4]}" + ("" if variant == "after" else f" ({variant})")
            style = dict(color=colors[solver], marker="o" if control == "load" else "s",
                         linestyle="--" if control == "displacement" else {"after": "-", "al": ":"}.get(variant, "-."),
                         fillstyle="full" if variant == "after" else "none")
            n = [r["N"] for r in chosen]
            handles[label], = axes[0, column].plot(n, [r["pairs"] for r in chosen], label=label, **style)
            axes[1, column].plot(n, [r["seconds"] for r in chosen], label=label, **style)
        axes[0, column].set_title(f"p* = {pstar}")
        for row, quantity in enumerate(("FFT pairs", "seconds")):
            axes[row, column].set(xscale="log", yscale="log", xlabel="N", ylabel=quantity)
            axes[row, column].minorticks_off()
            axes[row, column].set_xticks(sizes, [str(n) for n in sizes])
    axes[0, -1].legend(handles.values(), handles.keys(), fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    return common.save_figure(fig, folder, "tao_speed.png")


def report(rows, profile, folder):
    lines = ["# TAO bound types against Polonsky-Keer, before and after issue 40", "",
             "Generated by `OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/tao_speed.py --report` (group #1 "
             "surface, seed 1, natural KKT residual 1e-8, cold starts, FFTW_MEASURE plans from the wisdom cache). "
             "FFT pairs are deterministic and include the certificate. `x PK time`, `x PK ms/pair`: against "
             "Polonsky-Keer under the same control, N and p*; `load/disp pairs`: the load-controlled solve's pairs "
             "over the same solver's displacement-controlled ones. Variants: `after`, `-tao_type X` as it is now "
             "(under load control every bound type but BNCG solves for the gap in one TAO solve, "
             "roughpetsc/solvers/bound_gap.py; displacement control is unchanged); `al`, `-bound_load al`, the "
             "augmented Lagrangian on mean(p) = pbar that was their load control before (bound_qp.py); `before`, "
             "the methods before issue 40 (a root find on d, PETSc's initial Hessian), measured on commit 4c0fa30 "
             "at N = 512, p* = 0.5 only. PK and `after` rows: `--variants after --repeat 3 --max-time 200`, every "
             "solve run three times in a row and its fastest run kept (the iterates repeat exactly; the machine's "
             "other load can only slow a run), with the long background runs paused and the second core idle. "
             "Single runs beside those jobs had flattered the TAO types: PK gained more from a quiet machine "
             "(0.26 s against 0.40 s at N = 512, p* = 0.05) than they did. The `al` rows (`--variants al --solvers "
             "blmvm bqnls tron --max-time 200`; GPCG's, which stall at p* >= 0.5 after 300 s, from the run before) "
             "are single runs from earlier sessions, whose PK they divide by no longer. The N = 2048 rows (p* = 0.5; "
             "`--sizes 2048 --pstars 0.5 --solvers blmvm bqnls --variants after before --max-time 300`) are single "
             "runs beside the test suite, for the initial Hessian at N = 2048: under displacement control `before` "
             "is PETSc's (`-bound_h0 none`) and `after` the Fourier one; both with today's callbacks.",
             ""] + TRIED
    if rows:
        lines += ["## Load against displacement control, every bound type (item 1)", "",
                  "FFT pairs of the load-controlled solve over the displacement-controlled one at the same "
                  "separation, `after` rows. BNCG, BNLS, BNTR, BNTL, BQNKLS, BQNKTR and BQNKTL are single runs "
                  "(`--solvers bncg bnls bntr bntl bqnkls bqnktr bqnktl --max-time 200`) made beside the test "
                  "suite and the long background run: their pairs are exact, their seconds (in the next table) "
                  "are slowed by that load and not comparable with the idle rows.", "",
                  load_ratio_table(rows), "",
                  "## Every solve", "", grid_table(rows), "",
                  f"![time and pairs]({plot([r for r in rows if r['solver'] in PLOTTED], folder)})", ""]
    if profile:
        lines += ["## Where the time goes: p* = 0.5", "",
                  "Vector operations per iteration by PETSc event (-log_view counts read through petsc4py), "
                  "and seconds in them, in FFT pairs and in our callbacks. `TAO's own work` is TaoSolve's time "
                  "less our callbacks inside it (objective and gradient, initial Hessian, convergence test): "
                  "PETSc's vector operations, projections and line search. `ms/pair without our work` is what a "
                  "pair would cost if our callbacks did nothing but their FFT pairs, (TAO's own + FFT) / pairs: "
                  "the per-pair cost no change on our side can go below. The `after` rows come from one run "
                  "each (`--profile 1024`, then `--profile 512`) with the long background runs paused; the "
                  "`before` rows at N = 1024 from an earlier, loaded run (without TaoSolve).", "",
                  profile_table(profile), ""]
    with open(os.path.join(folder, "tao_speed.md"), "w") as f:
        f.write("\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[512, 1024])
    parser.add_argument("--pstars", type=float, nargs="+", default=[0.05, 0.5, 2.0])
    parser.add_argument("--solvers", nargs="+", default=["blmvm", "bqnls", "gpcg", "tron"])
    parser.add_argument("--variants", nargs="+", default=["after"], choices=["after", "al", "before"])
    parser.add_argument("--max-time", type=float, default=600.0)
    parser.add_argument("--repeat", type=int, default=1,
                        help="time every solve this many times and keep the fastest run (iterates repeat exactly)")
    parser.add_argument("--profile", type=int, default=0, help="N of the -log_view breakdown (0: none)")
    args, path, rows = common.start_resumable(parser, OUT, "tao_speed", "write tao_speed.md and the plot only")
    profile_path = os.path.join(OUT, "tao_speed_profile.json")
    if args.report:
        report(rows, common.load_rows(profile_path), OUT)
        return
    start = time.perf_counter()
    if args.profile:
        run_profile(args.profile, profile_path, args.max_time)
    else:
        run_grid(args, path, rows)
    print(f"done in {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
