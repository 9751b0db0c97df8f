"""The solver facade: one backend for a problem, warm starts along loads, every result certified.

:class:`Solver` resolves the backend by name through :mod:`~roughpetsc.solvers.registry`, starts each
load-controlled solve from :class:`~roughpetsc.solvers.continuation.LoadContinuation`, and turns the
backend's :class:`~roughpetsc.solvers.protocol.Outcome` into a :class:`~roughpetsc.contact.Result`
checked on a gap computed afresh from the returned pressure (the natural KKT residual of
docs/conventions.md).
"""

import time

import numpy as np

from ..contact import Result, measure
from ..errors import ParameterError
from ..kkt import report
from .continuation import LoadContinuation
from .protocol import Guess, Outcome, quote_certificate
from .registry import make_backend


class Solver:
    """One contact solver for a problem, chosen by name; solves loads in order with warm starts.

    Parameters
    ----------
    problem : ContactProblem
    control : "load" or "displacement"
    tao_type : str or None
        A registered name (:func:`~roughpetsc.solvers.registry.backend_names`). None, "pk", "none" or
        "python": Polonsky-Keer (preconditioned by default, ``-pk_pc``) under load and displacement
        control; "almm": ALMM (load control only); a bound type: that TAO type (inside the root find
        under load control).
    rtol : float
        Stopping tolerance on the natural KKT residual (and the load error under load control).
    prefix : str or None
        Options prefix of the solver's TAO objects and of its own options (``-bound_pc``, ``-pk_pc``,
        ``-solve_max_time``, ...); None reads them unprefixed, as the command line gives them.

    Attributes
    ----------
    name : str
        The solver's name in results: the TAO type, ``rootfind(<type>)``, ``almm`` or ``pk(<pc>)``.
    backend :
        The backend object (:mod:`roughpetsc.solvers.protocol`).
    """

    def __init__(self, problem, control, tao_type, rtol, prefix=None):
        self.problem = problem
        self.control = control
        self.rtol = rtol
        self.backend = make_backend(problem, control, tao_type, rtol, prefix)
        self.name = self.backend.name
        keeps_displacement = control == "load" and getattr(self.backend, "keeps_displacement", False)
        self.path = LoadContinuation(problem, keeps_displacement)
        self.gap = problem.vec()
        self.last_separation = None

    @property
    def pressure(self):
        """The pressure Vec (scaled) of the last solve, and the start of the next."""
        return self.path.pressure

    @property
    def tao(self):
        """The backend's TAO object (the inner one of the root find): for monitors and views."""
        return self.backend.tao

    def unusable_options(self):
        """Options given that the backend read but cannot use (Polonsky-Keer has no line search or KSP)."""
        return getattr(self.backend, "unusable_options", list)()

    def solve(self, pbar=None, pstar=None, gbar=None):
        """Solve one load; the previous solution is the start. Returns a :class:`Result`.

        Give ``pbar`` (mean pressure) or ``pstar`` (= pbar / sqrt(m0^p)) under load control, ``gbar``
        (the mean gap, which is the rigid separation (3.38) of the dissertation) under displacement
        control.
        """
        problem = self.problem
        start = time.perf_counter()
        applications = problem.operator.applications
        if gbar is not None:
            if not gbar > 0:
                raise ParameterError("gbar", f"the mean gap must be positive (complete contact has zero mean "
                                             f"gap), got {gbar}")
            target = None
            outcome = self.backend.solve(gbar / problem.height_scale, self.pressure, Guess())
        elif pbar is None and pstar is None:
            raise ParameterError("pbar", "give the load: pbar or pstar (load control), or gbar (displacement control)")
        else:
            target = problem.scaled_pbar(pbar, pstar)
            if not target > 0:
                raise ParameterError("pbar" if pstar is None else "pstar",
                                     f"the load must be positive, got {pbar if pstar is None else pstar}")
            if problem.upper_bound is not None and target >= problem.upper_bound:
                raise ParameterError("pbar" if pstar is None else "pstar",
                                     "the mean pressure must stay below the hardness, which caps every pressure")
            if problem.complete_contact_exact(target):
                outcome = self._complete_contact(target)
            else:
                displacement = self.load_start(target)
                # The facade certifies every result on a fresh gap, so the backend need not confirm.
                guess = Guess(separation=self.last_separation, displacement=displacement, confirm=False)
                outcome = self.backend.solve(target, self.pressure, guess)
        self.last_separation = outcome.separation
        result = self._result(outcome, target, start, applications)
        if not outcome.confirmed and not result.converged:
            # The backend stopped on its updated gap and the fresh one disagrees: resume, confirming this time.
            resumed = self.backend.solve(target, self.pressure, Guess(separation=outcome.separation))
            outcome = Outcome(resumed.separation, outcome.iterations + resumed.iterations, resumed.reason,
                              np.concatenate([outcome.history, resumed.history]))
            self.last_separation = outcome.separation
            result = self._result(outcome, target, start, applications)
        self.path.record(target, outcome.separation, self.gap)
        return result

    def load_start(self, target):
        """Put the start of a load-controlled solve at ``target`` (scaled) in :attr:`pressure`; its K p or None.

        The load-path predictor of :class:`~roughpetsc.solvers.continuation.LoadContinuation`; a
        subclass may replace it (studies/load_path_recycling.py tries reduced-basis predictors).
        """
        return self.path.start(target)

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
        kkt = report(problem.mpi, p, g, problem.n, target, problem.upper_bound)
        measures = measure(problem, p, g)
        converged = kkt.natural <= self.rtol and (kkt.load_error is None or kkt.load_error <= self.rtol)
        reason = outcome.reason if converged else quote_certificate(outcome.reason, kkt)
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
            control=self.control, history=outcome.history, A_plastic=measures["A_plastic"])

    def fields(self):
        """This rank's rows of the pressure and gap of the last solve, in pressure and length units."""
        problem = self.problem
        return (problem.local(self.pressure, readonly=True) * problem.pressure_scale,
                problem.local(self.gap, readonly=True) * problem.height_scale)

    def destroy(self):
        self.backend.destroy()
        self.path.destroy()
        self.gap.destroy()
