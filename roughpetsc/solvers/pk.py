"""Polonsky-Keer as a solver backend (``pk``, ``none``, ``python``; the default): a TAO ``python`` object.

Along a load path it accepts the start's K p from the facade's predictor (``keeps_displacement``).
"""

import numpy as np

from .options import PARTS_UNUSED_BY_PYTHON_TAO, given_but_unusable, python_tao
from .polonsky_keer import PolonskyKeer
from .protocol import Backend, Guess, Outcome
from .registry import register
from .root_find import RootFind
from .stopping import describe_stop

NAMES = ("pk", "none", "python")
OPTIONS = [
    ("pk_pc", "fourier", "Polonsky-Keer preconditioner: fourier (inverse symbol pi E*|k| on the contact set) | none"),
    ("pk_active_set", "bccg", "Polonsky-Keer active set: bccg (overlapping nodes join the free set, Polak-Ribiere "
                              "without restarts) | pk (as published: nodes enter after the step, CG restarts)"),
    ("pk_refresh", 50, "Polonsky-Keer: recompute K p from scratch at least every this many iterations"),
    ("pk_split_radius", 0, "Polonsky-Keer: after a step the projection moved, add K of its corrections by a stencil "
                           "of this many nodes (32 measured best) and a coarse far field instead of a fresh K p "
                           "(0, the default: a fresh K p; periodic grids with square cells, bccg, no hardness cap)"),
    ("pk_split_coarsening", 4, "Polonsky-Keer: the split's far field is computed on a grid this many times coarser"),
    ("pk_split_transfer", "bilinear", "Polonsky-Keer: the split's far field is interpolated from its coarse grid by "
                                      "bilinear | cubic (4-point Lagrange: 3-5x more exact, fewer iterations at "
                                      "N = 8192 only, 1.5x the interpolation's time)"),
    ("pk_split_refresh", 1e-2, "Polonsky-Keer: with split corrections, K p is computed afresh each time the "
                               "residual falls by this factor"),
]


class PKBackend(Backend):
    """Polonsky-Keer (projected, preconditioned CG) as a TAO of type ``python`` (so -tao_monitor etc. work).

    Under displacement control also the inner solver of :class:`~roughpetsc.solvers.root_find.RootFind`.
    """

    keeps_displacement = True

    def __init__(self, problem, control, name, settings):
        self.problem = problem
        self.control = control
        self.context = PolonskyKeer(problem, settings.rule)
        self.prefix = settings.prefix
        self.max_seconds = settings.rule.max_seconds
        self.tao = python_tao(problem.comm, self.context, settings.prefix)

    @property
    def name(self):
        return f"pk({self.context.preconditioner})"

    @property
    def split_applications(self):
        return self.context.split_applications

    @property
    def separation(self):
        """The separation of the last solve (scaled)."""
        return self.context.separation

    def unusable_options(self):
        """Options given for parts this TAO never runs (line search, KSP, PC, other TAO types): reported unused."""
        return given_but_unusable(PARTS_UNUSED_BY_PYTHON_TAO, self.prefix)

    def solve(self, target, pressure, guess=None, history=None):
        """Solve for ``target`` from ``pressure`` (overwritten); ``history``, if given, receives the residuals too."""
        context = self.context
        guess = guess or Guess()
        if self.control == "load":
            context.target_pbar, context.target_separation = target, None
        else:
            context.target_pbar, context.target_separation = None, target
            local = self.problem.local(pressure)
            np.maximum(local, 0.0, out=local)
        context.initial_displacement, context.confirm = guess.displacement, guess.confirm
        try:
            self.tao.setSolution(pressure)
            self.tao.solve(pressure)
        finally:
            context.initial_displacement, context.confirm = None, True
        reason = describe_stop(self.tao.getConvergedReason(), context.watch, load_control=self.control == "load")
        if history is not None:
            history.extend(context.history.rows)
        return Outcome(context.separation, self.tao.getIterationNumber(), reason, context.history.as_array(),
                       confirmed=not context.unconfirmed)

    def destroy(self):
        self.tao.destroy()
        self.context.destroy()


class CappedPKLoad(Backend):
    """Load control under a hardness cap: PK's own load control, and the root find around PK if that fails.

    PK's rescaling stagnates when the capped nodes carry nearly all the load (measured: at a load error of 0.4
    on the Westergaard wave with H = 1.2 pbar); the root find then takes over from where it stopped.
    """

    def __init__(self, problem, control, name, settings):
        self.problem = problem
        self.direct = PKBackend(problem, "load", name, settings)
        try:
            inner = PKBackend(problem, "displacement", name, settings)
            self.fallback = RootFind(problem, "load", name, settings, inner=inner)
        except Exception:
            self.direct.destroy()
            raise

    @property
    def name(self):
        return self.direct.name

    @property
    def tao(self):
        return self.direct.tao

    def solve(self, target, pressure, guess):
        outcome = self.direct.solve(target, pressure, Guess(separation=guess.separation))
        if outcome.reason.startswith("CONVERGED"):
            return outcome
        found = self.fallback.solve(target, pressure, guess)
        return Outcome(found.separation, outcome.iterations + found.iterations,
                       f"{found.reason}; PK's own load control first stopped: {outcome.reason}",
                       np.concatenate([outcome.history, found.history]))

    def destroy(self):
        self.direct.destroy()
        self.fallback.destroy()


def make_pk(problem, control, name, settings):
    """PK for ``problem``: its own load control, or under a hardness cap :class:`CappedPKLoad`."""
    if control == "load" and problem.upper_bound is not None:
        return CappedPKLoad(problem, control, name, settings)
    return PKBackend(problem, control, name, settings)


register(NAMES, make_pk, options=OPTIONS)
