"""The warm starts of a path: the unknown of a problem and the start of each solve from the previous solutions.

:class:`PressureContinuation` (pressure as the unknown) and :class:`GapContinuation` (adhesive, gap as the
unknown) follow the continuation protocol of :mod:`roughpetsc.solvers.protocol`.
"""

import numpy as np
from petsc4py import PETSc

from ..errors import ParameterError
from ..parallel import allsum


class PressureContinuation:
    """The pressure Vec a :class:`~roughpetsc.solvers.solver.Solver` solves in, and what predicts its starts.

    Parameters
    ----------
    problem : ContactProblem
    keeps_displacement : bool
        Keep K p of the solutions, so that :meth:`start` also returns K p of the start.

    Attributes
    ----------
    unknown, pressure : petsc4py.PETSc.Vec
        The current pressure (scaled): the start before a solve, the solution after it.
    previous : petsc4py.PETSc.Vec or None
        The solution before the last (load paths only).
    targets : list of float
        Scaled loads of the solutions in (previous, pressure).
    cold_start : callable or None
        ``cold_start(target, pressure)`` puts the start of a cold load-controlled solve (no solution before it)
        in ``pressure`` (any mean): the cascade of :mod:`roughpetsc.solvers.cascade`. None: the uniform load.
    """

    def __init__(self, problem, keeps_displacement):
        self.problem = problem
        self.keeps_displacement = keeps_displacement
        self.pressure = problem.vec()
        self.pressure.set(0.0)
        self.previous = None
        self.targets = []
        # K p of the solutions in targets, K p of the start, every Vec made for them.
        self.displacements, self.start_displacement, self.pool = [], None, []
        self.last_separation = None
        self.cold_start = None

    @property
    def unknown(self):
        return self.pressure

    def start(self, control, target, start=None):
        """Put the start of a solve at ``target`` in :attr:`unknown`; the :class:`Guess` of the backend.

        Load control: the load-path predictor (:meth:`load_start`), unconfirmed (every result is certified
        afresh); displacement control: the previous solution. ``start='uniform'``: the uniform load.
        """
        from ..solvers.protocol import Guess

        if start not in (None, "uniform"):
            raise ParameterError("start", f"the start of the contact problem is 'uniform' or the previous solution, "
                                          f"got '{start}'")
        if start == "uniform":
            self.targets, self.displacements = [], []
            self.pressure.set(0.0)
        if control == "displacement":
            return Guess()
        displacement = self.load_start(target, use_cold_start=start != "uniform")
        return Guess(separation=self.last_separation, displacement=displacement, confirm=False)

    def load_start(self, target, use_cold_start=True):
        """Put the start of a load-controlled solve at ``target`` in :attr:`pressure`; its K p if known.

        After two load-controlled solves, linear extrapolation in the load (step ratio capped at 2), projected
        onto p >= 0; after one, that solution; with none, the pressure put there (a resumed path's), or else
        :attr:`cold_start`'s (if set and ``use_cold_start``), else uniform; then scaled to the new mean pressure.
        Returns K p of the start when the kept K p of the previous solutions give it exactly (one FFT pair
        saved per step), else None. Higher-order predictors started no closer (studies/load_history.py).
        """
        displacements = self.displacements
        known = self.keeps_displacement and len(displacements) == len(self.targets)
        if known and self.start_displacement is None:
            self.start_displacement = self.problem.vec()
            self.pool.append(self.start_displacement)
        if self.targets and self.previous is None:
            self.previous = self.problem.vec()
        if len(self.targets) == 2:
            older, newer = self.targets
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
                    displacements[1].copy(self.start_displacement)
                    self.start_displacement.scale(1.0 + ratio)
                    self.start_displacement.axpy(-ratio, displacements[0])
            elif known:
                displacements[1].copy(self.start_displacement)
        elif self.targets:
            self.pressure.copy(self.previous)
            if known:
                displacements[0].copy(self.start_displacement)
        elif self.pressure.norm(PETSc.NormType.INFINITY) > 0:
            known = False  # a start put in the pressure (a resumed path): its K p is computed by the backend
        elif use_cold_start and self.cold_start is not None:
            self.cold_start(target, self.pressure)
            known = False
        elif known:
            self.start_displacement.set(0.0)
        mean_p = self.pressure.sum() / self.problem.n
        if mean_p > 0:
            self.pressure.scale(target / mean_p)
            if known:
                self.start_displacement.scale(target / mean_p)
        else:
            self.pressure.set(target)
            if known:
                self.start_displacement.set(0.0)
        return self.start_displacement if known else None

    def record(self, control, target, outcome, gap):
        """Remember the certified solution at ``target`` and its separation; with ``keeps_displacement`` (load
        control) also K p = g - d + h of its fresh ``gap``."""
        self.last_separation = separation = outcome.separation
        target = target if control == "load" else None
        self.targets = (self.targets + [target])[-2:] if target is not None else []
        if target is None or not self.keeps_displacement:
            self.displacements = []
            return
        if len(self.displacements) == 2:
            kept = self.displacements.pop(0)
        else:
            kept = self.problem.vec()
            self.pool.append(kept)
        kept.waxpy(1.0, self.problem.heights, gap)
        kept.shift(-separation)
        self.displacements.append(kept)

    def destroy(self):
        self.pressure.destroy()
        if self.previous is not None:
            self.previous.destroy()
        for v in self.pool:
            v.destroy()


class GapContinuation:
    """The gap of an adhesive problem and its starts along a path of mean gaps.

    The first solve starts from the rigid gap gbar - h, later ones from the previous gap shifted by the change
    of gbar (the solver projects onto g >= 0, mean gbar). Along a retraction keep each step below the law's
    range, or the path snaps off early. ``start="rigid"`` or ``"uniform"`` (g = gbar, Tamaas' start) forces a
    start: the local minimum of the non-convex problem depends on it.
    """

    STARTS = (None, "rigid", "uniform")

    def __init__(self, problem):
        self.problem = problem
        self.unknown = problem.vec()
        self.started = False

    def start(self, control, target, start=None):
        from ..solvers.protocol import Guess

        if start not in self.STARTS:
            raise ParameterError("start", f"the start is 'rigid' or 'uniform', got '{start}'")
        problem = self.problem
        g = problem.local(self.unknown)
        if start == "uniform":
            g[...] = target
        elif start == "rigid" or not self.started:
            g[...] = target - problem.local(problem.heights, readonly=True)
        else:
            current, = allsum(problem.mpi, [g.sum()])
            g += target - current / problem.n
        self.started = True
        return Guess()

    def resume(self, gap):
        """Start the next solve from ``gap`` (this rank's rows, scaled): a path taken up again from a checkpoint.
        The solver shifts it to the next mean gap, as it shifts its own last solution."""
        self.problem.local(self.unknown)[...] = gap
        self.started = True

    def record(self, control, target, outcome, work):
        """Nothing to remember: the gap itself is the next start."""

    def destroy(self):
        self.unknown.destroy()
