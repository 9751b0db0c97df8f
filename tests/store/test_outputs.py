"""Outputs a user can use: read back, every step's fields, interrupted and resumed paths, units, plots, progress."""

import json
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from conftest import MPI_ENV, ROOT, finish, run_cli, run_on_terminal

SMALL = ["-surface_N", 64, "-surface_ks", 16, "-surface_kl", 4]
PATH = ["-pstar_list", "0.2,0.5,1"]


def steps_of(path):
    with h5py.File(path) as f:
        return [dict(f[f"steps/{i:03d}"].attrs) for i in range(len(f["steps"]))]


def assert_same_path(resumed, reference):
    """A* and gbar within 1e-8 relative, pressure fields within 1e-7 of their maximum, step by step."""
    a, b = steps_of(resumed), steps_of(reference)
    assert len(a) == len(b) and all(step["converged"] for step in a)
    for x, y in zip(a, b):
        assert x["A"] == pytest.approx(y["A"], rel=1e-8) and x["gbar"] == pytest.approx(y["gbar"], rel=1e-8)
    with h5py.File(resumed) as f, h5py.File(reference) as g:
        for index in range(len(a)):
            p, q = f[f"steps/{index:03d}/pressure"][()], g[f"steps/{index:03d}/pressure"][()]
            assert np.abs(p - q).max() <= 1e-7 * np.abs(q).max()


def test_our_output_reads_back_as_surface_file(tmp_path):
    out = run_cli(SMALL + ["-surface_L", 2.0, "-output", tmp_path / "a.h5"])
    assert out.returncode == 0, out.stderr
    out = run_cli(["-surface_file", tmp_path / "a.h5", "-output", tmp_path / "b.h5"])
    assert out.returncode == 0, out.stderr
    with h5py.File(tmp_path / "a.h5") as a, h5py.File(tmp_path / "b.h5") as b:
        assert np.allclose(a["heights"][()], b["heights"][()], rtol=0, atol=1e-14 * np.abs(a["heights"][()]).max())
        assert json.loads(b.attrs["length"]) == [2.0, 2.0]  # the recorded cell length is kept
        assert b.attrs["E_star"] == a.attrs["E_star"]


def test_output_fields_all_keeps_every_step_and_none_keeps_none(tmp_path):
    out = run_cli(SMALL + PATH + ["-output_fields", "all", "-output", tmp_path / "all.h5"])
    assert out.returncode == 0, out.stderr
    with h5py.File(tmp_path / "all.h5") as f:
        assert len(f["steps"]) == 3
        for index in range(3):
            assert f[f"steps/{index:03d}/pressure"].shape == f[f"steps/{index:03d}/gap"].shape == (64, 64)
        assert np.array_equal(f["steps/002/pressure"][()], f["pressure"][()])
        assert not np.array_equal(f["steps/000/pressure"][()], f["pressure"][()])
    out = run_cli(SMALL + PATH + ["-output_fields", "none", "-output", tmp_path / "none.h5"])
    assert out.returncode == 0, out.stderr
    with h5py.File(tmp_path / "none.h5") as f:
        assert "heights" in f and "pressure" not in f and "pressure" not in f["steps/000"]


def test_datasets_carry_units_and_the_surface_parameters_are_recorded(tmp_path):
    out = run_cli(SMALL + ["-output", tmp_path / "u.h5"])
    assert out.returncode == 0, out.stderr
    with h5py.File(tmp_path / "u.h5") as f:
        assert f["heights"].attrs["units"] == "length" and f["gap"].attrs["units"] == "length"
        assert "E_star" in f["pressure"].attrs["units"]
        for name in ("heights", "pressure", "gap", "steps/000/history"):
            assert f[name].attrs["description"]
        parameters = json.loads(f.attrs["surface_parameters"])
    # Defaults included: type, H, m2, seed and generator were not given.
    assert parameters == {"surface_type": "fractal", "surface_N": 64, "surface_N0": 0, "surface_L": 1.0,
                          "surface_kl": 4.0, "surface_ks": 16.0, "surface_H": 0.8, "surface_m2": 2e-4,
                          "surface_seed": 1, "surface_generator": "filter"}


@pytest.mark.mpi
@pytest.mark.slow
def test_a_path_out_of_time_keeps_its_steps_and_resumes(tmp_path):
    args = SMALL + PATH + ["-kkt_rtol", 1e-11, "-output_fields", "all"]
    out = run_cli(args + ["-output", tmp_path / "r.h5", "-solve_max_time", 1e-9])
    assert out.returncode == 3
    assert [step["converged"] for step in steps_of(tmp_path / "r.h5")] == [False] * 3
    out = run_cli(args + ["-output", tmp_path / "r.h5", "-resume"])
    assert out.returncode == 0, out.stderr
    out = run_cli(args + ["-output", tmp_path / "u.h5"])
    assert_same_path(tmp_path / "r.h5", tmp_path / "u.h5")
    # Resuming a finished path solves nothing; another surface is refused in one line.
    out = run_cli(args + ["-output", tmp_path / "r.h5", "-resume"])
    assert out.returncode == 0 and out.stdout.count("(from ") == 3
    out = run_cli(args + ["-output", tmp_path / "r.h5", "-resume", "-surface_seed", 2])
    assert out.returncode == 2 and "another problem (different surface)" in out.stderr


@pytest.mark.slow
def test_ctrl_c_keeps_the_finished_steps_and_resume_completes_the_path(tmp_path):
    loads = ",".join(f"{0.05 * i:.2f}" for i in range(1, 41))
    args = ["-surface_N", 128, "-pk_pc", "none", "-kkt_rtol", 1e-11, "-pstar_list", loads, "-output_fields", "all"]
    output = tmp_path / "i.h5"
    command = [sys.executable, "-m", "roughpetsc", *map(str, args), "-output", str(output)]
    env = dict(os.environ, **MPI_ENV, PYTHONPATH=ROOT)
    # A suite started in the background of a non-interactive shell inherits SIGINT ignored, and Python
    # then keeps ignoring it: the child gets Ctrl-C's default back, as a command typed at a terminal has it.
    run = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env,
                           preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    while not output.exists() and run.poll() is None:  # the first step is saved
        time.sleep(0.01)
    run.send_signal(signal.SIGINT)
    _, stderr = finish(run, command)
    assert run.returncode == 130, stderr
    assert "Traceback" not in stderr and "rerun with -resume" in stderr
    finished = steps_of(output)
    assert 0 < len(finished) < 40 and all(step["converged"] for step in finished)
    out = run_cli(args + ["-output", output, "-resume"])
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("(from ") == len(finished)
    out = run_cli(args + ["-output", tmp_path / "u.h5"])
    assert_same_path(output, tmp_path / "u.h5")


@pytest.mark.parametrize("loads", [["-pstar", 0.5], PATH])
def test_plot_writes_a_figure(tmp_path, loads):
    from matplotlib.image import imread

    out = run_cli(SMALL + loads + ["-plot", tmp_path / "p.png"])
    assert out.returncode == 0, out.stderr
    image = imread(tmp_path / "p.png")
    assert image.ndim == 3 and image.shape[1] > image.shape[0] > 100 and image.std() > 0.05


def test_plot_of_an_unknown_format_is_refused_before_the_solve(tmp_path):
    out = run_cli(SMALL + ["-plot", tmp_path / "p.jpgx"])
    assert out.returncode == 2 and "-plot" in out.stderr and "Traceback" not in out.stderr


def test_progress_lines_on_a_terminal_only(tmp_path):
    args = SMALL + ["-progress_interval", 1e-6]
    status, printed = run_on_terminal([sys.executable, "-m", "roughpetsc", *map(str, args)])
    assert status == 0 and "... step 1 of 1 (pstar 0.5): inner solve 1, iteration" in printed
    assert "KKT natural" in printed
    out = run_cli(args)
    assert out.returncode == 0 and "... step" not in out.stdout


@pytest.mark.mpi
@pytest.mark.slow
def test_fields_written_by_every_rank_equal_one_rank(tmp_path):
    """Under mpiexec Debian's h5py is the parallel build: each rank writes its rows of the fields (store)."""
    import h5py
    import numpy as np

    args = ["-surface_N", 40, "-surface_N0", 37, "-surface_ks", 10, "-surface_kl", 2, "-pstar_list", "0.3,0.9",
            "-kkt_rtol", 1e-13, "-output_fields", "all", "-fft_effort", "FFTW_ESTIMATE"]
    files = []
    for ranks in (1, 3):
        path = tmp_path / f"fields{ranks}.h5"
        out = run_cli(args + ["-output", path], ranks=ranks)
        assert out.returncode == 0, out.stdout + out.stderr
        files.append(path)
    with h5py.File(files[0]) as one, h5py.File(files[1]) as three:
        assert not one.attrs["fields_written_by_every_rank"]
        assert three.attrs["fields_written_by_every_rank"]  # python3-h5py-mpi (tools/bootstrap.sh)
        for name in ("pressure", "gap", "steps/000/pressure", "steps/001/gap"):
            a, b = one[name][()], three[name][()]
            assert a.shape == b.shape == (37, 40)
            assert np.abs(a - b).max() <= 1e-12 * np.abs(a).max()
            assert dict(one[name].attrs) == dict(three[name].attrs)
