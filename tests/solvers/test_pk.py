"""Polonsky-Keer with and without the Fourier preconditioner, under load and displacement control.

The references are independent algorithms: plain (unpreconditioned) PK and TAO's BLMVM on the
displacement-controlled QP.
"""

import numpy as np
import pytest
from petsc4py import PETSc

from conftest import fractal_problem
from roughpetsc.contact.problem import ContactProblem
from roughpetsc.solvers.facade import Solver
from roughpetsc.surface.grid import Grid
from roughpetsc.surface.generators import fractal


@pytest.fixture(scope="module")
def problem():
    problem = fractal_problem(128, 16, 64)
    yield problem
    problem.destroy()


def solve(problem, control, tao_type, preconditioner, rtol, active_set="bccg", **load):
    PETSc.Options().setValue("pk_pc", preconditioner)
    PETSc.Options().setValue("pk_active_set", active_set)
    solver = Solver(problem, control, tao_type, rtol)
    try:
        result = solver.solve(**load)
        return result, solver.fields()[0].copy()
    finally:
        solver.destroy()
        PETSc.Options().delValue("pk_pc")
        PETSc.Options().delValue("pk_active_set")


# Sparse early contact (small islands) gains least from the Fourier preconditioner.
@pytest.mark.parametrize("pstar, iteration_ratio", [(0.05, 0.9), (0.5, 0.6), (2.0, 0.6)])
def test_preconditioned_load_control_matches_plain_pk_in_fewer_iterations(problem, pstar, iteration_ratio):
    plain, plain_field = solve(problem, "load", None, "none", 1e-10, pstar=pstar)
    fourier, fourier_field = solve(problem, "load", None, "fourier", 1e-10, pstar=pstar)
    assert plain.converged and fourier.converged
    assert fourier.solver == "pk(fourier)" and plain.solver == "pk(none)"
    assert np.abs(fourier_field - plain_field).max() <= 1e-7 * plain_field.max()
    assert fourier.A == plain.A
    assert fourier.gbar == pytest.approx(plain.gbar, rel=1e-8)
    assert fourier.iterations < iteration_ratio * plain.iterations


@pytest.mark.parametrize("control, load", [("load", {"pstar": 0.05}), ("load", {"pstar": 0.5}),
                                           ("displacement", {"gbar": 0.6})])
@pytest.mark.parametrize("preconditioner", ["none", "fourier"])
def test_bccg_active_set_matches_published_pk_in_fewer_iterations(problem, control, load, preconditioner):
    """BCCG and PK's restart rule reach the same solution; BCCG in fewer iterations."""
    if control == "displacement":
        load = {"gbar": load["gbar"] * problem.height_scale}
    published, published_field = solve(problem, control, None, preconditioner, 1e-10, active_set="pk", **load)
    bccg, bccg_field = solve(problem, control, None, preconditioner, 1e-10, active_set="bccg", **load)
    assert published.converged and bccg.converged
    assert np.abs(bccg_field - published_field).max() <= 1e-7 * published_field.max()
    assert bccg.A == published.A
    assert bccg.iterations < published.iterations


@pytest.mark.parametrize("preconditioner", ["none", "fourier"])
def test_displacement_control_matches_blmvm(problem, preconditioner):
    load, _ = solve(problem, "load", None, "fourier", 1e-10, pstar=0.5)
    reference, reference_field = solve(problem, "displacement", "blmvm", "none", 1e-9, gbar=load.separation)
    result, field = solve(problem, "displacement", None, preconditioner, 1e-9, gbar=load.separation)
    assert reference.converged and result.converged
    assert result.kkt.load_error is None and result.kkt.natural <= 1e-9
    assert np.abs(field - reference_field).max() <= 1e-6 * reference_field.max()
    assert result.pstar == pytest.approx(0.5, rel=1e-7)


@pytest.mark.parametrize("option, value", [("pk_pc", "multigrid"), ("pk_active_set", "greedy")])
def test_unknown_choice_is_a_user_error_naming_its_option(problem, option, value):
    from roughpetsc.errors import UserError

    PETSc.Options().setValue(option, value)
    try:
        with pytest.raises(UserError, match=f"-{option}"):
            Solver(problem, "load", None, 1e-8)
    finally:
        PETSc.Options().delValue(option)


def test_fourier_preconditioner_is_symmetric_positive_definite_on_a_free_set():
    """The free-set matrix TAO's PC "mat" applies: assembled column by column on a 16^2 grid."""
    from roughpetsc.solvers.preconditioner import FourierPreconditioner

    grid = Grid(16, 16)
    small = ContactProblem(grid, fractal(grid, 2, 8, 0.8, 2e-4, 5), 1.0, PETSc.COMM_SELF,
                           fft_effort="FFTW_ESTIMATE")
    fourier = FourierPreconditioner(small)
    full = fourier.mat()
    free = PETSc.IS().createGeneral(np.flatnonzero(small.local(small.heights, readonly=True).ravel() > 0)
                                    .astype(PETSc.IntType), comm=PETSc.COMM_SELF)
    sub = full.createSubMatrix(free, free)
    try:
        size = free.getSize()
        x, y = sub.createVecs()
        columns = []
        for j in range(size):
            x.set(0.0)
            x.setValue(j, 1.0)
            x.assemble()
            sub.mult(x, y)
            columns.append(y.getArray().copy())
        dense = np.array(columns).T
        assert np.abs(dense - dense.T).max() <= 1e-12 * np.abs(dense).max()
        assert np.linalg.eigvalsh(dense).min() > 0
    finally:
        for obj in (x, y, sub, free, full, fourier):
            obj.destroy()
        small.destroy()


def test_bnls_with_and_without_the_fourier_preconditioner_agree(problem):
    load, _ = solve(problem, "load", None, "fourier", 1e-10, pstar=0.5)
    fields = {}
    for preconditioner in ("none", "fourier"):
        PETSc.Options().setValue("bound_pc", preconditioner)
        try:
            result, fields[preconditioner] = solve(problem, "displacement", "bnls", "fourier", 1e-9,
                                                   gbar=load.separation)
        finally:
            PETSc.Options().delValue("bound_pc")
        assert result.converged, result.reason
    assert np.abs(fields["fourier"] - fields["none"]).max() <= 1e-6 * fields["none"].max()


def test_load_path_reuses_the_predicted_displacement_and_certifies_every_step(problem):
    """Along a load path PK starts from the predictor's K p (a combination of the kept K p, not a fresh
    FFT pair) and stops without its own fresh confirmation; every step is still certified on a fresh gap
    by the Solver, equals a cold solve, and a failed certificate resumes PK."""
    loads = [0.05, 0.1, 0.15, 0.2]
    solver = Solver(problem, "load", None, 1e-9)
    try:
        for k, pstar in enumerate(loads):
            target = problem.scaled_pbar(None, pstar)
            if k >= 1:
                # The start's K p from the predictor equals a fresh K p of the start (probed on copies).
                path = solver.path
                pressure, previous = path.pressure, path.previous
                path.pressure = pressure.copy()
                path.previous = previous.copy() if previous is not None else None
                predicted = path.load_start(target)
                assert predicted is not None
                fresh = problem.vec()
                problem.operator.displacement(path.pressure, fresh)
                scale = np.abs(problem.local(fresh)).max()
                assert np.abs(problem.local(predicted) - problem.local(fresh)).max() <= 1e-12 * scale
                for v in (fresh, path.pressure, path.previous):
                    if v is not None:
                        v.destroy()
                path.pressure, path.previous = pressure, previous
            warm = solver.solve(pstar=pstar)
            assert warm.converged and warm.kkt.natural <= 1e-9
            cold, cold_field = solve(problem, "load", None, "fourier", 1e-9, pstar=pstar)
            field = solver.fields()[0]
            assert np.abs(field - cold_field).max() <= 1e-6 * cold_field.max()
            assert warm.gbar == pytest.approx(cold.gbar, rel=1e-7)
        # A certificate that fails (here forced by a perturbed stop) resumes PK to a certified result.
        backend_solve, calls = solver.backend.solve, []

        def counted(target, pressure, guess):
            calls.append(target)
            return backend_solve(target, pressure, guess)

        def perturbed(target, pressure, guess):
            outcome = counted(target, pressure, guess)
            solver.backend.solve = counted
            problem.local(pressure)[...] *= 1.0 + 1e-3 * (problem.local(problem.heights, readonly=True) > 0)
            return outcome

        solver.backend.solve = perturbed
        result = solver.solve(pstar=0.25)
        assert len(calls) == 2 and result.converged and result.kkt.natural <= 1e-9
    finally:
        solver.destroy()
