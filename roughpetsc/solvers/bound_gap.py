"""Load control of every bound-constrained TAO type in the gap: one TAO solve holds mean(p) = pbar exactly.

On the periodic cell, with the stiffness S (symbol pi E* |k|, zero on the mean) and the gap g = K p + d - h,
the pressure is p = pbar + S (g + h). The gap g >= 0 that minimises

    Pi(g) = 1/2 (g + h)' S (g + h) + pbar sum(g)

has the gradient p, so the KKT conditions of Pi are those of the contact problem (3.41)-(3.44): g >= 0, p >= 0,
g p = 0, and mean(p) = pbar holds at every iterate. Its Hessian is S. :class:`CompliancePreconditioner`, the
compliance K on the free set (the mirror of Polonsky-Keer's S on the contact set), starts the quasi-Newton
types' L-BFGS, and preconditions the Newton types' KSP with ``-bound_pc fourier`` (TRON's default; the others'
is none, which measured better; docs/solvers.md). This works on the periodic boundary
without a hardness cap only: the free boundary's stiffness is no Fourier filter, and a cap bounds p, which is
the gradient here, not the unknown. See docs/solvers.md.
"""

import math

import numpy as np
from petsc4py import PETSc

from ..contact import loops
from ..errors import UserError
from ..parallel import allmax, allmin, allsum
from .bound_qp import AugmentedQuadratic, BoundQP, FourierInitialHessian, PenalizedCompliance, _set_recycle
from .preconditioner import FourierPreconditioner
from .protocol import Outcome
from .stopping import ConvergenceTest, History, describe_stop, option_name

# Weight of the free set's uniform mode in the initial Hessian. BLMVM at N = 256, p* = 0.5 (group #1) took
# 239 / 201 / 162 FFT pairs at 0.3 / 1 / 3, and stopped on a failed line search at 8.
GAP_MEAN_MODE_WEIGHT = 3.0
# The reported pressure's residual is measured at each new lowest residual of the iterate below this multiple of
# the tolerance (GapLoadQP._natural_residual).
CHECK_ABOVE = 10.0
# The Newton types that take the compliance preconditioner by default here. TRON (KSP at 0.1) took 165 / 142 / 70
# FFT pairs with it against 206 / 95 / 53 without at N = 512, 158 / 158 / 75 against 283 / 122 / 71 at 1024
# (group #1, p* = 0.05 / 0.5 / 2): fewer at the small load, where it was slowest. BNTR (292 / 244 / 121 against
# 427 / 161 / 91 at 512) and GPCG keep none: GPCG, preconditioned on its free set (FreeSetPC), ran out of 100 s
# at a natural residual of 5.2e-10 / 1.2e-6 at N = 512, p* = 0.05 / 0.5 (301 / 146 pairs without), its line
# search's floor (docs/solvers.md), and took 103 pairs against 78 at p* = 2.
GAP_FOURIER_DEFAULT_TYPES = ("tron",)
# The cold start's bisection on the separation (GapLoadQP._cold_separation) stops once the free nodes' mean
# pressure is within this fraction of pbar, or after START_STEPS operator applications.
START_TOLERANCE = 0.3
START_STEPS = 20


class GapQuadratic(AugmentedQuadratic):
    """Pi(g) of the module docstring and its gradient p; the separation of a point is d = mean(g) + mean(h)."""

    def __init__(self, problem):
        super().__init__(problem)
        self.loaded_heights = problem.vec()  # -S h, as the gradient's kernel subtracts its heights
        problem.operator.elastic_pressure(problem.heights, self.loaded_heights)
        self.loaded_heights.scale(-1.0)
        self.mean_height = problem.heights.sum() / problem.n

    def _apply(self, x, out):
        self.problem.operator.elastic_pressure(x, out)
        return self.loaded_heights.getArray(readonly=True), self.pbar

    def _separation(self, offset, total):
        return total / self.problem.n + self.mean_height

    def destroy(self):
        super().destroy()
        self.loaded_heights.destroy()


class _Stiffness:
    """The Hessian S of Pi (+ BNK's shift) as a MATPYTHON context's ``mult`` and ``getDiagonal``."""

    def mult(self, mat, x, y):
        self.problem.operator.elastic_pressure(x, y)
        if self.perturbation:
            y.axpy(self.perturbation, x)

    def getDiagonal(self, mat, d):
        d.set(self.problem.operator.stiffness_diagonal + self.perturbation)


class GapHessian(_Stiffness, PenalizedCompliance):
    """MATPYTHON context: the Hessian S of Pi."""


class CompliancePreconditioner(FourierPreconditioner):
    """The mirror of Polonsky-Keer's preconditioner for S on the free set F of the gap: K applied to the residual
    made zero-mean on F, and F's uniform mode by its own stiffness 1_C' S 1_C / |F| (C the fixed nodes)."""

    mean_mode_weight = GAP_MEAN_MODE_WEIGHT

    def inverse_symbol(self, source, target):
        self.problem.operator.compliance(source, target)

    def mean_mode_compliance(self, free, count):
        """The stiffness of the uniform gap on F (the divisor of its mean): recomputed, one operator application,
        when |F| changed by more than 5 %; without fixed nodes, that of the longest wavelength."""
        computed_for, stiffness = self._mean_mode
        if abs(count - computed_for) <= 0.05 * count:
            return stiffness
        problem = self.problem
        fixed = problem.local(self.indicator).ravel()
        np.subtract(1.0, free, out=fixed)
        problem.operator.elastic_pressure(self.indicator, self.response)
        energy, = allsum(problem.mpi, [np.dot(problem.local(self.response, readonly=True).ravel(), fixed)])
        grid = problem.scaled_grid
        stiffness = energy / count if energy > 0 else np.pi / max(grid.l0, grid.l1)
        self._mean_mode = (count, stiffness)
        return stiffness


class GapInitialHessian(_Stiffness, FourierInitialHessian):
    """The quasi-Newton types' initial Hessian in the gap: gamma times :class:`CompliancePreconditioner` on the
    free set, gamma / diag(S) off it."""

    mean_mode_weight, mean_mode_type = GAP_MEAN_MODE_WEIGHT, CompliancePreconditioner

    def __init__(self, problem, objective):
        super().__init__(problem, objective)
        self.fixed_scale = 1.0 / problem.operator.stiffness_diagonal


class GapLoadQP(BoundQP):
    """A bound-constrained TAO type under load control, solved for the gap (module docstring)."""

    objective_type, hessian_type, initial_hessian_type = GapQuadratic, GapHessian, GapInitialHessian
    preconditioner_type = CompliancePreconditioner
    load_method = "gap"
    keeps_displacement = True  # the load path's K p of the start spares the start's operator application

    def __init__(self, problem, control, tao_type, settings):
        name = option_name("bound_load", settings.prefix)
        where = name + " gap"
        if control != "load":
            raise UserError(f"{where} is a method of load control")
        if problem.boundary != "periodic" or problem.upper_bound is not None:
            raise UserError(f"{where} needs the periodic boundary without a hardness cap (the free boundary's "
                            f"stiffness is no Fourier filter; a cap bounds the pressure, which is the gradient "
                            f"there): use {name} al")
        # Before the base's set-up, whose refusal of a bad TAO option calls destroy.
        self.variable, self.reported = problem.vec(), problem.vec()
        super().__init__(problem, control, tao_type, settings)
        self.lowest = math.inf
        self.name = self.tao.getType() + "(gap)"

    @staticmethod
    def _default_preconditioner(tao_type):
        return "fourier" if tao_type in GAP_FOURIER_DEFAULT_TYPES else "none"

    @PETSc.Log.EventDecorator("RPBoundTest")  # -log_view: the fused convergence test
    def _natural_residual(self, tao):
        """``(natural, load error, fresh)`` of the iterate: the residual of (g, gradient) and no load error (the
        gradient's mean is pbar); once that is within the tolerance, those of the pressure it would report, on
        that pressure's own fresh gap (one operator application).

        Zeroing the pressure off contact moves the fresh gap by K of its small remainder, mostly long waves:
        the reported residual was 1.1-5000 times the iterate's. A ratio measured at one iterate did not hold at
        the next, so every iterate within the tolerance is measured. Zeroing also removes the residual of small
        gaps, so the reported residual can be the smaller: GPCG at N = 512, p* = 0.05 stalled at 4.9e-8 with a
        reported 1.9e-9. So each new lowest residual within CHECK_ABOVE times the tolerance is measured too.
        The iterate goes to the spare buffer in the same pass.
        """
        x = tao.getSolution()
        gradient, _, separation = self.objective.cached_gap(x)
        pbar = self.objective.pbar
        # natural_and_copy scales its first argument by 1 / scale: min(p, pbar g) / pbar = min(p / pbar, g).
        local = loops.natural_and_copy(x.getArray(readonly=True), gradient, 1.0 / pbar, math.inf,
                                       self.buffers[1 - self.best].getArray()) / pbar
        natural, = allmax(self.problem.mpi, [local])
        load_error = None
        if natural <= self.rule.rtol or (natural <= CHECK_ABOVE * self.rule.rtol and natural < self.lowest):
            self.lowest = natural
            natural, load_error = self._reported_residual(x, gradient, pbar, separation)
        self.last = (natural, load_error, pbar, separation)
        return natural, load_error, True

    def _reported_residual(self, gap, gradient, pbar, separation):
        """The natural residual and load error of the reported pressure on its fresh gap."""
        problem = self.problem
        pressure, fresh = self.reported, self.objective.scratch
        self._report(gap.getArray(readonly=True), gradient, pbar, pressure.getArray())
        problem.gap(pressure, separation, fresh)
        total, = allsum(problem.mpi, [pressure.getArray(readonly=True).sum()])
        local = loops.natural_and_copy(pressure.getArray(readonly=True), fresh.getArray(readonly=True), pbar,
                                       math.inf, fresh.getArray())
        natural, = allmax(problem.mpi, [local])
        return natural, abs(total / problem.n - pbar) / pbar

    @staticmethod
    def _report(gap, gradient, pbar, out):
        """The pressure reported for a gap: its gradient where that exceeds pbar g (the side of the natural
        residual's min that says "in contact"), zero elsewhere, as A counts p > 0."""
        np.copyto(out, np.where(gradient > pbar * gap, gradient, 0.0))

    def _cold_separation(self, pbar):
        """The separation d of a cold start: where the surface cut at d, g = max(d - h, 0), has free nodes (g > 0)
        of mean pressure zero, the minimum of Pi along d. Bisection between the lowest and highest heights, one
        operator application a step, to START_TOLERANCE pbar.

        The start before, d at the highest summit, put the free set's uniform mode so far from its optimum that
        the first quasi-Newton steps overshot it at small loads: BLMVM at N = 256 (group #1) took 1150 / 98 /
        121 / 46 FFT pairs at p* = 0.01 / 0.05 / 0.5 / 2 from there, 64 / 65 / 95 / 44 from here (the search's
        5 / 3 / 4 / 2 pairs included). The pressure vanishes on the free set of both the shallow end (nearly every
        node free) and the deep end (none), so the search keeps the sign, not the size, of the mean.
        """
        problem, mpi = self.problem, self.problem.mpi
        heights = problem.local(problem.heights, readonly=True)
        cut, response = self.reported, self.variable  # free until the solve fills them
        low, = allmin(mpi, [heights.min()])
        high = problem.max_height
        for _ in range(START_STEPS):
            separation = 0.5 * (low + high)
            np.maximum(heights, separation, out=problem.local(cut))  # g + h
            problem.operator.elastic_pressure(cut, response)
            free = problem.local(cut, readonly=True) > heights
            count, stiff = allsum(mpi, [np.count_nonzero(free), problem.local(response, readonly=True)[free].sum()])
            total = pbar * count + stiff  # the sum of p = pbar + S (g + h) over the free nodes
            if count and abs(total) <= START_TOLERANCE * pbar * count:
                break
            if count and total > 0:
                high = separation
            else:
                low = separation
        return separation

    def solve(self, target, pressure, guess=None, history=None):
        """Solve for the mean pressure ``target`` from ``pressure`` (overwritten with the solution).

        The start is the gap of ``pressure`` at the guessed separation (without one, :meth:`_cold_separation`),
        clipped at zero: one operator application, none where the load path's predictor gives K p of ``pressure``
        (``guess.displacement``).
        """
        problem = self.problem
        history = history or History(problem)
        test = ConvergenceTest(self.rule.watch(history), self._natural_residual, keep_best=self._keep_best)
        self.tao.setConvergenceTest(test)
        self.last = None
        self.lowest = math.inf  # the lowest residual of an iterate measured for its reported pressure
        self.objective.configure(0.0, 0.0, target)
        gap = self.variable
        separation = guess.separation if guess is not None and guess.separation is not None else None
        if separation is None:
            separation = self._cold_separation(target)
        if guess is not None and guess.displacement is not None:
            gap.waxpy(-1.0, problem.heights, guess.displacement)
            gap.shift(separation)
        else:
            problem.gap(pressure, separation, gap)
        np.maximum(problem.local(gap), 0.0, out=problem.local(gap))
        _set_recycle(self.tao, False)
        iterations, restarts = self._run(gap, test)
        reason = self.tao.getConvergedReason()
        if reason < 0 and np.isfinite(test.watch.best_natural):
            self.buffers[self.best].copy(gap)
        gradient, _, separation = self.objective.cached_gap(gap)
        self._report(gap.getArray(readonly=True), gradient, target, pressure.getArray())
        return Outcome(separation, iterations, describe_stop(reason, test.watch, restarts, load_control=True),
                       history.as_array())

    def destroy(self):
        super().destroy()
        self.variable.destroy()
        self.reported.destroy()
