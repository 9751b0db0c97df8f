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

from .slab import SlabTransform, row_split
from .surfaces import Grid
from .fftw import planner_effort
from .westergaard import FilterOperator, per_float


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


def _overlaps(starts_a, counts_a, starts_b, counts_b):
    """Rows shared by each block of split ``a`` with each block of split ``b``: an (a, b) matrix of counts."""
    ends_a, ends_b = starts_a + counts_a, starts_b + counts_b
    low = np.maximum(starts_a[:, None], starts_b[None, :])
    high = np.minimum(ends_a[:, None], ends_b[None, :])
    return np.maximum(high - low, 0)


class RowExchange:
    """Moves rows between two row splits of the same array over MPI (one ``Alltoallv`` each way).

    ``forward`` sends this rank's rows of split ``a`` (the grid's ``n0`` rows) into its rows of
    split ``b`` (the first ``n0`` of the padded grid's ``2 n0`` rows); ``backward`` the reverse.
    Only ``columns`` columns travel.
    """

    def __init__(self, comm, split_a, split_b, columns):
        rank = comm.Get_rank()
        shared = _overlaps(*split_a, *split_b)
        self.comm = comm
        self.columns = columns
        self.send_counts = shared[rank, :] * columns
        self.recv_counts = shared[:, rank] * columns
        self.send_displs = np.concatenate(([0], np.cumsum(self.send_counts)[:-1]))
        self.recv_displs = np.concatenate(([0], np.cumsum(self.recv_counts)[:-1]))
        self.rows_a = int(split_a[1][rank])
        first_b, count_b = int(split_b[0][rank]), int(split_b[1][rank])
        # Received rows arrive in rank order, i.e. in row order: they fill this rank's rows of split b
        # from its first row on, as far as the data rows (< n0) reach.
        self.rows_b = int(self.recv_counts.sum() // columns) if columns else 0
        self.first_b, self.count_b = first_b, count_b

    def forward(self, source, target):
        """``source``: (rows_a, columns) array; ``target``: (count_b, >= columns), filled in its first rows."""
        from mpi4py import MPI

        received = np.empty((self.rows_b, self.columns))
        self.comm.Alltoallv([np.ascontiguousarray(source), (self.send_counts, self.send_displs), MPI.DOUBLE],
                            [received, (self.recv_counts, self.recv_displs), MPI.DOUBLE])
        target[:self.rows_b, :self.columns] = received

    def backward(self, source, target):
        """The inverse: ``source`` (count_b, >= columns) rows back into ``target`` (rows_a, columns)."""
        from mpi4py import MPI

        sent = np.ascontiguousarray(source[:self.rows_b, :self.columns])
        received = np.empty((self.rows_a, self.columns))
        self.comm.Alltoallv([sent, (self.recv_counts, self.recv_displs), MPI.DOUBLE],
                            [received, (self.send_counts, self.send_displs), MPI.DOUBLE])
        target[...] = received


class PrunedPaddedTransform:
    """The zero-padded ``2 n0 x 2 n1`` FFT pair on one rank, pruned to the quarter that holds the field.

    The field occupies rows and columns ``[0, n0) x [0, n1)`` of the padded grid and only that block
    of the result is kept, so the row transforms (along axis 1) run on the ``n0`` rows that carry data,
    forward and backward, instead of all ``2 n0``: about a quarter less work than the full 2-D plan,
    with the same result. Four pyFFTW plans made once (real rows, complex columns, each way).
    """

    def __init__(self, padded, threads, effort):
        import pyfftw

        effort = planner_effort(effort)
        rows, columns = padded.n0 // 2, padded.n1
        self.rows, self.n1 = rows, columns // 2
        self.row_buffer = pyfftw.zeros_aligned((rows, columns), dtype="float64")  # right half stays 0
        self.spectrum = pyfftw.empty_aligned((padded.n0, columns // 2 + 1), dtype="complex128")
        half = self.spectrum[:rows]
        flags = (effort,)
        self._rows_forward = pyfftw.FFTW(self.row_buffer, half, axes=(1,), flags=flags, threads=threads)
        self._columns_forward = pyfftw.FFTW(self.spectrum, self.spectrum, axes=(0,), flags=flags, threads=threads)
        self._columns_backward = pyfftw.FFTW(self.spectrum, self.spectrum, axes=(0,), direction="FFTW_BACKWARD",
                                             flags=flags, threads=threads)
        self._rows_backward = pyfftw.FFTW(half, self.row_buffer, axes=(1,), direction="FFTW_BACKWARD",
                                          flags=(effort, "FFTW_DESTROY_INPUT"), threads=threads)
        self.local_rows = slice(0, rows)
        self.spectral_slice = (slice(None), slice(None))

    def filter(self, source, target, symbol):
        """``target = crop(irfft2(symbol * rfft2(pad(source))))`` (unnormalised, as SerialTransform.filter)."""
        self.row_buffer[:, :self.n1] = source
        self.row_buffer[:, self.n1:] = 0.0
        self._rows_forward.execute()
        self.spectrum[self.rows:] = 0.0
        self._columns_forward.execute()
        self.spectrum.view(np.float64).__imul__(symbol)
        self._columns_backward.execute()
        self._rows_backward.execute()
        target[...] = self.row_buffer[:, :self.n1]


class PaddedTransform:
    """Linear convolution of a grid's field by FFT on the zero-padded ``2 n0 x 2 n1`` grid.

    The same ``filter(source, target, symbol)`` contract as the periodic transforms (real symbol
    per float of the local spectral block of the padded grid, normalisation folded in), on the
    grid's own local rows: the padding, and on several ranks the move of rows between the grid's
    split and the padded grid's split, happen inside.
    """

    def __init__(self, grid, comm, threads, effort):
        import pyfftw

        n0, n1 = grid.shape
        padded = Grid(2 * n0, 2 * n1, 2 * grid.l0, 2 * grid.l1)
        self.padded_grid = padded
        self.n1 = n1
        size = comm.Get_size()
        if size == 1:
            self.inner = PrunedPaddedTransform(padded, threads, effort)
            self.exchange = None
            self.local_rows = slice(0, n0)
        else:
            mpi = comm.tompi4py()
            self.inner = SlabTransform(padded, mpi, effort)
            split_grid, split_padded = row_split(n0, size), row_split(2 * n0, size)
            self.exchange = RowExchange(mpi, split_grid, split_padded, n1)
            rank = mpi.Get_rank()
            start = int(split_grid[0][rank])
            self.local_rows = slice(start, start + int(split_grid[1][rank]))
        self.spectral_slice = self.inner.spectral_slice
        rows = self.inner.local_rows
        if self.exchange is not None:
            self.buffer = pyfftw.zeros_aligned((rows.stop - rows.start, 2 * n1), dtype="float64")

    def filter(self, source, target, symbol):
        if self.exchange is None:
            self.inner.filter(source, target, symbol)  # pads and crops itself
            return
        buffer = self.buffer
        buffer[...] = 0.0
        self.exchange.forward(source, buffer)
        self.inner.filter(buffer, buffer, symbol)
        self.exchange.backward(buffer, target)

    def destroy(self):
        if hasattr(self.inner, "destroy"):
            self.inner.destroy()


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

    def __init__(self, grid, E_star, comm=None, threads=1, effort="FFTW_MEASURE"):
        comm = comm or PETSc.COMM_WORLD
        self.E_star = float(E_star)
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
