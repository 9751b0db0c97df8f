"""Solvers of the contact QP under displacement and load control.

* Displacement control (prescribed mean gap d): ``min 1/2 p'Kp + p'(d - h)``,
  ``p >= 0``, by any TAO bound-constrained type (:class:`BoundQP`).
* Load control (prescribed pbar):
  Polonsky-Keer constrained CG as a TAO ``python`` type (:mod:`roughpetsc.pk`,
  also under displacement control),
  a safeguarded root find on d around :class:`BoundQP` (:class:`RootFind`), or
  TAO ALMM with the equality ``mean(p) = pbar`` (:class:`ALMMLoad`).

Every solver works on the scaled problem of :class:`~roughpetsc.contact.ContactProblem`,
updates the pressure Vec it is given (the warm start) and returns an
:class:`Outcome`; :class:`Solver` turns that into a checked
:class:`~roughpetsc.contact.Result`.
"""

from contextlib import contextmanager
from dataclasses import dataclass
import time

import numpy as np
from petsc4py import PETSc

from .contact import Result, measure
from .errors import UserError
from .kkt import ConvergenceTest, History, allsum, report
from .pk import PolonskyKeer
from .preconditioner import FourierPreconditioner

BOUND_TYPES = ("blmvm", "bqnls", "bncg", "bqnkls", "bqnktr", "bqnktl", "bnls", "bntr", "bntl", "tron", "gpcg")
# Types whose Newton step is a KSP solve on the free set: they take the Fourier preconditioner.
# It is their default where it won (group #1, N = 512, p* = 0.5, displacement control: BNLS
# 622 -> 495 operator applications); TRON and GPCG run faster without it (TRON 298 -> 315,
# GPCG 434 -> 6520), so their default is no PC.
KSP_TYPES = ("bnls", "bntr", "bntl", "tron", "gpcg")
FOURIER_DEFAULT_TYPES = ("bnls", "bntr", "bntl")
BOUND_PRECONDITIONERS = ("fourier", "none", "options")
DEFAULT_MAX_IT = 100000


@dataclass
class Outcome:
    """What a solver reports besides the pressure it leaves in its Vec."""

    separation: float
    iterations: int
    reason: str
    history: np.ndarray


def reason_name(reason):
    """PETSc's name of a TAO converged reason."""
    for name, value in vars(PETSc.TAO.Reason).items():
        if not name.startswith("_") and value == reason and name not in ("ITERATING", "CONVERGED_ITERATING"):
            return name
    return str(reason)


def _reason(tao, test, restarts=0):
    """PETSc's reason, with what our convergence test stopped for (time limit, stagnation) and the floor.

    ``test`` is a :class:`~roughpetsc.kkt.ConvergenceTest` or the Polonsky-Keer context (both have
    ``stopped_by`` and ``best_natural``). A solve that ends short of the tolerance says which natural
    residual it reached (and, after restarts, that this is the floor that restarting could not
    lower), so a bare DIVERGED_LS_FAILURE is never the whole story.
    """
    name = reason_name(tao.getConvergedReason())
    notes = [test.stopped_by] if test.stopped_by and name == "DIVERGED_USER" else []
    if tao.getConvergedReason() < 0 and np.isfinite(test.best_natural):
        measure = "natural residual" if getattr(test, "target_pbar", None) is None else "of natural residual, load error"
        notes.append(f"best {measure} {test.best_natural:.2g}")
        if restarts:
            notes.append(f"floor after {restarts} restart{'s' * (restarts > 1)}")
    return f"{name} ({', '.join(notes)})" if notes else name


def restartable(reason, test):
    """True for the stops that round-off in the objective causes: a failed line search, stagnation."""
    return reason in (PETSc.TAO.Reason.DIVERGED_LS_FAILURE, PETSc.TAO.Reason.DIVERGED_TR_REDUCTION) \
        or (reason == PETSc.TAO.Reason.DIVERGED_USER and test.stopped_by == "stagnation")


# Restarts of a TAO solve that stopped for round-off (BoundQP.solve): at most this many, and only
# while each attempt lowers the best natural residual below this fraction of the previous one.
MAX_RESTARTS = 8
RESTART_GAIN = 0.9


def max_seconds():
    """``-solve_max_time``: seconds after which a solve stops with DIVERGED_USER (0: no limit)."""
    seconds = PETSc.Options().getReal("solve_max_time", 0.0)
    if not seconds >= 0:
        raise UserError(f"-solve_max_time must be a non-negative number of seconds, got {seconds}")
    return seconds


def set_from_options(tao, cleanup):
    """``tao.setFromOptions()``; a bad TAO option becomes a :class:`UserError` naming it, after ``cleanup()``."""
    try:
        tao.setFromOptions()
    except PETSc.Error as error:
        cleanup()
        lines = [line.split("]", 1)[-1].strip() for line in str(error).splitlines() if line.strip()]
        raise UserError(f"a solver option was refused by PETSc: {lines[-1]}") from None


@contextmanager
def default_options(defaults):
    """Options that apply inside the block unless the user gave them; removed again afterwards.

    The working defaults of one solver object must not stay in the global options database, where
    they would become the next object's settings (BNLS's CG made a later BNTR refuse its KSP).
    """
    options = PETSc.Options()
    inserted = [name for name in defaults if not options.hasName(name)]
    for name in inserted:
        options.setValue(name, defaults[name])
    try:
        yield
    finally:
        for name in inserted:
            options.delValue(name)


class QuadraticObjective:
    """The QP objective f = p'Kp/2 + p'(d - h) and its gradient, the gap g = K p + d - h, free of cancellation.

    TAO uses f only through differences, so f is measured from the first point evaluated after
    :meth:`restart` and accumulated from the last evaluated point r: f(x) = f(r) + (x - r)'(g(x) + g(r)) / 2,
    exact for a quadratic. Evaluated directly, f = (p'g + d sum(p) - p'h) / 2 carries a round-off of
    about eps |f| while a step near the solution changes f by about (residual)^2 |f|, so below a
    residual of about 1e-8 every line search and trust-region ratio failed for round-off (TAO's
    DIVERGED_LS_FAILURE at 1.9e-9 on a 128^2 problem). The increment's round-off is relative to
    the step, and after a restart the values TAO compares are as small as the decrease left.

    The last point and its gap are cached: :meth:`gap_of` of the last evaluated point costs nothing.

    ``increments=False`` evaluates f directly instead. ALMM wants that: its augmented-Lagrangian
    updates use the size of f, and with f measured from the start it took 26272 operator
    applications instead of 14976 (128^2, p* = 0.5, 1e-8).
    """

    def __init__(self, problem, increments=True):
        self.problem = problem
        self.increments = increments
        self.separation = 0.0
        self.value = 0.0
        self.point, self.gap, self.step = problem.vec(), problem.vec(), problem.vec()
        self.cached = False

    def restart(self, separation=None):
        """Forget the cache (and set a new separation): the next evaluated point has f = 0."""
        if separation is not None:
            self.separation = separation
        self.cached = False

    def evaluate(self, x, out):
        """``out = g(x)`` (one operator application); returns f(x)."""
        if not self.increments:
            self.problem.gap(x, self.separation, out)
            self.value = 0.5 * (x.dot(out) + self.separation * x.sum() - x.dot(self.problem.heights))
        elif self.cached:
            self.step.waxpy(-1.0, self.point, x)
            increment = self.step.dot(self.gap)
            self.problem.gap(x, self.separation, out)
            self.value += 0.5 * (increment + self.step.dot(out))
        else:
            self.problem.gap(x, self.separation, out)
            self.value = 0.0
        x.copy(self.point)
        if out is not self.gap:
            out.copy(self.gap)
        self.cached = True
        return self.value

    def gap_of(self, x):
        """The gap of ``x`` as this rank's local array, from the cache when ``x`` is the last point."""
        if not (self.cached and x.equal(self.point)):
            self.evaluate(x, self.gap)
        return self.problem.local(self.gap, readonly=True)

    def destroy(self):
        for v in (self.point, self.gap, self.step):
            v.destroy()


class BoundQP:
    """Displacement control: the bound-constrained QP at a given separation, by TAO.

    Working defaults for a shell Hessian are set before ``setFromOptions`` so
    that options override them: no gradient tolerances (the natural-residual
    test decides), a high iteration limit (the BNK family stops at 50 by
    default), subset type ``subvec`` for TRON and GPCG. The types that solve
    a Newton step with a KSP (BNLS, BNTR, BNTL, TRON, GPCG) get the Fourier
    preconditioner on the free set (``-bound_pc fourier``, the default of
    the BNK types), no PC (``none``, the default of TRON and GPCG), or
    whatever the options say (``options``).
    """

    def __init__(self, problem, tao_type, rtol):
        self.problem = problem
        self.rtol = rtol
        self.max_seconds = max_seconds()
        comm = problem.comm
        self.objective = QuadraticObjective(problem)
        self.best = problem.vec()  # the best iterate of a solve (lowest natural residual)
        self.hessian = problem.operator.mat()
        self.lower = problem.vec()
        self.lower.set(0.0)
        self.upper = problem.vec()
        self.upper.set(PETSc.INFINITY)
        self.gradient = problem.vec()
        self.fourier = self.preconditioning = None
        tao = self.tao = PETSc.TAO().create(comm)
        tao.setType(tao_type)
        defaults = {}
        if tao_type in ("tron", "gpcg"):
            # The default mask subset and ILU fail on a shell Hessian.
            defaults["tao_subset_type"] = "subvec"
        if tao_type == "bnls":  # its default KSP, STCG, took 100x the operator applications of CG here
            defaults["tao_bnk_ksp_type"] = "cg"
        preconditioner = PETSc.Options().getString("bound_pc",
                                                   "fourier" if tao_type in FOURIER_DEFAULT_TYPES else "none")
        if preconditioner not in BOUND_PRECONDITIONERS:
            self.destroy()
            raise UserError(f"-bound_pc: unknown preconditioner '{preconditioner}' "
                            f"(one of {', '.join(BOUND_PRECONDITIONERS)})")
        if tao_type in KSP_TYPES and preconditioner == "fourier":
            # The inverse symbol on the free set, through the Hessian's preconditioning matrix and PC "mat".
            self.fourier = FourierPreconditioner(problem)
            self.preconditioning = self.fourier.mat()
            tao.getKSP().getPC().setType("mat")
        elif tao_type in KSP_TYPES and preconditioner == "none":
            tao.getKSP().getPC().setType("none")
        tao.setObjectiveGradient(self._objective_gradient, self.gradient)
        tao.setHessian(self._hessian, self.hessian, self.preconditioning or self.hessian)
        tao.setVariableBounds((self.lower, self.upper))
        tao.setTolerances(gatol=0.0, grtol=0.0, gttol=0.0)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        tao.setMaximumFunctionEvaluations(10 * DEFAULT_MAX_IT)
        with default_options(defaults):
            set_from_options(tao, self.destroy)
        self.tao_type = tao.getType()

    def _objective_gradient(self, tao, x, gradient):
        return self.objective.evaluate(x, gradient)

    def _hessian(self, tao, x, H, P):
        H.getPythonContext().perturbation = 0.0  # a fresh Hessian: BNK's MatShift of the last one is undone

    @property
    def separation(self):
        return self.objective.separation

    def solve(self, separation, pressure, history=None):
        """Solve at ``separation`` (scaled) from the start ``pressure`` (overwritten).

        When TAO stops short of the tolerance for a reason that round-off can cause (a failed line
        search, or no progress for many iterations), it is restarted from its best iterate with the
        objective measured from there; this repeats while each attempt improves the best residual
        by at least :data:`RESTART_GAIN`, at most :data:`MAX_RESTARTS` times. If the tolerance is
        still not met, the best iterate is returned and the reason names the floor reached.
        """
        self.objective.restart(separation)
        history = history or History(self.problem)
        test = ConvergenceTest(self.problem.mpi, self.problem.n, self.rtol, self.objective.gap_of, history,
                               max_seconds=self.max_seconds, best=self.best)
        self.tao.setConvergenceTest(test)
        # A start outside the bounds would be projected by TAO anyway; do it here.
        local = self.problem.local(pressure)
        np.maximum(local, 0.0, out=local)
        iterations, restarts, floor = 0, 0, np.inf
        while True:
            self.objective.restart()
            self.tao.setSolution(pressure)
            self.tao.solve(pressure)
            iterations += self.tao.getIterationNumber()
            test.iteration_offset = iterations
            reason = self.tao.getConvergedReason()
            if reason > 0 or not restartable(reason, test) or restarts == MAX_RESTARTS \
                    or not test.best_natural < RESTART_GAIN * floor:
                break
            floor = test.best_natural
            restarts += 1
            test.stopped_by, test.since_best = None, 0
            self.best.copy(pressure)
        if reason < 0 and np.isfinite(test.best_natural):
            self.best.copy(pressure)
        return Outcome(separation, iterations, _reason(self.tao, test, restarts), history.as_array())

    def destroy(self):
        self.tao.destroy()
        for obj in (self.objective, self.best, self.hessian, self.lower, self.upper, self.gradient,
                    self.preconditioning, self.fourier):
            if obj is not None:
                obj.destroy()


class RootFind:
    """Load control by a safeguarded root find on the separation around :class:`BoundQP`.

    The mean pressure P(d) of the displacement-controlled solution decreases
    from the complete-contact pressure max(-p_c) at d -> 0+ to 0 at d = max(h),
    so [0, max h] brackets the root and no solve is needed at its ends. Brent's
    method (scipy) narrows it; every inner solve starts from the previous
    pressure. The search stops when |P(d) - pbar| / pbar <= rtol.

    Near complete contact P changes so fast with d that the bracket can reach
    round-off in d before the load is met. The solution is affine in d while
    the contact set stays the same (K_CC p_C = h_C - d), so the search then
    interpolates to the load between its closest solutions on either side of
    it; the result is kept if it meets the tolerance on a fresh gap.
    """

    def __init__(self, problem, tao_type, rtol, max_evaluations=100):
        self.qp = BoundQP(problem, tao_type, rtol)
        self.problem = problem
        self.rtol = rtol
        self.max_evaluations = max_evaluations
        self.tao_type = self.qp.tao_type
        self.bracket = {"above": problem.vec(), "below": problem.vec()}  # solutions either side of the load
        self.trial, self.gap = problem.vec(), problem.vec()

    def solve(self, pbar, pressure, separation_guess=None):
        from scipy.optimize import brentq

        problem = self.problem
        history = History(problem)
        state = {"iterations": 0, "evaluations": 0, "inner": "", "stop": None, "separation": None}

        class Found(Exception):
            pass

        def excess(d):
            if d <= 0.0:
                return problem.complete_contact_pbar - pbar
            if d >= problem.max_height:
                return -pbar
            outcome = self.qp.solve(d, pressure, history)
            state["iterations"] += outcome.iterations
            state["evaluations"] += 1
            state["inner"], state["separation"] = outcome.reason, d
            mean_p = pressure.sum() / problem.n
            side = "above" if mean_p > pbar else "below"  # the closest solutions on each side of the load
            pressure.copy(self.bracket[side])
            state[side] = (d, mean_p)
            if abs(mean_p - pbar) <= self.rtol * pbar:
                if not outcome.reason.startswith("CONVERGED"):
                    state["stop"] = "DIVERGED_ROOT_INNER"  # the load is met, the inner QP is not solved
                raise Found
            if state["evaluations"] >= self.max_evaluations:
                state["stop"] = "DIVERGED_ROOT_MAXFCN"
                raise Found
            if history.out_of_time(self.qp.max_seconds):
                state["stop"] = "DIVERGED_USER"
                raise Found
            return mean_p - pbar

        lower, upper = 0.0, problem.max_height
        try:
            if separation_guess is not None and 0.0 < separation_guess < upper:
                value = excess(separation_guess)
                lower, upper = (separation_guess, upper) if value > 0 else (lower, separation_guess)
            brentq(excess, lower, upper, xtol=1e-15 * problem.max_height, rtol=1e-15, maxiter=self.max_evaluations)
            state["stop"] = "DIVERGED_ROOT_TOLERANCE"  # the bracket shrank to round-off without meeting the load
        except Found:
            pass
        if state["separation"] is None:
            state["separation"] = self.qp.separation
        interpolated = state["stop"] in ("DIVERGED_ROOT_TOLERANCE", "DIVERGED_ROOT_MAXFCN") and \
            "above" in state and "below" in state and self._interpolate(pbar, pressure, state)
        load_error = abs(pressure.sum() / problem.n - pbar) / pbar
        if interpolated:
            reason = (f"CONVERGED_ROOT ({state['evaluations']} inner solves; the bracket on d reached round-off, "
                      "the solutions either side of the load interpolated to it)")
        elif state["stop"] is None:
            reason = f"CONVERGED_ROOT ({state['evaluations']} inner solves)"
        else:
            notes = [f"{state['evaluations']} inner solves", f"load error {load_error:.2g}"]
            if state["stop"] == "DIVERGED_USER":
                notes.insert(0, "time limit")
            if not state["inner"].startswith("CONVERGED"):
                notes.append(f"last inner solve: {state['inner']}")
            reason = f"{state['stop']} ({', '.join(notes)})"
        return Outcome(state["separation"], state["iterations"], reason, history.as_array())

    def _interpolate(self, pbar, pressure, state):
        """Replace ``pressure`` by the interpolation to the load of the solutions either side of it.

        Returns True when the interpolated pressure meets the tolerance on a fresh gap (one operator
        application) and has been put in ``pressure`` and ``state["separation"]``.
        """
        problem = self.problem
        (d_above, mean_above), (d_below, mean_below) = state["above"], state["below"]
        t = (pbar - mean_below) / (mean_above - mean_below)
        separation = d_below + t * (d_above - d_below)
        above, below = self.bracket["above"], self.bracket["below"]
        self.trial.waxpy(-1.0, below, above)  # p_above - p_below
        self.trial.aypx(t, below)             # p_below + t (p_above - p_below)
        local = problem.local(self.trial)
        np.maximum(local, 0.0, out=local)
        problem.gap(self.trial, separation, self.gap)
        kkt = report(problem.mpi, local, problem.local(self.gap, readonly=True), problem.n, pbar)
        if not (kkt.natural <= self.rtol and kkt.load_error <= self.rtol):
            return False
        self.trial.copy(pressure)
        state["separation"] = separation
        return True

    def destroy(self):
        self.qp.destroy()
        for v in (*self.bracket.values(), self.trial, self.gap):
            v.destroy()


class ALMMLoad:
    """Load control by TAO ALMM: ``min 1/2 p'Kp - p'h`` with ``p >= 0`` and ``mean(p) = pbar``.

    The multiplier of the equality is the separation; it is recovered from the
    contact set as in Polonsky-Keer. The subsolver is chosen with
    ``-tao_almm_subsolver_tao_type`` (first-order types only in PETSc 3.18).
    """

    def __init__(self, problem, rtol):
        self.problem = problem
        self.rtol = rtol
        self.max_seconds = max_seconds()
        self.target = 0.0
        self.history = None
        comm = problem.comm
        n_local = problem.operator.local_shape[0] * problem.operator.local_shape[1]
        rows = 1 if comm.getRank() == 0 else 0
        self.gradient = problem.vec()
        self.gap_vec = problem.vec()
        self.objective = QuadraticObjective(problem, increments=False)  # at separation 0: f = p'Kp/2 - p'h
        self.hessian = problem.operator.mat()
        self.lower = problem.vec()
        self.lower.set(0.0)
        self.upper = problem.vec()
        self.upper.set(PETSc.INFINITY)
        self.constraint = PETSc.Vec().createMPI((rows, 1), comm=comm)
        # The Jacobian of mean(p) - pbar: one dense row of 1/n, owned by rank 0.
        self.jacobian = PETSc.Mat().createDense(((rows, 1), (n_local, problem.n)), comm=comm)
        self.jacobian.setUp()
        start, end = self.gradient.getOwnershipRange()
        columns = np.arange(start, end, dtype=PETSc.IntType)
        self.jacobian.setValues([0], columns, np.full(columns.size, 1.0 / problem.n))
        self.jacobian.assemble()
        tao = self.tao = PETSc.TAO().create(comm)
        tao.setType("almm")
        tao.setObjectiveGradient(self._objective_gradient, self.gradient)
        tao.setHessian(lambda *args: None, self.hessian, self.hessian)
        tao.setVariableBounds((self.lower, self.upper))
        tao.setEqualityConstraints(self._equality, self.constraint)
        tao.setJacobianEquality(lambda *args: None, self.jacobian, self.jacobian)
        tao.setTolerances(gatol=0.0, grtol=0.0, gttol=0.0)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        set_from_options(tao, self.destroy)
        self.tao_type = "almm"

    def _objective_gradient(self, tao, x, gradient):
        objective = self.objective.evaluate(x, gradient)
        if self.history is not None and self.history.out_of_time(self.max_seconds):
            # petsc4py cannot reach the subsolver's convergence test: a zero gradient ends the inner
            # solve at once, and the outer test then reports the time limit.
            gradient.set(0.0)
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

    def solve(self, pbar, pressure):
        self.target = pbar
        history = self.history = History(self.problem)
        test = ConvergenceTest(self.problem.mpi, self.problem.n, self.rtol, self.gap_of, history, target_pbar=pbar,
                               max_seconds=self.max_seconds)
        self.tao.setConvergenceTest(test)
        self.objective.restart()
        self.tao.setSolution(pressure)
        self.tao.solve(pressure)
        self.gap_of(pressure)
        return Outcome(self.separation, self.tao.getIterationNumber(), _reason(self.tao, test), history.as_array())

    def destroy(self):
        self.tao.destroy()
        for obj in (self.gradient, self.gap_vec, self.objective, self.hessian, self.lower, self.upper, self.constraint,
                    self.jacobian):
            obj.destroy()


class PKSolve:
    """Polonsky-Keer (projected, preconditioned CG) as a TAO of type ``python`` (so -tao_monitor etc. work).

    ``solve(target, pressure)`` takes the scaled mean pressure under load
    control, the scaled separation under displacement control.
    """

    def __init__(self, problem, rtol, control):
        self.problem = problem
        self.control = control
        self.context = PolonskyKeer(problem, rtol)
        self.context.max_seconds = max_seconds()
        try:
            self.context.configure()
        except UserError:
            self.context.destroy()
            raise
        tao = self.tao = PETSc.TAO().create(problem.comm)
        tao.setType(PETSc.TAO.Type.PYTHON)
        tao.setPythonContext(self.context)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        set_from_options(tao, self.destroy)
        self.tao_type = "pk"

    def solve(self, target, pressure):
        if self.control == "load":
            self.context.target_pbar, self.context.target_separation = target, None
        else:
            self.context.target_pbar, self.context.target_separation = None, target
            local = self.problem.local(pressure)
            np.maximum(local, 0.0, out=local)
        self.tao.setSolution(pressure)
        self.tao.solve(pressure)
        ctx = self.context
        return Outcome(ctx.separation, self.tao.getIterationNumber(), _reason(self.tao, ctx), ctx.history.as_array())

    def destroy(self):
        self.tao.destroy()
        self.context.destroy()


class Solver:
    """One contact solver for a problem, chosen by options; solves loads in order with warm starts.

    Parameters
    ----------
    problem : ContactProblem
    control : "load" or "displacement"
    tao_type : str or None
        None: Polonsky-Keer (preconditioned by default, ``-pk_pc``) under
        load and displacement control; "almm": ALMM (load control only); a bound type: that TAO type
        (inside the root find under load control).
    rtol : float
        Stopping tolerance on the natural KKT residual (-kkt_rtol).
    """

    def __init__(self, problem, control, tao_type, rtol):
        self.problem = problem
        self.control = control
        self.rtol = rtol
        if tao_type in (None, "", "python", "pk"):
            tao_type = None
        elif tao_type == "almm":
            if control != "load":
                raise UserError("-tao_type almm solves load control only (use -pbar or -pstar)")
        elif tao_type not in BOUND_TYPES:
            raise UserError(f"-tao_type {tao_type} is not a bound-constrained TAO type for this QP; "
                            f"use one of {', '.join(BOUND_TYPES)}, almm, or none (Polonsky-Keer)")
        if tao_type is None:
            self.backend = PKSolve(problem, rtol, control)
        elif control == "displacement":
            self.backend = BoundQP(problem, tao_type, rtol)
        elif tao_type == "almm":
            self.backend = ALMMLoad(problem, rtol)
        else:
            self.backend = RootFind(problem, tao_type, rtol)
        self.name = self.backend.tao_type if control == "displacement" or tao_type in (None, "almm") \
            else f"rootfind({self.backend.tao_type})"
        if tao_type is None:
            self.name = f"pk({self.backend.context.preconditioner})"
        self.pressure = problem.vec()
        self.pressure.set(0.0)
        self.previous = None  # the solution before the last, for the load-path predictor (load paths only)
        self.gap = problem.vec()
        self.last_separation = None
        self.solved_targets = []  # scaled loads of the solutions in (previous, pressure)
        # PK's load paths: K p of the solutions in solved_targets, K p of the start, every Vec made for them.
        self._displacements, self._start_displacement, self._displacement_pool = [], None, []

    def solve(self, pbar=None, pstar=None, gbar=None):
        """Solve one load; the previous solution is the start. Returns a :class:`Result`."""
        problem = self.problem
        start = time.perf_counter()
        applications = problem.operator.applications
        unconfirmed = False  # PK stopped without confirming on a fresh gap (load control, see _pk_solve)
        if gbar is not None:
            if not gbar > 0:
                raise UserError(f"-gbar must be positive (complete contact has zero mean gap), got {gbar}")
            target = None
            outcome = self.backend.solve(gbar / problem.height_scale, self.pressure)
        else:
            target = problem.scaled_pbar(pbar, pstar)
            if not target > 0:
                raise UserError(f"the load must be positive: -pbar/-pstar gave {pbar if pstar is None else pstar}")
            if target >= problem.complete_contact_pbar:
                outcome = self._complete_contact(target)
            else:
                start_displacement = self._load_start(target)
                if isinstance(self.backend, RootFind):
                    outcome = self.backend.solve(target, self.pressure, self.last_separation)
                elif isinstance(self.backend, PKSolve):
                    outcome = self._pk_solve(target, start_displacement)
                    unconfirmed = self.backend.context.unconfirmed
                else:
                    outcome = self.backend.solve(target, self.pressure)
        self.last_separation = outcome.separation
        self.solved_targets = (self.solved_targets + [target])[-2:] if target is not None else []
        result = self._result(outcome, target, start, applications)
        if unconfirmed and not result.converged:
            # PK stopped on its updated gap and the fresh one disagrees: resume, confirming this time.
            resumed = self.backend.solve(target, self.pressure)
            outcome = Outcome(resumed.separation, outcome.iterations + resumed.iterations, resumed.reason,
                              np.concatenate([outcome.history, resumed.history]))
            self.last_separation = outcome.separation
            result = self._result(outcome, target, start, applications)
        self._keep_displacement(target, outcome.separation)
        return result

    def _pk_solve(self, target, start_displacement):
        """PK under load control: it starts from the predicted K p and stops unconfirmed; certified here.

        The predictor knows K p of its start (a combination of the K p of the previous solutions: one FFT
        pair saved), and PK may stop on its updated gap without a fresh confirming K p (another), because
        :meth:`_result` checks every result on a fresh gap: if that check fails, :meth:`solve` resumes PK
        from its iterate with the confirmation on.
        """
        context = self.backend.context
        context.initial_displacement = start_displacement
        context.confirm = False
        try:
            outcome = self.backend.solve(target, self.pressure)
        finally:
            context.initial_displacement, context.confirm = None, True
        return outcome

    def _keep_displacement(self, target, separation):
        """Keep K p of the solution just certified (from its fresh gap: K p = g - d + h) for the predictor.

        Load control by PK only; the kept K p follow ``solved_targets``.
        """
        if target is None or self.control != "load" or not isinstance(self.backend, PKSolve):
            self._displacements = []
            return
        if len(self._displacements) == 2:
            kept = self._displacements.pop(0)
        else:
            kept = self.problem.vec()
            self._displacement_pool.append(kept)
        kept.waxpy(1.0, self.problem.heights, self.gap)
        kept.shift(-separation)
        self._displacements.append(kept)

    def _load_start(self, target):
        """The start of a load-controlled solve from the previous solutions, and its K p if known.

        After two load-controlled solves, the pressure is extrapolated
        linearly in the load from them (the predictor of a continuation along
        the load path, its step ratio capped at 2), projected onto p >= 0; it
        is then scaled to the new mean pressure. After one, that solution is
        scaled; with none, the start is uniform.

        Returns K p of the start when it follows from the kept K p of the previous solutions (PK only:
        the same combination, exact when the projection changed nothing; K of a uniform pressure is 0),
        else None. Other choices tried along the 95-step history (quadratic or cubic extrapolation in the
        load, linear or quadratic in log or sqrt of the load, the predicted gap's entering nodes) started
        no closer: see studies/load_history.py.
        """
        displacements = self._displacements
        known = isinstance(self.backend, PKSolve) and len(displacements) == len(self.solved_targets)
        if known and self._start_displacement is None:
            self._start_displacement = self.problem.vec()
            self._displacement_pool.append(self._start_displacement)
        if self.solved_targets and self.previous is None:
            self.previous = self.problem.vec()
        if len(self.solved_targets) == 2:
            older, newer = self.solved_targets
            if newer != older:
                ratio = min((target - newer) / (newer - older), 2.0)
                # previous <- (1 + ratio) p_newer - ratio p_older, then swap: the start in pressure,
                # the newer solution kept in previous for the next step.
                self.previous.axpby(1.0 + ratio, -ratio, self.pressure)
                self.pressure, self.previous = self.previous, self.pressure
                local = self.problem.local(self.pressure)
                clipped, = allsum(self.problem.mpi, [np.count_nonzero(local < 0.0)])
                np.maximum(local, 0.0, out=local)
                if known:
                    known = clipped == 0
                    displacements[1].copy(self._start_displacement)
                    self._start_displacement.scale(1.0 + ratio)
                    self._start_displacement.axpy(-ratio, displacements[0])
            elif known:
                displacements[1].copy(self._start_displacement)
        elif self.solved_targets:
            self.pressure.copy(self.previous)
            if known:
                displacements[0].copy(self._start_displacement)
        elif known:
            self._start_displacement.set(0.0)
        mean_p = self.pressure.sum() / self.problem.n
        if mean_p > 0:
            self.pressure.scale(target / mean_p)
            if known:
                self._start_displacement.scale(target / mean_p)
        else:
            self.pressure.set(target)
            if known:
                self._start_displacement.set(0.0)
        return self._start_displacement if known else None

    def _complete_contact(self, target):
        """Beyond complete contact the exact answer is p = pbar + p_c, g = 0 (d = 0)."""
        self.problem.pressure_surface.copy(self.pressure)
        self.pressure.shift(target)
        return Outcome(0.0, 0, "COMPLETE_CONTACT_EXACT", np.zeros((0, 4)))

    def _result(self, outcome, target, start, applications):
        problem = self.problem
        # The certificate: a fresh gap of the final pressure, whatever the solver cached.
        problem.gap(self.pressure, outcome.separation, self.gap)
        p = problem.local(self.pressure, readonly=True)
        g = problem.local(self.gap, readonly=True)
        kkt = report(problem.mpi, p, g, problem.n, target)
        measures = measure(problem, p, g)
        converged = kkt.natural <= self.rtol and (kkt.load_error is None or kkt.load_error <= self.rtol)
        reason = outcome.reason
        if not converged and reason.startswith(("CONVERGED", "COMPLETE")):
            # The solver's own test passed on its own gap; the certificate on a fresh one did not.
            load = "" if kkt.load_error is None else f", load error {kkt.load_error:.2g}"
            reason = f"NOT_CERTIFIED ({reason}, but on a fresh gap: natural residual {kkt.natural:.2g}{load})"
        pbar = measures["pbar"] * problem.pressure_scale
        gbar = measures["gbar"] * problem.height_scale
        return Result(
            pbar=pbar, pstar=pbar / problem.sqrt_m0p, A=measures["A"], A_corrected=measures["A_corrected"],
            gbar=gbar, gstar=gbar / problem.sqrt_m0h, separation=outcome.separation * problem.height_scale,
            rms_gap_contact=measures["rms_gap_contact"] * problem.height_scale, kkt=kkt,
            iterations=outcome.iterations, operator_applications=problem.operator.applications - applications,
            time_s=time.perf_counter() - start, reason=reason, converged=converged, solver=self.name,
            control=self.control, history=outcome.history)

    def fields(self):
        """This rank's rows of the pressure and gap of the last solve, in pressure and length units."""
        problem = self.problem
        return (problem.local(self.pressure, readonly=True) * problem.pressure_scale,
                problem.local(self.gap, readonly=True) * problem.height_scale)

    def destroy(self):
        self.backend.destroy()
        self.pressure.destroy()
        if self.previous is not None:
            self.previous.destroy()
        for v in self._displacement_pool:
            v.destroy()
        self.gap.destroy()
