"""Issue 37, no lost step: -resume keeps every saved step; an interrupted path (1 or 2 ranks) holds every step it
printed and says so in one line; Ctrl-C in ensemble mode; a closed pipe; progress lines only for a person watching."""

import hashlib
import json
import os
import re
import signal
import subprocess
import sys

import h5py
import numpy as np
import pytest

from conftest import MPI_ENV, ROOT, finish, run_cli, run_on_terminal, run_process
from conftest import assert_one_clear_error

TINY = ["-surface_N", 32, "-surface_ks", 8, "-surface_kl", 2, "-fft_effort", "FFTW_ESTIMATE"]


def digest(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def saved_steps(path):
    with h5py.File(path) as f:
        return [dict(f[f"steps/{index:03d}"].attrs) for index in range(len(f["steps"]))]


# --- -resume never discards a saved step --------------------------------------------------------------------------

@pytest.fixture
def saved_path(tmp_path):
    """A three-step path in k.h5 (and its summary k.json)."""
    out = run_cli(TINY + ["-pstar_list", "0.1,0.2,0.3", "-output", "k.h5", "-json", "k.json", "-quiet"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    return tmp_path / "k.h5"


@pytest.mark.parametrize("loads, says", [
    ("0.1,0.2", "stops after 2 of them"),                     # the reproduction: fewer loads
    ("0.1,0.25,0.3,0.4", "differs at step 2: pstar 0.25 here, pstar 0.2 in the file"),
])
def test_resume_with_other_loads_is_refused_naming_the_saved_ones(saved_path, loads, says):
    before = digest(saved_path)
    out = run_cli(TINY + ["-pstar_list", loads, "-output", "k.h5", "-resume"], cwd=saved_path.parent)
    message = assert_one_clear_error(out, "-resume", "k.h5", "3 saved step(s)", "pstar 0.1, 0.2, 0.3", says)
    assert out.stdout == "", message
    assert digest(saved_path) == before


def test_resume_with_other_load_kind_is_refused(saved_path):
    out = run_cli(TINY + ["-pbar_list", "1e-3,2e-3", "-output", "k.h5", "-resume"], cwd=saved_path.parent)
    assert_one_clear_error(out, "-resume", "differs at step 1: pbar 0.001 here, pstar 0.1 in the file")


@pytest.mark.mpi
def test_resume_with_a_longer_list_extends_the_path(saved_path):
    before = saved_steps(saved_path)
    # Its own -json is rewritten without -overwrite.
    out = run_cli(TINY + ["-pstar_list", "0.1,0.2,0.3,0.4,0.5", "-output", "k.h5", "-json", "k.json", "-resume"],
                  cwd=saved_path.parent)
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("(from k.h5)") == 3
    after = saved_steps(saved_path)
    assert len(after) == 5 and all(step["converged"] for step in after)
    for old, new in zip(before, after):  # the saved steps are kept as they were
        assert old["A"] == new["A"] and old["iterations"] == new["iterations"]
    summary = json.load(open(saved_path.parent / "k.json"))
    assert [step["pstar"] for step in summary["steps"]] == pytest.approx([0.1, 0.2, 0.3, 0.4, 0.5], rel=1e-8)
    # The same path solved at once: the same areas (the added steps start from the saved pressure).
    out = run_cli(TINY + ["-pstar_list", "0.1,0.2,0.3,0.4,0.5", "-json", "fresh.json", "-quiet"],
                  cwd=saved_path.parent)
    fresh = json.load(open(saved_path.parent / "fresh.json"))["steps"]
    assert [s["A"] for s in summary["steps"]] == pytest.approx([s["A"] for s in fresh], abs=1.0 / 32 ** 2)


def test_resume_refuses_a_json_that_is_not_its_own(saved_path):
    other = saved_path.parent / "other.json"
    other.write_text('{"mine": 1}\n')
    out = run_cli(TINY + ["-pstar_list", "0.1,0.2,0.3", "-output", "k.h5", "-json", "other.json", "-resume"],
                  cwd=saved_path.parent)
    assert_one_clear_error(out, "-json", "other.json", "-overwrite")
    assert other.read_text() == '{"mine": 1}\n'


# --- an interrupted path holds every step it printed, on any number of ranks --------------------------------------

def start(args, ranks, cwd):
    """Start the command line (SIGINT as at a terminal, not ignored as in a background shell)."""
    command = [sys.executable, "-m", "roughpetsc", *map(str, args)]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), "--oversubscribe", *command]
    env = dict(os.environ, **MPI_ENV, PYTHONPATH=ROOT)
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def interrupt_after(run, marker, count):
    """Read the run's output until ``count`` lines hold ``marker``, send SIGINT, return (stdout, stderr)."""
    seen = []
    while sum(marker in line for line in seen) < count:
        line = run.stdout.readline()
        assert line, "the run ended before it could be interrupted: " + run.stderr.read()
        seen.append(line)
    run.send_signal(signal.SIGINT)
    # Read on through run.stdout: communicate() would read the pipe past what readline() has buffered.
    rest, stderr = run.stdout.read(), run.stderr.read()
    finish(run, run.args)
    return "".join(seen) + rest, stderr


@pytest.mark.mpi
@pytest.mark.parametrize("ranks, fields", [(1, "last"), (2, "all"), (2, "last")])
def test_an_interrupted_path_holds_every_step_it_printed(tmp_path, ranks, fields):
    """`timeout -s INT 5 mpiexec -n 2 ... -output_fields all` once printed 8 converged steps and kept 4, silently."""
    loads = np.linspace(0.01, 3.0, 4000)  # minutes of work: the run is interrupted long before its end
    (tmp_path / "loads.txt").write_text("\n".join(repr(v) for v in loads) + "\n")
    args = TINY + ["-pstar_list", "@loads.txt", "-output", "h.h5", "-output_fields", fields]
    run = start(args, ranks, tmp_path)
    stdout, stderr = interrupt_after(run, "CONVERGED", 3)
    if ranks == 1:
        assert run.returncode == 130, stderr
    else:
        assert run.returncode != 0, stderr
    assert "Traceback" not in stderr and "PETSC ERROR" not in stderr, stderr
    # Open MPI's mpiexec kills the ranks a second after it passes the signal on, maybe in a checkpoint's write:
    # the line comes at the signal, not after the write.
    said = [line for line in stderr.splitlines() if line.startswith("roughpetsc:")]
    assert len(said) == 1 and said[0].startswith("roughpetsc: interrupted after "), stderr
    held = int(said[0].split("after ")[1].split(" of ")[0])
    steps = saved_steps(tmp_path / "h.h5")
    printed = stdout.count("CONVERGED_USER")
    # Once mpiexec has the signal it forwards no more of the ranks' output: rank 0 may have printed more lines.
    assert held == len(steps) >= printed >= 3 and (ranks > 1 or printed == held), (held, printed, len(steps))
    assert all(step["converged"] for step in steps)
    assert [step["load_value"] for step in steps] == list(loads[:len(steps)])
    if fields == "all":
        with h5py.File(tmp_path / "h.h5") as f:
            assert all(f[f"steps/{i:03d}/pressure"].shape == (32, 32) for i in range(len(steps)))
    out = run_cli(args + ["-resume", "-solve_max_time", 60, "-pstar_list", ",".join(map(repr, loads[:held + 2]))],
                  cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.count(f"(from h.h5)") == held and len(saved_steps(tmp_path / "h.h5")) == held + 2


def test_a_stop_request_is_announced_at_once_and_no_file_is_replaced_after_it(tmp_path):
    """The closing line does not wait for the main thread (mpiexec kills the ranks a second after the signal,
    perhaps in a long write), and the files it names keep what they held when it was printed."""
    from roughpetsc.app.interrupts import StopRequests
    from roughpetsc.store.outputs import atomic_path

    for name in ("a.h5", "a.json"):
        (tmp_path / name).write_text("old")
    blocked, release = os.pipe()
    with StopRequests() as requests:
        requests.announcement = lambda: os.write(release, b"announced")
        written = []
        for name in ("a.h5", "a.json"):
            with atomic_path(tmp_path / name, deferred=written) as temporary:
                open(temporary, "w").write("new")
        os.kill(os.getpid(), signal.SIGTERM)
        # The main thread stays in this read until the announcement writes to the pipe.
        assert os.read(blocked, 64) == b"announced"
        assert requests.is_set()
        assert not requests.replace_unless_stopped(written, then=pytest.fail)
    assert sorted(os.listdir(tmp_path)) == ["a.h5", "a.json"]  # no temporary left
    assert all((tmp_path / name).read_text() == "old" for name in ("a.h5", "a.json"))
    os.close(blocked)
    os.close(release)


def test_files_are_replaced_together_without_a_stop_request(tmp_path):
    from roughpetsc.app.interrupts import StopRequests
    from roughpetsc.store.outputs import atomic_path

    with StopRequests() as requests:
        written, done = [], []
        for name in ("a.h5", "a.json"):
            with atomic_path(tmp_path / name, deferred=written) as temporary:
                open(temporary, "w").write("new")
        assert sorted(os.listdir(tmp_path))[0].startswith(".tmp-")  # nothing replaced yet
        assert not any((tmp_path / name).exists() for name in ("a.h5", "a.json"))
        assert requests.replace_unless_stopped(written, then=lambda: done.append(1)) and done == [1]
    assert sorted(os.listdir(tmp_path)) == ["a.h5", "a.json"]
    assert all((tmp_path / name).read_text() == "new" for name in ("a.h5", "a.json"))


def test_ctrl_c_in_ensemble_mode_ends_in_one_line(tmp_path):
    from roughpetsc import ensemble

    run = start(TINY + ["-mode", "ensemble", "-ensemble_size", 500, "-ensemble_loads", "0.1,0.5", "-output", "e.h5"],
                1, tmp_path)
    _, stderr = interrupt_after(run, "steps converged", 2)
    assert run.returncode == 130, stderr
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughpetsc: interrupted; e.h5 keeps "), stderr
    kept = int(lines[0].split("keeps ")[1].split(" of ")[0])
    saved = ensemble.read(tmp_path / "e.h5")
    assert kept >= 2 and len(saved["surfaces/index"]) == saved["@n_finished"] == kept


def test_output_into_a_pipe_closed_early_ends_quietly(tmp_path):
    """`... | head -n 2`: no SIGPIPE abort of PETSc; the run finishes and writes its files."""
    loads = ",".join(f"{0.05 * k:g}" for k in range(1, 21))
    command = (f"{sys.executable} -m roughpetsc {' '.join(map(str, TINY))} -pstar_list {loads} -json p.json "
               "| head -n 2; exit ${PIPESTATUS[0]}")
    out = run_process(["bash", "-c", command], cwd=tmp_path, env=dict(os.environ, PYTHONPATH=ROOT))
    assert out.returncode == 0, out.stderr
    assert len(out.stdout.splitlines()) == 2
    assert "PETSC ERROR" not in out.stderr and "BrokenPipe" not in out.stderr, out.stderr
    assert len(json.load(open(tmp_path / "p.json"))["steps"]) == 20


# --- progress lines: only for a person watching, each naming its step and inner solve --------------------------

PROGRESS = TINY + ["-pstar_list", "0.2,0.4", "-progress_interval", 1e-9]


@pytest.mark.mpi
def test_progress_on_a_terminal_behind_mpiexec(tmp_path):
    command = ["mpiexec", "-n", "2", "--oversubscribe", sys.executable, "-m", "roughpetsc", *map(str, PROGRESS)]
    status, printed = run_on_terminal(command, tmp_path)
    assert status == 0, printed
    assert "... step 2 of 2 (pstar 0.4): inner solve 1, iteration" in printed


@pytest.mark.mpi
def test_no_progress_into_a_log_under_mpiexec(tmp_path):
    """Open MPI gives each rank a terminal: isatty() is true there, yet mpiexec writes into a pipe or a file."""
    out = run_cli(PROGRESS, ranks=2)
    assert out.returncode == 0, out.stderr
    assert "... step" not in out.stdout


def test_progress_can_be_forced_off_and_on(tmp_path):
    status, printed = run_on_terminal([sys.executable, "-m", "roughpetsc", *map(str, PROGRESS + ["-progress", "off"])],
                                      tmp_path)
    assert status == 0 and "... step" not in printed
    out = run_cli(PROGRESS + ["-progress", "on"])
    assert out.returncode == 0 and "... step 1 of 2 (pstar 0.2): inner solve 1, iteration 0" in out.stdout


def test_progress_names_the_inner_solves_of_a_root_find():
    """Under load control a TAO bound type solves several displacement problems in a row (one per multiplier
    of its augmented Lagrangian), and the progress line counts them."""
    out = run_cli(TINY + ["-pstar", 0.4, "-tao_type", "blmvm", "-bound_load", "al", "-progress", "on",
                          "-progress_interval", 1e-9])
    assert out.returncode == 0, out.stderr
    inner = {int(line.split("inner solve ")[1].split(",")[0]) for line in out.stdout.splitlines() if "... step" in line}
    assert len(inner) >= 3 and inner == set(range(1, max(inner) + 1))
    assert re.search(r"\.\.\. step 1 of 1 \(pstar 0\.4\): inner solve 2, iteration \d+,", out.stdout), out.stdout
