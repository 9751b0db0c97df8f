"""Load control in the gap (roughpetsc/solvers/bound_gap.py, ``-bound_load gap``) against Polonsky-Keer, a second
algorithm, and its refusals; two ranks against one: tests/solvers/test_bound_qp.py."""

import numpy as np
import pytest

from roughpetsc.errors import UserError
from roughpetsc.solvers import Solver

from conftest import fractal_problem
from test_tao_types import _pk_reference

GAP = {"bound_load": "gap"}


@pytest.fixture(scope="module")
def references():
    """Polonsky-Keer under load control to 1e-12 on a 64^2 fractal surface, at p* = 0.05 and 0.5."""
    problem, result, pressure = _pk_reference(64, 4, 16)
    low = Solver(problem, "load", None, 1e-12)
    low_result = low.solve(pstar=0.05)
    low_pressure = low.fields()[0].copy()
    low.destroy()
    yield problem, {0.5: (result, pressure), 0.05: (low_result, low_pressure)}
    problem.destroy()


@pytest.mark.parametrize("pstar", [0.05, 0.5])
@pytest.mark.parametrize("tao_type, preconditioner", [("blmvm", ""), ("bqnls", ""), ("tron", ""), ("gpcg", ""),
                                                      ("bnls", ""), ("tron", "none")])
def test_gap_form_reaches_the_pk_pressure_in_one_solve(references, tao_type, preconditioner, pstar):
    problem, solved = references
    pk, pressure = solved[pstar]
    solver = Solver(problem, "load", tao_type, 1e-8, options=dict(GAP, bound_pc=preconditioner))
    try:
        result = solver.solve(pstar=pstar)
        assert result.converged, result.reason
        assert result.solver == f"{tao_type}(gap)"
        assert result.kkt.natural <= 1e-8 and result.kkt.load_error <= 1e-8
        assert result.separation == pytest.approx(pk.separation, rel=1e-6)
        assert result.A == pk.A
        assert np.abs(solver.fields()[0] - pressure).max() <= 1e-6 * np.abs(pressure).max()
    finally:
        solver.destroy()


@pytest.mark.parametrize("pstar", [0.01, 0.5, 2.0])
def test_cold_start_cuts_the_surface_where_the_free_pressure_has_zero_mean(references, pstar):
    """The separation of a cold start, checked with numpy's FFT and the stiffness symbol pi |k| (scaled): the
    free nodes of the cut surface max(d, h) carry a mean pressure within START_TOLERANCE of pbar."""
    from roughpetsc.solvers.bound_gap import START_TOLERANCE

    problem, _ = references
    solver = Solver(problem, "load", "blmvm", 1e-8, options=GAP)
    try:
        pbar = problem.target("load", pstar=pstar)
        separation = solver.backend._cold_separation(pbar)
    finally:
        solver.destroy()
    heights = problem.local(problem.heights, readonly=True)
    k0, k1 = problem.scaled_grid.rfft_wavenumbers()
    cut = np.maximum(heights, separation)
    pressure = pbar + np.fft.irfft2(np.fft.rfft2(cut) * np.pi * np.hypot(k0, k1), s=cut.shape)
    free = cut > heights
    assert 0 < free.sum() < free.size
    assert abs(pressure[free].mean()) <= START_TOLERANCE * pbar


def test_gap_form_follows_a_load_path(references):
    """Warm starts from the last solution (its gap at the last separation) along a rising load."""
    problem, solved = references
    solver = Solver(problem, "load", "blmvm", 1e-8, options=GAP)
    try:
        results = [solver.solve(pstar=p) for p in (0.05, 0.2, 0.5)]
    finally:
        solver.destroy()
    assert all(r.converged for r in results), [r.reason for r in results]
    assert results[0].separation == pytest.approx(solved[0.05][0].separation, rel=1e-6)
    assert results[-1].separation == pytest.approx(solved[0.5][0].separation, rel=1e-6)


@pytest.mark.parametrize("options, problem_options, named", [
    ({}, {"boundary": "free"}, "bound_load gap needs the periodic boundary"),
    ({}, {"hardness": 5.0}, "bound_load gap needs the periodic boundary"),
])
def test_gap_form_refuses_what_it_cannot_solve(options, problem_options, named):
    problem = fractal_problem(32, **problem_options)
    try:
        with pytest.raises(UserError, match=named):
            Solver(problem, "load", "tron", 1e-8, options=dict(GAP, **options))
    finally:
        problem.destroy()
