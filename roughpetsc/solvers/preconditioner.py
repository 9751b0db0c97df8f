"""The Fourier preconditioner of the contact QP on its free (contact) set.

``B r = P S P r + w mean_C(r) / lambda_C 1_C`` (Vollebregt, J. Comput. Phys. 257, 2014), used by
Polonsky-Keer and, as a Hessian preconditioning matrix, by TRON, GPCG and BNK: docs/solvers.md.
"""

import numpy as np
from petsc4py import PETSc

from ..contact import loops
from ..parallel import allsum

# Weight w of the mean mode. Measured with PK under displacement control on
# group #1, p* = 0.5, iterations at N = 256 / 512: w = 1: 102 / 123, 4: 59 / 83,
# 8: 62 / 84, 16: 51 / 68, 32: 88 / 149. The middle of the flat range (on a
# log scale) is kept, away from the cliff above 16.
MEAN_MODE_WEIGHT = 8.0


class FourierPreconditioner:
    """``B`` of the module docstring for a :class:`~roughpetsc.contact.ContactProblem`."""

    mean_mode_weight = MEAN_MODE_WEIGHT

    def __init__(self, problem):
        self.problem = problem
        self.indicator = problem.vec()
        self.response = problem.vec()
        self._mean_mode = (0.0, 1.0)  # (|C| it was computed for, lambda_C)

    def destroy(self):
        self.indicator.destroy()
        self.response.destroy()

    def mean_mode_compliance(self, contact, count):
        """``lambda_C``, recomputed (one K application) when |C| changed by more than 5 %."""
        computed_for, compliance = self._mean_mode
        if abs(count - computed_for) <= 0.05 * count:
            return compliance
        problem = self.problem
        problem.local(self.indicator).ravel()[...] = contact
        problem.operator.displacement(self.indicator, self.response)
        energy, = allsum(problem.mpi, [np.dot(problem.local(self.response, readonly=True).ravel(), contact)])
        # C = every node: the uniform pressure is the rigid mode (K 1 = 0), nothing to precondition.
        compliance = energy / count if energy > 0 else np.inf
        self._mean_mode = (count, compliance)
        return compliance

    @PETSc.Log.EventDecorator("RPFourierPC")  # -log_view: one application of B, its FFT pair included
    def apply(self, residual, out, contact, count, keep_load, rigid_compliance=np.inf):
        """``out = B residual`` on local flat arrays; ``residual`` vanishes off C (``contact`` 1.0 on C, |C| ``count``).

        ``keep_load``: the residual has zero mean on C, and the mean-mode term is dropped. ``rigid_compliance``:
        the lambda_C when C is every node (K 1 = 0); infinite drops the mean mode there, as PK wants.
        """
        problem = self.problem
        operator = problem.operator
        shape = operator.local_shape
        if keep_load:  # P residual = residual
            self.inverse_symbol(residual.reshape(shape), out.reshape(shape))
        else:
            residual_sum, = allsum(problem.mpi, [residual.sum()])
            residual_mean = residual_sum / count
            np.multiply(contact, -residual_mean, out=out)
            out += residual  # P residual, built in out: the FFT pair may run in place
            self.inverse_symbol(out.reshape(shape), out.reshape(shape))
        out_sum, = allsum(problem.mpi, [loops.masked_sum(out, contact)])
        loops.shift_on(out, contact, out_sum / count, out)
        if not keep_load:
            compliance = self.mean_mode_compliance(contact, count)
            if not np.isfinite(compliance):
                compliance = rigid_compliance
            out += self.mean_mode_weight * residual_mean / compliance * contact

    def inverse_symbol(self, source, target):
        """The approximate inverse of the Hessian on local ``(rows, n1)`` arrays: here the stiffness S."""
        self.problem.operator.stiffness(source, target)

    def mat(self):
        """A python Mat applying ``B`` with C = all nodes (``createSubMatrix``: on a free set), for PC type ``mat``."""
        return self.problem.operator.mat(_RestrictedMat(self, None))


class _RestrictedMat:
    """MATPYTHON context: ``B`` on the free set given by an IS of global indices (None: every node)."""

    def __init__(self, preconditioner, free, rigid_compliance=None):
        self.preconditioner = preconditioner
        problem = preconditioner.problem
        self.residual = problem.vec()
        self.out = problem.vec()
        start = self.residual.getOwnershipRange()[0]
        self.contact = np.zeros(self.residual.getLocalSize())
        if free is None:
            self.indices = None
            self.contact[...] = 1.0
        else:
            self.indices = free.getIndices() - start
            self.contact[self.indices] = 1.0
        self.count, = allsum(problem.mpi, [self.contact.sum()])
        # With every node free, K is singular (K 1 = 0) and a TAO Newton type shifts it, K + a I: the
        # mean mode is then preconditioned by 1 / a, or, before any shift, by the compliance of the
        # longest wavelength, so that B stays positive definite (a singular B broke BNLS/BNTR's CG).
        grid = problem.scaled_grid  # scaled units: E* = 1
        self.rigid_compliance = rigid_compliance or max(grid.l0, grid.l1) / np.pi

    def mult(self, mat, x, y):
        residual = self.residual.getArray()
        out = self.out.getArray()
        if self.indices is None:
            residual[...] = x.getArray(readonly=True)
        else:
            residual[...] = 0.0
            residual[self.indices] = x.getArray(readonly=True)
        self.preconditioner.apply(residual, out, self.contact, self.count, keep_load=False,
                                  rigid_compliance=self.rigid_compliance)
        y.getArray()[...] = out if self.indices is None else out[self.indices]

    def shift(self, mat, a):
        """TAO's BNK Hessian perturbation (MatShift): the rigid mode of K + a I has compliance 1 / a."""
        if a > 0:
            self.rigid_compliance = 1.0 / a

    def createSubMatrix(self, mat, isrow, iscol, submat):
        context = _RestrictedMat(self.preconditioner, isrow, self.rigid_compliance)
        if submat is not None:  # MAT_REUSE_MATRIX: same sizes, new free set
            submat.getPythonContext().destroy(submat)
            submat.setPythonContext(context)
            return submat
        sub = PETSc.Mat().createPython(((isrow.getLocalSize(), isrow.getSize()),) * 2, context=context,
                                       comm=mat.getComm())
        sub.setUp()
        return sub

    def destroy(self, mat):
        self.residual.destroy()
        self.out.destroy()


class FreeSetPC:
    """PCPYTHON context: ``B`` on the free set of GPCG's reduced Newton system.

    PETSc's GPCG takes its preconditioning submatrix from the Hessian, not from the preconditioning matrix it is
    given (``TaoMatGetSubMat(tao->hessian, ...)`` for ``Hsub_pre`` in gpcg.c, 3.18 to 3.26), so PC type ``mat``
    applied the free-set Hessian itself: 290-339 KSP iterations a step where none took 42-46 (N = 256,
    p* = 0.05). This PC finds the free set as GPCG does (``VecWhichInactive`` of the iterate and its gradient,
    strong), once per reduced system, and applies ``B`` there.
    """

    def __init__(self, preconditioner, tao, gradient, upper_bound):
        self.preconditioner = preconditioner
        self.tao, self.gradient = tao, gradient
        self.upper = np.inf if upper_bound is None else upper_bound
        self.restricted = None

    def setUp(self, pc):
        x = self.tao.getSolution().getArray(readonly=True)
        g = self.gradient.getArray(readonly=True)
        free = ((x > 0.0) & (x < self.upper)) | ((x == 0.0) & (g < 0.0)) | ((x == self.upper) & (g > 0.0))
        indices = np.flatnonzero(free).astype(PETSc.IntType) + self.gradient.getOwnershipRange()[0]
        size = pc.getOperators()[1].getLocalSize()[0]
        if indices.size != size:  # GPCG's reduced system is not on the set this PC found
            raise RuntimeError(f"GPCG's reduced system has {size} local rows, its free set here {indices.size}")
        self.reset(pc)
        free_set = PETSc.IS().createGeneral(indices, comm=self.gradient.getComm())
        try:
            self.restricted = _RestrictedMat(self.preconditioner, free_set)
        finally:
            free_set.destroy()

    def apply(self, pc, x, y):
        self.restricted.mult(None, x, y)

    def reset(self, pc):
        if self.restricted is not None:
            self.restricted.destroy(None)
            self.restricted = None

    def destroy(self, pc):
        self.reset(pc)
