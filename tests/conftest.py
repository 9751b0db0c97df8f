"""Shared test set-up: PETSc initialised once; helpers to run the command line."""

import os
import pty
import subprocess
import sys

import petsc4py

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

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_rmaps_base_oversubscribe": "1", "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}


def run_cli(args, ranks=1, cwd=None, timeout=600):
    """Run ``python -m roughpetsc args`` on ``ranks`` MPI ranks; returns the CompletedProcess."""
    command = [sys.executable, "-m", "roughpetsc", *[str(a) for a in args]]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), "--oversubscribe", *command]
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run(command, capture_output=True, text=True, cwd=cwd or ROOT, env=env, timeout=timeout)


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
    return run.wait(timeout=300), printed.decode()


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
