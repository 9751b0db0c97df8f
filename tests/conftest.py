"""Shared test set-up: PETSc initialised once; helpers to run the command line."""

import faulthandler
import json
import os
import pty
import subprocess
import sys

import petsc4py
import pytest

# Every test plans its transforms afresh, as on a new machine: no wisdom from earlier runs.
# ROUGHPETSC_FFT_EFFORT (FFTW_ESTIMATE, FFTW_MEASURE, FFTW_PATIENT) forces one planner effort on the
# whole suite, subprocesses included; .ci/run runs the suite under two of them.
os.environ.setdefault("ROUGHPETSC_FFT_WISDOM", "none")

petsc4py.init([sys.argv[0]])


def pytest_configure(config):
    # Debian's llvmlite (under numba) still calls a deprecated importlib.resources function.
    config.addinivalue_line("filterwarnings", "ignore:path is deprecated:DeprecationWarning")


def pytest_report_header(config):
    effort = os.environ.get("ROUGHPETSC_FFT_EFFORT") or "as each test asks"
    return f"roughpetsc: FFTW planner effort {effort}, wisdom cache {os.environ['ROUGHPETSC_FFT_WISDOM']}"

# A test still running after this many seconds ends the whole run, with every thread's traceback (which names
# the test) on stderr: a hang inside the test process, even one in C code that never returns to Python, must not
# run on to CI's limit. The longest test takes about 3 minutes on a loaded two-core machine.
TEST_TIME_LIMIT = float(os.environ.get("ROUGHPETSC_TEST_TIME_LIMIT", 900))
TERMINAL_STDERR = pytest.StashKey[int]()


def _terminal_stderr(config):
    """A copy of the stderr that pytest's output capture replaces during a test (where a traceback would be lost)."""
    capture = config.pluginmanager.getplugin("capturemanager")
    if capture is None:
        return os.dup(2)
    with capture.global_and_fixture_disabled():
        return os.dup(2)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    if TERMINAL_STDERR not in item.config.stash:
        item.config.stash[TERMINAL_STDERR] = _terminal_stderr(item.config)
    faulthandler.dump_traceback_later(TEST_TIME_LIMIT, exit=True, file=item.config.stash[TERMINAL_STDERR])
    try:
        yield
    finally:
        faulthandler.cancel_dump_traceback_later()


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_rmaps_base_oversubscribe": "1", "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}


# Every subprocess of a test (mpiexec included) has this much time: the longest takes about 90 s on a 2-core
# machine loaded by two suites at once, so reaching it means a hang, and the failure says which command hung.
SUBPROCESS_TIMEOUT = 900


def timed_out(command, error):
    """Fail the test with the command that did not finish within its time."""
    shown = command if isinstance(command, str) else " ".join(str(part) for part in command)
    pytest.fail(f"timed out after {error.timeout:g} s (a hang: no loaded machine takes this long): {shown}",
                pytrace=False)


def run_process(command, timeout=SUBPROCESS_TIMEOUT, **kwargs):
    """``subprocess.run(command, capture_output=True, text=True, **kwargs)``; a timeout fails the test by name."""
    try:
        return subprocess.run(command, capture_output=True, text=True, timeout=timeout, **kwargs)
    except subprocess.TimeoutExpired as error:
        timed_out(command, error)


def finish(process, command, timeout=SUBPROCESS_TIMEOUT):
    """``process.communicate()`` within ``timeout``; a timeout kills it and fails the test naming ``command``."""
    try:
        return process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired as error:
        process.kill()
        process.communicate()
        timed_out(command, error)


def run_cli(args, ranks=1, cwd=None):
    """Run ``python -m roughpetsc args`` on ``ranks`` MPI ranks; returns the CompletedProcess."""
    command = [sys.executable, "-m", "roughpetsc", *[str(a) for a in args]]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), "--oversubscribe", *command]
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    return run_process(command, cwd=cwd or ROOT, env=env)


def assert_parallel_equals_serial(args, tmp_path, printed, counted):
    """The first step of ``python -m roughpetsc args`` on 1, 2 and 3 ranks: the same iterations, pairs, the
    ``counted`` pairs (positive), contact area, and mean gap to round-off; ``printed`` is in every table."""
    steps = {}
    for ranks in (1, 2, 3):
        out = tmp_path / f"run{ranks}.json"
        done = run_cli(list(args) + ["-json", out], ranks=ranks)
        assert done.returncode == 0, done.stderr
        steps[ranks] = json.loads(out.read_text())["steps"][0]
        assert printed in done.stdout
    for ranks in (2, 3):
        assert steps[ranks]["iterations"] == steps[1]["iterations"]
        assert steps[ranks]["operator_applications"] == steps[1]["operator_applications"]
        assert steps[ranks][counted] == steps[1][counted] > 0
        assert steps[ranks]["A"] == steps[1]["A"]
        assert abs(steps[ranks]["gstar"] - steps[1]["gstar"]) <= 1e-12 * abs(steps[1]["gstar"])


def run_on_terminal(command, cwd=None):
    """Run ``command`` (a list) with stdout on a pseudo-terminal; returns (exit status, what it printed)."""
    primary, secondary = pty.openpty()
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    run = subprocess.Popen(command, stdout=secondary, stderr=subprocess.PIPE, cwd=cwd or ROOT, env=env)
    os.close(secondary)
    printed = b""
    while True:
        try:
            chunk = os.read(primary, 4096)
        except OSError:  # the terminal closed with the process
            break
        if not chunk:
            break
        printed += chunk
    os.close(primary)
    finish(run, command)
    return run.returncode, printed.decode()


def applications_at_time_limit(monkeypatch, problem):
    """A list that receives ``problem``'s operator applications when a solve first finds its time limit passed.

    ``problem.operator.applications`` minus its one entry is then the work done after the limit.
    """
    from roughpetsc.solvers import stopping

    at_limit = []
    out_of_time = stopping.History.out_of_time

    def recorded(history, max_seconds):
        expired = out_of_time(history, max_seconds)
        if expired and not at_limit:
            at_limit.append(problem.operator.applications)
        return expired

    monkeypatch.setattr(stopping.History, "out_of_time", recorded)
    return at_limit


def fractal_problem(n=64, k_l=4, k_s=16, seed=3, **options):
    """The small test problem: a fractal surface (H = 0.8, m2 = 2e-4) on an n x n unit cell, E* = 1, one rank,
    FFTW_ESTIMATE plans; ``options`` go to ContactProblem (boundary, hardness). Destroy it after use."""
    from petsc4py import PETSc

    from roughpetsc import ContactProblem, Grid, fractal

    grid = Grid(n, n)
    return ContactProblem(grid, fractal(grid, k_l, k_s, 0.8, 2e-4, seed), 1.0, PETSc.COMM_SELF,
                          fft_effort="FFTW_ESTIMATE", **options)


@pytest.fixture(scope="module")
def small_problem():
    """:func:`fractal_problem` with its defaults (64^2, k_l = 4, k_s = 16), shared by the tests of a module."""
    problem = fractal_problem()
    yield problem
    problem.destroy()


def error_lines(out):
    return [line for line in out.stderr.splitlines() if line.startswith("roughpetsc: error")]


def assert_one_clear_error(out, *named):
    """Exit status 2, no traceback, exactly one ``roughpetsc: error`` line naming every string of ``named``."""
    assert out.returncode == 2, out.stderr
    assert "Traceback" not in out.stderr
    errors = error_lines(out)
    assert len(errors) == 1, out.stderr
    for text in named:
        assert str(text) in errors[0], errors[0]
    return errors[0]
