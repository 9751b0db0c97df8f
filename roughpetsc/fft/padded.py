"""The real FFT pair on the zero-padded 2 n0 x 2 n1 grid of a free boundary, on one or several ranks.

On several ranks the rows of the n0 x n1 field and those of the padded grid are distributed differently:
:class:`RowExchange` moves rows between the two decompositions.
"""

import numpy as np

from ..parallel import row_split
from ..surface.grid import Grid
from .plans import planner_effort
from .slab import SlabTransform


def _overlaps(starts_a, counts_a, starts_b, counts_b):
    """Rows shared by each block of split ``a`` with each block of split ``b``: an (a, b) matrix of counts."""
    ends_a, ends_b = starts_a + counts_a, starts_b + counts_b
    low = np.maximum(starts_a[:, None], starts_b[None, :])
    high = np.minimum(ends_a[:, None], ends_b[None, :])
    return np.maximum(high - low, 0)


class RowExchange:
    """Moves rows between two row splits of the same array over MPI (one ``Alltoallv`` each way).

    ``forward``: the grid's split ``a`` into the padded grid's split ``b``; ``backward`` the reverse.
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

    The row transforms run on the ``n0`` rows that carry data: about a quarter less work than the full plan.
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

    The ``filter`` contract of the periodic transforms, on the grid's own local rows (symbol per float of
    the padded grid's local spectral block); padding and the exchange of rows happen inside.
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
