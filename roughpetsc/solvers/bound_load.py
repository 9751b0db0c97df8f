"""Every bound-constrained TAO type under load and displacement control, with fused callbacks (issue 40).

Registered as ``fast_<type>`` for every type of :data:`~roughpetsc.solvers.bound_qp.BOUND_TYPES`
(``Solver(problem, "load", "fast_blmvm", rtol)``; ``-tao_type fast_blmvm`` once this module is imported),
beside the backends of :mod:`.bound_qp` and :mod:`.root_find`, which it is meant to replace. Three changes
against them; measured in studies/tao_speed.py (studies/output/tao_speed/tao_speed.md).

**Load control inside TAO, by an augmented Lagrangian on one scalar.** The load-controlled problem
(3.41)-(3.44) of the dissertation is ``min 1/2 p'Kp - p'h`` over ``p >= 0`` with ``mean(p) = pbar``;
the multiplier of the equality is the rigid separation d. Each inner solve minimises, by the TAO type,

    L(p; lambda) = 1/2 p'Kp - p'h + lambda (sum p - n pbar) + c n / 2 (mean p - pbar)^2,  p >= 0,

whose gradient is the gap ``K p - h + d`` at ``d = lambda + c (mean p - pbar)``: the solution is the
displacement-controlled one at that d, with the rigid flat held by a spring of compliance c. The
quadratic part is the same for every lambda, so the quasi-Newton memory stays valid from one inner
solve to the next (TaoSetRecycleHistory, BLMVM's recycle flag: ``-bound_al_recycle``) and so does the
pressure (warm start). lambda starts at the previous load's separation along a load path, else at
Polonsky-Keer's separation of the start (zero mean gap on its contact set; no operator application
more). Between inner solves lambda moves to the root of P(d) = pbar, P the mean pressure of the
displacement-controlled solution: the first move is a Newton step with the contact stiffness
k = -dP/dd = 1_C' K_CC^-1 1_C / n of the first inner solution (:func:`contact_stiffness`, a
preconditioned CG on its contact set C, about 10 to 20 operator applications; ``-bound_al_newton
false``: the method of multipliers, lambda <- d, which shrinks the separation error only by
1 / (1 + c k)); later ones a secant on the (d, log P) pairs (log P is nearer linear in d at small
loads), kept inside the bracket the pairs give. The inner solves are inexact: one stops as soon as its
natural residual is below ``-bound_al_eta`` times its load error; only the last one is solved to the
tolerance. Convergence: natural residual and load error both at most rtol on the same iterate, as in
:class:`~roughpetsc.kkt.ConvergenceTest`.

The penalty c is given in units of the compliance of the longest wavelength, L / pi (scaled units,
``-bound_al_penalty``, default 1): the Hessian ``K + c/n 1 1'`` then has the spectrum of K with the
rigid mode at the top of it. Larger penalties cost more (group #1, N = 256, p* = 0.5, BLMVM: 220, 645
and 4102 operator applications for c = 1, 10, 100; TRON 526, 796, 1197); 0.1 to 0.3 with eta 0.3 cost
172 to 190 against 220, which is within the noise of one surface, so the defaults stay at 1 and 0.1.

**The Fourier initial Hessian for the quasi-Newton types** (``-bound_h0 fourier|none``): BLMVM, BQNLS
(and the other BQNK types) start each L-BFGS two-loop recursion from ``gamma B r`` instead of PETSc's
scaled identity or diagonal, B Polonsky-Keer's preconditioner on the free set (free: 0 < p, or p = 0
with a negative gap; :class:`~roughpetsc.preconditioner.FourierPreconditioner`: the inverse
Westergaard symbol pi |k| of the residual less its mean on the free set, restricted to it, plus the
mean mode weighted by its compliance, which includes the penalty; an operator application each time
the free set's size changes by 5 %), and ``gamma / diag(K)`` on the fixed nodes. gamma corrects the
scale (:class:`FourierInitialHessian`): the symbol on a free set overestimates the inverse of K on it.
One FFT pair per quasi-Newton step, counted in the operator applications. The symbol alone (without the
mean-mode term) took 80 iterations where this took 49 (N = 256, p* = 0.5, displacement control). With
it, an L-BFGS memory of one pair is the default (fewest iterations and vector operations), and BQNLS
runs without its Bertsekas active-set estimate, which applies the initial Hessian a second time.

**Fused callbacks.** The objective (the exact increments of
:class:`~roughpetsc.solvers.objective.QuadraticObjective`) and the convergence test (natural residual,
load error, the best iterate) each make one pass over the vectors (:mod:`.bound_kernels`) instead of
about six and eleven; the best iterate is written into one of two buffers in that pass instead of
copied. The gap of an iterate is taken from the objective's cache when the iterate's Vec has not
changed since it was evaluated (its PETSc object state), else when it equals the cached point.

Options (under the solver's prefix): ``-bound_h0 fourier|none`` (default ``fourier`` for the
quasi-Newton types), ``-bound_al_penalty`` (1), ``-bound_al_eta`` (0.1), ``-bound_al_max_outer`` (40),
``-bound_al_recycle`` (true), ``-bound_al_newton`` (true), ``-bound_pc`` as for :mod:`.bound_qp`.
"""

import ctypes
import math

import numpy as np
from petsc4py import PETSc

from ..errors import UserError
from ..kkt import STAGNATION_ITERATIONS, ConvergenceTest, History, allmax, allmin, allsum
from .. import kernels
from ..preconditioner import MEAN_MODE_WEIGHT, FourierPreconditioner
from . import bound_kernels
from .bound_qp import (BOUND_PRECONDITIONERS, BOUND_TYPES, FOURIER_DEFAULT_TYPES, KSP_TYPES, MAX_RESTARTS,
                       RESTART_GAIN, BoundQP, restartable)
from .protocol import Backend, Outcome, describe_stop
from .registry import register
from .tao_options import DEFAULT_MAX_IT, _petsc_library, default_options, option_name, set_from_options

PREFIX = "fast_"
QUASI_NEWTON_TYPES = ("blmvm", "bqnls", "bqnkls", "bqnktr", "bqnktl")
INITIAL_HESSIANS = ("fourier", "none")
# Bounds of the initial Hessian's scale gamma (FourierInitialHessian); it settled at 0.1-0.3 in the solves measured.
GAMMA_BOUNDS = (1e-3, 1e3)


def _check(error, what):
    if error != 0:
        raise RuntimeError(f"PETSc error {error} in {what}")


class AugmentedQuadratic:
    """The objective L(p; lambda) of the module docstring and its gradient, the gap at d = lambda + c (mean p - pbar).

    ``penalty`` c = 0 and ``lam`` = d: the displacement-controlled QP ``1/2 p'Kp + p'(d - h)``. The value
    is accumulated from exact increments, f(x) = f(r) + (x - r)'(g(x) + g(r)) / 2 (a quadratic in p for
    fixed lambda), so that TAO's comparisons of values are free of cancellation
    (:class:`~roughpetsc.solvers.objective.QuadraticObjective`). :meth:`configure` restarts the values.

    The last evaluated point, its gap, its sum and its separation are cached (:meth:`cached_gap`).
    """

    def __init__(self, problem):
        self.problem = problem
        self.lam = 0.0
        self.penalty = 0.0
        self.pbar = None
        self.value = 0.0
        self.point, self.gap, self.scratch = problem.vec(), problem.vec(), problem.vec()
        self.cached = False
        self.state = None  # the PETSc object state of the evaluated Vec right after its evaluation
        self.vec_handle = None
        self.total = 0.0  # sum of p at the cached point
        self.separation = 0.0  # d of the cached point's gap
        self.initial_lam = False  # take lambda from the first evaluated point's contact set
        # Armed by the initial Hessian after it made a direction: the next evaluation (the line search's
        # first trial) records the exact minimiser along its step, in units of the step.
        self.probe_armed = False
        self.probe_ratio = None

    def configure(self, lam, penalty=0.0, pbar=None):
        """A new lambda (None: from the contact set of the first point evaluated), penalty and target."""
        self.lam = 0.0 if lam is None else lam
        self.initial_lam = lam is None
        self.penalty = penalty
        self.pbar = pbar
        self.cached = False

    def restart(self):
        """Forget the cached point: the next evaluated point has f = 0 (a new TAO solve)."""
        self.cached = False

    def evaluate(self, x, out):
        """``out = g(x)`` (one operator application); returns f(x)."""
        problem = self.problem
        n = problem.n
        x_local = x.getArray(readonly=True)
        separation = self.lam
        if self.penalty:
            total, = allsum(problem.mpi, [bound_kernels.local_sum(x_local)])
            separation += self.penalty * (total / n - self.pbar)
        problem.operator.displacement(x, out)
        out_local = out.getArray()
        if self.initial_lam:
            # PK's separation of the start: zero mean gap on its contact set (no operator application more).
            elastic = problem.local(self.scratch)
            np.subtract(out_local.reshape(elastic.shape), problem.local(problem.heights, readonly=True), out=elastic)
            self.lam = problem.contact_separation(x, elastic)
            self.initial_lam = False
            separation += self.lam
        sums = bound_kernels.gradient_step(x_local, self.point.getArray(), self.gap.getArray(), out_local,
                                           problem.heights.getArray(readonly=True), separation, out_local,
                                           self.cached)
        before, after, total = allsum(problem.mpi, sums)
        self.value = self.value + 0.5 * (before + after) if self.cached else 0.0
        if self.probe_armed and self.cached:
            # The first point after a new direction: how far along the step the quadratic's minimum lies.
            self.probe_ratio = -before / (after - before) if after > before else None
            self.probe_armed = False
        self.cached = True
        self.total, self.separation = total, separation
        self.vec_handle, self.state = x.handle, x.stateGet()
        return self.value

    def cached_gap(self, x):
        """``(gap, sum of p, separation)`` of the iterate ``x``: the gap as this rank's flat array.

        From the cache when ``x`` is the Vec last evaluated and unchanged since, or equal to the cached
        point; else evaluated (an operator application), which moves the base of the increments to ``x``.
        """
        fresh = self.cached and x.handle == self.vec_handle and x.stateGet() == self.state
        fresh = bool(allmin(self.problem.mpi, [float(fresh)])[0])  # every rank must take the same branch
        if not fresh and not (self.cached and x.equal(self.point)):
            self.evaluate(x, self.scratch)
        return self.gap.getArray(readonly=True), self.total, self.separation

    def destroy(self):
        for v in (self.point, self.gap, self.scratch):
            v.destroy()


class FusedConvergenceTest(ConvergenceTest):
    """:class:`~roughpetsc.kkt.ConvergenceTest` in one pass over the iterate, with an inexact-inner stop.

    The natural residual (and the load error under load control) decide as in the parent class. With
    ``inner_eta`` > 0 (an inner solve of the augmented Lagrangian), a solve also stops, with
    CONVERGED_USER and ``certified`` False, once its natural residual is at most ``inner_eta`` times its
    load error: the load, not the inner problem, is then what is far from solved.

    The best iterate (lowest :func:`~roughpetsc.kkt.merit`) is kept by writing every iterate into the
    one of two buffers that does not hold the best, in the residual's pass; :attr:`best_vec` is the best.
    """

    def __init__(self, problem, rtol, objective, history, target_pbar=None, max_seconds=0.0, inner_eta=0.0,
                 buffers=None):
        super().__init__(problem.mpi, problem.n, rtol, None, history, target_pbar=target_pbar,
                         max_seconds=max_seconds, upper=problem.upper_bound)
        self.objective = objective
        self.inner_eta = inner_eta
        self.buffers = buffers
        self.best_index = 0
        self.certified = False
        self.last = None  # (natural, load error, mean p, separation) of the last iterate tested

    @property
    def best_vec(self):
        return self.buffers[self.best_index]

    @PETSc.Log.EventDecorator("RPBoundTest")  # -log_view: the fused convergence test
    def __call__(self, tao):
        x = tao.getSolution()
        gap, total, separation = self.objective.cached_gap(x)
        mean_p = total / self.n_total
        scale = self.target_pbar if self.target_pbar else (mean_p if mean_p > 0 else 1.0)
        spare = 1 - self.best_index
        upper = math.inf if self.upper is None else self.upper
        local = bound_kernels.natural_and_copy(x.getArray(readonly=True), gap, scale, upper,
                                               self.buffers[spare].getArray())
        natural, = allmax(self.comm, [local])
        load_error = None if self.target_pbar is None else abs(mean_p - self.target_pbar) / self.target_pbar
        self.last = (natural, load_error, mean_p, separation)
        iteration = tao.getIterationNumber()
        self.history.record(iteration + self.iteration_offset, natural)
        load_ok = load_error is None or load_error <= self.rtol
        if merit_of(natural, load_error) < self.best_natural:
            self.best_natural, self.since_best, self.best_index = merit_of(natural, load_error), 0, spare
        else:
            self.since_best += 1
        if natural <= self.rtol and load_ok:
            self.certified = True
            return PETSc.TAO.Reason.CONVERGED_USER
        if self.inner_eta and natural <= self.inner_eta * load_error:
            return PETSc.TAO.Reason.CONVERGED_USER
        if self.history.out_of_time(self.max_seconds):
            self.stopped_by = "time limit"
            return PETSc.TAO.Reason.DIVERGED_USER
        if self.since_best >= STAGNATION_ITERATIONS:
            self.stopped_by = "stagnation"
            return PETSc.TAO.Reason.DIVERGED_USER
        if tao.getConvergedReason() > 0 and iteration < tao.getMaximumIterations():
            return PETSc.TAO.Reason.CONTINUE_ITERATING
        return None


def merit_of(natural, load_error):
    """:func:`roughpetsc.kkt.merit` of a residual and a load error (None under displacement control)."""
    return natural if load_error is None else max(natural, load_error)


class PenalizedCompliance:
    """MATPYTHON context: the Hessian ``K + c/n 1 1' (+ a I)`` of the augmented Lagrangian (c = 0: K).

    ``shift`` is the BNK family's Hessian perturbation, reset by the owner at each Hessian evaluation.
    """

    def __init__(self, problem):
        self.problem = problem
        self.penalty = 0.0
        self.perturbation = 0.0

    def mult(self, mat, x, y):
        self.problem.operator.displacement(x, y)
        shift = self.penalty * x.sum() / self.problem.n if self.penalty else 0.0
        if shift:
            y.shift(shift)
        if self.perturbation:
            y.axpy(self.perturbation, x)

    def multTranspose(self, mat, x, y):
        self.mult(mat, x, y)

    def getDiagonal(self, mat, d):
        d.set(self.problem.operator.diagonal + self.penalty / self.problem.n + self.perturbation)

    def shift(self, mat, a):
        self.perturbation += a


class PenalizedFourier(FourierPreconditioner):
    """Polonsky-Keer's preconditioner for the Hessian ``K + c/n 1 1'``: the mean mode on the free set C has the
    compliance lambda_C + c |C| / n (lambda_C of K alone; with C every node, c)."""

    penalty = 0.0

    def mean_mode_compliance(self, contact, count):
        compliance = super().mean_mode_compliance(contact, count)
        if not self.penalty:
            return compliance
        return (compliance if np.isfinite(compliance) else 0.0) + self.penalty * count / self.problem.n


class FourierInitialHessian(PenalizedCompliance):
    """MATPYTHON context of the quasi-Newton types' initial Hessian: ``mult`` is the exact Hessian, ``solve``
    Polonsky-Keer's Fourier approximation of its inverse on the free set (module docstring).

    PETSc's L-BFGS applies ``MatSolve`` of its J0 in every two-loop recursion (MatLMVMApplyJ0Inv); the free
    set is that of the objective's last evaluated point, the current iterate.

    The symbol on the free set overestimates the inverse of K restricted to it (the Schur complement
    (K^-1)_FF >= (K_FF)^-1), and the line search then cut the first trial step by 3 to 10 every
    iteration (two function evaluations per iteration). So the approximation is scaled by gamma:
    the objective measures, at the line search's first trial after each direction, where the
    quadratic's minimum lies along the step (exactly, from s'g before and after the step: no operator
    application more), and gamma is multiplied by that ratio (bounded by GAMMA_BOUNDS). The line search's
    own accepted step was tried first: it let gamma sink to its bound from a uniform start (1751
    operator applications against 220).
    """

    def __init__(self, problem, objective):
        super().__init__(problem)
        self.objective = objective
        self.gamma = 1.0
        self.mask = np.zeros(int(np.prod(problem.operator.local_shape)))  # 1.0 on the free set
        self.residual = problem.vec()
        self.fourier = PenalizedFourier(problem)
        self.fixed_scale = 1.0 / problem.operator.diagonal
        grid = problem.scaled_grid
        self.longest_compliance = max(grid.l0, grid.l1) / np.pi

    def mean_compliance(self):
        """The compliance the mean mode of the whole grid has in the Hessian: c, or that of the longest wavelength."""
        return self.penalty if self.penalty else self.longest_compliance

    def _update_scale(self):
        ratio = self.objective.probe_ratio
        if ratio is not None and ratio > 0:
            self.gamma = min(max(self.gamma * ratio, GAMMA_BOUNDS[0]), GAMMA_BOUNDS[1])
        self.objective.probe_ratio = None
        self.objective.probe_armed = True

    @PETSc.Log.EventDecorator("RPBoundH0")  # -log_view: the initial Hessian's MatSolve, its FFT pair included
    def solve(self, mat, b, x):
        """``x = gamma B b`` on the free set, ``gamma b / diag(K)`` off it: four passes and one FFT pair."""
        self._update_scale()
        problem = self.problem
        mpi = problem.mpi
        upper = math.inf if problem.upper_bound is None else problem.upper_bound
        source, residual, out = b.getArray(readonly=True), self.residual.getArray(), x.getArray()
        count, total = allsum(mpi, bound_kernels.free_residual(
            self.objective.point.getArray(readonly=True), self.objective.gap.getArray(readonly=True), upper,
            source, self.mask, residual))
        if count == 0:
            bound_kernels.finish_initial_hessian(out, source, self.mask, 0.0, 0.0, self.fixed_scale, self.gamma)
            return
        mean = total / count
        kernels.shift_on(residual, self.mask, mean, residual)  # P r: zero mean on the free set
        shape = problem.operator.local_shape
        problem.operator.stiffness(residual.reshape(shape), out.reshape(shape))
        out_mean = allsum(mpi, [kernels.masked_sum(out, self.mask)])[0] / count
        self.fourier.penalty = self.penalty
        compliance = self.fourier.mean_mode_compliance(self.mask, count)
        if not np.isfinite(compliance):
            compliance = self.mean_compliance()
        mean_term = MEAN_MODE_WEIGHT * mean / compliance
        bound_kernels.finish_initial_hessian(out, source, self.mask, out_mean, mean_term, self.fixed_scale, self.gamma)

    def destroy(self, mat=None):
        self.residual.destroy()
        if self.fourier is not None:
            self.fourier.destroy()


def _set_lmvm_initial_hessian(tao, tao_type, mat):
    """Make ``mat`` (with ``solve``) the initial Hessian J0 of the L-BFGS matrix of a BLMVM or BQNK ``tao``.

    petsc4py 3.18 wraps TaoLMVMSetH0 (BLMVM) but not TaoGetLMVMMatrix (the BQNK types), which ctypes calls.
    """
    if tao_type == "blmvm":
        tao.setLMVMH0(mat)
        return
    library = _petsc_library()
    lmvm = ctypes.c_void_p()
    _check(library.TaoGetLMVMMatrix(ctypes.c_void_p(tao.handle), ctypes.byref(lmvm)), "TaoGetLMVMMatrix")
    _check(library.MatLMVMSetJ0(lmvm, ctypes.c_void_p(mat.handle)), "MatLMVMSetJ0")


def _set_recycle(tao, flag):
    """Keep the quasi-Newton memory from one TaoSolve to the next (TaoSetRecycleHistory; BLMVM's own flag)."""
    library = _petsc_library()
    handle = ctypes.c_void_p(tao.handle)
    _check(library.TaoSetRecycleHistory(handle, ctypes.c_int(bool(flag))), "TaoSetRecycleHistory")
    _check(library.TaoLMVMRecycle(handle, ctypes.c_int(bool(flag))), "TaoLMVMRecycle")


def contact_stiffness(problem, pressure, preconditioner, rtol=1e-3, max_it=30):
    """The contact stiffness k = -dP/dd = 1_C' K_CC^-1 1_C / n of the solution ``pressure``, by PCG on its contact set C.

    The mean pressure of the displacement-controlled solution changes at this rate with the separation while
    the contact set C (0 < p below the cap) stays; the augmented Lagrangian's first step on lambda is the
    Newton step with it. Preconditioned by Polonsky-Keer's Fourier preconditioner (``preconditioner``, a
    :class:`~roughpetsc.preconditioner.FourierPreconditioner`); two operator applications per iteration.
    Stops when k changes by less than ``rtol`` relatively. Returns k (scaled), or None with C empty or every node.
    """
    operator = problem.operator
    mpi = problem.mpi
    p = problem.local(pressure, readonly=True).ravel()
    contact = (p > 0.0).astype(np.float64)
    if problem.upper_bound is not None:
        contact[p >= problem.upper_bound] = 0.0
    count, = allsum(mpi, [contact.sum()])
    if count == 0 or count == problem.n:
        return None
    work = [problem.vec() for _ in range(3)]
    try:
        residual = contact.copy()
        solution = np.zeros_like(residual)
        z = problem.local(work[0]).ravel()
        direction = problem.local(work[1]).ravel()
        response = problem.local(work[2]).ravel()
        preconditioner.apply(residual, z, contact, count, keep_load=False)
        direction[...] = z
        rz, = allsum(mpi, [np.dot(residual, z)])
        stiffness = 0.0
        for _ in range(max_it):
            operator.displacement(work[1], work[2])
            response *= contact
            curvature, = allsum(mpi, [np.dot(direction, response)])
            alpha = rz / curvature
            solution += alpha * direction
            residual -= alpha * response
            previous, stiffness = stiffness, allsum(mpi, [solution.sum()])[0] / problem.n
            if abs(stiffness - previous) <= rtol * stiffness:
                break
            preconditioner.apply(residual, z, contact, count, keep_load=False)
            rz_new, = allsum(mpi, [np.dot(residual, z)])
            direction *= rz_new / rz
            direction += z
            rz = rz_new
        return stiffness
    finally:
        for v in work:
            v.destroy()


class FastBound(Backend):
    """A bound-constrained TAO type under load (augmented Lagrangian) or displacement control (module docstring).

    Parameters are those of the registry's factories; ``name`` is ``fast_<type>``.
    """

    def __init__(self, problem, control, name, settings):
        tao_type = name[len(PREFIX):] if name.startswith(PREFIX) else name
        self.problem = problem
        self.control = control
        self.rtol = settings.rtol
        self.max_seconds = settings.max_seconds
        self.prefix = settings.prefix
        options = PETSc.Options(settings.prefix)
        self.penalty_factor = options.getReal("bound_al_penalty", 1.0)
        self.eta = options.getReal("bound_al_eta", 0.1)
        self.max_outer = options.getInt("bound_al_max_outer", 40)
        self.recycle = options.getBool("bound_al_recycle", True)
        self.newton = options.getBool("bound_al_newton", True)
        default_h0 = "fourier" if tao_type in QUASI_NEWTON_TYPES else "none"
        h0 = options.getString("bound_h0", default_h0)
        preconditioner = options.getString("bound_pc", "fourier" if tao_type in FOURIER_DEFAULT_TYPES else "none")
        self._check_options(h0, preconditioner, tao_type)
        self.objective = AugmentedQuadratic(problem)
        self.stiffness_preconditioner = FourierPreconditioner(problem)
        self.buffers = (problem.vec(), problem.vec())
        self.lower, self.upper, self.gradient = problem.vec(), problem.vec(), problem.vec()
        self.lower.set(0.0)
        self.upper.set(PETSc.INFINITY if problem.upper_bound is None else problem.upper_bound)
        self.hessian_context = PenalizedCompliance(problem)
        self.hessian = self._python_mat(self.hessian_context)
        self.fourier = self.preconditioning = None
        self.initial_context = self.initial_hessian = None
        tao = self.tao = PETSc.TAO().create(problem.comm)
        tao.setOptionsPrefix(settings.prefix)
        tao.setType(tao_type)
        if tao_type in KSP_TYPES and preconditioner == "fourier":
            self.fourier = FourierPreconditioner(problem)
            self.preconditioning = self.fourier.mat()
            tao.getKSP().getPC().setType("mat")
        elif tao_type in KSP_TYPES and preconditioner == "none":
            tao.getKSP().getPC().setType("none")
        tao.setObjectiveGradient(lambda tao, x, g: self.objective.evaluate(x, g), self.gradient)
        tao.setHessian(self._evaluate_hessian, self.hessian, self.preconditioning or self.hessian)
        tao.setVariableBounds((self.lower, self.upper))
        tao.setTolerances(gatol=0.0, grtol=0.0, gttol=0.0)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        tao.setMaximumFunctionEvaluations(10 * DEFAULT_MAX_IT)
        # -tao_type fast_<type> names this backend: its TAO reads the plain type.
        with default_options({"tao_type": tao_type}, settings.prefix, replace=True), \
                default_options(self._default_options(tao_type, h0), settings.prefix):
            set_from_options(tao, self.destroy)
        if h0 != "none" and tao_type in QUASI_NEWTON_TYPES:
            self.initial_context = FourierInitialHessian(problem, self.objective)
            self.initial_hessian = self._python_mat(self.initial_context)
            _set_lmvm_initial_hessian(tao, tao_type, self.initial_hessian)
        self.h0 = h0 if self.initial_context else "none"
        self.tao_type = tao_type
        self.name = f"{tao.getType()}(h0 {self.h0})" + ("+al" if control == "load" else "")

    @staticmethod
    def _default_options(tao_type, h0):
        """BoundQP's defaults; with the Fourier initial Hessian an L-BFGS memory of one pair (fewest iterations and
        vector operations: group #1, N = 256 and 512, p* = 0.5, memory 1, 2, 3, 5, 8), and BQNLS without the
        Bertsekas active-set estimate (it applies the initial Hessian a second time per iteration)."""
        defaults = BoundQP._default_options(tao_type)
        if h0 == "fourier" and tao_type in QUASI_NEWTON_TYPES:
            defaults[f"tao_{tao_type}_mat_lmvm_hist_size"] = "1"
        if tao_type == "bqnls":
            defaults["tao_bnk_as_type"] = "none"
        return defaults

    def _check_options(self, h0, preconditioner, tao_type):
        prefix = self.prefix
        if h0 not in INITIAL_HESSIANS:
            raise UserError(f"{option_name('bound_h0', prefix)}: unknown initial Hessian '{h0}' "
                            f"(one of {', '.join(INITIAL_HESSIANS)})")
        if preconditioner not in BOUND_PRECONDITIONERS:
            raise UserError(f"{option_name('bound_pc', prefix)}: unknown preconditioner '{preconditioner}' "
                            f"(one of {', '.join(BOUND_PRECONDITIONERS)})")
        if not self.penalty_factor > 0:
            raise UserError(f"{option_name('bound_al_penalty', prefix)} must be positive, got {self.penalty_factor}")
        if not 0 <= self.eta < 1:
            raise UserError(f"{option_name('bound_al_eta', prefix)} must be in [0, 1), got {self.eta}")
        if self.max_outer < 1:
            raise UserError(f"{option_name('bound_al_max_outer', prefix)} must be at least 1, got {self.max_outer}")

    def _python_mat(self, context):
        n_local = self.problem.vec().getLocalSize()
        mat = PETSc.Mat().createPython(((n_local, self.problem.n), (n_local, self.problem.n)), context=context,
                                       comm=self.problem.comm)
        mat.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        mat.setUp()
        return mat

    def _evaluate_hessian(self, tao, x, H, P):
        self.hessian_context.perturbation = 0.0  # a fresh Hessian: BNK's MatShift of the last one is undone

    def _set_penalty(self, penalty):
        self.hessian_context.penalty = penalty
        if self.initial_context is not None:
            self.initial_context.penalty = penalty

    def _run(self, pressure, test):
        """TAO from ``pressure``, restarted from its best iterate while round-off stops it (as BoundQP)."""
        iterations, restarts, floor = 0, 0, np.inf
        while True:
            self.objective.restart()
            self.tao.setSolution(pressure)
            self.tao.solve(pressure)
            iterations += self.tao.getIterationNumber()
            test.iteration_offset += self.tao.getIterationNumber()
            reason = self.tao.getConvergedReason()
            if reason > 0 or not restartable(reason, test) or restarts == MAX_RESTARTS \
                    or not test.best_natural < RESTART_GAIN * floor:
                return iterations, restarts
            floor = test.best_natural
            restarts += 1
            test.stopped_by, test.since_best = None, 0
            test.best_vec.copy(pressure)

    def _project(self, pressure):
        local = self.problem.local(pressure)
        np.maximum(local, 0.0, out=local)
        if self.problem.upper_bound is not None:
            np.minimum(local, self.problem.upper_bound, out=local)

    def solve(self, target, pressure, guess):
        """Solve for ``target`` (scaled mean pressure or separation) from ``pressure`` (overwritten)."""
        self._project(pressure)
        history = History(self.problem)
        if self.control == "displacement":
            return self._solve_displacement(target, pressure, history)
        return self._solve_load(target, pressure, guess, history)

    def _solve_displacement(self, separation, pressure, history):
        self._set_penalty(0.0)
        self.objective.configure(separation)
        test = FusedConvergenceTest(self.problem, self.rtol, self.objective, history, max_seconds=self.max_seconds,
                                    buffers=self.buffers)
        self.tao.setConvergenceTest(test)
        _set_recycle(self.tao, False)
        iterations, restarts = self._run(pressure, test)
        if self.tao.getConvergedReason() < 0 and np.isfinite(test.best_natural):
            test.best_vec.copy(pressure)
        return Outcome(separation, iterations, describe_stop(self.tao, test, restarts), history.as_array())

    def _solve_load(self, pbar, pressure, guess, history):
        """The augmented Lagrangian on mean(p) = pbar (module docstring); lambda starts at ``guess.separation``."""
        problem = self.problem
        grid = problem.scaled_grid
        penalty = self.penalty_factor * max(grid.l0, grid.l1) / np.pi
        self._set_penalty(penalty)
        lam = guess.separation if guess is not None else None
        test = FusedConvergenceTest(problem, self.rtol, self.objective, history, target_pbar=pbar,
                                    max_seconds=self.max_seconds, inner_eta=self.eta, buffers=self.buffers)
        self.tao.setConvergenceTest(test)
        points = []  # (d, mean p) of each inner solution
        iterations = restarts = 0
        for outer in range(self.max_outer):
            _set_recycle(self.tao, self.recycle and outer > 0)
            self.objective.configure(lam, penalty, pbar)
            test.inner_eta = self.eta if outer < self.max_outer - 1 else 0.0
            done, restarted = self._run(pressure, test)
            iterations += done
            restarts += restarted
            natural, load_error, mean_p, separation = self._last(test, pressure)
            points.append((separation, mean_p))
            if test.certified or self.tao.getConvergedReason() < 0:
                break
            stiffness = contact_stiffness(problem, pressure, self.stiffness_preconditioner) \
                if len(points) == 1 and self.newton else None
            lam = self._next_lambda(points, pbar, separation, stiffness)
        note = f"{len(points)} inner solves"
        if test.certified:
            reason = f"CONVERGED_USER ({note})"
        elif self.tao.getConvergedReason() < 0:
            reason = describe_stop(self.tao, test, restarts)
            reason = reason.replace("(", f"({note}, ", 1) if "(" in reason else f"{reason} ({note})"
        else:
            reason = f"DIVERGED_AL_MAX_OUTER ({note}, best of natural residual, load error {test.best_natural:.2g})"
        if not test.certified and np.isfinite(test.best_natural):
            test.best_vec.copy(pressure)
        return Outcome(separation, iterations, reason, history.as_array())

    def _last(self, test, pressure):
        """(natural, load error, mean p, separation) of the TAO solution in ``pressure``."""
        if test.last is None:
            gap, total, separation = self.objective.cached_gap(pressure)
            return np.inf, np.inf, total / self.problem.n, separation
        return test.last

    @staticmethod
    def _next_lambda(points, pbar, separation, stiffness=None):
        """The next lambda: a secant step on the (d, log P) pairs, inside their bracket; the first a Newton step with
        the contact ``stiffness`` (the multiplier update, lambda <- d, without one).

        P(d) decreases with d, like exp(-d / l) at small loads (Bush, Gibson and Thomas), so log P is
        closer to linear in d than P, and the steps are taken on it. A pair with P > pbar lies below the
        root, one with P < pbar above it.
        """
        below = [d for d, p in points if p > pbar]
        above = [d for d, p in points if p < pbar]
        low = max(below) if below else -math.inf
        high = min(above) if above else math.inf
        d1, p1 = points[-1]
        if len(points) < 2:
            if not stiffness or not p1 > 0:
                return separation  # the method of multipliers: lambda <- d
            step = d1 + math.log(p1 / pbar) * p1 / stiffness  # d log P / dd = -k / P
        else:
            d0, p0 = points[-2]
            if d1 == d0 or not (p0 > 0 and p1 > 0) or not (math.log(p1 / p0)) / (d1 - d0) < 0:
                step = separation
            else:
                step = d1 + math.log(p1 / pbar) * (d1 - d0) / math.log(p0 / p1)  # root of the secant of log P
        if not low < step < high:
            step = 0.5 * (low + high) if math.isfinite(low) and math.isfinite(high) else separation
        return step

    def destroy(self):
        self.tao.destroy()
        # (PETSc destroys the contexts of the python Mats with them.)
        for obj in (self.objective, *self.buffers, self.lower, self.upper, self.gradient, self.hessian,
                    self.preconditioning, self.fourier, self.initial_hessian, self.stiffness_preconditioner):
            if obj is not None:
                obj.destroy()


register(tuple(PREFIX + t for t in BOUND_TYPES), FastBound)
