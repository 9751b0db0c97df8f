"""A coarse-to-fine start for cold, load-controlled contact solves (issue 39, item 2).

A cold solve starts from the uniform pressure, or with ``-cascade_coarsest M`` (under the solver's prefix)
from coarser grids N/2^k, ..., N/2 that keep at least M nodes per side: the heights injected
(every 2^k-th node), each level solved by Polonsky-Keer under load control at the same mean pressure to a
natural residual of ``-cascade_rtol`` (default 1e-3) from the level below, and its solution prolongated to
the next grid as ``max(bilinear(p - S_00 max(g, 0)), 0)`` (S_00 the diagonal of the coarse stiffness: the
contact edge becomes the zero line of a signed field that interpolates across it, not the one-cell dilation
of interpolating p). The fine solve then runs from that start as from any other, to its own tolerance and
certificate. Only the start changes: a cascade cannot change the answer.

Default: M = 256 on grids of at least 1024 nodes per side (periodic contact, no hardness cap, load control),
where it wins; no cascade elsewhere. ``-cascade_coarsest 0`` turns it off; an M given explicitly applies on
any grid with a level of at least M nodes per side, and is refused where a cascade cannot apply.

Measured (``studies/solver_scaling.py``, variant ``pk-cascade``, groups 1 and 18, seed 1, natural residual
1e-8, coarse pairs weighted by (N_c / N)^2): at N = 2048 the cold solve takes 0.68-0.70 of the uniform start's
FFT pairs at p* = 0.05, 0.82-0.83 at p* = 0.5 and 1.00-1.03 at p* = 2; at N = 1024 0.78-0.84, 0.88-0.94 and
0.97-0.99; at N = 512 0.93-1.11 (hence the default from N = 1024). From the cascade start the fine grid takes
about the iterations of CG on the final contact set; what is left is the fresh K p after each projected step.

Each coarse level is a :class:`~roughpetsc.ContactProblem` on the same communicator; its injected heights and
its solution are gathered on every rank ((N / 2^k)^2 numbers each, for the coarse problem and the interpolation
across rank boundaries), so parallel runs give the serial start exactly.
"""

import numpy as np
from petsc4py import PETSc

from ..errors import UserError
from ..elastic.split import applicable as split_applicable
from ..parallel import allgather_rows
from .stopping import option_name, read_option

DEFAULT_RTOL = 1e-3
DEFAULT_COARSEST = 256
DEFAULT_FROM = 1024  # the default cascade starts grids of at least this many nodes per side

OPTIONS = [
    ("cascade_coarsest", DEFAULT_COARSEST, "cold load-controlled contact solves start from coarse grids N/2, N/4, "
                                           "... of at least this many nodes per side (0: none; not given: 256 on "
                                           f"grids of at least {DEFAULT_FROM} nodes per side, none on smaller ones)"),
    ("cascade_rtol", DEFAULT_RTOL, "natural KKT residual of the cascade's coarse solves"),
]


def coarsening_factors(shape, coarsest):
    """The factors 2^k of the coarse grids with at least ``coarsest`` nodes per side, coarsest first.

    ``((1024, 1024), 256)`` -> ``(4, 2)``; ``()`` when no grid qualifies or ``coarsest`` is 0.
    """
    factors = []
    factor = 2
    while coarsest > 0 and min(shape) // factor >= coarsest and all(n % factor == 0 for n in shape):
        factors.insert(0, factor)
        factor *= 2
    return tuple(factors)


def prolong_bilinear_rows(coarse, rows):
    """Rows ``rows`` (a slice) of the periodic bilinear interpolation of ``coarse`` (m0 x m1) to 2 m0 x 2 m1.

    Coarse node (i, j) is fine node (2 i, 2 j).
    """
    m0, m1 = coarse.shape
    fine_rows = np.arange(rows.start, rows.stop)
    lower = coarse[fine_rows // 2]
    upper = coarse[(fine_rows // 2 + 1) % m0]
    lines = np.where((fine_rows % 2 == 1)[:, None], 0.5 * (lower + upper), lower)
    out = np.empty((lines.shape[0], 2 * m1))
    out[:, 0::2] = lines
    out[:, 1::2] = 0.5 * (lines + np.roll(lines, -1, axis=1))
    return out


def cascade_settings(prefix=None):
    """``(-cascade_coarsest, -cascade_rtol)`` under ``prefix``, checked; the first None when not given."""
    options = PETSc.Options(prefix)
    coarsest = read_option(options, "Int", "cascade_coarsest", -1) if options.hasName("cascade_coarsest") else None
    rtol = read_option(options, "Real", "cascade_rtol", DEFAULT_RTOL)
    if coarsest is not None and coarsest < 0:
        raise UserError(f"{option_name('cascade_coarsest', prefix)} is the least number of nodes per side of a "
                        f"coarse grid (0: no cascade), got {coarsest}")
    if not 0 < rtol < 1:
        raise UserError(f"{option_name('cascade_rtol', prefix)} is the natural residual of the coarse solves, "
                        f"between 0 and 1, got {rtol}")
    return coarsest, rtol


def applies(problem, control):
    """Why a cascade cannot start this problem's solves, or '' if it can."""
    if problem.kind != "contact" or control != "load":
        return f"a cascade starts load-controlled contact solves only, not a {problem.kind} problem under " \
               f"{control} control"
    if problem.boundary != "periodic" or problem.upper_bound is not None:
        return "a cascade needs the periodic boundary and no hardness cap"
    return ""


def make_cascade(problem, control, prefix=None):
    """The :class:`CascadeStart` the options under ``prefix`` ask for (or the default's), or None.

    Asked for explicitly where it cannot apply, a cascade is refused by name.
    """
    coarsest, rtol = cascade_settings(prefix)
    why_not = applies(problem, control)
    if coarsest is None:
        if why_not or min(problem.grid.shape) < DEFAULT_FROM:
            return None
        coarsest = DEFAULT_COARSEST
    if coarsest == 0:
        return None
    if why_not:
        raise UserError(f"{option_name('cascade_coarsest', prefix)}: {why_not}")
    factors = coarsening_factors(problem.grid.shape, coarsest)
    return CascadeStart(problem, factors, rtol, split_settings(prefix)) if factors else None


def split_settings(prefix):
    """The split corrections the fine solve was asked for (``-pk_split_*``), for the coarse levels too; or None."""
    from .polonsky_keer import SPLIT_COARSENING, SPLIT_REFRESH, SPLIT_TRANSFER

    options = PETSc.Options(prefix)
    radius = read_option(options, "Int", "pk_split_radius", 0)
    if radius <= 0:
        return None
    return (radius, read_option(options, "Int", "pk_split_coarsening", SPLIT_COARSENING),
            read_option(options, "Real", "pk_split_refresh", SPLIT_REFRESH),
            options.getString("pk_split_transfer", SPLIT_TRANSFER))


class CascadeStart:
    """Fills a pressure Vec with the cascade's start (a callable for ``PressureContinuation.cold_start``).

    Attributes
    ----------
    factors : tuple of int
        Coarsening factors of the levels, coarsest first.
    pairs : float
        FFT pairs of the coarse solves so far, in fine-grid pairs (each level's weighted by its size).
    """

    def __init__(self, problem, factors, rtol, split=None):
        self.problem = problem
        self.factors = tuple(factors)
        self.rtol = rtol
        self.split = split  # (radius, coarsening, refresh, transfer) of the fine solve's split corrections, or None
        self.pairs = 0.0

    def take_pairs(self):
        """The coarse pairs spent since the last call."""
        pairs, self.pairs = self.pairs, 0.0
        return pairs

    def __call__(self, target, pressure):
        """Put the start for the scaled mean pressure ``target`` into ``pressure`` (its mean is left free)."""
        from roughpetsc.contact.problem import ContactProblem
        from roughpetsc.surface.grid import Grid

        problem = self.problem
        grid = problem.grid
        local = problem.local(problem.heights, readonly=True)
        pbar = target * problem.pressure_scale
        signed = None
        for factor in self.factors:
            # The injected rows of this rank (global row a multiple of factor), gathered: (N / factor)^2 numbers.
            injected = local[(-problem.local_rows.start) % factor::factor, ::factor]
            heights = allgather_rows(problem.mpi, injected) * problem.height_scale
            # FFTW's estimate: measuring plans for grids solved once, to 1e-3, costs more than it saves
            coarse = ContactProblem(Grid(grid.n0 // factor, grid.n1 // factor, grid.l0, grid.l1), heights,
                                    problem.E_star, problem.comm, problem.fft_threads, "FFTW_ESTIMATE")
            try:
                signed = self._solve_level(coarse, pbar, signed, factor)
            finally:
                coarse.destroy()
        problem.local(pressure)[...] = np.maximum(prolong_bilinear_rows(signed, problem.local_rows), 0.0)

    def _solve_level(self, coarse, pbar, below, factor):
        """Solve one coarse level from the prolongated ``below`` (None: uniform); its signed field, gathered."""
        from .facade import Solver

        options = {"cascade_coarsest": 0, "pk_split_radius": 0}
        if self.split is not None and split_applicable(coarse.operator, *self.split[:2]) is None:
            options.update(zip(("pk_split_radius", "pk_split_coarsening", "pk_split_refresh", "pk_split_transfer"),
                               self.split))
        solver = Solver(coarse, "load", "pk", self.rtol, options=options)
        try:
            if below is not None:
                def start(target, pressure):
                    coarse.local(pressure)[...] = np.maximum(prolong_bilinear_rows(below, coarse.local_rows), 0.0)
                solver.path.cold_start = start
            applications = coarse.operator.applications
            result = solver.solve(pbar=pbar)
            self.pairs += (coarse.operator.applications - applications + result.split_applications) / factor ** 2
            p = coarse.local(solver.pressure, readonly=True)
            gap = coarse.local(solver.work, readonly=True)
            signed = p - coarse.operator.stiffness_diagonal * np.maximum(gap, 0.0)
            return allgather_rows(coarse.mpi, signed)
        finally:
            solver.destroy()
