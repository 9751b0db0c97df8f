"""The contact problem (3.41)-(3.44) and its results.

Scaled internally so every solver sees numbers of order one: heights by the rms height ``s = sqrt(m0^h)``,
in-plane lengths by the cell length ``L`` along x, pressures by ``E* s / L``. The compliance then has the
symbol ``1 / (pi |k|)`` and the gap ``g = K p + d - h`` is the gradient of ``min 1/2 p'Kp + p'(d - h), p >= 0``.
"""

import math
import time

import numpy as np
from petsc4py import PETSc

from ..elastic.factory import BOUNDARIES, make_operator
from ..errors import ParameterError
from ..parallel import allsum, allmin
from ..surface.grid import Grid
from .certificate import certified, report
from .result import Result, measure


class ContactProblem:
    """A rough surface against a rigid flat, distributed over the ranks of ``comm``.

    Parameters
    ----------
    grid : surfaces.Grid
        The periodic cell (length units).
    heights : ndarray (n0, n1)
        The whole surface, length units, the same on every rank. Its mean is removed (it only shifts the
        rigid separation).
    E_star : float
        Composite modulus E* (1.6), pressure units.
    comm : petsc4py.PETSc.Comm
    fft_threads, fft_effort :
        Passed to the operator.
    boundary : "periodic" or "free"
        ``periodic``: the Westergaard compliance (3.33); ``free``: an isolated body, Love's coefficients
        (3.31) by a padded FFT. Under ``free`` the mean gap is not the rigid separation, no load gives
        complete contact exactly, and p* still uses sqrt(m0^p) of the pressure surface (2.47).
    hardness : float or None
        The hardness cap H, pressure units: perfect plasticity as ``0 <= p <= H`` (None: none).
    operator_factory : callable
        ``operator_factory(boundary, grid, E_star, comm, fft_threads, fft_effort)`` returns the compliance;
        called with the scaled grid (cell length 1 along x) and E* = 1.

    Attributes
    ----------
    kind : str
        ``"contact"``, the key of :mod:`roughpetsc.solvers.registry`.
    controls : tuple
        Load control (a mean pressure) and displacement control (a mean gap).
    progress : callable or None
        ``progress(iteration, natural_residual, seconds)``, called with every residual a solver records.
    stop_requested : callable or None
        ``stop_requested()`` is True once a stop was asked for (Ctrl-C); every solve then ends at its next
        iteration on every rank alike. Set it on every rank or none.
    """

    kind = "contact"
    controls = ("load", "displacement")

    def __init__(self, grid, heights, E_star, comm=None, fft_threads=1, fft_effort="FFTW_MEASURE",
                 boundary="periodic", hardness=None, operator_factory=make_operator):
        if boundary not in BOUNDARIES:
            raise ParameterError("boundary", f"the boundary is one of {', '.join(BOUNDARIES)}, got '{boundary}'")
        if hardness is not None and not (hardness > 0 and math.isfinite(hardness)):
            raise ParameterError("hardness", f"the hardness must be positive and finite, got {hardness}")
        if not (isinstance(E_star, (int, float, np.integer, np.floating)) and E_star > 0 and math.isfinite(E_star)):
            raise ParameterError("E_star", f"the composite modulus must be positive and finite, got {E_star!r}")
        if not isinstance(grid, Grid):
            raise ParameterError("grid", f"the grid must be a roughpetsc Grid, got {type(grid).__name__}")
        if np.shape(heights) != grid.shape:
            raise ParameterError("heights", f"the heights have shape {np.shape(heights)}, the grid {grid.shape}")
        heights = np.asarray(heights)
        if not np.issubdtype(heights.dtype, np.number) or np.iscomplexobj(heights):
            raise ParameterError("heights", f"the heights must be real numbers, got dtype {heights.dtype}")
        if not np.all(np.isfinite(heights)):
            raise ParameterError("heights", f"{int(np.count_nonzero(~np.isfinite(heights)))} height(s) are NaN or "
                                            "infinite")
        if np.ptp(heights) == 0:
            raise ParameterError("heights", "the surface is flat (all heights equal): there is no contact problem")
        self.comm = comm or PETSc.COMM_WORLD
        self.mpi = self.comm.tompi4py()
        self.grid = grid
        self.E_star = float(E_star)
        self.n = grid.size
        heights = heights - np.mean(heights)
        self.height_scale = float(np.sqrt(np.mean(heights ** 2)))
        self.pressure_scale = self.E_star * self.height_scale / grid.l1
        self.scaled_grid = Grid(grid.n0, grid.n1, grid.l0 / grid.l1, 1.0)
        self.boundary = boundary
        self.fft_threads, self.fft_effort = fft_threads, fft_effort
        self.operator = operator_factory(boundary, self.scaled_grid, 1.0, self.comm, fft_threads, fft_effort)
        self.local_rows = self.operator.local_rows
        self.heights = self.operator.vec()
        self.operator.local(self.heights)[...] = heights[self.local_rows] / self.height_scale
        self.pressure_surface = self.operator.vec()
        self.operator.pressure_surface(self.heights, self.pressure_surface)
        local_pc = self.local(self.pressure_surface, readonly=True)
        sum_pc2, = allsum(self.mpi, [np.dot(local_pc.ravel(), local_pc.ravel())])
        self.m0p_scaled = sum_pc2 / self.n
        # Complete contact (every node in contact) at pbar = -min(p_c): exact only on the periodic cell.
        self.complete_contact_pbar = float(-allmin(self.mpi, [local_pc.min()])[0]) if boundary == "periodic" \
            else math.inf
        self.max_pressure_surface = float(-allmin(self.mpi, [-local_pc.max()])[0])
        self.hardness = hardness
        self.upper_bound = None if hardness is None else hardness / self.pressure_scale
        self.max_height = float(-allmin(self.mpi, [-self.local(self.heights, readonly=True).max()])[0])
        self.progress = None
        self.stop_requested = None

    # --- vectors and fields -------------------------------------------------
    def vec(self):
        return self.operator.vec()

    def local(self, v, readonly=False):
        """This rank's rows of ``v`` as a ``(rows, n1)`` array view."""
        return self.operator.local(v, readonly)

    def gap(self, pressure, separation, out):
        """``out = K p + d - h`` (scaled): one operator application."""
        self.operator.displacement(pressure, out)
        out.axpy(-1.0, self.heights)
        out.shift(separation)

    def contact_separation(self, pressure, elastic_gap):
        """The rigid separation d giving the gap zero mean on the contact set (PK's choice).

        ``elastic_gap``: local ``K p - h``. Under a hardness cap the contact set is the elastic one (0 < p < H).
        """
        local = self.local(pressure, readonly=True)
        in_contact = local > 0
        if self.upper_bound is not None:
            in_contact &= local < self.upper_bound
        sums = allsum(self.mpi, [np.sum(elastic_gap[in_contact]), np.count_nonzero(in_contact)])
        return -sums[0] / sums[1] if sums[1] else self.max_height

    # --- units --------------------------------------------------------------
    @property
    def sqrt_m0h(self):
        """rms height sqrt(m0^h), length units."""
        return self.height_scale

    @property
    def sqrt_m0p(self):
        """rms of the pressure surface sqrt(m0^p) (2.52), pressure units, from the field p_c of (2.47)."""
        return math.sqrt(self.m0p_scaled) * self.pressure_scale

    def scaled_pbar(self, pbar=None, pstar=None):
        """The prescribed mean pressure in scaled units, from ``pbar`` (pressure units) or ``pstar``."""
        if pstar is not None:
            return pstar * math.sqrt(self.m0p_scaled)
        return pbar / self.pressure_scale

    # --- what every problem offers the solvers (roughpetsc.solvers.protocol) ---------
    def target(self, control, pbar=None, pstar=None, gbar=None):
        """The scaled mean pressure (``pbar`` or ``pstar``, load control) or rigid separation (``gbar``), checked."""
        if control == "displacement":
            if gbar is None:
                raise ParameterError("gbar", "give the mean gap gbar (displacement control)")
            if not gbar > 0:
                raise ParameterError("gbar", f"the mean gap must be positive (complete contact has zero mean "
                                             f"gap), got {gbar}")
            return gbar / self.height_scale
        if pbar is None and pstar is None:
            raise ParameterError("pbar", "give the load: pbar or pstar (load control), or gbar (displacement "
                                         "control)")
        target = self.scaled_pbar(pbar, pstar)
        if not target > 0:
            raise ParameterError("pbar" if pstar is None else "pstar",
                                 f"the load must be positive, got {pbar if pstar is None else pstar}")
        if self.upper_bound is not None and target >= self.upper_bound:
            raise ParameterError("pbar" if pstar is None else "pstar",
                                 "the mean pressure must stay below the hardness, which caps every pressure")
        return target

    def continuation(self, keeps_displacement=False):
        """The pressure and its load-path predictor (:class:`~roughpetsc.contact.continuation.PressureContinuation`)."""
        from .continuation import PressureContinuation

        return PressureContinuation(self, keeps_displacement)

    def exact(self, target, control, unknown):
        """Beyond complete contact the exact answer p = pbar + p_c, g = 0 (d = 0) into ``unknown``; its Outcome.

        None below complete contact, under displacement control, or where that answer exceeds the cap.
        """
        from ..solvers.protocol import Outcome

        below_cap = self.upper_bound is None or target + self.max_pressure_surface <= self.upper_bound
        if control != "load" or not (target >= self.complete_contact_pbar and below_cap):
            return None
        self.pressure_surface.copy(unknown)
        unknown.shift(target)
        return Outcome(0.0, 0, "COMPLETE_CONTACT_EXACT", np.zeros((0, 4)))

    def certify(self, unknown, work, outcome, target, control, rtol, solver, started, applications):
        """The :class:`~roughpetsc.contact.Result` of the pressure ``unknown``, certified on a fresh gap.

        ``work`` receives the gap computed afresh (one operator application); the natural KKT residual and,
        under load control, the load error are checked on it against ``rtol``.
        """
        load_target = target if control == "load" else None
        self.gap(unknown, outcome.separation, work)
        p = self.local(unknown, readonly=True)
        g = self.local(work, readonly=True)
        kkt = report(self.mpi, p, g, self.n, load_target, self.upper_bound)
        measures = measure(self, p, g)
        converged, reason = certified(outcome.reason, kkt, rtol)
        pbar = measures["pbar"] * self.pressure_scale
        gbar = measures["gbar"] * self.height_scale
        return Result(
            pbar=pbar, pstar=pbar / self.sqrt_m0p, A=measures["A"], A_corrected=measures["A_corrected"],
            gbar=gbar, gstar=gbar / self.sqrt_m0h, separation=outcome.separation * self.height_scale,
            rms_gap_contact=measures["rms_gap_contact"] * self.height_scale, kkt=kkt,
            iterations=outcome.iterations, operator_applications=self.operator.applications - applications,
            time_s=time.perf_counter() - started, reason=reason, converged=converged, solver=solver,
            control=control, history=outcome.history, A_plastic=measures["A_plastic"])

    def fields(self, unknown, work, result):
        """This rank's rows of the pressure and gap of the last certified solve, in pressure and length units."""
        return (self.local(unknown, readonly=True) * self.pressure_scale,
                self.local(work, readonly=True) * self.height_scale)

    def destroy(self):
        for v in (self.heights, self.pressure_surface):
            v.destroy()
        self.operator.destroy()


