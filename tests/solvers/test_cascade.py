"""The cascade start of cold load-controlled solves (roughpetsc.solvers.cascade).

References: scipy's linear interpolation for the prolongation; the solve from the uniform start (the same
answer from another start) and the KKT certificate for the solution; the serial run for the parallel one.
"""


import numpy as np
import pytest
from petsc4py import PETSc
from scipy.interpolate import RegularGridInterpolator

from roughpetsc import ContactProblem, Grid, Solver, fractal
from roughpetsc.errors import UserError
from roughpetsc.solvers.cascade import coarsening_factors, make_cascade, prolong_bilinear_rows

from conftest import assert_parallel_equals_serial

EFFORT = "FFTW_ESTIMATE"


def make_problem(n, comm=PETSc.COMM_SELF, hardness=None):
    grid = Grid(n, n)
    return ContactProblem(grid, fractal(grid, 4, 16, 0.8, 2e-4, 3), 1.0, comm, fft_effort=EFFORT, hardness=hardness)


def test_coarsening_factors():
    assert coarsening_factors((1024, 1024), 256) == (4, 2)
    assert coarsening_factors((2048, 1024), 256) == (4, 2)
    assert coarsening_factors((512, 512), 256) == (2,)
    assert coarsening_factors((256, 256), 256) == ()
    assert coarsening_factors((96, 96), 16) == (4, 2)  # 96 / 8 = 12 nodes: too few
    assert coarsening_factors((1024, 1024), 0) == ()


def test_prolongation_is_periodic_bilinear_interpolation_in_any_row_blocks():
    rng = np.random.default_rng(2)
    coarse = rng.normal(size=(6, 10))
    # scipy on the grid extended by its first row and column (the period), at the fine nodes (i / 2, j / 2)
    wrapped = np.pad(coarse, ((0, 1), (0, 1)), mode="wrap")
    interpolate = RegularGridInterpolator((np.arange(7), np.arange(11)), wrapped)
    rows, cols = np.meshgrid(np.arange(12) / 2, np.arange(20) / 2, indexing="ij")
    expected = interpolate(np.stack([rows, cols], axis=-1))
    whole = prolong_bilinear_rows(coarse, slice(0, 12))
    blocks = np.concatenate([prolong_bilinear_rows(coarse, slice(a, b)) for a, b in ((0, 5), (5, 6), (6, 12))])
    assert np.abs(whole - expected).max() <= 1e-14
    assert np.array_equal(blocks, whole)


@pytest.mark.parametrize("pstar", [0.05, 0.5, 2.0])
def test_cascade_start_gives_the_uniform_starts_solution(pstar):
    problem = make_problem(64)
    try:
        fields = {}
        for coarsest in (0, 16):
            solver = Solver(problem, "load", None, 1e-10, options={"cascade_coarsest": coarsest})
            try:
                result = solver.solve(pstar=pstar)
                fields[coarsest] = (result, solver.fields()[0].copy())
            finally:
                solver.destroy()
    finally:
        problem.destroy()
    (plain, expected), (cascaded, pressure) = fields[0], fields[16]
    assert plain.converged and cascaded.converged and cascaded.kkt.natural <= 1e-10
    assert plain.cascade_applications == 0
    # two levels (16 and 32 nodes per side): at least one pair each, weighted 1/16 and 1/4
    assert cascaded.cascade_applications >= 1 / 16 + 1 / 4
    assert np.array_equal(pressure > 0, expected > 0)
    assert np.abs(pressure - expected).max() <= 1e-7 * expected.max()


def test_only_cold_starts_are_cascaded():
    """Warm steps, a 'uniform' start and a load solve after a displacement-controlled one start as before."""
    problem = make_problem(64)
    solver = Solver(problem, "load", None, 1e-8, options={"cascade_coarsest": 16})
    try:
        first = solver.solve(pstar=0.5)
        second = solver.solve(pstar=0.6)
        uniform = solver.solve(pstar=0.6, start="uniform")
    finally:
        solver.destroy()
    assert first.cascade_applications > 0 and second.cascade_applications == 0
    assert uniform.cascade_applications == 0
    assert first.converged and second.converged and uniform.converged
    problem.destroy()


def test_default_cascade_on_large_grids_only():
    small, large = make_problem(512), make_problem(1024)
    try:
        assert make_cascade(small, "load") is None
        assert make_cascade(large, "displacement") is None
        assert make_cascade(large, "load").factors == (4, 2)
        capped = make_problem(64, hardness=1e-3)
        try:
            assert make_cascade(capped, "load") is None  # not asked for: no cascade, no error
        finally:
            capped.destroy()
    finally:
        small.destroy()
        large.destroy()


@pytest.mark.parametrize("options, control, hardness, words", [
    ({"cascade_coarsest": 16}, "displacement", None, "load-controlled contact solves only"),
    ({"cascade_coarsest": 16}, "load", 1e-3, "no hardness cap"),
    ({"cascade_coarsest": -1}, "load", None, "least number of nodes"),
    ({"cascade_coarsest": 16, "cascade_rtol": 1.5}, "load", None, "between 0 and 1"),
])
def test_refusals_name_the_option(options, control, hardness, words):
    problem = make_problem(64, hardness=hardness)
    try:
        with pytest.raises(UserError, match=words) as error:
            Solver(problem, control, None, 1e-8, options=options)
        named = [name for name in options if name in str(error.value)]
        assert len(named) == 1
    finally:
        problem.destroy()


def test_parallel_cascade_equals_serial(tmp_path):
    args = ["-surface_N", 128, "-surface_kl", 8, "-surface_ks", 32, "-pstar", 0.5, "-cascade_coarsest", 32,
            "-fft_effort", "FFTW_ESTIMATE"]
    assert_parallel_equals_serial(args, tmp_path, "coarse start", "cascade_applications")



def test_a_start_put_in_the_pressure_is_solved_from_its_own_displacement():
    """A resumed path puts its last pressure in the solver: the next step then costs what the same step costs
    after that solve in one run (the same start, scaled to the load), plus the one pair of its K p. (Its K p
    was once taken as zero, the uniform start's, which cost 13 more pairs at N = 256.)"""
    problem = make_problem(64)
    try:
        solver = Solver(problem, "load", None, 1e-8)
        try:
            solver.solve(pstar=0.5)
            saved = problem.local(solver.pressure, readonly=True).copy()
            continued = solver.solve(pstar=0.6)
        finally:
            solver.destroy()
        solver = Solver(problem, "load", None, 1e-8)
        try:
            problem.local(solver.pressure)[...] = saved
            resumed = solver.solve(pstar=0.6)
        finally:
            solver.destroy()
    finally:
        problem.destroy()
    assert continued.converged and resumed.converged
    assert resumed.iterations == continued.iterations
    assert resumed.operator_applications == continued.operator_applications + 1
