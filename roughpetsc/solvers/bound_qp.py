"""Displacement control by any bound-constrained TAO type: ``min 1/2 p'Kp + p'(d - h)``, ``p >= 0``.

The scaled QP of the contact problem (3.41)-(3.44) of the dissertation at a prescribed rigid
separation d (the mean gap (3.38)). Registered under every name of :data:`BOUND_TYPES` for
displacement control; under load control the same names mean the root find on d
(:mod:`roughpetsc.solvers.root_find`) around this backend.
"""

import numpy as np
from petsc4py import PETSc

from ..contact.certificate import report
from ..errors import UserError
from .objective import QuadraticObjective
from .options import default_options, set_from_options
from .preconditioner import FourierPreconditioner
from .protocol import Backend, Outcome
from .registry import register
from .stopping import DEFAULT_MAX_IT, ConvergenceTest, History, describe_stop, option_name

BOUND_TYPES = ("blmvm", "bqnls", "bncg", "bqnkls", "bqnktr", "bqnktl", "bnls", "bntr", "bntl", "tron", "gpcg")
# Types whose Newton step is a KSP solve on the free set: they take the Fourier preconditioner.
# It is their default where it won (group #1, N = 512, p* = 0.5, displacement control: BNLS
# 622 -> 495 operator applications); TRON and GPCG run faster without it (TRON 298 -> 315,
# GPCG 434 -> 6520), so their default is no PC.
KSP_TYPES = ("bnls", "bntr", "bntl", "tron", "gpcg")
FOURIER_DEFAULT_TYPES = ("bnls", "bntr", "bntl")
BOUND_PRECONDITIONERS = ("fourier", "none", "options")
OPTIONS = [
    ("bound_pc", "", "TAO bnls/bntr/bntl/tron/gpcg: fourier (inverse symbol on the free set; default of the BNK "
                     "types) | none (default of tron, gpcg) | options (-tao_*pc_type decides)"),
]

# Restarts of a TAO solve that stopped for round-off (BoundQP.solve): at most this many, and only
# while each attempt lowers the best natural residual below this fraction of the previous one.
MAX_RESTARTS = 8
RESTART_GAIN = 0.9


def restartable(reason, test):
    """True for the stops that round-off in the objective causes: a failed line search, stagnation."""
    return reason in (PETSc.TAO.Reason.DIVERGED_LS_FAILURE, PETSc.TAO.Reason.DIVERGED_TR_REDUCTION) \
        or (reason == PETSc.TAO.Reason.DIVERGED_USER and test.stopped_by == "stagnation")


class BoundQP(Backend):
    """Displacement control: the bound-constrained QP at a given separation, by TAO.

    Working defaults for a shell Hessian are set before ``setFromOptions`` so
    that options override them: no gradient tolerances (the natural-residual
    test decides), a high iteration limit (the BNK family stops at 50 by
    default), subset type ``subvec`` for TRON and GPCG. The types that solve
    a Newton step with a KSP (BNLS, BNTR, BNTL, TRON, GPCG) get the Fourier
    preconditioner on the free set (``-bound_pc fourier``, the default of
    the BNK types), no PC (``none``, the default of TRON and GPCG), or
    whatever the options say (``options``).

    Parameters
    ----------
    problem : ContactProblem
    control : str
        Unused (always displacement control); part of the factory signature of the registry.
    tao_type : str
        One of :data:`BOUND_TYPES`.
    settings : roughpetsc.solvers.protocol.BackendSettings
    """

    def __init__(self, problem, control, tao_type, settings):
        self.problem = problem
        self.rule = settings.rule
        self.max_seconds = settings.max_seconds
        self.objective = QuadraticObjective(problem)
        self.best = problem.vec()  # the best iterate of a solve (lowest natural residual)
        self.hessian = problem.operator.mat()
        self.lower = problem.vec()
        self.lower.set(0.0)
        self.upper = problem.vec()
        self.upper.set(PETSc.INFINITY if problem.upper_bound is None else problem.upper_bound)
        self.gradient = problem.vec()
        self.fourier = self.preconditioning = None
        tao = self.tao = PETSc.TAO().create(problem.comm)
        tao.setOptionsPrefix(settings.prefix)
        tao.setType(tao_type)
        self._preconditioner(tao_type, settings.prefix)
        tao.setObjectiveGradient(self._objective_gradient, self.gradient)
        tao.setHessian(self._hessian, self.hessian, self.preconditioning or self.hessian)
        tao.setVariableBounds((self.lower, self.upper))
        tao.setTolerances(gatol=0.0, grtol=0.0, gttol=0.0)
        tao.setMaximumIterations(DEFAULT_MAX_IT)
        tao.setMaximumFunctionEvaluations(10 * DEFAULT_MAX_IT)
        with default_options(self._default_options(tao_type), settings.prefix):
            set_from_options(tao, self.destroy)
        self.name = tao.getType()

    @staticmethod
    def _default_options(tao_type):
        defaults = {}
        if tao_type in ("tron", "gpcg"):
            # The default mask subset and ILU fail on a shell Hessian.
            defaults["tao_subset_type"] = "subvec"
        if tao_type == "bnls":  # its default KSP, STCG, took 100x the operator applications of CG here
            defaults["tao_bnk_ksp_type"] = "cg"
        return defaults

    def _preconditioner(self, tao_type, prefix):
        """The KSP's PC from ``-bound_pc`` (read here: a bad value is refused before any solve)."""
        default = "fourier" if tao_type in FOURIER_DEFAULT_TYPES else "none"
        preconditioner = PETSc.Options(prefix).getString("bound_pc", default)
        if preconditioner not in BOUND_PRECONDITIONERS:
            self.destroy()
            raise UserError(f"{option_name('bound_pc', prefix)}: unknown preconditioner '{preconditioner}' "
                            f"(one of {', '.join(BOUND_PRECONDITIONERS)})")
        if tao_type in KSP_TYPES and preconditioner == "fourier":
            # The inverse symbol on the free set, through the Hessian's preconditioning matrix and PC "mat".
            self.fourier = FourierPreconditioner(self.problem)
            self.preconditioning = self.fourier.mat()
            self.tao.getKSP().getPC().setType("mat")
        elif tao_type in KSP_TYPES and preconditioner == "none":
            self.tao.getKSP().getPC().setType("none")

    def _objective_gradient(self, tao, x, gradient):
        return self.objective.evaluate(x, gradient)

    def _hessian(self, tao, x, H, P):
        H.getPythonContext().perturbation = 0.0  # a fresh Hessian: BNK's MatShift of the last one is undone

    @property
    def separation(self):
        return self.objective.separation

    def solve(self, separation, pressure, guess=None, history=None):
        """Solve at ``separation`` (scaled) from the start ``pressure`` (overwritten); ``guess`` is unused.

        ``history`` (:class:`~roughpetsc.kkt.History`) collects the residuals of several solves (the
        root find's); a fresh one by default.

        When TAO stops short of the tolerance for a reason that round-off can cause (a failed line
        search, or no progress for many iterations), it is restarted from its best iterate with the
        objective measured from there; this repeats while each attempt improves the best residual
        by at least :data:`RESTART_GAIN`, at most :data:`MAX_RESTARTS` times. If the tolerance is
        still not met, the best iterate is returned and the reason names the floor reached.
        """
        self.objective.restart(separation)
        history = history or History(self.problem)
        watch = self.rule.watch(history)
        test = ConvergenceTest(watch, self._natural_residual, keep_best=lambda x: x.copy(self.best))
        self.tao.setConvergenceTest(test)
        # A start outside the bounds would be projected by TAO anyway; do it here.
        local = self.problem.local(pressure)
        np.maximum(local, 0.0, out=local)
        if self.problem.upper_bound is not None:
            np.minimum(local, self.problem.upper_bound, out=local)
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
            watch.restart(iterations - 1)  # the next solve's first iteration, numbered iterations, counts one
            self.best.copy(pressure)
        if reason < 0 and np.isfinite(test.best_natural):
            self.best.copy(pressure)
        return Outcome(separation, iterations, describe_stop(reason, watch, restarts), history.as_array())

    def _natural_residual(self, tao):
        """The natural residual of TAO's iterate on its gap (the objective's cache): the convergence test's input."""
        x = tao.getSolution()
        problem = self.problem
        kkt = report(problem.mpi, x.getArray(readonly=True), self.objective.gap_of(x), problem.n, None,
                     problem.upper_bound)
        return kkt.natural, None, True

    def destroy(self):
        self.tao.destroy()
        for obj in (self.objective, self.best, self.hessian, self.lower, self.upper, self.gradient,
                    self.preconditioning, self.fourier):
            if obj is not None:
                obj.destroy()


register(BOUND_TYPES, BoundQP, controls=("displacement",), options=OPTIONS)
