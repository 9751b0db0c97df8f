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

from .errors import UserError
from .kkt import KKTReport, allsum, allmin
from .surfaces import Grid
from .westergaard import Westergaard

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
        The whole surface (every rank passes the same array). Its mean is removed: the mean height
        only shifts the rigid separation, and every scale (sqrt(m0^h), the bracket of the separation,
        p*) is that of the zero-mean surface.
    E_star : float
        Composite modulus E* (1.6), pressure units.
    comm : petsc4py.PETSc.Comm
    fft_threads, fft_effort :
        Passed to :class:`~roughpetsc.westergaard.Westergaard`.

    Attributes
    ----------
    progress : callable or None
        Called as ``progress(iteration, natural_residual, seconds)`` with every residual that a
        solver of this problem records (:class:`~roughpetsc.kkt.History`); None by default.
    """

    def __init__(self, grid, heights, E_star, comm=None, fft_threads=1, fft_effort="FFTW_MEASURE"):
        if not (E_star > 0 and math.isfinite(E_star)):
            raise UserError(f"-E_star must be a positive, finite modulus, got {E_star}")
        self.comm = comm or PETSc.COMM_WORLD
        self.mpi = self.comm.tompi4py()
        self.grid = grid
        self.E_star = float(E_star)
        self.n = grid.size
        heights = heights - np.mean(heights)
        self.height_scale = float(np.sqrt(np.mean(heights ** 2)))
        self.pressure_scale = self.E_star * self.height_scale / grid.l1
        self.scaled_grid = Grid(grid.n0, grid.n1, grid.l0 / grid.l1, 1.0)
        self.operator = Westergaard(self.scaled_grid, 1.0, self.comm, fft_threads, fft_effort)
        self.local_rows = self.operator.local_rows
        self.heights = self.operator.vec()
        self.local(self.heights)[...] = heights[self.local_rows] / self.height_scale
        self.pressure_surface = self.operator.vec()
        self.operator.pressure_surface(self.heights, self.pressure_surface)
        local_pc = self.local(self.pressure_surface, readonly=True)
        sum_pc2, = allsum(self.mpi, [np.dot(local_pc.ravel(), local_pc.ravel())])
        self.m0p_scaled = sum_pc2 / self.n
        self.complete_contact_pbar = float(-allmin(self.mpi, [local_pc.min()])[0])
        self.max_height = float(-allmin(self.mpi, [-self.local(self.heights, readonly=True).max()])[0])
        self.progress = None

    # --- vectors and fields -------------------------------------------------
    def vec(self):
        return self.operator.vec()

    def local(self, v, readonly=False):
        return self.operator.local(v, readonly)

    def gap(self, pressure, separation, out):
        """``out = K p + d - h`` (scaled): one operator application."""
        self.operator.displacement(pressure, out)
        out.axpy(-1.0, self.heights)
        out.shift(separation)

    def contact_separation(self, pressure, elastic_gap):
        """The rigid separation d for which the gap has zero mean on the contact set (PK's choice).

        ``elastic_gap`` is ``K p - h``, the gap at d = 0 (local array of this rank).
        """
        in_contact = self.local(pressure, readonly=True) > 0
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

    def destroy(self):
        for v in (self.heights, self.pressure_surface):
            v.destroy()
        self.operator.destroy()


@dataclass
class Result:
    """What one solve at one load gives; the same type for every solver.

    Pressures in pressure units, gaps in length units; ``pstar`` = pbar /
    sqrt(m0^p), ``gstar`` = gbar / sqrt(m0^h); ``A`` by node count (3.45),
    ``A_corrected`` with the perimeter correction; ``rms_gap_contact`` is (3.50).
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

    Returns a dict with A (3.45), A_corrected, gbar (3.46 with the SPEC erratum:
    the mean over all nodes of the gap, zero in contact), the rms gap in
    contact (3.50), all in scaled units except the area fractions.
    """
    in_contact = pressure > 0
    sums = allsum(problem.mpi, [np.count_nonzero(in_contact), gap[~in_contact].sum(),
                                np.dot(gap[in_contact], gap[in_contact]), pressure.sum()])
    n_contact, gap_sum, gap2_contact, p_sum = sums
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
        "rms_gap_contact": float(math.sqrt(gap2_contact / n_contact)) if n_contact else 0.0,
        "pbar": float(p_sum / problem.n),
    }
