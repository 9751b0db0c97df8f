"""Every bound-constrained TAO type on the contact QP (3.41)-(3.44) of the dissertation, under both controls.

Registered under every name of :data:`BOUND_TYPES`. Load control by an augmented Lagrangian on mean(p) = pbar
inside TAO, the Fourier initial Hessian of the quasi-Newton types, fused callbacks, working defaults: see
docs/solvers.md, "The bound-constrained TAO types".
"""

import ctypes
import math
import re

import numpy as np
from petsc4py import PETSc

from ..contact import loops
from ..elastic.operator import ShellContext
from ..errors import UserError
from ..parallel import allmax, allmin, allsum
from .options import _petsc_library, default_options, given_but_unusable, set_from_options, tao_with_callbacks
from .preconditioner import MEAN_MODE_WEIGHT, FourierPreconditioner, FreeSetPC
from .protocol import Backend, Outcome
from .registry import register
from .stopping import (DEFAULT_MAX_IT, ConvergenceTest, History, Verdict, describe_stop, option_name,
                       read_option)

BOUND_TYPES = ("blmvm", "bqnls", "bncg", "bqnkls", "bqnktr", "bqnktl", "bnls", "bntr", "bntl", "tron", "gpcg")
# Types whose Newton step is a KSP solve on the free set: they take the Fourier preconditioner. It is their
# default where it won (group #1, N = 512, p* = 0.5, displacement control: BNLS 622 -> 495 operator
# applications). GPCG's goes through FreeSetPC (PETSc's GPCG ignores the preconditioning matrix; through it, it
# took 434 -> 6520): under displacement control 161 / 330 / 260 pairs against 155 / 432 / 650 without at N = 512,
# 217 / 413 / 334 against 250 / 672 / 1027 at 1024 (p* = 0.05 / 0.5 / 2); under the augmented Lagrangian 398
# against 377 at N = 512, p* = 0.05, and the same stall at 0.5 and 2. TRON with its KSP at 0.1 took
# 127 / 191 / 178 pairs with it against 116 / 192 / 432 without at N = 512, 137 / 201 / 196 against
# 144 / 245 / 467 at 1024 (p* = 0.05 / 0.5 / 2).
KSP_TYPES = ("bnls", "bntr", "bntl", "tron", "gpcg")
FOURIER_DEFAULT_TYPES = ("bnls", "bntr", "bntl", "tron", "gpcg")
QUASI_NEWTON_TYPES = ("blmvm", "bqnls", "bqnkls", "bqnktr", "bqnktl")
BOUND_PRECONDITIONERS = ("fourier", "none", "options")
INITIAL_HESSIANS = ("fourier", "none")
LOAD_METHODS = ("al", "rootfind", "gap")
# The types whose load control is in the gap by default where it applies: against the augmented Lagrangian it
# took 0.43-0.81x the FFT pairs of BLMVM and BQNLS and 0.10-0.84x of TRON at N = 512 and 1024, p* = 0.05-2
# (group #1); GPCG converged at p* = 0.5 and 2, where it stalls with the multiplier, except at N = 1024, p* = 2;
# BNTR took 427 / 161 / 91 pairs (292 / 244 / 121 with -bound_pc fourier) against 516 / 605 / 209 at N = 512.
# From the cut start (N = 512, p* = 0.05 / 0.5 / 2), the gap against the multiplier: BQNKLS 292 / 252 / 130 pairs
# against 541 / 600 / 206, BQNKTR 256 / 262 / 138 against 582 / 626 / 220, BQNKTL 256 / 262 / 138 against
# 582 / 626 / 220, BNLS 361 / 139 / 78 against 568 / 488 / 163, BNTL 294 / 143 / 97 against 520 / 516 / 209.
# Not BNCG: out of 60 s at p* = 0.05 and 0.5 in the gap (natural residual 1.2e-4), against 128 / 216 / 235 pairs.
GAP_DEFAULT_TYPES = ("blmvm", "bqnls", "bqnkls", "bqnktr", "bqnktl", "bnls", "bntr", "bntl", "tron", "gpcg")
# Bounds of the initial Hessian's scale gamma; it settled at 0.1-0.3 in the solves measured.
GAMMA_BOUNDS = (1e-3, 1e3)
# The default penalty c of the augmented Lagrangian (units of L / pi): with the Fourier H0, BLMVM and BQNLS took
# 6-39 % fewer FFT pairs at 0.1 than at 1 in 10 of 12 load-controlled solves (group #1, N = 512 and 1024,
# p* = 0.05, 0.5, 2), 4-39 % more in two at p* = 2; 0.03 and 0.3 did worse than 0.1. TRON and BNLS did not gain
# (TRON 452 -> 523 pairs at p* = 0.05) and keep 1.
PENALTY_QUASI_NEWTON, PENALTY_OTHERS = 0.1, 1.0
# The default inner tolerance of the augmented Lagrangian, in units of the load error: 0.3 gave BLMVM and BQNLS
# 3-19 % fewer FFT pairs than 0.1 in 11 of 12 of those solves; BNLS under load on the free-boundary Hertz
# contact of tests/contact/test_free_boundary.py did not return within 150 s at 0.3, so the others keep 0.1.
ETA_QUASI_NEWTON, ETA_OTHERS = 0.3, 0.1
# Restarts of a TAO solve that stopped for round-off: at most this many, and only while each attempt lowers the
# best natural residual below this fraction of the previous one.
MAX_RESTARTS = 8
RESTART_GAIN = 0.9

OPTIONS = [
    ("bound_pc", "", "TAO bnls/bntr/bntl/tron/gpcg: fourier (inverse symbol on the free set; their default, but "
                     "of tron alone in the gap form) | none (the others' default in the gap form) | options "
                     "(-tao_*pc_type decides)"),
    ("bound_h0", "", "TAO blmvm/bqnls/bqnk*: initial Hessian of L-BFGS: fourier (Polonsky-Keer's preconditioner on "
                     "the free set, their default) | none (PETSc's)"),
    ("bound_load", "", "TAO bound types under load control: gap (one solve for the gap, whose gradient is the "
                       "pressure of mean pbar; periodic boundary without a hardness cap; default of every type but "
                       "bncg there) | al (augmented Lagrangian on mean(p) = pbar inside the solve; default "
                       "otherwise) | rootfind (a safeguarded root find on the separation around displacement "
                       "control)"),
    ("bound_al_penalty", "", "augmented Lagrangian: penalty c in units of the compliance of the longest wavelength "
                             "(default 0.1 for the quasi-Newton types with the Fourier H0, 1 for the others)"),
    ("bound_al_eta", "", "augmented Lagrangian: an inner solve stops once its natural residual is below this "
                         "times its load error, in [0, 1) (default 0.3 for the quasi-Newton types with the Fourier "
                         "H0, 0.1 for the others)"),
    ("bound_al_max_outer", 40, "augmented Lagrangian: at most this many inner solves"),
    ("bound_al_recycle", False, "augmented Lagrangian: keep the quasi-Newton memory from one inner solve to the next"),
    ("bound_al_newton", True,
     "augmented Lagrangian: first multiplier step by the contact stiffness (else lambda <- d)"),
]


def _check(error, what):
    if error != 0:
        raise RuntimeError(f"PETSc error {error} in {what}")


def restartable(reason, watch):
    """True for the stops that round-off in the objective causes: a failed line search, stagnation."""
    return reason in (PETSc.TAO.Reason.DIVERGED_LS_FAILURE, PETSc.TAO.Reason.DIVERGED_TR_REDUCTION) \
        or (reason == PETSc.TAO.Reason.DIVERGED_USER and watch.stopped_by == "stagnation")


class AugmentedQuadratic:
    """The objective L(p; lambda) (docs/solvers.md) and its gradient, the gap at d = lambda + c (mean p - pbar).

    c = 0 and lambda = d: the displacement-controlled QP. The value is accumulated from exact increments,
    f(x) = f(r) + (x - r)'(g(x) + g(r)) / 2, free of cancellation; the last evaluated point is cached.
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
        # Armed by the initial Hessian after it made a direction: the next evaluation (the line search's first
        # trial) records the exact minimiser along its step, in units of the step.
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

    def _apply(self, x, out):
        """``out = K x``; returns the heights and the separation of ``g = K x - h + separation``."""
        problem = self.problem
        separation = self.lam
        if self.penalty:
            total, = allsum(problem.mpi, [loops.local_sum(x.getArray(readonly=True))])
            separation += self.penalty * (total / problem.n - self.pbar)
        problem.operator.displacement(x, out)
        if self.initial_lam:
            elastic = problem.local(self.scratch)
            np.subtract(problem.local(out, readonly=True), problem.local(problem.heights, readonly=True), out=elastic)
            self.lam = problem.contact_separation(x, elastic)
            self.initial_lam = False
            separation += self.lam
        return problem.heights.getArray(readonly=True), separation

    def _separation(self, offset, total):
        """The rigid separation d of the point whose gradient's offset is ``offset`` and sum ``total``."""
        return offset

    def evaluate(self, x, out):
        """``out = g(x)`` (one operator application); returns f(x)."""
        problem = self.problem
        heights, offset = self._apply(x, out)
        out_local = out.getArray()
        sums = loops.gradient_step(x.getArray(readonly=True), self.point.getArray(), self.gap.getArray(), out_local,
                                   heights, offset, out_local, self.cached)
        before, after, total = allsum(problem.mpi, sums)
        self.value = self.value + 0.5 * (before + after) if self.cached else 0.0
        if self.probe_armed and self.cached:
            # The first point after a new direction: how far along the step the quadratic's minimum lies.
            self.probe_ratio = -before / (after - before) if after > before else None
            self.probe_armed = False
        self.cached = True
        self.total, self.separation = total, self._separation(offset, total)
        self.vec_handle, self.state = x.handle, x.stateGet()
        return self.value

    def cached_gap(self, x):
        """``(gap, sum of p, separation)`` of ``x``, the gap as this rank's flat array: cached, else evaluated."""
        fresh = self.cached and x.handle == self.vec_handle and x.stateGet() == self.state
        fresh = bool(allmin(self.problem.mpi, [float(fresh)])[0])  # every rank must take the same branch
        if not fresh and not (self.cached and x.equal(self.point)):
            self.evaluate(x, self.scratch)
        return self.gap.getArray(readonly=True), self.total, self.separation

    def destroy(self):
        for v in (self.point, self.gap, self.scratch):
            v.destroy()


class PenalizedCompliance(ShellContext):
    """MATPYTHON context: the Hessian ``K + c/n 1 1' (+ a I)`` of the augmented Lagrangian, a the BNK shift."""

    def __init__(self, problem):
        super().__init__(problem.operator)
        self.problem = problem
        self.penalty = 0.0

    def mult(self, mat, x, y):
        self.problem.operator.displacement(x, y)
        shift = self.penalty * x.sum() / self.problem.n if self.penalty else 0.0
        if shift:
            y.shift(shift)
        if self.perturbation:
            y.axpy(self.perturbation, x)

    def getDiagonal(self, mat, d):
        d.set(self.problem.operator.diagonal + self.penalty / self.problem.n + self.perturbation)


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
    """MATPYTHON context of the quasi-Newton types' initial Hessian: ``mult`` the exact Hessian, ``solve``
    gamma times Polonsky-Keer's approximation of its inverse on the current free set (docs/solvers.md)."""

    mean_mode_weight = MEAN_MODE_WEIGHT
    mean_mode_type = PenalizedFourier

    def __init__(self, problem, objective):
        super().__init__(problem)
        self.objective = objective
        self.gamma = 1.0
        self.mask = np.zeros(int(np.prod(problem.operator.local_shape)))  # 1.0 on the free set
        self.residual = problem.vec()
        self.fourier = self.mean_mode_type(problem)
        self.fixed_scale = 1.0 / problem.operator.diagonal
        grid = problem.scaled_grid
        self.longest_compliance = max(grid.l0, grid.l1) / np.pi

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
        count, total = allsum(mpi, loops.free_residual(
            self.objective.point.getArray(readonly=True), self.objective.gap.getArray(readonly=True), upper,
            source, self.mask, residual))
        if count == 0:
            loops.finish_initial_hessian(out, source, self.mask, 0.0, 0.0, self.fixed_scale, self.gamma)
            return
        mean = total / count
        loops.shift_on(residual, self.mask, mean, residual)  # P r: zero mean on the free set
        self._inverse_on_free(self.residual, x)
        out_mean = allsum(mpi, [loops.masked_sum(out, self.mask)])[0] / count
        mean_term = self.mean_mode_weight * mean / self._mean_mode_curvature(count)
        loops.finish_initial_hessian(out, source, self.mask, out_mean, mean_term, self.fixed_scale, self.gamma)

    def _inverse_on_free(self, residual, out):
        """``out`` = the approximate inverse of the Hessian applied to ``residual`` (zero mean on the free set)."""
        self.fourier.inverse_symbol(self.problem.local(residual, readonly=True), self.problem.local(out))

    def _mean_mode_curvature(self, count):
        """The Hessian's curvature on the uniform field of the free set (``mask``, ``count`` nodes): its compliance."""
        self.fourier.penalty = self.penalty
        compliance = self.fourier.mean_mode_compliance(self.mask, count)
        if not np.isfinite(compliance):
            compliance = self.penalty if self.penalty else self.longest_compliance
        return compliance

    def destroy(self, mat=None):
        self.residual.destroy()
        if self.fourier is not None:
            self.fourier.destroy()
            self.fourier = None


def _set_lmvm_initial_hessian(tao, tao_type, mat):
    """Make ``mat`` the J0 of a BLMVM or BQNK ``tao`` (petsc4py 3.18 lacks TaoGetLMVMMatrix: ctypes)."""
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


def contact_stiffness(problem, pressure, preconditioner, rtol=1e-2, max_it=30):
    """The contact stiffness k = -dP/dd = 1_C' K_CC^-1 1_C / n of ``pressure``, by PCG on its contact set C.

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


def next_multiplier(points, pbar, separation, stiffness=None, touch=None):
    """The next lambda: a secant step on the (d, log P) pairs, inside their bracket; the first a Newton step with
    the contact ``stiffness`` (lambda <- d without one). log P is nearly linear in d at small loads (P ~ exp(-d/l),
    Bush, Gibson and Thomas). After a solution out of contact (P = 0: no slope of log P), ``touch``, the separation
    at which its surfaces touch, an upper bound of the root (lambda <- d moves by only c pbar there).
    """
    below = [d for d, p in points if p > pbar]
    above = [d for d, p in points if p < pbar]
    low = max(below) if below else -math.inf
    high = min(above) if above else math.inf
    d1, p1 = points[-1]
    if p1 == 0 and touch is not None:
        step = touch
    elif len(points) < 2:
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


class BoundQP(Backend):
    """A bound-constrained TAO type under load (augmented Lagrangian) or displacement control."""

    load_method = "al"

    objective_type, hessian_type, initial_hessian_type = AugmentedQuadratic, PenalizedCompliance, FourierInitialHessian
    preconditioner_type = FourierPreconditioner

    def __init__(self, problem, control, tao_type, settings):
        self.problem = problem
        self.control = control
        self.rule = settings.rule
        self.max_seconds = settings.rule.max_seconds
        self.prefix = settings.prefix
        options = PETSc.Options(settings.prefix)
        h0 = options.getString("bound_h0", "") or ("fourier" if tao_type in QUASI_NEWTON_TYPES else "none")
        quasi_newton_h0 = h0 == "fourier" and tao_type in QUASI_NEWTON_TYPES
        self.penalty_factor = read_option(options, "Real", "bound_al_penalty",
                                          PENALTY_QUASI_NEWTON if quasi_newton_h0 else PENALTY_OTHERS)
        self.eta = read_option(options, "Real", "bound_al_eta", ETA_QUASI_NEWTON if quasi_newton_h0 else ETA_OTHERS)
        self.max_outer = read_option(options, "Int", "bound_al_max_outer", 40)
        self.recycle = read_option(options, "Bool", "bound_al_recycle", False)
        self.newton = read_option(options, "Bool", "bound_al_newton", True)
        preconditioner = options.getString("bound_pc", "") or self._default_preconditioner(tao_type)
        self._check_options(h0, preconditioner)
        self.objective = self.objective_type(problem)
        self.stiffness_preconditioner = FourierPreconditioner(problem)
        self.buffers = (problem.vec(), problem.vec())  # the best iterate is in buffers[best]
        self.best = 0
        self.lower, self.upper, self.gradient = problem.vec(), problem.vec(), problem.vec()
        self.lower.set(0.0)
        self.upper.set(PETSc.INFINITY if problem.upper_bound is None else problem.upper_bound)
        self.hessian_context = self.hessian_type(problem)
        self.hessian = problem.operator.mat(self.hessian_context)
        self.fourier = self.preconditioning = None
        self.initial_context = self.initial_hessian = None
        self.last = None  # (natural, load error, mean p, separation) of the last iterate tested
        tao = self.tao = tao_with_callbacks(problem.comm, settings.prefix)
        tao.setType(tao_type)
        if tao_type in KSP_TYPES and preconditioner == "fourier":
            self.fourier = self.preconditioner_type(problem)
            pc = tao.getKSP().getPC()
            if tao_type == "gpcg":  # GPCG ignores the preconditioning matrix (FreeSetPC)
                pc.setType("python")
                pc.setPythonContext(FreeSetPC(self.fourier, tao, self.gradient, problem.upper_bound))
            else:
                self.preconditioning = self.fourier.mat()
                pc.setType("mat")
        elif tao_type in KSP_TYPES and preconditioner == "none":
            tao.getKSP().getPC().setType("none")
        tao.setObjectiveGradient(lambda tao, x, g: self.objective.evaluate(x, g), self.gradient)
        tao.setHessian(self._evaluate_hessian, self.hessian, self.preconditioning or self.hessian)
        tao.setVariableBounds((self.lower, self.upper))
        tao.setTolerances(gatol=0.0, grtol=0.0, gttol=0.0)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        tao.setMaximumFunctionEvaluations(10 * DEFAULT_MAX_IT)
        with default_options(self._default_options(tao_type, h0), settings.prefix):
            set_from_options(tao, self.destroy)
        if quasi_newton_h0:
            self.initial_context = self.initial_hessian_type(problem, self.objective)
            self.initial_hessian = problem.operator.mat(self.initial_context)
            _set_lmvm_initial_hessian(tao, tao_type, self.initial_hessian)
        self.name = tao.getType() + ("(al)" if control == "load" else "")

    @staticmethod
    def _default_preconditioner(tao_type):
        return "fourier" if tao_type in FOURIER_DEFAULT_TYPES else "none"

    @staticmethod
    def _default_options(tao_type, h0):
        defaults = {}
        if tao_type in ("tron", "gpcg"):
            defaults["tao_subset_type"] = "subvec"  # the default mask subset and ILU fail on a shell Hessian
        if tao_type == "bnls":  # its default KSP, STCG, took 100x the operator applications of CG here
            defaults["tao_bnk_ksp_type"] = "cg"
        if tao_type == "tron":
            # An inexact Newton step (TRON's KSP shares the TAO's prefix). Without a preconditioner, 0.1 instead of
            # PETSc's 1e-5 took 206 / 95 / 53 FFT pairs under load control against 379 / 127 / 55, and
            # 116 / 192 / 432 under displacement control against 177 / 298 / 681 (group #1, N = 512,
            # p* = 0.05 / 0.5 / 2); 0.3 and 0.03 were no better.
            defaults["ksp_rtol"] = "0.1"
        if h0 == "fourier" and tao_type in QUASI_NEWTON_TYPES:
            # Fewest iterations and vector operations with the Fourier H0: memory 1, 2, 3, 5, 8 tried (group #1,
            # N = 256 and 512, p* = 0.5).
            defaults[f"tao_{tao_type}_mat_lmvm_hist_size"] = "1"
        if tao_type == "bqnls" and h0 == "fourier":
            defaults["tao_bnk_as_type"] = "none"
        return defaults

    def _check_options(self, h0, preconditioner):
        prefix = self.prefix
        if h0 not in INITIAL_HESSIANS:
            raise UserError(f"{option_name('bound_h0', prefix)}: unknown initial Hessian '{h0}' "
                            f"(one of {', '.join(INITIAL_HESSIANS)})")
        if preconditioner not in BOUND_PRECONDITIONERS:
            raise UserError(f"{option_name('bound_pc', prefix)}: unknown preconditioner '{preconditioner}' "
                            f"(one of {', '.join(BOUND_PRECONDITIONERS)})")
        if not (self.penalty_factor > 0 and np.isfinite(self.penalty_factor)):
            raise UserError(f"{option_name('bound_al_penalty', prefix)} must be positive and finite, "
                            f"got {self.penalty_factor}")
        if not 0 <= self.eta < 1:
            raise UserError(f"{option_name('bound_al_eta', prefix)} must be in [0, 1), got {self.eta}")
        if self.max_outer < 1:
            raise UserError(f"{option_name('bound_al_max_outer', prefix)} must be at least 1, got {self.max_outer}")

    def unusable_options(self):
        """This backend's own options given for a part it does not run: the load control's under displacement
        control (or the augmented Lagrangian's beside another method), the initial Hessian of a type without
        L-BFGS, the preconditioner of a type without a KSP. Reported like unused options."""
        names = []
        if self.control == "displacement":
            names += ["bound_load", "bound_al_"]
        elif self.load_method != "al":
            names += ["bound_al_"]
        if self.tao.getType() not in QUASI_NEWTON_TYPES:
            names.append("bound_h0")
        if self.tao.getType() not in KSP_TYPES:
            names.append("bound_pc")
        return given_but_unusable(re.compile("^(" + "|".join(names) + ")"), self.prefix) if names else []

    def _evaluate_hessian(self, tao, x, H, P):
        self.hessian_context.perturbation = 0.0  # a fresh Hessian: BNK's MatShift of the last one is undone

    def _set_penalty(self, penalty):
        self.hessian_context.penalty = penalty
        if self.initial_context is not None:
            self.initial_context.penalty = penalty

    @PETSc.Log.EventDecorator("RPBoundTest")  # -log_view: the fused convergence test
    def _natural_residual(self, tao):
        """The convergence test's ``(natural, load error, fresh)`` in one pass; the iterate goes to the spare buffer."""
        problem = self.problem
        x = tao.getSolution()
        gap, total, separation = self.objective.cached_gap(x)
        mean_p = total / problem.n
        pbar = self.objective.pbar
        scale = pbar if pbar else (mean_p if mean_p > 0 else 1.0)
        upper = math.inf if problem.upper_bound is None else problem.upper_bound
        local = loops.natural_and_copy(x.getArray(readonly=True), gap, scale, upper,
                                       self.buffers[1 - self.best].getArray())
        natural, = allmax(problem.mpi, [local])
        load_error = None if pbar is None else abs(mean_p - pbar) / pbar
        self.last = (natural, load_error, mean_p, separation)
        return natural, load_error, True

    def _keep_best(self, x):
        self.best = 1 - self.best  # the spare buffer holds the iterate just tested

    def _run(self, pressure, test):
        """TAO from ``pressure``, restarted from its best iterate while round-off stops it; (iterations, restarts)."""
        iterations, restarts, floor = 0, 0, np.inf
        while True:
            self.objective.restart()
            self.tao.setSolution(pressure)
            self.tao.solve(pressure)
            iterations += self.tao.getIterationNumber()
            test.iteration_offset += self.tao.getIterationNumber()
            reason = self.tao.getConvergedReason()
            if reason > 0 or not restartable(reason, test.watch) or restarts == MAX_RESTARTS \
                    or not test.watch.best_natural < RESTART_GAIN * floor:
                return iterations, restarts
            floor = test.watch.best_natural
            restarts += 1
            test.watch.restart(test.iteration_offset - 1)
            self.buffers[self.best].copy(pressure)

    def _touch(self, pressure):
        """The separation at which the surfaces touch, for ``pressure`` out of contact (its gap is d - h)."""
        gap, _, separation = self.objective.cached_gap(pressure)
        return separation - allmin(self.problem.mpi, [gap.min()])[0]

    def _project(self, pressure):
        local = self.problem.local(pressure)
        np.maximum(local, 0.0, out=local)
        if self.problem.upper_bound is not None:
            np.minimum(local, self.problem.upper_bound, out=local)

    @property
    def separation(self):
        return self.objective.separation

    def solve(self, target, pressure, guess=None, history=None):
        """Solve for ``target`` (scaled mean pressure or separation) from ``pressure`` (overwritten).

        ``history`` collects the residuals of several solves (a root find's); a fresh one by default.
        """
        self._project(pressure)
        history = history or History(self.problem)
        watch = self.rule.watch(history)
        test = ConvergenceTest(watch, self._natural_residual, keep_best=self._keep_best)
        self.tao.setConvergenceTest(test)
        self.last = None
        if self.control == "displacement":
            return self._solve_displacement(target, pressure, test, history)
        return self._solve_load(target, pressure, guess, test, history)

    def _solve_displacement(self, separation, pressure, test, history):
        self._set_penalty(0.0)
        self.objective.configure(separation)
        _set_recycle(self.tao, False)
        iterations, restarts = self._run(pressure, test)
        reason = self.tao.getConvergedReason()
        if reason < 0 and np.isfinite(test.watch.best_natural):
            self.buffers[self.best].copy(pressure)
        return Outcome(separation, iterations, describe_stop(reason, test.watch, restarts), history.as_array())

    def _solve_load(self, pbar, pressure, guess, test, history):
        """The augmented Lagrangian on mean(p) = pbar; lambda starts at ``guess.separation``."""
        problem = self.problem
        grid = problem.scaled_grid
        penalty = self.penalty_factor * max(grid.l0, grid.l1) / np.pi
        self._set_penalty(penalty)
        lam = guess.separation if guess is not None else None
        points = []  # (d, mean p) of each inner solution
        iterations = restarts = 0
        for outer in range(self.max_outer):
            _set_recycle(self.tao, self.recycle and outer > 0)
            self.objective.configure(lam, penalty, pbar)
            test.watch.inner_eta = self.eta if outer < self.max_outer - 1 else 0.0
            done, restarted = self._run(pressure, test)
            iterations += done
            restarts += restarted
            if self.last is None:
                gap, total, separation = self.objective.cached_gap(pressure)
                mean_p = total / problem.n
            else:
                _, _, mean_p, separation = self.last
            points.append((separation, mean_p))
            if test.verdict is not Verdict.INNER_DONE:
                break
            stiffness = contact_stiffness(problem, pressure, self.stiffness_preconditioner) \
                if len(points) == 1 and self.newton else None
            lam = next_multiplier(points, pbar, separation, stiffness, self._touch(pressure) if mean_p == 0 else None)
        note = f"{len(points)} inner solve{'s' * (len(points) > 1)}"
        reason = self.tao.getConvergedReason()
        if test.verdict is Verdict.CONVERGED:
            description = f"CONVERGED_USER ({note})"
        elif test.verdict is Verdict.INNER_DONE:
            description = f"DIVERGED_AL_MAX_OUTER ({note}, best of natural residual, load error " \
                          f"{test.watch.best_natural:.2g})"
        else:
            description = describe_stop(reason, test.watch, restarts, load_control=True, note=note)
        if test.verdict is not Verdict.CONVERGED and np.isfinite(test.watch.best_natural):
            self.buffers[self.best].copy(pressure)
        return Outcome(separation, iterations, description, history.as_array())

    def destroy(self):
        self.tao.destroy()
        for obj in (self.objective, *self.buffers, self.lower, self.upper, self.gradient, self.hessian,
                    self.preconditioning, self.fourier, self.initial_hessian, self.stiffness_preconditioner):
            if obj is not None:
                obj.destroy()


def make_bound(problem, control, tao_type, settings):
    """The bound type ``tao_type``: :class:`BoundQP`, or under load control with ``-bound_load rootfind`` RootFind."""
    gap_applies = getattr(problem, "boundary", None) == "periodic" and getattr(problem, "upper_bound", None) is None
    method = PETSc.Options(settings.prefix).getString("bound_load", "") or \
        ("gap" if gap_applies and tao_type in GAP_DEFAULT_TYPES else "al")
    if method not in LOAD_METHODS:
        raise UserError(f"{option_name('bound_load', settings.prefix)}: unknown method '{method}' "
                        f"(one of {', '.join(LOAD_METHODS)})")
    if control == "load" and method == "rootfind":
        from .root_find import RootFind

        return RootFind(problem, control, tao_type, settings)
    if control == "load" and method == "gap":  # under displacement control every method is the same QP
        from .bound_gap import GapLoadQP

        return GapLoadQP(problem, control, tao_type, settings)
    return BoundQP(problem, control, tao_type, settings)


register(BOUND_TYPES, make_bound, options=OPTIONS)
