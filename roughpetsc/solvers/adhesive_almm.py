"""The adhesive problem of :mod:`roughpetsc.adhesive` as a TAO problem: ALMM with the mean-gap equality.

``min Pi(g)`` over ``g >= 0`` with ``mean(g) = gbar``: TAO ALMM (the PHR augmented Lagrangian, by
default) handles the equality and a bound-constrained subsolver (BQNLS by default,
``-tao_almm_subsolver_tao_type``) the bounds and the non-convex energy. It is the general-purpose
alternative to the projected CG of :mod:`roughpetsc.solvers.gap_cg` (``-tao_type almm`` with
``-adhesion``), slower and bounded below by the round-off floor of TAO's line searches on the
energy (the non-adhesive floors are in the README).

The outer iterations stop on the natural residual of :class:`~roughpetsc.adhesive.AdhesiveContact`,
computed on a fresh S g.
"""

import numpy as np
from petsc4py import PETSc

from ..kkt import STAGNATION_ITERATIONS, History, allsum
from .almm import mean_jacobian
from .protocol import Outcome, reason_name
from .tao_options import DEFAULT_MAX_IT, default_options, set_from_options, stop_subsolver

DEFAULTS = {"tao_almm_type": "phr", "tao_almm_subsolver_tao_type": "bqnls"}


class AdhesiveALMM:
    """TAO ALMM on an :class:`~roughpetsc.adhesive.AdhesiveContact`; options under ``prefix``."""

    name = "almm"

    def __init__(self, adhesive, prefix=None):
        self.adhesive = adhesive
        problem = adhesive.problem
        comm = problem.comm
        self.target = 0.0
        self.gradient = problem.vec()
        self.elastic = problem.vec()
        self.lower = problem.vec()
        self.lower.set(0.0)
        self.upper = problem.vec()
        self.upper.set(PETSc.INFINITY)
        self.constraint = PETSc.Vec().createMPI((1 if comm.getRank() == 0 else 0, 1), comm=comm)
        self.jacobian = mean_jacobian(self.constraint, self.gradient, problem.n, comm)
        self.test = None
        tao = self.tao = PETSc.TAO().create(comm)
        tao.setOptionsPrefix(prefix)
        tao.setType("almm")
        tao.setObjectiveGradient(self._objective_gradient, self.gradient)
        tao.setVariableBounds((self.lower, self.upper))
        tao.setEqualityConstraints(self._equality, self.constraint)
        tao.setJacobianEquality(lambda *args: None, self.jacobian, self.jacobian)
        tao.setTolerances(gatol=0.0, grtol=0.0, gttol=0.0)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        with default_options(DEFAULTS, prefix):
            set_from_options(tao, self.destroy)

    def _objective_gradient(self, tao, x, gradient):
        """Pi(x) per unit area and its gradient r / n (one operator application)."""
        adhesive = self.adhesive
        problem = adhesive.problem
        adhesive.elastic_pressure(x, self.elastic)
        g = problem.local(x, readonly=True)
        elastic = problem.local(self.elastic, readonly=True)
        r = problem.local(gradient)
        adhesive.gradient(g, elastic, r)
        r *= 1.0 / problem.n
        if self.test is not None and self.test.history.out_of_time(adhesive.max_seconds):
            stop_subsolver(tao)  # ends the inner solve; the outer test reports the time limit
        return adhesive.energy(g, elastic)

    def _equality(self, tao, x, c):
        c.set(x.sum() / self.adhesive.problem.n - self.target)

    def solve(self, target):
        """Solve at the scaled mean gap ``target`` from ``adhesive.gap`` (projected first); an Outcome."""
        from .gap_cg import project_mean

        adhesive = self.adhesive
        problem = adhesive.problem
        self.target = target
        project_mean(problem.mpi, problem.local(adhesive.gap).ravel(), target, problem.n)
        self.test = _NaturalTest(adhesive, self.elastic, target)
        self.tao.setConvergenceTest(self.test)
        self.tao.setSolution(adhesive.gap)
        self.tao.solve(adhesive.gap)
        reason = reason_name(self.tao.getConvergedReason())
        notes = [self.test.stopped_by] if self.test.stopped_by else []
        if self.tao.getConvergedReason() < 0 and np.isfinite(self.test.best):
            self.test.best_iterate.copy(adhesive.gap)  # the caller certifies it afresh
            notes.append(f"best of natural residual, mean gap error {self.test.best:.2g}")
        self.test.best_iterate.destroy()
        return Outcome(separation=target, iterations=self.tao.getIterationNumber(),
                       reason=f"{reason} ({', '.join(notes)})" if notes else reason,
                       history=self.test.history.as_array())

    def destroy(self):
        self.tao.destroy()
        for obj in (self.gradient, self.elastic, self.lower, self.upper, self.constraint, self.jacobian):
            obj.destroy()


class _NaturalTest:
    """ALMM's outer convergence test: the natural residual on a fresh S g and the mean gap's error, a time
    limit, stagnation."""

    def __init__(self, adhesive, elastic_vec, target):
        self.adhesive = adhesive
        self.target = target
        self.elastic_vec = elastic_vec
        self.history = History(adhesive.problem)
        self.best, self.best_iteration, self.stopped_by = np.inf, 0, None
        self.best_iterate = adhesive.problem.vec()  # returned by a stop short of the tolerance

    def __call__(self, tao):
        adhesive = self.adhesive
        problem = adhesive.problem
        x = tao.getSolution()
        adhesive.elastic_pressure(x, self.elastic_vec)
        g = problem.local(x, readonly=True).ravel()
        elastic = problem.local(self.elastic_vec, readonly=True).ravel()
        r, open_nodes = np.empty_like(g), np.empty(g.shape, dtype=bool)
        adhesive.gradient(g, elastic, r)
        lam, _ = adhesive.multiplier(g, r, open_nodes)
        natural = adhesive.natural(g, r, lam)
        total, = allsum(problem.mpi, [g.sum()])
        natural = max(natural, abs(total / problem.n - self.target))  # the equality counts too
        iteration = tao.getIterationNumber()
        self.history.record(iteration, natural)
        if natural < self.best:
            self.best, self.best_iteration = natural, iteration
            x.copy(self.best_iterate)
        if natural <= adhesive.rtol:
            tao.setConvergedReason(PETSc.TAO.Reason.CONVERGED_USER)
        elif self.history.out_of_time(adhesive.max_seconds):
            self.stopped_by = "time limit"
            tao.setConvergedReason(PETSc.TAO.Reason.DIVERGED_USER)
        elif iteration - self.best_iteration >= STAGNATION_ITERATIONS:
            self.stopped_by = "stagnation"
            tao.setConvergedReason(PETSc.TAO.Reason.DIVERGED_USER)
        elif iteration >= tao.getMaximumIterations():
            tao.setConvergedReason(PETSc.TAO.Reason.DIVERGED_MAXITS)

