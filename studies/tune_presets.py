"""Tuning of the solver presets in solvers/: candidate options of each TAO type, timed on one problem.

    .venv/bin/python studies/tune_presets.py [--n 256] [--pstar 0.5]

Group #1 surface, seed 1; displacement control at the separation of the load p* (found first by
preconditioned PK to 1e-12), natural KKT residual 1e-8; ALMM and PK under load control. For each
candidate: iterations, operator applications (FFT pairs), wall time. The preset files quote the
winners. Options nobody reads stop the script (a misspelled candidate cannot pass unnoticed).
"""

import argparse
import json
import os

import common

CANDIDATES = {
    "pk": [{"pk_pc": "none"}, {"pk_pc": "fourier"}, {"pk_pc": "fourier", "pk_refresh": "10"},
           {"pk_pc": "fourier", "pk_refresh": "200"}],
    "blmvm": [{"tao_blmvm_mat_lmvm_hist_size": v} for v in ("3", "5", "10", "20")],
    "bqnls": [{"tao_bqnls_mat_lmvm_hist_size": v} for v in ("5", "10", "20")],
    "bncg": [{"tao_bncg_type": v} for v in ("gd", "pcgd", "hs", "fr", "prp", "pr", "dy", "hz", "dk", "kd",
                                            "ssml_bfgs", "ssml_dfp", "ssml_brdn")],
    "bqnkls": [{"tao_bqnk_mat_lmvm_hist_size": v} for v in ("5", "10")],
    "bqnktr": [{"tao_bqnk_mat_lmvm_hist_size": v} for v in ("5", "10")],
    "bnls": [{"bound_pc": pc, "tao_bnk_ksp_type": k} for pc in ("fourier", "none") for k in ("cg", "stcg")],
    "bntr": [{"bound_pc": pc, "tao_bnk_ksp_type": k} for pc in ("fourier", "none") for k in ("stcg", "gltr")],
    "tron": [{"bound_pc": pc, "tao_tron_maxgpits": g} for pc in ("none", "fourier") for g in ("3", "10")],
    "gpcg": [{"bound_pc": pc} for pc in ("none", "fourier")],
    "almm": [{"tao_almm_subsolver_tao_type": t, "tao_almm_type": a} for t in ("bqnls", "blmvm", "bncg")
             for a in ("classic", "phr")],
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=256)
    parser.add_argument("--pstar", type=float, default=0.5)
    parser.add_argument("--types", nargs="*", default=list(CANDIDATES))
    parser.add_argument("--max-time", type=float, default=60.0)
    args = parser.parse_args()
    common.init()
    problem = common.group1_problem(args.n)
    reference, _, _ = common.solve(problem, {"pk_pc": "fourier"}, 1e-12, pstar=args.pstar)
    rows, records = [], []
    for tao_type in args.types:
        for candidate in CANDIDATES[tao_type]:
            options = dict(candidate, solve_max_time=str(args.max_time))
            if tao_type != "pk":
                options["tao_type"] = tao_type
            if common.load_controls(options):
                result, _, _ = common.solve(problem, options, 1e-8, pstar=args.pstar)
            else:
                result, _, _ = common.solve(problem, options, 1e-8, "displacement", gbar=reference.separation)
            label = " ".join(f"-{k} {v}" for k, v in candidate.items()) or "(defaults)"
            rows.append([tao_type, label, result.control, result.iterations, result.operator_applications,
                         f"{result.time_s:.3f}", f"{result.kkt.natural:.1e}", result.reason])
            records.append({"type": tao_type, "options": candidate, "control": result.control,
                            "iterations": result.iterations, "applications": result.operator_applications,
                            "seconds": result.time_s, "natural": result.kkt.natural, "reason": result.reason,
                            "converged": result.converged})
            print(" | ".join(str(c) for c in rows[-1]), flush=True)
    problem.destroy()
    table = common.markdown_table(["type", "options", "control", "iterations", "FFT pairs", "seconds",
                                   "natural KKT", "reason"], rows)
    text = (f"# Preset tuning\n\nGroup #1, N = {args.n}, p* = {args.pstar}; displacement control at the "
            f"separation of that load unless the type is PK or ALMM; natural KKT residual 1e-8; time limit "
            f"{args.max_time} s per solve. Shared 2-core machine: compare within one run.\n\n{table}\n\n"
            f"Regenerate: `.venv/bin/python studies/tune_presets.py --n {args.n}`\n")
    os.makedirs(common.OUTPUT, exist_ok=True)
    with open(os.path.join(common.OUTPUT, "tune_presets.md"), "w") as f:
        f.write(text)
    with open(os.path.join(common.OUTPUT, "tune_presets.json"), "w") as f:
        json.dump(records, f, indent=1)
    print(table)


if __name__ == "__main__":
    main()
