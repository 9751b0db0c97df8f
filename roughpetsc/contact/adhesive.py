"""Adhesive contact of a rough surface and a rigid flat in the periodic BEM, the gap as the unknown.

With an interaction law phi (:mod:`roughpetsc.interaction`) the total energy per unit area of a gap
field g >= 0 at the mean gap gbar (the rigid separation, (3.38)) is

    Pi(g) = 1/2 <g + h, S (g + h)> + <phi(g)>,

``<.>`` the mean over the nodes and ``S`` the stiffness (the inverse symbol pi E* |k| of the Westergaard
compliance (3.33), zero at k = 0): the surface displacement is u = g - gbar + h and S kills constants.
The gap is bound-constrained, the mean gap the one equality: adhesive contact jumps in and out of contact
under load control, so paths run under displacement control and the load is an output.

First-order conditions, with r = S (g + h) + phi'(g) and a multiplier lambda = -pbar (compressive positive):
out of contact (g > 0) r = lambda, the total pressure S(g + h) + pbar equals the law's traction -phi'(g);
in contact (g = 0) the contact pressure c = r - lambda >= 0.

The certified natural residual is ``max |min(g / sqrt(m0^h), (r - lambda) / sqrt(m0^p))|`` on a fresh S g,
lambda the mean of r out of contact, sqrt(m0^p) (2.52) that of the non-adhesive problem (the mean pressure
may be zero or tensile here). ``load_error`` is the mean gap's error over sqrt(m0^h).

Periodic boundary only (the free boundary's stiffness is not a Fourier filter). Solved by ``gapcg`` and
``almm`` through the :class:`~roughpetsc.solvers.Solver` facade.
"""

import math
import time

import numpy as np

from ..errors import ParameterError
from ..parallel import allmax, allmin, allsum
from . import loops
from .certificate import KKTReport, certified
from .curvature import TOLERANCE as CURVATURE_TOLERANCE, least_curvature, longest_wave_stiffness
from .result import Result, measure


class AdhesiveProblem:
    """A :class:`~roughpetsc.contact.ContactProblem` with an adhesive law, its unknown the gap.

    Parameters
    ----------
    problem : ContactProblem
        Periodic, without a hardness cap; it stays the caller's to destroy.
    law : laws.Dugdale or laws.Exponential
        In the problem's units (pressure units of E*, length units of the heights).

    ``kind`` is ``"adhesive"`` (:mod:`roughpetsc.solvers.registry`); ``controls`` displacement control only.
    """

    kind = "adhesive"
    controls = ("displacement",)

    def __init__(self, problem, law):
        if problem.boundary != "periodic":
            raise ParameterError("boundary", "adhesion is solved on the periodic cell only")
        if problem.upper_bound is not None:
            raise ParameterError("hardness", "adhesion and a hardness cap cannot be combined yet")
        self.elastic_problem = problem
        self.law = law
        self.scaled_law = law.scaled(problem.height_scale, problem.pressure_scale)
        # The pressure scale of the residual: sqrt(m0^p) (2.52) of the non-adhesive problem, scaled units.
        self.residual_scale = math.sqrt(problem.m0p_scaled)
        self.check_curvature = True  # the second-order half of the certificate (:mod:`.curvature`)
        self.longest_wave_stiffness = None
        self.least_mode = None  # the last eigenvector of least curvature: the next one's start along a path
        self.progress = None        # as ContactProblem's: the command line's progress line, Ctrl-C
        self.stop_requested = None

    # --- what every problem offers the solvers (roughpetsc.solvers.protocol) ---------
    def __getattr__(self, name):
        # The layout, units and surface of the elastic problem are this problem's too.
        if name == "elastic_problem":
            raise AttributeError(name)
        return getattr(self.elastic_problem, name)

    def target(self, control, pbar=None, pstar=None, gbar=None):
        """The scaled mean gap of ``gbar`` (length units); a load is refused (displacement control only)."""
        if gbar is None:
            raise ParameterError("pbar" if pstar is None else "pstar",
                                 "adhesive contact is solved under displacement control: prescribe the mean "
                                 "gap (the load jumps where contact snaps in or out)")
        if not (gbar > 0 and math.isfinite(gbar)):
            raise ParameterError("gbar", f"the mean gap must be positive and finite, got {gbar}")
        return gbar / self.height_scale

    def continuation(self, keeps_displacement=False):
        """The gap and its starts along a path (:class:`~roughpetsc.contact.continuation.GapContinuation`)."""
        from .continuation import GapContinuation

        return GapContinuation(self)

    def exact(self, target, control, unknown):
        """No closed-form answer: every gap is solved."""
        return None

    # --- the energy and its gradient ------------------------------------------
    def elastic_pressure(self, gap_vec, out):
        """``out = S (g + h)``: the elastic pressure less its mean (one operator application)."""
        self.operator.elastic_pressure(gap_vec, out)
        out.axpy(1.0, self.pressure_surface)

    def gradient(self, g, elastic, out):
        """``out = r = S (g + h) + phi'(g)`` of local arrays ``g`` and ``elastic`` = S (g + h)."""
        self.scaled_law.force(g, out=out)
        out += elastic

    def multiplier(self, g, r, open_nodes):
        """``(lambda, count)``: the mean of r over the ``count`` nodes out of contact, marked in ``open_nodes``."""
        count, r_sum = allsum(self.mpi, loops.open_sums(g.ravel(), r.ravel(), open_nodes.reshape(-1)))
        return (r_sum / count if count else 0.0), count

    def natural(self, g, r, lam):
        """The natural residual max |min(g, (r - lambda) / sqrt(m0^p))| (scaled gaps)."""
        return float(allmax(self.mpi, [loops.gap_natural(g.ravel(), r.ravel(), lam, self.residual_scale)])[0])

    def stationarity(self, g, elastic):
        """``(r, lambda, report)`` of local arrays ``g`` and ``elastic`` = S (g + h).

        ``min_p``: the least r - lambda in contact; ``complementarity``: mean g |r - lambda| out of contact.
        """
        r = np.empty_like(g)
        self.gradient(g, elastic, r)
        out_of_contact = np.empty(g.shape, dtype=bool)
        lam, _ = self.multiplier(g, r, out_of_contact)
        natural = self.natural(g, r, lam)
        excess = (r - lam) / self.residual_scale
        min_c = np.min(excess, where=~out_of_contact, initial=np.inf)
        equilibrium = np.abs(excess, where=out_of_contact, out=np.zeros_like(excess))
        min_c, min_g = allmin(self.mpi, [min_c, g.min()])
        complementarity, = allsum(self.mpi, [np.dot(equilibrium.ravel(), g.ravel())])
        kkt = KKTReport(natural=natural, complementarity=float(complementarity / self.n),
                        min_p=float(min_c) if np.isfinite(min_c) else 0.0, min_g=float(min_g))
        return r, lam, kkt

    def energy(self, g, elastic):
        """Pi(g) (scaled, per unit area) of local arrays ``g`` and ``elastic`` = S (g + h)."""
        h = self.local(self.heights, readonly=True).ravel()
        e = elastic.ravel()
        sums = allsum(self.mpi, [0.5 * (np.dot(g.ravel(), e) + np.dot(h, e)), self.scaled_law.energy(g).sum()])
        return float(sums.sum() / self.n)

    def energy_of(self, gap):
        """Pi (scaled, per unit area) of a whole gap field ``gap`` in length units (one operator application)."""
        gap_vec, elastic_vec = self.vec(), self.vec()
        try:
            g = self.local(gap_vec)
            g[...] = np.asarray(gap)[self.local_rows] / self.height_scale
            self.elastic_pressure(gap_vec, elastic_vec)
            return self.energy(g, self.local(elastic_vec, readonly=True))
        finally:
            gap_vec.destroy()
            elastic_vec.destroy()

    # --- results ----------------------------------------------------------------
    def certify(self, unknown, work, outcome, target, control, rtol, solver, started, applications):
        """The :class:`Result` of the gap ``unknown`` at mean gap ``target``, certified on a fresh S g (in ``work``)."""
        self.elastic_pressure(unknown, work)
        g = self.local(unknown, readonly=True)
        elastic = self.local(work, readonly=True)
        _, lam, kkt = self.stationarity(g, elastic)
        total, = allsum(self.mpi, [g.sum()])
        kkt.load_error = abs(total / self.n - target)  # the prescribed mean gap's error, over sqrt(m0^h)
        converged, reason = certified(outcome.reason, kkt, rtol, "mean gap error", "S g")
        if converged and self.check_curvature:
            converged, reason = self._second_order(g, kkt, reason)
        energy = self.energy(g, elastic) * self.pressure_scale * self.height_scale
        in_contact = (g == 0).astype(np.float64)
        measures = measure(self.elastic_problem, in_contact, g)
        pbar = -lam * self.pressure_scale
        gbar = target * self.height_scale
        return Result(
            pbar=pbar, pstar=pbar / self.sqrt_m0p, A=measures["A"], A_corrected=measures["A_corrected"],
            gbar=gbar, gstar=target, separation=gbar, rms_gap_contact=0.0, kkt=kkt,
            iterations=outcome.iterations, operator_applications=self.operator.applications - applications,
            time_s=time.perf_counter() - started, reason=reason, converged=converged, solver=solver,
            control="displacement", history=outcome.history, energy=energy)

    def _second_order(self, g, kkt, reason):
        """``(converged, reason)`` with the least curvature in ``kkt``: a negative one is no local minimum."""
        if self.longest_wave_stiffness is None:
            self.longest_wave_stiffness = longest_wave_stiffness(self)
        if self.least_mode is None:
            self.least_mode = np.zeros_like(g)
        kkt.min_curvature, how = least_curvature(self, g, self.longest_wave_stiffness, self.least_mode)
        if kkt.min_curvature is None:
            return True, f"{reason} (least curvature not determined: {how})"
        if kkt.min_curvature < -CURVATURE_TOLERANCE:
            return False, f"NOT_A_LOCAL_MINIMUM ({reason}, but the energy's least curvature is " \
                          f"{kkt.min_curvature:.2g} s1 ({how}))"
        return True, reason

    def fields(self, unknown, work, result):
        """This rank's rows of the total pressure S (g + h) + pbar (compressive positive) and the gap, in units."""
        pressure = self.local(work, readonly=True) * self.pressure_scale + result.pbar
        return pressure, self.local(unknown, readonly=True) * self.height_scale


def summit_radius(m4h):
    """1 / (mean summit curvature (8/3) sqrt(m4^h / pi)) (Nayak's high-bandwidth limit), length units."""
    return 1.0 / (8.0 / 3.0 * math.sqrt(m4h / math.pi))


def approach_retraction(gbar_max, gbar_min, steps):
    """Mean gaps from ``gbar_max`` down to ``gbar_min`` and back up, ``steps`` each way; the turn appears once."""
    down = np.linspace(gbar_max, gbar_min, steps + 1)
    return np.concatenate([down, down[-2::-1]])


def dissipated_energy(gbars, pbars):
    """Energy dissipated per unit area in one approach-retraction cycle: -closed integral of pbar dgbar.

    d Pi / d gbar = -pbar on every equilibrium branch, so the work around a closed cycle is what the jumps
    dissipated. Trapezoids over the path (pressure x length units); positive for a hysteresis loop.
    """
    gbars, pbars = np.asarray(gbars), np.asarray(pbars)
    return float(-np.sum(0.5 * (pbars[1:] + pbars[:-1]) * np.diff(gbars)))
