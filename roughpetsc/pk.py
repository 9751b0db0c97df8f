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

    def solve(self, tao):
        problem = self.problem
        operator = problem.operator
        mpi = problem.mpi
        n = problem.n
        pbar = self.target_pbar
        pressure = tao.getSolution()
        p = problem.local(pressure).ravel()
        h = problem.local(problem.heights, readonly=True).ravel()
        gap = problem.local(self.displacement).ravel()
        t = problem.local(self.direction).ravel()
        r = problem.local(self.direction_response).ravel()
        contact = np.empty_like(p)  # 1.0 on the contact set, 0.0 elsewhere: masks as dot products
        t[...] = 0.0
        self.history = History(operator)
        max_it = tao.getMaximumIterations()
        norm_old, conjugate = 1.0, False
        iteration, reason = 0, PETSc.TAO.Reason.DIVERGED_MAXITS
        while True:
            np.greater(p, 0.0, out=contact)
            operator.displacement(pressure, self.displacement)
            gap -= h
            count, gap_sum = allsum(mpi, [contact.sum(), np.dot(gap, contact)])
            mean_gap = gap_sum / count
            gap -= mean_gap  # g = K p - h + d with d fixed by a zero mean gap on the contact set
            self.separation = -mean_gap
            kkt = report(mpi, p, gap, n, pbar)
            self.history.record(iteration, kkt.natural)
            tao.monitor(its=iteration, f=kkt.complementarity, res=kkt.natural, cnorm=kkt.load_error or 0.0)
            if kkt.natural <= self.rtol and kkt.load_error <= self.rtol:
                reason = PETSc.TAO.Reason.CONVERGED_USER
                break
            if iteration >= max_it:
                break
            # Conjugate direction on the contact set: t = g_c + beta t_c.
            t *= contact
            np.multiply(gap, contact, out=r)  # r holds g_c until K t overwrites it
            norm, = allsum(mpi, [np.dot(r, r)])
            t *= norm / norm_old if conjugate else 0.0
            t += r
            norm_old = norm
            operator.displacement(self.direction, self.direction_response)
            # Step length with K t less its mean on the contact set (t vanishes off it).
            r_sum, t_sum, numerator, r_dot_t = allsum(mpi, [np.dot(r, contact), t.sum(), np.dot(gap, t),
                                                             np.dot(r, t)])
            denominator = r_dot_t - r_sum / count * t_sum
            if not denominator > 0:
                reason = PETSc.TAO.Reason.DIVERGED_LS_FAILURE
                break
            step = numerator / denominator
            # r (K t) is spent: it is the scratch for the products, so no N^2 temporaries.
            np.multiply(t, step, out=r)
            p -= r
            np.maximum(p, 0.0, out=p)
            # Nodes out of contact that the gap says overlap re-enter; then restart CG.
            overlap = (gap < 0) & (p == 0)
            entering, = allsum(mpi, [np.count_nonzero(overlap)])
            if entering:
                np.multiply(gap, -step, out=r)
                np.copyto(p, r, where=overlap)
            conjugate = entering == 0
            total, = allsum(mpi, [p.sum()])
            p *= pbar * n / total
            iteration += 1
            tao.setIterationNumber(iteration)
        tao.setIterationNumber(iteration)
        tao.setConvergedReason(reason)
