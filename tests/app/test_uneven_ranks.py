"""More ranks than cores, rows that the ranks do not divide: 3 and 4 ranks equal 1 rank.

The grid has 62 rows and 66 columns: 62 rows split 21/21/20 on 3 ranks and
16/16/15/15 on 4 (the uneven slab path, as PETSc's PETSC_DECIDE would split
them), and the 34 spectral columns split unevenly too. The runs are
oversubscribed (``mpiexec --oversubscribe`` on a 2-core machine). Every run is
solved to a natural KKT residual of 1e-13, so all of them are at the unique
solution and must agree to round-off: A*, A* corrected (its perimeter looks at
the neighbour rank's first row) and the mean gap to 1e-12 relative, the
pressure field to 1e-12 of its maximum, the heights bit for bit.
"""

import json

import h5py
import numpy as np
import pytest

from conftest import run_cli

UNEVEN = ["-surface_N", 66, "-surface_N0", 62, "-surface_ks", 16, "-surface_kl", 4,
          "-kkt_rtol", 1e-13, "-pstar_list", "0.1,0.5,1.5"]
TOLERANCE = 1e-12


def solve(tmp_path, ranks, extra=()):
    """Run the solve mode; returns (fields from the HDF5 file, the JSON steps)."""
    name = f"r{ranks}_{'_'.join(str(a).strip('-') for a in extra)}"
    h5, js = tmp_path / f"{name}.h5", tmp_path / f"{name}.json"
    out = run_cli(UNEVEN + list(extra) + ["-output", h5, "-json", js], ranks=ranks)
    assert out.returncode == 0, out.stdout + out.stderr
    with h5py.File(h5) as f:
        fields = {k: f[k][()] for k in ("heights", "pressure", "gap")}
    steps = json.load(open(js))["steps"]
    assert all(step["converged"] for step in steps)
    return fields, steps


def differences(reference, other):
    """Largest relative differences: A*, A* corrected, mean gap (over the steps) and pressure (max norm)."""
    (fields1, steps1), (fields2, steps2) = reference, other
    assert np.array_equal(fields1["heights"], fields2["heights"])  # same seed, same surface on any ranks
    assert fields2["pressure"].shape == (62, 66)

    def relative(key):
        return max(abs(a[key] - b[key]) / abs(a[key]) for a, b in zip(steps1, steps2))

    pressure = np.abs(fields1["pressure"] - fields2["pressure"]).max() / np.abs(fields1["pressure"]).max()
    return {"A": relative("A"), "A_corrected": relative("A_corrected"), "gbar": relative("gbar"),
            "pressure": pressure}


@pytest.fixture(scope="module")
def one_rank(tmp_path_factory):
    """The 1-rank answers, per planner effort."""
    folder = tmp_path_factory.mktemp("one_rank")
    return {effort: solve(folder, 1, ["-fft_effort", effort]) for effort in ("FFTW_ESTIMATE", "FFTW_MEASURE")}


@pytest.mark.mpi
@pytest.mark.slow
@pytest.mark.parametrize("effort", ["FFTW_ESTIMATE", "FFTW_MEASURE"])
@pytest.mark.parametrize("ranks", [3, 4])
def test_uneven_rows_equal_one_rank(tmp_path, one_rank, ranks, effort):
    measured = differences(one_rank[effort], solve(tmp_path, ranks, ["-fft_effort", effort]))
    print(f"{ranks} ranks, {effort}: " + ", ".join(f"{k} {v:.2e}" for k, v in measured.items()))
    assert max(measured.values()) <= TOLERANCE, measured


def test_planner_efforts_agree(one_rank):
    """The answer does not depend on the FFTW plan (only round-off separates two plans)."""
    measured = differences(one_rank["FFTW_ESTIMATE"], one_rank["FFTW_MEASURE"])
    assert max(measured.values()) <= TOLERANCE, measured


@pytest.mark.mpi
@pytest.mark.slow
def test_displacement_control_on_three_ranks(tmp_path):
    """Displacement control (the mean-mode term of the preconditioner, global sums over uneven blocks)."""
    common = ["-surface_N", 66, "-surface_N0", 62, "-surface_ks", 16, "-surface_kl", 4, "-kkt_rtol", 1e-13,
              "-gbar", 3e-4, "-fft_effort", "FFTW_ESTIMATE"]
    steps = {}
    for ranks in (1, 3):
        out = run_cli(common + ["-json", tmp_path / f"d{ranks}.json"], ranks=ranks)
        assert out.returncode == 0, out.stdout + out.stderr
        steps[ranks] = json.load(open(tmp_path / f"d{ranks}.json"))["steps"][0]
    for key in ("A", "pbar", "gbar"):
        assert steps[3][key] == pytest.approx(steps[1][key], rel=TOLERANCE), key


@pytest.mark.mpi
@pytest.mark.slow
def test_tao_bound_solver_on_four_ranks(tmp_path):
    """A TAO bound solver with the Fourier preconditioner on the free set (createSubMatrix on uneven blocks).

    TAO's iterates differ in round-off with the rank count, so the answers agree to the solver tolerance.
    """
    common = ["-surface_N", 66, "-surface_N0", 62, "-surface_ks", 16, "-surface_kl", 4, "-kkt_rtol", 1e-9,
              "-pstar", 0.5, "-tao_type", "bntr", "-bound_pc", "fourier", "-fft_effort", "FFTW_ESTIMATE"]
    steps = {}
    for ranks in (1, 4):
        out = run_cli(common + ["-json", tmp_path / f"t{ranks}.json"], ranks=ranks)
        assert out.returncode == 0, out.stdout + out.stderr
        steps[ranks] = json.load(open(tmp_path / f"t{ranks}.json"))["steps"][0]
    assert steps[4]["converged"]
    assert steps[4]["A"] == pytest.approx(steps[1]["A"], rel=1e-6)
    assert steps[4]["gbar"] == pytest.approx(steps[1]["gbar"], rel=1e-6)


@pytest.mark.mpi
def test_more_ranks_than_rows_is_refused_by_name(tmp_path):
    out = run_cli(["-surface_N", 16, "-surface_N0", 3, "-surface_ks", 4, "-surface_kl", 2], ranks=4)
    assert out.returncode == 2, out.stdout + out.stderr
    errors = [line for line in out.stderr.splitlines() if line.startswith("roughpetsc: error")]
    assert len(errors) == 1 and "-surface_N0/-surface_N" in errors[0], out.stderr


@pytest.mark.mpi
@pytest.mark.slow
def test_ensemble_group_of_three_ranks_equals_one_rank(tmp_path):
    """An ensemble group solves each surface on its own communicator: uneven rows there too."""
    common = ["-mode", "ensemble", "-surface_N", 62, "-surface_ks", 16, "-surface_kl", 4, "-ensemble_size", 2,
              "-ensemble_loads", "0.1,0.5", "-kkt_rtol", 1e-13, "-fft_effort", "FFTW_ESTIMATE",
              "-ensemble_models", "none"]
    steps = {}
    for ranks, extra in ((1, []), (3, ["-ensemble_group_ranks", 3])):
        path = tmp_path / f"e{ranks}.h5"
        out = run_cli(common + extra + ["-output", path], ranks=ranks)
        assert out.returncode == 0, out.stdout + out.stderr
        with h5py.File(path) as f:
            steps[ranks] = {key: f[f"steps/{key}"][()] for key in ("A", "A_corrected", "gbar")}
    for key, reference in steps[1].items():
        assert np.abs(steps[3][key] - reference).max() <= TOLERANCE * np.abs(reference).max(), key
