"""The hand-written slab FFT pair (roughpetsc.slab) against numpy's rfft2/irfft2 on 1 to 4 ranks.

The grids include row counts that the ranks do not divide (the uneven slab
path: the first ``n0 % size`` ranks own one extra row) and spectral column
counts that they do not divide.
"""

import os
import sys

import numpy as np
import pytest

from roughpetsc.errors import ParameterError
from roughpetsc.fft.slab import SlabTransform
from roughpetsc.parallel import block_split, row_split
from roughpetsc.surface.grid import Grid

from conftest import MPI_ENV, ROOT, run_process

# Run under mpiexec: every rank checks its part against numpy on the whole array.
DRIVER = r"""
import sys
import numpy as np
import petsc4py
petsc4py.init(sys.argv[:1])
import pyfftw
from mpi4py import MPI
from petsc4py import PETSc
from roughpetsc.fft.slab import SlabTransform
from roughpetsc.parallel import row_split
from roughpetsc.surface.grid import Grid
from roughpetsc.elastic.westergaard import Westergaard

world = MPI.COMM_WORLD
size, rank = world.Get_size(), world.Get_rank()
# The row blocks are PETSc's own split (PETSC_DECIDE) of n0 items, and the operator's Vecs
# (explicit local sizes) are owned exactly by those row blocks.
for n0, n1 in ((62, 64), (66, 10), (13, 8), (64, 64)):
    starts, counts = row_split(n0, size)
    first, last = int(starts[rank]), int(starts[rank] + counts[rank])
    decided = PETSc.Vec().createMPI(n0, comm=PETSc.COMM_WORLD)
    assert decided.getOwnershipRange() == (first, last), (decided.getOwnershipRange(), first, last)
    decided.destroy()
    operator = Westergaard(Grid(n0, n1), 1.0, PETSc.COMM_WORLD, effort="FFTW_ESTIMATE")
    assert operator.local_rows == slice(first, last)
    v = operator.vec()
    assert v.getOwnershipRange() == (first * n1, last * n1) and v.getSize() == n0 * n1
    v.destroy()
    operator.destroy()
# On 4 ranks also two groups of 2 (as an ensemble splits the ranks): each group transforms on its own.
comms = [world] + ([world.Split(world.Get_rank() // 2, world.Get_rank())] if world.Get_size() == 4 else [])
worst = 0.0
for comm, exchange in [(c, e) for c in comms for e in ("shared", "alltoall")]:
    for shape, lengths in (((8, 8), (1.0, 1.0)), ((16, 10), (1.0, 2.0)), ((12, 9), (1.0, 1.0)),
                           ((64, 96), (0.75, 1.0)), ((256, 256), (1.0, 1.0)), ((32, 6), (1.0, 1.0)),
                           ((62, 64), (1.0, 1.0)), ((66, 64), (1.0, 1.0)), ((13, 11), (1.3, 1.0)), ((5, 8), (1.0, 1.0))):
        grid = Grid(*shape, *lengths)
        transform = SlabTransform(grid, comm, "FFTW_ESTIMATE", exchange)
        rows, spectral = transform.local_rows, transform.spectral_slice
        # Every row and every spectral column is owned by exactly one rank.
        assert comm.allreduce(rows.stop - rows.start) == shape[0]
        assert comm.allreduce(spectral[1].stop - spectral[1].start) == shape[1] // 2 + 1
        x = np.random.default_rng(7).standard_normal(shape) + 3.0
        X = np.fft.rfft2(x)
        # The symbol as roughpetsc.westergaard builds it from spectral_slice.
        k0, k1 = grid.rfft_wavenumbers(spectral[0])
        k = np.hypot(k0, k1[:, spectral[1]])
        with np.errstate(divide="ignore"):
            symbol = np.where(k > 0, 1.0 / (np.pi * k), 0.0)
        full_k = np.hypot(*grid.rfft_wavenumbers())
        with np.errstate(divide="ignore"):
            full_symbol = np.where(full_k > 0, 1.0 / (np.pi * full_k), 0.0)
        expected = np.fft.irfft2(X * full_symbol, s=shape)
        scale_x, scale_X, scale_e = abs(x).max(), abs(X).max(), abs(expected).max()
        # Sources and targets: aligned and contiguous, misaligned, and strided views.
        padded = pyfftw.empty_aligned(x[rows].size + 1)
        misaligned = padded[1:].reshape(x[rows].shape)
        wide = np.zeros((x[rows].shape[0], shape[1] * 2))
        for source_kind in range(3):
            local = pyfftw.empty_aligned(x[rows].shape)
            local[...] = x[rows]
            source = (local, misaligned, wide[:, ::2])[source_kind]
            source[...] = x[rows]
            spectrum = transform.forward(source)
            worst = max(worst, abs(spectrum - X[spectral]).max() / scale_X)
            assert np.array_equal(source, x[rows])                  # the source is kept
            spectrum *= 1.0 / grid.size
            target = (pyfftw.empty_aligned(x[rows].shape), misaligned, wide[:, 1::2])[(source_kind + 1) % 3]
            transform.backward(target)
            worst = max(worst, abs(target - x[rows]).max() / scale_x)
            source[...] = x[rows]
            transform.filter(source, target, np.repeat(symbol / grid.size, 2, axis=1))
            worst = max(worst, abs(target - expected[rows]).max() / scale_e)
        transform.destroy()
automatic = SlabTransform(Grid(8, 8), world, "FFTW_ESTIMATE")
assert automatic.exchange == "shared"                        # mpiexec on one machine: one node
automatic.destroy()
worst = world.allreduce(worst, op=MPI.MAX)
if world.Get_rank() == 0:
    print(f"worst {worst:.3e}")
sys.exit(0 if worst <= 1e-12 else 1)
"""


def run_driver(ranks, tmp_path):
    driver = tmp_path / "slab_driver.py"
    driver.write_text(DRIVER)
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    command = ["mpiexec", "-n", str(ranks), "--oversubscribe", sys.executable, str(driver)]
    return run_process(command, env=env, cwd=ROOT)


@pytest.mark.mpi
@pytest.mark.slow
@pytest.mark.parametrize("ranks", [1, 2, 3, 4])
def test_slab_pair_matches_numpy(ranks, tmp_path):
    done = run_driver(ranks, tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "worst" in done.stdout


def test_block_split_is_balanced():
    starts, counts = block_split(1025, 2)
    assert list(counts) == [513, 512] and list(starts) == [0, 513]
    starts, counts = block_split(6, 4)
    assert list(counts) == [2, 2, 1, 1] and list(starts) == [0, 2, 4, 5]
    starts, counts = row_split(62, 3)
    assert list(counts) == [21, 21, 20] and list(starts) == [0, 21, 42]


@pytest.mark.mpi
def test_fewer_rows_than_ranks_is_refused_by_name():
    with pytest.raises(ParameterError, match="fewer than the 4 MPI ranks") as refused:
        row_split(3, 4)
    assert refused.value.parameter == "n0"


def test_one_rank_in_process_and_bad_sizes():
    from mpi4py import MPI

    grid = Grid(16, 12)
    transform = SlabTransform(grid, MPI.COMM_SELF, "FFTW_ESTIMATE")
    try:
        x = np.random.default_rng(1).random(grid.shape)
        assert transform.local_rows == slice(0, 16)
        assert np.abs(transform.forward(x) - np.fft.rfft2(x)).max() <= 1e-13 * np.abs(x).sum()
    finally:
        transform.destroy()
    with pytest.raises(ValueError):
        SlabTransform(Grid(16, 12), MPI.COMM_SELF, "FFTW_ESTIMATE", exchange="ring")
