"""The one stopping rule of every solver backend: tolerance, fresh confirmation, limits, stagnation, best iterate.

Every backend decides when to stop with a :class:`Watch` on one :class:`StoppingRule`: converged when the
natural KKT residual (docs/conventions.md) and the error of a prescribed load or mean gap are at most ``rtol``
(on a fresh gradient); else the iteration limit, the time limit or Ctrl-C (decided collectively), or
stagnation. A stop short of the tolerance names its reason and the best residual (:func:`describe_stop`).
"""

from dataclasses import dataclass
import enum
import time

import numpy as np
from petsc4py import PETSc

from ..errors import UserError
from ..parallel import allmax

# The iteration limit every TAO of the solvers starts with (-tao_max_it changes it): the natural-residual
# test decides, and TAO's own limits (the BNK family stops at 50) would end solves early.
DEFAULT_MAX_IT = 100000
# A solve whose residual has not improved on its best for this many iterations is stopped (BQNLS can freeze at
# a fixed iterate without a verdict of its own; CG wanders at the round-off floor).
STAGNATION_ITERATIONS = 500

OPTIONS = [
    ("solve_max_time", 0.0, "stop a solve after this many seconds, reported as DIVERGED_USER (0: no limit)"),
]


def option_name(name, prefix=None):
    """The option as the user types it: ``-`` + prefix + name."""
    return f"-{prefix or ''}{name}"


KIND_WORDS = {"Real": "a number", "Int": "an integer", "Bool": "true or false"}


def read_option(options, kind, name, default):
    """``options.get<kind>(name, default)`` (kind: Real, Int or Bool); a value PETSc cannot read is refused by name.

    PETSc's own message ("Input string abc has no numeric value") names neither the option nor its prefix.
    """
    try:
        value = getattr(options, "get" + kind)(name, default)
    except PETSc.Error:
        raise UserError(f"{option_name(name, options.prefix)}: cannot read the value '{options.getString(name, '')}' "
                        f"as {KIND_WORDS[kind]}") from None
    if kind == "Int":
        check_int_range(options, name, value)
    return value


def check_int_range(options, name, value):
    """Refuse an integer ``-name`` beyond PETSc's integers: PETSc reads 3000000000 as -1294967296, silently."""
    if not options.hasName(name):
        return
    text = options.getString(name, "").strip()
    try:
        given = int(text)
    except ValueError:
        return
    if given != value:
        limits = np.iinfo(PETSc.IntType)
        raise UserError(f"{option_name(name, options.prefix)}: the value '{text}' is beyond the integers PETSc "
                        f"reads ({limits.min} to {limits.max})")


def max_seconds(prefix=None):
    """``-solve_max_time`` under ``prefix``: seconds after which a solve stops (0: no limit)."""
    seconds = read_option(PETSc.Options(prefix), "Real", "solve_max_time", 0.0)
    if not (seconds >= 0 and np.isfinite(seconds)):
        raise UserError(f"{option_name('solve_max_time', prefix)} must be a non-negative, finite number of seconds "
                        f"(0: no limit), got {seconds}")
    return seconds


class History:
    """Residual history of one solve: iteration, natural residual, operator applications, seconds.

    Each row is also passed to the problem's ``progress(iteration, natural, seconds)``, if set.
    """

    def __init__(self, problem):
        self.operator = problem.operator
        self.mpi = problem.mpi
        self.progress = problem.progress
        self.stop_requested = problem.stop_requested
        self.start = time.perf_counter()
        self.rows = []

    def record(self, iteration, natural):
        seconds = time.perf_counter() - self.start
        self.rows.append((iteration, natural, self.operator.applications, seconds))
        if self.progress is not None:
            self.progress(iteration, natural, seconds)

    def extend(self, rows):
        """Append the rows of another solve (the inner solves of a root find), numbered on from these."""
        offset = self.rows[-1][0] + 1 if self.rows else 0
        self.rows.extend((offset + row[0], *row[1:]) for row in rows)

    def out_of_time(self, max_seconds):
        """True when ``max_seconds`` (> 0) have passed since the start, or a stop was requested on any rank.

        Collective: rank 0's clock decides for every rank (ranks leaving at different iterations would hang).
        """
        timed = max_seconds > 0
        if not timed and self.stop_requested is None:
            return False
        expired = timed and time.perf_counter() - self.start > max_seconds
        asked = self.stop_requested is not None and self.stop_requested()
        return bool(allmax(self.mpi, [(expired and self.mpi.Get_rank() == 0) or asked])[0])

    def as_array(self):
        return np.array(self.rows, dtype=np.float64).reshape(-1, 4)


@dataclass(frozen=True)
class StoppingRule:
    """When a solve stops: tolerance ``rtol`` on the natural residual and load error, ``max_seconds``
    (``-solve_max_time``, 0: no limit), ``stagnation`` iterations without a new best residual."""

    rtol: float
    max_seconds: float = 0.0
    stagnation: int = STAGNATION_ITERATIONS

    def watch(self, history, max_iterations=DEFAULT_MAX_IT):
        """A :class:`Watch` of one solve under this rule, recording into ``history``."""
        return Watch(self, history, max_iterations)


class Verdict(enum.Enum):
    CONTINUE = "continue"
    CONFIRM = "confirm on a fresh gradient"
    CONVERGED = "converged"
    INNER_DONE = "an inner solve done: its residual is below the share of the load error it may keep"
    MAX_ITERATIONS = "iteration limit"
    TIME_LIMIT = "time limit"
    STAGNATION = "stagnation"

    @property
    def tao_reason(self):
        """The TAO converged reason of a final verdict (None while iterating)."""
        return {Verdict.CONVERGED: PETSc.TAO.Reason.CONVERGED_USER,
                Verdict.INNER_DONE: PETSc.TAO.Reason.CONVERGED_USER,
                Verdict.MAX_ITERATIONS: PETSc.TAO.Reason.DIVERGED_MAXITS,
                Verdict.TIME_LIMIT: PETSc.TAO.Reason.DIVERGED_USER,
                Verdict.STAGNATION: PETSc.TAO.Reason.DIVERGED_USER}.get(self)


class Watch:
    """One solve under a :class:`StoppingRule`: its history, its best residual, its verdicts.

    Attributes
    ----------
    best_natural : float
        The lowest merit seen: the natural residual, or the larger of it and the load error.
    improved : bool
        Whether the last :meth:`assess` found a new best.
    stopped_by : str or None
        ``"time limit"`` or ``"stagnation"`` when the watch ended the solve so.
    inner_eta : float or None
        An inner solve of an augmented Lagrangian is done (``INNER_DONE``) once it has taken a step and its natural
        residual is at most ``inner_eta`` times its load error capped at 1. 0: only an exact inner solution ends it
        short of the tolerance (BNLS, asked to go on from one, never returned). None: not an inner solve.
    """

    def __init__(self, rule, history, max_iterations=DEFAULT_MAX_IT):
        self.rule = rule
        self.history = history
        self.max_iterations = max_iterations
        self.inner_eta = None
        self.best_natural = np.inf
        self.best_iteration = 0
        self.improved = False
        self.stopped_by = None

    def converged(self, natural, load_error=None):
        rtol = self.rule.rtol
        return natural <= rtol and (load_error is None or load_error <= rtol)

    def assess(self, iteration, natural, load_error=None, fresh=True, confirm=True):
        """The verdict on an iterate with this residual (and load error); records it unless it must be confirmed.

        A converged residual on an updated (not ``fresh``) gradient returns ``CONFIRM`` when ``confirm``.
        """
        self.improved = False
        merit = natural if load_error is None else max(natural, load_error)
        if self.converged(natural, load_error):
            if not fresh and confirm:
                return Verdict.CONFIRM
            self.history.record(iteration, natural)
            self.best_natural = merit
            return Verdict.CONVERGED
        self.history.record(iteration, natural)
        if merit < self.best_natural:
            self.best_natural, self.best_iteration, self.improved = merit, iteration, True
        if self.inner_eta is not None and load_error is not None and natural <= self.inner_eta * min(load_error, 1.0):
            return Verdict.INNER_DONE
        if iteration >= self.max_iterations:
            return Verdict.MAX_ITERATIONS
        if self.history.out_of_time(self.rule.max_seconds):
            self.stopped_by = "time limit"
            return Verdict.TIME_LIMIT
        if iteration - self.best_iteration >= self.rule.stagnation:
            self.stopped_by = "stagnation"
            return Verdict.STAGNATION
        return Verdict.CONTINUE

    def restart(self, iteration):
        """A backend restarts from its best iterate at ``iteration``: stagnation counts afresh, the best stays."""
        self.best_iteration, self.stopped_by = iteration, None


class ConvergenceTest:
    """The :class:`Watch` as a TAO convergence test (``tao.setConvergenceTest``).

    ``evaluate(tao)`` returns ``(natural, load_error, fresh)`` of the current iterate. TAO's own "converged"
    never ends a solve early. ``keep_best(x)``, if given, is called with each new best iterate.
    """

    def __init__(self, watch, evaluate, keep_best=None, confirm=True):
        self.watch = watch
        self.evaluate = evaluate
        self.keep_best = keep_best
        self.confirm = confirm
        self.iteration_offset = 0
        self.verdict = Verdict.CONTINUE

    def __call__(self, tao):
        natural, load_error, fresh = self.evaluate(tao)
        iteration = tao.getIterationNumber()
        self.watch.max_iterations = tao.getMaximumIterations() + self.iteration_offset
        verdict = self.watch.assess(iteration + self.iteration_offset, natural, load_error, fresh, self.confirm)
        if verdict is Verdict.INNER_DONE and iteration == 0 and natural > 0:
            # The start of an inner solve is the last one's pressure at a new multiplier: not a point of P(d).
            verdict = Verdict.CONTINUE
        self.verdict = verdict
        if verdict is Verdict.CONFIRM:
            return PETSc.TAO.Reason.CONTINUE_ITERATING
        if self.watch.improved and self.keep_best is not None:
            self.keep_best(tao.getSolution())
        if verdict is not Verdict.CONTINUE:
            return verdict.tao_reason
        if tao.getConvergedReason() > 0 and iteration < tao.getMaximumIterations():
            return PETSc.TAO.Reason.CONTINUE_ITERATING
        return None


def check_convergence(tao):
    """Run the convergence test set on ``tao`` and set its reason (petsc4py 3.18 wraps no ``TaoConverged``)."""
    test, args, kwargs = tao.getConvergenceTest()
    reason = test(tao, *(args or ()), **(kwargs or {}))
    if reason is not None:
        tao.setConvergedReason(reason)
    return tao.getConvergedReason()


def reason_name(reason):
    """PETSc's name of a TAO converged reason."""
    for name, value in vars(PETSc.TAO.Reason).items():
        if not name.startswith("_") and value == reason and name not in ("ITERATING", "CONVERGED_ITERATING"):
            return name
    return str(reason)


def describe_stop(reason, watch, restarts=0, load_control=False, note=None):
    """PETSc's reason name (``reason``: int or name) with what the watch stopped for and, short of the
    tolerance, the best residual reached; ``note`` says why a backend gave up by itself."""
    name = reason if isinstance(reason, str) else reason_name(reason)
    notes = [watch.stopped_by] if watch.stopped_by and name == "DIVERGED_USER" else []
    if note:
        notes.insert(0, note)
    if not name.startswith("CONVERGED") and np.isfinite(watch.best_natural):
        measure = "of natural residual, load error" if load_control else "natural residual"
        notes.append(f"best {measure} {watch.best_natural:.2g}")
        if restarts:
            notes.append(f"floor after {restarts} restart{'s' * (restarts > 1)}")
    return f"{name} ({', '.join(notes)})" if notes else name
