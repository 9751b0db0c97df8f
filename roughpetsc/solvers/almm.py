"""Load control by TAO ALMM (``almm``): the QP (3.41)-(3.44) of the dissertation with ``mean(p) = pbar``."""

import numpy as np
from petsc4py import PETSc

from ..contact.certificate import report
from .options import default_options, set_from_options, stop_subsolver, tao_with_callbacks
from .protocol import Backend, Outcome
from .registry import register
from .stopping import DEFAULT_MAX_IT, ConvergenceTest, History, describe_stop


def mean_jacobian(constraint, vec, n, comm):
    """The Jacobian of the mean of a Vec laid out like ``vec``: one dense row of 1/n, owned by rank 0."""
    jacobian = PETSc.Mat().createDense(((constraint.getLocalSize(), 1), (vec.getLocalSize(), n)), comm=comm)
    jacobian.setUp()
    start, end = vec.getOwnershipRange()
    columns = np.arange(start, end, dtype=PETSc.IntType)
    jacobian.setValues([0], columns, np.full(columns.size, 1.0 / n))
    jacobian.assemble()
    return jacobian


class MeanConstrainedALMM(Backend):
    """TAO ALMM on ``unknown >= 0`` (``<= upper``) with the one equality ``mean(unknown) = target``.

    The base of the ALMM backends of both problem kinds. A subclass supplies :meth:`evaluate` (objective and
    gradient), :meth:`natural_residual` (``(natural, error of the equality, fresh)``), :meth:`prepare` and
    :meth:`finish` (returns the Outcome's separation). ``hessian``: the Mat TAO may use; ``defaults``: working
    defaults of TAO options.
    """

    name = "almm"

    def __init__(self, problem, settings, upper=None, hessian=None, defaults=None):
        self.problem = problem
        self.rule = settings.rule
        self.target = 0.0
        self.history = None
        self.watch = None
        comm = problem.comm
        self.gradient = problem.vec()
        self.lower = problem.vec()
        self.lower.set(0.0)
        self.upper = problem.vec()
        self.upper.set(PETSc.INFINITY if upper is None else upper)
        self.constraint = PETSc.Vec().createMPI((1 if comm.getRank() == 0 else 0, 1), comm=comm)
        self.jacobian = mean_jacobian(self.constraint, self.gradient, problem.n, comm)
        tao = self.tao = tao_with_callbacks(comm, settings.prefix)
        tao.setType("almm")
        tao.setObjectiveGradient(self._objective_gradient, self.gradient)
        if hessian is not None:
            tao.setHessian(lambda *args: None, hessian, hessian)
        tao.setVariableBounds((self.lower, self.upper))
        tao.setEqualityConstraints(self._equality, self.constraint)
        tao.setJacobianEquality(lambda *args: None, self.jacobian, self.jacobian)
        tao.setTolerances(gatol=0.0, grtol=0.0, gttol=0.0)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        with default_options(defaults or {}, settings.prefix):
            set_from_options(tao, self.destroy)

    def _objective_gradient(self, tao, x, gradient):
        value = self.evaluate(x, gradient)
        if self.history is not None and self.history.out_of_time(self.rule.max_seconds):
            # The subsolve ends at its next convergence test, and the outer test then reports the time limit.
            # (A zero gradient did not end it: the augmented Lagrangian's gradient keeps the constraint
            # term, and a 1024^2 solve ran 100 s past a 10 s limit.)
            stop_subsolver(tao)
        return value

    def _equality(self, tao, x, c):
        c.set(x.sum() / self.problem.n - self.target)

    def keep_best(self, x):
        """A new best outer iterate (nothing kept by default)."""

    def solve(self, target, unknown, guess=None):
        """Solve for the mean ``target`` (scaled) from ``unknown`` (overwritten); ``guess`` is unused."""
        self.target = target
        self.prepare(unknown)
        history = self.history = History(self.problem)
        self.watch = self.rule.watch(history)
        self.tao.setConvergenceTest(ConvergenceTest(self.watch, self.natural_residual, keep_best=self.keep_best))
        self.tao.setSolution(unknown)
        self.tao.solve(unknown)
        reason = self.tao.getConvergedReason()
        separation = self.finish(unknown, reason)
        return Outcome(separation, self.tao.getIterationNumber(),
                       describe_stop(reason, self.watch, load_control=True), history.as_array())

    def destroy(self):
        self.tao.destroy()
        for obj in (self.gradient, self.lower, self.upper, self.constraint, self.jacobian):
            obj.destroy()


class ALMMLoad(MeanConstrainedALMM):
    """Load control by TAO ALMM: ``min 1/2 p'Kp - p'h`` with ``p >= 0`` and ``mean(p) = pbar``.

    The separation is recovered from the contact set as in Polonsky-Keer. The subsolver is chosen with
    ``-tao_almm_subsolver_tao_type`` (first-order types only in PETSc 3.18).
    """

    def __init__(self, problem, control, name, settings):
        self.separation = 0.0
        self.gap_vec = problem.vec()
        # The last point evaluated and its gradient K p - h (the gap at d = 0), for the convergence test.
        self.point, self.elastic_gap = problem.vec(), problem.vec()
        self.cached = False
        self.hessian = problem.operator.mat()
        super().__init__(problem, settings, problem.upper_bound, self.hessian)

    def evaluate(self, x, gradient):
        """``gradient = K p - h`` (one operator application); returns f = p'Kp/2 - p'h.

        f is evaluated directly, not accumulated from exact increments as the bound types' objective is
        (:class:`~roughpetsc.solvers.bound_qp.AugmentedQuadratic`): ALMM's augmented-Lagrangian updates use
        the size of f, and with f measured from the start it took 26272 operator applications instead of
        14976 (128^2, p* = 0.5, 1e-8).
        """
        self.problem.gap(x, 0.0, gradient)
        x.copy(self.point)
        if gradient is not self.elastic_gap:
            gradient.copy(self.elastic_gap)
        self.cached = True
        return 0.5 * (x.dot(gradient) - x.dot(self.problem.heights))

    def gap_of(self, x):
        """The gap of ``x`` at the separation that zeroes its mean on the contact set (PK's choice)."""
        problem = self.problem
        if not (self.cached and x.equal(self.point)):
            self.evaluate(x, self.elastic_gap)
        elastic_gap = problem.local(self.elastic_gap, readonly=True)  # K p - h
        self.separation = problem.contact_separation(x, elastic_gap)
        gap = problem.local(self.gap_vec)
        np.add(elastic_gap, self.separation, out=gap)
        return gap

    def natural_residual(self, tao):
        """The natural residual and load error of the outer iterate, at PK's separation."""
        x = tao.getSolution()
        problem = self.problem
        kkt = report(problem.mpi, x.getArray(readonly=True), self.gap_of(x), problem.n, self.target,
                     problem.upper_bound)
        return kkt.natural, kkt.load_error, True

    def prepare(self, pressure):
        self.cached = False

    def finish(self, pressure, reason):
        self.gap_of(pressure)
        return self.separation

    def destroy(self):
        super().destroy()
        for obj in (self.gap_vec, self.point, self.elastic_gap, self.hessian):
            obj.destroy()


register("almm", ALMMLoad, controls=("load",))
