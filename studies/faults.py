"""Faults: an ensemble killed with SIGKILL at random moments resumes to the same file, bit for bit;
a full disk and a read-only output folder give one message and leave the previous file intact.

    .venv/bin/python studies/faults.py [--kills 10] [--size 10] [--n 128] [--seed 2026]

1. An uninterrupted 2-rank ensemble (``--size`` surfaces of ``--n``^2, 95 load steps) is the reference.
2. The same command is started again and again into a second file; each run is killed with SIGKILL
   (mpiexec and both ranks) at a random moment, every third one at the moment rank 0 is writing the
   HDF5 file (its temporary exists). After every kill the file must be absent (killed before the first
   surface finished) or readable with whole surfaces only, and hold no fewer surfaces than before.
3. A last run completes it; every dataset must equal the reference's bit for bit (``ensemble.compare``,
   run bookkeeping and times excluded).
4. A finished file is copied to a 1 MiB tmpfs that the next run fills (full disk) and to a tmpfs
   remounted read-only; each rerun with a new configuration must exit 2 with one message naming the
   file and leave the file's bytes unchanged. These need ``mount`` (root); without it they are reported
   as not run.

Both runs use FFTW_ESTIMATE: plans made by measuring may differ between two processes (the reference
and the killed run), while a resumed run takes the plans stored in its file.
Writes studies/output/faults.md.
"""

import argparse
import hashlib
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

import common

from roughpetsc import ensemble

MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_rmaps_base_oversubscribe": "1", "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}


def command(args, output, ranks=2):
    base = [sys.executable, "-m", "roughpetsc", *[str(a) for a in args], "-output", str(output)]
    return ["mpiexec", "-n", str(ranks), "--oversubscribe", *base] if ranks > 1 else base


def environment():
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = common.ROOT + os.pathsep + env.get("PYTHONPATH", "")
    return env


def kill_session(session):
    """SIGKILL mpiexec and every rank it started: all of them are in the session the run was started in.

    A second round catches a process started between the first round's look-up and its kill.
    """
    for _ in range(2):
        subprocess.run(["pkill", "-KILL", "-s", str(session)])
        time.sleep(0.1)


def temporaries(folder):
    return {name for name in os.listdir(folder) if name.startswith(".tmp-")}


def finished(path):
    if not os.path.exists(path):
        return 0
    contents = ensemble.read(path)  # raises if the file is not a whole, readable ensemble file
    indices = contents["surfaces/index"]
    assert contents["steps/A"].shape[0] == len(indices) == contents["@n_finished"]
    return len(indices)


def kill_trials(args, output, kills, reference_seconds, startup, size, rng):
    rows = []
    folder = os.path.dirname(output)
    for trial in range(kills):
        before = finished(output)
        mid_write = trial % 3 == 2
        # After its start-up, each kill falls within the next quarter of the work left, so that the
        # trials find surfaces both finished and still to do.
        remaining = (reference_seconds - startup) * (1 - before / size)
        delay = rng.uniform(startup, startup + min(remaining, (reference_seconds - startup) / 4))
        writes_to_pass = rng.randint(0, 2)  # a mid-write kill hits the first, second or third write
        process = subprocess.Popen(command(args, output), cwd=common.ROOT, env=environment(), start_new_session=True,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        start = time.time()
        moment, was_writing, stale = "random", False, temporaries(folder)  # stale: left by earlier kills
        while process.poll() is None:
            elapsed = time.time() - start
            now_writing = mid_write and bool(temporaries(folder) - stale)
            if now_writing and not was_writing:
                if writes_to_pass == 0:
                    moment = "mid-write"
                    break
                writes_to_pass -= 1
            was_writing = now_writing
            if not mid_write and elapsed > delay:
                break
            time.sleep(0.0005 if mid_write else 0.01)
        ended_by_itself = process.poll() is not None
        kill_session(process.pid)
        process.wait()
        after = finished(output)
        assert after >= before, f"trial {trial}: {before} surfaces before the kill, {after} after"
        leftovers = temporaries(folder)
        rows.append([trial, moment, f"{time.time() - start:.2f}", before, after, "yes" if ended_by_itself else "no",
                     len(leftovers)])
        print(f"trial {trial}: killed {moment} after {time.time() - start:.2f} s, surfaces {before} -> {after}"
              f"{' (run had ended)' if ended_by_itself else ''}", flush=True)
    return rows


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def mount_tmpfs(folder, size):
    result = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", folder], capture_output=True,
                            text=True)
    return result.returncode == 0, result.stderr.strip()


def disk_trials(args, finished_file):
    """(case, exit status, first stderr line, file unchanged) for a full disk and a read-only folder."""
    rows = []
    changed = [*args, "-ensemble_seed", "99"]  # another configuration: the run must not touch the old file
    for case in ("full disk", "read-only folder"):
        folder = tempfile.mkdtemp(prefix="roughpetsc-faults-")
        ok, why = mount_tmpfs(folder, "1m" if case == "full disk" else "4m")
        if not ok:
            rows.append([case, "not run", f"mount refused: {why}", ""])
            os.rmdir(folder)
            continue
        try:
            target = os.path.join(folder, "run.h5")
            shutil.copy(finished_file, target)
            if case == "full disk":
                try:  # fill the disk to the last block
                    with open(os.path.join(folder, "filler"), "wb") as f:
                        while True:
                            f.write(b"\0" * 4096)
                            f.flush()
                except OSError:
                    pass
                # A fresh configuration into a new file of the full disk (the old one is refused anyway).
                target_new = os.path.join(folder, "new.h5")
                before = digest(target)
                out = subprocess.run(command(changed, target_new, ranks=1), cwd=common.ROOT, env=environment(),
                                     capture_output=True, text=True, timeout=600)
                intact = digest(target) == before and not os.path.exists(target_new)
            else:
                subprocess.run(["mount", "-o", "remount,ro", folder], check=True)
                before = digest(target)
                out = subprocess.run(command([*args, "-overwrite"], target, ranks=1), cwd=common.ROOT,
                                     env=environment(), capture_output=True, text=True, timeout=600)
                intact = digest(target) == before
            first = (out.stderr.strip().splitlines() or [""])[0]
            traceback = "Traceback" in out.stderr
            rows.append([case, out.returncode, first + (" (TRACEBACK)" if traceback else ""),
                         "yes" if intact else "NO"])
            print(f"{case}: exit {out.returncode}: {first}; file intact: {intact}", flush=True)
        finally:
            subprocess.run(["umount", folder], capture_output=True)
            shutil.rmtree(folder, ignore_errors=True)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--kills", type=int, default=10)
    parser.add_argument("--size", type=int, default=10)
    parser.add_argument("--n", type=int, default=128)
    parser.add_argument("--seed", type=int, default=2026)
    parsed = parser.parse_args()
    rng = random.Random(parsed.seed)
    args = ["-mode", "ensemble", "-surface_N", parsed.n, "-surface_kl", 8, "-surface_ks", 32,
            "-ensemble_size", parsed.size, "-ensemble_models", "none", "-fft_effort", "FFTW_ESTIMATE",
            "-ensemble_loads", "history"]
    work = tempfile.mkdtemp(prefix="roughpetsc-kill-")
    try:
        reference = os.path.join(work, "reference.h5")
        start = time.time()
        process = subprocess.Popen(command(args, reference), cwd=common.ROOT, env=environment(),
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        process.stdout.readline()  # the run's header: start-up (interpreter, MPI, plans) is over
        startup = time.time() - start
        process.communicate()
        if process.returncode:
            raise SystemExit(f"the reference run failed (exit {process.returncode})")
        reference_seconds = time.time() - start
        print(f"reference: {reference_seconds:.1f} s, start-up {startup:.1f} s", flush=True)
        os.makedirs(os.path.join(work, "killed"))
        killed = os.path.join(work, "killed", "killed.h5")
        rows = kill_trials(args, killed, parsed.kills, reference_seconds, startup, parsed.size, rng)
        subprocess.run(command(args, killed), cwd=common.ROOT, env=environment(), check=True, capture_output=True)
        worst = ensemble.compare(reference, killed)
        different = {name: value for name, value in worst.items() if value != 0.0}
        log = ensemble.read(killed)["@runs"]
        disk = disk_trials(args, reference)
    finally:
        shutil.rmtree(work, ignore_errors=True)

    lines = ["# Faults: SIGKILL and resume, full disk, read-only folder", "",
             f"Generated by `.venv/bin/python studies/faults.py --kills {parsed.kills} --size {parsed.size} "
             f"--n {parsed.n} --seed {parsed.seed}` (2 ranks, {parsed.size} surfaces of {parsed.n}^2, 95 load steps, "
             f"FFTW_ESTIMATE; the uninterrupted run took {reference_seconds:.1f} s).", "",
             "## SIGKILL at random moments, then resume", "",
             common.markdown_table(["trial", "moment", "killed after s", "surfaces before", "surfaces after",
                                    "run had ended", "temporaries left"], rows), "",
             f"After the last resume: {len(worst)} quantities compared with the uninterrupted run, "
             f"{len(different)} differ" + (f": {different}" if different else " (bit for bit equal)") + ".",
             f"Runs logged in the file: {len(__import__('json').loads(log))}.", "",
             "A temporary left by a kill is a hidden `.tmp-*` file beside the output; the next run ignores it.", "",
             "## Full disk and read-only folder", "",
             common.markdown_table(["case", "exit", "message", "previous file unchanged"], disk), ""]
    path = os.path.join(common.OUTPUT, "faults.md")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {path}")
    if different or any(r[3] == "NO" for r in disk):
        sys.exit(1)


if __name__ == "__main__":
    main()
