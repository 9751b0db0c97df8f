"""What every solver backend of the contact QP offers the :class:`~roughpetsc.solvers.solver.Solver` facade.

A backend solves the scaled QP of :class:`~roughpetsc.contact.ContactProblem` (the contact problem
(3.41)-(3.44) of the dissertation) for one target:

``solve(target, pressure, guess) -> Outcome``
    ``target`` is the scaled mean pressure under load control or the scaled rigid separation under
    displacement control; ``pressure`` is the Vec the backend updates in place (it holds the start);
    ``guess`` (:class:`Guess`) is what the facade knows about the start, which a backend may use or ignore.
``destroy()``, ``name`` (the solver's name in results), ``tao`` (its TAO object, for monitors).

Optional behaviour is an attribute with a default here, never a type check in the facade:
``keeps_displacement`` asks the facade to keep K p of its solutions along a load path, so that
:class:`Guess` can carry K p of the next start; an :class:`Outcome` with ``confirmed=False`` (allowed
by ``Guess.confirm=False``) asks the facade to solve again with ``Guess(confirm=True)`` when its
certificate on a fresh gap fails (the resume of Polonsky-Keer along a load path).
"""

from dataclasses import dataclass

import re

import numpy as np
from petsc4py import PETSc


@dataclass
class Outcome:
    """What a backend reports besides the pressure it leaves in its Vec.

    Attributes
    ----------
    separation : float
        The rigid separation d of the solution (scaled by sqrt(m0^h)).
    iterations : int
    reason : str
        PETSc's converged reason, with notes (:func:`describe_stop`).
    history : ndarray (k, 4)
        Iteration, natural residual, operator applications, seconds (:class:`~roughpetsc.kkt.History`).
    confirmed : bool
        False when the backend stopped on an updated gap without a freshly computed one (allowed by
        ``Guess.confirm = False``): if the facade's certificate then fails, it solves again with
        ``confirm = True``.
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
        K p of the start, when the load-path predictor knows it (the backend may skip one operator
        application); only offered to backends with ``keeps_displacement``.
    confirm : bool
        True: the backend confirms its convergence on a freshly computed gap. False: it may stop on an
        updated gap, because the facade certifies every result on a fresh gap anyway.
    """

    separation: float = None
    displacement: object = None
    confirm: bool = True


@dataclass(frozen=True)
class BackendSettings:
    """What every backend is built with besides the problem and its control.

    rtol : float
        Stopping tolerance on the natural KKT residual (and the load error under load control).
    prefix : str or None
        Options prefix of the backend's TAO objects (None: unprefixed options).
    max_seconds : float
        Seconds after which a solve stops with DIVERGED_USER (0: no limit).
    """

    rtol: float
    prefix: str = None
    max_seconds: float = 0.0


class Backend:
    """The defaults of the optional parts of the backend protocol; backends may derive from it.

    A backend needs ``solve``, ``destroy``, ``name`` and ``tao``; ``keeps_displacement`` defaults to False.
    """

    keeps_displacement = False

    def solve(self, target, pressure, guess):
        raise NotImplementedError

    def destroy(self):
        raise NotImplementedError


def reason_name(reason):
    """PETSc's name of a TAO converged reason."""
    for name, value in vars(PETSc.TAO.Reason).items():
        if not name.startswith("_") and value == reason and name not in ("ITERATING", "CONVERGED_ITERATING"):
            return name
    return str(reason)


# The note of describe_stop that quotes the residual of the solver's best iterate.
BEST_NOTE = re.compile(r"best (of natural residual, load error|natural residual) [^,)]+")


def quote_certificate(reason, kkt):
    """``reason`` with its residual note quoting the result as certified (:class:`~roughpetsc.kkt.KKTReport`).

    A solver's own best residual (ALMM's merit, on its cached gap, of an iterate it may not return) can
    differ from the certificate of the result, which the output files record: a stop reason quotes the
    latter, so that the line and the files give the same numbers.
    """
    measured = f"natural residual {kkt.natural:.2g}"
    if kkt.load_error is not None:
        measured += f", load error {kkt.load_error:.2g}"
    return BEST_NOTE.sub(measured, reason, count=1)


def describe_stop(tao, test, restarts=0):
    """PETSc's reason, with what our convergence test stopped for (time limit, stagnation) and the floor.

    ``test`` is a :class:`~roughpetsc.kkt.ConvergenceTest` or the Polonsky-Keer context (both have
    ``stopped_by`` and ``best_natural``). A solve that ends short of the tolerance says which natural
    residual it reached (and, after restarts, that this is the floor that restarting could not
    lower), so a bare DIVERGED_LS_FAILURE is never the whole story.
    """
    name = reason_name(tao.getConvergedReason())
    notes = [test.stopped_by] if test.stopped_by and name == "DIVERGED_USER" else []
    if tao.getConvergedReason() < 0 and np.isfinite(test.best_natural):
        load_control = getattr(test, "target_pbar", None) is not None
        measure = "of natural residual, load error" if load_control else "natural residual"
        notes.append(f"best {measure} {test.best_natural:.2g}")
        if restarts:
            notes.append(f"floor after {restarts} restart{'s' * (restarts > 1)}")
    return f"{name} ({', '.join(notes)})" if notes else name
