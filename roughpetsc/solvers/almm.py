"""Load control by TAO ALMM: the QP (3.41)-(3.44) of the dissertation with the equality ``mean(p) = pbar``.

Registered as ``almm`` for load control only.
"""

import numpy as np
from petsc4py import PETSc

from ..kkt import ConvergenceTest, History
from .objective import QuadraticObjective
from .protocol import Backend, Outcome, describe_stop
from .registry import register
from .tao_options import DEFAULT_MAX_IT, set_from_options, stop_subsolver


def mean_jacobian(constraint, vec, n, comm):
    """The Jacobian of the mean of a Vec laid out like ``vec``: one dense row of 1/n, owned by rank 0.

    ``constraint`` is the one-entry constraint Vec (its row is on rank 0) of an equality on the mean.
    """
    jacobian = PETSc.Mat().createDense(((constraint.getLocalSize(), 1), (vec.getLocalSize(), n)), comm=comm)
    jacobian.setUp()
    start, end = vec.getOwnershipRange()
    columns = np.arange(start, end, dtype=PETSc.IntType)
    jacobian.setValues([0], columns, np.full(columns.size, 1.0 / n))
    jacobian.assemble()
    return jacobian


class ALMMLoad(Backend):
    """Load control by TAO ALMM: ``min 1/2 p'Kp - p'h`` with ``p >= 0`` and ``mean(p) = pbar``.

    The multiplier of the equality is the separation; it is recovered from the
    contact set as in Polonsky-Keer. The subsolver is chosen with
    ``-tao_almm_subsolver_tao_type`` (first-order types only in PETSc 3.18).

    Parameters are those of the registry's factories (``control`` is "load", ``name`` "almm").
    """

    name = "almm"

    def __init__(self, problem, control, name, settings):
        self.problem = problem
        self.rtol = settings.rtol
        self.max_seconds = settings.max_seconds
        self.target = 0.0
        self.history = None
        comm = problem.comm
        self.gradient = problem.vec()
        self.gap_vec = problem.vec()
        self.objective = QuadraticObjective(problem, increments=False)  # at separation 0: f = p'Kp/2 - p'h
        self.hessian = problem.operator.mat()
        self.lower = problem.vec()
        self.lower.set(0.0)
        self.upper = problem.vec()
        self.upper.set(PETSc.INFINITY if problem.upper_bound is None else problem.upper_bound)
        self.constraint = PETSc.Vec().createMPI((1 if comm.getRank() == 0 else 0, 1), comm=comm)
        self.jacobian = mean_jacobian(self.constraint, self.gradient, problem.n, comm)
        tao = self.tao = PETSc.TAO().create(comm)
        tao.setOptionsPrefix(settings.prefix)
        tao.setType("almm")
        tao.setObjectiveGradient(self._objective_gradient, self.gradient)
        tao.setHessian(lambda *args: None, self.hessian, self.hessian)
        tao.setVariableBounds((self.lower, self.upper))
        tao.setEqualityConstraints(self._equality, self.constraint)
        tao.setJacobianEquality(lambda *args: None, self.jacobian, self.jacobian)
        tao.setTolerances(gatol=0.0, grtol=0.0, gttol=0.0)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        set_from_options(tao, self.destroy)

    def _objective_gradient(self, tao, x, gradient):
        objective = self.objective.evaluate(x, gradient)
        if self.history is not None and self.history.out_of_time(self.max_seconds):
            # The subsolve ends at its next convergence test, and the outer test then reports the time limit.
            # (A zero gradient did not end it: the augmented Lagrangian's gradient keeps the constraint
            # term, and a 1024^2 solve ran 100 s past a 10 s limit.)
            stop_subsolver(tao)
        return objective

    def _equality(self, tao, x, c):
        c.set(x.sum() / self.problem.n - self.target)

    def gap_of(self, x):
        """The gap of ``x`` at the separation that zeroes its mean on the contact set (PK's choice)."""
        problem = self.problem
        elastic_gap = self.objective.gap_of(x)  # K p - h
        self.separation = problem.contact_separation(x, elastic_gap)
        gap = problem.local(self.gap_vec)
        np.add(elastic_gap, self.separation, out=gap)
        return gap

    def solve(self, pbar, pressure, guess=None):
        """Solve for the mean pressure ``pbar`` (scaled) from ``pressure``; ``guess`` is unused."""
        self.target = pbar
        history = self.history = History(self.problem)
        test = ConvergenceTest(self.problem.mpi, self.problem.n, self.rtol, self.gap_of, history, target_pbar=pbar,
                               max_seconds=self.max_seconds, upper=self.problem.upper_bound)
        self.tao.setConvergenceTest(test)
        self.objective.restart()
        self.tao.setSolution(pressure)
        self.tao.solve(pressure)
        self.gap_of(pressure)
        return Outcome(self.separation, self.tao.getIterationNumber(), describe_stop(self.tao, test),
                       history.as_array())

    def destroy(self):
        self.tao.destroy()
        for obj in (self.gradient, self.gap_vec, self.objective, self.hessian, self.lower, self.upper, self.constraint,
                    self.jacobian):
            obj.destroy()


register("almm", ALMMLoad, controls=("load",))
