"""The two protocols of the solver layer (docs/solvers.md): what a problem offers, what a backend offers."""

from dataclasses import dataclass

import numpy as np

from .stopping import StoppingRule


@dataclass
class Outcome:
    """What a backend reports besides the unknown it leaves in its Vec.

    Attributes
    ----------
    separation : float
        The rigid separation d of the solution (scaled by sqrt(m0^h)); the mean gap of an adhesive one.
    iterations : int
    reason : str
        PETSc's converged reason, with notes (:func:`~roughpetsc.solvers.stopping.describe_stop`).
    history : ndarray (k, 4)
        Iteration, natural residual, operator applications, seconds (:class:`~roughpetsc.solvers.stopping.History`).
    confirmed : bool
        False when the backend stopped on an updated gradient (``Guess.confirm = False``): if the
        certificate fails, the facade solves again with ``confirm = True``.
    """

    separation: float
    iterations: int
    reason: str
    history: np.ndarray
    confirmed: bool = True


@dataclass(frozen=True)
class Guess:
    """What the facade knows about the start of a solve.

    Attributes
    ----------
    separation : float or None
        The separation of the previous solution (scaled), a first guess for a root find on d.
    displacement : petsc4py.PETSc.Vec or None
        K p of the start, when the load-path predictor knows it (backends with ``keeps_displacement``).
    confirm : bool
        Whether the backend confirms its convergence on a freshly computed gradient.
    """

    separation: float = None
    displacement: object = None
    confirm: bool = True


@dataclass(frozen=True)
class BackendSettings:
    """What every backend is built with besides the problem and its control.

    rule : StoppingRule
    prefix : str or None
        Options prefix of the backend's TAO objects and its own options (None: unprefixed options).
    """

    rule: StoppingRule
    prefix: str = None


class Backend:
    """The defaults of the optional parts of the backend protocol; backends may derive from it."""

    keeps_displacement = False
    split_applications = 0.0  # coarse FFT pairs so far beside the problem operator's, in its pairs (cumulative)

    def solve(self, target, unknown, guess):
        raise NotImplementedError

    def destroy(self):
        raise NotImplementedError

    def unusable_options(self):
        return []

