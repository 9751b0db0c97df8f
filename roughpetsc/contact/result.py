"""What one solve gives: the :class:`Result` of every solver, and the contact measures (3.45)-(3.50)."""

from dataclasses import asdict, dataclass, field
import math

import numpy as np

from ..parallel import allsum, next_rank_first_row
from .certificate import KKTReport


# Perimeter correction of the node-count contact area, Yastrebov, Anciaux and Molinari, Tribol. Int. 114
# (2017): A = A_nodes - c P_d dx with the staircase perimeter P_d of the contact set on the square grid.
PERIMETER_COEFFICIENT = (math.pi - 1.0 + math.log(2.0)) / 24.0


@dataclass
class Result:
    """What one solve at one load gives; the same type for every solver.

    Pressures in pressure units, gaps in length units; ``pstar`` = pbar / sqrt(m0^p), ``gstar`` = gbar /
    sqrt(m0^h); ``A`` by node count (3.45), ``A_corrected`` with the perimeter correction; ``rms_gap_contact``
    (3.50) over the elastic contact nodes; ``A_plastic`` the fraction of nodes at the cap; ``energy`` the total
    energy per unit area of an adhesive solution (pressure x length units, :mod:`~roughpetsc.contact.adhesive`);
    ``cascade_applications`` the FFT pairs of a cold start's coarse solves (:mod:`roughpetsc.solvers.cascade`)
    in fine-grid pairs (each level's weighted by its size), beside ``operator_applications`` on the grid itself;
    ``split_applications`` the coarse FFT pairs of Polonsky-Keer's split corrections (:mod:`roughpetsc.elastic.split`),
    in fine-grid pairs as well.
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
    energy: float = None
    cascade_applications: float = 0.0
    split_applications: float = 0.0

    def summary(self):
        """A JSON-ready dict (no fields, no history)."""
        out = {k: v for k, v in asdict(self).items() if k not in ("history", "kkt")}
        out["kkt"] = self.kkt.as_dict()
        return out


def contact_perimeter_edges(problem, in_contact):
    """``(along axis 1, along axis 0)``: the grid edges between contact and non-contact nodes, all ranks."""
    along_x = np.count_nonzero(in_contact != np.roll(in_contact, -1, axis=1))
    below = next_rank_first_row(problem.mpi, in_contact)
    along_y = np.count_nonzero(in_contact[:-1] != in_contact[1:]) + np.count_nonzero(in_contact[-1] != below)
    return tuple(allsum(problem.mpi, [along_x, along_y]))


def measure(problem, pressure, gap):
    """Contact measures of a solution (scaled local arrays ``pressure``, ``gap``).

    A (3.45), A_corrected, gbar ((3.46) with the erratum of docs/conventions.md), the rms gap in contact (3.50),
    pbar and the plastic fraction A_plastic, in scaled units.
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
