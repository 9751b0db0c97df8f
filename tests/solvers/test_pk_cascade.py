"""The cascaded PK prototype of issue 39 (studies/pk_cascade.py, a study's solver: serial, not a backend yet).

References: today's Polonsky-Keer (an independent implementation) for the solution; dense eigenvalues
(numpy) for the Lanczos estimates of the spectrum and for the symmetry and definiteness of the edge-band
preconditioner; a direct evaluation of the compliance for the kernel-copy corrections.
"""

import importlib.util
import os

import numpy as np
import pytest
from petsc4py import PETSc

from roughpetsc import ContactProblem, Grid, Solver, fractal

from conftest import ROOT


def load_prototype():
    """studies/pk_cascade.py as a module (the studies are scripts, not a package)."""
    spec = importlib.util.spec_from_file_location("pk_cascade", os.path.join(ROOT, "studies", "pk_cascade.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


pk_cascade = load_prototype()

EFFORT = "FFTW_ESTIMATE"


def make_problem(n):
    grid = Grid(n, n)
    return ContactProblem(grid, fractal(grid, 4, 16, 0.8, 2e-4, 3), 1.0, PETSc.COMM_SELF, fft_effort=EFFORT)


@pytest.fixture(scope="module")
def problem():
    problem = make_problem(64)
    yield problem
    problem.destroy()


def reference(problem, pstar):
    """Today's PK to 1e-12: the scaled pressure."""
    solver = Solver(problem, "load", None, 1e-12)
    try:
        result = solver.solve(pstar=pstar)
        assert result.converged
        return solver.fields()[0].ravel() / problem.pressure_scale
    finally:
        solver.destroy()


def heights(problem):
    return problem.local(problem.heights, readonly=True).copy()


@pytest.mark.parametrize("pstar", [0.05, 0.5, 2.0])
@pytest.mark.parametrize("options", [
    dict(cascade=(), preconditioner="fourier", point_corrections=0),
    dict(cascade="auto", coarsest=16, prolong="signed", preconditioner="band:width=2,radius=1.5,sweeps=4",
         point_corrections=16),
    dict(cascade=(2,), restart_fraction=0.01, prolong="bilinear", restrict="spectral"),
])
def test_cold_solve_matches_todays_pk(problem, pstar, options):
    expected = reference(problem, pstar)
    solver = pk_cascade.CascadePK(heights(problem), effort=EFFORT, **options)
    try:
        result = solver.solve(problem.scaled_pbar(pstar=pstar), 1e-10)
    finally:
        solver.destroy()
    assert result.converged and result.natural <= 1e-10
    assert np.abs(result.pressure - expected).max() <= 1e-7 * expected.max()
    assert np.array_equal(result.pressure > 0, expected > 0)


def dense_operator(level, contact, preconditioner):
    """Dense ``B P K_CC P`` on the zero-sum subspace of C (orthonormal basis Q): Q' B P K P Q, and Q' B Q."""
    free = np.flatnonzero(contact)
    count = free.size
    basis = np.linalg.qr(np.eye(count) - 1.0 / count)[0][:, :count - 1]  # orthonormal, zero sums
    preconditioner.setup(contact)

    def apply(columns, with_k):
        out = []
        full, response, result = (np.zeros(level.size) for _ in range(3))
        for column in columns.T:
            full[...] = 0.0
            full[free] = column
            if with_k:
                level.compliance(full, response)
                pk_cascade.remove_mean_on(response, contact, count)
            else:
                response[...] = full
            preconditioner.apply(response, result, contact, count)
            out.append(result[free])
        return basis.T @ np.array(out).T
    return apply(basis, True), apply(basis, False)


# The band preconditioner makes cond about 1.07 here: CG stops within a few steps, before its top Ritz
# value has converged, so that one is only checked to 1e-3.
@pytest.mark.parametrize("spec, top", [("fourier", 1e-6), ("band:width=2,radius=3.2,sweeps=4", 1e-3)])
def test_lanczos_extremes_match_dense_eigenvalues_and_band_pc_is_spd(spec, top):
    problem = make_problem(32)
    try:
        pbar = problem.scaled_pbar(pstar=0.5)
        contact = reference(problem, 0.5) > 0
        level = pk_cascade.Level(heights(problem), 32, EFFORT)
        preconditioner = pk_cascade.make_preconditioner(level, spec)
        run = pk_cascade.fixed_set_pcg(level, contact, pbar, preconditioner, 1e-8, extra_rtol=1e-13)
        low, high, _ = pk_cascade.lanczos_extremes(run.alphas, run.betas)
        product, pc_matrix = dense_operator(level, contact, preconditioner)
        level.destroy()
    finally:
        problem.destroy()
    assert run.pairs == 2 * run.iterations + 2 and run.certified <= 1e-8
    assert np.abs(pc_matrix - pc_matrix.T).max() <= 1e-10 * np.abs(pc_matrix).max()
    assert np.linalg.eigvalsh(pc_matrix).min() > 0
    eigenvalues = np.sort(np.linalg.eigvals(product).real)
    # Ritz values lie inside the spectrum. The top converges fast; the bottom is a cluster at 1 (the Fourier
    # preconditioner exceeds K_CC^-1 by a matrix of rank <= the number of nodes outside C, so B K - I is
    # singular), which CG resolves only to about its tolerance.
    assert eigenvalues[-1] * (1 - top) <= high <= eigenvalues[-1] * (1 + 1e-12)
    assert eigenvalues[0] - 1e-12 <= low <= eigenvalues[0] * (1 + 1e-3)


def test_fixed_set_pcg_from_a_start_certifies_on_the_exact_set():
    """The warm floor's runs: from today's PK solution the certificate holds at once (the first K p and the
    certificate's, 2 pairs); from that solution perturbed by 10 % node by node CG reaches the tolerance."""
    problem = make_problem(32)
    try:
        pbar = problem.scaled_pbar(pstar=0.5)
        expected = reference(problem, 0.5)
        contact = expected > 0
        level = pk_cascade.Level(heights(problem), 32, EFFORT)
        preconditioner = pk_cascade.make_preconditioner(level, "fourier")
        exact = pk_cascade.fixed_set_pcg(level, contact, pbar, preconditioner, 1e-8, start=expected)
        noise = 1 + 0.1 * np.random.default_rng(5).uniform(-1, 1, expected.size)
        perturbed = pk_cascade.fixed_set_pcg(level, contact, pbar, preconditioner, 1e-8, start=expected * noise)
        level.destroy()
    finally:
        problem.destroy()
    assert exact.iterations == 0 and exact.pairs == 2 and exact.certified <= 1e-8
    assert perturbed.history[0] > 1e-3
    assert perturbed.iterations > 0 and perturbed.certified <= 1e-8


def test_point_responses_equal_the_compliance():
    level = pk_cascade.Level(np.zeros((16, 16)), 16, EFFORT)
    try:
        nodes = np.array([0, 17, 255, 100])
        values = np.array([1.0, -0.5, 2.0, 0.25])
        field = np.zeros(256)
        field[nodes] = values
        expected = np.empty(256)
        level.compliance(field, expected)
        out = np.zeros(256)
        level.add_point_responses(nodes, values, out)
    finally:
        level.destroy()
    assert np.abs(out - expected).max() <= 1e-13 * np.abs(expected).max()


def test_bilinear_prolongation_and_coarsening_factors():
    coarse = np.arange(16.0).reshape(4, 4)
    fine = pk_cascade.prolong_bilinear(coarse)
    assert np.array_equal(fine[::2, ::2], coarse)
    assert fine[1, 1] == pytest.approx(np.mean([coarse[0, 0], coarse[0, 1], coarse[1, 0], coarse[1, 1]]))
    assert fine[7, 7] == pytest.approx(np.mean([coarse[3, 3], coarse[3, 0], coarse[0, 3], coarse[0, 0]]))  # periodic
    assert pk_cascade.coarsening_factors(1024, 256) == (4, 2)
    assert pk_cascade.coarsening_factors(256, 256) == ()
