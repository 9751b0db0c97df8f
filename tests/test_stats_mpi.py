"""The stats mode on 1 and 2 MPI ranks (subprocess mpiexec): identical results, files, user errors."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PYTHON = "/usr/bin/python3"

DRIVER = """
import sys, petsc4py
petsc4py.init(sys.argv)
from petsc4py import PETSc
from mpi4py import MPI
from roughpetsc import stats_mode
from roughpetsc.errors import UserError
try:
    stats_mode.run(PETSc.Options(), MPI.COMM_WORLD)
except UserError as error:
    print("error:", error, file=sys.stderr)
    sys.exit(2)
"""

SMALL_GROUP = ["-surface_N", "128", "-surface_kl", "4", "-surface_ks", "16", "-surface_H", "0.8",
               "-surface_m2", "2e-4", "-surface_seed", "11"]

def run_stats(ranks, arguments, tmp_path):
    environment = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                       PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER)
    command = ["mpiexec", "-n", str(ranks), "--oversubscribe", PYTHON, str(driver)] + arguments
    return subprocess.run(command, capture_output=True, text=True, env=environment, timeout=120, cwd=ROOT)


def stats_json(ranks, arguments, tmp_path):
    path = tmp_path / f"stats_{ranks}.json"
    result = run_stats(ranks, arguments + ["-stats_json", str(path)], tmp_path)
    assert result.returncode == 0, result.stderr
    return json.loads(path.read_text()), result.stdout


def test_ensemble_on_two_ranks_equals_one_rank(tmp_path):
    arguments = SMALL_GROUP + ["-stats_ensemble", "5"]
    one, _ = stats_json(1, arguments, tmp_path)
    two, stdout = stats_json(2, arguments, tmp_path)
    assert one["seeds"] == two["seeds"] == [11, 12, 13, 14, 15]
    assert one["per_surface"] == two["per_surface"]          # bit-identical, seed order
    assert one["mean"] == two["mean"]
    assert one["std"] == two["std"]
    assert one["histogram_density"] == two["histogram_density"]
    assert one["pdf_l1"] == two["pdf_l1"]
    assert stdout.count("stats: 5 realisation(s)") == 1      # printed by rank 0 only


def test_single_surface_on_two_ranks_equals_python_api(tmp_path):
    from roughpetsc import spectra
    from roughpetsc.surfaces import Grid, fractal

    two, _ = stats_json(2, SMALL_GROUP, tmp_path)
    grid = Grid(128, 128, 1.0, 1.0)
    heights = fractal(grid, 4.0, 16.0, 0.8, 2e-4, 11)
    summary = spectra.surface_moment_summary(grid, heights)
    assert two["realisations"] == 1
    assert two["mean"]["m4h_fd_x"] == pytest.approx(summary["h_fd"]["x"][4], rel=1e-12)
    assert two["mean"]["m2p_spec_y"] == pytest.approx(summary["p_spectral"]["y"][2], rel=1e-12)
    assert two["mean"]["alpha_p"] == pytest.approx(summary["alpha_p"], rel=1e-12)
    assert two["std"]["alpha_h"] == 0.0


def test_hdf5_and_plots_are_written(tmp_path):
    import h5py

    h5 = tmp_path / "s.h5"
    prefix = tmp_path / "pdf"
    result = run_stats(2, SMALL_GROUP + ["-stats_ensemble", "3", "-stats_h5", str(h5), "-stats_plot", str(prefix),
                                         "-E_star", "2.0"], tmp_path)
    assert result.returncode == 0, result.stderr
    with h5py.File(h5, "r") as f:
        assert json.loads(f.attrs["settings"])["e_star"] == 2.0
        assert f.attrs["surface_options.surface_N"] == 128
        assert "numpy" in json.loads(f.attrs["versions"])
        assert list(f["seeds"][()]) == [11, 12, 13]
        m0p = f["per_surface/m0p_fd"][()]
        assert m0p.shape == (3,)
        assert f["mean"].attrs["m0p_fd"] == pytest.approx(np.mean(m0p), rel=1e-15)
        assert f["std"].attrs["m0p_fd"] == pytest.approx(np.std(m0p, ddof=1), rel=1e-12)
    assert (tmp_path / "pdf_h.png").stat().st_size > 0 and (tmp_path / "pdf_p.png").stat().st_size > 0
    assert not [p for p in os.listdir(tmp_path) if ".tmp-" in p]


def test_e_star_scales_pressure_moments(tmp_path):
    one, _ = stats_json(1, SMALL_GROUP, tmp_path)
    (tmp_path / "e").mkdir()
    three, _ = stats_json(1, SMALL_GROUP + ["-E_star", "3.0"], tmp_path / "e")
    for key in ("m0p_fd", "m2p_fd", "m4p_fd"):
        assert three["mean"][key] == pytest.approx(9.0 * one["mean"][key], rel=1e-12)
    assert three["mean"]["alpha_p"] == pytest.approx(one["mean"]["alpha_p"], rel=1e-12)


@pytest.mark.parametrize("arguments, option", [
    (["-stats_ensemble", "-2"], "-stats_ensemble"),
    (["-stats_bin_width", "0"], "-stats_bin_width"),
    (["-stats_fd_scheme", "upwind"], "-stats_fd_scheme"),
    (["-E_star", "-1"], "-E_star"),
    (["-stats_json", "/nonexistent-folder/x.json"], "-stats_json"),
    (["-surface_ks", "100"], "-surface_ks"),
    (["-surface_type", "wave", "-stats_ensemble", "2"], "-stats_ensemble"),
])
def test_bad_input_names_the_option_on_two_ranks(tmp_path, arguments, option):
    result = run_stats(2, SMALL_GROUP + arguments, tmp_path)
    assert result.returncode != 0
    assert option in result.stderr
    assert "Traceback" not in result.stderr
    assert not list(tmp_path.glob("*.json"))
