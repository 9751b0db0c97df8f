"""The Westergaard shell Mat against a direct numpy evaluation of (3.33)."""

import numpy as np
from petsc4py import PETSc

from roughpetsc.surface.grid import Grid
from roughpetsc.elastic.westergaard import Westergaard


def reference_displacement(grid, pressure, E_star):
    k0, k1 = grid.rfft_wavenumbers()
    k = np.hypot(k0, k1)
    with np.errstate(divide="ignore"):
        symbol = np.where(k > 0, 1.0 / (np.pi * E_star * k), 0.0)
    return np.fft.irfft2(np.fft.rfft2(pressure) * symbol, s=grid.shape)


def test_shell_mat_matches_direct_fft_and_removes_the_mean():
    grid = Grid(48, 64, 0.75, 1.0)
    operator = Westergaard(grid, 3.0, PETSc.COMM_SELF, effort="FFTW_ESTIMATE")
    x, y = operator.vec(), operator.vec()
    pressure = np.random.default_rng(3).random(grid.shape) + 5.0
    operator.local(x)[...] = pressure
    mat = operator.mat()
    try:
        mat.mult(x, y)
        expected = reference_displacement(grid, pressure, 3.0)
        assert np.abs(operator.local(y, True) - expected).max() <= 1e-14 * np.abs(expected).max()
        assert abs(operator.local(y, True).mean()) < 1e-15 * np.abs(expected).max()
        # Symmetric: x'(K z) = z'(K x).
        z, kz = operator.vec(), operator.vec()
        z.setRandom()
        mat.mult(z, kz)
        assert abs(x.dot(kz) - z.dot(y)) <= 1e-12 * abs(x.dot(kz))
        # Its diagonal is the mean of the symbol: K e_0 at node 0.
        unit = operator.vec()
        unit.set(0.0)
        operator.local(unit)[0, 0] = 1.0
        mat.mult(unit, z)
        assert abs(operator.local(z, True)[0, 0] - operator.diagonal) < 1e-14 * operator.diagonal
    finally:
        mat.destroy()


def test_single_mode_has_the_analytic_displacement():
    """p = cos(2 pi x / lambda) gives w = p / (pi E* / lambda) (Johnson 1985, Westergaard)."""
    grid = Grid(4, 128, 4 / 128, 1.0)
    operator = Westergaard(grid, 2.0, PETSc.COMM_SELF, effort="FFTW_ESTIMATE")
    _, x = grid.coordinates()
    wavelength = 1.0 / 8
    pressure = np.broadcast_to(np.cos(2 * np.pi * x / wavelength), grid.shape)
    p, w = operator.vec(), operator.vec()
    operator.local(p)[...] = pressure
    operator.displacement(p, w)
    assert np.allclose(operator.local(w, True), pressure * wavelength / (np.pi * 2.0), rtol=0, atol=1e-15)
