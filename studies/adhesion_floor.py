"""The floor of the adhesive solve: what it costs once the final contact set is known (issue 39, item 6).

    .venv/bin/python studies/adhesion_floor.py [--n 512 ...] [--rtol 1e-8] [--reference-rtol 1e-10]

The cases of ``studies/adhesion_cost.py`` (group #1 surface, E* = 1, g* = 1.5, 1 and 0.5; the exponential law
weak, strong and short). For each case, and for the non-adhesive problem at the same mean gap:

- *the solve*: the default solver to ``--rtol`` from the rigid start (the gap CG, or Polonsky-Keer for the
  non-adhesive problem), its FFT pairs with and without the certificate;
- *the exact contact set* C: that of the same solve to ``--reference-rtol`` (the gap's zeros; Polonsky-Keer's
  pressure > 0), with the number of nodes where the ``--rtol`` solve's set differs;
- *the oracle floor*: the same preconditioned nonlinear CG as the gap CG (Polak-Ribiere, the compliance as the
  preconditioner, the energy's Armijo line search from the Newton step along the direction) with the set fixed
  to C: g = 0 on C, the free set F = the rest, no projection. From the rigid start (projected onto the mean gap
  as the gap CG's, then set to 0 on C and shifted on F) until the natural residual on the whole grid
  (:meth:`~roughpetsc.contact.AdhesiveProblem.natural`) is at most ``--rtol`` on a fresh S g. Pairs = the first
  S g, two per iteration (C r, S t), the refreshes and the fresh confirmation. It is what the solve would cost if
  the contact set were known from the start: the set search costs the rest;
- *the spectrum* of the preconditioned Hessian C H, H = S + diag(phi''(g)) at the solution, on F (zero mean):
  the extreme Ritz values of linear PCG on H from the rigid start's gradient, to a reduction of 1e-10
  (:func:`pk_cascade.lanczos_extremes`). Preconditioned CG needs about sqrt(cond) iterations per decade.

Where the fixed set's energy, without the bound g >= 0, has lower stationary points at negative gaps (a free
node next to the contact where S_ii + phi''(g) < 0), the oracle runs into them and stops short: the floor is then
not defined, and the table says so. Serial only (a study of counts, not of scaling).

Output: studies/output/adhesion/floor.md (and floor.json, the rows).
"""

import argparse
import json
import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

import adhesion_cost
import common

REFRESH = 50  # S g afresh every REFRESH iterations, as the gap CG
ARMIJO, MAX_BACKTRACKS = 1e-4, 40
SPECTRUM_RTOL = 1e-10


# What the table does not show (measured once, 2026-11-28, N = 512), for the report.
NOTES = [
    "## Reading the table", "",
    "- Where the oracle floor is 'none', the fixed set's energy without the bound g >= 0 has stationary points "
    "at negative gaps that the CG runs into: a node of the free set next to the contact, where the law's "
    "concavity exceeds the stiffness (S_ii + phi''(g) < 0: the short law; the strong law at N <= 256), is pulled "
    "through g = 0. The floor is then not defined; the solve itself is within 3x for those laws at N = 512.",
    "- The oracle's pairs move with the round-off of the FFT plans, as the solves' do: two runs gave 165 / 254 / "
    "276 and 165 / 258 / 276 pairs for the strong law at N = 512.",
    "- The gap CG itself from the oracle's start (the rigid gap with the exact set imposed, the bound kept) is no "
    "floor: its set still changes, and before the line search below it took 236 / 344 / 348 pairs for the "
    "strong law at N = 512, against "
    "165 / 254 / 276 with the set fixed and 334 / 371 / 369 from the rigid start. For the short law at g* = 0.5 "
    "it stagnates at a natural residual of 3.2 (60 iterations, 6579 pairs): every projected step raises the "
    "energy, and halving it until no gap crosses 0 costs a pair a halving. Going straight to the first breakpoint "
    "instead bounded an iteration to 3 pairs but did not end the stagnation (1000 iterations at 3.2), and it "
    "stopped a Dugdale sphere path of the tests (a step below the gaps' round-off changes the law's energy by 0 "
    "and the elastic energy by more, so the line search fails). The line search now in the solver tries 8 "
    "projected steps an iteration, then the first breakpoint, and where that is below round-off puts every gap "
    "at round-off that the direction closes into contact: from this start it takes 318 / 458 / 496 pairs for "
    "the strong law and 121 / 175 / 208 for the short law at g* = 1.5 / 1 / 0.5, all certified (its energies "
    "within 0.2 % of the reference solves'). The short law's stagnation came from 97965 gaps the imposed set "
    "left at round-off (1e-17), which blocked every projected step: one closing of them ends it, where closing "
    "one breakpoint's gap an iteration still stagnated at 3.2 (1000 iterations, 10022 pairs).", ""]


@dataclass
class OracleRun:
    """A fixed-set run: pairs, iterations, the natural residual reached, and whether it reached ``rtol``."""

    pairs: int = 0
    iterations: int = 0
    natural: float = math.inf
    converged: bool = False
    history: list = field(default_factory=list)


class FixedSet:
    """The energy of the gap on a fixed free set F of ``problem`` (a ContactProblem, scaled units), with the
    scaled adhesive ``law`` or none: g = 0 off F, the mean gap ``target``.

    ``Pi(g) = 1/2 <g + h, S (g + h)> + <phi(g)>`` (:mod:`roughpetsc.contact.adhesive`); its gradient
    r = S (g + h) + phi'(g), the multiplier the mean of r on F.
    """

    def __init__(self, problem, law, free, target):
        self.problem, self.law, self.free, self.target = problem, law, free, target
        self.count = int(np.count_nonzero(free))
        self.scale = math.sqrt(problem.m0p_scaled)
        self.gap_vec, self.elastic_vec = problem.vec(), problem.vec()
        self.direction_vec, self.response_vec = problem.vec(), problem.vec()
        self.residual_vec, self.preconditioned_vec = problem.vec(), problem.vec()
        self.g = problem.local(self.gap_vec).ravel()
        self.elastic = problem.local(self.elastic_vec).ravel()
        self.t = problem.local(self.direction_vec).ravel()
        self.response = problem.local(self.response_vec).ravel()

    def destroy(self):
        for v in (self.gap_vec, self.elastic_vec, self.direction_vec, self.response_vec, self.residual_vec,
                  self.preconditioned_vec):
            v.destroy()

    def start_rigid(self):
        """The gap CG's rigid start, then 0 off F and shifted on F to the mean gap."""
        from roughpetsc.solvers.gap_cg import project_mean

        problem, g = self.problem, self.g
        g[...] = self.target - problem.local(problem.heights, readonly=True).ravel()
        project_mean(problem.mpi, g, self.target, problem.n)
        g[~self.free] = 0.0
        g[self.free] += (problem.n * self.target - g.sum()) / self.count

    def refresh(self):
        """``elastic = S (g + h)``: one pair."""
        self.problem.operator.elastic_pressure(self.gap_vec, self.elastic_vec)
        self.elastic += self.problem.local(self.problem.pressure_surface, readonly=True).ravel()

    def gradient(self):
        """r = S (g + h) + phi'(g), phi continued below g = 0 by its tangent (as the line search's energy)."""
        r = self.elastic.copy()
        if self.law is not None:
            r += self.law.force(np.maximum(self.g, 0.0))
        return r

    def natural(self, r):
        """The natural residual on the whole grid, as the adhesive problem's; and the multiplier."""
        lam = r[self.free].mean()
        return float(np.max(np.abs(np.minimum(self.g, (r - lam) / self.scale)))), lam

    def on_free(self, v):
        """``v`` restricted to F at zero mean there (in place)."""
        v[~self.free] = 0.0
        v[self.free] -= v[self.free].mean()
        return v

    def precondition(self, r_free):
        """``C r`` on F, zero mean there (a new array): one pair."""
        self.problem.local(self.residual_vec).ravel()[...] = r_free
        self.problem.operator.displacement(self.residual_vec, self.preconditioned_vec)
        return self.on_free(self.problem.local(self.preconditioned_vec, readonly=True).ravel().copy())

    def stiffness_along(self):
        """``response = S t``: one pair."""
        self.problem.operator.elastic_pressure(self.direction_vec, self.response_vec)

    def law_curvature(self, g, t):
        return 0.0 if self.law is None else float(np.sum(self.curvature(g) * t * t))

    def curvature(self, g):
        """phi''(g), 0 below g = 0 (the tangent's)."""
        return np.where(g > 0, self.law.curvature(np.maximum(g, 0.0)), 0.0)

    def law_change(self, g, t, step):
        """sum phi(g - step t) - phi(g), phi continued below 0 by its tangent at both ends (the law's own sum
        continues the trial only: the gap CG's g is never negative, the oracle's may be), free of cancellation:
        the tangent parts' difference and the law's change between the clipped gaps."""
        if self.law is None:
            return 0.0
        trial = g - step * t
        below = (trial - np.maximum(trial, 0.0)) - (g - np.maximum(g, 0.0))
        return float(self.law.peak_stress * below.sum() +
                     self.law.energy_change(np.maximum(g, 0.0), np.maximum(trial, 0.0)).sum())


def oracle_cg(fixed, rtol, max_it=5000):
    """The gap CG with the contact set fixed (the module's docstring): an :class:`OracleRun`."""
    operator = fixed.problem.operator
    start = operator.applications
    run = OracleRun()
    fixed.start_rigid()
    fixed.refresh()
    fresh, since_fresh, rz_old = True, 0, 1.0
    r_old = np.zeros_like(fixed.g)
    t = fixed.t
    t[...] = 0.0
    while run.iterations < max_it:
        r = fixed.gradient()
        natural, lam = fixed.natural(r)
        run.history.append((run.iterations, natural, operator.applications - start))
        if natural <= rtol:
            if fresh:
                run.converged = True
                break
            fixed.refresh()
            fresh, since_fresh = True, 0
            continue
        if since_fresh >= REFRESH:
            fixed.refresh()
            fresh, since_fresh = True, 0
            continue
        r_free = fixed.on_free(r - lam)
        z = fixed.precondition(r_free)
        rz = float(np.dot(r_free, z))
        beta = max((rz - float(np.dot(r_old, z))) / rz_old, 0.0) if run.iterations else 0.0
        rz_old = rz
        r_old = r_free
        t *= beta
        t += z
        slope = float(np.dot(r_free, t))
        if not slope > 0:
            t[...] = z
            slope = rz
        fixed.stiffness_along()
        curvature_elastic = float(np.dot(t, fixed.response))
        elastic_slope = float(np.dot(t, fixed.elastic))
        curvature = curvature_elastic + fixed.law_curvature(fixed.g, t)
        step = slope / (curvature if curvature > 0 else curvature_elastic)
        for _ in range(MAX_BACKTRACKS):
            change = step * (0.5 * step * curvature_elastic - elastic_slope) + fixed.law_change(fixed.g, t, step)
            if change <= -ARMIJO * step * slope:
                break
            step *= 0.5
        else:
            break
        fixed.g -= step * t
        fixed.elastic -= step * fixed.response
        fresh, since_fresh = False, since_fresh + 1
        run.iterations += 1
    run.natural = run.history[-1][1]
    run.pairs = operator.applications - start
    return run


def hessian_spectrum(fixed, rtol=SPECTRUM_RTOL, max_it=3000):
    """Extreme Ritz values of C H on F at the current gap (H = S + diag(phi'')), and PCG's iterations: the
    coefficients of linear PCG on H x = b, b the rigid start's gradient on F (x itself is not needed; the gap is
    restored)."""
    import pk_cascade

    solution = fixed.g.copy()
    curvature = np.zeros_like(solution) if fixed.law is None else fixed.curvature(solution)
    fixed.start_rigid()
    fixed.refresh()
    b = fixed.on_free(fixed.gradient())
    fixed.g[...] = solution

    def hessian(v):
        fixed.t[...] = v
        fixed.stiffness_along()
        return fixed.on_free(fixed.response + curvature * v)

    r = b.copy()
    z = fixed.precondition(r)
    p = z.copy()
    rz = float(np.dot(r, z))
    norm0 = math.sqrt(float(np.dot(r, r)))
    alphas, betas = [], [0.0]
    for _ in range(max_it):
        q = hessian(p)
        alpha = rz / float(np.dot(p, q))
        alphas.append(alpha)
        r -= alpha * q
        if math.sqrt(float(np.dot(r, r))) <= rtol * norm0:
            break
        z = fixed.precondition(r)
        rz_new = float(np.dot(r, z))
        beta = rz_new / rz
        betas.append(beta)
        rz = rz_new
        p = z + beta * p
    low, high, steps = pk_cascade.lanczos_extremes(alphas, betas[:len(alphas)])
    return low, high, steps


def exact_free_set(problem, law, gbar, rtol):
    """``(free mask, solution gap scaled, result)`` of the default solver to ``rtol`` from the rigid start."""
    from roughpetsc import Solver
    from roughpetsc.contact import AdhesiveProblem

    if law is None:
        solver = Solver(problem, "displacement", "pk", rtol)
    else:
        solver = Solver(AdhesiveProblem(problem, law), "displacement", rtol=rtol)
    try:
        start = problem.operator.applications
        result = solver.solve(gbar=gbar)
        result.pairs_solve = int(result.history[-1, 2] - start)
        pressure, gap = solver.fields()
        free = (gap > 0) if law is not None else ~(pressure > 0)
        return free.ravel().copy(), gap.ravel() / problem.height_scale, result
    finally:
        solver.destroy()


def run_case(problem, law, gbar, args):
    """One row: the solve, the exact set, the oracle floor and the spectrum of ``law`` (None: non-adhesive)."""
    started = time.perf_counter()
    free_loose, _, result = exact_free_set(problem, law, gbar, args.rtol)
    free, solution, exact = exact_free_set(problem, law, gbar, args.reference_rtol)
    scaled = None if law is None else law.scaled(problem.height_scale, problem.pressure_scale)
    fixed = FixedSet(problem, scaled, free, gbar / problem.height_scale)
    try:
        oracle = oracle_cg(fixed, args.rtol)
        fixed.g[...] = solution
        low, high, steps = hessian_spectrum(fixed)
    finally:
        fixed.destroy()
    row = dict(law=None if law is None else law.name, pairs=result.operator_applications,
               pairs_solve=result.pairs_solve if law is not None else None, converged=bool(result.converged),
               reason=result.reason, natural=result.kkt.natural, reference_converged=bool(exact.converged),
               reference_natural=exact.kkt.natural, contact=int((~free).sum()),
               set_difference=int(np.count_nonzero(free != free_loose)), oracle_pairs=oracle.pairs,
               oracle_iterations=oracle.iterations, oracle_natural=oracle.natural, oracle_converged=oracle.converged,
               lambda_min=low, lambda_max=high, cond=high / low, lanczos_steps=steps)
    row["seconds"] = time.perf_counter() - started
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[512])
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--reference-rtol", type=float, default=1e-10)
    args = parser.parse_args()
    common.init()
    rows = []
    for n in args.n:
        problem = common.group1_problem(n)
        try:
            for gstar in adhesion_cost.GSTARS:
                gbar = gstar * problem.sqrt_m0h
                cases = [("none", None)] + [(case, law) for case, law in adhesion_cost.laws(problem)
                                            if law.name == "exponential"]
                for case, law in cases:
                    row = dict(n=n, gstar=gstar, case=case, **run_case(problem, law, gbar, args))
                    rows.append(row)
                    print(json.dumps(row), flush=True)
        finally:
            problem.destroy()
    write(rows, args)


def table_row(row, pk):
    """A line of floor.md: ``pk`` the pairs of Polonsky-Keer's solve at the same N and g*."""
    adhesive = row["pairs_solve"] is not None
    law = row["case"] if adhesive else "non-adhesive (PK)"
    parts = f"{row['pairs_solve']}, {row['pairs'] - row['pairs_solve']}" if adhesive else "-"
    cells = [f"{row['n']}", f"{row['gstar']:g}", law, f"{row['pairs']} ({parts})", f"{row['pairs'] / pk:.2f}"]
    if row["oracle_converged"]:
        certificate = row["pairs"] - row["pairs_solve"] if adhesive else 0
        cells += [f"{row['oracle_pairs']} ({row['oracle_iterations']})", f"{row['oracle_pairs'] / pk:.2f}",
                  f"{(row['oracle_pairs'] + certificate) / pk:.2f}" if adhesive else "-"]
    else:
        cells += [f"none: stops at {row['oracle_natural']:.1e} after {row['oracle_iterations']} iterations", "-", "-"]
    cells += [f"{row['contact']}", f"{row['set_difference']}",
              f"{row['lambda_min']:.3f} / {row['lambda_max']:.2f} ({row['cond']:.1f})"]
    return "| " + " | ".join(cells) + " |"


def write(rows, args):
    out = os.path.join(common.OUTPUT, "adhesion")
    with open(os.path.join(out, "floor.json"), "w") as f:
        json.dump(dict(args=vars(args), rows=rows), f, indent=1)
    reference = {(row["n"], row["gstar"]): row["pairs"] for row in rows if row["case"] == "none"}
    lines = ["# The adhesive solve against its floor on the exact contact set", "",
             f"Generated by `.venv/bin/python studies/adhesion_floor.py --n {' '.join(map(str, args.n))} --rtol "
             f"{args.rtol:g} --reference-rtol {args.reference_rtol:g}` (definitions in the module docstring). FFT "
             "pairs, deterministic; ratios over Polonsky-Keer's solve of the non-adhesive problem at the same N and "
             "mean gap (issue 39, item 6: at most 3x at N = 512). 'solve': the default solver from the rigid start, "
             "its pairs (before the certificate, of the certificate); 'oracle floor': the same CG with the final "
             "contact set fixed, its pairs (iterations); '+ certificate': the oracle floor and the solve's "
             "certificate; 'set difference': nodes where the set at the solve's tolerance differs from the exact "
             "one; the spectrum is that of the compliance times the Hessian on the free set at the solution "
             "(for the non-adhesive row, the compliance times the stiffness).", "",
             "| N | g* | law | solve pairs (solve, certificate) | / PK | oracle floor pairs (iterations) | / PK | "
             "+ certificate / PK | \\|C\\| | set difference | C H on F: lambda_min / lambda_max (cond) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [table_row(row, reference[row["n"], row["gstar"]]) for row in rows] + [""] + NOTES
    with open(os.path.join(out, "floor.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
