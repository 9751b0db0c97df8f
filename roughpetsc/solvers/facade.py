"""The solver facade: one backend for a problem of any kind, warm starts along loads, every result certified."""

import time

import numpy as np

from ..errors import ParameterError
from .cascade import make_cascade
from .options import SolverOptions
from .protocol import BackendSettings, Guess, Outcome
from .registry import make_backend
from .stopping import StoppingRule, max_seconds


class Solver:
    """One solver for a problem, chosen by name; solves loads in order with warm starts.

    Parameters
    ----------
    problem : ContactProblem or AdhesiveProblem
    control : "load" or "displacement"
    tao_type : str or None
        A registered name for the problem's kind (:func:`~roughpetsc.solvers.registry.backend_names`);
        None reads ``-tao_type`` under ``prefix``, and without one the kind's default (``pk``, ``gapcg``).
    rtol : float
        Stopping tolerance on the natural KKT residual (and the error of the prescribed load or mean gap).
    prefix : str or None
        Options prefix of the solver's TAO objects and of its own options; None: unprefixed.
    options : dict or None
        Options for this solver alone (``{"tao_type": "bqnls", "tao_max_it": 500}``, names without dash or
        prefix), set under the prefix while the solver lives. An option given here that nothing reads is an error.

    Attributes
    ----------
    name : str
        The solver's name in results: the TAO type, ``<type>(al)``, ``rootfind(<type>)``, ``almm``, ``pk(<pc>)``,
        ``gapcg``.
    """

    def __init__(self, problem, control, tao_type=None, rtol=1e-8, prefix=None, options=None):
        if control not in problem.controls:
            raise ParameterError("control", f"the {problem.kind} problem is solved under "
                                            f"{' or '.join(problem.controls)} control, not {control}")
        self.problem = problem
        self.control = control
        self.rtol = rtol
        self.options = SolverOptions(prefix, options)
        try:
            prefix = self.options.prefix
            if tao_type is None:
                tao_type = self.options.get("tao_type") or None
            settings = BackendSettings(StoppingRule(rtol, max_seconds(prefix)), prefix)
            self.backend = make_backend(problem, control, tao_type, settings)
        except BaseException:
            self.options.destroy()
            raise
        self.name = self.backend.name
        keeps_displacement = control == "load" and self.backend.keeps_displacement
        self.path = problem.continuation(keeps_displacement)
        try:
            self.cascade = make_cascade(problem, control, self.options.prefix)
        except BaseException:
            self.destroy()
            raise
        if self.cascade is not None:
            self.path.cold_start = self.cascade
        self.work = problem.vec()  # the certificate's gradient: the gap (contact), S (g + h) (adhesive)
        self.last = None
        unused = self.options.unused()
        if unused:
            self.destroy()
            raise ParameterError("options", f"option(s) not used by the solver {self.name}: "
                                            + ", ".join(unused))

    @property
    def unknown(self):
        """The unknown Vec (scaled) of the last solve, and the start of the next."""
        return self.path.unknown

    # The contact problem's unknown is the pressure.
    pressure = unknown

    @property
    def tao(self):
        """The backend's TAO object: for monitors and views."""
        return self.backend.tao

    def split_applications(self):
        """The backend's coarse FFT pairs so far (an optional attribute of the protocol: 0 if it has none)."""
        return getattr(self.backend, "split_applications", 0.0)

    def unusable_options(self):
        """Options given that the backend read but cannot use (Polonsky-Keer has no line search or KSP)."""
        return self.backend.unusable_options()

    def solve(self, pbar=None, pstar=None, gbar=None, start=None):
        """Solve one load; the previous solution is the start. Returns a :class:`~roughpetsc.contact.Result`.

        Give ``pbar`` or ``pstar`` (= pbar / sqrt(m0^p)) under load control, ``gbar`` (the mean gap, the rigid
        separation (3.38)) under displacement control. ``start`` names another start (the continuation's).
        """
        problem = self.problem
        started = time.perf_counter()
        applications = problem.operator.applications
        split_applications = self.split_applications()
        control = "displacement" if gbar is not None else ("load" if (pbar, pstar) != (None, None) else self.control)
        if control != self.control:
            given = "gbar" if gbar is not None else ("pstar" if pstar is not None else "pbar")
            raise ParameterError(given, f"this solver was made for {self.control} control; {given} prescribes "
                                        f"{control} control")
        target = problem.target(control, pbar=pbar, pstar=pstar, gbar=gbar)
        outcome = problem.exact(target, control, self.path.unknown)
        if outcome is None:
            guess = self.path.start(control, target, start)  # may swap the unknown's Vec (the predictor's)
            outcome = self.backend.solve(target, self.path.unknown, guess)
        result = self._certify(outcome, target, started, applications)
        if not outcome.confirmed and not result.converged:
            # The backend stopped on its updated gradient and the fresh one disagrees: resume, confirming this time.
            resumed = self.backend.solve(target, self.path.unknown, Guess(separation=outcome.separation))
            outcome = Outcome(resumed.separation, outcome.iterations + resumed.iterations, resumed.reason,
                              np.concatenate([outcome.history, resumed.history]))
            result = self._certify(outcome, target, started, applications)
        result.split_applications = self.split_applications() - split_applications
        if self.cascade is not None:
            result.cascade_applications = self.cascade.take_pairs()
        self.path.record(control, target, outcome, self.work)
        self.last = result
        return result

    def _certify(self, outcome, target, started, applications):
        return self.problem.certify(self.path.unknown, self.work, outcome, target, self.control, self.rtol, self.name,
                                    started, applications)

    def fields(self):
        """This rank's rows of the pressure and gap of the last solve, in pressure and length units."""
        return self.problem.fields(self.path.unknown, self.work, self.last)

    def resume(self, gap):
        """Start the next solve from ``gap``: this rank's rows in length units, as :meth:`fields` returns them
        (an adhesive path taken up again from a checkpoint). A pressure path restarts from its loads instead."""
        if not hasattr(self.path, "resume"):
            raise ParameterError("resume", f"a {self.problem.kind} path is not resumed from a gap field; only an "
                                           "adhesive path is")
        gap = np.asarray(gap, dtype=float)
        local_shape = self.problem.local(self.path.unknown, readonly=True).shape
        if gap.shape != local_shape:
            raise ParameterError("resume", f"the gap has shape {gap.shape}, this rank's rows {local_shape}")
        self.path.resume(gap / self.problem.height_scale)

    def destroy(self):
        for part in ("backend", "path"):
            if hasattr(self, part):
                getattr(self, part).destroy()
        if hasattr(self, "work"):
            self.work.destroy()
        self.options.destroy()
