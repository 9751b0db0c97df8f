"""Perfect plasticity as a hardness cap 0 <= p <= H, in every solver, against independent references.

References: a second algorithm (scipy's L-BFGS-B on the bound-constrained QP, its compliance applied
with numpy's FFT and the symbol 1 / (pi E* |k|) of (3.33), nothing of roughpetsc), the fully plastic
limit (every contact node at H: contact area = load / H), and the elastic answer when H is never reached.
"""

import h5py
import numpy as np
import pytest
from scipy.optimize import minimize

from conftest import run_cli
from roughpetsc.contact.problem import ContactProblem
from roughpetsc.solvers import Solver
from roughpetsc.surface.grid import Grid
from roughpetsc.surface.generators import fractal, wave

N = 24


@pytest.fixture(scope="module")
def capped():
    """A 24^2 fractal with a cap at half its complete-contact pressure, and the dense reference at d = 0.3."""
    grid = Grid(N, N)
    heights = fractal(grid, 2, 6, 0.8, 2e-4, 3)
    probe = ContactProblem(grid, heights, 1.0, fft_effort="FFTW_ESTIMATE")
    hardness = 0.5 * probe.complete_contact_pbar * probe.pressure_scale
    probe.destroy()
    problem = ContactProblem(grid, heights, 1.0, fft_effort="FFTW_ESTIMATE", hardness=hardness)
    separation = 0.3  # scaled
    yield problem, dense_reference(grid, heights, problem, separation), separation
    problem.destroy()


def dense_reference(grid, heights, problem, separation):
    """min 1/2 p'Kp + p'(d - h), 0 <= p <= H by L-BFGS-B, in the problem's scaled units."""
    h = (heights - heights.mean()).ravel() / problem.height_scale
    k0, k1 = grid.rfft_wavenumbers()
    k = np.hypot(k0, k1) * grid.l1  # cycles per cell length: the scaled symbol is 1 / (pi |k|)
    symbol = np.where(k > 0, 1 / (np.pi * np.where(k > 0, k, 1)), 0.0)

    def compliance(p):
        return np.fft.irfft2(np.fft.rfft2(p.reshape(grid.shape)) * symbol, s=grid.shape).ravel()

    def objective(p):
        gradient = compliance(p) + separation - h
        return 0.5 * p @ compliance(p) + p @ (separation - h), gradient

    found = minimize(objective, np.zeros(grid.size), jac=True, method="L-BFGS-B",
                     bounds=[(0, problem.upper_bound)] * grid.size,
                     options=dict(ftol=1e-16, gtol=1e-13, maxiter=100000, maxcor=50))
    return found.x.reshape(grid.shape)


@pytest.mark.slow
@pytest.mark.parametrize("tao_type, control", [(None, "displacement"), ("blmvm", "displacement"),
                                               ("tron", "displacement"), ("bnls", "displacement"),
                                               (None, "load"), ("bnls", "load"), ("almm", "load")])
def test_every_solver_meets_the_dense_reference(capped, tao_type, control):
    problem, reference, separation = capped
    assert (reference >= problem.upper_bound * (1 - 1e-9)).mean() > 0.05  # the cap binds
    # 1e-9: above the round-off floors of the quasi-Newton types (1e-10 to 2e-10, README), which depend on the
    # machine's FFT plans; the reference itself is good to about 1e-7 of the cap.
    solver = Solver(problem, control, tao_type, 1e-9)
    try:
        if control == "displacement":
            result = solver.solve(gbar=separation * problem.height_scale)
        else:
            result = solver.solve(pbar=reference.mean() * problem.pressure_scale)
        pressure = problem.local(solver.pressure, readonly=True)
        assert result.converged, result.reason
        # L-BFGS-B's own accuracy is about 1e-7 of the cap here.
        assert np.abs(pressure - reference).max() < 1e-6 * problem.upper_bound
        assert result.A_plastic == pytest.approx((reference >= problem.upper_bound * (1 - 1e-9)).mean())
        assert pressure.max() <= problem.upper_bound
    finally:
        solver.destroy()


@pytest.mark.parametrize("hardness_ratio", [0.4, 0.05])
def test_fully_plastic_wave_has_the_area_load_over_hardness(hardness_ratio):
    """A cap far below the wave's complete-contact pressure p*: the contact is plastic but for a rim of a node."""
    grid = Grid(8, 256)
    complete = np.pi * 1e-3  # p* = pi E* h / lambda of the wave (E* = 1)
    hardness = hardness_ratio * complete
    pbar = 0.25 * hardness
    problem = ContactProblem(grid, wave(grid, 1e-3, 1.0), 1.0, hardness=hardness, fft_effort="FFTW_ESTIMATE")
    solver = Solver(problem, "load", None, 1e-10)
    try:
        result = solver.solve(pbar=pbar)
    finally:
        solver.destroy()
        problem.destroy()
    assert result.converged, result.reason
    assert result.A_plastic * hardness <= pbar * (1 + 1e-9) <= result.A * hardness * (1 + 1e-9)
    assert abs(result.A - pbar / hardness) <= 2 / grid.n1


def test_a_cap_never_reached_changes_nothing():
    grid = Grid(32, 32)
    heights = fractal(grid, 2, 8, 0.8, 2e-4, 5)
    answers = []
    for hardness in (None, 1.0):  # p is of order 1e-2 here
        problem = ContactProblem(grid, heights, 1.0, fft_effort="FFTW_ESTIMATE", hardness=hardness)
        solver = Solver(problem, "load", None, 1e-11)
        try:
            result = solver.solve(pstar=0.5)
            answers.append((result, problem.local(solver.pressure, readonly=True).copy()))
        finally:
            solver.destroy()
            problem.destroy()
    (free, p_free), (cap, p_cap) = answers
    assert cap.A_plastic == 0 and cap.A == free.A
    assert np.abs(p_cap - p_free).max() < 1e-9 * p_free.max()


@pytest.mark.mpi
@pytest.mark.slow
def test_hardness_on_two_ranks_equals_one_rank(tmp_path):
    args = ["-surface_N", 40, "-surface_ks", 10, "-surface_kl", 2, "-hardness", 0.012, "-kkt_rtol", 1e-13,
            "-pstar_list", "0.3,1", "-fft_effort", "FFTW_ESTIMATE"]
    fields, plastic = [], []
    for ranks in (1, 2):
        path = tmp_path / f"cap{ranks}.h5"
        out = run_cli(args + ["-output", path], ranks=ranks)
        assert out.returncode == 0, out.stdout + out.stderr
        with h5py.File(path) as f:
            fields.append(f["pressure"][()])
            plastic.append(f["steps/001"].attrs["A_plastic"])
            assert f.attrs["hardness"] == 0.012
    assert plastic[0] == plastic[1] > 0
    assert np.abs(fields[0] - fields[1]).max() < 1e-12 * np.abs(fields[0]).max()
    assert fields[0].max() <= 0.012
