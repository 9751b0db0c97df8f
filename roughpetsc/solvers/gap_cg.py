"""Projected conjugate gradients on the gap for adhesive contact (:mod:`roughpetsc.adhesive`).

The algorithm of Rey, Anciaux and Molinari (Comput. Mech. 60, 2017), Polonsky-Keer's CG with the gap
as the unknown and the mean gap as the constraint, with three changes of ours:

* the search direction is preconditioned by the compliance (the inverse symbol 1 / (pi E* |k|) of the
  Hessian S, as Polonsky-Keer on the pressure is preconditioned by the stiffness; Vollebregt, J.
  Comput. Phys. 257, 2014), restricted to the free set and kept at zero mean there;
* the free set is the nodes out of contact and the contact nodes whose contact pressure is negative
  (they open along the direction itself, as in Vollebregt's BCCG), with the Polak-Ribiere beta
  clipped at 0 so conjugacy survives changes of the set;
* the step minimises the quadratic model with the law's curvature phi'' when that model is convex and
  the elastic one otherwise, and is then cut back until the energy decreases (Armijo), since phi makes
  the energy non-convex: the iterates follow the energy downhill to the local minimum next to the
  start, which is what a quasi-static path of adhesive contact needs.

After each step the gap is projected onto {g >= 0, mean g = gbar} exactly (a shift of the positive
nodes found by Newton's method on a piecewise-linear function). Every stop is decided on a freshly
computed S g; a stop short of the tolerance returns an iterate whose residual is within a factor 2 of the
lowest it saw (a copy is kept each time the residual halves, not at every iteration).
"""

import numpy as np

from ..kkt import STAGNATION_ITERATIONS, History, allsum
from .. import kernels
from .protocol import Outcome

REFRESH = 50  # recompute S g at least every REFRESH iterations (the update S g -= step S t drifts)
ARMIJO = 1e-4
MAX_BACKTRACKS = 40


def project_mean(mpi, g, target, n):
    """``g <- max(g - c, 0)`` with c such that the mean of g is ``target`` (in place).

    ``f(c) = sum max(g - c, 0) - n target`` is convex, decreasing and piecewise linear; Newton's method
    from the uniform shift (where f >= 0) increases c monotonically to the root in a few steps.
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


def gap_cg(adhesive, target):
    """Solve ``adhesive`` (an :class:`~roughpetsc.adhesive.AdhesiveContact`) at the scaled mean gap ``target``.

    ``adhesive.gap`` holds the start and receives the solution; ``adhesive.elastic`` holds S (g + h) of
    the last fresh evaluation. Returns an :class:`~roughpetsc.solvers.protocol.Outcome`.
    """
    problem = adhesive.problem
    vecs = [problem.vec() for _ in range(4)]
    try:
        return _iterate(adhesive, target, *vecs)
    finally:
        for v in vecs:
            v.destroy()


class _Scratch:
    """The local arrays of one solve, allocated once: the loop makes no N^2 temporaries."""

    def __init__(self, size):
        self.r = np.empty(size)
        self.work = np.empty(size)
        self.free = np.empty(size)
        self.open = np.empty(size, dtype=bool)
        # the line search's parts of phi (interaction laws' energy_changes_from)
        self.law = (np.empty(size), np.empty(size), np.empty(size))
        self.best = np.empty(size)  # an iterate near the lowest natural residual, returned by a stop short of it


def _iterate(adhesive, target, direction_vec, response_vec, preconditioned_vec, previous_vec):
    problem = adhesive.problem
    operator, mpi, n = problem.operator, problem.mpi, problem.n
    law = adhesive.scaled_law
    g = problem.local(adhesive.gap).ravel()
    elastic = problem.local(adhesive.elastic).ravel()
    t = problem.local(direction_vec).ravel()
    response = problem.local(response_vec).ravel()
    z = problem.local(preconditioned_vec).ravel()
    r_old = problem.local(previous_vec).ravel()
    scratch = _Scratch(g.size)
    r, work, free = scratch.r, scratch.work, scratch.free
    t[...] = 0.0
    r_old[...] = 0.0
    project_mean(mpi, g, target, n)
    history = History(problem)
    rz_old, fresh_needed, since_fresh = 1.0, True, 0
    best, best_iteration, saved, stopped_by = np.inf, 0, np.inf, None
    iteration, reason = 0, "DIVERGED_MAXITS"
    while True:
        if fresh_needed or since_fresh >= REFRESH:
            adhesive.elastic_pressure(adhesive.gap, adhesive.elastic)
            fresh_needed, since_fresh = False, 0
        adhesive.gradient(g, elastic, r)
        lam, open_count = adhesive.multiplier(g, r, scratch.open)
        natural = adhesive.natural(g, r, lam)
        if natural <= adhesive.rtol and since_fresh:
            fresh_needed = True  # confirm on a freshly computed S g
            continue
        history.record(iteration, natural)
        if natural <= adhesive.rtol:
            reason = "CONVERGED_USER"
            break
        if natural < best:
            best, best_iteration = natural, iteration
            if natural <= 0.5 * saved:  # an N^2 copy per halving of the residual, not per iteration
                saved = natural
                np.copyto(scratch.best, g)
        if iteration >= adhesive.max_iter:
            break
        if history.out_of_time(adhesive.max_seconds):
            reason, stopped_by = "DIVERGED_USER", "time limit"
            break
        if iteration - best_iteration >= STAGNATION_ITERATIONS:
            reason, stopped_by = "DIVERGED_USER", "stagnation"
            break
        # The free set: out of contact, and the contact nodes that pull (they open along the direction);
        # the residual on it, at zero mean there (directions keep the mean gap).
        count, total = allsum(mpi, kernels.gap_free_residual(r, lam, scratch.open, free, response))
        kernels.shift_on(response, free, total / count, response)
        operator.displacement(response_vec, preconditioned_vec)
        _restrict(mpi, z, free, count)
        rz, r_old_z, t_free, z_sum = allsum(mpi, kernels.conjugacy_sums(response, z, r_old, t, free, True))
        beta = max((rz - r_old_z) / rz_old, 0.0) if iteration else 0.0
        rz_old = rz
        # t = beta t + z, at zero mean on the free set.
        kernels.new_direction(t, free, beta, (beta * t_free + z_sum) / count, z)
        slope = _feasible(mpi, t, r, scratch.open, open_count)
        if not slope > 0:
            # Not a descent direction once feasible: the projected residual is one (CG restarts).
            np.copyto(t, response)
            slope = _feasible(mpi, t, r, scratch.open, open_count)
            r_old[...] = 0.0
            if not slope > 0:
                reason, stopped_by = "DIVERGED_LS_FAILURE", "no feasible descent direction (round-off)"
                break
        operator.elastic_pressure(direction_vec, response_vec)  # S t
        curvature_elastic, elastic_slope = allsum(mpi, kernels.two_dots(t, response, elastic))
        curvature = curvature_elastic + _law_curvature(law, mpi, g, t, work)
        if not curvature > 0:
            curvature = curvature_elastic
        step = _armijo_step(adhesive, g, t, slope, curvature_elastic, elastic_slope, slope / curvature, work,
                            scratch.law)
        if step is None:
            reason, stopped_by = "DIVERGED_LS_FAILURE", "no decrease of the energy along the direction"
            break
        if allsum(mpi, [kernels.gap_step(g, t, step)])[0]:
            project_mean(mpi, g, target, n)
            fresh_needed = True
        else:
            kernels.subtract_scaled(elastic, response, step)
        since_fresh += 1
        iteration += 1
    notes = [stopped_by] if stopped_by else []
    if not reason.startswith("CONVERGED") and np.isfinite(best):
        if natural > saved:  # natural: the residual of the last iterate, the one g holds
            np.copyto(g, scratch.best)  # the caller certifies it afresh
            natural = saved
        notes.append(f"best natural residual {natural:.2g}")
    return Outcome(separation=target, iterations=iteration,
                   reason=f"{reason} ({', '.join(notes)})" if notes else reason, history=history.as_array())


def _restrict(mpi, v, free, count):
    """``v`` restricted to the free set (a 0/1 float mask) and shifted to zero mean there (in place)."""
    total, = allsum(mpi, [kernels.masked_sum(v, free)])
    kernels.shift_on(v, free, total / count, v)


def _law_curvature(law, mpi, g, t, work):
    """``<phi''(g), t^2>``: the law's part of the curvature along t (0 for a piecewise-linear law)."""
    if not law.curved:
        return 0.0
    law.curvature(g, out=work)
    work *= t
    total, = allsum(mpi, [np.dot(work, t)])
    return total


def _feasible(mpi, t, r, open_nodes, open_count):
    """Make ``-t`` a feasible direction at g = 0 (in place); returns the slope ``<r, t>`` of the energy.

    A contact node (g = 0) may only open: where t > 0 it is set to 0, and the mean of t is restored on
    the ``open_count`` nodes out of contact (``open_nodes``, g > 0), which can move either way; small
    steps along -t then need no projection, so the energy change of the line search is that of the
    projected iterate.
    """
    total, = allsum(mpi, [kernels.close_contact_nodes(t, open_nodes)])
    slope, = allsum(mpi, [kernels.shift_open_slope(t, open_nodes, total / open_count, r)])
    return slope


def _armijo_step(adhesive, g, t, slope, curvature_elastic, elastic_slope, step, trial, law_scratch):
    """The first of ``step``, step/2, ... along -t that decreases the energy enough (None if none does).

    The test is on the energy along the line before the projection (phi continued below g = 0 by its
    tangent, :meth:`energy_change` of the laws), whose slope at 0 is exactly ``slope``; the projection
    follows, as in Polonsky-Keer. The change is summed from node-wise changes, so it does not cancel near
    the solution: the elastic part is the quadratic -s <S(g + h), t> + s^2/2 <t, S t>, the law's part
    sum (phi(g - s t) - phi(g)). ``trial`` and the two arrays of ``law_scratch`` are scratch of g's size.
    """
    law, mpi = adhesive.scaled_law, adhesive.problem.mpi
    changes = law.energy_changes_from(g, law_scratch)
    for _ in range(MAX_BACKTRACKS):
        np.multiply(t, -step, out=trial)
        trial += g
        law_change, = allsum(mpi, [changes(trial, trial).sum()])
        change = step * (0.5 * step * curvature_elastic - elastic_slope) + law_change
        if change <= -ARMIJO * step * slope:
            return step
        step *= 0.5
    return None
