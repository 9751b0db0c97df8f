"""Adhesive contact against Tamaas 2.9's adhesive gap solver (issue 15, item 3).

    .venv/bin/python studies/peer_adhesion.py [--sizes 128 256 512] [--tolerances 1e-8 1e-10 1e-12]

A group-#1 surface (options/group01.opts) on an n x n unit cell, E* = 1, mean gap g* = 1 (displacement
control), with the exponential and the Maugis-Dugdale laws of range 0.2 sqrt(m0^h) and peak stress 0.05
(weak) and 0.3 (moderate) sqrt(m0^p). Tamaas: ``PolonskyKeerRey`` on the gap with the mean-gap constraint and
``ExponentialAdhesionFunctional`` / ``MaugisAdhesionFunctional`` (the same laws, conventions in
studies/peers/run_peer.py), run in its own virtualenv (studies/peers/install.sh) at each of ``--tolerances``
(its own error measure). Ours: the gap CG at natural residual 1e-10, started as Tamaas starts (a uniform gap
equal to the mean gap): the problem is not convex, and its local minima depend on the start.

Each answer is judged by our natural residual computed from its fields alone (max |min(g / sqrt(m0^h),
(p + phi'(g)) / sqrt(m0^p))|), so that both codes are held to one measure; the table gives A, the mean
pressure, the energy Pi of each answer (scaled units; the lower of two local minima is the more stable),
the largest field difference from ours (over sqrt(m0^p)) and the solve times of one run each.
Output: studies/output/adhesion/peer.md.
"""

import argparse
import os
import tempfile

import numpy as np

import common

# Peak stresses of the laws over sqrt(m0^p): weak (one local minimum near the start) and moderate.
STRENGTHS = (0.05, 0.3)


def natural(problem, law, pressure, gap):
    """Our natural residual of a (pressure, gap) pair, from the fields alone."""
    excess = (pressure + law.force(gap)) / problem.sqrt_m0p
    return float(np.abs(np.minimum(gap / problem.sqrt_m0h, excess)).max())


def energy(adhesive, gap):
    """Pi of a gap field (length units), per unit area in the problem's scaled units (module roughpetsc.adhesive)."""
    problem = adhesive.problem
    g = problem.local(adhesive.gap)
    g[...] = gap / problem.height_scale
    adhesive.elastic_pressure(adhesive.gap, adhesive.elastic)
    return adhesive.energy(g, problem.local(adhesive.elastic, readonly=True))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[128, 256, 512])
    parser.add_argument("--tolerances", type=float, nargs="+", default=[1e-8, 1e-10, 1e-12])
    args = parser.parse_args()
    common.init()
    import peers
    from roughpetsc import ContactProblem, Grid
    from roughpetsc.contact.adhesive import AdhesiveContact
    from roughpetsc.contact.laws import Dugdale, Exponential

    rows = []
    with tempfile.TemporaryDirectory() as workdir:
        for n in args.sizes:
            grid = Grid(n, n)
            heights = common.group1_heights(grid)
            surface_path = os.path.join(workdir, "surface.npy")
            np.save(surface_path, heights)
            problem = ContactProblem(grid, heights, 1.0)
            range_ = 0.2 * problem.sqrt_m0h
            gbar = problem.sqrt_m0h
            for strength in STRENGTHS:
                peak = strength * problem.sqrt_m0p
                for name, law in (("exponential", Exponential(peak * range_, range_)),
                                  ("maugis", Dugdale(peak * range_, peak))):
                    adhesive = AdhesiveContact(problem, law, rtol=1e-10)
                    try:
                        result = adhesive.solve(gbar, start="uniform")
                        pressure, gap = (a.copy() for a in adhesive.fields())
                        case = {"N": n, "law": name, "peak / sqrt(m0p)": strength}
                        rows.append(dict(case, code="roughpetsc", tolerance=1e-10,
                                         natural=natural(problem, law, pressure, gap), A=result.A, pbar=result.pbar,
                                         energy=energy(adhesive, gap), **{"max |dp| / sqrt(m0p)": 0.0},
                                         **{"solve s": result.time_s}, converged=result.converged))
                        print(rows[-1], flush=True)
                        for tol in args.tolerances:
                            info, field = peers.run_peer("tamaas", surface_path, gbar, tol, workdir, 3600,
                                                         adhesion=(name, law.work, law.range))
                            difference = float(np.abs(field - pressure).max() / problem.sqrt_m0p)
                            rows.append(dict(case, code="tamaas", tolerance=tol,
                                             natural=natural(problem, law, field, info["gap"]), A=info["A"],
                                             pbar=float(field.mean()), energy=energy(adhesive, info["gap"]),
                                             **{"max |dp| / sqrt(m0p)": difference}, **{"solve s": info["solve_s"]},
                                             converged=info["converged"]))
                            print(rows[-1], flush=True)
                    finally:
                        adhesive.destroy()
            problem.destroy()
    lines = ["# Adhesive contact: roughpetsc against Tamaas 2.9", "",
             f"Generated by `.venv/bin/python studies/peer_adhesion.py --sizes {' '.join(map(str, args.sizes))} "
             f"--tolerances {' '.join(f'{t:g}' for t in args.tolerances)}` (see its docstring); one run each, "
             "times in seconds on a shared machine; 'natural' is our residual measured on each code's fields.", "",
             common.records_table(rows)]
    out = os.path.join(common.OUTPUT, "adhesion")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "peer.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
