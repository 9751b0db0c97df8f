"""The adhesive problem as a TAO problem: ALMM with the mean-gap equality (``-tao_type almm`` with ``-adhesion``).

``min Pi(g)`` over ``g >= 0`` with ``mean(g) = gbar``: ALMM (PHR) handles the equality, a bound-constrained
subsolver (BQNLS) the bounds. Slower than :mod:`roughpetsc.solvers.gap_cg`, and bounded below by the round-off
floor of TAO's line searches on the energy.
"""

import numpy as np

from ..parallel import allsum
from .almm import MeanConstrainedALMM
from .gap_cg import project_mean
from .registry import register

DEFAULTS = {"tao_almm_type": "phr", "tao_almm_subsolver_tao_type": "bqnls"}


class AdhesiveALMM(MeanConstrainedALMM):
    """TAO ALMM on an :class:`~roughpetsc.contact.AdhesiveProblem` (displacement control, the mean gap prescribed)."""

    def __init__(self, problem, control, name, settings):
        self.elastic = problem.vec()
        self.best_iterate = problem.vec()  # returned by a stop short of the tolerance
        super().__init__(problem, settings, defaults=DEFAULTS)

    def evaluate(self, x, gradient):
        """Pi(x) per unit area and its gradient r / n (one operator application)."""
        problem = self.problem
        problem.elastic_pressure(x, self.elastic)
        g = problem.local(x, readonly=True)
        elastic = problem.local(self.elastic, readonly=True)
        r = problem.local(gradient)
        problem.gradient(g, elastic, r)
        r *= 1.0 / problem.n
        return problem.energy(g, elastic)

    def natural_residual(self, tao):
        """The natural residual on a fresh S g (one operator application) and the error of the mean gap."""
        problem = self.problem
        x = tao.getSolution()
        problem.elastic_pressure(x, self.elastic)
        g = problem.local(x, readonly=True).ravel()
        _, _, kkt = problem.stationarity(g, problem.local(self.elastic, readonly=True).ravel())
        total, = allsum(problem.mpi, [g.sum()])
        return kkt.natural, abs(total / problem.n - self.target), True

    def keep_best(self, x):
        x.copy(self.best_iterate)

    def prepare(self, gap):
        problem = self.problem
        project_mean(problem.mpi, problem.local(gap).ravel(), self.target, problem.n)

    def finish(self, gap, reason):
        if reason < 0 and np.isfinite(self.watch.best_natural):
            self.best_iterate.copy(gap)  # the facade certifies it afresh
        return self.target

    def destroy(self):
        super().destroy()
        self.elastic.destroy()
        self.best_iterate.destroy()


register("almm", AdhesiveALMM, controls=("displacement",), kinds=("adhesive",))
