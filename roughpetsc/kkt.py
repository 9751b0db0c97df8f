"""KKT residuals of the contact problem (3.41)-(3.44) of the dissertation and the TAO convergence test.

The residuals and their scaling follow docs/conventions.md ("Residuals").

All residuals are scale-free: pressures are divided by the mean pressure pbar,
gaps by the rms height sqrt(m0^h). In the scaled variables of
:class:`roughpetsc.contact.ContactProblem` the rms height is 1, so gaps enter
as they are.
"""

from dataclasses import dataclass, asdict
import time

import numpy as np
from petsc4py import PETSc


@dataclass
class KKTReport:
    """The KKT report of one solve.

    natural : ||min(p / pbar, g / sqrt(m0^h))||_inf, the natural residual; with a hardness cap
        0 <= p <= H, ||mid(p / pbar, g / sqrt(m0^h), (p - H) / pbar)||_inf, the natural residual of
        the box (the middle value is the distance to the projection of p - g onto [0, H]).
    complementarity : sum(p g) / (sum(p) sqrt(m0^h)) (over the nodes below the cap, with one).
    min_p : min(p) / pbar (primal feasibility, >= 0 at a solution).
    min_g : min(g) / sqrt(m0^h) over the nodes below the cap (dual feasibility, >= 0 at a solution).
    load_error : |mean(p) - pbar| / pbar under load control, None under displacement control.
    """

    natural: float
    complementarity: float
    min_p: float
    min_g: float
    load_error: float = None

    def as_dict(self):
        return asdict(self)


def _allreduce(comm, values, operation):
    local = np.asarray(values, dtype=np.float64)
    if comm.Get_size() == 1:
        return local
    from mpi4py import MPI

    total = np.empty_like(local)
    comm.Allreduce(local, total, op=getattr(MPI, operation))
    return total


def allsum(comm, values):
    """Global sums of a sequence of local floats in one reduction (mpi4py communicator)."""
    return _allreduce(comm, values, "SUM")


def allmin(comm, values):
    """Global minima of a sequence of local floats in one reduction."""
    return _allreduce(comm, values, "MIN")


def allmax(comm, values):
    """Global maxima of a sequence of local floats in one reduction."""
    return _allreduce(comm, values, "MAX")


# -log_view: every call (the certificate of each result; each iteration of the TAO types' convergence test)
@PETSc.Log.EventDecorator("RPKKTCheck")
def report(comm, pressure, gap, n_total, target_pbar=None, upper=None):
    """KKT report of local arrays ``pressure``, ``gap`` (scaled units, rms height 1).

    ``target_pbar`` is the prescribed mean pressure under load control (None
    under displacement control, where the solution's own mean is used).
    ``upper`` is the hardness cap in the same units (None: no upper bound).
    """
    pressure, gap = pressure.ravel(), gap.ravel()
    residual, high = np.empty_like(pressure), np.empty_like(pressure)
    sum_p, sum_pg = allsum(comm, [pressure.sum(), np.dot(pressure, gap)])
    mean_p = sum_p / n_total
    scale = target_pbar if target_pbar else (mean_p if mean_p > 0 else 1.0)
    np.multiply(pressure, 1.0 / scale, out=residual)
    if upper is None:
        np.minimum(residual, gap, out=residual)
    else:
        # mid(p, g, p - H) = min(max(g, p - H), p) since p - H < p (in units of the scale).
        np.subtract(residual, upper / scale, out=high)
        np.maximum(gap, high, out=high)
        np.minimum(high, residual, out=residual)
    natural, = allmax(comm, [max(residual.max(initial=0.0), -residual.min(initial=0.0))])
    if upper is not None:
        # The capped nodes leave sum(p g) and min(g) through their mask in single passes: this runs every
        # iteration of a capped TAO solve, and numpy's reductions with where= are several times slower.
        at_cap = np.greater_equal(pressure, upper, out=high.view(np.bool_)[:pressure.size])
        capped_pg, = allsum(comm, [np.einsum("i,i,i->", at_cap, pressure, gap)])
        sum_pg -= capped_pg
    if upper is None:
        min_g_local = gap.min(initial=np.inf)
    else:
        lifted = np.multiply(at_cap, np.finfo(np.float64).max, out=residual)  # capped nodes out of min(g)
        lifted += gap
        min_g_local = lifted.min(initial=np.inf)
    min_p, min_g = allmin(comm, [pressure.min(initial=np.inf), min_g_local])
    min_p /= scale
    return KKTReport(
        natural=float(natural),
        complementarity=float(sum_pg / sum_p) if sum_p > 0 else 0.0,
        min_p=float(min_p),
        min_g=float(min_g),
        load_error=None if target_pbar is None else float(abs(mean_p - target_pbar) / target_pbar),
    )


def merit(kkt):
    """One number for "how far from the solution": the natural residual, and the load error if there is one.

    A load-controlled iterate with a small natural residual but the wrong mean pressure is not
    close to the solution (ALMM's early iterates), so the best iterate of a solve and the floor it
    reports are judged by both.
    """
    return kkt.natural if kkt.load_error is None else max(kkt.natural, kkt.load_error)


class History:
    """Residual history of one solve of ``problem``: iteration, natural residual, operator applications, seconds.

    The problem's ``progress`` callable, if set, is called as ``progress(iteration, natural, seconds)``
    with every row that any solver records (the command line's progress line on a terminal,
    :class:`Progress`).
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

    def out_of_time(self, max_seconds):
        """True when ``max_seconds`` (> 0) have passed since the history started (``-solve_max_time``), or
        when a stop was requested on any rank (the problem's ``stop_requested``, Ctrl-C).

        Collective when ``max_seconds > 0`` or a stop can be requested: rank 0's clock decides for
        every rank, as ranks whose clocks disagreed at the limit would leave the solve by different
        iterations and hang, and a request on any rank stops them all.
        """
        timed = max_seconds > 0
        if not timed and self.stop_requested is None:
            return False
        expired = timed and time.perf_counter() - self.start > max_seconds
        asked = self.stop_requested is not None and self.stop_requested()
        if self.mpi.Get_size() == 1:
            return expired or asked
        from mpi4py import MPI

        return bool(self.mpi.allreduce(int((expired and self.mpi.Get_rank() == 0) or asked), op=MPI.MAX))

    def as_array(self):
        return np.array(self.rows, dtype=np.float64).reshape(-1, 4)


class Progress:
    """Prints where a running load step is, at most every ``interval`` seconds of wall time.

    A line names the load step (:meth:`start_step`), the inner solve of the step (a root find on the
    separation solves several problems in a row, each counting its iterations from 0, and a solve
    that is resumed to confirm its result is a second one), the iteration, the natural residual and
    the seconds since the step began::

          ... step 3 of 95 (pstar 0.02): inner solve 2, iteration 120, KKT natural 1.20e-05, 4.1 s

    Nothing is printed for a step shorter than ``interval`` (each step prints its own line when it ends).
    """

    def __init__(self, interval, stream):
        self.interval = interval
        self.stream = stream
        self.printed_at = -np.inf
        self.step = "the solve"
        self.step_started = time.perf_counter()
        self.inner = 0

    def start_step(self, index, count, kind, value):
        """A new load step: the ``index``-th (from 0) of ``count``, ``kind`` (pstar, pbar, gbar) = ``value``."""
        self.step = f"step {index + 1} of {count} ({kind} {value:g})"
        self.step_started = time.perf_counter()
        self.inner = 0

    def __call__(self, iteration, natural, seconds):
        if iteration == 0:  # every solve records its iteration 0 first
            self.inner += 1
        now = time.perf_counter()
        elapsed = now - self.step_started
        if elapsed >= self.interval and now - self.printed_at >= self.interval:
            self.printed_at = now
            print(f"  ... {self.step}: inner solve {max(self.inner, 1)}, iteration {iteration}, KKT natural "
                  f"{natural:.2e}, {elapsed:.1f} s", file=self.stream, flush=True)


# A TAO solve whose natural residual has not improved on its best for this many
# iterations is stopped (BQNLS can freeze at a fixed iterate without a verdict of its own).
STAGNATION_ITERATIONS = 500


class ConvergenceTest:
    """TAO convergence test on the natural KKT residual (``tao.setConvergenceTest``).

    TAO's default test runs first (petsc4py calls it before this one); with its
    gradient tolerances set to zero it only stops on iteration/evaluation
    limits or a failed line search. This test declares convergence when the
    natural residual of the current iterate is at most ``rtol``; a default
    "converged" verdict reached with a larger residual is turned back into
    "continue" while iterations remain, so TAO's own residual measure (which
    differs by type) never ends a solve early. It stops a solve with
    DIVERGED_USER after ``max_seconds`` (if > 0) or when the residual has not
    improved for ``STAGNATION_ITERATIONS`` iterations (``stopped_by`` says which).

    ``gap_of(x)`` returns the local gap array of the iterate ``x`` (cached by
    the objective when possible).
    """

    def __init__(self, comm, n_total, rtol, gap_of, history, target_pbar=None, max_seconds=0.0, best=None,
                 upper=None):
        self.comm = comm
        self.upper = upper  # the hardness cap (scaled), or None
        self.n_total = n_total
        self.rtol = rtol
        self.gap_of = gap_of
        self.history = history
        self.target_pbar = target_pbar
        self.max_seconds = max_seconds
        self.best_natural = np.inf
        self.best = best  # a Vec that receives the best iterate, or None
        self.since_best = 0
        self.iteration_offset = 0  # iterations of earlier TAO solves of the same problem (restarts)
        self.stopped_by = None  # "time limit" or "stagnation" when this test ended the solve

    def __call__(self, tao):
        x = tao.getSolution()
        kkt = report(self.comm, x.getArray(readonly=True), self.gap_of(x), self.n_total, self.target_pbar,
                     self.upper)
        iteration = tao.getIterationNumber()
        self.history.record(iteration + self.iteration_offset, kkt.natural)
        load_ok = kkt.load_error is None or kkt.load_error <= self.rtol
        if kkt.natural <= self.rtol and load_ok:
            self.best_natural = kkt.natural
            return PETSc.TAO.Reason.CONVERGED_USER
        if self.history.out_of_time(self.max_seconds):
            self.stopped_by = "time limit"
            return PETSc.TAO.Reason.DIVERGED_USER
        if merit(kkt) < self.best_natural:
            self.best_natural, self.since_best = merit(kkt), 0
            if self.best is not None:
                x.copy(self.best)
        else:
            self.since_best += 1
        if self.since_best >= STAGNATION_ITERATIONS:
            self.stopped_by = "stagnation"
            return PETSc.TAO.Reason.DIVERGED_USER
        if tao.getConvergedReason() > 0 and iteration < tao.getMaximumIterations():
            return PETSc.TAO.Reason.CONTINUE_ITERATING
        return None


class CompositeCriterion:
    """The dissertation's composite convergence criterion (3.47)-(3.51), evaluated per iteration as a TAO monitor.

    (3.47) ||p^k - p^(k-1)||_2 / ||p^k||_2 < 5e-5;
    (3.48) |A^k - A^(k-1)| / A^k < 2 / (Nx Ny);
    (3.51) sigma_h < min(1e-4 sqrt(m0^h), 0.01 gbar), sigma_h the rms gap over the contact
           nodes as in (3.50) (the mean over them; the dissertation's 1/N is read as 1/|contact set|).
    (3.49), monotone A* and gbar along a load path, involves two solves and is
    checked by the callers that have a path (ensembles).

    ``gap_of(x)`` returns the gap (scaled, local array) of the iterate ``x``.
    ``rows`` holds (iteration, (3.47) value, (3.48) value, sigma_h, its bound,
    natural residual or nan); ``first`` is the first iteration where (3.47),
    (3.48) and (3.51) all hold.
    """

    def __init__(self, comm, n_total, gap_of, natural_of=None):
        self.comm = comm
        self.n_total = n_total
        self.gap_of = gap_of
        self.natural_of = natural_of
        self.previous = None
        self.previous_area = None
        self.rows = []
        self.first = None

    def __call__(self, tao):
        x = tao.getSolution()
        p = x.getArray(readonly=True)
        g = self.gap_of(x)
        contact = p > 0
        if self.previous is None:
            self.previous, change2 = np.array(p), np.inf
        else:
            np.subtract(p, self.previous, out=self.previous)  # the change, in the buffer of the previous iterate
            change2 = np.dot(self.previous, self.previous)
        p_norm2, change2, n_contact, gap_sum, gap2_contact = allsum(self.comm, [
            np.dot(p, p), change2, np.count_nonzero(contact), g[~contact].sum(), np.dot(g[contact], g[contact])])
        area = n_contact / self.n_total
        relative_change = float(np.sqrt(change2 / p_norm2)) if p_norm2 > 0 else np.inf
        area_change = abs(area - self.previous_area) / area if self.previous_area is not None and area else np.inf
        sigma = float(np.sqrt(gap2_contact / n_contact)) if n_contact else 0.0
        bound = min(1e-4, 0.01 * gap_sum / self.n_total)
        iteration = tao.getIterationNumber()
        natural = self.natural_of(x, g) if self.natural_of else float("nan")
        self.rows.append((iteration, relative_change, area_change, sigma, bound, natural))
        if self.first is None and relative_change < 5e-5 and area_change < 2.0 / self.n_total and sigma < bound:
            self.first = iteration
        np.copyto(self.previous, p)
        self.previous_area = area
