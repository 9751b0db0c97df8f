"""The split compliance (roughpetsc.elastic.split) and Polonsky-Keer's projection corrections through it.

References: the FFT compliance itself (K c computed by a pair), exactly when the far field is not coarsened;
the solve with a fresh K p after every projection (another algorithm, the same answer) and the KKT
certificate; the serial run for the parallel one.
"""


import numpy as np
import pytest
from petsc4py import PETSc

from roughpetsc import ContactProblem, Grid, Solver, fractal
from roughpetsc.elastic import Westergaard
from roughpetsc.elastic.split import (TRANSFERS, SplitCompliance, add_interpolated, applicable, restrict_points,
                                      transfer_weights)
from roughpetsc.errors import UserError

from conftest import assert_parallel_equals_serial, run_cli

EFFORT = "FFTW_ESTIMATE"


def point_loads(n, count, seed):
    rng = np.random.default_rng(seed)
    nodes = rng.choice(n * n, count, replace=False)
    return nodes // n, nodes % n, rng.random(count)


def exact_and_split(n, radius, coarsening, loads, transfer="bilinear"):
    operator = Westergaard(Grid(n, n), 1.0, PETSc.COMM_SELF, effort=EFFORT)
    c, u, work = operator.vec(), operator.vec(), operator.vec()
    try:
        split = SplitCompliance(operator, radius, coarsening, c, work, PETSc.COMM_SELF.tompi4py(), transfer)
        rows, cols, values = loads
        local = operator.local(c)
        local[...] = 0.0
        local[rows, cols] = values
        operator.displacement(c, u)
        exact = operator.local(u, readonly=True).copy()
        approx = np.zeros((n, n))
        split.add(rows, cols, values, approx)
        return exact, approx, split
    finally:
        for v in (c, u, work):
            v.destroy()


def test_without_coarsening_the_split_is_the_compliance_to_round_off():
    exact, approx, split = exact_and_split(64, 8, 1, point_loads(64, 40, 1))
    assert np.abs(approx - exact).max() <= 1e-12 * np.abs(exact).max()
    assert split.coarse_applications == 1.0


@pytest.mark.parametrize("radius, coarsening, transfer, bound", [
    (16, 2, "bilinear", 1e-2), (16, 4, "bilinear", 2e-2), (32, 4, "bilinear", 4e-3), (32, 4, "cubic", 1.5e-3)])
def test_the_coarse_far_field_error_falls_with_the_radius_over_the_coarsening(radius, coarsening, transfer, bound):
    """Measured max errors 0.3, 0.8 and 0.15 % of max |K c| (bilinear), 0.052 % (cubic)."""
    exact, approx, split = exact_and_split(256, radius, coarsening, point_loads(256, 200, 2), transfer)
    error = approx - exact
    error -= error.mean()  # a uniform displacement is the rigid mode: the separation absorbs it
    assert np.abs(error).max() <= bound * np.abs(exact).max()
    assert split.coarse_applications == 1.0 / coarsening ** 2


@pytest.mark.parametrize("transfer, degree", [("bilinear", 1), ("cubic", 3)])
@pytest.mark.parametrize("coarsening", [2, 4, 8])
def test_the_transfers_interpolate_polynomials_exactly_and_restrict_by_their_transpose(transfer, degree, coarsening):
    weights, offset = transfer_weights(transfer, coarsening)
    nodes = np.arange(weights.shape[1]) - offset
    t = np.arange(coarsening) / coarsening
    for power in range(degree + 1):
        assert np.allclose(weights @ nodes.astype(float) ** power, t ** power, atol=1e-14)
    rng = np.random.default_rng(coarsening)
    coarse = rng.standard_normal((6, 5))
    fine = np.zeros((6 * coarsening, 5 * coarsening))
    add_interpolated(fine, 0, coarse, weights, offset)
    assert np.allclose(fine[::coarsening, ::coarsening], coarse, atol=1e-14)  # coarse node (i, j) is (s i, s j)
    rows, cols = np.divmod(rng.choice(fine.size, 40, replace=False), fine.shape[1])
    values = rng.standard_normal(40)
    restricted = np.zeros_like(coarse)
    restrict_points(restricted, rows, cols, values, weights, offset)
    assert np.dot(restricted.ravel(), coarse.ravel()) == pytest.approx(np.dot(values, fine[rows, cols]), rel=1e-12)


def test_where_the_split_cannot_apply():
    periodic = Westergaard(Grid(64, 64), 1.0, PETSc.COMM_SELF, effort=EFFORT)
    oblong = Westergaard(Grid(64, 64, 1.0, 2.0), 1.0, PETSc.COMM_SELF, effort=EFFORT)
    try:
        assert applicable(periodic, 16, 4) is None
        assert "square" in applicable(oblong, 16, 4)
        assert "2 x 32 + 1" in applicable(periodic, 32, 4)
        assert "divisible by 3" in applicable(periodic, 16, 3)
    finally:
        periodic.destroy()
        oblong.destroy()


def make_problem(n, comm=PETSc.COMM_SELF, hardness=None, boundary="periodic"):
    grid = Grid(n, n)
    return ContactProblem(grid, fractal(grid, 4, 16, 0.8, 2e-4, 3), 1.0, comm, fft_effort=EFFORT,
                          hardness=hardness, boundary=boundary)


@pytest.mark.parametrize("pstar, transfer", [(0.05, "bilinear"), (0.5, "bilinear"), (2.0, "bilinear"), (0.5, "cubic")])
def test_split_corrections_give_the_fresh_corrections_solution(pstar, transfer):
    problem = make_problem(128)
    try:
        runs = {}
        for radius in (0, 16):
            options = {"pk_split_radius": radius, "pk_split_transfer": transfer} if radius else {}
            solver = Solver(problem, "load", None, 1e-10, options=options)
            try:
                result = solver.solve(pstar=pstar)
                runs[radius] = (result, solver.fields()[0].copy())
            finally:
                solver.destroy()
        (fresh, p_fresh), (split, p_split) = runs[0], runs[16]
        assert fresh.converged and split.converged
        assert split.kkt.natural <= 1e-10
        assert fresh.split_applications == 0 < split.split_applications
        assert np.abs(p_split - p_fresh).max() <= 1e-8 * np.abs(p_fresh).max()
        assert split.A == pytest.approx(fresh.A, abs=2 / 128 ** 2)
    finally:
        problem.destroy()


def test_displacement_control_with_split_corrections():
    problem = make_problem(128)
    try:
        gaps = {}
        for radius in (0, 16):
            solver = Solver(problem, "displacement", None, 1e-10, options={"pk_split_radius": radius})
            try:
                grid = problem.grid
                heights = fractal(grid, 4, 16, 0.8, 2e-4, 3)
                result = solver.solve(gbar=0.5 * float(np.std(heights)))
                assert result.converged
                assert (result.split_applications > 0) == (radius > 0)
                gaps[radius] = result.pbar
            finally:
                solver.destroy()
        assert gaps[16] == pytest.approx(gaps[0], rel=1e-8)
    finally:
        problem.destroy()


@pytest.mark.parametrize("options, hardness, boundary, words", [
    ({"pk_split_radius": 16}, 1e-3, "periodic", "hardness cap"),
    ({"pk_split_radius": 16}, None, "free", "not periodic"),
    ({"pk_split_radius": 16, "pk_active_set": "pk"}, None, "periodic", "pk active set"),
    ({"pk_split_radius": -1}, None, "periodic", "0 \\(off\\)"),
    ({"pk_split_refresh": 1.5}, None, "periodic", "in \\(0, 1\\)"),
    ({"pk_split_radius": 16, "pk_split_transfer": "quintic"}, None, "periodic", "unknown transfer 'quintic'"),
    ({"pk_split_transfer": "cubic"}, None, "periodic", "the split is off"),
    ({"pk_split_radius": 0, "pk_split_coarsening": 2}, None, "periodic", "the split is off"),
])
def test_refusals_name_the_option(options, hardness, boundary, words):
    problem = make_problem(64, hardness=hardness, boundary=boundary)
    try:
        with pytest.raises(UserError, match=words) as error:
            Solver(problem, "load", None, 1e-8, options=options)
        assert "pk_split" in str(error.value)
    finally:
        problem.destroy()


@pytest.mark.parametrize("given, words", [
    (["-pk_split_radius"], "pk_split_radius"),                              # no value
    (["-pk_split_radius", 4294967328], "beyond the integers"),              # PETSc would read 32
    (["-pk_split_refresh", "abc"], "as a number"),
    (["-pk_split_radius", 16, "-boundary", "free"], "not periodic"),
    (["-pk_split_coarsening", 0, "-pk_split_radius", 16], "at least 1"),
    (["-pk_split_radius", 16, "-pk_split_transfer"], "pk_split_transfer"),  # no value
    (["-pk_split_transfer", "cubic"], "the split is off"),
])
def test_the_command_line_refuses_by_name_and_writes_nothing(tmp_path, given, words):
    done = run_cli(["-surface_N", 64, "-surface_kl", 4, "-surface_ks", 16, "-pstar", 0.5, *given,
                    "-fft_effort", "FFTW_ESTIMATE",
                    "-json", tmp_path / "out.json"])
    assert done.returncode != 0
    assert words in done.stderr and "pk_split" in done.stderr
    assert not (tmp_path / "out.json").exists()


@pytest.mark.parametrize("transfer", TRANSFERS)
def test_parallel_split_corrections_equal_serial(tmp_path, transfer):
    args = ["-surface_N", 128, "-surface_kl", 8, "-surface_ks", 32, "-pstar", 0.5, "-pk_split_radius", 16,
            "-pk_split_transfer", transfer, "-fft_effort", "FFTW_ESTIMATE"]
    assert_parallel_equals_serial(args, tmp_path, "split corrections", "split_applications")
