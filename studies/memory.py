"""Peak resident memory of a whole run per grid point (target: <= 40 doubles per grid point per rank).

    .venv/bin/python studies/memory.py [--sizes 1024,2048,4096] [--ranks2 2048] [--stages 2048:1,2048:2]

Part 1: the peak resident set size ("Maximum resident set size" of /usr/bin/time, per MPI rank) of
``python -m roughpetsc -surface_N N -pstar 0.5 -tao_max_it 50 -quiet`` (group #1 surface, Polonsky-Keer), for
each N, against the same run at N = 32 (the interpreter + PETSc/MPI/FFTW/numpy/scipy/h5py footprint). The
iterations are capped at 50 because the memory of a solve does not depend on how many iterations it makes (every
array is allocated before the first one); the capped runs therefore exit with status 3 (not converged), which
is expected here. Bytes and doubles per grid point (per rank: N^2 / ranks points) are given in total and above
the baseline. One row adds ``-json -output`` (the HDF5 file with heights, pressure and gap).

Part 2: where the memory goes, stage by stage, in one process that repeats the command line's steps
(surface, operator + problem, statistics, solver, solve, fields, HDF5): the peak of each stage above the
resident memory before it (the kernel's peak counter is reset between stages through /proc/self/clear_refs)
and what the stage keeps, in doubles per grid point. Writes studies/output/memory.md.
"""

import argparse
import datetime
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_rmaps_base_oversubscribe": "1", "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}
LIMIT = 40
BASE_ARGS = ["-pstar", "0.5", "-tao_max_it", "50", "-quiet"]


def environment():
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    return env


def peak_rss(N, ranks=1, extra=()):
    """Peak RSS in bytes of each rank of one command-line run, and its exit status and wall time."""
    timed = ["/usr/bin/time", "-f", "maxrss_kb=%M wall_s=%e", sys.executable, "-m", "roughpetsc",
             "-surface_N", str(N), *BASE_ARGS, *extra]
    command = ["mpiexec", "-n", str(ranks), "--oversubscribe", *timed] if ranks > 1 else timed
    out = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, env=environment())
    found = re.findall(r"maxrss_kb=(\d+) wall_s=([\d.]+)", out.stderr)
    if len(found) != ranks:
        raise RuntimeError(f"no memory report from {' '.join(command)}:\n{out.stderr}")
    return [int(kb) * 1024 for kb, _ in found], out.returncode, max(float(w) for _, w in found)


# ---------------------------------------------------------------------------------------------------------
# Part 2: stages in one process
# ---------------------------------------------------------------------------------------------------------

def _status():
    values = {}
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(("VmHWM", "VmRSS")):
                key, value = line.split(":")
                values[key] = int(value.split()[0]) * 1024
    return values["VmRSS"], values["VmHWM"]


def _reset_peak():
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")


def stages(N, folder):
    """Run the command line's steps at N (every rank builds the whole surface, as the command line does);
    rank 0 prints one line per stage (bytes)."""
    import tracemalloc

    import petsc4py

    petsc4py.init([sys.argv[0], "-tao_max_it", "50"])
    tracemalloc.start()
    from petsc4py import PETSc

    from roughpetsc import ContactProblem, Grid, Solver, fractal, fractal_group
    from roughpetsc.surface import moments as surface_moments
    from roughpetsc.parallel import gather_rows
    from roughpetsc.store import path_file as load_path
    from roughpetsc.surface.files import validate

    comm = PETSc.COMM_WORLD.tompi4py()
    grid = Grid(N, N, 1.0, 1.0)
    group = fractal_group(1)
    state = {}
    rows = []

    def stage(name, action):
        before, _ = _status()
        live_before = tracemalloc.get_traced_memory()[0]
        _reset_peak()
        tracemalloc.reset_peak()
        action()
        after, peak = _status()
        live_after, live_peak = tracemalloc.get_traced_memory()
        rows.append((name, before, peak, after, live_before, live_peak, live_after))

    def surface():
        state["heights"] = validate(fractal(grid, group["k_l"], group["k_s"], group["hurst"], group["m2"], 1))

    def problem():
        state["problem"] = ContactProblem(grid, state["heights"], 1.0, PETSc.COMM_WORLD, 1, "FFTW_MEASURE")

    def statistics():
        state["statistics"] = surface_moments(grid, state["heights"], 1.0)

    def solver():
        state["solver"] = Solver(state["problem"], "load", None, 1e-8)

    def solve():
        state["result"] = state["solver"].solve(pstar=0.5)

    def fields():
        pressure, gap = state["solver"].fields()
        state["fields"] = (gather_rows(comm, pressure), gather_rows(comm, gap))

    def hdf5():
        if comm.Get_rank():
            return
        summary = {"grid": [N, N], "steps": [state["result"].summary()]}
        pressure, gap = state["fields"]
        load_path.write(os.path.join(folder, "stages.h5"), summary,
                        {"heights": state["heights"], "pressure": pressure, "gap": gap}, {0: state["result"].history})

    for name, action in (("surface: fractal + validate (surfaces.from_options)", surface),
                         ("ContactProblem (Westergaard plans, symbols, heights, p_c)", problem),
                         ("surface statistics (surface_moments.surface_moments)", statistics),
                         ("Solver (PK work vectors)", solver),
                         ("solve, 50 PK iterations", solve),
                         ("fields + gather (solve_mode.solve_path)", fields),
                         ("HDF5 file (-output)", hdf5)):
        stage(name, action)
    if comm.Get_rank() == 0:
        for row in rows:
            print("STAGE|" + "|".join(str(v) for v in row), flush=True)
    state["solver"].destroy()
    state["problem"].destroy()


def stage_rows(N, ranks=1):
    """Stage rows of rank 0 (the rank that also gathers the fields and writes the file)."""
    with tempfile.TemporaryDirectory() as folder:
        command = [sys.executable, os.path.abspath(__file__), "--run-stages", str(N), "--folder", folder]
        if ranks > 1:
            command = ["mpiexec", "-n", str(ranks), "--oversubscribe", *command]
        out = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, env=environment())
    rows = [line.split("|")[1:] for line in out.stdout.splitlines() if line.startswith("STAGE|")]
    if not rows:
        raise RuntimeError(out.stdout + out.stderr)
    return [(row[0], *map(int, row[1:])) for row in rows]


MMAP_PROBE = """
import ctypes, sys
import numpy as np
libc = ctypes.CDLL("libc.so.6")
class Info(ctypes.Structure):
    _fields_ = [(n, ctypes.c_size_t) for n in "arena ordblks smblks hblks hblkhd usmblks fsmblks uordblks fordblks keepcost".split()]
libc.mallinfo2.restype = Info
def mapped(size):
    a = np.ones(size)
    return libc.mallinfo2().hblkhd >= a.nbytes
before = mapped(1 << 22)
import petsc4py
petsc4py.init([sys.argv[0]])
from petsc4py import PETSc
print(int(before), int(mapped(1 << 22)))
"""


def mmap_probe():
    """Whether glibc serves a 32 MiB array by mmap before and after loading PETSc (which frees it back to the OS)."""
    out = subprocess.run([sys.executable, "-c", MMAP_PROBE], capture_output=True, text=True, env=environment())
    before, after = (bool(int(v)) for v in out.stdout.split())
    return before, after


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1024,2048,4096")
    parser.add_argument("--ranks2", default="2048", help="sizes also run on 2 ranks ('' for none)")
    parser.add_argument("--stages", default="2048:1,2048:2", help="N:ranks of the stage breakdowns ('' for none)")
    parser.add_argument("--run-stages", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--folder", default="", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.run_stages:
        stages(args.run_stages, args.folder)
        return 0

    MiB = 1024.0 ** 2
    runs = [(N, 1, ()) for N in map(int, args.sizes.split(","))]
    runs += [(N, 2, ()) for N in map(int, filter(None, args.ranks2.split(",")))]
    with tempfile.TemporaryDirectory() as folder:
        if 2048 in [N for N, _, _ in runs]:
            runs.insert(2, (2048, 1, ("-json", os.path.join(folder, "m.json"), "-output", os.path.join(folder, "m.h5"))))
        baselines = {}
        lines = ["| N | ranks | outputs | exit | peak RSS per rank [MiB] | baseline (N=32) [MiB] | "
                 "doubles/point/rank, total | doubles/point/rank, above baseline | <= 40? | wall s |",
                 "|---|---|---|---|---|---|---|---|---|---|"]
        worst = 0.0
        for N, ranks, extra in runs:
            if ranks not in baselines:
                # The default surface's k_s = 64 is beyond the Nyquist wavenumber of 32^2: a smaller band.
                rss, code, _ = peak_rss(32, ranks, ("-surface_kl", "2", "-surface_ks", "8"))
                if code not in (0, 3):
                    raise RuntimeError(f"the N=32 baseline run failed (exit {code})")
                baselines[ranks] = max(rss)
                print(f"baseline N=32 on {ranks} rank(s): {baselines[ranks] / MiB:.1f} MiB", flush=True)
            rss, code, wall = peak_rss(N, ranks, extra)
            peak = max(rss)
            points = N * N / ranks
            total = peak / (8.0 * points)
            above = (peak - baselines[ranks]) / (8.0 * points)
            worst = max(worst, total)
            line = (f"| {N} | {ranks} | {'-json -output' if extra else 'none'} | {code} | {peak / MiB:.1f} | "
                    f"{baselines[ranks] / MiB:.1f} | {total:.1f} | {above:.1f} | "
                    f"{'yes' if total <= LIMIT else 'NO'} | {wall:.1f} |")
            lines.append(line)
            print(line, flush=True)
    stage_lines = []
    for spec in filter(None, args.stages.split(",")):
        N, ranks = map(int, spec.split(":"))
        unit = 8.0 * N * N / ranks
        stage_lines += [
            f"Stage breakdown at N = {N} on {ranks} rank(s) (rank 0), in doubles per grid point per rank "
            f"(N^2/{ranks} points). RSS: resident memory before the stage, "
            "the stage's peak above it and what stays resident after it (once PETSc is loaded glibc no longer "
            "uses mmap, see the notes, so freed temporaries stay resident and 'RSS kept' includes them). Live arrays: numpy/Python allocations traced by tracemalloc (PETSc Vecs on one "
            "rank are numpy arrays from pyFFTW; FFTW's own plan buffers are not traced): live before, the stage's "
            "peak above that, and what the stage keeps.", "",
            "| stage | RSS before | RSS peak above | RSS kept | live before | live peak above | live kept |",
            "|---|---|---|---|---|---|---|"]
        for name, before, peak, after, lb, lp, la in stage_rows(N, ranks):
            stage_lines.append(f"| {name} | {before / unit:.1f} | {(peak - before) / unit:+.1f} | "
                               f"{(after - before) / unit:+.1f} | {lb / unit:.1f} | {(lp - lb) / unit:+.1f} | "
                               f"{(la - lb) / unit:+.1f} |")
            print(stage_lines[-1], flush=True)
        stage_lines.append("")
    before, after = mmap_probe()
    notes = [
        "Notes:",
        "",
        f"- glibc serves a 32 MiB numpy array by mmap before PETSc is loaded: {'yes' if before else 'no'}; after "
        f"`petsc4py.init()`/`from petsc4py import PETSc`: {'yes' if after else 'no'}. "
        + ("" if after else "Loading PETSc loads libsuperlu_dist.so.8, whose static initialiser calls "
           "mallopt(M_MMAP_MAX, 0) (found with objdump): from then on every array comes from the brk heap and "
           "freed temporaries stay resident (reused, but not returned to the OS). Restoring the default with "
           "`ctypes.CDLL('libc.so.6').mallopt(-4, 65536)` after that library is loaded lowered the peaks by only "
           "1-4 % here (the peak is set by arrays that are live together, not by retention)."),
        "- Live N^2-sized arrays at the peak (1 = one double per point per rank): the surface heights whole on "
        "every rank (solve_mode.solve_path: 1 on one rank, R on R ranks); ContactProblem: heights and p_c Vecs (2), the "
        "FFT real and complex buffers (2), the compliance, stiffness and preconditioner symbols stored as "
        "repeated real pairs (3), plus the exchange buffers of the slab transform on more than one rank; "
        "Solver: pressure and gap (2; the predictor's previous solution only on load paths), 6 Polonsky-Keer "
        "work Vecs and 2 of the Fourier preconditioner (8); kkt.report: 3 temporaries per call (p/pbar, minimum, "
        "abs); at the end Solver.fields() makes 2 scaled copies, gathered whole on rank 0 only for -output.",
        "",
    ]
    text = "\n".join([
        "# Peak resident memory per grid point (target: <= 40 doubles per grid point per rank)",
        "",
        f"Generated {datetime.datetime.now().isoformat(timespec='seconds')} by `.venv/bin/python studies/memory.py"
        + "".join(f" {a}" for a in sys.argv[1:]) + f"` on {os.uname().nodename}.",
        "",
        "Command: `[mpiexec -n R] /usr/bin/time -f %M python -m roughpetsc -surface_N N -pstar 0.5 -tao_max_it 50 "
        "-quiet` (group #1 surface, Polonsky-Keer, one FFTW plan on one rank, the slab transform of "
        "roughpetsc.slab on two). The peak is the largest \"Maximum resident set size\" over the ranks; a double "
        "per point is 8 N^2 / R bytes. "
        "Iterations are capped at 50 (exit status 3 when that stops the solve): every array of the solve exists "
        "from its first iteration, so the peak does not depend on the iteration count. The baseline is the same "
        "command at N = 32 (with k_l = 2, k_s = 8, below its Nyquist wavenumber) on the same number of ranks "
        "(interpreter, PETSc, MPI, FFTW, numpy, scipy, h5py).",
        "",
        *lines,
        "",
        f"Largest total: {worst:.1f} doubles per grid point per rank ({'within' if worst <= LIMIT else 'ABOVE'} "
        f"the limit of {LIMIT}).",
        "",
        *stage_lines,
        *notes,
    ])
    os.makedirs(os.path.join(ROOT, "studies", "output"), exist_ok=True)
    with open(os.path.join(ROOT, "studies", "output", "memory.md"), "w") as f:
        f.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
