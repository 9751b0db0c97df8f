"""The second-order half of an adhesive solution's local-minimum certificate: the least curvature of the energy.

At a gap g that meets the first-order conditions, the energy Pi(g) (:mod:`~roughpetsc.contact.adhesive`) has no
descent direction to first order; it is a strict local minimum when its Hessian S + diag(phi''(g)) is positive on
the directions that keep the constraints to first order: zero on the nodes in contact (g = 0) and of zero mean
(the mean gap is prescribed). Its least eigenvalue there is reported over s1 = pi E* / L, the stiffness of the
longest wavelength. S alone gives at least 1 on zero-mean directions, so with phi'' >= -s1 on the free nodes (any
Dugdale law, whose phi'' is zero off its kink) the bound 1 + min phi'' / s1 >= 0 certifies without a solve.
Otherwise SLEPc's LOBPCG finds it, preconditioned by the compliance (the inverse of S), to an absolute
residual of :data:`TOLERANCE` s1.
"""

import numpy as np
from petsc4py import PETSc

from ..parallel import allmin, allsum

# The least curvature is found to this absolute residual, in units of s1: a value below -TOLERANCE is negative.
TOLERANCE = 1e-2
MAX_ITERATIONS = 500


class _Projected:
    """MATPYTHON and PCPYTHON context: x on the free nodes -> P A P x, A the stiffness plus diag(phi'') or the
    compliance, P the projection onto zero mean over the free nodes."""

    def __init__(self, problem, free, curvature, count, apply):
        self.problem, self.free, self.curvature, self.count, self.apply = problem, free, curvature, count, apply
        self.full, self.out = problem.vec(), problem.vec()

    def _mean(self, values):
        return allsum(self.problem.mpi, [values.sum()])[0] / self.count

    def mult(self, mat, x, y):
        values = x.getArray(readonly=True)
        full, out = self.problem.local(self.full).ravel(), self.problem.local(self.out, readonly=True).ravel()
        full[...] = 0.0
        full[self.free] = values - self._mean(values)
        self.apply(self.full, self.out)
        result = out[self.free]
        if self.curvature is not None:
            result = result + self.curvature * full[self.free]
        y.getArray()[...] = result - self._mean(result)

    def release(self):  # not destroy(): PETSc calls a MATPYTHON context's destroy(mat) itself
        self.full.destroy()
        self.out.destroy()


def longest_wave_stiffness(problem):
    """s1: the stiffness S on the longest wavelength along axis 1, measured (one operator application)."""
    wave, out = problem.vec(), problem.vec()
    try:
        local = problem.local(wave)
        local[...] = np.cos(2 * np.pi * np.arange(local.shape[1]) / local.shape[1])
        problem.operator.elastic_pressure(wave, out)
        return allsum(problem.mpi, [np.dot(problem.local(out, readonly=True).ravel(), local.ravel())])[0] / \
            allsum(problem.mpi, [np.dot(local.ravel(), local.ravel())])[0]
    finally:
        wave.destroy()
        out.destroy()


def least_curvature(problem, gap, s1, mode=None):
    """The least eigenvalue over ``s1`` of the energy's Hessian on the feasible zero-mean directions at the local
    scaled ``gap`` of the adhesive ``problem``: ``(value, how)``, how "bound" or "LOBPCG, K iterations".

    ``mode``: a local array of gap's shape, LOBPCG's start where nonzero on the free nodes (the last step's
    eigenvector along a path: a few iterations), overwritten with this one's. Returns (None, reason) if no free
    node is left, or if LOBPCG does not converge.
    """
    g = gap.ravel()
    free = g > 0
    count_local = int(np.count_nonzero(free))
    count = int(allsum(problem.mpi, [count_local])[0])
    if count < 2:
        return None, "no free direction"
    curvature = problem.scaled_law.curvature(g[free])
    least, = allmin(problem.mpi, [curvature.min(initial=np.inf)])
    if 1.0 + least / s1 >= 0.0:
        return 1.0 + least / s1, "bound"
    from slepc4py import SLEPc

    hessian = _Projected(problem, free, curvature, count, problem.operator.elastic_pressure)
    compliance = _Projected(problem, free, None, count, problem.operator.displacement)
    comm = problem.heights.getComm()
    mat = PETSc.Mat().createPython(((count_local, count), (count_local, count)), context=hessian, comm=comm)
    eps = SLEPc.EPS().create(comm)
    start = mat.createVecLeft()
    try:
        mat.setUp()
        eps.setOperators(mat)
        eps.setProblemType(SLEPc.EPS.ProblemType.HEP)
        eps.setType(SLEPc.EPS.Type.LOBPCG)
        eps.setWhichEigenpairs(SLEPc.EPS.Which.SMALLEST_REAL)
        eps.setConvergenceTest(SLEPc.EPS.Conv.ABS)
        eps.setTolerances(tol=TOLERANCE * s1, max_it=MAX_ITERATIONS)
        ksp = eps.getST().getKSP()
        eps.getST().setType(SLEPc.ST.Type.PRECOND)
        ksp.setType(PETSc.KSP.Type.PREONLY)
        pc = ksp.getPC()
        pc.setType(PETSc.PC.Type.PYTHON)
        pc.setPythonContext(_PC(compliance))
        values = mode.ravel()[free] if mode is not None else np.zeros(count_local)
        if not allsum(problem.mpi, [np.dot(values, values)])[0] > 0:
            # A fixed start, the same on any number of ranks: a function of the global node number.
            nodes = np.flatnonzero(free) + problem.local_rows.start * gap.shape[-1]
            values = np.sin(1.0 + 0.7548776662466927 * nodes)
        start.getArray()[...] = values - allsum(problem.mpi, [values.sum()])[0] / count
        eps.setInitialSpace([start])
        eps.solve()
        if eps.getConverged() < 1:
            return None, f"LOBPCG did not converge in {eps.getIterationNumber()} iterations"
        if mode is not None:
            eps.getEigenpair(0, start)
            mode[...] = 0.0
            mode.ravel()[free] = start.getArray(readonly=True)
        return eps.getEigenvalue(0).real / s1, f"LOBPCG, {eps.getIterationNumber()} iterations"
    finally:
        for obj in (start, eps, mat):
            obj.destroy()
        hessian.release()
        compliance.release()


class _PC:
    """PCPYTHON context: the projected compliance (a separate object: the MATPYTHON context given as a PCPYTHON
    one too crashed PETSc)."""

    def __init__(self, context):
        self.context = context

    def apply(self, pc, x, y):
        self.context.mult(None, x, y)
