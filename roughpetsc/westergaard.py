"""The periodic Westergaard operator (3.33) as a matrix-free PETSc shell Mat.

``w = F^-1[ F[p] / (pi E* |k|) ]`` for k != 0; the k = 0 mode carries no
displacement (the mean pressure only moves the body rigidly; docs/conventions.md),
so the mean of ``w`` is zero and the mean gap equals the rigid separation (3.38).

One rank: a direct 2-D FFTW plan (pyFFTW, r2c and c2r, built once with
``FFTW_MEASURE``) that reads the input Vec's memory and writes the output Vec's
memory in place: one r2c, one pointwise product, one c2r per application and no
N^2 copy. Several ranks: the slab transform of :mod:`roughpetsc.slab` (rows of
the real array distributed like PETSc's ownership ranges; on one node the half
spectrum lives in an MPI-3 shared window, so there is no transpose copy). It
replaced mpi4py-fft's PFFT, which was 3.5x slower on 2 ranks here
(studies/output/mpi_speedup.md; the study builds that PFFT pair itself).
"""

import numpy as np
from petsc4py import PETSc

from .errors import ParameterError
from .fftw import planner_effort
from .spectra import rfft_multiplicity

# PETSc log events (-log_view, prefix RP for roughpetsc): the operator applications by kind
# (RPCompliance, RPStiffness), and every FFT pair (r2c, symbol product, c2r) whatever asked for it.
log_event = PETSc.Log.EventDecorator


def wavenumber_modulus(grid, rows=slice(None), cols=slice(None)):
    k0, k1 = grid.rfft_wavenumbers(rows)
    return np.hypot(k0, k1[:, cols])


class SerialTransform:
    """2-D real FFT pair on one rank through pyFFTW plans made once."""

    def __init__(self, grid, threads, effort):
        import pyfftw

        effort = planner_effort(effort)
        shape = grid.shape
        self._alignment = pyfftw.simd_alignment
        self.real = pyfftw.empty_aligned(shape, dtype="float64")
        self.spectrum = pyfftw.empty_aligned((shape[0], shape[1] // 2 + 1), dtype="complex128")
        # Aligned plans run twice as fast as FFTW_UNALIGNED ones here; a Vec whose
        # memory happens to be aligned is used in place, any other goes through
        # self.real (a copy costs a few percent of a transform).
        self._forward = pyfftw.FFTW(self.real, self.spectrum, axes=(0, 1), direction="FFTW_FORWARD",
                                    flags=(effort,), threads=threads)
        self._backward = pyfftw.FFTW(self.spectrum, self.real, axes=(0, 1), direction="FFTW_BACKWARD",
                                     flags=(effort, "FFTW_DESTROY_INPUT"), threads=threads)
        self.local_rows = slice(0, shape[0])
        self.spectral_slice = (slice(None), slice(None))

    def _aligned(self, array):
        return array.ctypes.data % self._alignment == 0

    def filter(self, source, target, symbol):
        """``target = irfft2(symbol * rfft2(source))``, unnormalised (1/N is in the symbol).

        ``symbol`` is real and given per float of the complex spectrum (each
        value twice), so the product is one contiguous real multiply.
        """
        if self._aligned(source):
            self._forward.update_arrays(source, self.spectrum)
        else:
            self.real[...] = source
            self._forward.update_arrays(self.real, self.spectrum)
        self._forward.execute()
        self.spectrum.view(np.float64).__imul__(symbol)
        direct = self._aligned(target)
        self._backward.update_arrays(self.spectrum, target if direct else self.real)
        self._backward.execute()
        if not direct:
            target[...] = self.real


class FilterOperator:
    """A compliance applied as a real Fourier filter: the Vec layout, the shell Mat, the counts.

    What the periodic (:class:`Westergaard`) and the free-boundary
    (:class:`roughpetsc.love.FreeBoundary`) compliances share. A subclass sets ``transform`` (an
    object with ``filter(source, target, symbol)``, ``local_rows`` and ``spectral_slice``), the
    symbols ``compliance_symbol`` and ``preconditioner_symbol`` (real, one value per float of the
    local spectral block, normalisation folded in) and the ``diagonal`` of the compliance matrix,
    then calls :meth:`_set_layout`.

    Attributes
    ----------
    local_rows : slice
        Rows of the real-space grid owned by this rank (PETSc ownership).
    applications : int
        Number of FFT pairs so far (compliance or stiffness applications).
    """

    def _set_layout(self, grid, comm):
        self.grid = grid
        self.comm = comm
        self.local_rows = self.transform.local_rows
        self.local_shape = (self.local_rows.stop - self.local_rows.start, grid.n1)
        self.applications = 0

    def vec(self):
        """A new distributed Vec laid out like the grid (rows owned by this rank).

        The local size is given explicitly (this rank's rows times ``n1``), so
        PETSc's ownership range is exactly ``local_rows`` however unevenly the
        rows are shared (PETSC_DECIDE would split the ``n0 n1`` nodes, not rows).
        Its memory is SIMD-aligned, so that the FFTW plans (serial or slab) run
        on it in place (no copy per application).
        """
        import pyfftw

        n_local = self.local_shape[0] * self.local_shape[1]
        return PETSc.Vec().createWithArray(pyfftw.zeros_aligned(n_local, dtype="float64"),
                                           size=(n_local, self.grid.size), comm=self.comm)

    def local(self, v, readonly=False):
        """This rank's part of ``v`` as a ``(rows, n1)`` array view."""
        array = v.getArray(readonly=readonly)
        return array.reshape(self.local_shape)

    @log_event("RPCompliance")
    def displacement(self, pressure, out):
        """``out = K pressure``: the surface displacement, length units."""
        self.applications += 1
        self._filter(self.local(pressure, readonly=True), self.local(out), self.compliance_symbol)

    @log_event("RPFFTPair")
    def _filter(self, source, target, symbol):
        self.transform.filter(source, target, symbol)

    @log_event("RPStiffness")
    def stiffness(self, source, target):
        """``target = S source`` on local ``(rows, n1)`` arrays: the preconditioner's approximate inverse of K.

        Counts as an application. See the subclass for what ``S`` is.
        """
        self.applications += 1
        self._filter(source, target, self.preconditioner_symbol)

    def mat(self):
        """The compliance as a symmetric shell Mat (``MATPYTHON``); destroy it when done."""
        n_local = self.local_shape[0] * self.local_shape[1]
        mat = PETSc.Mat().createPython(((n_local, self.grid.size), (n_local, self.grid.size)),
                                       context=_ShellContext(self), comm=self.comm)
        mat.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        mat.setUp()
        return mat

    def destroy(self):
        if hasattr(self.transform, "destroy"):
            self.transform.destroy()


def per_float(symbol):
    """A real symbol repeated once per float of the complex spectrum (see :meth:`SerialTransform.filter`)."""
    return np.repeat(symbol, 2, axis=1)


class Westergaard(FilterOperator):
    """Compliance of the periodic half-space, (3.33), applied through FFTW.

    Parameters
    ----------
    grid : surfaces.Grid
        The periodic cell.
    E_star : float
        Composite modulus E* (1.6) in pressure units.
    comm : petsc4py.PETSc.Comm
        Communicator; on one rank a direct 2-D FFTW plan is used.
    threads : int
        FFTW threads of the one-rank plan.
    effort : str
        FFTW planner flag (``FFTW_ESTIMATE``, ``FFTW_MEASURE``, ``FFTW_PATIENT``).

    Attributes
    ----------
    transform : SerialTransform or roughpetsc.slab.SlabTransform
        The FFT pair: a 2-D FFTW plan on one rank, the slab transform on several.

    The preconditioner's ``stiffness`` is ``F^-1[pi E* max(|k|, 1/L) F[source]]``: the inverse symbol
    of the compliance, with the mean (k = 0) mode weighted like the longest wavelength 1/L instead of
    dropped (Polonsky-Keer needs the mean under displacement control).
    """

    def __init__(self, grid, E_star, comm=None, threads=1, effort="FFTW_MEASURE"):
        if not (isinstance(E_star, (int, float, np.integer, np.floating)) and E_star > 0 and np.isfinite(E_star)):
            raise ParameterError("E_star", f"the composite modulus must be positive and finite, got {E_star!r}")
        comm = comm or PETSc.COMM_WORLD
        self.E_star = float(E_star)
        if comm.getSize() == 1:
            self.transform = SerialTransform(grid, threads, effort)
        else:
            from .slab import SlabTransform

            self.transform = SlabTransform(grid, comm.tompi4py(), effort)
        self._set_layout(grid, comm)
        k = wavenumber_modulus(grid, *self.transform.spectral_slice)
        with np.errstate(divide="ignore"):
            # The 1/(n0 n1) of the unnormalised FFT pair is folded into the symbols.
            compliance = np.where(k > 0, 1.0 / (np.pi * self.E_star * k), 0.0) / grid.size
        stiffness = np.pi * self.E_star * k / grid.size
        longest = 1.0 / max(grid.l0, grid.l1)
        preconditioner = np.pi * self.E_star * np.maximum(k, longest) / grid.size
        self.compliance_symbol = per_float(compliance)
        self._stiffness = per_float(stiffness)
        self.preconditioner_symbol = per_float(preconditioner)

    @property
    def diagonal(self):
        """The (constant) diagonal of the compliance matrix: mean of its symbol over the full spectrum."""
        k = wavenumber_modulus(self.grid)
        with np.errstate(divide="ignore"):
            symbol = np.where(k > 0, 1.0 / (np.pi * self.E_star * k), 0.0)
        # rfft layout: a column that stands for two modes of the full spectrum counts twice.
        return float((symbol * rfft_multiplicity(self.grid.n1)).sum() / self.grid.size)

    @log_event("RPStiffness")
    def elastic_pressure(self, displacement, out):
        """``out = F^-1[pi E* |k| F[displacement]]``: the pressure less its mean that makes ``displacement``.

        The exact inverse of the compliance on the zero-mean fields (the adhesive gap formulation's
        Hessian); counts as an application.
        """
        self.applications += 1
        self._filter(self.local(displacement, readonly=True), self.local(out), self._stiffness)

    def pressure_surface(self, heights, out):
        """``out = F^-1[pi E* |k| F[heights]]``: the complete-contact pressure p_c of (2.47)."""
        self._filter(self.local(heights, readonly=True), self.local(out), self._stiffness)


class _ShellContext:
    """The MATPYTHON context of :meth:`FilterOperator.mat`: K + perturbation I.

    ``perturbation`` is TAO's Hessian shift: the BNK family (BNLS, BNTR, BNTL)
    calls MatShift when a Newton step fails to descend, and expects the next
    Hessian evaluation to start afresh (the owner sets ``perturbation`` back to 0).
    """

    def __init__(self, operator):
        self.operator = operator
        self.perturbation = 0.0

    def mult(self, mat, x, y):
        self.operator.displacement(x, y)
        if self.perturbation:
            y.axpy(self.perturbation, x)

    def multTranspose(self, mat, x, y):
        self.mult(mat, x, y)

    def getDiagonal(self, mat, d):
        d.set(self.operator.diagonal + self.perturbation)

    def shift(self, mat, a):
        self.perturbation += a
