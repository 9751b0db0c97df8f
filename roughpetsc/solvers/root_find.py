"""Load control by a safeguarded root find on the rigid separation around the displacement-controlled QP (3.41)-(3.44).

Used by the bound types with ``-bound_load rootfind`` and by Polonsky-Keer under a hardness cap.
"""

import math

import numpy as np

from .stopping import History
from ..contact.certificate import report
from .bound_qp import BoundQP
from .protocol import Backend, Outcome


class RootFind(Backend):
    """Load control by a safeguarded root find on the separation around :class:`BoundQP`.

    The mean pressure P(d) decreases from the complete-contact pressure at d -> 0+ to 0 at d = max(h), so
    [0, max h] brackets the root; Brent's method (scipy) narrows it until |P(d) - pbar| / pbar <= rtol. If the
    bracket reaches round-off in d first (near complete contact), the solution being affine in d while the
    contact set stays, the closest solutions either side are interpolated to the load.

    ``inner``: the displacement-controlled solver to drive instead of a BoundQP of ``tao_type`` (with
    BoundQP's ``solve(..., history=)``, ``separation``, ``max_seconds``, ``name``, ``tao``, ``destroy``).
    """

    def __init__(self, problem, control, tao_type, settings, max_evaluations=100, inner=None):
        self.qp = inner or BoundQP(problem, "displacement", tao_type, settings)
        self.problem = problem
        self.rtol = settings.rule.rtol
        self.max_evaluations = max_evaluations
        self.name = f"rootfind({self.qp.name})"
        self.bracket = {"above": problem.vec(), "below": problem.vec()}  # solutions either side of the load
        self.trial, self.gap = problem.vec(), problem.vec()

    @property
    def tao(self):
        return self.qp.tao

    def unusable_options(self):
        """Those of the displacement-controlled solver it drives, but -bound_load, which chose this method."""
        return [name for name in self.qp.unusable_options() if not name.endswith("bound_load")]

    def solve(self, pbar, pressure, guess):
        """Solve for the mean pressure ``pbar`` (scaled); ``guess.separation`` is tried first if inside the bracket."""
        from scipy.optimize import brentq

        separation_guess = guess.separation
        problem = self.problem
        history = History(problem)
        state = {"iterations": 0, "evaluations": 0, "inner": "", "stop": None, "separation": None}

        class Found(Exception):
            pass

        # Periodic and uncapped, d <= 0 is complete contact, whose load is known; otherwise it is solved.
        closed_at_zero = math.isfinite(problem.complete_contact_pbar) and problem.upper_bound is None

        def excess(d):
            if d <= 0.0 and closed_at_zero:
                return problem.complete_contact_pbar - pbar
            if d >= problem.max_height:
                return -pbar
            outcome = self.qp.solve(d, pressure, history=history)
            state["iterations"] += outcome.iterations
            state["evaluations"] += 1
            state["inner"], state["separation"] = outcome.reason, d
            mean_p = pressure.sum() / problem.n
            side = "above" if mean_p > pbar else "below"  # the closest solutions on each side of the load
            pressure.copy(self.bracket[side])
            state[side] = (d, mean_p)
            inner_solved = outcome.reason.startswith("CONVERGED")
            if abs(mean_p - pbar) <= self.rtol * pbar and inner_solved:
                raise Found
            # The time limit before the load: an inner solve cut short at its start keeps the start's mean
            # pressure, which may be the load itself.
            if history.out_of_time(self.qp.max_seconds):
                state["stop"] = "DIVERGED_USER"
                raise Found
            if abs(mean_p - pbar) <= self.rtol * pbar:
                state["stop"] = "DIVERGED_ROOT_INNER"  # the load is met, the inner QP is not solved
                raise Found
            if state["evaluations"] >= self.max_evaluations:
                state["stop"] = "DIVERGED_ROOT_MAXFCN"
                raise Found
            return mean_p - pbar

        lower, upper = 0.0, problem.max_height
        try:
            if not closed_at_zero:
                # A free boundary or a hardness cap: the load at d = 0 is not known in closed form (under
                # a cap it may fall short of pbar); widen the bracket downwards until it exceeds pbar.
                while excess(lower) < 0:
                    lower -= upper - lower
            if separation_guess is not None and lower < separation_guess < upper:
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
        return Outcome(state["separation"], state["iterations"], self._reason(state, interpolated, load_error),
                       history.as_array())

    @staticmethod
    def _reason(state, interpolated, load_error):
        """CONVERGED_ROOT or why the search stopped, with the inner solves and the load error reached."""
        if interpolated:
            return (f"CONVERGED_ROOT ({state['evaluations']} inner solves; the bracket on d reached round-off, "
                    "the solutions either side of the load interpolated to it)")
        if state["stop"] is None:
            return f"CONVERGED_ROOT ({state['evaluations']} inner solves)"
        notes = [f"{state['evaluations']} inner solves", f"load error {load_error:.2g}"]
        if state["stop"] == "DIVERGED_USER":
            notes.insert(0, "time limit")
        if not state["inner"].startswith("CONVERGED"):
            notes.append(f"last inner solve: {state['inner']}")
        return f"{state['stop']} ({', '.join(notes)})"

    def _interpolate(self, pbar, pressure, state):
        """Replace ``pressure`` by the interpolation to the load of the solutions either side of it, if that
        meets the tolerance on a fresh gap (then True)."""
        problem = self.problem
        (d_above, mean_above), (d_below, mean_below) = state["above"], state["below"]
        t = (pbar - mean_below) / (mean_above - mean_below)
        separation = d_below + t * (d_above - d_below)
        above, below = self.bracket["above"], self.bracket["below"]
        self.trial.waxpy(-1.0, below, above)  # p_above - p_below
        self.trial.aypx(t, below)             # p_below + t (p_above - p_below)
        local = problem.local(self.trial)
        np.maximum(local, 0.0, out=local)
        if problem.upper_bound is not None:
            np.minimum(local, problem.upper_bound, out=local)
        problem.gap(self.trial, separation, self.gap)
        kkt = report(problem.mpi, local, problem.local(self.gap, readonly=True), problem.n, pbar,
                     problem.upper_bound)
        if not (kkt.natural <= self.rtol and kkt.load_error <= self.rtol):
            return False
        self.trial.copy(pressure)
        state["separation"] = separation
        return True

    def destroy(self):
        self.qp.destroy()
        for v in (*self.bracket.values(), self.trial, self.gap):
            v.destroy()

