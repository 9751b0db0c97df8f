"""What every compliance applied as a real Fourier filter shares: the Vec layout, the shell Mat, the counts."""

import numpy as np
from petsc4py import PETSc

from ..parallel import destroyed_at_exit


# PETSc log events (-log_view): the operator applications by kind, and every FFT pair.
log_event = PETSc.Log.EventDecorator


def wavenumber_modulus(grid, rows=slice(None), cols=slice(None)):
    k0, k1 = grid.rfft_wavenumbers(rows)
    return np.hypot(k0, k1[:, cols])


class FilterOperator:
    """A compliance applied as a real Fourier filter: the Vec layout, the shell Mat, the counts.

    A subclass sets ``transform`` (with ``filter(source, target, symbol)``, ``local_rows``,
    ``spectral_slice``), ``compliance_symbol`` and ``preconditioner_symbol`` (per float, normalised) and
    ``diagonal``, then calls :meth:`_set_layout`.

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
        """A new distributed Vec of this rank's rows (``local_rows``), SIMD-aligned for in-place FFTW plans."""
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
        self.compliance(self.local(pressure, readonly=True), self.local(out))

    def compliance(self, source, target):
        """``target = K source`` on local ``(rows, n1)`` arrays (may be the same array)."""
        self.applications += 1
        self._filter(source, target, self.compliance_symbol)

    def _filter(self, source, target, symbol):
        self._filter_with(self.transform, source, target, symbol)

    @staticmethod
    @log_event("RPFFTPair")
    def _filter_with(transform, source, target, symbol):
        transform.filter(source, target, symbol)

    @log_event("RPStiffness")
    def stiffness(self, source, target):
        """``target = S source`` on local ``(rows, n1)`` arrays: the preconditioner's approximate inverse of K."""
        self.applications += 1
        self._filter(source, target, self.preconditioner_symbol)

    def mat(self, context=None):
        """The compliance as a symmetric shell Mat (``MATPYTHON``); destroy it when done.

        ``context``: another MATPYTHON context on this layout (a Hessian or preconditioner made from K).
        """
        n_local = self.local_shape[0] * self.local_shape[1]
        mat = destroyed_at_exit(PETSc.Mat().createPython(((n_local, self.grid.size), (n_local, self.grid.size)),
                                                         context=context or ShellContext(self), comm=self.comm))
        mat.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        mat.setUp()
        return mat

    def destroy(self):
        if hasattr(self.transform, "destroy"):
            self.transform.destroy()


def per_float(symbol):
    """A real symbol repeated once per float of the complex spectrum (see :meth:`SerialTransform.filter`)."""
    return np.repeat(symbol, 2, axis=1)


class ShellContext:
    """The MATPYTHON context of :meth:`FilterOperator.mat`: K + perturbation I.

    ``perturbation`` is the BNK family's MatShift; the owner resets it at each Hessian evaluation.
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
