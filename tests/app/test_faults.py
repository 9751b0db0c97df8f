"""A full disk or a read-only folder under a running or resumed ensemble: one message, the file intact.

The disk is a small tmpfs mounted for the test (root, as on CI); where mounting is refused the test
says so and is skipped (studies/faults.py reports the same cases, and the SIGKILL trials).
"""

import hashlib
import os
import subprocess
import sys
import time

import h5py
import pytest

from conftest import MPI_ENV, ROOT, SUBPROCESS_TIMEOUT, finish, run_cli
from roughpetsc import ensemble

ARGS = ["-mode", "ensemble", "-surface_N", 64, "-surface_kl", 4, "-surface_ks", 16, "-ensemble_models", "none",
        "-ensemble_loads", "0.05,0.2,0.5,1,2", "-fft_effort", "FFTW_ESTIMATE"]


@pytest.fixture
def small_disk(tmp_path):
    folder = tmp_path / "disk"
    folder.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(folder)], capture_output=True,
                             text=True)
    if mounted.returncode:
        pytest.skip(f"cannot mount a tmpfs here ({mounted.stderr.strip()}): needs root")
    yield folder
    subprocess.run(["umount", str(folder)], capture_output=True)


def _fill(folder):
    try:
        with open(folder / "filler", "wb") as f:
            while True:
                f.write(b"\0" * 4096)
                f.flush()
    except OSError:
        pass


def _finished(path):
    try:
        with h5py.File(path, "r") as f:
            return int(f.attrs["n_finished"])
    except Exception:
        return 0


def _digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.mpi
@pytest.mark.slow
def test_disk_full_during_an_ensemble_stops_with_one_message_and_keeps_the_file(small_disk):
    output = small_disk / "run.h5"
    command = ["mpiexec", "-n", "2", "--oversubscribe", sys.executable, "-m", "roughpetsc",
               *[str(a) for a in ARGS + ["-ensemble_size", 40, "-output", output]]]
    env = dict(os.environ, **MPI_ENV, PYTHONPATH=ROOT)
    process = subprocess.Popen(command, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + SUBPROCESS_TIMEOUT
    while process.poll() is None and _finished(output) < 1 and time.time() < deadline:
        time.sleep(0.01)
    _fill(small_disk)
    stdout, stderr = finish(process, command)
    assert process.returncode != 0
    assert "roughpetsc: error: cannot write" in stderr and "No space left on device" in stderr, stderr
    assert "Traceback" not in stderr and len([line for line in stderr.splitlines() if "roughpetsc" in line]) == 1
    kept = ensemble.read(output)  # whole and readable
    assert kept["@n_finished"] >= 1 and kept["steps/A"].shape[0] == kept["@n_finished"]
    assert not [name for name in os.listdir(small_disk) if name.startswith(".tmp-")]
    os.remove(small_disk / "filler")
    resumed = run_cli(ARGS + ["-ensemble_size", 6, "-output", output], ranks=2) if kept["@n_finished"] <= 6 else None
    if resumed is not None:
        assert resumed.returncode == 0, resumed.stderr
        assert ensemble.read(output)["@n_finished"] == 6


@pytest.mark.mpi
@pytest.mark.slow
def test_read_only_folder_refuses_before_work_and_leaves_the_file(small_disk):
    output = small_disk / "run.h5"
    first = run_cli(ARGS + ["-ensemble_size", 2, "-output", output], ranks=2)
    assert first.returncode == 0, first.stderr
    before = _digest(output)
    subprocess.run(["mount", "-o", "remount,ro", str(small_disk)], check=True)
    for extra, ranks in (([], 2), (["-ensemble_size", 4], 2), (["-ensemble_size", 4], 1)):
        out = run_cli(ARGS + ["-ensemble_size", 2, "-output", output] + extra, ranks=ranks)
        if extra:
            assert out.returncode == 2, out.stderr
            assert str(output) in out.stderr and "Traceback" not in out.stderr
            # One line of ours (mpiexec adds its own banner about the exit status under MPI).
            assert len([line for line in out.stderr.splitlines() if line.startswith("roughpetsc")]) == 1
        assert _digest(output) == before
