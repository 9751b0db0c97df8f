"""The contact problem (3.41)-(3.44) and its results.

Internally the problem is dimensionless so that every solver sees numbers of
order one whatever the unit system: heights are divided by the rms height
``s = sqrt(m0^h)``, in-plane lengths by the cell length ``L`` along x, and
pressures by ``E* s / L``. The compliance then has the symbol
``1 / (pi |k|)`` (k in cycles per cell length) and the gap of a pressure field
``p`` at rigid separation ``d`` is ``g = K p + d - h``: the gradient of the QP
``min 1/2 p'Kp + p'(d - h), p >= 0``.
"""

from dataclasses import dataclass, field, asdict
import math

import numpy as np
from petsc4py import PETSc

from .errors import ParameterError
from .kkt import KKTReport, allsum, allmin
from .surfaces import Grid
from .love import FreeBoundary
from .westergaard import Westergaard

BOUNDARIES = ("periodic", "free")

# Perimeter correction of the node-count contact area, Yastrebov, Anciaux and
# Molinari, Tribol. Int. 114 (2017): A = A_nodes - c P_d dx with the staircase
# perimeter P_d of the contact set on the square grid.
PERIMETER_COEFFICIENT = (math.pi - 1.0 + math.log(2.0)) / 24.0


class ContactProblem:
    """A rough surface against a rigid flat, distributed over the ranks of ``comm``.

    Parameters
    ----------
    grid : surfaces.Grid
        The periodic cell (length units).
    heights : ndarray (n0, n1)
        The whole surface, length units (every rank passes the same array). Its mean is removed: the mean height
        only shifts the rigid separation, and every scale (sqrt(m0^h), the bracket of the separation,
        p*) is that of the zero-mean surface.
    E_star : float
        Composite modulus E* (1.6), pressure units.
    comm : petsc4py.PETSc.Comm
    fft_threads, fft_effort :
        Passed to the operator.
    boundary : "periodic" or "free"
        ``periodic``: the cell repeats (the Westergaard compliance (3.33)); ``free``: an isolated
        body, nothing outside the grid (Love's coefficients (3.31) by a padded FFT,
        :class:`~roughpetsc.love.FreeBoundary`). Under ``free`` the mean gap is not the rigid
        separation, no load gives complete contact exactly, and p* still uses sqrt(m0^p) of the
        pressure surface (2.47) of the heights, a statistic of the surface.
    hardness : float or None
        The hardness cap H, pressure units: perfect plasticity as ``0 <= p <= H`` (None: none).

    Attributes
    ----------
    progress : callable or None
        Called as ``progress(iteration, natural_residual, seconds)`` with every residual that a
        solver of this problem records (:class:`~roughpetsc.kkt.History`); None by default.
    stop_requested : callable or None
        ``stop_requested()`` is True when this process was asked to stop (Ctrl-C,
        :class:`roughpetsc.interrupts.StopRequests`); every solve then ends at its next iteration, on
        every rank alike (:meth:`~roughpetsc.kkt.History.out_of_time`). Set it on every rank or none.
    """

    def __init__(self, grid, heights, E_star, comm=None, fft_threads=1, fft_effort="FFTW_MEASURE",
                 boundary="periodic", hardness=None):
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
        periodic = Westergaard(self.scaled_grid, 1.0, self.comm, fft_threads, fft_effort)
        self.local_rows = periodic.local_rows
        self.heights = periodic.vec()
        periodic.local(self.heights)[...] = heights[self.local_rows] / self.height_scale
        self.pressure_surface = periodic.vec()
        periodic.pressure_surface(self.heights, self.pressure_surface)
        if boundary == "periodic":
            self.operator = periodic
        else:
            periodic.destroy()
            self.operator = FreeBoundary(self.scaled_grid, 1.0, self.comm, fft_threads, fft_effort)
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
        """The rigid separation d for which the gap has zero mean on the contact set (PK's choice).

        ``elastic_gap`` is ``K p - h``, the gap at d = 0 (local array of this rank). Under a hardness
        cap the contact set is the elastic one (0 < p < H): the gap of a plastic node may be negative.
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

    def complete_contact_exact(self, pbar):
        """True when ``pbar`` (scaled) reaches complete contact, where p = pbar + p_c is the exact answer.

        Under a hardness cap only while that answer stays below the cap everywhere.
        """
        below_cap = self.upper_bound is None or pbar + self.max_pressure_surface <= self.upper_bound
        return pbar >= self.complete_contact_pbar and below_cap

    def scaled_pbar(self, pbar=None, pstar=None):
        """The prescribed mean pressure in scaled units, from ``pbar`` (pressure units) or ``pstar``."""
        if pstar is not None:
            return pstar * math.sqrt(self.m0p_scaled)
        return pbar / self.pressure_scale

    def destroy(self):
        for v in (self.heights, self.pressure_surface):
            v.destroy()
        self.operator.destroy()


@dataclass
class Result:
    """What one solve at one load gives; the same type for every solver.

    Pressures in pressure units, gaps in length units; ``pstar`` = pbar /
    sqrt(m0^p), ``gstar`` = gbar / sqrt(m0^h); ``A`` by node count (3.45),
    ``A_corrected`` with the perimeter correction; ``rms_gap_contact`` is (3.50) (over the elastic
    contact nodes under a hardness cap); ``A_plastic`` the fraction of nodes at the cap (0 without one).
    """

    pbar: float
    pstar: float
    A: float
    A_corrected: float
    gbar: float
    gstar: float
    separation: float
    rms_gap_contact: float
    kkt: KKTReport
    iterations: int
    operator_applications: int
    time_s: float
    reason: str
    converged: bool
    solver: str
    control: str
    history: np.ndarray = field(default=None, repr=False)
    A_plastic: float = 0.0

    def summary(self):
        """A JSON-ready dict (no fields, no history)."""
        out = {k: v for k, v in asdict(self).items() if k not in ("history", "kkt")}
        out["kkt"] = self.kkt.as_dict()
        return out


def contact_perimeter_edges(problem, in_contact):
    """Number of grid edges between a contact and a non-contact node (periodic), summed over ranks.

    Returns ``(edges along axis 1, edges along axis 0)``.
    """
    along_x = np.count_nonzero(in_contact != np.roll(in_contact, -1, axis=1))
    below = _next_rank_first_row(problem.mpi, in_contact)
    along_y = np.count_nonzero(in_contact[:-1] != in_contact[1:]) + np.count_nonzero(in_contact[-1] != below)
    return tuple(allsum(problem.mpi, [along_x, along_y]))


def _next_rank_first_row(comm, rows):
    """The first row of the next rank (periodically): the neighbour below this rank's last row.

    Every rank owns at least one row (:func:`roughpetsc.slab.row_split`), however unevenly they are shared.
    """
    size, rank = comm.Get_size(), comm.Get_rank()
    if size == 1:
        return rows[0]
    received = np.empty_like(rows[0])
    comm.Sendrecv(np.ascontiguousarray(rows[0]), dest=(rank - 1) % size, recvbuf=received, source=(rank + 1) % size)
    return received


def measure(problem, pressure, gap):
    """Contact measures of a solution (scaled local arrays ``pressure``, ``gap``).

    Returns a dict with A (3.45), A_corrected, gbar (3.46 with the erratum of
    docs/conventions.md: the mean over all nodes of the gap, zero in contact), the rms gap in
    contact (3.50) and the plastic fraction A_plastic (nodes at the hardness cap), all in scaled
    units except the area fractions.
    """
    in_contact = pressure > 0
    plastic = np.zeros_like(in_contact) if problem.upper_bound is None else pressure >= problem.upper_bound
    elastic = in_contact & ~plastic  # a plastic node's gap is its plastic penetration, not a residual
    sums = allsum(problem.mpi, [np.count_nonzero(in_contact), gap[~in_contact].sum(),
                                np.dot(gap[elastic], gap[elastic]), pressure.sum(), np.count_nonzero(elastic),
                                np.count_nonzero(plastic)])
    n_contact, gap_sum, gap2_contact, p_sum, n_elastic, n_plastic = sums
    edges_x, edges_y = contact_perimeter_edges(problem, in_contact)
    grid = problem.grid
    dx, dy = grid.l1 / grid.n1, grid.l0 / grid.n0
    # Edge between x-neighbours has length dy; the correction strip is c * P_d * dx.
    perimeter = edges_x * dy + edges_y * dx
    area = n_contact / problem.n
    corrected = area - PERIMETER_COEFFICIENT * perimeter * math.sqrt(dx * dy) / grid.area
    return {
        "A": float(area),
        "A_corrected": float(max(corrected, 0.0)),
        "gbar": float(gap_sum / problem.n),
        "rms_gap_contact": float(math.sqrt(gap2_contact / n_elastic)) if n_elastic else 0.0,
        "pbar": float(p_sum / problem.n),
        "A_plastic": float(n_plastic / problem.n),
    }
