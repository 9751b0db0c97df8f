"""MPI speed-up of an ensemble (the project target: 8 surfaces, one surface per rank, serial FFTs, >= 1.9x on 2 ranks).

    .venv/bin/python studies/ensemble_speedup.py [--N 256] [--size 8] [--loads history] [--ranks 2]

Runs ``python -m roughpetsc -mode ensemble`` twice on the same ensemble (group #1 of Table 7.1 by
default, ``--size`` surfaces of N x N nodes along the load history (7.11), no statistical models):
once on one rank and once under ``mpiexec -n RANKS`` with ``-ensemble_group_ranks 1`` (whole surfaces
per rank). It prints the wall time of each run (process start to end, so start-up and file writes
count), the ratio, and the largest difference between the two files (expected <= 1e-12, see
``roughpetsc.ensemble.compare``); a markdown summary goes to studies/output/ensemble_speedup.md.

``--loads`` takes anything ``-ensemble_loads`` does, or ``history/K`` for every K-th step of the
history (a documented subset for quick checks; the target is for the whole history). The machine
should be quiet and have at least RANKS cores: on a shared machine the ratio measures the neighbours.
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the repository

MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_rmaps_base_oversubscribe": "1", "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}


def load_argument(text):
    from roughpetsc.contact import loads

    if text.startswith("history/"):
        step = int(text.split("/", 1)[1])
        return ",".join(repr(float(p)) for p in loads.history()[step - 1::step])
    return text


def timed_run(arguments, ranks, output):
    command = [sys.executable, "-m", "roughpetsc", *arguments, "-output", output]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), "--oversubscribe", *command]
    env = dict(os.environ, **MPI_ENV, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    start, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(command, cwd=ROOT, env=env, capture_output=True, text=True)
    seconds, after = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
    from roughpetsc import ensemble

    inside = json.loads(ensemble.read(output)["@runs"])[-1]["seconds"]
    return seconds, inside, cpu


def concurrent_runs(arguments, ranks, folder):
    """``ranks`` independent one-rank ensembles side by side (no MPI between them), each with its own master
    seed: what the machine allows any distribution of whole surfaces. Returns (wall s, CPU s, files)."""
    env = dict(os.environ, **MPI_ENV, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    outputs = [os.path.join(folder, f"alone{r}.h5") for r in range(ranks)]
    start, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    processes = [subprocess.Popen([sys.executable, "-m", "roughpetsc", *arguments, "-ensemble_seed", str(1000 + r),
                                   "-output", output], cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.PIPE, text=True)
                 for r, output in enumerate(outputs)]
    for process in processes:
        _, error = process.communicate()
        if process.returncode != 0:
            sys.exit(f"a concurrent one-rank ensemble failed ({process.returncode}):\n{error}")
    seconds, after = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return seconds, cpu, outputs


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--N", type=int, default=256)
    parser.add_argument("--size", type=int, default=8)
    parser.add_argument("--loads", default="history")
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--options_file", default="", help="a surface preset, e.g. options/group01.opts")
    parser.add_argument("--extra", default="", help="more options for both runs, e.g. \"-surface_ks 16\"")
    parser.add_argument("--report", default=os.path.join(ROOT, "studies", "output", "ensemble_speedup.md"))
    args = parser.parse_args()

    from roughpetsc import ensemble

    arguments = ["-mode", "ensemble", "-surface_N", str(args.N), "-ensemble_size", str(args.size),
                 "-ensemble_loads", load_argument(args.loads), "-ensemble_models", "none",
                 "-ensemble_group_ranks", "1"]
    if args.options_file:
        arguments = ["-options_file", args.options_file] + arguments
    arguments += args.extra.split()
    with tempfile.TemporaryDirectory(prefix="ensemble_speedup_") as folder:
        one = os.path.join(folder, "one.h5")
        many = os.path.join(folder, "many.h5")
        load_before = os.getloadavg()[0]
        t1, e1, c1 = timed_run(arguments, 1, one)
        print(f"1 rank: {t1:.2f} s ({e1:.2f} s inside the ensemble run, {c1:.2f} CPU s)", flush=True)
        tn, en, cn = timed_run(arguments, args.ranks, many)
        print(f"{args.ranks} ranks: {tn:.2f} s ({en:.2f} s inside the ensemble run, {cn:.2f} CPU s over all "
              f"ranks)", flush=True)
        half = list(arguments)
        half[half.index("-ensemble_size") + 1] = str(args.size // args.ranks)
        tc, cc, alone = concurrent_runs(half, args.ranks, folder)
        print(f"{args.ranks} independent one-rank processes side by side, {args.size // args.ranks} surfaces each: "
              f"{tc:.2f} s, {cc:.2f} CPU s", flush=True)
        load_after = os.getloadavg()[0]
        worst = max(ensemble.compare(one, many).values())
        content = ensemble.read(one)
        steps = content["steps/iterations"].shape[1]
        solve_seconds = float(content["surfaces/time_s"].sum())
        per_surface = {"1 rank": content["surfaces/time_s"].mean(),
                       f"{args.ranks} ranks": ensemble.read(many)["surfaces/time_s"].mean(),
                       "side by side": float(np.mean([ensemble.read(f)["surfaces/time_s"].mean() for f in alone]))}
    ratio, inner, ceiling = t1 / tn, e1 / en, t1 / tc
    print(f"speed-up {ratio:.3f} (process wall time), {inner:.3f} (inside the run, without interpreter and MPI "
          f"start-up) on {args.ranks} ranks (target >= 1.9 on 2); files differ by at most {worst:.2e}")
    lines = [
        "# Ensemble speed-up (target: an ensemble of 8 surfaces on 2 ranks >= 1.9x faster than on 1)",
        "",
        f"`python studies/ensemble_speedup.py --N {args.N} --size {args.size} --loads {args.loads} --ranks "
        f"{args.ranks}" + (f" --options_file {args.options_file}" if args.options_file else "")
        + (f" --extra '{args.extra}'" if args.extra else "") + f"`: {args.size} surfaces, N = {args.N}, "
        f"{steps} load steps, one surface per rank (serial FFTs, -ensemble_group_ranks 1, no models). "
        "Process: wall time from process start to end (interpreter and MPI start-up included); run: the "
        "ensemble's own elapsed time (from its start to the final file, `seconds` in the file's run log).",
        "",
        "| ranks | process [s] | run [s] | CPU, all ranks [s] | speed-up (process) | speed-up (run) |",
        "|---|---|---|---|---|---|",
        f"| 1 | {t1:.2f} | {e1:.2f} | {c1:.2f} | 1 | 1 |",
        f"| {args.ranks} | {tn:.2f} | {en:.2f} | {cn:.2f} | {ratio:.3f} | {inner:.3f} |",
        f"| {args.ranks} independent one-rank processes, {args.size // args.ranks} surfaces each | {tc:.2f} | — | "
        f"{cc:.2f} | {ceiling:.3f} | — |",
        "",
        "The last row is the machine's own ceiling for whole surfaces per core: no MPI between the processes, "
        "each with its own master seed (surfaces of the same statistics). Mean solve time of one surface: "
        + ", ".join(f"{key} {value:.2f} s" for key, value in per_surface.items())
        + ". A surface solved while the other core also solves one takes longer than one solved alone: the two "
        "cores share the caches and the memory bus.",
        "",
        f"Sum of the per-surface solve times on 1 rank: {solve_seconds:.2f} s. Largest scaled difference between "
        f"the two files: {worst:.2e}. Measured on {os.cpu_count()} logical CPUs, 1-minute load average "
        f"{load_before:.2f} before and {load_after:.2f} after: with a load above the number of CPUs the ratio "
        "measures the neighbours (the CPU seconds over all ranks show whether the parallel run did more work).",
        "",
    ]
    if args.report:
        os.makedirs(os.path.dirname(args.report), exist_ok=True)
        with open(args.report, "w") as handle:
            handle.write("\n".join(lines))
        print(f"wrote {args.report}")


if __name__ == "__main__":
    main()
