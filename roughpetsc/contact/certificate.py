"""KKT residuals of the contact problem (3.41)-(3.44) of the dissertation and the TAO convergence test.

Scale-free residuals (docs/conventions.md, "Residuals"): pressures over the mean pressure pbar, gaps over the
rms height sqrt(m0^h), which is 1 in the scaled variables of :class:`roughpetsc.contact.ContactProblem`.
"""

from dataclasses import dataclass, asdict
import re

import numpy as np
from petsc4py import PETSc

from ..parallel import allmax, allmin, allsum


@dataclass
class KKTReport:
    """The KKT report of one solve.

    natural : ||min(p / pbar, g / sqrt(m0^h))||_inf, the natural residual; with a hardness cap
        0 <= p <= H, ||mid(p / pbar, g / sqrt(m0^h), (p - H) / pbar)||_inf, the natural residual of
        the box (the middle value is the distance to the projection of p - g onto [0, H]).
    complementarity : sum(p g) / (sum(p) sqrt(m0^h)) (over the nodes below the cap, with one).
    min_p : min(p) / pbar (primal feasibility, >= 0 at a solution).
    min_g : min(g) / sqrt(m0^h) over the nodes below the cap (dual feasibility, >= 0 at a solution).
    load_error : |mean(p) - pbar| / pbar under load control, None under displacement control.
    min_curvature : adhesive contact: a lower bound, of the same sign, of the least curvature of the energy on the
        feasible directions over the stiffness s1 of the longest wavelength: 1 + min phi''/s1 where that is >= 0
        (any Dugdale law), else the relaxed bound where that is >= 0, else the least eigenvalue of the compliance
        times the Hessian
        (:mod:`~roughpetsc.contact.curvature`; > 0: a strict local minimum); None where not checked.
    """

    natural: float
    complementarity: float
    min_p: float
    min_g: float
    load_error: float = None
    min_curvature: float = None

    def as_dict(self):
        return asdict(self)


# -log_view: every call (the certificate of each result; each iteration of the TAO types' convergence test)
@PETSc.Log.EventDecorator("RPKKTCheck")
def report(comm, pressure, gap, n_total, target_pbar=None, upper=None):
    """KKT report of local arrays ``pressure``, ``gap`` (scaled units, rms height 1).

    ``target_pbar``: the prescribed mean pressure (None under displacement control: the solution's own mean).
    ``upper``: the hardness cap in the same units (None: no upper bound).
    """
    pressure, gap = pressure.ravel(), gap.ravel()
    residual, high = np.empty_like(pressure), np.empty_like(pressure)
    sum_p, sum_pg = allsum(comm, [pressure.sum(), np.dot(pressure, gap)])
    mean_p = sum_p / n_total
    scale = target_pbar if target_pbar else (mean_p if mean_p > 0 else 1.0)
    np.multiply(pressure, 1.0 / scale, out=residual)
    if upper is None:
        np.minimum(residual, gap, out=residual)
    else:
        # mid(p, g, p - H) = min(max(g, p - H), p) since p - H < p (in units of the scale).
        np.subtract(residual, upper / scale, out=high)
        np.maximum(gap, high, out=high)
        np.minimum(high, residual, out=residual)
    natural, = allmax(comm, [max(residual.max(initial=0.0), -residual.min(initial=0.0))])
    if upper is not None:
        # The capped nodes leave sum(p g) and min(g) through their mask in single passes: this runs every
        # iteration of a capped TAO solve, and numpy's reductions with where= are several times slower.
        at_cap = np.greater_equal(pressure, upper, out=high.view(np.bool_)[:pressure.size])
        capped_pg, = allsum(comm, [np.einsum("i,i,i->", at_cap, pressure, gap)])
        sum_pg -= capped_pg
    if upper is None:
        min_g_local = gap.min(initial=np.inf)
    else:
        lifted = np.multiply(at_cap, np.finfo(np.float64).max, out=residual)  # capped nodes out of min(g)
        lifted += gap
        min_g_local = lifted.min(initial=np.inf)
    min_p, min_g = allmin(comm, [pressure.min(initial=np.inf), min_g_local])
    min_p /= scale
    return KKTReport(
        natural=float(natural),
        complementarity=float(sum_pg / sum_p) if sum_p > 0 else 0.0,
        min_p=float(min_p),
        min_g=float(min_g),
        load_error=None if target_pbar is None else float(abs(mean_p - target_pbar) / target_pbar),
    )


# The note of describe_stop (roughpetsc.solvers.stopping) that quotes the residual of the solver's best iterate.
BEST_NOTE = re.compile(r"best (of natural residual, load error|natural residual) [^,)]+")


def certified(reason, kkt, rtol, load_name="load error", gradient="gap"):
    """``(converged, reason)`` of a result whose certificate, on a fresh ``gradient``, is ``kkt``.

    Converged: the natural residual and the load error are at most ``rtol``; the solver's ``reason`` stands.
    Otherwise a reason whose solver's own test passed becomes ``NOT_CERTIFIED``. Either way the reason quotes
    the certificate (which the files record) in place of the solver's own best residual: a stop on the time
    limit whose best iterate passes said "best ... 3.7e-07" beside a certified 6.2e-10.
    """
    measured = f"natural residual {kkt.natural:.2g}"
    if kkt.load_error is not None:
        measured += f", {load_name} {kkt.load_error:.2g}"
    reason = BEST_NOTE.sub(measured, reason, count=1)
    if kkt.natural <= rtol and (kkt.load_error is None or kkt.load_error <= rtol):
        return True, reason
    if reason.startswith(("CONVERGED", "COMPLETE")):
        reason = f"NOT_CERTIFIED ({reason}, but on a fresh {gradient}: {measured})"
    return False, reason


class CompositeCriterion:
    """The dissertation's composite convergence criterion (3.47)-(3.51), evaluated per iteration as a TAO monitor.

    (3.47) ||p^k - p^(k-1)||_2 / ||p^k||_2 < 5e-5;
    (3.48) |A^k - A^(k-1)| / A^k < 2 / (Nx Ny);
    (3.51) sigma_h < min(1e-4 sqrt(m0^h), 0.01 gbar), sigma_h the rms gap (3.50) over the contact nodes
           (the dissertation's 1/N read as 1/|contact set|).
    (3.49), monotone A* and gbar along a path, is checked by the callers that have a path (ensembles).

    ``gap_of(x)``: the gap (scaled, local) of iterate ``x``. ``rows``: (iteration, (3.47), (3.48), sigma_h, its
    bound, natural residual or nan); ``first``: the first iteration where (3.47), (3.48) and (3.51) all hold.
    """

    def __init__(self, comm, n_total, gap_of, natural_of=None):
        self.comm = comm
        self.n_total = n_total
        self.gap_of = gap_of
        self.natural_of = natural_of
        self.previous = None
        self.previous_area = None
        self.rows = []
        self.first = None

    def __call__(self, tao):
        x = tao.getSolution()
        p = x.getArray(readonly=True)
        g = self.gap_of(x)
        contact = p > 0
        if self.previous is None:
            self.previous, change2 = np.array(p), np.inf
        else:
            np.subtract(p, self.previous, out=self.previous)  # the change, in the buffer of the previous iterate
            change2 = np.dot(self.previous, self.previous)
        p_norm2, change2, n_contact, gap_sum, gap2_contact = allsum(self.comm, [
            np.dot(p, p), change2, np.count_nonzero(contact), g[~contact].sum(), np.dot(g[contact], g[contact])])
        area = n_contact / self.n_total
        relative_change = float(np.sqrt(change2 / p_norm2)) if p_norm2 > 0 else np.inf
        area_change = abs(area - self.previous_area) / area if self.previous_area is not None and area else np.inf
        sigma = float(np.sqrt(gap2_contact / n_contact)) if n_contact else 0.0
        bound = min(1e-4, 0.01 * gap_sum / self.n_total)
        iteration = tao.getIterationNumber()
        natural = self.natural_of(x, g) if self.natural_of else float("nan")
        self.rows.append((iteration, relative_change, area_change, sigma, bound, natural))
        if self.first is None and relative_change < 5e-5 and area_change < 2.0 / self.n_total and sigma < bound:
            self.first = iteration
        np.copyto(self.previous, p)
        self.previous_area = area
