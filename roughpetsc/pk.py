"""Polonsky-Keer constrained conjugate gradients under load control, as a TAO ``python`` type.

Polonsky and Keer, Wear 231 (1999): CG on the contact set with the mean gap
there removed (which fixes the rigid separation), a restart whenever nodes
enter the contact set, projection onto p >= 0 and rescaling to the prescribed
mean pressure after each step. Two operator applications per iteration: K p
for the gap and K t for the step length.

The stopping rule is the natural KKT residual of :mod:`roughpetsc.kkt`,
evaluated on the gap of the current iterate (which the iteration computes
anyway). ``tao.monitor`` is called every iteration so that ``-tao_monitor``
and Python monitors work.
"""

import numpy as np
from petsc4py import PETSc

from .kkt import History, allsum, report


class PolonskyKeer:
    """The context of a TAO of type ``python``; set ``target_pbar`` (scaled) before ``tao.solve``."""

    def __init__(self, problem, rtol):
        self.problem = problem
        self.rtol = rtol
        self.target_pbar = None
        self.separation = 0.0
        self.displacement = problem.vec()
        self.direction = problem.vec()
        self.direction_response = problem.vec()
        self.history = None

    def destroy(self, tao=None):
        for v in (self.displacement, self.direction, self.direction_response):
            v.destroy()

    def _contact_mean(self, values, in_contact):
        total, count = allsum(self.problem.mpi, [values[in_contact].sum(), np.count_nonzero(in_contact)])
        return total / count if count else 0.0

    def solve(self, tao):
        problem = self.problem
        operator = problem.operator
        n = problem.n
        pbar = self.target_pbar
        pressure = tao.getSolution()
        p = problem.local(pressure)
        h = problem.local(problem.heights, readonly=True)
        u = problem.local(self.displacement)
        t = problem.local(self.direction)
        r = problem.local(self.direction_response)
        t[...] = 0.0
        self.history = History(operator)
        max_it = tao.getMaximumIterations()
        norm_old, conjugate = 1.0, False
        iteration, reason = 0, PETSc.TAO.Reason.DIVERGED_MAXITS
        while True:
            in_contact = p > 0
            operator.displacement(pressure, self.displacement)
            gap = u  # reuse the displacement storage for the gap: g = K p - h + d
            gap -= h
            mean_gap = self._contact_mean(gap, in_contact)
            gap -= mean_gap
            self.separation = -mean_gap
            kkt = report(problem.mpi, p, gap, n, pbar)
            self.history.record(iteration, kkt.natural)
            tao.monitor(its=iteration, f=kkt.complementarity, res=kkt.natural, cnorm=kkt.load_error or 0.0)
            if kkt.natural <= self.rtol and kkt.load_error <= self.rtol:
                reason = PETSc.TAO.Reason.CONVERGED_USER
                break
            if iteration >= max_it:
                break
            # Conjugate direction on the contact set.
            norm, = allsum(problem.mpi, [np.dot(gap[in_contact], gap[in_contact])])
            beta = norm / norm_old if conjugate else 0.0
            t *= beta
            t += gap
            t[~in_contact] = 0.0
            norm_old = norm
            operator.displacement(self.direction, self.direction_response)
            r -= self._contact_mean(r, in_contact)
            numerator, denominator = allsum(problem.mpi, [np.dot(gap[in_contact], t[in_contact]),
                                                          np.dot(r[in_contact], t[in_contact])])
            if not denominator > 0:
                reason = PETSc.TAO.Reason.DIVERGED_LS_FAILURE
                break
            step = numerator / denominator
            p -= step * t
            np.maximum(p, 0.0, out=p)
            # Nodes out of contact that the gap says overlap re-enter; then restart CG.
            overlap = (p == 0) & (gap < 0)
            entering, = allsum(problem.mpi, [np.count_nonzero(overlap)])
            p[overlap] -= step * gap[overlap]
            conjugate = entering == 0
            total, = allsum(problem.mpi, [p.sum()])
            p *= pbar * n / total
            iteration += 1
            tao.setIterationNumber(iteration)
        tao.setIterationNumber(iteration)
        tao.setConvergedReason(reason)
