"""Love's influence coefficients (3.31) of the non-periodic half-space, applied by FFT on a padded grid.

A uniform pressure on one rectangular element ``dx x dy`` of the surface of an elastic half-space
(no periodic images) displaces the surface point at offsets ``(R, S)`` from the element's centre by
``K(R, S) / (pi E*)`` per unit pressure, (3.30)-(3.31) of the dissertation (Love 1929). The sum (3.30)
over an ``n0 x n1`` grid is a linear (not circular) convolution; embedded in a ``2 n0 x 2 n1``
circulant (zero padding of the pressure, the kernel laid out with its negative offsets wrapped: the
Hockney / DC-FFT construction), it becomes one real FFT pair of twice the size in each direction.
"""

import numpy as np
from petsc4py import PETSc

from ..fft.padded import PaddedTransform
from .operator import FilterOperator, per_float
from .westergaard import periodic_transform, stiffness_symbol


def _primitive(a, b):
    """``a asinh(b / a) + b asinh(a / b)``, the double integral of 1/r; 0 where a factor is 0.

    The form with ``asinh`` replaces (3.31)'s logarithms of ratios: it is the same function
    (``ln(y + sqrt(x^2 + y^2)) = asinh(y / |x|) + ln|x|``, the ``ln|x|`` cancelling in each ratio)
    but does not lose digits to cancellation far from the element.
    """
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    with np.errstate(divide="ignore", invalid="ignore"):
        first = np.where(a != 0.0, a * np.arcsinh(b / np.where(a != 0.0, np.abs(a), 1.0)), 0.0)
        second = np.where(b != 0.0, b * np.arcsinh(a / np.where(b != 0.0, np.abs(b), 1.0)), 0.0)
    return first + second


def influence(offset_x, offset_y, dx, dy):
    """Love's coefficient ``K_rs`` of (3.31) (length units) for offsets from an element's centre.

    Parameters
    ----------
    offset_x, offset_y : array_like
        Offsets ``R``, ``S`` of the field point from the loaded element's centre (length units,
        any sign; the coefficient is even in each).
    dx, dy : float
        Element sizes.

    Returns
    -------
    ndarray
        ``K`` such that the normal surface displacement is ``K p / (pi E*)`` for a uniform pressure
        ``p`` on the element: the integral of ``1 / r`` over the element.
    """
    r = np.abs(np.asarray(offset_x, float))
    s = np.abs(np.asarray(offset_y, float))
    hx, hy = 0.5 * dx, 0.5 * dy
    return (_primitive(r + hx, s + hy) - _primitive(r + hx, s - hy)
            - _primitive(r - hx, s + hy) + _primitive(r - hx, s - hy))


def circulant_kernel(n0, n1, dy, dx):
    """The ``(2 n0, 2 n1)`` circulant embedding of the influence coefficients of an ``n0 x n1`` grid.

    Index ``(i, j)`` holds the coefficient of the offset ``(i, j)`` rows/columns for ``i < n0`` and of
    ``i - 2 n0`` for ``i > n0`` (likewise ``j``); the offset ``n0`` (``n1``) never occurs between two
    nodes of the grid and is left 0.
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
    """The real ``rfft2`` symbol of the free-boundary compliance on the padded grid.

    ``w = crop(irfft2(symbol * rfft2(pad(p))))`` is (3.30) with the coefficients (3.31): the kernel is
    even in both offsets, so its transform is real (the imaginary part is round-off and dropped).
    The ``1 / (4 n0 n1)`` of the unnormalised FFT pair is folded in.
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

    The counterpart of :class:`roughpetsc.westergaard.Westergaard` for a free (non-periodic)
    boundary: the same Vec layout, ``displacement``, ``stiffness`` and ``mat``, applied through
    :class:`PaddedTransform` (one FFT pair of the padded grid per application, four times the
    points of the periodic one). The displacement has no zero-mean property: the mean gap is not
    the rigid separation.

    The preconditioner's ``stiffness`` is the periodic stiffness ``pi E* max(|k|, 1 / 2L)`` of the
    doubled cell applied to the zero-padded field and cropped: the inverse of the compliance of a
    cell twice as large, which the free compliance approaches away from the edges of the loaded region.
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
        """``out = F^-1[pi E* |k| F[heights]]`` on the periodic cell: p_c of (2.47), a statistic of the surface.

        p* is measured with it on either boundary. The free boundary has no FFT pair of the cell itself: one
        is made for this call and released.
        """
        transform = periodic_transform(self.grid, self.comm, self.threads, self.effort)
        try:
            symbol = stiffness_symbol(self.grid, self.E_star, transform.spectral_slice)
            self._filter_with(transform, self.local(heights, readonly=True), self.local(out), symbol)
        finally:
            if hasattr(transform, "destroy"):
                transform.destroy()
