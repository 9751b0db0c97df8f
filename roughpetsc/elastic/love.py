"""Love's influence coefficients (3.31) of the non-periodic half-space, applied by FFT on a padded grid.

The sum (3.30) over an ``n0 x n1`` grid is a linear convolution; embedded in a ``2 n0 x 2 n1`` circulant
(Hockney / DC-FFT), it becomes one real FFT pair of twice the size in each direction.
"""

import numpy as np
from petsc4py import PETSc

from ..fft.padded import PaddedTransform
from .operator import FilterOperator, per_float
from .westergaard import periodic_transform, stiffness_symbol


def _primitive(a, b):
    """``a asinh(b / a) + b asinh(a / b)``, the double integral of 1/r; 0 where a factor is 0.

    The same function as (3.31)'s logarithms of ratios, without their cancellation far from the element.
    """
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    with np.errstate(divide="ignore", invalid="ignore"):
        first = np.where(a != 0.0, a * np.arcsinh(b / np.where(a != 0.0, np.abs(a), 1.0)), 0.0)
        second = np.where(b != 0.0, b * np.arcsinh(a / np.where(b != 0.0, np.abs(b), 1.0)), 0.0)
    return first + second


def influence(offset_x, offset_y, dx, dy):
    """Love's coefficient ``K_rs`` of (3.31) (length units) at offsets ``(R, S)`` from the centre of a
    ``dx x dy`` element: the surface displacement is ``K p / (pi E*)`` for a uniform pressure p on it."""
    r = np.abs(np.asarray(offset_x, float))
    s = np.abs(np.asarray(offset_y, float))
    hx, hy = 0.5 * dx, 0.5 * dy
    return (_primitive(r + hx, s + hy) - _primitive(r + hx, s - hy)
            - _primitive(r - hx, s + hy) + _primitive(r - hx, s - hy))


def circulant_kernel(n0, n1, dy, dx):
    """The ``(2 n0, 2 n1)`` circulant embedding of the influence coefficients of an ``n0 x n1`` grid.

    Negative offsets wrapped to ``i + 2 n0``; the offset ``n0`` (``n1``), which never occurs, is 0.
    """
    rows = np.arange(2 * n0)
    cols = np.arange(2 * n1)
    rows = np.where(rows <= n0, rows, rows - 2 * n0)
    cols = np.where(cols <= n1, cols, cols - 2 * n1)
    kernel = influence(cols[None, :] * dx, rows[:, None] * dy, dx, dy)
    kernel[n0, :] = 0.0
    kernel[:, n1] = 0.0
    return kernel


def padded_symbol(n0, n1, dy, dx, E_star):
    """The real ``rfft2`` symbol of the free-boundary compliance (3.30) on the padded grid, 1 / (4 n0 n1) folded in.

    The kernel is even in both offsets, so its transform is real.
    """
    kernel = circulant_kernel(n0, n1, dy, dx) / (np.pi * E_star)
    return np.fft.rfft2(kernel).real / (4 * n0 * n1)


def direct_displacement(pressure, dy, dx, E_star):
    """(3.30) summed directly, ``O(n^4)``: the reference that tests the padded FFT on small grids."""
    n0, n1 = pressure.shape
    out = np.zeros_like(pressure, dtype=float)
    rows, cols = np.arange(n0), np.arange(n1)
    for i in range(n0):
        for j in range(n1):
            coefficients = influence((cols - j)[None, :] * dx, (rows - i)[:, None] * dy, dx, dy)
            out[i, j] = np.sum(coefficients * pressure)
    return out / (np.pi * E_star)


class FreeBoundary(FilterOperator):
    """The compliance of an isolated half-space, (3.30)-(3.31), as the operator of a contact problem.

    As :class:`Westergaard`, through :class:`PaddedTransform`; the mean gap is not the rigid separation.
    ``stiffness`` is the periodic ``pi E* max(|k|, 1 / 2L)`` of the doubled cell on the zero-padded field.
    """

    boundary = "free"

    def __init__(self, grid, E_star, comm=None, threads=1, effort="FFTW_MEASURE"):
        comm = comm or PETSc.COMM_WORLD
        self.E_star = float(E_star)
        self.threads, self.effort = threads, effort
        self.transform = PaddedTransform(grid, comm, threads, effort)
        self._set_layout(grid, comm)
        n0, n1 = grid.shape
        dy, dx = grid.l0 / n0, grid.l1 / n1
        block = self.transform.spectral_slice
        padded = self.transform.padded_grid
        k = np.hypot(*padded.rfft_wavenumbers())[block]
        longest = 1.0 / max(padded.l0, padded.l1)
        self.compliance_symbol = per_float(padded_symbol(n0, n1, dy, dx, self.E_star)[block])
        self.preconditioner_symbol = per_float(np.pi * self.E_star * np.maximum(k, longest) / padded.size)
        self._diagonal = float(influence(0.0, 0.0, dx, dy)) / (np.pi * self.E_star)

    @property
    def diagonal(self):
        """The diagonal of the compliance matrix: the self-influence of an element, (3.31) at R = S = 0."""
        return self._diagonal

    def pressure_surface(self, heights, out):
        """``out = F^-1[pi E* |k| F[heights]]`` on the periodic cell: p_c of (2.47), by a transient FFT pair."""
        transform = periodic_transform(self.grid, self.comm, self.threads, self.effort)
        try:
            symbol = stiffness_symbol(self.grid, self.E_star, transform.spectral_slice)
            self._filter_with(transform, self.local(heights, readonly=True), self.local(out), symbol)
        finally:
            if hasattr(transform, "destroy"):
                transform.destroy()
