"""A hand-written slab-decomposed 2-D real FFT pair for several MPI ranks.

Rows of the real array and columns of the half spectrum dealt to the ranks; exchanges ``shared`` (an
MPI-3 shared window) and ``alltoall``. The layout and the two exchanges: docs/runtime.md.
"""

import numpy as np

from ..errors import ParameterError
from ..parallel import block_split, row_split
from .plans import planner_effort


def _shares_memory(comm):
    """True when every rank of ``comm`` is on one shared-memory node."""
    from mpi4py import MPI

    node = comm.Split_type(MPI.COMM_TYPE_SHARED, key=comm.Get_rank())
    try:
        return node.Get_size() == comm.Get_size()
    finally:
        node.Free()


class SlabTransform:
    """2-D real FFT pair over the ranks of an mpi4py communicator, slabs of rows / spectral columns.

    Parameters
    ----------
    grid : surfaces.Grid
        At least one row and one spectral column (``n1 // 2 + 1``) per rank.
    comm : mpi4py.MPI.Comm
    effort : str
        FFTW planner flag.
    exchange : "auto", "shared" or "alltoall"
        ``auto`` takes ``shared`` when all ranks are on one node.
    """

    def __init__(self, grid, comm, effort="FFTW_MEASURE", exchange="auto"):
        import pyfftw

        n0, n1 = grid.shape
        size, rank = comm.Get_size(), comm.Get_rank()
        row_starts, row_counts = row_split(n0, size)
        if n1 // 2 + 1 < size:
            raise ParameterError("n1", f"{n1} columns give {n1 // 2 + 1} spectral columns, fewer than the "
                                       f"{size} MPI ranks that share them")
        if exchange == "auto":
            exchange = "shared" if _shares_memory(comm) else "alltoall"
        if exchange not in ("shared", "alltoall"):
            raise ParameterError("exchange", f"unknown exchange {exchange!r} (auto, shared or alltoall)")
        self.exchange = exchange
        self.comm = comm
        self.shape = (n0, n1)
        half = n1 // 2 + 1
        rows = int(row_counts[rank])
        starts, counts = block_split(half, size)
        c0, c1 = int(starts[rank]), int(starts[rank] + counts[rank])
        self._local_row_count, self._starts, self._counts = rows, starts, counts
        self.local_rows = slice(int(row_starts[rank]), int(row_starts[rank]) + rows)
        self.spectral_slice = (slice(None), slice(c0, c1))
        self._alignment = pyfftw.simd_alignment
        self._window = None

        if exchange == "shared":
            rows_block, self.spectrum = self._shared_spectrum(n0, half, c0, c1)
        else:
            rows_block = pyfftw.empty_aligned((rows, half), dtype="complex128")
            self.spectrum = pyfftw.empty_aligned((n0, c1 - c0), dtype="complex128")
            # Forward: the r2c rows are packed into per-destination blocks (rows, counts[q]) here.
            self._packed = pyfftw.empty_aligned(rows * half, dtype="complex128")
            self._send_counts = rows * counts
            self._send_displs = rows * starts
            # From rank p come its row_counts[p] rows of our columns: rows row_starts[p]... of the slab.
            self._recv_counts = row_counts * (c1 - c0)
            self._recv_displs = row_starts * (c1 - c0)
        self._rows = rows_block
        self.real = pyfftw.empty_aligned((rows, n1), dtype="float64")
        effort = planner_effort(effort)
        flags = (effort,)
        self._r2c = pyfftw.FFTW(self.real, rows_block, axes=(1,), direction="FFTW_FORWARD", flags=flags)
        self._c2r = pyfftw.FFTW(rows_block, self.real, axes=(1,), direction="FFTW_BACKWARD",
                                flags=(effort, "FFTW_DESTROY_INPUT"))
        self._c2c_forward = pyfftw.FFTW(self.spectrum, self.spectrum, axes=(0,), direction="FFTW_FORWARD",
                                        flags=flags)
        self._c2c_backward = pyfftw.FFTW(self.spectrum, self.spectrum, axes=(0,), direction="FFTW_BACKWARD",
                                         flags=flags)
        comm.Barrier()

    def _shared_spectrum(self, n0, half, c0, c1):
        from mpi4py import MPI

        comm = self.comm
        itemsize = np.dtype("complex128").itemsize
        nbytes = n0 * half * itemsize + self._alignment
        # Rank 0 allocates the whole half spectrum; the others map it.
        self._window = MPI.Win.Allocate_shared(nbytes if comm.Get_rank() == 0 else 0, 1, comm=comm)
        memory, _ = self._window.Shared_query(0)
        raw = np.frombuffer(memory, dtype=np.uint8, count=nbytes)
        offset = (-raw.ctypes.data) % self._alignment
        full = raw[offset: offset + n0 * half * itemsize].view("complex128").reshape(n0, half)
        self._window.Lock_all(MPI.MODE_NOCHECK)
        self._full = full
        return full[self.local_rows], full[:, c0:c1]

    def _synchronise(self):
        """All ranks' writes to the shared spectrum are visible to all (one barrier)."""
        self._window.Sync()
        self.comm.Barrier()
        self._window.Sync()

    def _aligned(self, array):
        return array.ctypes.data % self._alignment == 0

    def forward(self, source):
        """Unnormalised ``rfft2`` of the ``(rows, n1)`` array; returns the local spectral block, valid till the next."""
        if self._aligned(source) and source.flags.c_contiguous:
            self._r2c.update_arrays(source, self._rows)
        else:
            self.real[...] = source
            self._r2c.update_arrays(self.real, self._rows)
        self._r2c.execute()
        if self.exchange == "shared":
            self._synchronise()
        else:
            self._alltoall_forward()
        self._c2c_forward.execute()
        return self.spectrum

    def backward(self, target):
        """Unnormalised ``irfft2`` of the local spectral block (destroyed) into the ``(rows, n1)`` target."""
        self._c2c_backward.execute()
        if self.exchange == "shared":
            self._synchronise()
        else:
            self._alltoall_backward()
        direct = self._aligned(target) and target.flags.c_contiguous
        self._c2r.update_arrays(self._rows, target if direct else self.real)
        self._c2r.execute()
        if not direct:
            target[...] = self.real

    def filter(self, source, target, symbol):
        """``target = irfft2(symbol * rfft2(source))``, unnormalised; ``symbol`` real, per float of the local block."""
        spectrum = self.forward(source)
        spectrum.view(np.float64).__imul__(symbol)
        self.backward(target)

    def _blocks(self):
        """Per destination rank: its block of the packed buffer, ``(rows, columns)``, and its column slice."""
        rows = self._local_row_count
        for start, count in zip(self._starts, self._counts):
            yield (self._packed[rows * start: rows * (start + count)].reshape(rows, count),
                   slice(start, start + count))

    def _alltoall_forward(self):
        from mpi4py import MPI

        for block, columns in self._blocks():
            block[...] = self._rows[:, columns]
        self.comm.Alltoallv([self._packed, (self._send_counts, self._send_displs), MPI.C_DOUBLE_COMPLEX],
                            [self.spectrum, (self._recv_counts, self._recv_displs), MPI.C_DOUBLE_COMPLEX])

    def _alltoall_backward(self):
        from mpi4py import MPI

        self.comm.Alltoallv([self.spectrum, (self._recv_counts, self._recv_displs), MPI.C_DOUBLE_COMPLEX],
                            [self._packed, (self._send_counts, self._send_displs), MPI.C_DOUBLE_COMPLEX])
        for block, columns in self._blocks():
            self._rows[:, columns] = block

    def destroy(self):
        if self._window is not None:
            self.comm.Barrier()
            self._full = self._rows = self.spectrum = None
            self._r2c = self._c2r = self._c2c_forward = self._c2c_backward = None
            self._window.Unlock_all()
            self._window.Free()
            self._window = None
