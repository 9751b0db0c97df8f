"""The second-order half of an adhesive solution's local-minimum certificate: the least curvature of the energy.

At a gap g that meets the first-order conditions, the energy Pi(g) (:mod:`~roughpetsc.contact.adhesive`) has no
descent direction to first order; it is a strict local minimum when its Hessian H = S + diag(phi''(g)) is positive
on the directions that keep the constraints to first order: zero on the nodes in contact (g = 0) and of zero mean
(the mean gap is prescribed). Curvatures are reported over s1 = pi E* / L, the stiffness of the longest
wavelength. S alone gives at least 1 on zero-mean directions, so with phi'' >= -s1 on the free nodes (any Dugdale
law, whose phi'' is zero off its kink) the bound 1 + min phi''/s1 >= 0 certifies without a solve.

Otherwise, first a relaxed bound: with A = max(-phi'', 0) on the free nodes and C the compliance (the inverse of S
on zero-mean fields), x'H x >= x'S x - x'A x >= (1 - lambda) x'S x >= (1 - lambda) s1 |x|^2 for any zero-mean x,
lambda the largest eigenvalue of A^(1/2) C A^(1/2) (over every zero-mean x, not only the feasible ones: relaxed).
One operator application a product, and the largest eigenvalue of a compact operator converges in a few: when
1 - lambda - :data:`TOLERANCE` >= 0 (weak laws, short ranges), that is the certificate.

Else the certificate is the least eigenvalue nu of C H, C the compliance (the inverse of S) on the same
directions, found by SLEPc's Krylov-Schur to an absolute residual of :data:`TOLERANCE`. C is positive definite
there, so C H has the inertia of H (Sylvester's law): nu > 0 exactly when H is positive definite, and as
C <= 1/s1, H >= nu s1 when nu >= 0. So nu is a lower bound of the least curvature over s1, of the same sign, not
that curvature itself. C H is the operator the gap CG iterates with, so its least eigenvalue converges in tens of
products. LOBPCG on H itself, preconditioned by C, took 5-10x the operator applications: its residual is in S's
units, so it had to resolve the highest wavenumbers, and it reapplied H to its whole basis every iteration.
"""

import numpy as np
from petsc4py import PETSc

from ..parallel import allmin, allsum

# Both eigenvalues (the module's docstring) are found to this absolute residual; the relaxed bound subtracts it,
# and a value of nu below -TOLERANCE is negative.
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
    """A lower bound, of the same sign where negative, of the least eigenvalue over ``s1`` of the energy's Hessian
    on the feasible zero-mean directions at the local scaled ``gap`` of the adhesive ``problem`` (the module's
    docstring says which): ``(value, how)``, how "bound", "relaxed bound, K iterations" or "Krylov-Schur, K
    iterations".

    ``mode``: a local array of gap's shape, the last eigen-solve's start where nonzero on the free nodes (the last
    step's eigenvector along a path), overwritten with this one's. Returns (None, reason) if no free node is left,
    or if the eigen-solve does not converge.
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
    nodes = np.flatnonzero(free) + problem.local_rows.start * gap.shape[-1]
    # A fixed start, the same on any number of ranks: a function of the global node number. The relaxed solve
    # leaves its eigenvector in it (weight where |phi''| is largest), which starts nu's solve when no mode is given.
    fixed = np.sin(1.0 + 0.7548776662466927 * nodes)
    weighted = _Weighted(problem, free, np.sqrt(np.maximum(-curvature, 0.0)))
    try:
        largest, its = _extreme_eigenvalue(problem, weighted, (count_local, count), "LARGEST_REAL", fixed, True)
    finally:
        weighted.release()
    if largest is not None and 1.0 - largest - TOLERANCE >= 0.0:
        return 1.0 - largest - TOLERANCE, f"relaxed bound, {its} iterations"
    hessian = _Projected(problem, free, curvature, count, problem.operator.elastic_pressure)
    compliance = _Projected(problem, free, None, count, problem.operator.displacement)
    preconditioned = _Product(hessian, compliance)
    values = mode.ravel()[free] if mode is not None else np.zeros(count_local)
    if not allsum(problem.mpi, [np.dot(values, values)])[0] > 0:
        values = fixed
    values = values - allsum(problem.mpi, [values.sum()])[0] / count
    try:
        # C H is self-adjoint in the product of C's inverse, not in the Euclidean one: non-Hermitian to SLEPc.
        nu, its = _extreme_eigenvalue(problem, preconditioned, (count_local, count), "SMALLEST_REAL", values, False)
    finally:
        for context in (preconditioned, hessian, compliance):
            context.release()
    if nu is None:
        return None, f"Krylov-Schur did not converge in {its} iterations"
    if mode is not None:
        mode[...] = 0.0
        mode.ravel()[free] = values
    return nu, f"Krylov-Schur, {its} iterations"


def _extreme_eigenvalue(problem, context, sizes, which, start, hermitian):
    """``(eigenvalue, iterations)``: the eigenvalue ``which`` (a SLEPc ``EPS.Which`` name) of the MATPYTHON
    ``context`` (symmetric if ``hermitian``) by Krylov-Schur to :data:`TOLERANCE`, from the local array ``start``,
    overwritten with its eigenvector; (None, iterations) if it does not converge."""
    from slepc4py import SLEPc

    comm = problem.heights.getComm()
    mat = PETSc.Mat().createPython((sizes, sizes), context=context, comm=comm)
    eps = SLEPc.EPS().create(comm)
    vector = mat.createVecLeft()
    try:
        mat.setUp()
        eps.setOperators(mat)
        eps.setProblemType(SLEPc.EPS.ProblemType.HEP if hermitian else SLEPc.EPS.ProblemType.NHEP)
        eps.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
        eps.setWhichEigenpairs(getattr(SLEPc.EPS.Which, which))
        eps.setConvergenceTest(SLEPc.EPS.Conv.ABS)
        eps.setTolerances(tol=TOLERANCE, max_it=MAX_ITERATIONS)
        if not hermitian:
            # C H maps the constant on the free nodes, outside the zero-mean directions, to 0: an eigenvalue 0 that
            # round-off lets in unless deflated. SLEPc keeps a reference to the vector, not a copy.
            constant = mat.createVecLeft()
            constant.set(1.0)
            eps.setDeflationSpace([constant])
            constant.destroy()
        vector.getArray()[...] = start
        eps.setInitialSpace([vector])
        eps.solve()
        if eps.getConverged() < 1:
            return None, eps.getIterationNumber()
        value = eps.getEigenpair(0, vector)
        start[...] = vector.getArray(readonly=True)
        return value.real, eps.getIterationNumber()
    finally:
        for obj in (vector, eps, mat):
            obj.destroy()


class _Weighted:
    """MATPYTHON context: y on the free nodes -> a C (a y), a = |phi''|^(1/2) where phi'' < 0, C the compliance on
    the whole grid (zero on the mean): the relaxed bound's operator."""

    def __init__(self, problem, free, weight):
        self.problem, self.free, self.weight = problem, free, weight
        self.full, self.out = problem.vec(), problem.vec()

    def mult(self, mat, x, y):
        full, out = self.problem.local(self.full).ravel(), self.problem.local(self.out, readonly=True).ravel()
        full[...] = 0.0
        full[self.free] = self.weight * x.getArray(readonly=True)
        self.problem.operator.displacement(self.full, self.out)
        y.getArray()[...] = self.weight * out[self.free]

    def release(self):
        self.full.destroy()
        self.out.destroy()


class _Product:
    """MATPYTHON context: x -> second(first(x)) of two :class:`_Projected`, here the compliance after the Hessian."""

    def __init__(self, first, second):
        self.first, self.second = first, second
        self.between = None

    def mult(self, mat, x, y):
        if self.between is None:
            self.between = x.duplicate()
        self.first.mult(None, x, self.between)
        self.second.mult(None, self.between, y)

    def release(self):
        if self.between is not None:
            self.between.destroy()
