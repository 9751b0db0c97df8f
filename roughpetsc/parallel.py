"""MPI bookkeeping every layer shares: reductions of local sums, the split of grid rows over ranks, row exchange,
and the collective destroy at exit of the PETSc objects with Python callbacks.

A field of the grid is distributed by rows (PETSc's ownership ranges, the slab of the FFT); every rank
owns at least one row.
"""

import atexit
import gc
import weakref

import numpy as np

from .errors import ParameterError

# The PETSc objects with Python callbacks not yet destroyed, in the order of their (collective) creation.
_with_callbacks = []


def destroyed_at_exit(obj):
    """``obj``, a PETSc object with Python callbacks or context, destroyed at exit if the script did not.

    petsc4py defers the destruction of a collected parallel object to PetscFinalize, which runs after the
    interpreter has gone; the destroy of a TAO or MATPYTHON releases its Python context and callbacks there,
    and the process dies of SIGSEGV at exit.
    """
    _with_callbacks[:] = [reference for reference in _with_callbacks if reference() is not None]
    _with_callbacks.append(weakref.ref(obj))
    return obj


@atexit.register
def _destroy_objects_with_callbacks():
    """Every rank destroys in reverse creation order (destroys are collective), then empties PETSc's garbage of
    the ones already collected, while the interpreter still runs."""
    from petsc4py import PETSc

    for reference in reversed(_with_callbacks):
        obj = reference()
        if obj is not None:
            obj.destroy()
    _with_callbacks.clear()
    gc.collect()
    PETSc.garbage_cleanup()


def _allreduce(comm, values, operation):
    local = np.asarray(values, dtype=np.float64)
    if comm.Get_size() == 1:
        return local
    from mpi4py import MPI

    total = np.empty_like(local)
    comm.Allreduce(local, total, op=getattr(MPI, operation))
    return total


def allsum(comm, values):
    """Global sums of a sequence of local floats in one reduction (mpi4py communicator)."""
    return _allreduce(comm, values, "SUM")


def allmin(comm, values):
    """Global minima of a sequence of local floats in one reduction."""
    return _allreduce(comm, values, "MIN")


def allmax(comm, values):
    """Global maxima of a sequence of local floats in one reduction."""
    return _allreduce(comm, values, "MAX")


def block_split(count, size):
    """``(starts, counts)`` of ``count`` items over ``size`` ranks, as PETSc's ``PetscSplitOwnership``.

    Rank ``r`` gets ``count // size + (r < count % size)`` items.
    """
    counts = np.full(size, count // size, dtype=int)
    counts[: count % size] += 1
    starts = np.concatenate(([0], np.cumsum(counts)[:-1])).astype(int)
    return starts, counts


def row_split(n0, size):
    """The row blocks ``(starts, counts)`` of ``n0`` rows on ``size`` ranks; ParameterError if a rank gets none."""
    if n0 < size:
        raise ParameterError("n0", f"the grid has {n0} row(s), fewer than the {size} MPI ranks "
                                   "that share them (every rank needs at least one row)")
    return block_split(n0, size)


def gather_rows(comm, local):
    """The whole array on rank 0 (None elsewhere) from each rank's block of rows (mpi4py ``comm``)."""
    if comm.Get_size() == 1:
        return np.array(local)
    parts = comm.gather(np.ascontiguousarray(local), root=0)
    return np.concatenate(parts, axis=0) if comm.Get_rank() == 0 else None


def allgather_rows(comm, local):
    """The whole array on every rank from each rank's block of rows (mpi4py ``comm``)."""
    if comm.Get_size() == 1:
        return np.array(local)
    return np.concatenate(comm.allgather(np.ascontiguousarray(local)), axis=0)


def next_rank_first_row(comm, rows):
    """The first row of the next rank (periodically): the neighbour below this rank's last row."""
    size, rank = comm.Get_size(), comm.Get_rank()
    if size == 1:
        return rows[0]
    received = np.empty_like(rows[0])
    comm.Sendrecv(np.ascontiguousarray(rows[0]), dest=(rank - 1) % size, recvbuf=received, source=(rank + 1) % size)
    return received
