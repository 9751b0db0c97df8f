"""Adhesive contact of a rough surface and a rigid flat in the periodic BEM, the gap as the unknown.

With an interaction law phi (:mod:`roughpetsc.interaction`) the total energy per unit area of a gap
field g >= 0 at the mean gap gbar (the rigid separation, (3.38)) is

    Pi(g) = 1/2 <g + h, S (g + h)> + <phi(g)>,

``<.>`` the mean over the nodes and ``S`` the stiffness (the inverse symbol pi E* |k| of the Westergaard
compliance (3.33), zero at k = 0): the surface displacement is u = g - gbar + h and S kills constants.
The gap stays bound-constrained; the mean gap is the one equality (displacement control). Adhesive
contact is unstable under load control (it jumps in and out of contact), so paths run under
displacement control and the load is an output.

First-order conditions, with r = S (g + h) + phi'(g) and a multiplier lambda = -pbar (pbar the mean
pressure, compressive positive):

* out of contact (g > 0): r = lambda, i.e. the total pressure p = S(g + h) + pbar equals the law's
  traction -phi'(g);
* in contact (g = 0): the contact pressure c = r - lambda >= 0.

The natural residual certified after every solve is ``max |min(g / sqrt(m0^h), (r - lambda) /
sqrt(m0^p))|`` over all nodes, on a gap whose S g is computed afresh, with lambda the mean of r out of
contact (the best multiplier for those nodes). Its pressure scale sqrt(m0^p) (2.52) is that of the
non-adhesive problem (the mean pressure may be zero or tensile here). The report's ``load_error`` is
the error of the prescribed quantity, the mean gap, over sqrt(m0^h); a converged solve has both below
the tolerance.

Only the periodic boundary is supported (the free boundary's stiffness is not a Fourier filter).
"""

import math
import time

import numpy as np

from .contact import Result, measure
from .errors import ParameterError
from .kkt import KKTReport, allmax, allmin, allsum
from . import kernels
from .solvers.gap_cg import gap_cg

SOLVERS = ("gapcg", "almm")


class AdhesiveContact:
    """A :class:`~roughpetsc.contact.ContactProblem` with an adhesive law, solved for the gap.

    Parameters
    ----------
    problem : ContactProblem
        Periodic, without a hardness cap.
    law : interaction.Dugdale or interaction.Exponential
        In the problem's units (pressure units of E*, length units of the heights).
    rtol : float
        Tolerance on the natural residual (module docstring).
    max_iter : int
    max_seconds : float
        Seconds after which a solve stops, reported as a time limit (0: none).
    solver : "gapcg" or "almm"
        The projected CG on the gap (:mod:`roughpetsc.solvers.gap_cg`) or TAO ALMM with the mean-gap
        equality (:mod:`roughpetsc.solvers.adhesive_almm`, its TAO options under ``prefix``).
    prefix : str or None
        Options prefix of the TAO object of ``almm``.

    Attributes
    ----------
    gap : petsc4py.PETSc.Vec
        The scaled gap of the last solve, the start of the next.
    """

    def __init__(self, problem, law, rtol=1e-8, max_iter=20000, max_seconds=0.0, solver="gapcg", prefix=None):
        if problem.boundary != "periodic":
            raise ParameterError("boundary", "adhesion is solved on the periodic cell only")
        if problem.upper_bound is not None:
            raise ParameterError("hardness", "adhesion and a hardness cap cannot be combined yet")
        self.problem = problem
        self.law = law
        self.scaled_law = law.scaled(problem.height_scale, problem.pressure_scale)
        self.rtol = rtol
        self.max_iter = max_iter
        self.max_seconds = max_seconds
        self.gap = problem.vec()
        self.elastic = problem.vec()  # S g + p_c = S (g + h)
        self.pressure_scale = math.sqrt(problem.m0p_scaled)
        self.started = False
        self.last_pbar = 0.0
        if solver not in SOLVERS:
            raise ParameterError("tao_type", f"the adhesive problem is solved by {' or '.join(SOLVERS)}, got "
                                             f"'{solver}'")
        self.name = solver
        self.tao_solver = None
        if solver == "almm":
            from .solvers.adhesive_almm import AdhesiveALMM

            self.tao_solver = AdhesiveALMM(self, prefix)

    def destroy(self):
        if self.tao_solver is not None:
            self.tao_solver.destroy()
        self.gap.destroy()
        self.elastic.destroy()

    # --- the energy and its gradient ------------------------------------------
    def elastic_pressure(self, gap_vec, out):
        """``out = S (g + h)``: the elastic pressure less its mean (one operator application)."""
        self.problem.operator.elastic_pressure(gap_vec, out)
        out.axpy(1.0, self.problem.pressure_surface)

    def gradient(self, g, elastic, out):
        """``out = r = S (g + h) + phi'(g)`` of local arrays ``g`` and ``elastic`` = S (g + h)."""
        self.scaled_law.force(g, out=out)
        out += elastic

    def multiplier(self, g, r, open_nodes):
        """lambda, the mean of r out of contact; ``open_nodes`` (bool, contiguous, written) marks g > 0. Also their
        count."""
        count, r_sum = allsum(self.problem.mpi, kernels.open_sums(g.ravel(), r.ravel(), open_nodes.reshape(-1)))
        return (r_sum / count if count else 0.0), count

    def natural(self, g, r, lam):
        """The natural residual max |min(g, (r - lambda) / sqrt(m0^p))| (scaled gaps)."""
        return float(allmax(self.problem.mpi, [kernels.gap_natural(g.ravel(), r.ravel(), lam, self.pressure_scale)])[0])

    def stationarity(self, g, elastic):
        """``(r, lambda, report)`` of local arrays ``g`` and ``elastic`` = S (g + h) (module docstring).

        The report: ``natural`` as above, ``min_p`` the least contact pressure r - lambda in contact and
        ``complementarity`` the mean of g |r - lambda| out of contact (both over sqrt(m0^p)), ``min_g``.
        """
        mpi = self.problem.mpi
        r = np.empty_like(g)
        self.gradient(g, elastic, r)
        out_of_contact = np.empty(g.shape, dtype=bool)
        lam, _ = self.multiplier(g, r, out_of_contact)
        natural = self.natural(g, r, lam)
        excess = (r - lam) / self.pressure_scale
        min_c = np.min(excess, where=~out_of_contact, initial=np.inf)
        equilibrium = np.abs(excess, where=out_of_contact, out=np.zeros_like(excess))
        min_c, min_g = allmin(mpi, [min_c, g.min()])
        complementarity, = allsum(mpi, [np.dot(equilibrium.ravel(), g.ravel())])
        kkt = KKTReport(natural=natural, complementarity=float(complementarity / self.problem.n),
                        min_p=float(min_c) if np.isfinite(min_c) else 0.0, min_g=float(min_g))
        return r, lam, kkt

    def energy(self, g, elastic):
        """Pi(g) (scaled, per unit area) of local arrays ``g`` and ``elastic`` = S (g + h)."""
        h = self.problem.local(self.problem.heights, readonly=True).ravel()
        e = elastic.ravel()
        sums = allsum(self.problem.mpi, [0.5 * (np.dot(g.ravel(), e) + np.dot(h, e)),
                                         self.scaled_law.energy(g).sum()])
        return float(sums.sum() / self.problem.n)

    # --- solves ---------------------------------------------------------------
    def solve(self, gbar=None, pbar=None, pstar=None, start=None):
        """Solve at the mean gap ``gbar`` (length units) from the last solution; a :class:`Result`.

        The first solve starts from the rigid gap max(gbar - h, 0) shifted to mean gbar; later ones from
        the previous gap shifted by the change of gbar (both projected onto g >= 0, mean gbar). Along a
        retraction, keep each step below the range of the law: a longer one starts the solver with the
        whole contact opened beyond the law's reach, and the path snaps off early.
        ``start="rigid"`` or ``"uniform"`` (g = gbar everywhere, the start of Tamaas' solver) forces a
        start: the local minimum a non-convex problem reaches depends on it. A load (``pbar``,
        ``pstar``) is refused: adhesive contact is solved under displacement control.
        """
        if gbar is None:
            raise ParameterError("pbar" if pstar is None else "pstar",
                                 "adhesive contact is solved under displacement control: prescribe the mean "
                                 "gap (the load jumps where contact snaps in or out)")
        if not (gbar > 0 and math.isfinite(gbar)):
            raise ParameterError("gbar", f"the mean gap must be positive and finite, got {gbar}")
        problem = self.problem
        target = gbar / problem.height_scale
        g = problem.local(self.gap)
        if start not in (None, "rigid", "uniform"):
            raise ParameterError("start", f"the start is 'rigid' or 'uniform', got '{start}'")
        if start == "uniform":
            g[...] = target
            self.started = True
        elif start == "rigid" or not self.started:
            g[...] = target - problem.local(problem.heights, readonly=True)
            self.started = True
        else:
            current, = allsum(problem.mpi, [g.sum()])
            g += target - current / problem.n
        started_at = time.perf_counter()
        applications = problem.operator.applications
        outcome = gap_cg(self, target) if self.tao_solver is None else self.tao_solver.solve(target)
        return self._result(outcome, target, started_at, applications)

    def _result(self, outcome, target, start, applications):
        problem = self.problem
        self.elastic_pressure(self.gap, self.elastic)
        g = problem.local(self.gap, readonly=True)
        elastic = problem.local(self.elastic, readonly=True)
        _, lam, kkt = self.stationarity(g, elastic)
        total, = allsum(problem.mpi, [g.sum()])
        kkt.load_error = abs(total / problem.n - target)  # the prescribed mean gap's error, over sqrt(m0^h)
        converged = kkt.natural <= self.rtol and kkt.load_error <= self.rtol
        reason = outcome.reason
        if not converged and reason.startswith("CONVERGED"):
            reason = (f"NOT_CERTIFIED ({reason}, but on a fresh S g: natural residual {kkt.natural:.2g}, mean gap "
                      f"error {kkt.load_error:.2g})")
        in_contact = (g == 0).astype(np.float64)
        measures = measure(problem, in_contact, g)
        pbar = -lam * problem.pressure_scale
        self.last_pbar = pbar
        gbar = target * problem.height_scale
        return Result(
            pbar=pbar, pstar=pbar / problem.sqrt_m0p, A=measures["A"], A_corrected=measures["A_corrected"],
            gbar=gbar, gstar=target, separation=gbar, rms_gap_contact=0.0, kkt=kkt,
            iterations=outcome.iterations, operator_applications=problem.operator.applications - applications,
            time_s=time.perf_counter() - start, reason=reason, converged=converged, solver=self.name,
            control="displacement", history=outcome.history)

    def fields(self):
        """This rank's rows of the total pressure (compressive positive) and the gap of the last solve.

        Pressure and length units. The pressure is S (g + h) + pbar: the contact pressure in contact,
        the law's traction -phi'(g) out of it.
        """
        problem = self.problem
        pressure = problem.local(self.elastic, readonly=True) * problem.pressure_scale + self.last_pbar
        return pressure, problem.local(self.gap, readonly=True) * problem.height_scale

    def path(self, gbars):
        """A generator of Results along the mean gaps ``gbars`` (length units), each warm-started."""
        for gbar in gbars:
            yield self.solve(gbar)


def summit_radius(m4h):
    """1 / (mean summit curvature (8/3) sqrt(m4^h / pi)) (Nayak's high-bandwidth limit), length units.

    The radius with which the header's Tabor parameter describes a rough surface.
    """
    return 1.0 / (8.0 / 3.0 * math.sqrt(m4h / math.pi))


def approach_retraction(gbar_max, gbar_min, steps):
    """Mean gaps from ``gbar_max`` down to ``gbar_min`` and back up, ``steps`` each way (length units).

    The turning point appears once; a path along it shows the hysteresis of adhesive contact.
    """
    down = np.linspace(gbar_max, gbar_min, steps + 1)
    return np.concatenate([down, down[-2::-1]])


def dissipated_energy(gbars, pbars):
    """Energy dissipated per unit area in one approach-retraction cycle: -closed integral of pbar dgbar.

    d Pi / d gbar = -pbar along every equilibrium branch, so the work -integral pbar dgbar put in
    around a closed cycle is what the jumps in and out of contact dissipated. Trapezoids over the
    path (pressure x length units); positive for a hysteresis loop.
    """
    gbars, pbars = np.asarray(gbars), np.asarray(pbars)
    return float(-np.sum(0.5 * (pbars[1:] + pbars[:-1]) * np.diff(gbars)))
