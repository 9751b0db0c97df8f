"""The stats mode on 1 and 2 MPI ranks (subprocess mpiexec): identical results, files, user errors."""

import json
import os

import numpy as np
import pytest

from conftest import ROOT, run_cli, run_process
from roughpetsc import ensemble
from roughpetsc.surface import seeds
from roughpetsc.store import stats_file

PYTHON = "/usr/bin/python3"

DRIVER = """
import sys, petsc4py
petsc4py.init(sys.argv)
from petsc4py import PETSc
from mpi4py import MPI
from roughpetsc.app import stats_mode
from roughpetsc.errors import UserError
try:
    stats_mode.run(PETSc.Options(), MPI.COMM_WORLD)
except UserError as error:
    print("error:", error, file=sys.stderr)
    sys.exit(2)
"""

SURFACE = ["-surface_N", "128", "-surface_kl", "4", "-surface_ks", "16", "-surface_H", "0.8", "-surface_m2", "2e-4"]
SMALL_GROUP = SURFACE + ["-surface_seed", "11"]     # one surface
ENSEMBLE = SURFACE + ["-ensemble_seed", "11"]       # realisations i: seeds.surface_seed(11, i)

def run_stats(ranks, arguments, tmp_path):
    environment = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                       PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER)
    command = ["mpiexec", "-n", str(ranks), "--oversubscribe", PYTHON, str(driver)] + arguments
    return run_process(command, env=environment, cwd=ROOT)


def stats_json(ranks, arguments, tmp_path):
    path = tmp_path / f"stats_{ranks}.json"
    result = run_stats(ranks, arguments + ["-stats_json", str(path)], tmp_path)
    assert result.returncode == 0, result.stderr
    return json.loads(path.read_text()), result.stdout


@pytest.mark.mpi
def test_ensemble_on_two_ranks_equals_one_rank(tmp_path):
    arguments = ENSEMBLE + ["-stats_ensemble", "5"]
    one, _ = stats_json(1, arguments, tmp_path)
    two, stdout = stats_json(2, arguments, tmp_path)
    assert one["seeds"] == two["seeds"] == seeds.surface_seeds(11, 5)
    assert one["per_surface"] == two["per_surface"]          # bit-identical, seed order
    assert one["mean"] == two["mean"]
    assert one["std"] == two["std"]
    assert one["histogram_density"] == two["histogram_density"]
    assert one["pdf_l1"] == two["pdf_l1"]
    assert stdout.count("stats: 5 realisation(s)") == 1      # printed by rank 0 only


def test_single_surface_on_two_ranks_equals_python_api(tmp_path):
    from roughpetsc.surface import spectra
    from roughpetsc.surface.grid import Grid
    from roughpetsc.surface.generators import fractal

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
    result = run_stats(2, ENSEMBLE + ["-stats_ensemble", "3", "-stats_h5", str(h5), "-stats_plot", str(prefix),
                                      "-E_star", "2.0"], tmp_path)
    assert result.returncode == 0, result.stderr
    with h5py.File(h5, "r") as f:
        assert json.loads(f.attrs["settings"])["e_star"] == 2.0
        assert f.attrs["surface_options.surface_N"] == 128
        assert "numpy" in json.loads(f.attrs["versions"])
        assert list(f["seeds"][()]) == seeds.surface_seeds(11, 3)
        m0p = f["per_surface/m0p_fd"][()]
        assert m0p.shape == (3,)
        assert f["mean"].attrs["m0p_fd"] == pytest.approx(np.mean(m0p), rel=1e-15)
        assert f["std"].attrs["m0p_fd"] == pytest.approx(np.std(m0p, ddof=1), rel=1e-12)
    assert (tmp_path / "pdf_h.png").stat().st_size > 0 and (tmp_path / "pdf_p.png").stat().st_size > 0
    assert not [p for p in os.listdir(tmp_path) if ".tmp-" in p]
    stored = stats_file.read(h5)                             # the reader of the file kind
    assert stored["seeds"] == seeds.surface_seeds(11, 3) and stored["settings"]["e_star"] == 2.0
    assert np.array_equal(stored["per_surface"]["m0p_fd"], m0p)


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
    (["-stats_ensemble", "2"], "-surface_seed"),       # an ensemble's seeds derive from -ensemble_seed
])
def test_bad_input_names_the_option_on_two_ranks(tmp_path, arguments, option):
    result = run_stats(2, SMALL_GROUP + arguments, tmp_path)
    assert result.returncode != 0
    assert option in result.stderr
    assert "Traceback" not in result.stderr
    assert not list(tmp_path.glob("*.json"))


@pytest.mark.mpi
@pytest.mark.slow
def test_one_master_seed_means_one_surface_in_stats_and_ensemble_modes(tmp_path):
    """(master seed, index) -> one surface: -mode stats and -mode ensemble, on 1 and 2 ranks."""
    surface = ["-surface_N", "64", "-surface_kl", "4", "-surface_ks", "16", "-ensemble_seed", "7"]
    one, _ = stats_json(1, surface + ["-stats_ensemble", "3"], tmp_path)
    two, _ = stats_json(2, surface + ["-stats_ensemble", "3"], tmp_path)
    path = tmp_path / "e.h5"
    out = run_cli(["-mode", "ensemble", *surface, "-ensemble_size", 3, "-ensemble_loads", "0.1",
                   "-ensemble_models", "none", "-output", path], ranks=2)
    assert out.returncode == 0, out.stderr
    stored = ensemble.read(path)
    assert one["seeds"] == two["seeds"] == list(stored["surfaces/seed"]) == seeds.surface_seeds(7, 3)
    assert one["per_surface"] == two["per_surface"]
    # The same heights give the same spectral moments (2.12) and finite-difference bandwidths (7.6)/(7.7).
    for stats_name, ensemble_name in (("m0h_spec", "m0h"), ("m2h_spec", "m2h"), ("m4h_spec", "m4h"),
                                      ("m2p_spec", "m2p"), ("alpha_h_spectral", "alpha_h"),
                                      ("alpha_p_spectral", "alpha_p"), ("alpha_h", "alpha_h_fd"),
                                      ("alpha_p", "alpha_p_fd")):
        assert one["per_surface"][stats_name] == list(stored[f"surfaces/{ensemble_name}"]), stats_name


ONE_RANK_FAILS = """
import sys, petsc4py
petsc4py.init(sys.argv)
from petsc4py import PETSc
from mpi4py import MPI
from roughpetsc.app import stats_mode
from roughpetsc.errors import ParameterError, UserError

compute_one = stats_mode.surface_statistics


def fails_on_rank_1(grid, heights, settings, edges):
    if MPI.COMM_WORLD.rank == 1:  # a library error on one rank only: the other must not wait for it
        raise ParameterError("k_s", "must lie below the Nyquist wavenumber")
    return compute_one(grid, heights, settings, edges)


stats_mode.surface_statistics = fails_on_rank_1
try:
    stats_mode.run(PETSc.Options(), MPI.COMM_WORLD)
except UserError as error:
    # One file per rank: two ranks printing to one stdout interleave.
    import os
    with open(f"{os.environ['ONE_RANK_FAILS_OUT']}.rank{MPI.COMM_WORLD.rank}", "w") as out:
        out.write(str(error))
    sys.exit(2)
"""


@pytest.mark.mpi
def test_a_library_error_on_one_rank_stops_every_rank(tmp_path):
    """A ParameterError raised on rank 1 alone is every rank's UserError naming the option (no rank hangs)."""
    driver = tmp_path / "one_rank_fails.py"
    driver.write_text(ONE_RANK_FAILS)
    environment = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                       PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""),
                       ONE_RANK_FAILS_OUT=str(tmp_path / "error"))
    command = ["mpiexec", "-n", "2", "--oversubscribe", PYTHON, str(driver), "-surface_N", "32",
               "-surface_kl", "2", "-surface_ks", "8", "-ensemble_seed", "3", "-stats_ensemble", "2"]
    result = run_process(command, env=environment, cwd=ROOT)
    assert result.returncode == 2, result.stderr
    for rank in (0, 1):  # the message of rank 1's error, raised on both ranks
        message = (tmp_path / f"error.rank{rank}").read_text()
        assert message == "-surface_ks: must lie below the Nyquist wavenumber"
    assert "Traceback" not in result.stderr
