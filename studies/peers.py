"""Peer comparison: the same discrete surface and load solved by roughpetsc, Tamaas and ContactMechanics.

    bash studies/peers/install.sh            # once: the peers' own virtualenv .peers-venv
    .venv/bin/python studies/peers.py [--sizes 256 512 1024] [--pstar 0.5] \
        [--ours pk_pc=none,pk_active_set=pk default] [--tolerances 1e-8 1e-9] [--repeats 3]

For each N: the group-1 surface (k_l, k_s, H, m2) = (16, 64, 0.8, 2e-4), seed 1, unit cell, E* = 1, is
saved as .npy; the load is pbar = p* sqrt(m0^p) (from our ContactProblem). Each of our option sets
(``name=value[,name=value]``, PETSc options without the dash; ``default`` for none) solves it under load
control to a natural KKT residual <= --target. Each peer runs in .peers-venv
(``studies/peers/run_peer.py``, one process, one thread) and its pressure field is judged by OUR operator:
g = K p + d - h with d giving zero mean gap on the contact set (as Polonsky-Keer does), natural residual
||min(p / pbar, g / sqrt(m0^h))||_inf. A peer's tolerance is the loosest of the decade scan
1e-4 ... 1e-14 whose field reaches --target; that run and --repeats - 1 more are timed (solve only,
minimum reported). A* (node count) and gbar (mean gap over all nodes, zero in contact) of every field
are computed by the same code, relative differences against our first option set.

Writes studies/output/peers.md, peers.json and peers.png. Wall times on a shared machine are noisy:
the ratios are what matters, and the lead reruns the final table on a quiet machine.
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "FFTW_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import petsc4py  # noqa: E402

petsc4py.init([sys.argv[0]])
import numpy as np  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from roughpetsc import ContactProblem, Grid, Solver, fractal, fractal_group  # noqa: E402
from roughpetsc.contact.result import measure  # noqa: E402
from roughpetsc.contact.certificate import report  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PEER_PYTHON = os.path.join(ROOT, ".peers-venv", "bin", "python")
RUN_PEER = os.path.join(ROOT, "studies", "peers", "run_peer.py")
OUTPUT = os.path.join(ROOT, "studies", "output")
PEERS = ("tamaas", "contactmechanics")
PEER_NAMES = {"tamaas": "Tamaas PolonskyKeerRey", "contactmechanics": "ContactMechanics CCG"}
# Group #1 of Table 7.1 as options/group01.opts types it (its grid, N = 1024, is not used here).
SURFACE = {key: value for key, value in fractal_group(1).items() if key in ("k_l", "k_s", "hurst", "m2")}


def parse_option_set(text):
    """``"pk_pc=fourier,pk_refresh=50"`` -> [("pk_pc", "fourier"), ("pk_refresh", "50")]; ``default`` -> []."""
    text = text.strip()
    if text in ("", "default", "none"):
        return []
    pairs = []
    for item in text.replace(" ", ",").split(","):
        if not item:
            continue
        name, _, value = item.lstrip("-").partition("=")
        pairs.append((name, value))
    return pairs


def label_of(pairs):
    return "roughpetsc PK" + ("" if not pairs else " [" + " ".join(f"-{k} {v}" for k, v in pairs) + "]")


class Evaluator:
    """Judges a pressure field (pressure units) with our operator on our scaled problem."""

    def __init__(self, problem, pbar_scaled):
        self.problem = problem
        self.target = pbar_scaled
        self.pressure = problem.vec()
        self.work = problem.vec()

    def __call__(self, pressure_field):
        problem = self.problem
        p = problem.local(self.pressure)
        p[...] = pressure_field[problem.local_rows] / problem.pressure_scale
        problem.operator.displacement(self.pressure, self.work)
        gap = problem.local(self.work) - problem.local(problem.heights, readonly=True)
        separation = problem.contact_separation(self.pressure, gap)
        gap += separation
        p = problem.local(self.pressure, readonly=True)
        kkt = report(problem.mpi, p, gap, problem.n, self.target)
        m = measure(problem, p, gap)
        return {
            "natural": kkt.natural, "load_error": kkt.load_error, "min_p": kkt.min_p, "min_g": kkt.min_g,
            "complementarity": kkt.complementarity,
            "A": m["A"], "gbar": m["gbar"] * problem.height_scale,
            "separation": separation * problem.height_scale, "n_contact": int(round(m["A"] * problem.n)),
        }

    def destroy(self):
        self.pressure.destroy()
        self.work.destroy()


def run_ours(grid, heights, pairs, pstar, rtol, repeats):
    """Solve with one option set ``repeats`` times from a cold start; the fastest run's numbers."""
    problem = ContactProblem(grid, heights, 1.0, PETSc.COMM_SELF)
    best, field = None, None
    try:
        for _ in range(repeats):
            solver = Solver(problem, "load", rtol=rtol, options=dict(pairs))
            try:
                cpu = time.process_time()
                result = solver.solve(pstar=pstar)
                result.cpu_s = time.process_time() - cpu
                if best is None or result.time_s < best.time_s:
                    best = result
                    field = np.array(solver.fields()[0])
            finally:
                solver.destroy()
    finally:
        problem.destroy()
    return best, field


def run_peer(peer, surface_path, pbar, tol, workdir, timeout, hardness=None, adhesion=None):
    """Solve with ``peer`` in its own virtualenv: (its JSON summary, its pressure field).

    ``adhesion``: ``(law, work, range)`` for Tamaas' adhesive gap solve (run_peer.py --adhesion); ``pbar`` is
    then the prescribed mean gap and the summary gains the gap field under ``"gap"``.
    """
    prefix = os.path.join(workdir, f"{peer}_{tol:.0e}")
    env = dict(os.environ)
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "FFTW_NUM_THREADS"):
        env[name] = "1"
    env.pop("PYTHONPATH", None)
    command = [PEER_PYTHON, RUN_PEER, surface_path, "1.0", repr(pbar), peer, repr(tol), prefix]
    if hardness is not None:
        command += ["--hardness", repr(hardness)]
    if adhesion is not None:
        law, work, range_ = adhesion
        command += ["--adhesion", law, "--work", repr(work), "--range", repr(range_)]
    completed = subprocess.run(command, cwd=workdir, env=env, capture_output=True, text=True, timeout=timeout)
    if completed.returncode != 0:
        raise RuntimeError(f"{peer} at tol {tol:g} failed:\n{completed.stderr[-3000:]}")
    with open(prefix + ".json") as f:
        info = json.load(f)
    field = np.load(prefix + ".npy")
    os.remove(prefix + ".npy")
    if adhesion is not None:
        info["gap"] = np.load(prefix + ".gap.npy")
        os.remove(prefix + ".gap.npy")
    return info, field


def scan_peer(peer, surface_path, pbar, evaluate, target, tolerances, repeats, workdir, timeout, log):
    """Loosest decade tolerance whose field reaches ``target`` under our evaluation; then time it."""
    scan = []
    chosen = None
    for tol in tolerances:
        info, field = run_peer(peer, surface_path, pbar, tol, workdir, timeout)
        judged = evaluate(field)
        scan.append({"tolerance": tol, "iterations": info["iterations"], "solve_s": info["solve_s"],
                     "natural": judged["natural"], "A": judged["A"], "gbar": judged["gbar"],
                     "peer_converged": info["converged"]})
        log(f"    {peer:16s} tol {tol:.0e}: {info['iterations']} it, {info['solve_s']:.3f} s, "
            f"natural {judged['natural']:.2e}")
        if judged["natural"] <= target:
            chosen = (tol, info, field, judged)
            break
    if chosen is None:
        return {"peer": peer, "tolerance": None, "scan": scan, "reached": False}
    tol, info, field, judged = chosen
    times, cpus = [info["solve_s"]], [info["cpu_s"]]
    for _ in range(repeats - 1):
        again, _field = run_peer(peer, surface_path, pbar, tol, workdir, timeout)
        times.append(again["solve_s"])
        cpus.append(again["cpu_s"])
    return {"peer": peer, "tolerance": tol, "scan": scan, "reached": True, "info": info, "judged": judged,
            "times": times, "time_s": min(times), "cpu_s": min(cpus), "field": field}


def relative(a, b):
    return abs(a - b) / abs(b) if b else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024])
    parser.add_argument("--pstar", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--ours", nargs="+", default=["pk_pc=none,pk_active_set=pk", "default"],
                        help="our option sets, e.g. pk_pc=none pk_pc=fourier,pk_refresh=50 (default: the published "
                             "PK and our default solver)")
    parser.add_argument("--peers", nargs="+", default=list(PEERS), choices=PEERS)
    parser.add_argument("--target", type=float, default=1e-8, help="natural KKT residual to reach (default 1e-8)")
    parser.add_argument("--tolerances", type=float, nargs="+",
                        default=[10.0 ** -e for e in range(4, 15)], help="the peers' tolerance scan, loose first")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per solver (minimum reported)")
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds per peer run")
    parser.add_argument("--output", default=os.path.join(OUTPUT, "peers"),
                        help="output prefix (.md, .json, .png); default studies/output/peers")
    parser.add_argument("--no-plot", action="store_true")
    args = parser.parse_args()
    if not os.path.exists(PEER_PYTHON):
        sys.exit(f"{PEER_PYTHON} is missing: run `bash studies/peers/install.sh` first")

    def log(message):
        print(message, flush=True)

    option_sets = [parse_option_set(text) for text in args.ours]
    workdir = tempfile.mkdtemp(prefix="roughpetsc-peers-")
    record = {
        "surface": dict(SURFACE, seed=args.seed, cell=1.0, E_star=1.0), "pstar": args.pstar,
        "target": args.target, "tolerances": args.tolerances, "repeats": args.repeats, "host": platform.node(),
        "cpus": os.cpu_count(),
        "loadavg_start": os.getloadavg(), "started": time.strftime("%Y-%m-%d %H:%M:%S"), "sizes": [],
    }
    try:
        for n in args.sizes:
            grid = Grid(n, n, 1.0, 1.0)
            heights = fractal(grid, SURFACE["k_l"], SURFACE["k_s"], SURFACE["hurst"], SURFACE["m2"], args.seed)
            surface_path = os.path.join(workdir, f"surface_{n}.npy")
            np.save(surface_path, heights)
            problem = ContactProblem(grid, heights, 1.0, PETSc.COMM_SELF)
            pbar = args.pstar * problem.sqrt_m0p
            evaluate = Evaluator(problem, problem.scaled_pbar(pstar=args.pstar))
            log(f"N={n}: pbar={pbar:.6e} (p*={args.pstar}), sqrt(m0h)={problem.sqrt_m0h:.6e}")
            rows = []
            for pairs in option_sets:
                result, field = run_ours(grid, heights, pairs, args.pstar, args.target, args.repeats)
                judged = evaluate(field)
                rows.append({
                    "solver": label_of(pairs), "kind": "ours", "options": dict(pairs), "tolerance": args.target,
                    "iterations": result.iterations, "operator_applications": result.operator_applications,
                    "A": result.A, "gbar": result.gbar, "natural": judged["natural"],
                    "natural_own": result.kkt.natural, "time_s": result.time_s, "cpu_s": result.cpu_s,
                    "reason": result.reason,
                    "converged": result.converged, "A_eval": judged["A"], "gbar_eval": judged["gbar"],
                })
                log(f"    {label_of(pairs)}: {result.iterations} it, {result.time_s:.3f} s, "
                    f"natural {judged['natural']:.2e}, A*={result.A:.8f}, gbar={result.gbar:.10e}")
            for peer in args.peers:
                out = scan_peer(peer, surface_path, pbar, evaluate, args.target, args.tolerances, args.repeats,
                                workdir, args.timeout, log)
                row = {"solver": PEER_NAMES[peer], "kind": "peer", "peer": peer, "tolerance": out["tolerance"],
                       "scan": out["scan"], "reached": out["reached"]}
                if out["reached"]:
                    info, judged = out["info"], out["judged"]
                    row.update({"iterations": info["iterations"], "A": judged["A"], "gbar": judged["gbar"],
                                "natural": judged["natural"], "time_s": out["time_s"], "times": out["times"],
                                "cpu_s": out["cpu_s"],
                                "setup_s": info["setup_s"], "version": info["version"],
                                "settings": info["settings"], "peer_error": info["peer_error"],
                                "load_error": judged["load_error"]})
                rows.append(row)
            evaluate.destroy()
            problem.destroy()
            reference = rows[0]
            ours = [r for r in rows if r["kind"] == "ours" and r["converged"]]
            peers = [r for r in rows if r["kind"] == "peer" and r["reached"]]
            fastest_ours = min(ours, key=lambda r: r["time_s"]) if ours else None
            faster_peer = min(peers, key=lambda r: r["time_s"]) if peers else None
            for r in rows:
                if "A" in r:
                    r["rel_A"] = relative(r["A"], reference["A"])
                    r["rel_gbar"] = relative(r["gbar"], reference["gbar"])
                if faster_peer and "time_s" in r:
                    r["ratio_to_faster_peer"] = r["time_s"] / faster_peer["time_s"]
                    r["cpu_ratio_to_faster_peer"] = r["cpu_s"] / faster_peer["cpu_s"]
            record["sizes"].append({
                "n": n, "pbar": pbar, "sqrt_m0h": float(np.sqrt(np.mean(heights ** 2))), "rows": rows,
                "fastest_ours": fastest_ours["solver"] if fastest_ours else None,
                "faster_peer": faster_peer["solver"] if faster_peer else None,
                "ratio": fastest_ours["time_s"] / faster_peer["time_s"] if fastest_ours and faster_peer else None,
                "cpu_ratio": fastest_ours["cpu_s"] / faster_peer["cpu_s"] if fastest_ours and faster_peer else None,
            })
            write_outputs(record, args)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    record["loadavg_end"] = os.getloadavg()
    write_outputs(record, args)
    print(open(args.output + ".md").read())


def fmt(value, spec):
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) else format(value, spec)


def table_lines(record):
    lines = ["| N | solver | tolerance | iterations | A* | gbar | natural KKT (ours on its field) | wall s | "
             "wall / faster peer | CPU s | CPU / faster peer | rel. diff A* | rel. diff gbar |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for size in record["sizes"]:
        for r in size["rows"]:
            if r["kind"] == "peer" and not r["reached"]:
                lines.append(f"| {size['n']} | {r['solver']} | none of the scan reached the target | | | | "
                             f"{min(s['natural'] for s in r['scan']):.1e} | | | | | | |")
                continue
            tol = fmt(r["tolerance"], ".0e")
            if r["kind"] == "ours":
                tol = f"natural {tol}"
            lines.append(
                f"| {size['n']} | {r['solver']} | {tol} | {r['iterations']} | {r['A']:.8f} | {r['gbar']:.10e} | "
                f"{r['natural']:.2e} | {r['time_s']:.3f} | {fmt(r.get('ratio_to_faster_peer'), '.3f')} | "
                f"{r['cpu_s']:.3f} | {fmt(r.get('cpu_ratio_to_faster_peer'), '.3f')} | "
                f"{fmt(r.get('rel_A'), '.1e')} | {fmt(r.get('rel_gbar'), '.1e')} |")
    return lines


def write_outputs(record, args):
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    public = json.loads(json.dumps(record, default=lambda o: None if isinstance(o, np.ndarray) else float(o)))
    for size in public["sizes"]:
        for r in size["rows"]:
            r.pop("field", None)
    tmp = args.output + ".json.tmp"
    with open(tmp, "w") as f:
        json.dump(public, f, indent=1)
    os.replace(tmp, args.output + ".json")
    versions = {}
    for size in record["sizes"]:
        for r in size["rows"]:
            if r.get("version"):
                versions[r["solver"]] = r["version"]
    s = record["surface"]
    lines = [
        "# Peer comparison: roughpetsc vs Tamaas and ContactMechanics",
        "",
        f"Generated by `studies/peers.py` (started {record['started']}, host {record['host']}, "
        f"{record['cpus']} CPUs, load average at start {record['loadavg_start'][0]:.2f}"
        + (f", at end {record['loadavg_end'][0]:.2f}" if "loadavg_end" in record else "") + ").",
        "",
        f"Surface: group 1, (k_l, k_s, H, m2) = ({s['k_l']}, {s['k_s']}, {s['hurst']}, {s['m2']}), seed "
        f"{s['seed']}, unit cell, E* = 1; load p* = {record['pstar']} (pbar = p* sqrt(m0^p)), load control. "
        "Every solver uses the same periodic Westergaard kernel 1/(pi E* |k|) with no k = 0 displacement "
        "(checked mode by mode: `run_peer.py --check-kernels`). One process and one thread each "
        "(OMP_NUM_THREADS=1).",
        "",
        f"Target: natural KKT residual ||min(p/pbar, g/sqrt(m0^h))||_inf <= {record['target']:g}, evaluated by "
        "OUR operator on every solver's pressure field (g = K p + d - h, d from a zero mean gap on the contact "
        f"set). A peer's tolerance is the loosest of the scan {' '.join(f'{t:g}' for t in record['tolerances'])} "
        "that reaches the target "
        "(Tamaas: PKR's own error; ContactMechanics: pentol = tol rms(h), forcetol = tol x mean nodal force, "
        "thermotol = tol). A* by node count, gbar = mean gap over all nodes. Relative differences against "
        f"the first of our rows. Wall time: the solve only, minimum of {record['repeats']} runs; CPU: the "
        "process CPU time of the same span (minimum), steadier than wall time on a loaded machine. The faster "
        "peer is the one with the smaller wall time.",
        "",
        "**Measured on a shared, noisy 2-core machine: the wall times and ratios are indicative only; the "
        "acceptance figures come from the lead's rerun on a quiet machine.**",
        "",
    ]
    lines += table_lines(record)
    lines += ["", "Wall-time ratio of our fastest configuration to the faster peer (CPU-time ratio):", ""]
    for size in record["sizes"]:
        lines.append(f"- N = {size['n']}: {size['fastest_ours']} / {size['faster_peer']} = "
                     f"{fmt(size['ratio'], '.3f')} ({fmt(size.get('cpu_ratio'), '.3f')})")
    lines += ["", "Peer tolerance scans (tolerance: iterations, natural residual by our operator):", ""]
    for size in record["sizes"]:
        for r in size["rows"]:
            if r["kind"] == "peer":
                scan = ", ".join(f"{x['tolerance']:.0e}: {x['iterations']} it, {x['natural']:.1e}"
                                 for x in r["scan"])
                lines.append(f"- N = {size['n']}, {r['solver']}: {scan}")
    if versions:
        lines += ["", "Versions: " + ", ".join(f"{k} {v}" for k, v in versions.items())
                  + f"; roughpetsc on PETSc {'.'.join(map(str, PETSc.Sys.getVersion()))}."]
    lines += ["", "Regenerate: `bash studies/peers/install.sh && .venv/bin/python studies/peers.py "
              + " ".join(["--sizes"] + [str(x["n"]) for x in record["sizes"]])
              + " --tolerances " + " ".join(f"{t:g}" for t in record["tolerances"])
              + f" --repeats {record['repeats']}`", ""]
    tmp = args.output + ".md.tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines))
    os.replace(tmp, args.output + ".md")
    if not args.no_plot and record["sizes"]:
        plot(record, args.output + ".png")


def plot(record, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    series = {}
    for size in record["sizes"]:
        for r in size["rows"]:
            if "time_s" in r:
                series.setdefault(r["solver"], ([], [], []))
                series[r["solver"]][0].append(size["n"])
                series[r["solver"]][1].append(r["time_s"])
                series[r["solver"]][2].append(r["iterations"])
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for name, (ns, ts, its) in series.items():
        style = "o-" if name.startswith("roughpetsc") else "s--"
        axes[0].loglog(ns, ts, style, label=name)
        axes[1].loglog(ns, its, style, label=name)
    axes[0].set_xlabel("N")
    axes[0].set_ylabel("wall time of the solve [s]")
    axes[1].set_xlabel("N")
    axes[1].set_ylabel("iterations")
    sizes = [size["n"] for size in record["sizes"]]
    for ax in axes:
        ax.set_xscale("log", base=2)
        ax.set_xticks(sizes, [str(n) for n in sizes])
        ax.minorticks_off()
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"Natural KKT residual <= {record['target']:g}, p* = {record['pstar']} (shared machine)")
    fig.tight_layout()
    fig.savefig(path + ".tmp.png", dpi=110)
    plt.close(fig)
    os.replace(path + ".tmp.png", path)


if __name__ == "__main__":
    main()
