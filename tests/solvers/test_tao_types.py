"""Every bound-constrained TAO type solves the displacement-controlled QP to the same pressure field."""

import numpy as np
import pytest
from petsc4py import PETSc

from roughpetsc.solvers.facade import Solver

from conftest import applications_at_time_limit, fractal_problem

TYPES = ["blmvm", "bqnls", "bncg", "bqnkls", "bqnktr", "bnls", "bntr", "tron", "gpcg"]


def _pk_reference(n, k_l, k_s):
    """Load control by Polonsky-Keer at p* = 0.5 on an n^2 fractal surface, solved to 1e-12."""
    problem = fractal_problem(n, k_l, k_s, seed=7)
    solver = Solver(problem, "load", None, 1e-12)
    result = solver.solve(pstar=0.5)
    pressure = solver.fields()[0].copy()
    solver.destroy()
    assert result.converged
    return problem, result, pressure


@pytest.fixture(scope="module")
def reference():
    """The group-#1 surface on 128^2."""
    problem, result, pressure = _pk_reference(128, 16, 64)
    yield problem, result, pressure
    problem.destroy()


@pytest.mark.parametrize("tao_type", TYPES)
def test_type_converges_to_the_pk_pressure(reference, tao_type):
    problem, load_result, pressure = reference
    solver = Solver(problem, "displacement", tao_type, 1e-8)
    try:
        result = solver.solve(gbar=load_result.separation)
        assert result.converged, result.reason
        assert result.kkt.natural <= 1e-8
        field = solver.fields()[0]
        assert np.abs(field - pressure).max() <= 1e-6 * np.abs(pressure).max()
        assert result.pstar == pytest.approx(0.5, rel=1e-6)
    finally:
        solver.destroy()


def test_gpcg_is_preconditioned_by_the_fourier_symbol_on_its_free_set():
    """PETSc's GPCG builds its preconditioning submatrix from the Hessian, so ``-bound_pc fourier`` goes through a
    PC of its own (FreeSetPC). It must give PK's pressure and cut the FFT pairs: at p* = 2 (N = 128), where
    GPCG's Krylov solves dominate, 202 against 377 without it when measured (the bypassed PC took more than none:
    290-339 Krylov iterations a step against 42-46 at N = 256, p* = 0.05)."""
    problem = fractal_problem(128, 16, 64, seed=1)
    try:
        reference = Solver(problem, "load", None, 1e-12)
        load = reference.solve(pstar=2.0)
        pressure = reference.fields()[0].copy()
        reference.destroy()
        pairs = {}
        for preconditioner in ("none", "fourier"):
            solver = Solver(problem, "displacement", "gpcg", 1e-8, options={"bound_pc": preconditioner})
            try:
                result = solver.solve(gbar=load.separation)
                assert result.converged, result.reason
                assert np.abs(solver.fields()[0] - pressure).max() <= 1e-6 * np.abs(pressure).max()
                pairs[preconditioner] = result.operator_applications
            finally:
                solver.destroy()
        assert pairs["fourier"] < 0.75 * pairs["none"], pairs
    finally:
        problem.destroy()


@pytest.fixture(scope="module")
def small_reference():
    """The reference on 64^2 (ALMM costs tens of thousands of operator applications on 128^2)."""
    problem, result, pressure = _pk_reference(64, 4, 16)
    yield problem, result, pressure
    problem.destroy()


@pytest.mark.slow
@pytest.mark.parametrize("tao_type, size", [("bqnls", 128), ("almm", 64)])
def test_other_load_controls_agree_with_pk(reference, small_reference, tao_type, size):
    problem, load_result, pressure = reference if size == 128 else small_reference
    solver = Solver(problem, "load", tao_type, 1e-8)
    try:
        result = solver.solve(pstar=0.5)
        assert result.converged, result.reason
        assert result.kkt.load_error <= 1e-8
        assert np.abs(solver.fields()[0] - pressure).max() <= 1e-6 * np.abs(pressure).max()
        assert result.A == load_result.A
    finally:
        solver.destroy()


@pytest.mark.parametrize("tao_type", ["bnls", "bntr"])
def test_newton_types_under_load_control_near_complete_contact(tao_type):
    """The root find's first separations make every node free, where K is singular (K 1 = 0): the Fourier
    preconditioner must stay positive definite there (it broke BNLS/BNTR's Krylov solves: time limit
    at a natural residual of 0.78 on 128^2, p* = 3)."""
    problem = fractal_problem(128, 16, 64, seed=3)
    PETSc.Options().setValue("solve_max_time", 60)
    PETSc.Options().setValue("bound_pc", "fourier")
    solver = Solver(problem, "load", tao_type, 1e-10)
    try:
        result = solver.solve(pstar=3.0)
        assert result.converged, result.reason
        assert result.kkt.natural <= 1e-10 and result.kkt.load_error <= 1e-10
    finally:
        solver.destroy()
        problem.destroy()
        PETSc.Options().delValue("solve_max_time")
        PETSc.Options().delValue("bound_pc")


# TRON: a Newton type, whose inner solves reach 1e-13 on every FFTW plan (BNCG's stop at a floor near
# 2e-10 under some plans, which the root find then reports as such).
@pytest.mark.parametrize("tao_type", ["tron"])
def test_root_find_meets_the_load_near_complete_contact(tao_type):
    """Near complete contact the mean pressure is so steep in d that Brent's bracket reaches round-off
    first (load error 4e-8 with tron before); the solution is affine in d on a fixed contact set, so the
    interpolation between the bracket's solutions meets the load, certified on a fresh gap."""
    problem = fractal_problem(64, 4, 16, seed=5)
    pstar = 0.98 * problem.complete_contact_pbar * problem.pressure_scale / problem.sqrt_m0p
    solver = Solver(problem, "load", tao_type, 1e-10)
    try:
        result = solver.solve(pstar=pstar)
        assert result.converged, result.reason
        assert result.kkt.natural <= 1e-10 and result.kkt.load_error <= 1e-10
        assert result.A > 0.99
    finally:
        solver.destroy()
        problem.destroy()


def test_almm_stops_within_a_line_search_of_its_time_limit(monkeypatch):
    """ALMM's time limit ends its subsolve (a zero gradient did not: the augmented Lagrangian keeps the
    constraint term, and a 1024^2 solve ran 994 operator applications, 100 s, past a 10 s limit)."""
    problem = fractal_problem(256, 16, 64, seed=5)
    at_limit = applications_at_time_limit(monkeypatch, problem)
    PETSc.Options().setValue("solve_max_time", 0.5)
    solver = Solver(problem, "load", "almm", 1e-12)
    try:
        result = solver.solve(pstar=0.98 * problem.complete_contact_pbar * problem.pressure_scale / problem.sqrt_m0p)
        assert not result.converged and "time limit" in result.reason
        assert at_limit and problem.operator.applications - at_limit[0] <= 40  # one line search's evaluations
    finally:
        solver.destroy()
        problem.destroy()
        PETSc.Options().delValue("solve_max_time")
