"""What every compliance applied as a real Fourier filter shares: the Vec layout, the shell Mat, the counts."""

import numpy as np
from petsc4py import PETSc


# PETSc log events (-log_view, prefix RP for roughpetsc): the operator applications by kind
# (RPCompliance, RPStiffness), and every FFT pair (r2c, symbol product, c2r) whatever asked for it.
log_event = PETSc.Log.EventDecorator


def wavenumber_modulus(grid, rows=slice(None), cols=slice(None)):
    k0, k1 = grid.rfft_wavenumbers(rows)
    return np.hypot(k0, k1[:, cols])


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

    def _filter(self, source, target, symbol):
        self._filter_with(self.transform, source, target, symbol)

    @staticmethod
    @log_event("RPFFTPair")
    def _filter_with(transform, source, target, symbol):
        transform.filter(source, target, symbol)

    @log_event("RPStiffness")
    def stiffness(self, source, target):
        """``target = S source`` on local ``(rows, n1)`` arrays: the preconditioner's approximate inverse of K.

        Counts as an application. See the subclass for what ``S`` is.
        """
        self.applications += 1
        self._filter(source, target, self.preconditioner_symbol)

    def mat(self, context=None):
        """The compliance as a symmetric shell Mat (``MATPYTHON``); destroy it when done.

        ``context``: another MATPYTHON context on this layout (a Hessian or preconditioner made from K).
        """
        n_local = self.local_shape[0] * self.local_shape[1]
        mat = PETSc.Mat().createPython(((n_local, self.grid.size), (n_local, self.grid.size)),
                                       context=context or ShellContext(self), comm=self.comm)
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
