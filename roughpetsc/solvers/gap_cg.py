"""Projected conjugate gradients on the gap for adhesive contact (:class:`roughpetsc.contact.AdhesiveProblem`).

Rey, Anciaux and Molinari (Comput. Mech. 60, 2017), preconditioned by the compliance, with a BCCG free set
and an Armijo line search on the non-convex energy: docs/solvers.md.
"""

import numpy as np
from petsc4py import PETSc

from ..parallel import allmax, allmin, allsum
from ..contact import loops
from .options import python_tao
from .protocol import Backend, Outcome
from .registry import register
from .stopping import ConvergenceTest, History, Verdict, check_convergence, describe_stop

REFRESH = 50  # recompute S g at least every REFRESH iterations (the update S g -= step S t drifts)
ARMIJO = 1e-4
MAX_BACKTRACKS = 40
MAX_PROJECTED_TRIALS = 8  # projected steps tried an iteration (a pair each), then steps short of the breakpoint
BREAKPOINT_ROUNDOFF = 1e-12  # a step moving no gap by more than this times the largest gap is below round-off
# A fall of the energy by this fraction of the work of adhesion (over the surface) since the last counts as
# progress (it restarts the stagnation count): far above the round-off floor, where steps change the energy by
# residual^2.
ENERGY_PROGRESS = 1e-10


def project_mean(mpi, g, target, n):
    """``g <- max(g - c, 0)`` with c such that the mean of g is ``target`` (in place).

    Newton's method on the convex, decreasing, piecewise-linear ``sum max(g - c, 0) - n target``.
    """
    total, = allsum(mpi, [g.sum()])
    c = (total - n * target) / n
    for _ in range(100):
        above = g > c
        count, excess = allsum(mpi, [np.count_nonzero(above), (g - c).sum(where=above)])
        f = excess - n * target
        if f <= 1e-15 * n * max(target, 1e-300) or not count:
            break
        c += f / count
    g -= c
    np.maximum(g, 0.0, out=g)


class _Scratch:
    """The local arrays of one solve, allocated once."""

    def __init__(self, size):
        self.r = np.empty(size)
        self.free = np.empty(size)
        self.open = np.empty(size, dtype=bool)
        self.before = np.empty(size)  # the gap before a step, and S (g + h) there: a projected step may be undone
        self.elastic = np.empty(size)
        self.best = np.empty(size)  # an iterate near the lowest natural residual, returned by a stop short of it


class GapCG:
    """The projected CG on the gap as the context of a TAO of type ``python`` (so -tao_monitor, -tao_max_it work).

    Before ``tao.solve`` set :attr:`target` (the scaled mean gap); the TAO's solution is the gap.
    """

    def __init__(self, problem, rule):
        self.problem = problem
        self.rule = rule
        self.target = None
        self.watch = None
        self.history = None
        self.failure = None  # why the line search gave up, when it did
        self.current = None  # (natural, None, fresh) of the iterate the convergence test judges
        self.vecs = [problem.vec() for _ in range(5)]  # direction, S t, preconditioned, previous r, S (g + h)

    def setFromOptions(self, tao):
        pass

    def view(self, tao, viewer):
        viewer.printfASCII(f"  projected CG on the gap (Rey-Anciaux-Molinari), preconditioned by the compliance; "
                           f"S g refreshed every {REFRESH} iterations; stops at a natural residual of "
                           f"{self.rule.rtol:g}\n")

    def destroy(self, tao=None):
        for v in self.vecs:
            v.destroy()
        self.vecs = []

    def solve(self, tao):
        problem = self.problem
        operator, mpi, n = problem.operator, problem.mpi, problem.n
        law = problem.scaled_law
        target = self.target
        gap_vec = tao.getSolution()
        direction_vec, response_vec, preconditioned_vec, previous_vec, elastic_vec = self.vecs
        g = problem.local(gap_vec).ravel()
        elastic = problem.local(elastic_vec).ravel()
        t = problem.local(direction_vec).ravel()
        response = problem.local(response_vec).ravel()
        z = problem.local(preconditioned_vec).ravel()
        r_old = problem.local(previous_vec).ravel()
        scratch = _Scratch(g.size)
        r, free = scratch.r, scratch.free
        t[...] = 0.0
        r_old[...] = 0.0
        project_mean(mpi, g, target, n)
        self.history = History(problem)
        self.watch = self.rule.watch(self.history, tao.getMaximumIterations())
        test = ConvergenceTest(self.watch, lambda tao: self.current)
        tao.setConvergenceTest(test)
        tao.setConvergedReason(PETSc.TAO.Reason.CONTINUE_ITERATING)
        tao.setIterationNumber(0)
        self.failure = None
        rz_old, fresh_needed, since_fresh = 1.0, True, 0
        saved, fallen = np.inf, 0.0
        iteration, reason = 0, PETSc.TAO.Reason.DIVERGED_MAXITS
        while True:
            if fresh_needed or since_fresh >= REFRESH:
                problem.elastic_pressure(gap_vec, elastic_vec)
                fresh_needed, since_fresh = False, 0
            problem.gradient(g, elastic, r)
            lam, open_count = problem.multiplier(g, r, scratch.open)
            natural = problem.natural(g, r, lam)
            self.current = (natural, None, since_fresh == 0)
            reason = check_convergence(tao)
            if test.verdict is Verdict.CONFIRM:
                fresh_needed = True  # confirm on a freshly computed S g
                continue
            tao.monitor(its=iteration, res=natural)
            if reason != PETSc.TAO.Reason.CONTINUE_ITERATING:
                break
            if self.watch.improved and natural <= 0.5 * saved:
                saved = natural  # an N^2 copy per halving of the residual, not per iteration
                np.copyto(scratch.best, g)
            # The free set: out of contact, and the contact nodes that pull (they open along the direction);
            # the residual on it, at zero mean there (directions keep the mean gap).
            count, total = allsum(mpi, loops.gap_free_residual(r, lam, scratch.open, free, response))
            loops.shift_on(response, free, total / count, response)
            operator.displacement(response_vec, preconditioned_vec)
            _restrict(mpi, z, free, count)
            rz, r_old_z, t_free, z_sum = allsum(mpi, loops.conjugacy_sums(response, z, r_old, t, free, True))
            beta = max((rz - r_old_z) / rz_old, 0.0) if iteration else 0.0
            rz_old = rz
            # t = beta t + z, at zero mean on the free set.
            loops.new_direction(t, free, beta, (beta * t_free + z_sum) / count, z)
            slope = _feasible(mpi, t, r, scratch.open, open_count)
            if not slope > 0:
                # Not a descent direction once feasible: the projected residual is one (CG restarts).
                np.copyto(t, response)
                slope = _feasible(mpi, t, r, scratch.open, open_count)
                r_old[...] = 0.0
                if not slope > 0:
                    reason, self.failure = PETSc.TAO.Reason.DIVERGED_LS_FAILURE, \
                        "no feasible descent direction (round-off)"
                    break
            operator.elastic_pressure(direction_vec, response_vec)  # S t
            curvature_elastic, elastic_slope = allsum(mpi, loops.two_dots(t, response, elastic))
            # A piecewise-linear law adds nothing: no reduction over the ranks for it.
            curvature = curvature_elastic + (allsum(mpi, [law.curvature_along(g, t)])[0] if law.curved else 0.0)
            if not curvature > 0:
                curvature = curvature_elastic
            change, projected = self._descend(gap_vec, t, slope, (curvature_elastic, elastic_slope),
                                              slope / curvature, scratch)
            if change is None:
                reason, self.failure = PETSc.TAO.Reason.DIVERGED_LS_FAILURE, \
                    "no decrease of the energy along the direction"
                break
            since_fresh = 0 if projected else since_fresh + 1
            fallen -= change
            if fallen > ENERGY_PROGRESS * law.work * n:
                # The energy still falls: a long descent (past a jump in or out of contact), not stagnation.
                self.watch.restart(iteration)
                fallen = 0.0
            iteration += 1
            tao.setIterationNumber(iteration)
        if reason < 0 and np.isfinite(self.watch.best_natural) and natural > saved:
            np.copyto(g, scratch.best)  # an iterate within a factor 2 of the best; the facade certifies it
        tao.setIterationNumber(iteration)
        tao.setConvergedReason(reason)

    def _descend(self, gap_vec, t, slope, elastic_parts, step, scratch):
        """Step the gap of ``gap_vec`` along -t by the first of ``step``, step/2, ... that lowers the energy enough;
        ``(change of the energy, whether S g was computed afresh)``, or (None, False) if no step does.

        A step that crosses g = 0 is kept only if the projected gap's energy, on a fresh S g, is lower. After
        MAX_PROJECTED_TRIALS such trials (a pair each) the step is cut to the first breakpoint, which needs no
        projection; a breakpoint below the gaps' round-off closes the blocking gaps instead ((0.0, False)).
        """
        problem = self.problem
        elastic_vec = self.vecs[4]
        g, elastic, response = (problem.local(v).ravel() for v in (gap_vec, elastic_vec, self.vecs[1]))
        limit, failed = 0.0, 0  # the first breakpoint, once projected steps have failed; how many have
        while True:
            step, change = _armijo_step(problem, g, t, slope, *elastic_parts, step)
            if step is None:
                return None, False
            np.copyto(scratch.before, g)
            crossed = allsum(problem.mpi, [loops.gap_step(g, t, step)])[0]
            if not crossed or step <= limit:
                if crossed:
                    np.maximum(g, 0.0, out=g)  # at the breakpoint, round-off may leave its gap at -1e-17
                loops.subtract_scaled(elastic, response, step)
                return change, False
            before = problem.energy(scratch.before, elastic)
            np.copyto(scratch.elastic, elastic)
            project_mean(problem.mpi, g, self.target, problem.n)
            problem.elastic_pressure(gap_vec, elastic_vec)
            change = (problem.energy(g, elastic) - before) * problem.n  # a sum over the nodes, as Armijo's
            if change < 0:
                return change, True
            np.copyto(g, scratch.before)
            np.copyto(elastic, scratch.elastic)
            failed += 1
            if failed < MAX_PROJECTED_TRIALS:
                step *= 0.5
                continue
            limit, = allmin(problem.mpi, [loops.first_breakpoint(g, t)])
            largest, = allmax(problem.mpi, [np.abs(g).max(initial=0.0)])
            if limit * allmax(problem.mpi, [np.abs(t).max(initial=0.0)])[0] <= BREAKPOINT_ROUNDOFF * largest:
                # A step to the breakpoint is below the gaps' round-off: the line search cannot see it. Every
                # gap at round-off that the direction closes goes into contact instead (a change at round-off,
                # S g kept): a projection leaves thousands of them at 1e-17 to 1e-13, and closing only the first
                # breakpoint's would take an iteration each.
                loops.close_blocking(g, t, BREAKPOINT_ROUNDOFF * largest)
                return 0.0, False
            step = min(0.5 * step, limit)


class GapCGBackend(Backend):
    """:class:`GapCG` as the backend ``gapcg`` of the adhesive problem (displacement control)."""

    def __init__(self, problem, control, name, settings):
        self.problem = problem
        self.context = GapCG(problem, settings.rule)
        self.tao = python_tao(problem.comm, self.context, settings.prefix)
        self.name = "gapcg"

    def solve(self, target, gap, guess):
        """Solve at the scaled mean gap ``target`` from ``gap`` (overwritten); ``guess`` is unused."""
        self.context.target = target
        self.tao.setSolution(gap)
        self.tao.solve(gap)
        reason = describe_stop(self.tao.getConvergedReason(), self.context.watch, note=self.context.failure)
        return Outcome(separation=target, iterations=self.tao.getIterationNumber(), reason=reason,
                       history=self.context.history.as_array())

    def destroy(self):
        self.tao.destroy()
        self.context.destroy()


def _restrict(mpi, v, free, count):
    """``v`` restricted to the free set (a 0/1 float mask) and shifted to zero mean there (in place)."""
    total, = allsum(mpi, [loops.masked_sum(v, free)])
    loops.shift_on(v, free, total / count, v)


def _feasible(mpi, t, r, open_nodes, open_count):
    """Make ``-t`` a feasible direction at g = 0 (in place); returns the slope ``<r, t>`` of the energy.

    A contact node may only open: t > 0 there is set to 0, and the mean of t restored on the open nodes.
    """
    total, = allsum(mpi, [loops.close_contact_nodes(t, open_nodes)])
    slope, = allsum(mpi, [loops.shift_open_slope(t, open_nodes, total / open_count, r)])
    return slope


def _armijo_step(problem, g, t, slope, curvature_elastic, elastic_slope, step):
    """The first of ``step``, step/2, ... along -t that decreases the energy enough, and that decrease (None, None if
    none does).

    The test is on the line before the projection (phi continued below g = 0 by its tangent). The change is
    summed node-wise, free of cancellation: -s <S(g + h), t> + s^2/2 <t, S t> + sum (phi(g - s t) - phi(g)).
    """
    law, mpi = problem.scaled_law, problem.mpi
    for _ in range(MAX_BACKTRACKS):
        law_change, = allsum(mpi, [law.energy_change_along(g, t, step)])
        change = step * (0.5 * step * curvature_elastic - elastic_slope) + law_change
        if change <= -ARMIJO * step * slope:
            return step, change
        step *= 0.5
    return None, None


register("gapcg", GapCGBackend, controls=("displacement",), kinds=("adhesive",))
