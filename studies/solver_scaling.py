"""The contact solver's floor, its spectrum, cold solves against it, and warm load steps (issue 39, items 1-4).

    .venv/bin/python studies/solver_scaling.py [--sizes 256 512 1024 2048] [--loads 0.05 0.5 2] [--groups 1 18]
        [--parts reference pk floor cold] [--floor-pcs fourier band2 band3] [--cold VARIANT ...]
        [--warm-n 1024] [--report]

Resumable: every row (one measurement) is kept in ``studies/output/solver_scaling/rows.json`` as soon as it
is made, and a row already there is not remade; ``--report`` writes ``report.md`` and the plots from the
rows alone. Every count is deterministic (FFT pairs, iterations); wall times are from one run on a shared,
loaded machine and only their ratios within one run mean anything.

Surfaces: ``options/groupNN.opts`` (``fractal_group``) at N x N with the preset's generator ``xu`` and the
command line's default seed 1, i.e. the surface of
``python -m roughpetsc -options_file options/groupNN.opts -surface_N N -pstar P``; scaled units of
:class:`~roughpetsc.ContactProblem`; tolerance: natural KKT residual 1e-8.

Parts (``--parts``):

- ``reference``: today's default solver (Polonsky-Keer, BCCG active set, Fourier preconditioner) to a natural
  residual of ``--reference-rtol`` (1e-12). Its contact set {p > 0} is *the exact final contact set* C (kept
  as a bit mask in ``--cache``, outside the repository). At N = 4096 a 1e-12 reference stopped at round-off
  (2.8e-12) after 1637 pairs, and a pair at N = 8192 takes 4-6 s here, so those cases take 1e-10: the floor run certifies
  the set it is given (its natural residual on the whole grid is 1e-8 only if C is the final set to that
  tolerance), and the ``refcheck`` cases show that the floor does not depend on the reference tolerance.
- ``pk``: today's default solver, cold from the uniform pressure (``-cascade_coarsest 0``), to 1e-8
  (``common.solve``: the Solver facade, its certificate included): iterations, FFT pairs
  (``operator.applications``), seconds.
- ``floor``: *the floor*: preconditioned CG on the fixed set C for the load-controlled QP
  (``K_CC p + d = h_C``, ``sum p = n pbar``, p = 0 off C), from the natural start (the uniform pressure
  ``n pbar / |C|`` on C: the set and nothing else is known), until the natural KKT residual of the whole
  grid, ``max |min(p/pbar, g)|`` on the updated gap, is at most 1e-8 and then on a fresh gap (the
  certificate): pairs = 1 (first K p) + 2 per iteration (B r, K t) + 1 (certificate)
  (:func:`pk_cascade.fixed_set_pcg`). CG then runs on to a residual reduction of 1e-10
  for the spectrum: the extreme eigenvalues of the preconditioned operator restricted to C (zero-sum
  subspace) are the extreme eigenvalues of the Lanczos matrix of its coefficients. One preconditioner per
  ``--floor-pcs`` name (:data:`PRECONDITIONERS`).
- ``cold``: cold solves by the prototype :class:`pk_cascade.CascadePK`, one per
  ``--cold`` variant (:data:`COLD_VARIANTS`): FFT pairs of every level weighted by (N_c/N)^2, the
  certificate included, and an independent certificate afterwards (a fresh gap through
  ``ContactProblem.gap`` and ``roughpetsc.contact.certificate.report``, not counted).
- ``pkcascade``: today's solver from the cascade start (``-cascade_coarsest 256``,
  :mod:`roughpetsc.solvers.cascade`), cold, to 1e-8: the ``pk-cascade`` column of the cold table, its coarse
  pairs weighted by (N_c / N)^2.
- ``pksplit``: today's solver with the projection's corrections by the split compliance
  (``-pk_split_radius 32``, :mod:`roughpetsc.elastic.split`), cascade start at N >= 1024: the ``pk-split``
  column, its coarse pairs (cascade levels and far fields) weighted; timed beside ``-pk_split_radius 0``.
- ``projections``: how many nodes each projected step of today's solver moves, from the uniform and the
  cascade start (:func:`run_projections`).
- ``timing``: for the seconds of the scaling table on an otherwise idle machine: after an untimed solve to
  1e-2, ``pk`` (uniform start), ``pk-cascade`` and ``pk-split`` (:data:`TIMED_SOLVERS`) one after the other in
  one process, each cold to 1e-8, with the load average before and after (``--rows rows_idle``).
- ``slepc``: the Lanczos estimates checked against SLEPc (Krylov-Schur on ``B P K_CC P``, the constant on
  C deflated) at the smallest size and load given.
- ``deflation``: what a deflation of the edge modes would need (:func:`run_deflation`): the eigenvalues of
  ``B P K_CC P`` above 5 and 10 times its least (SLEPc, the largest ones), i.e. the size of a deflation space
  that brings the restricted condition number to 5 or 10, the operator applications spent finding them, and
  C's edge nodes; one row per ``--floor-pcs`` name. Small grids: at N = 256 it takes an hour here.
- ``warm``: the load history (7.11) (95 steps) at ``--warm-n``: pairs per warm step against one cold solve
  at p* = 0.5, for today's solver (``roughpetsc.load_path``'s linear predictor) and for the prototype with
  the same predictor.
- ``warmfloor``: what limits a warm step (:func:`run_warm_floor`): CG on each step's own final contact set
  from the predicted start, at ``--warm-n`` (p* = 0.5 keys only), one preconditioner per ``--floor-pcs``.
"""

import argparse
import json
import os
import sys
import time

import numpy as np

import common

OUT = os.path.join(common.OUTPUT, "solver_scaling")
RTOL = 1e-8

# Preconditioners of the floor runs (specs of pk_cascade.make_preconditioner).
PRECONDITIONERS = {
    "fourier": "fourier",
    "band1": "band:width=1,radius=1.5,sweeps=1",
    "band2": "band:width=2,radius=1.5,sweeps=4",
    "band3": "band:width=3,radius=3.2,sweeps=8",
    "band4": "band:width=4,radius=4.5,sweeps=16",
    # Diagnostics: the band's near-field matrix solved exactly (sparse LU) instead of by Jacobi sweeps.
    "band2-lu": "band:width=2,radius=1.5,sweeps=0",
    "band8-lu": "band:width=8,radius=3.2,sweeps=0",
    # The Schur form with the whole coupling by FFT (two pairs per application) and the band's Jacobi M.
    "schur1": "schur:width=1,radius=1.5,sweeps=1,damping=1",
    "schur4": "schur:width=4,radius=3.2,sweeps=8,damping=0.5",
}

MAIN_PRECONDITIONERS = ("fourier", "band2", "band3")

# Cold-solve variants of CascadePK: every option given (the prototype's defaults are the candidate `best`).
_NEVER = 1e9  # restart_fraction: Polak-Ribiere+ throughout, never restarted
_PLAIN = dict(cascade=(), restart_fraction=_NEVER, preconditioner="fourier", prolong="bilinear", point_corrections=0)
COLD_VARIANTS = {
    "pcg": _PLAIN,
    "pcg-restart1%": dict(_PLAIN, restart_fraction=0.01),
    "cascade": dict(_PLAIN, cascade=(4, 2), prolong="signed"),
    "cascade-bilinear": dict(_PLAIN, cascade=(4, 2)),
    "cascade-restart1%": dict(_PLAIN, cascade=(4, 2), restart_fraction=0.01),
    "pcg-lazy": dict(_PLAIN, lazy_ratio=1.0),
    "pcg-clipahead": dict(_PLAIN, clip_ahead=1.0),
    "band2": dict(_PLAIN, preconditioner=PRECONDITIONERS["band2"]),
    "band3": dict(_PLAIN, preconditioner=PRECONDITIONERS["band3"]),
    "cascade-band2": dict(_PLAIN, cascade=(4, 2), prolong="signed", preconditioner=PRECONDITIONERS["band2"]),
    "cascade-band3": dict(_PLAIN, cascade=(4, 2), prolong="signed", preconditioner=PRECONDITIONERS["band3"]),
    # The prototype's candidate: cascade N/2^k down to 256, signed prolongation, edge-band preconditioner,
    # few-node projections corrected by kernel copies; and the same with the Fourier preconditioner.
    "best": dict(cascade="auto", coarsest=256, restart_fraction=_NEVER, prolong="signed",
                 preconditioner=PRECONDITIONERS["band2"], point_corrections=16),
    "best-fourier": dict(cascade="auto", coarsest=256, restart_fraction=_NEVER, prolong="signed",
                         preconditioner="fourier", point_corrections=16),
    "best-tight": dict(cascade="auto", coarsest=256, coarse_rtol=1e-4, restart_fraction=_NEVER, prolong="signed",
                       preconditioner=PRECONDITIONERS["band2"], point_corrections=16),
    "best-band3": dict(cascade="auto", coarsest=256, restart_fraction=_NEVER, prolong="signed",
                       preconditioner=PRECONDITIONERS["band3"], point_corrections=16),
    # The fresh K p after a projection split in two: its near field (offsets up to 16 nodes) added at once by
    # the real-space kernel (no pair), its far field by one pair only when its bound max|K_far| sum(c) passes
    # far_ratio times the residual (`near16`), or only at the end (`near16-deferred`); `cascade-fourier` is
    # the same cascade with every correction by a pair.
    "cascade-fourier": dict(_PLAIN, cascade="auto", coarsest=256, prolong="signed"),
    "near16": dict(_PLAIN, cascade="auto", coarsest=256, prolong="signed", near_radius=16, far_ratio=1.0),
    "near16-deferred": dict(_PLAIN, cascade="auto", coarsest=256, prolong="signed", near_radius=16,
                            far_ratio=_NEVER),
    # The split kept whole: the far field on the grid coarsened 4 times at once (1/16 pair), and a fresh K p
    # when the residual has fallen 100 times since the last (`split32`, what -pk_split_radius 32 does), or never
    # before the certificate (`split32-norefresh`).
    "split32": dict(_PLAIN, cascade="auto", coarsest=256, prolong="signed", near_radius=32, split_coarsening=4,
                    refresh_ratio=1e-2),
    "split32-norefresh": dict(_PLAIN, cascade="auto", coarsest=256, prolong="signed", near_radius=32,
                              split_coarsening=4),
}


# --- problems and the reference contact set ----------------------------------------------------------------
def make_problem(group, n):
    """The surface of ``options/groupNN.opts`` at n x n (generator xu, seed 1), E* = 1, one process."""
    from petsc4py import PETSc

    from roughpetsc import ContactProblem, Grid, fractal, fractal_group

    preset = fractal_group(group)
    grid = Grid(n, n, preset["length"], preset["length"])
    heights = fractal(grid, preset["k_l"], preset["k_s"], preset["hurst"], preset["m2"], seed=1, generator="xu")
    return ContactProblem(grid, heights, 1.0, PETSc.COMM_SELF)


def case_key(group, n, pstar):
    return f"g{group:02d}_N{n}_p{pstar:g}"


REFERENCE_RTOL = 1e-12


def reference_variant(rtol):
    return f"pk {rtol:g}"


def contact_path(cache, key, rtol):
    suffix = "" if rtol == REFERENCE_RTOL else f"_ref{rtol:g}"
    return os.path.join(cache, key + suffix + ".contact.npz")


def reference_contact(problem, pstar, cache, key, rows, path, rtol=REFERENCE_RTOL):
    """The exact final contact set of the case (bool, flat): from the cache, or by today's solver to ``rtol``."""
    file = contact_path(cache, key, rtol)
    if os.path.exists(file):
        with np.load(file) as saved:
            return np.unpackbits(saved["bits"], count=problem.n).astype(bool)
    result, pressure, seconds = common.solve(problem, {"pk_split_radius": 0}, rtol, pstar=pstar)
    contact = pressure.ravel() > 0
    os.makedirs(cache, exist_ok=True)
    np.savez(file + ".partial.npz", bits=np.packbits(contact))
    os.replace(file + ".partial.npz", file)
    add_row(rows, path, dict(part="reference", key=key, variant=reference_variant(rtol), iterations=result.iterations,
                             pairs=result.operator_applications, natural=result.kkt.natural, A=result.A,
                             contact=int(contact.sum()), converged=result.converged, seconds=seconds))
    return contact


# --- rows -------------------------------------------------------------------------------------------------
def has_row(rows, part, key, variant, **fields):
    return any(r["part"] == part and r["key"] == key and r["variant"] == variant
               and all(r.get(k, REFERENCE_RTOL if k == "reference" else None) == v for k, v in fields.items())
               for r in rows)


def add_row(rows, path, row):
    rows.append(row)
    common.save_rows(path, rows)
    print(" ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items()), flush=True)


def parse_key(key):
    group, n, pstar = key.split("_")
    return int(group[1:]), int(n[1:]), float(pstar[1:])


# --- parts ------------------------------------------------------------------------------------------------
def run_pk(problem, pstar, key, rows, path):
    result, _, seconds = common.solve(problem, {"cascade_coarsest": 0, "pk_split_radius": 0}, RTOL, pstar=pstar)
    add_row(rows, path, dict(part="pk", key=key, variant="pk", iterations=result.iterations,
                             pairs=result.operator_applications, natural=result.kkt.natural,
                             converged=result.converged, seconds=seconds))


def fine_heights(problem):
    return problem.local(problem.heights, readonly=True).copy()


def run_floor(problem, pstar, contact, key, name, rows, path, reference=REFERENCE_RTOL):
    import pk_cascade

    n = problem.grid.n0
    level = pk_cascade.Level(fine_heights(problem), n)
    try:
        start = time.perf_counter()
        preconditioner = pk_cascade.make_preconditioner(level, PRECONDITIONERS[name])
        run = pk_cascade.fixed_set_pcg(level, contact, problem.scaled_pbar(pstar=pstar), preconditioner, RTOL,
                                       extra_rtol=1e-10)
        seconds = time.perf_counter() - start
        low, high, steps = pk_cascade.lanczos_extremes(run.alphas, run.betas)
    finally:
        level.destroy()
    add_row(rows, path, dict(part="floor", key=key, variant=name, pairs=run.pairs, iterations=run.iterations,
                             certified=run.certified, lambda_min=low, lambda_max=high, cond=high / low,
                             lanczos_steps=steps, contact=int(contact.sum()), reference=reference,
                             seconds=seconds))


def certify(problem, pressure, separation, pbar):
    """The natural residual and load error of a scaled pressure on a fresh gap (one uncounted pair)."""
    from roughpetsc.contact.certificate import report

    p_vec, gap = problem.vec(), problem.vec()
    try:
        problem.local(p_vec)[...] = pressure.reshape(problem.operator.local_shape)
        problem.gap(p_vec, separation, gap)
        kkt = report(problem.mpi, problem.local(p_vec, readonly=True), problem.local(gap, readonly=True),
                     problem.n, pbar)
    finally:
        p_vec.destroy()
        gap.destroy()
    return kkt


def run_cold(problem, pstar, key, name, rows, path):
    import pk_cascade

    pbar = problem.scaled_pbar(pstar=pstar)
    start = time.perf_counter()
    solver = pk_cascade.CascadePK(fine_heights(problem), **COLD_VARIANTS[name])
    setup = time.perf_counter() - start
    try:
        start = time.perf_counter()
        result = solver.solve(pbar, RTOL)
        seconds = time.perf_counter() - start
    finally:
        solver.destroy()
    kkt = certify(problem, result.pressure, result.separation, pbar)
    levels = "; ".join(f"{lv.n}: {lv.iterations} its {lv.pairs} pairs {lv.corrections} corr" for lv in result.levels)
    add_row(rows, path, dict(part="cold", key=key, variant=name, pairs=result.pairs,
                             iterations=result.levels[-1].iterations, natural=kkt.natural,
                             load_error=kkt.load_error,
                             converged=bool(kkt.natural <= RTOL and kkt.load_error <= RTOL),
                             levels=levels, seconds=seconds, setup_seconds=setup))


def paired_solves(problem, pstar, option_sets, rtol=RTOL):
    """One cold solve per set of solver options, one after the other in this run: ``[(Result, seconds)]``."""
    from roughpetsc import Solver

    measured = []
    for options in option_sets:
        solver = Solver(problem, "load", None, rtol, options=options)
        try:
            start = time.perf_counter()
            measured.append((solver.solve(pstar=pstar), time.perf_counter() - start))
        finally:
            solver.destroy()
    return measured


def run_pk_cascade(problem, pstar, key, rows, path, coarsest=256):
    """Today's solver from the cascade start (:mod:`roughpetsc.solvers.cascade`, ``-cascade_coarsest``), the
    variant ``pk-cascade`` of the cold table: the fine grid's pairs (its certificate included) plus the coarse
    levels' weighted by (N_c / N)^2; timed beside a solve from the uniform start in the same run (the coarse
    grids' set-up and FFTW plans inside the cascade's time)."""
    # paired: the same run times both starts
    (uniform, uniform_seconds), (result, seconds) = paired_solves(
        problem, pstar, [{"cascade_coarsest": 0, "pk_split_radius": 0},
                         {"cascade_coarsest": coarsest, "pk_split_radius": 0}])
    add_row(rows, path, dict(part="cold", key=key, variant="pk-cascade",
                             pairs=result.operator_applications + result.cascade_applications,
                             fine_pairs=result.operator_applications, coarse_pairs=result.cascade_applications,
                             iterations=result.iterations, natural=result.kkt.natural,
                             converged=bool(result.converged and uniform.converged), seconds=seconds,
                             uniform_pairs=uniform.operator_applications, uniform_seconds=uniform_seconds))


def run_pk_split(problem, pstar, key, rows, path):
    """Today's solver with ``-pk_split_radius 32``, the variant ``pk-split`` of the cold table: the cascade
    start where it is the default (N >= 1024) and the projection's corrections by the split compliance
    (:mod:`roughpetsc.elastic.split`); pairs = the grid's (the split's set-up pair and the certificate
    included) + the coarse levels' + the split's coarse far fields', each weighted by its grid's size. Timed
    beside the solver without the split (``-pk_split_radius 0``) in the same run."""
    (fresh, fresh_seconds), (result, seconds) = paired_solves(
        problem, pstar, [{"pk_split_radius": 0}, {"pk_split_radius": 32}])
    add_row(rows, path, dict(part="cold", key=key, variant="pk-split",
                             pairs=result.operator_applications + result.cascade_applications
                             + result.split_applications,
                             fine_pairs=result.operator_applications, coarse_pairs=result.cascade_applications,
                             split_pairs=result.split_applications,
                             iterations=result.iterations, natural=result.kkt.natural,
                             converged=bool(result.converged and fresh.converged), seconds=seconds,
                             fresh_pairs=fresh.operator_applications + fresh.cascade_applications,
                             fresh_seconds=fresh_seconds))


# The solvers of the `timing` part, each cold to 1e-8: from the uniform start, from the cascade start, and with
# the split compliance (the cascade start where it is the default, N >= 1024).
TIMED_SOLVERS = (("pk", {"cascade_coarsest": 0, "pk_split_radius": 0}),
                 ("pk-cascade", {"cascade_coarsest": 256, "pk_split_radius": 0}),
                 ("pk-split", {"pk_split_radius": 32}))


def run_timing(problem, pstar, key, rows, path):
    """The solvers of :data:`TIMED_SOLVERS` one after the other in one process, for the seconds of the scaling
    table on an otherwise idle machine: one row each, with the 1-minute load average before and after the
    case (this process counts 1). An untimed solve to 1e-2 first: the process's first solve pays one-off costs
    (the fine grid's transforms planned, first touches) that would otherwise fall on the first solver timed."""
    paired_solves(problem, pstar, [TIMED_SOLVERS[0][1]], rtol=1e-2)
    load_before = os.getloadavg()[0]
    measured = paired_solves(problem, pstar, [options for _, options in TIMED_SOLVERS])
    load_after = os.getloadavg()[0]
    for (name, _), (result, seconds) in zip(TIMED_SOLVERS, measured):
        coarse = result.cascade_applications + result.split_applications
        add_row(rows, path, dict(part="timing", key=key, variant=name, iterations=result.iterations,
                                 pairs=result.operator_applications + coarse, fine_pairs=result.operator_applications,
                                 natural=result.kkt.natural, converged=bool(result.converged), seconds=seconds,
                                 load_before=load_before, load_after=load_after,
                                 started=time.strftime("%Y-%m-%d %H:%M", time.gmtime())))


def run_projections(problem, pstar, key, rows, path, coarsest=256):
    """How many nodes each projected step moves, for today's solver from the uniform and the cascade start.

    Every step whose projection moved p costs a fresh K p (one pair); the counts say whether correcting u by
    shifted kernel copies instead (no pair for a few nodes, about one sweep of the grid per node) could save
    those pairs. The solver's step kernel is wrapped for the count (the study's own instrument).
    """
    from roughpetsc import Solver
    from roughpetsc.contact import loops

    moved, take_step = [], loops.take_step

    def counting_step(*args):
        clipped, total = take_step(*args)
        moved.append(clipped)
        return clipped, total

    for name, value in (("uniform", 0), ("cascade", coarsest)):
        loops.take_step = counting_step
        solver = Solver(problem, "load", None, RTOL, options={"cascade_coarsest": value, "pk_split_radius": 0})
        try:
            moved.clear()
            result = solver.solve(pstar=pstar)
        finally:
            loops.take_step = take_step
            solver.destroy()
        fine = np.array(moved[-result.iterations:]) if result.iterations else np.zeros(0, int)
        steps = fine[fine > 0]
        add_row(rows, path, dict(part="projections", key=key, variant=name, iterations=result.iterations,
                                 pairs=result.operator_applications, moving_steps=int(steps.size),
                                 at_most_16=int((steps <= 16).sum()), at_most_64=int((steps <= 64).sum()),
                                 median_moved=float(np.median(steps)) if steps.size else 0.0))


def restricted_operator(problem, contact, name):
    """``(apply, count, destroy)``: x -> B P K_CC P x on the zero-sum subspace of C (vectors of C's ``count``
    nodes), B the preconditioner ``name`` of :data:`PRECONDITIONERS`; ``destroy()`` frees its level. Each
    application is one FFT pair (K) and the preconditioner's; ``apply.calls`` counts them."""
    import pk_cascade

    level = pk_cascade.Level(fine_heights(problem), problem.grid.n0)
    preconditioner = pk_cascade.make_preconditioner(level, PRECONDITIONERS[name])
    preconditioner.setup(contact)
    free = np.flatnonzero(contact)
    count = free.size
    full, response, out = np.zeros(problem.n), np.zeros(problem.n), np.zeros(problem.n)

    def apply(x):
        apply.calls += 1
        full[...] = 0.0
        full[free] = x
        pk_cascade.remove_mean_on(full, contact, count)
        level.compliance(full, response)
        pk_cascade.remove_mean_on(response, contact, count)
        preconditioner.apply(response, out, contact, count)
        return out[free]

    apply.calls = 0
    return apply, count, level.destroy


def restricted_mat(problem, contact, name):
    """``(mat, constant, apply, destroy)``: B P K_CC P on C's nodes as a PETSc shell Mat
    (:func:`restricted_operator`, whose ``apply`` counts its calls), the unit constant (its null vector, to
    deflate), and ``destroy()`` for both and the level."""
    from petsc4py import PETSc

    apply, count, destroy_level = restricted_operator(problem, contact, name)

    class Operator:
        def mult(self, mat, x, y):
            y.getArray()[...] = apply(x.getArray(readonly=True))

    mat = PETSc.Mat().createPython((count, count), context=Operator(), comm=PETSc.COMM_SELF)
    mat.setUp()
    constant = mat.createVecLeft()
    constant.set(1.0 / np.sqrt(count))

    def destroy():
        constant.destroy()
        mat.destroy()
        destroy_level()

    return mat, constant, apply, destroy


def eigenvalues(mat, constant, which, nev):
    """The ``nev`` eigenvalues (real parts) of ``mat`` at the end ``which`` (SLEPc Krylov-Schur, tolerance 1e-8,
    ``constant`` deflated); fewer if fewer converged."""
    from petsc4py import PETSc
    from slepc4py import SLEPc

    eps = SLEPc.EPS().create(PETSc.COMM_SELF)
    try:
        eps.setOperators(mat)
        eps.setProblemType(SLEPc.EPS.ProblemType.NHEP)
        eps.setDeflationSpace([constant])
        eps.setWhichEigenpairs(which)
        eps.setDimensions(nev=nev, ncv=max(64, 2 * nev))
        eps.setTolerances(tol=1e-8, max_it=20000)
        eps.solve()
        return np.array([eps.getEigenvalue(i).real for i in range(eps.getConverged())])
    finally:
        eps.destroy()


def run_slepc(problem, pstar, contact, key, name, rows, path):
    """Extreme eigenvalues of ``B P K_CC P`` on the zero-sum subspace of C by SLEPc (Krylov-Schur)."""
    from slepc4py import SLEPc

    mat, constant, _, destroy = restricted_mat(problem, contact, name)
    start = time.perf_counter()
    try:
        low, high = (eigenvalues(mat, constant, which, 1) for which in (SLEPc.EPS.Which.SMALLEST_REAL,
                                                                        SLEPc.EPS.Which.LARGEST_REAL))
    finally:
        destroy()
    values = [v[0] if v.size else float("nan") for v in (low, high)]
    add_row(rows, path, dict(part="slepc", key=key, variant=name, lambda_min=values[0], lambda_max=values[1],
                             cond=values[1] / values[0], seconds=time.perf_counter() - start))


DEFLATION_CONDITIONS = (5.0, 10.0)


def run_deflation(problem, contact, key, name, rows, path):
    """How many eigenvectors a deflation space must hold for the restricted condition number to fall to each of
    :data:`DEFLATION_CONDITIONS`: the eigenvalues of ``B P K_CC P`` above that many times its least (SLEPc, the
    largest ones, doubling their number until the least found is below the first bound), against the number of
    C's edge nodes (a 4-neighbour outside C, periodic)."""
    from slepc4py import SLEPc

    mat, constant, apply, destroy = restricted_mat(problem, contact, name)
    start = time.perf_counter()
    try:
        least = eigenvalues(mat, constant, SLEPc.EPS.Which.SMALLEST_REAL, 1)[0]
        nev = 128
        while True:
            largest = eigenvalues(mat, constant, SLEPc.EPS.Which.LARGEST_REAL, nev)
            if largest.size and largest.min() <= DEFLATION_CONDITIONS[0] * least:
                break
            nev *= 2
    finally:
        destroy()
    n = problem.grid.n0
    inside = contact.reshape(n, n)
    inner = np.roll(inside, 1, 0) & np.roll(inside, -1, 0) & np.roll(inside, 1, 1) & np.roll(inside, -1, 1)
    row = dict(part="deflation", key=key, variant=name, contact=int(contact.sum()), edge=int((inside & ~inner).sum()),
               lambda_min=float(least), lambda_max=float(largest.max()), nev=nev, applications=apply.calls,
               seconds=time.perf_counter() - start)
    for bound in DEFLATION_CONDITIONS:
        row[f"above_{bound:g}"] = int(np.sum(largest > bound * least))
    add_row(rows, path, row)


class ExactBandPC:
    """Diagnostic, not a practical preconditioner: ``B = P (S_FF - S_FO S_OO^-1 S_OF) P`` with the band O of
    the nodes outside F within ``width`` of F, S applied by FFT and ``S_OO^-1`` by an inner CG (Jacobi
    preconditioned, to a relative residual of 1e-10): what the edge-band preconditioner tends to when its
    near-field stencil and Jacobi sweeps are made exact. With O every node outside F it is the exact
    inverse of K_FF (S = K^-1 on the grid), so cond = 1. Its inner pairs are counted apart."""

    name = "exactband"

    def __init__(self, level, width, inner_rtol=1e-10):
        self.level, self.width, self.inner_rtol = level, width, inner_rtol
        self.inner_pairs = 0
        self.diagonal = level.stiffness_stencil(0.0)[1][0]
        self.band = None

    def setup(self, free):
        from scipy.ndimage import maximum_filter

        n = self.level.n
        near = maximum_filter(free.reshape(n, n), size=2 * self.width + 1, mode="wrap").ravel()
        self.band = near & ~free

    def _stiffness(self, x):
        out = np.empty_like(x)
        self.level.stiffness(x, out)
        self.level.pairs -= 1
        self.inner_pairs += 1
        return out

    def _solve_band(self, rhs):
        band = self.band
        x, r = np.zeros_like(rhs), np.where(band, rhs, 0.0)
        z = r / self.diagonal
        t, rz, r0 = z.copy(), r @ z, np.linalg.norm(r)
        for _ in range(1000):
            if np.linalg.norm(r) <= self.inner_rtol * r0:
                break
            q = np.where(band, self._stiffness(t), 0.0)
            step = rz / (t @ q)
            x += step * t
            r -= step * q
            z = r / self.diagonal
            rz, rz_old = r @ z, rz
            t = z + rz / rz_old * t
        return x

    def apply(self, r, out, free, count):
        from pk_cascade import remove_mean_on

        y = self._stiffness(r)
        self.level.pairs += 1  # the one pair a practical preconditioner would also spend
        out[...] = y + self._stiffness(self._solve_band(-y))  # y_F - S_FO S_OO^-1 y_O, y_O = S_OF r
        remove_mean_on(out, free, count)


def run_gaps(problem, contact, key, rows, path):
    """How far the nodes outside C lie from C (Chebyshev distance, grid units, periodic): the band width that
    an exact band must have to cover them."""
    from scipy.ndimage import distance_transform_cdt

    n = problem.grid.n0
    outside = ~contact.reshape(n, n)
    pad = n // 2
    distance = distance_transform_cdt(np.pad(outside, pad, mode="wrap"), metric="chessboard")[pad:-pad, pad:-pad]
    values = distance[outside]
    add_row(rows, path, dict(part="gaps", key=key, variant="distance to C", median=float(np.median(values)),
                             p90=float(np.percentile(values, 90)), max=float(values.max())))


def run_exact_band(problem, pstar, contact, key, width, rows, path):
    import pk_cascade

    level = pk_cascade.Level(fine_heights(problem), problem.grid.n0)
    try:
        preconditioner = ExactBandPC(level, width)
        run = pk_cascade.fixed_set_pcg(level, contact, problem.scaled_pbar(pstar=pstar), preconditioner, RTOL,
                                       extra_rtol=1e-10)
        low, high, steps = pk_cascade.lanczos_extremes(run.alphas, run.betas)
    finally:
        level.destroy()
    add_row(rows, path, dict(part="exactband", key=key, variant=f"width {width}", pairs=run.pairs,
                             iterations=run.iterations, lambda_min=low, lambda_max=high, cond=high / low,
                             inner_pairs=preconditioner.inner_pairs))


# --- warm steps along the load history ---------------------------------------------------------------------
def extrapolated_start(previous, loads, target):
    """The load path's linear predictor: the last two solutions extrapolated in the load (step ratio capped at
    2), projected onto p >= 0; the caller scales it to the load. ``previous``: [(pbar, p, K p)]."""
    if len(previous) == 1:
        p, u = previous[-1][1:]
        return p.copy(), None if u is None else u.copy()
    (b0, p0, u0), (b1, p1, u1) = previous[-2], previous[-1]
    ratio = min((target - b1) / (b1 - b0), 2.0) if b1 != b0 else 0.0
    p = p1 + ratio * (p1 - p0)
    u = None if u1 is None else u1 + ratio * (u1 - u0)
    if (p < 0).any():
        return np.maximum(p, 0.0), None  # the projection moved p: K p of the start is computed afresh
    return p, u


def run_warm(problem, key, name, rows, path):
    """Pairs per step of the load history (7.11) warm-started, against a cold solve at p* = 0.5."""
    from roughpetsc import load_history
    import pk_cascade

    loads = load_history()
    if name == "pk":
        from roughpetsc import Solver

        solver = Solver(problem, "load", None, RTOL)
        try:
            start = time.perf_counter()
            cold = solver.solve(pstar=0.5)
            cold_seconds = time.perf_counter() - start
        finally:
            solver.destroy()
        cold_pairs = cold.operator_applications
        solver = Solver(problem, "load", None, RTOL)
        start = time.perf_counter()
        try:
            results = [solver.solve(pstar=p) for p in loads]
        finally:
            solver.destroy()
        seconds = time.perf_counter() - start
        pairs = [r.operator_applications for r in results]
        converged = sum(r.converged for r in results)
        starts = [r.history[0, 1] for r in results[1:] if len(r.history)]
    else:
        solver = pk_cascade.CascadePK(fine_heights(problem), **COLD_VARIANTS[name])
        try:
            start = time.perf_counter()
            cold = solver.solve(problem.scaled_pbar(pstar=0.5), RTOL)
            cold_seconds = time.perf_counter() - start
            cold_pairs = cold.pairs
            previous, pairs, converged, starts = [], [], 0, []
            start = time.perf_counter()
            for pstar in loads:
                pbar = problem.scaled_pbar(pstar=pstar)
                if previous:
                    p0, u0 = extrapolated_start(previous, loads, pbar)
                    result = solver.solve(pbar, RTOL, start=p0, start_displacement=u0)
                    starts.append(result.levels[-1].history[0])
                else:
                    result = solver.solve(pbar, RTOL)
                pairs.append(result.pairs)
                converged += result.converged
                # K p of the solution: the certificate's fresh gap plus h less d (no extra pair).
                displacement = solver.last_displacement.copy()
                previous = (previous + [(pbar, result.pressure.copy(), displacement)])[-2:]
            seconds = time.perf_counter() - start
        finally:
            solver.destroy()
    warm = np.mean(pairs[1:])
    add_row(rows, path, dict(part="warm", key=key, variant=name, steps=len(loads), cold_pairs=float(cold_pairs),
                             warm_pairs=float(warm), ratio=float(warm / cold_pairs),
                             time_ratio=float(seconds / len(loads) / cold_seconds), converged=int(converged),
                             start_residual=float(np.median(starts))))


def quadratic_start(previous, target):
    """The last three solutions extrapolated by the quadratic through them in the load, projected onto p >= 0.
    ``previous``: [(pbar, p)]; with fewer than three, the linear predictor."""
    if len(previous) < 3:
        return extrapolated_start([(b, p, None) for b, p in previous], None, target)[0]
    loads = [b for b, _ in previous[-3:]]
    p = np.zeros_like(previous[-1][1])
    for i, (b_i, p_i) in enumerate(previous[-3:]):
        weight = np.prod([(target - b_j) / (b_i - b_j) for j, b_j in enumerate(loads) if j != i])
        p += weight * p_i
    return np.maximum(p, 0.0)


# Starts of the warm floor: step k's start from the solutions of the steps before it ([(pbar, p)]).
WARM_PREDICTORS = {
    "linear": lambda previous, pbar: extrapolated_start([(b, p, None) for b, p in previous[-2:]], None, pbar)[0],
    "quadratic": quadratic_start,
    "previous": lambda previous, pbar: previous[-1][1].copy(),
}


def run_warm_floor(problem, key, name, rows, path):
    """The floor of each warm step: CG on the step's own final contact set from a predicted start.

    Today's solver walks the load history (7.11) as in the ``warm`` part; after step k its solution's contact
    set C_k = {p_k > 0} (natural residual 1e-8) and a start predicted from the solutions of the steps before
    (:data:`WARM_PREDICTORS`: ``linear`` is :func:`extrapolated_start`, the start today's solver is given)
    make a fixed-set CG run (:func:`pk_cascade.fixed_set_pcg` with ``start``): the pairs a warm step would
    cost if its final contact set were known, which no active-set method beats with the same preconditioner
    and start. Steps 3 to 95 (the quadratic predictor needs three solutions).
    """
    from roughpetsc import Solver, load_history
    import pk_cascade

    loads = load_history()
    level = pk_cascade.Level(fine_heights(problem), problem.grid.n0)
    preconditioner = pk_cascade.make_preconditioner(level, PRECONDITIONERS[name])
    solver = Solver(problem, "load", None, RTOL)
    previous, pk_pairs = [], []
    floors = {predictor: dict(pairs=[], start=[], certified=[]) for predictor in WARM_PREDICTORS}
    try:
        for pstar in loads:
            pbar = problem.scaled_pbar(pstar=pstar)
            result = solver.solve(pstar=pstar)
            pressure = problem.local(solver.pressure, readonly=True).ravel().copy()
            if len(previous) == 3:
                pk_pairs.append(result.operator_applications)
                for predictor, start in WARM_PREDICTORS.items():
                    run = pk_cascade.fixed_set_pcg(level, pressure > 0, pbar, preconditioner, RTOL, max_it=400,
                                                   start=start(previous, pbar))
                    floors[predictor]["pairs"].append(run.pairs)
                    floors[predictor]["start"].append(run.history[0])
                    floors[predictor]["certified"].append(run.certified)
            previous = (previous + [(pbar, pressure)])[-3:]
    finally:
        solver.destroy()
        level.destroy()
    add_row(rows, path, dict(part="warmfloor", key=key, variant=name, steps=len(pk_pairs), pk_pairs=pk_pairs,
                             floors=floors))


# --- report -----------------------------------------------------------------------------------------------
def rows_of(rows, part):
    return [r for r in rows if r["part"] == part]


def by_reference(found):
    """Rows of one measurement, the one on the tightest reference contact set last."""
    return sorted(found, key=lambda r: -r.get("reference", REFERENCE_RTOL))


def lookup(rows, part, key, variant, field="pairs"):
    found = by_reference([r for r in rows if r["part"] == part and r["key"] == key and r["variant"] == variant])
    return found[-1][field] if found else None


def fmt(value, spec=".0f"):
    return "-" if value is None else format(value, spec)


def floor_table(rows, keys, floor_names):
    header = ["group", "p*", "N", "reference", "|C|/N^2"] + [f"{n} pairs" for n in floor_names] + \
             [f"{n} lambda_min / lambda_max (cond)" for n in floor_names]
    table = []
    for key in keys:
        group, n, pstar = parse_key(key)
        floor = {name: by_reference([r for r in rows_of(rows, "floor") if r["key"] == key and r["variant"] == name])
                 for name in floor_names}
        if not any(floor.values()):
            continue
        first = next(v[-1] for v in floor.values() if v)
        row = [group, f"{pstar:g}", n, f"{first.get('reference', REFERENCE_RTOL):g}",
               f"{first['contact'] / n ** 2:.3f}"]
        row += [fmt(v[-1]["pairs"], "d") if v else "-" for v in floor.values()]
        row += [f"{v[-1]['lambda_min']:.3f} / {v[-1]['lambda_max']:.2f} ({v[-1]['cond']:.2f})" if v else "-"
                for v in floor.values()]
        table.append(row)
    return common.markdown_table(header, table)


def refcheck_table(rows):
    """Floor runs of one case on the reference sets of both tolerances, side by side."""
    table = []
    for loose in [r for r in rows_of(rows, "floor") if r.get("reference", REFERENCE_RTOL) != REFERENCE_RTOL]:
        tight = [r for r in rows_of(rows, "floor") if r["key"] == loose["key"] and r["variant"] == loose["variant"]
                 and r.get("reference", REFERENCE_RTOL) == REFERENCE_RTOL]
        if tight:
            t = tight[-1]
            table.append([loose["key"], loose["variant"], t["contact"], loose["contact"], t["pairs"], loose["pairs"],
                          f"{t['cond']:.3f}", f"{loose['cond']:.3f}"])
    return common.markdown_table(["case", "pc", "|C| (1e-12)", f"|C| ({loose['reference']:g})", "pairs (1e-12)",
                                  f"pairs ({loose['reference']:g})", "cond (1e-12)", f"cond ({loose['reference']:g})"],
                                 table)


def slepc_table(rows):
    check = []
    for r in rows_of(rows, "slepc"):
        lanczos = [f for f in rows_of(rows, "floor") if f["key"] == r["key"] and f["variant"] == r["variant"]]
        lz = lanczos[-1] if lanczos else None
        check.append([r["key"], r["variant"], f"{r['lambda_min']:.4f}", f"{r['lambda_max']:.4f}", f"{r['cond']:.3f}",
                      f"{lz['lambda_min']:.4f}" if lz else "-", f"{lz['lambda_max']:.4f}" if lz else "-",
                      f"{lz['cond']:.3f}" if lz else "-"])
    return common.markdown_table(["case", "preconditioner", "SLEPc lambda_min", "SLEPc lambda_max", "SLEPc cond",
                                  "Lanczos lambda_min", "Lanczos lambda_max", "Lanczos cond"], check)


def cold_table(rows, keys, cold_names):
    header = ["group", "p*", "N", "floor (fourier)", "floor (band2)", "pk (today)"] + cold_names + ["certified"]
    table = []
    for key in keys:
        group, n, pstar = parse_key(key)
        floor = lookup(rows, "floor", key, "fourier")
        pk = lookup(rows, "pk", key, "pk")
        if pk is None and not any(lookup(rows, "cold", key, c) for c in cold_names):
            continue

        def cell(value):
            if value is None:
                return "-"
            return f"{value:.1f}" + (f" ({value / floor:.2f})" if floor else "")
        cold = [r for r in rows_of(rows, "cold") if r["key"] == key]
        certified = f"{sum(r['converged'] for r in cold)}/{len(cold)}" if cold else "-"
        table.append([group, f"{pstar:g}", n, fmt(floor, "d"), fmt(lookup(rows, "floor", key, "band2"), "d"),
                      cell(pk)] + [cell(lookup(rows, "cold", key, c)) for c in cold_names] + [certified])
    return common.markdown_table(header, table)


def cascade_breakdown_table(rows, keys):
    """Where the cascade's pairs go against the floor: iterations, pairs beyond two per iteration, coarse pairs."""
    table = []
    for key in keys:
        found = [r for r in rows_of(rows, "cold") if r["key"] == key and r["variant"] == "pk-cascade"]
        floor = [r for r in rows_of(rows, "floor") if r["key"] == key and r["variant"] == "fourier"]
        if not (found and floor):
            continue
        r, f = found[-1], floor[-1]
        group, n, pstar = parse_key(key)
        moved = [m for m in rows_of(rows, "projections") if m["key"] == key and m["variant"] == "cascade"]
        moving = (f"{moved[-1]['moving_steps']} / {moved[-1]['at_most_16']} / {moved[-1]['median_moved']:.0f}"
                  if moved else "-")
        table.append([group, f"{pstar:g}", n, f["iterations"], r["iterations"], f["pairs"], r["fine_pairs"],
                      r["fine_pairs"] - 2 * r["iterations"] - 2, f"{r['coarse_pairs']:.1f}",
                      f"{r['pairs'] / f['pairs']:.2f}", moving])
    return common.markdown_table(
        ["group", "p*", "N", "floor iterations", "fine iterations", "floor pairs", "fine pairs",
         "fresh K p after projections", "coarse pairs", "total / floor",
         "steps that moved p / of them at most 16 nodes / median nodes moved"], table)


def split_table(rows, keys):
    """``pk-split`` against the floor and against the same solver with a fresh K p (pairs and wall time)."""
    table = []
    for key in keys:
        found = [r for r in rows_of(rows, "cold") if r["key"] == key and r["variant"] == "pk-split"]
        floor = lookup(rows, "floor", key, "fourier")
        if not found or floor is None:
            continue
        r = found[-1]
        group, n, pstar = parse_key(key)
        table.append([group, f"{pstar:g}", n, floor, r["iterations"], f"{r['fine_pairs']}",
                      f"{r['coarse_pairs']:.1f}", f"{r['split_pairs']:.2f}", f"{r['pairs']:.1f}",
                      f"{r['pairs'] / floor:.2f}", f"{r['fresh_pairs']:.1f}", f"{r['fresh_pairs'] / floor:.2f}",
                      f"{r['seconds'] / r['fresh_seconds']:.2f}", "yes" if r["converged"] else "NO"])
    return common.markdown_table(["group", "p*", "N", "floor pairs", "iterations", "grid pairs", "cascade pairs",
                                  "far-field pairs", "pk-split pairs", "/ floor", "fresh pairs", "/ floor",
                                  "wall split / fresh", "certified"], table)


def split_reading(rows, keys):
    """The split table in words: its ratio to the floor with and without the cascade start, and its wall time."""
    cases = []
    for key in keys:
        found = [r for r in rows_of(rows, "cold") if r["key"] == key and r["variant"] == "pk-split"]
        floor = lookup(rows, "floor", key, "fourier")
        if found and floor:
            cases.append((parse_key(key), found[-1]["pairs"] / floor, found[-1]["seconds"] / found[-1]["fresh_seconds"]))
    if not cases:
        return ""
    large = [ratio for (_, n, _), ratio, _ in cases if n >= 1024]
    small = [ratio for (_, n, _), ratio, _ in cases if n < 1024]
    over = [f"group {g} p* = {p:g} N = {n} ({ratio:.2f})" for (g, n, p), ratio, _ in cases if ratio > 1.3]
    walls = np.array([wall for _, _, wall in cases])
    return (f"Reading: with the split the cold solve costs {min(large):.2f}-{max(large):.2f}x the floor at N >= 1024 "
            f"(cascade start) and {min(small):.2f}-{max(small):.2f}x at N < 1024 (uniform start, where a step "
            f"clipping more than the stencil's work allows takes a fresh K p); over 1.3x: {', '.join(over) or 'none'}. "
            f"The coarse levels of the cascade are now the larger part of what is left at N >= 1024. Wall time "
            f"over the fresh solve's, in the same runs: {walls.min():.2f}-{walls.max():.2f} (median "
            f"{np.median(walls):.2f}): the stencil ((2R + 1)^2 operations per corrected node, memory-bound) and "
            f"the far field's interpolation cost about what the pairs saved, so the split is an option "
            f"(`-pk_split_radius 32`), not the default.")


def timing_table(rows, keys, cold_names):
    timing = []
    for key in keys:
        pk_seconds = lookup(rows, "pk", key, "pk", "seconds")
        if pk_seconds is None:
            continue
        cells = []
        for name in cold_names:
            seconds = lookup(rows, "cold", key, name, "seconds")
            # pk-cascade is timed beside a uniform start of its own run (paired)
            paired_field = {"pk-cascade": "uniform_seconds", "pk-split": "fresh_seconds"}.get(name)
            reference = lookup(rows, "cold", key, name, paired_field) if paired_field else pk_seconds
            cells.append(fmt(seconds / reference, ".2f") if seconds else "-")
        timing.append([key] + cells)
    return common.markdown_table(["case"] + cold_names, timing)


def exact_band_table(rows):
    exact = sorted(rows_of(rows, "exactband"), key=lambda r: (parse_key(r["key"])[1], int(r["variant"].split()[1])))
    return common.markdown_table(["case", "band", "lambda_min", "lambda_max", "cond", "outer pairs", "inner pairs"],
                                 [[r["key"], r["variant"], f"{r['lambda_min']:.3f}", f"{r['lambda_max']:.3f}",
                                   f"{r['cond']:.2f}", r["pairs"], r["inner_pairs"]] for r in exact])


def deflation_table(rows):
    found = sorted(rows_of(rows, "deflation"), key=lambda r: (parse_key(r["key"])[1], r["variant"]))
    header = ["case", "preconditioner", "C nodes", "edge nodes", "lambda_max / lambda_min",
              *(f"above {bound:g}x" for bound in DEFLATION_CONDITIONS), "applications"]
    return common.markdown_table(header, [[r["key"], r["variant"], r["contact"], r["edge"],
                                           f"{r['lambda_max'] / r['lambda_min']:.2f}",
                                           *(r[f"above_{bound:g}"] for bound in DEFLATION_CONDITIONS),
                                           r["applications"]] for r in found])


def gaps_table(rows, keys):
    table = []
    for key in keys:
        found = [r for r in rows_of(rows, "gaps") if r["key"] == key]
        if found:
            group, n, pstar = parse_key(key)
            table.append([group, f"{pstar:g}", n, f"{found[-1]['median']:.0f}", f"{found[-1]['p90']:.0f}",
                          f"{found[-1]['max']:.0f}"])
    return common.markdown_table(["group", "p*", "N", "median", "90 %", "max"], table)


def warm_table(rows):
    return common.markdown_table(
        ["case", "solver", "steps", "cold pairs (p* = 0.5)", "pairs per warm step", "ratio to its own cold",
         "time ratio (noisy)", "median start residual", "certified"],
        [[r["key"], r["variant"], r["steps"], f"{r['cold_pairs']:.1f}", f"{r['warm_pairs']:.1f}", f"{r['ratio']:.3f}",
          f"{r['time_ratio']:.3f}", f"{r['start_residual']:.1e}" if "start_residual" in r else "-",
          f"{r['converged']}/{r['steps']}"] for r in rows_of(rows, "warm")])


def warm_floor_table(rows):
    """One line per predictor of each warm-floor row: pairs per step against the cold solve of the case."""
    table = []
    for r in rows_of(rows, "warmfloor"):
        cold = lookup(rows, "warm", r["key"], "pk", "cold_pairs") or lookup(rows, "pk", r["key"], "pk")
        floor = lookup(rows, "floor", r["key"], r["variant"])
        pk = np.mean(r["pk_pairs"])
        table.append([r["key"], "today's pk (its warm steps)", r["steps"], f"{pk:.1f}", f"{pk / cold:.3f}",
                      f"{pk / floor:.2f}" if floor else "-", "-", "-"])
        for predictor, run in r["floors"].items():
            pairs = np.mean(run["pairs"])
            table.append([r["key"], f"floor from the {predictor} start ({r['variant']})", r["steps"],
                          f"{pairs:.1f}", f"{pairs / cold:.3f}", f"{pairs / floor:.2f}" if floor else "-",
                          f"{np.median(run['start']):.1e}",
                          f"{sum(c <= RTOL for c in run['certified'])}/{len(run['certified'])}"])
    return common.markdown_table(["case", "warm step", "steps", "pairs per step", "over pk's cold solve",
                                  "over the cold floor", "median start residual", "certified"], table)


def plot_warm_floor(rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from roughpetsc import load_history

    found = rows_of(rows, "warmfloor")
    fig, axes = plt.subplots(1, len(found), figsize=(6.5 * len(found), 4.5), squeeze=False)
    for axis, r in zip(axes[0], found):
        loads = load_history()[-r["steps"]:]
        cold = lookup(rows, "warm", r["key"], "pk", "cold_pairs") or lookup(rows, "pk", r["key"], "pk")
        steps = np.arange(len(loads)) + len(load_history()) - len(loads) + 1
        axis.plot(steps, r["pk_pairs"], "k-", label="today's pk, warm")
        for predictor, run in r["floors"].items():
            axis.plot(steps, run["pairs"], "--", label=f"floor, {predictor} start")
        axis.axhline(0.35 * cold, color="r", lw=0.8, label=f"0.35 x cold ({cold:.0f} pairs)")
        twin = axis.twinx()
        twin.plot(steps, loads, ":", color="0.6")
        twin.set_ylabel("p* of the step (dotted)")
        axis.set_xlabel("step of the load history (7.11)")
        axis.set_ylabel("FFT pairs to natural KKT 1e-8")
        axis.set_title(r["key"])
        axis.grid(alpha=0.3)
        axis.legend(fontsize=7)
    common.save_figure(fig, OUT, "warm_floor.png")


def scaling_table(rows, keys):
    """Iterations, pairs and seconds against N for Polonsky-Keer from both starts and the prototype, beside the
    floor."""
    table = []
    for key in keys:
        if lookup(rows, "pk", key, "pk") is None:
            continue
        group, n, pstar = parse_key(key)
        pk = [lookup(rows, "pk", key, "pk", field) for field in ("iterations", "pairs", "seconds")]
        cascade = [lookup(rows, "cold", key, "pk-cascade", field) for field in ("iterations", "pairs", "seconds")]
        best = [lookup(rows, "cold", key, "best", field) for field in ("iterations", "pairs", "seconds")]
        table.append([group, f"{pstar:g}", n, fmt(lookup(rows, "floor", key, "fourier")), pk[0], pk[1],
                      pk[1] - 2 * pk[0], fmt(pk[2], ".3g"), fmt(cascade[0]), fmt(cascade[1], ".1f"),
                      fmt(cascade[2], ".3g"), fmt(best[0]), fmt(best[1], ".1f"), fmt(best[2], ".3g")])
    return common.markdown_table(["group", "p*", "N", "floor pairs", "pk iterations", "pk pairs",
                                  "pk pairs besides 2 per iteration", "pk s", "pk-cascade iterations (fine)",
                                  "pk-cascade pairs", "pk-cascade s", "best iterations (finest level)",
                                  "best pairs", "best s"], table)


def idle_timing_table(rows, keys):
    """The `timing` part: the three solvers of :data:`TIMED_SOLVERS` timed one after the other in one process,
    their pairs over the floor and their seconds over the uniform start's."""
    table = []
    for key in keys:
        found = {r["variant"]: r for r in rows_of(rows, "timing") if r["key"] == key}
        if len(found) < len(TIMED_SOLVERS):
            continue
        group, n, pstar = parse_key(key)
        floor = lookup(rows, "floor", key, "fourier")
        pk = found["pk"]
        cells = []
        for name, _ in TIMED_SOLVERS:
            r = found[name]
            ratio = f" ({r['pairs'] / floor:.2f})" if floor else ""
            cells += [r["iterations"], f"{r['pairs']:.1f}{ratio}", f"{r['seconds']:.3g}"]
            if name != "pk":
                cells.append(f"{r['seconds'] / pk['seconds']:.2f}")
        certified = sum(found[name]["converged"] for name, _ in TIMED_SOLVERS)
        table.append([group, f"{pstar:g}", n, fmt(floor)] + cells
                     + [f"{1e3 * pk['seconds'] / pk['pairs']:.3g}",
                        f"{pk['load_before']:.2f} / {pk['load_after']:.2f}", f"{certified}/{len(TIMED_SOLVERS)}"])
    header = ["group", "p*", "N", "floor pairs"]
    for name, _ in TIMED_SOLVERS:
        header += [f"{name} iterations", f"{name} pairs (/ floor)", f"{name} s"]
        if name != "pk":
            header.append(f"{name} s / pk s")
    return common.markdown_table(header + ["pk ms per pair", "load average before / after", "converged"], table)


def idle_reading(rows, keys):
    """The idle table in words: each solver's wall time over the uniform start's and the split's over the cascade
    start's, by N."""
    by_n = {}
    for key in keys:
        found = {r["variant"]: r for r in rows_of(rows, "timing") if r["key"] == key}
        if len(found) == len(TIMED_SOLVERS):
            by_n.setdefault(parse_key(key)[1], []).append(found)
    parts = []
    for n, cases in sorted(by_n.items()):
        cascade = [c["pk-cascade"]["seconds"] / c["pk"]["seconds"] for c in cases]
        split = [c["pk-split"]["seconds"] / c["pk-cascade"]["seconds"] for c in cases]
        faster = sum(ratio < 1 for ratio in split)
        parts.append(f"N = {n} ({len(cases)} cases): pk-cascade / pk {min(cascade):.2f}-{max(cascade):.2f}, "
                     f"pk-split / pk-cascade {min(split):.2f}-{max(split):.2f} (median {np.median(split):.2f}, "
                     f"faster in {faster})")
    return "Reading, wall time: " + "; ".join(parts) + "."


def peer_table():
    """Today's solver against Tamaas from ``studies/output/peers.json`` (one run, the same field judged by our
    operator): iterations, operator applications and seconds against N."""
    path = os.path.join(common.OUTPUT, "peers.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        peers = json.load(f)
    table = []
    for size in peers["sizes"]:
        ours = next(r for r in size["rows"] if r["solver"] == "roughpetsc PK")
        tamaas = next((r for r in size["rows"] if r["solver"].startswith("Tamaas")), None)
        if tamaas is None:
            continue
        table.append([size["n"], ours["iterations"], ours["operator_applications"], f"{ours['time_s']:.3g}",
                      tamaas["iterations"], f"{tamaas['time_s']:.3g}", f"{ours['time_s'] / tamaas['time_s']:.3f}"])
    header = ["N", "pk iterations", "pk pairs", "pk s", "Tamaas PKR iterations",
              "Tamaas s", "pk s / Tamaas s"]
    return peers, common.markdown_table(header, table)


def report(rows):
    keys = sorted({r["key"] for r in rows}, key=lambda k: (parse_key(k)[0], parse_key(k)[2], parse_key(k)[1]))
    floor_names = [n for n in PRECONDITIONERS if any(r["variant"] == n for r in rows_of(rows, "floor"))]
    cold_names = [n for n in list(COLD_VARIANTS) + ["pk-cascade", "pk-split"] if any(r["variant"] == n for r in rows_of(rows, "cold"))]
    lines = ["# The contact solver's floor, cold solves against it, and warm load steps (issue 39, items 1-4)", "",
             "Written by `studies/solver_scaling.py` from its `rows*.json` (its docstring defines every quantity; "
             "`studies/pk_cascade.py` describes the prototype solver step by step). FFT pairs and "
             "iterations are deterministic; seconds come from one run each on a shared 2-core machine under a "
             "load average of 5-11 (noisy: compare only as ratios, and loosely). Surfaces: `options/group01.opts` "
             "(H = 0.8) and `options/group18.opts` (H = 0.1) at N x N, seed 1; natural KKT residual 1e-8.", "",
             "Preconditioners: `fourier` = the Fourier preconditioner of today's solver; `band<k>` = the edge-band "
             "preconditioner `pk_cascade.BandPC` (`-lu`: its band matrix solved exactly, a diagnostic); "
             "`schur<k>` = `pk_cascade.SchurPC` (two pairs per application): "
             + "; ".join(f"`{k}` = `{v}`" for k, v in PRECONDITIONERS.items() if k != "fourier") + ".", "",
             "## 1. The floor: preconditioned CG on the exact final contact set", "",
             "Pairs to a certified natural residual of 1e-8 from the uniform pressure on C (2 k + 2 for k "
             "iterations); cond = lambda_max / lambda_min of the preconditioned operator on the zero-sum "
             "subspace of C, from the Lanczos matrix of the CG coefficients (CG run on to a reduction of "
             "1e-10; Ritz values lie inside the spectrum, so lambda_max is a lower and lambda_min an upper "
             "estimate).", "", floor_table(rows, keys, [n for n in floor_names if n in MAIN_PRECONDITIONERS]), ""]
    if any(r.get("reference", REFERENCE_RTOL) != REFERENCE_RTOL for r in rows_of(rows, "floor")):
        lines += ["The reference contact set at N = 8192 comes from a solve to 1e-10 (column `reference`; at N = 4096 "
                  "a 1e-12 one stopped at round-off, 2.8e-12, after 1637 pairs, and a pair at 8192 takes 4-6 s "
                  "here). Where both exist, the two "
                  "references give the same set and the same floor (`--reference-rtol 1e-10`, rows_refcheck):",
                  "", refcheck_table(rows), ""]
    if rows_of(rows, "slepc"):
        lines += ["SLEPc cross-check (Krylov-Schur, tolerance 1e-8, the constant on C deflated):", "",
                  slepc_table(rows), ""]
    lines += ["## 2. Cold solves against the floor", "",
              "FFT pairs of a cold solve to a certified natural residual of 1e-8 (coarse levels weighted by "
              "(N_c/N)^2, the certificate included); in brackets the ratio to the Fourier floor of section 1. "
              "`pk (today)`: the default solver as it was before the cascade start (`python -m roughpetsc "
              "-options_file options/groupNN.opts -surface_N N -pstar P -cascade_coarsest 0`); `pk-cascade`: the "
              "same from the cascade start (`-cascade_coarsest 256`, the default at N >= 1024; "
              "`roughpetsc/solvers/cascade.py`), its coarse pairs weighted. The variants are `COLD_VARIANTS` of the study; `best` is the candidate "
              "described in `pk_cascade.py`. `certified`: the cold variants of the case whose result passed "
              "an independent certificate (`ContactProblem.gap`, `kkt.report`).", "",
              cold_table(rows, keys, cold_names), "",
              "Wall time of each cold solve over today's `pk` on the same case (one run each; `pk` includes its "
              "solver set-up, the variants do not include their grids' FFTW planning; noisy; `pk-cascade` over "
              "a solve from the uniform start timed in the same run):", "",
              timing_table(rows, keys, cold_names), ""]
    if any(r["variant"] == "pk-cascade" for r in rows_of(rows, "cold")):
        lines += ["Where the pairs of `pk-cascade` go, against the floor (the floor's 2 k + 2 pairs for k "
                  "iterations; the fine level's pairs beyond 2 per iteration and the first K p and certificate "
                  "are the fresh K p after each step whose projection moved p; `projections` part for the "
                  "last column):", "", cascade_breakdown_table(rows, keys), "",
                  "Reading: from the cascade start the fine level takes about the floor's iterations (within "
                  "-3 and +5 at N >= 512); what is left over the floor is the fresh K p after projections and "
                  "the coarse levels. The projections move a median of 49-470 nodes per step, and only 18-40 % "
                  "of the moving steps move 16 nodes or fewer: shifted kernel copies (the "
                  "prototype's point corrections, about one sweep of the grid per node) would save those few "
                  "pairs only.", ""]
    if any(r["variant"] == "pk-split" for r in rows_of(rows, "cold")):
        lines += ["### The fresh K p after projections, replaced: the split compliance", "",
                  "`pk-split` is today's solver with `-pk_split_radius 32` (`roughpetsc/elastic/split.py`): "
                  "after a step the projection moved, K c of its corrections c is added by a stencil of the "
                  "kernel's near part (offsets up to 32 nodes, split smoothly from 16) and the smooth far part "
                  "on the grid coarsened 4 times (1/16 pair), and K p is computed afresh each time the residual "
                  "has fallen 100 times since the last. The prototype's variants at N = 1024 say why each part "
                  "is there (cold table): `near16-deferred` (far field never applied before the end) doubles the "
                  "iterations, `split32-norefresh` (applied to 0.05-0.3 % but never refreshed) loses many, "
                  "`split32` does not. Pairs below count the grid's (the split's set-up pair, the refreshes and "
                  "the certificate included), the cascade levels' and the far fields', weighted; `fresh` is the "
                  "same solve with `-pk_split_radius 0` (a fresh K p after every moving step), timed in the same "
                  "run:", "", split_table(rows, keys), "", split_reading(rows, keys), ""]
    lines += ["## 3. The edge-band preconditioner and its exact limit", "",
              "The `band<k>` floor columns of section 1 are the practical edge-band preconditioner. Other "
              "settings, the band's near-field matrix solved exactly (`-lu`), and the Schur form with the "
              "coupling by FFT (`schur<k>`, two pairs per application, counted) on the same floor problem:", "",
              floor_table(rows, keys, [n for n in floor_names if n not in MAIN_PRECONDITIONERS]), "",
              "How far the nodes outside C lie from C (Chebyshev distance in nodes; `gaps` part):", "",
              gaps_table(rows, keys), "",
              "The limit with an exact band solve (`ExactBandPC` of the study: S_OO^-1 by an inner CG, the "
              "coupling by FFT, a diagnostic only: its inner pairs are counted apart) against the band width:",
              ""]
    lines += [exact_band_table(rows) if rows_of(rows, "exactband") else "(not run)", ""]
    if rows_of(rows, "deflation"):
        lines += ["Deflation of the edge modes (`deflation` part): the eigenvalues of the preconditioned operator "
                  "on C above 5 and 10 times its least, i.e. the eigenvectors a deflation space must hold for the "
                  "restricted condition number to fall to 5 or 10, against C's edge nodes; `applications` is what "
                  "SLEPc spent finding them (each one FFT pair and the preconditioner), against a floor of "
                  "40-80 pairs a solve:", "", deflation_table(rows), ""]
    lines += ["## 4. Warm steps along the load history (7.11)", ""]
    lines += [warm_table(rows) if rows_of(rows, "warm") else "(not run)", ""]
    if rows_of(rows, "warmfloor"):
        lines += ["What limits a warm step (`warmfloor` part): after each step of today's solver along the "
                  "history, CG on that step's own final contact set from a start predicted by the steps before "
                  "it (the linear predictor today's solver uses, the quadratic through the last three "
                  "solutions, the last solution alone), to the same certified residual. These runs are given "
                  "the answer's contact set: they estimate from below what a warm step costs with this "
                  "preconditioner from that start. Ratios are over the cold solve of the same case (today's pk, "
                  "first table) and over the cold floor of section 1:", "", warm_floor_table(rows), "",
                  "Reading: even given each step's final contact set, a warm step costs about 0.36 of a cold "
                  "solve at N = 1024. The predicted start is off by a natural residual of about 5e-2 (the "
                  "contact edge moves between the steps of (7.11), and no predictor tried starts closer: the "
                  "quadratic one is no better than the linear one), and CG takes about 21 iterations to bring "
                  "that to 1e-8 at the condition number 19 of section 1, 0.6 of the cold floor's 35. A warm "
                  "step within 0.35 of a cold solve needs a better preconditioner on the contact set (item 3) "
                  "or loads closer together; today's solver spends 0.52, 1.4 times the floor of its steps. The "
                  "preconditioner is what limits it: at N = 512 the edge-band preconditioner band2 brings the "
                  "same floor from 0.36 to 0.26-0.30 of the cold solve (rows `band2`); it is serial and not a "
                  "backend (item 3).", "",
                  "![pairs per warm step](warm_floor.png)", ""]
        plot_warm_floor(rows)
    lines += ["## 5. Scaling against N", "",
              "Polonsky-Keer from the uniform start (`pk`, `-cascade_coarsest 0`), from the cascade start "
              "(`pk-cascade`, the default at N >= 1024: section 2) and the prototype (`best`) against N, from "
              "the rows above (one run each "
              "beside other work on the 2 shared cores: the seconds are noisy, and the rows of different N "
              "come from different runs). Both converge with a count of pairs that grows slowly with N "
              "(the floor's condition number grows like log N, section 1). Polonsky-Keer spends two pairs "
              "per iteration (K t and the preconditioner) and one more at the start, one for the certificate, "
              "and one to recompute K p afresh after every step whose projection moved p: the column 'besides "
              "2 per iteration' is those, 17-31 % of the total at p* = 0.5 (growing with N); the rest of its "
              "excess over the floor is iterations from the uniform start (61 against the floor's 40 at "
              "N = 4096, group 1, p* = 0.5), which the cascade start removes (section 2).", "",
              scaling_table(rows, keys), ""]
    if rows_of(rows, "timing"):
        started = sorted(r["started"] for r in rows_of(rows, "timing"))
        lines += ["### One run on an otherwise idle machine", "",
                  f"The `timing` part ({started[0]} to {started[-1]} UTC, one process on one core of the 2, no "
                  "other work of ours running; the 1-minute load average, this process included, is given for "
                  "each case): for each "
                  "case an untimed solve to 1e-2, then `pk` (uniform start, `-cascade_coarsest 0 "
                  "-pk_split_radius 0`), `pk-cascade` (`-cascade_coarsest 256 -pk_split_radius 0`) and `pk-split` "
                  "(`-pk_split_radius 32`, the cascade start at N >= 1024 as by default), each cold to a certified "
                  "natural residual of 1e-8, timed from the start of the solve to its certificate. Pairs weighted "
                  "as in section 2; in brackets over the floor of section 1.", "",
                  idle_timing_table(rows, keys), "", idle_reading(rows, keys), "",
                  "The host's speed drifted within the run: group 1, N = 1024, p* = 0.5 timed again the same way at "
                  "04:37 took 2.82 / 2.79 / 3.00 s against 2.40 / 1.95 / 2.25 s at 02:55 (pk / pk-cascade / "
                  "pk-split), so a wall-time ratio within 20 % of 1 says nothing here. Group 18 at N = 8192 ran "
                  "later (06:14-07:19 UTC, with our other processes stopped). Pairs: `pk-split` stays within 1.3x "
                  "the floor at N = 2048-4096, but at 8192, p* = 0.5 it takes 58 fine iterations against the "
                  "cascade start's 46 (group 1, 1.59x the floor) and 65 against 50 (group 18, 1.62x). For group "
                  "1, with K p afresh at each 10-fold fall "
                  "instead (`python -m roughpetsc -options_file options/group01.opts -surface_N 8192 -pstar 0.5 "
                  "-pk_split_radius 32 -pk_split_refresh 1e-1`) it takes 62 (138 + 8.8 + 3.31 = 150.1 pairs), "
                  "so the far field's error between refreshes is not what costs those iterations. The radius "
                  "matters, and not monotonically: at N = 4096 (group 1, p* = 0.5, `-pk_split_radius R`) R = 16 / 24 "
                  "/ 32 / 48 take 52 / 43 / 43 / 44 iterations and 121.5 / 103.1 / 106.3 / 112.1 pairs (1.48 / 1.26 "
                  "/ 1.30 / 1.37x the floor); at 8192, p* = 0.5, R = 64 takes 51 iterations and 115 + 10.5 + 2.56 = "
                  "128.1 pairs (1.46x), against R = 32's 58 and 140.2.", "",
                  "The far field's accuracy is the lever at N = 8192 only. Its bilinear transfers (the loads "
                  "restricted by the transpose of the interpolation) leave an error falling like (4 / R)^2: for "
                  "300 random point loads at N = 1024 an rms of 1.45e-4 / 3.7e-5 of max |K c| at R = 32 / 64. "
                  "Cubic transfers (`-pk_split_transfer cubic`: 4-point Lagrange, restriction its transpose) cut "
                  "it 3-5 times, to 4.2e-5 / 7.1e-6, for 6 ms more per corrected step at N = 2048 (23 against 17 "
                  "ms; a pair takes 58 ms). "
                  "With them (group 1, p* = 0.5) N = 8192, R = 32 takes 51 iterations and 113 + 8.5 + 2.69 = "
                  "124.2 pairs (1.41x the floor; timed beside other work, so no time), as many as bilinear R = 64 "
                  "and against bilinear R = 32's 58; cubic R = 64 takes 52 (118 + 10.5 + 2.5 = 131.0 pairs), so "
                  "the rest of the gap to the cascade start's 46 does not close with accuracy. Below 8192 they "
                  "gain nothing: at N = 4096 R = 16 / 24 / 32 "
                  "took 50 / 44 / 46 iterations (1.43 / 1.28 / 1.38x) against bilinear's 52 / 43 / 43, at 2048 "
                  "R = 8 / 16 / 32 took 47 / 39 / 38 against 44 / 40 / 38. Where the far field is far off the "
                  "iterations grow at any N: at 2048, R = 8 takes 44, but 38 (the cascade start's count without "
                  "the split) with the far field exact (`-pk_split_coarsening 1`), and R = 16 takes 38 with "
                  "coarsening 2. Above that, below 8192, a change of the path moves the count by a few iterations "
                  "either way. A reading consistent with this: a step's far-field errors add up over its "
                  "corrected nodes, whose number grows with N, so the accuracy a step needs grows with N. The "
                  "cubic transfers are an option, not the default (a loss at 4096, and the time); what costs the "
                  "other 5 iterations at 8192 is open.",
                  ""]
    peers = peer_table()
    if peers:
        lines += [f"Against Tamaas ({peers[0]['started']}, `studies/output/peers.md`; group 1 with the peers' "
                  "own generator, p* = 0.5, the same discrete surface and kernel for both, one process each, "
                  "one run; both reach a natural residual of 1e-8 by our operator). Tamaas's iterations grow "
                  "1.7-1.8x per doubling of N (about N^0.8), ours 1.1-1.2x:", "", peers[1], ""]
    lines += ["The adhesive solver's cost against the non-adhesive one: `studies/output/adhesion/cost.md` "
              "(N = 512).", ""]
    plot(rows, keys, floor_names, cold_names)
    lines += ["![floor and cold solves](solver_scaling.png)", "",
              "Regenerate (resumable; `--report` rewrites this file from the rows): see the module docstring of "
              "`studies/solver_scaling.py`.", ""]
    return "\n".join(lines)


def plot(rows, keys, floor_names, cold_names):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = sorted({(parse_key(k)[0], parse_key(k)[2]) for k in keys})
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    for index, (group, pstar) in enumerate(cases):
        color = f"C{index % 10}"
        sizes = sorted(parse_key(k)[1] for k in keys if parse_key(k)[0] == group and parse_key(k)[2] == pstar)

        def series(part, variant, field):
            values = [lookup(rows, part, case_key(group, n, pstar), variant, field) for n in sizes]
            return [n for n, v in zip(sizes, values) if v], [v for v in values if v]
        label = f"g{group} p*={pstar:g}"
        axes[0].semilogx(*series("floor", "fourier", "pairs"), "o-", color=color, label=f"floor {label}")
        axes[0].semilogx(*series("pk", "pk", "pairs"), "s--", color=color, alpha=0.6)
        best = "best" if "best" in cold_names else (cold_names[0] if cold_names else None)
        if best:
            axes[0].semilogx(*series("cold", best, "pairs"), "^:", color=color, alpha=0.8)
        for style, name in zip(("o-", "d:"), [n for n in floor_names if n in ("fourier", "band2")]):
            axes[1].semilogx(*series("floor", name, "cond"), style, color=color,
                             label=f"{name} {label}" if name == "fourier" else None)
    axes[0].set_xlabel("N")
    axes[0].set_ylabel("FFT pairs to natural KKT 1e-8")
    axes[0].set_title("Fourier floor (o-), today's PK (s--), best (^:)")
    axes[1].set_xlabel("N")
    axes[1].set_ylabel("cond of the preconditioned operator on C")
    axes[1].set_title("Fourier (o-) and edge-band band2 (d:) preconditioners")
    for axis in axes:
        axis.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=7, ncol=2)
    common.save_figure(fig, OUT, "solver_scaling.png")


# --- main -------------------------------------------------------------------------------------------------
def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[256, 512, 1024, 2048])
    parser.add_argument("--loads", type=float, nargs="*", default=[0.05, 0.5, 2.0])
    parser.add_argument("--groups", type=int, nargs="*", default=[1, 18])
    parser.add_argument("--parts", nargs="*", default=["reference", "pk", "floor", "cold"],
                        choices=["reference", "pk", "floor", "cold", "pkcascade", "pksplit", "projections", "slepc",
                                 "warm", "warmfloor", "exactband", "gaps", "timing", "deflation"])
    parser.add_argument("--widths", type=int, nargs="*", default=[1, 2, 4, 8],
                        help="band widths of the exactband diagnostic")
    parser.add_argument("--floor-pcs", nargs="*", default=["fourier", "band2"], choices=list(PRECONDITIONERS))
    parser.add_argument("--cold", nargs="*", default=["pcg", "cascade", "band2", "cascade-band2"],
                        choices=list(COLD_VARIANTS))
    parser.add_argument("--warm", nargs="*", default=["pk", "cascade-band2"], choices=["pk"] + list(COLD_VARIANTS))
    parser.add_argument("--warm-n", type=int, default=1024, help="grid of the warm-step part (at p* = 0.5)")
    parser.add_argument("--reference-rtol", type=float, default=REFERENCE_RTOL,
                        help="natural residual of the reference solve whose contact set the floor runs on")
    parser.add_argument("--cache", default=os.path.expanduser("~/.cache/roughpetsc/solver_scaling"),
                        help="folder of the reference contact sets (bit masks)")
    parser.add_argument("--rows", default="rows", help="the rows file (OUT/NAME.json) this run adds to, so that "
                                                         "two runs can go side by side; the report reads every "
                                                         "rows*.json")
    args, _, _ = common.start_resumable(parser, OUT, "rows", "write report.md from the saved rows only")
    path = os.path.join(OUT, args.rows + ".json")
    rows = common.load_rows(path)
    if not args.report:
        for group in args.groups:
            for n in args.sizes:
                for pstar in args.loads:
                    run_case(args, group, n, pstar, rows, path)
    every = [row for name in sorted(os.listdir(OUT)) if name.startswith("rows") and name.endswith(".json")
             for row in common.load_rows(os.path.join(OUT, name))]
    with open(os.path.join(OUT, "report.md"), "w") as f:
        f.write(report(every))


def run_case(args, group, n, pstar, rows, path):
    key = case_key(group, n, pstar)
    todo = {part for part in args.parts if part not in ("floor", "cold", "slepc", "deflation", "warm", "warmfloor",
                                                        "pkcascade", "projections", "pksplit", "timing")
            and not has_row(rows, part, key, "pk" if part == "pk" else reference_variant(args.reference_rtol))}
    if "pkcascade" in args.parts and not has_row(rows, "cold", key, "pk-cascade"):
        todo.add("pkcascade")
    if "pksplit" in args.parts and not has_row(rows, "cold", key, "pk-split"):
        todo.add("pksplit")
    if "projections" in args.parts and not has_row(rows, "projections", key, "cascade"):
        todo.add("projections")
    if "timing" in args.parts and not has_row(rows, "timing", key, TIMED_SOLVERS[-1][0]):
        todo.add("timing")
    floors = [name for name in args.floor_pcs if "floor" in args.parts
              and not has_row(rows, "floor", key, name, reference=args.reference_rtol)]
    colds = [name for name in args.cold if "cold" in args.parts and not has_row(rows, "cold", key, name)]
    slepcs = [name for name in args.floor_pcs if "slepc" in args.parts and not has_row(rows, "slepc", key, name)]
    deflations = [name for name in args.floor_pcs if "deflation" in args.parts
                  and not has_row(rows, "deflation", key, name)]
    warms = [name for name in args.warm if "warm" in args.parts and n == args.warm_n and pstar == 0.5
             and not has_row(rows, "warm", key, name)]
    warm_floors = [name for name in args.floor_pcs if "warmfloor" in args.parts and n == args.warm_n
                   and pstar == 0.5 and not has_row(rows, "warmfloor", key, name)]
    widths = [w for w in args.widths if "exactband" in args.parts and not has_row(rows, "exactband", key, f"width {w}")]
    gaps = "gaps" in args.parts and not has_row(rows, "gaps", key, "distance to C")
    if not (todo or floors or colds or slepcs or deflations or warms or warm_floors or widths or gaps):
        return
    print(f"--- {key}", flush=True)
    problem = make_problem(group, n)
    try:
        if "pk" in todo:
            run_pk(problem, pstar, key, rows, path)
        if "pkcascade" in todo:
            run_pk_cascade(problem, pstar, key, rows, path)
        if "pksplit" in todo:
            run_pk_split(problem, pstar, key, rows, path)
        if "projections" in todo:
            run_projections(problem, pstar, key, rows, path)
        if "timing" in todo:
            run_timing(problem, pstar, key, rows, path)
        if floors or slepcs or deflations or widths or gaps or "reference" in todo:
            contact = reference_contact(problem, pstar, args.cache, key, rows, path, args.reference_rtol)
        for name in floors:
            run_floor(problem, pstar, contact, key, name, rows, path, args.reference_rtol)
        if gaps:
            run_gaps(problem, contact, key, rows, path)
        for width in widths:
            run_exact_band(problem, pstar, contact, key, width, rows, path)
        for name in slepcs:
            run_slepc(problem, pstar, contact, key, name, rows, path)
        for name in deflations:
            run_deflation(problem, contact, key, name, rows, path)
        for name in colds:
            run_cold(problem, pstar, key, name, rows, path)
        for name in warms:
            run_warm(problem, key, name, rows, path)
        for name in warm_floors:
            run_warm_floor(problem, key, name, rows, path)
    finally:
        problem.destroy()


if __name__ == "__main__":
    sys.exit(main())
