"""The second-order half of the adhesive certificate against dense eigen-solves of the Hessian with numpy."""

import numpy as np
import pytest

from roughpetsc.contact import AdhesiveProblem
from roughpetsc.contact.curvature import TOLERANCE, least_curvature, longest_wave_stiffness
from roughpetsc.contact.laws import Dugdale, Exponential
from roughpetsc.contact.problem import ContactProblem
from roughpetsc.solvers import Solver
from roughpetsc.surface.generators import fractal
from roughpetsc.surface.grid import Grid

N, E_STAR = 24, 1.0


def dense_curvatures(law, gap):
    """``(least, nu, relaxed)`` on zero-mean vectors of the free nodes, in the units of the input (L = 1), with dense
    matrices S = F^-1 pi E* |k| F and C = F^-1 (pi E* |k|)^-1 F (0 at k = 0): the least eigenvalue over pi E* of the
    Hessian H = S + diag phi''(g); the least eigenvalue nu of C H; and 1 - TOLERANCE - the largest eigenvalue of
    a C a on the free nodes, a = max(-phi'', 0)^(1/2) (the certificate's bounds)."""
    k0 = np.fft.fftfreq(N, 1.0 / N)
    k = np.hypot(*np.meshgrid(k0, k0, indexing="ij")).ravel()
    fourier = np.fft.fft(np.fft.fft(np.eye(N * N).reshape(N * N, N, N), axis=1), axis=2).reshape(N * N, N * N)

    def dense(symbol):
        return (fourier.conj().T @ (symbol[:, None] * fourier)).real / (N * N)

    stiffness = dense(np.pi * E_STAR * k)
    compliance = dense(np.divide(1.0, np.pi * E_STAR * k, out=np.zeros_like(k), where=k > 0))
    free = gap.ravel() > 0
    hessian = stiffness[np.ix_(free, free)] + np.diag(law.curvature(gap.ravel()[free]))
    basis = np.linalg.qr(np.vstack([np.ones(free.sum()), np.eye(free.sum())[:-1]]).T)[0][:, 1:]  # zero mean
    hessian = basis.T @ hessian @ basis
    preconditioned = basis.T @ compliance[np.ix_(free, free)] @ basis @ hessian
    weight = np.sqrt(np.maximum(-law.curvature(gap.ravel()[free]), 0.0))
    relaxed = 1.0 - TOLERANCE - np.linalg.eigvalsh(weight[:, None] * compliance[np.ix_(free, free)] * weight)[-1]
    return np.linalg.eigvalsh(hessian)[0] / (np.pi * E_STAR), np.linalg.eigvals(preconditioned).real.min(), relaxed


@pytest.fixture(scope="module")
def problem():
    grid = Grid(N, N, 1.0, 1.0)
    contact = ContactProblem(grid, fractal(grid, 2, 6, 0.8, 1e-2, seed=3), E_STAR, fft_effort="FFTW_ESTIMATE")
    yield contact
    contact.destroy()


# The first two exponential laws take the relaxed bound, the third the eigenvalue of C H (relaxed bound -0.03).
@pytest.mark.parametrize("law, gbar", [(Exponential(5e-5, 1e-3), 7e-3), (Exponential(2e-5, 1e-4), 4e-3),
                                       (Exponential(2e-4, 1e-3), 7e-3), (Dugdale(5e-5, 5e-2), 7e-3)])
def test_the_least_curvature_of_a_solution_is_that_of_the_dense_hessian(problem, law, gbar):
    adhesive = AdhesiveProblem(problem, law)
    solver = Solver(adhesive, "displacement", rtol=1e-10)
    try:
        result = solver.solve(gbar=gbar)
        _, gap = solver.fields()
        assert result.converged, result.reason
        assert 0 < result.A < 1
        least, nu, relaxed = dense_curvatures(law, gap)
        if law.name == "dugdale":  # phi'' = 0 off the kink: the bound 1 <= the least curvature certifies
            assert result.kkt.min_curvature == 1.0 <= least
        else:
            # Clear of the switch between the two bounds, so that the one taken is known.
            assert abs(relaxed) > 2 * TOLERANCE
            assert result.kkt.min_curvature == pytest.approx(relaxed if relaxed > 0 else nu, abs=TOLERANCE)
            assert 0 < nu <= least and relaxed <= least
        assert result.energy == pytest.approx(adhesive.energy_of(gap) * problem.pressure_scale
                                              * problem.height_scale, rel=1e-12)
    finally:
        solver.destroy()


def test_a_negative_curvature_is_found(problem):
    """A gap with many nodes deep in a strong exponential law's range: a saddle, not a minimum."""
    law = Exponential(1e-4, 1e-4)
    adhesive = AdhesiveProblem(problem, law)
    gap = np.where(np.arange(N * N).reshape(N, N) % 3 == 0, 0.0, 5e-5) / problem.height_scale
    value, how = least_curvature(adhesive, gap, longest_wave_stiffness(adhesive))
    least, nu, relaxed = dense_curvatures(law, gap * problem.height_scale)
    assert how.startswith("Krylov-Schur") and least < -1 and nu < -TOLERANCE and relaxed < 0
    assert value == pytest.approx(nu, abs=TOLERANCE)
