"""MPI speed-up of one solve against the speed-up of the bare distributed FFT pair (issue 5).

    .venv/bin/python studies/mpi_speedup.py [--n 2048] [--pair-sizes 1024,2048] [--rounds 3]
                                            [--solve-rounds 3] [--no-solve] [--ranks 2]
                                            [--transforms current,mpi4py-fft] [--variants base|all|LIST]

One run launches ``mpiexec -n 1`` and ``mpiexec -n RANKS`` workers (this script with ``--worker``),
alternating the rank counts round after round because the machine is shared and noisy, and takes
medians (per worker: median over interleaved repeats; per configuration: median over rounds).

Pair workers (at each N of --pair-sizes), one r2c + c2r pair each, no symbol multiply:

- ``fftw2d``: the direct pyFFTW 2-D plan (FFTW_MEASURE, aligned), one rank only;
- ``mpi4py-fft``: the bare distributed pair, mpi4py-fft ``PFFT(grid=(-1,), backend='pyfftw',
  planner_effort='FFTW_MEASURE')`` -- the reference of the speed-up criterion;
- ``mpi4py-fft/fftw``, ``mpi4py-fft/collapse`` (``--variants all``: ``mpi4py-fft/patient``):
  mpi4py-fft's own options (its 2.0.4 has no ``communication=`` option, only Alltoallw); the
  ``fftw`` backend (mpi4py-fft's own FFTW wrapper) runs in a worker of its own because it crashes
  (SIGSEGV) in a process that also uses pyFFTW plans;
- ``slab/shared``, ``slab/alltoall``: :class:`roughpetsc.slab.SlabTransform` with its two exchanges;
- ``shell``: one MatMult of ``Westergaard(Grid(n, n), 1.0, COMM_WORLD).mat()`` as
  ``roughpetsc.westergaard`` is (1 rank: direct 2-D plan; several: :class:`roughpetsc.slab.SlabTransform`);
  ``shell/mpi4py-fft``: the same with the old multi-rank transform, :class:`PfftTransform` below
  (mpi4py-fft PFFT, which roughpetsc used before roughpetsc.slab), for comparison (its 1-rank time is
  ``shell``'s).

Solve workers: one cold load-controlled solve of the group-1 surface (N = --n, k_l = 16, k_s = 64,
H = 0.8, m2 = 2e-4, seed 1, E* = 1) at p* = 0.5 to a natural KKT residual of 1e-8 with the default
solver (``Solver(problem, "load", None, 1e-8)``), ``Result.time_s`` (the solve only, no set-up), with
the transform as it is (``current``) and with the old mpi4py-fft one (``mpi4py-fft``); the table names
the transform class each run used.

Prints and writes studies/output/mpi_speedup.md: pair times, speed-ups (1 rank / RANKS ranks; the
solve's 1-rank time always uses the direct 2-D plan), and the ratio
solve speed-up / bare-pair (mpi4py-fft) speed-up, which must be >= 0.9. The load average of the
machine is recorded around every worker.
"""

import argparse
import contextlib
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_rmaps_base_oversubscribe": "1", "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}
BASE_VARIANTS = ["fftw2d", "mpi4py-fft", "mpi4py-fft/fftw", "mpi4py-fft/collapse", "slab/shared",
                 "slab/alltoall", "shell", "shell/mpi4py-fft"]
ALL_VARIANTS = BASE_VARIANTS + ["mpi4py-fft/patient"]


# --------------------------------------------------------------------------- workers (under mpiexec)
class PfftTransform:
    """The 2-D real FFT pair over MPI ranks that roughpetsc used before its slab transform.

    mpi4py-fft's slab decomposition along axis 0 (``PFFT(grid=(-1,), backend='pyfftw')``), with the
    interface of :class:`roughpetsc.slab.SlabTransform` that :class:`roughpetsc.westergaard.Westergaard`
    uses (``local_rows``, ``spectral_slice``, ``filter``, ``destroy``).
    """

    def __init__(self, grid, comm, effort):
        from mpi4py_fft import PFFT, newDistArray

        self.fft = PFFT(comm, grid.shape, axes=(0, 1), dtype=float, grid=(-1,), backend="pyfftw",
                        planner_effort=effort)
        self.real = newDistArray(self.fft, False)
        self.spectrum = newDistArray(self.fft, True)
        self.local_rows = self.fft.local_slice(False)[0]
        self.spectral_slice = self.fft.local_slice(True)

    def filter(self, source, target, symbol):
        self.real[...] = source
        self.fft.forward(self.real, self.spectrum, normalize=False)
        self.spectrum.view("float64").__imul__(symbol)
        self.fft.backward(self.spectrum, self.real, normalize=False)
        target[...] = self.real

    def destroy(self):
        self.fft.destroy()


@contextlib.contextmanager
def _transform(name):
    """Within the block, Westergaard builds its multi-rank transform as ``name`` says (what-if runs).

    ``current``: as roughpetsc.westergaard is; ``mpi4py-fft``: :class:`PfftTransform`, swapped in for
    roughpetsc.slab.SlabTransform, which westergaard imports when it builds one.
    """
    from roughpetsc.fft import slab

    if name == "current":
        yield
        return
    if name != "mpi4py-fft":
        raise ValueError(f"unknown transform {name!r}")
    kept = slab.SlabTransform
    slab.SlabTransform = PfftTransform
    try:
        yield
    finally:
        slab.SlabTransform = kept


def _label(transform):
    exchange = getattr(transform, "exchange", None)
    return type(transform).__name__ + (f"({exchange})" if exchange else "")


class _Pair:
    """One variant: ``run()`` does one r2c + c2r pair; ``destroy()`` frees it."""

    def __init__(self, name, n, comm):
        import numpy as np
        import pyfftw
        from petsc4py import PETSc

        from roughpetsc import Grid

        rng = np.random.default_rng(comm.Get_rank())
        self._destroy = []
        self.label = None
        grid = Grid(n, n)
        if name == "fftw2d":
            real = pyfftw.empty_aligned((n, n), dtype="float64")
            spectrum = pyfftw.empty_aligned((n, n // 2 + 1), dtype="complex128")
            forward = pyfftw.FFTW(real, spectrum, axes=(0, 1), flags=("FFTW_MEASURE",))
            backward = pyfftw.FFTW(spectrum, real, axes=(0, 1), direction="FFTW_BACKWARD",
                                   flags=("FFTW_MEASURE", "FFTW_DESTROY_INPUT"))
            real[...] = rng.random((n, n))

            def run():
                forward.execute()
                backward.execute()
        elif name.startswith("mpi4py-fft"):
            from mpi4py_fft import PFFT, newDistArray

            options = {"backend": "pyfftw", "planner_effort": "FFTW_MEASURE"}
            if name == "mpi4py-fft/fftw":
                options["backend"] = "fftw"
            elif name == "mpi4py-fft/patient":
                options["planner_effort"] = "FFTW_PATIENT"
            elif name == "mpi4py-fft/collapse":
                options["collapse"] = True
            fft = PFFT(comm, (n, n), axes=(0, 1), dtype=float, grid=(-1,), **options)
            real, spectrum = newDistArray(fft, False), newDistArray(fft, True)
            real[...] = rng.random(real.shape)

            def run():
                fft.forward(real, spectrum, normalize=False)
                fft.backward(spectrum, real, normalize=False)
            self._destroy.append(fft.destroy)
        elif name.startswith("slab/"):
            from roughpetsc.fft.slab import SlabTransform

            transform = SlabTransform(grid, comm, "FFTW_MEASURE", name.split("/")[1])
            real = pyfftw.empty_aligned(transform.real.shape, dtype="float64")
            real[...] = rng.random(real.shape)

            def run():
                transform.forward(real)
                transform.backward(real)
            self._destroy.append(transform.destroy)
        elif name in ("shell", "shell/mpi4py-fft"):
            from roughpetsc.elastic import westergaard

            with _transform("current" if name == "shell" else "mpi4py-fft"):
                operator = westergaard.Westergaard(grid, 1.0, PETSc.COMM_WORLD)
            self.label = _label(operator.transform)
            mat = operator.mat()
            x, y = operator.vec(), operator.vec()
            x.setRandom()

            def run():
                mat.mult(x, y)
            self._destroy += [mat.destroy, x.destroy, y.destroy, operator.destroy]
        else:
            raise ValueError(name)
        self.run = run

    def destroy(self):
        for function in self._destroy:
            function()


def worker_pairs(n, variants, repeats):
    import numpy as np
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    size = comm.Get_size()
    variants = [v for v in variants if not (v == "fftw2d" and size > 1)
                and not (v == "shell/mpi4py-fft" and size == 1)]
    pairs = {}
    for name in variants:
        pairs[name] = _Pair(name, n, comm)
        pairs[name].run()
    times = {name: [] for name in pairs}
    cpu = {name: [] for name in pairs}
    for _ in range(repeats):  # interleaved: drift of the shared machine hits every variant alike
        for name, pair in pairs.items():
            comm.Barrier()
            start, start_cpu = MPI.Wtime(), time.process_time()
            pair.run()
            comm.Barrier()
            times[name].append(MPI.Wtime() - start)
            cpu[name].append(time.process_time() - start_cpu)
    out = {name: statistics.median(t) for name, t in times.items()}
    out["labels"] = {name: pair.label for name, pair in pairs.items() if pair.label}
    for name, t in cpu.items():  # the CPU time of the busiest rank: the wall time on an idle machine
        busiest = np.empty(len(t))
        comm.Allreduce(np.array(t), busiest, op=MPI.MAX)
        out["cpu:" + name] = float(np.median(busiest))
    for pair in pairs.values():
        pair.destroy()
    return out


def worker_solve(n, transform):
    from mpi4py import MPI
    from petsc4py import PETSc

    from roughpetsc import ContactProblem, Grid, Solver, fractal, fractal_group

    group = fractal_group(1)
    grid = Grid(n, n)
    heights = fractal(grid, group["k_l"], group["k_s"], group["hurst"], group["m2"], 1)
    with _transform(transform):
        problem = ContactProblem(grid, heights, 1.0, PETSc.COMM_WORLD)
    label = _label(problem.operator.transform)
    solver = Solver(problem, "load", None, 1e-8)
    try:
        start_cpu = time.process_time()
        result = solver.solve(pstar=0.5)
        cpu = problem.mpi.allreduce(time.process_time() - start_cpu, op=MPI.MAX)
    finally:
        solver.destroy()
        problem.destroy()
    return {"time_s": result.time_s, "cpu_s": cpu, "class": label, "iterations": result.iterations,
            "applications": result.operator_applications, "natural": result.kkt.natural,
            "converged": bool(result.converged), "A": result.A, "gstar": result.gstar, "solver": result.solver}


def worker(args):
    import petsc4py

    petsc4py.init([sys.argv[0]])
    from mpi4py import MPI

    try:
        if args.worker == "pairs":
            out = worker_pairs(args.n, args.variants.split(","), args.repeats)
        else:
            out = worker_solve(args.n, args.transform)
    except BaseException:
        import traceback

        traceback.print_exc()
        sys.stderr.flush()
        MPI.COMM_WORLD.Abort(1)  # never leave the other ranks waiting
    if MPI.COMM_WORLD.Get_rank() == 0:
        print("RESULT " + json.dumps(out), flush=True)


# --------------------------------------------------------------------------- driver
def worker_groups(variants):
    """Variants per worker process: mpi4py-fft's own FFTW backend crashes beside pyFFTW in one process."""
    names = BASE_VARIANTS if variants == "base" else ALL_VARIANTS if variants == "all" else variants.split(",")
    alone = [v for v in names if v == "mpi4py-fft/fftw"]
    return [g for g in ([v for v in names if v not in alone], alone) if g]


def launch(ranks, arguments):
    command = ["mpiexec", "-n", str(ranks), sys.executable, os.path.abspath(__file__), *arguments]
    env = dict(os.environ, **MPI_ENV, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    before = os.getloadavg()[0]
    done = subprocess.run(command, cwd=ROOT, env=env, capture_output=True, text=True, timeout=3600)
    after = os.getloadavg()[0]
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
    line = [x for x in done.stdout.splitlines() if x.startswith("RESULT ")][-1]
    return json.loads(line[len("RESULT "):]), (before + after) / 2


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2048, help="grid of the solve (and a pair size)")
    parser.add_argument("--pair-sizes", default="", help="pair grids, default 1024 and --n")
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--rounds", type=int, default=3, help="pair workers per rank count and size")
    parser.add_argument("--repeats", type=int, default=15, help="timed pairs per variant per worker")
    parser.add_argument("--solve-rounds", type=int, default=3, help="solves per rank count and transform")
    parser.add_argument("--transforms", default="current,mpi4py-fft",
                        help="multi-rank transforms of the solve: current (as westergaard is) and/or mpi4py-fft")
    parser.add_argument("--no-solve", action="store_true")
    parser.add_argument("--variants", default="base", help="base, all, or a comma list")
    parser.add_argument("--report", default=os.path.join(ROOT, "studies", "output", "mpi_speedup.md"))
    parser.add_argument("--worker", choices=["pairs", "solve"], help=argparse.SUPPRESS)
    parser.add_argument("--transform", default="current", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        if args.variants in ("base", "all"):
            args.variants = ",".join(BASE_VARIANTS if args.variants == "base" else ALL_VARIANTS)
        return worker(args)

    ranks = (1, args.ranks)
    sizes = [int(s) for s in args.pair_sizes.split(",")] if args.pair_sizes else sorted({1024, args.n})
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    loads = []
    labels = {}  # transform class of the shell variants on RANKS ranks
    pairs = {(n, r): [] for n in sizes for r in ranks}
    for k in range(args.rounds):
        for n in sizes:
            for r in (ranks if k % 2 == 0 else ranks[::-1]):
                out = {}
                for group in worker_groups(args.variants):
                    part, load = launch(r, ["--worker", "pairs", "--n", str(n), "--variants", ",".join(group),
                                            "--repeats", str(args.repeats)])
                    found = part.pop("labels")
                    if r > 1:
                        labels.update(found)
                    out.update(part)
                    loads.append(load)
                pairs[n, r].append(out)
                print(f"pairs N={n} ranks={r} (ms wall/CPU): "
                      + ", ".join(f"{v} {1e3 * t:.1f}/{1e3 * out['cpu:' + v]:.1f}"
                                  for v, t in out.items() if not v.startswith("cpu:"))
                      + f"  (load {load:.2f})", flush=True)
    pair = {key: {v: statistics.median([o[v] for o in outs]) for v in outs[0]} for key, outs in pairs.items()}

    solves = {}
    if not args.no_solve:
        configurations = [(1, "current")] + [(args.ranks, t) for t in args.transforms.split(",")]
        for k in range(args.solve_rounds):
            for r, transform in (configurations if k % 2 == 0 else configurations[::-1]):
                out, load = launch(r, ["--worker", "solve", "--n", str(args.n), "--transform", transform])
                loads.append(load)
                solves.setdefault((r, transform), []).append(out)
                print(f"solve N={args.n} ranks={r} transform={transform}: {out['time_s']:.2f} s, "
                      f"CPU {out['cpu_s']:.2f} s, {out['iterations']} its, {out['applications']} K, "
                      f"KKT {out['natural']:.1e}, A={out['A']:.6f}  (load {load:.2f})", flush=True)

    lines = report(args, sizes, ranks, pair, solves, loads, started, labels)
    print("\n".join(lines))
    os.makedirs(os.path.dirname(args.report), exist_ok=True)
    with open(args.report, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"written {args.report}")


def _pair_table(pair, sizes, ranks, prefix):
    one, many = ranks
    lines = ["| variant | " + " | ".join(f"N={n}, {r} rank{'s' * (r > 1)}" for n in sizes for r in ranks)
             + " | " + " | ".join(f"speed-up N={n}" for n in sizes) + " |",
             "|---" * (1 + len(sizes) * (len(ranks) + 1)) + "|"]
    variants = []
    for table in pair.values():
        variants += [v[len(prefix):] for v in table if v.startswith(prefix) and v[len(prefix):] not in variants
                     and (prefix or not v.startswith("cpu:"))]
    for v in variants:
        cells = [f"{1e3 * pair[n, r][prefix + v]:.1f}" if prefix + v in pair[n, r] else ""
                 for n in sizes for r in ranks]
        speed = []
        for n in sizes:
            serial = pair[n, one].get(prefix + (v if v != "shell/mpi4py-fft" else "shell"))
            parallel = pair[n, many].get(prefix + v)
            speed.append(f"{serial / parallel:.2f}" if serial and parallel else "")
        lines.append(f"| {v} | " + " | ".join(cells) + " | " + " | ".join(speed) + " |")
    return lines


def report(args, sizes, ranks, pair, solves, loads, started, labels):
    one, many = ranks
    lines = [f"# MPI speed-up on {many} ranks (`studies/mpi_speedup.py`)", "",
             f"Run {started}, {os.cpu_count()} cores, 1-minute load average around the workers "
             f"{min(loads):.1f} to {max(loads):.1f} (median {statistics.median(loads):.1f}; our own workers "
             "count 1 or 2 of it): a shared machine, medians of interleaved repeats "
             f"({args.repeats} pairs per variant per worker, median over {args.rounds} workers per cell).", "",
             "## One r2c + c2r pair: wall time (ms)", ""]
    lines += _pair_table(pair, sizes, ranks, "")
    lines += ["", "## The same pairs: CPU time of the busiest rank (ms)", "",
              "What the wall time would be on an otherwise idle machine (waiting in MPI spins, so it counts).", ""]
    lines += _pair_table(pair, sizes, ranks, "cpu:")
    lines += ["", "Speed-up = 1-rank time / %d-rank time of the same row; `shell` is one MatMult of the Westergaard "
              "shell Mat (1 rank: direct 2-D FFTW plan; %d ranks: %s), `shell/mpi4py-fft` the same with the old "
              "mpi4py-fft transform (its 1-rank time is `shell`'s). `slab/*` is roughpetsc.slab.SlabTransform "
              "with each exchange. The reference bare distributed pair is the `mpi4py-fft` row."
              % (many, many, labels.get("shell", "?"))]
    if solves:
        n = args.n
        lines += ["", f"## One load-controlled solve, N={n}, p*=0.5, natural KKT 1e-8 (default solver)", "",
                  "| ranks | transform | wall s per run | iterations | K applications | wall s (median) "
                  "| wall ms / K | CPU ms / K | speed-up wall | ratio wall | speed-up per K | ratio per K "
                  "| speed-up CPU per K | ratio CPU |", "|---" * 14 + "|"]
        bare = pair[n, one]["mpi4py-fft"] / pair[n, many]["mpi4py-fft"]
        bare_cpu = pair[n, one]["cpu:mpi4py-fft"] / pair[n, many]["cpu:mpi4py-fft"]

        def medians(outs):
            return (statistics.median(o["time_s"] for o in outs),
                    statistics.median(o["time_s"] / o["applications"] for o in outs),
                    statistics.median(o["cpu_s"] / o["applications"] for o in outs))

        serial, serial_k, serial_cpu_k = medians(solves[one, "current"])
        for (r, transform), outs in sorted(solves.items()):
            t, per_k, cpu_k = medians(outs)
            lines.append(f"| {r} | {transform} = {outs[-1]['class']} | "
                         + ", ".join(f"{o['time_s']:.1f}" for o in outs) + " | "
                         + ", ".join(str(o["iterations"]) for o in outs) + " | "
                         + ", ".join(str(o["applications"]) for o in outs)
                         + f" | {t:.2f} | {1e3 * per_k:.1f} | {1e3 * cpu_k:.1f} | {serial / t:.2f} | "
                         f"{serial / t / bare:.2f} | {serial_k / per_k:.2f} | {serial_k / per_k / bare:.2f} | "
                         f"{serial_cpu_k / cpu_k:.2f} | {serial_cpu_k / cpu_k / bare_cpu:.2f} |")
        finals = {round(o["A"], 10) for outs in solves.values() for o in outs}
        lines += ["", f"Bare distributed FFT pair (mpi4py-fft) speed-up at N={n}: {bare:.2f} wall, "
                  f"{bare_cpu:.2f} CPU. "
                  "ratio = solve speed-up / bare-pair speed-up; target: ratio wall >= 0.9. "
                  "'per K' divides each solve's time by its operator applications (the iteration count of "
                  "a solve can change from run to run: FFTW_MEASURE may pick other plans, hence other "
                  f"round-off, and the active set path follows it). A* of all runs: {sorted(finals)}."]
    return lines


if __name__ == "__main__":
    main()
