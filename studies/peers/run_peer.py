"""Solve one load-controlled contact problem with a peer library (runs INSIDE .peers-venv).

    .peers-venv/bin/python studies/peers/run_peer.py SURFACE.npy E_STAR PBAR PEER TOL OUT_PREFIX [--length L]

PEER is ``tamaas`` (PolonskyKeerRey, pressure primal) or ``contactmechanics``
(constrained conjugate gradients, Polonsky-Keer, under ``external_force``).
Writes ``OUT_PREFIX.npy`` (the pressure field, pressure units, same layout as the
surface) and ``OUT_PREFIX.json`` (A* by node count, gbar, iterations, solve and
setup wall time, versions, the peer's own error measure).

ADHESIVE mode (Tamaas only; displacement control by the imposed mean gap G):

    .peers-venv/bin/python studies/peers/run_peer.py SURFACE.npy E_STAR G tamaas TOL OUT_PREFIX \
        --adhesion exponential|maugis|none --work W --range RHO [--mean-gap G] [--length L]

It runs PolonskyKeerRey with the gap as primal and the mean gap as constraint, plus Tamaas'
Exponential/Maugis adhesion functional (Rey-Anciaux-Molinari). The third positional is the mean
gap (--mean-gap overrides it). It writes OUT_PREFIX.npy (the total normal traction, compressive
positive, adhesive tensile negative), OUT_PREFIX.gap.npy (the gap g >= 0) and OUT_PREFIX.json.
The conventions are in solve_tamaas_adhesion's docstring.

It never imports roughpetsc: the peers live in their own virtualenv with their own numpy.

Both peers are set up on OUR discrete problem (docs/conventions.md, eq. 3.33): a periodic
square cell of side L, the Westergaard compliance u_hat = p_hat / (pi E* |k|)
with k in cycles per length, no displacement for the k = 0 mode; gap
g = u + d - h with the heights h of the file as the rough surface.

* Tamaas: model ``basic_2d`` with E = E*, nu = 0 (Tamaas' E_star = E / (1 - nu^2));
  its ``Westergaard::neumann`` operator is exactly 1/(pi E* |k|) with a zero k = 0
  mode (checked numerically by ``--check-kernels``). The surface passed is h.
  The tolerance is PKR's own relative error (complementarity-like measure).
* ContactMechanics: ``PeriodicFFTElasticHalfSpace(shape, E*, (L, L),
  stiffness_q0=0.0)``; stiffness_q0 = 0 drops the k = 0 mode (the default None
  would give it the stiffness of the lowest modes - harmless for the pressure
  under load control, but not our kernel). Its Green's function is
  1/(pi E* q) with q in cycles per length, and it works with point forces
  (negative = compressive): external_force = pbar * L^2. The tolerance t
  sets pentol = t * rms(h), forcetol = t * pbar * L^2 / n (t times the mean
  nodal force) and thermotol = t.

Wall time: the solve only (``time.perf_counter`` around ``solver.solve`` or
``constrained_conjugate_gradients``, and the process CPU time of the same span);
model/substrate creation is reported as setup.
"""

import argparse
import json
import os
import sys
import time

import numpy as np


def _version(distribution, fallback):
    """The installed distribution's version (ContactMechanics' __version__ is a git describe)."""
    from importlib import metadata

    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return str(fallback)


def _tamaas_solver(heights, e_star, tol, length, max_iter, primal):
    """Tamaas' basic_2d model (E = E*, nu = 0) and a PolonskyKeerRey on ``primal`` ("pressure" or "gap"),
    constrained on the same variable; returns (model, surface, solver), log level error."""
    import tamaas as tm

    tm.set_log_level(tm.LogLevel.error)
    n0, n1 = heights.shape
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [length, length * n1 / n0], [n0, n1])
    model.E = e_star
    model.nu = 0.0
    surface = np.ascontiguousarray(heights, dtype=np.float64)
    variable = getattr(tm.PolonskyKeerRey, primal)
    solver = tm.PolonskyKeerRey(model, surface, tol, variable, variable)
    solver.max_iter = max_iter
    return model, surface, solver


def solve_tamaas(heights, e_star, pbar, tol, length, max_iter):
    import tamaas as tm

    start = time.perf_counter()
    model, surface, solver = _tamaas_solver(heights, e_star, tol, length, max_iter, "pressure")
    # Iterations: at log level info PKR prints (to stderr, from C++) a table row at
    # iteration 0, every dump_freq iterations and at the last one; with a huge
    # dump_freq only the first and the last rows are printed. Capture fd 2.
    tm.set_log_level(tm.LogLevel.info)
    solver.dump_freq = 10 ** 9
    setup = time.perf_counter() - start
    with _CaptureStderr() as log:
        start, cpu = time.perf_counter(), time.process_time()
        error = solver.solve(pbar)
        solve_time, cpu = time.perf_counter() - start, time.process_time() - cpu
    tm.set_log_level(tm.LogLevel.error)
    rows = [line.split() for line in log.text.splitlines()]
    counts = [int(r[0]) for r in rows if len(r) == 3 and r[0].isdigit()]
    iterations = counts[-1] if counts else None
    pressure = np.array(model.traction, dtype=np.float64).reshape(heights.shape)
    return {
        "pressure": pressure,
        "iterations": iterations,
        "peer_error": float(error),
        "converged": bool(error < tol),
        "setup_s": setup,
        "solve_s": solve_time,
        "cpu_s": cpu,
        "version": _version("tamaas", tm.__version__),
        "settings": {"tolerance": tol, "max_iter": max_iter,
                     "primal": "pressure", "constraint": "pressure", "E": e_star, "nu": 0.0},
    }


class _CaptureStderr:
    """Capture what C++ code writes to file descriptor 2."""

    def __enter__(self):
        import tempfile

        sys.stderr.flush()
        self._file = tempfile.TemporaryFile(mode="w+b")
        self._saved = os.dup(2)
        os.dup2(self._file.fileno(), 2)
        return self

    def __exit__(self, *exc):
        sys.stderr.flush()
        os.dup2(self._saved, 2)
        os.close(self._saved)
        self._file.seek(0)
        self.text = self._file.read().decode(errors="replace")
        self._file.close()
        return False


ADHESION_LAWS = ("exponential", "maugis", "none")


def _adhesion_law(law, work, range_):
    """(phi(g), phi'(g)) of Tamaas' adhesion functionals, per unit area (see solve_tamaas_adhesion)."""
    if law == "exponential":
        return (lambda g: -work * np.exp(-g / range_)), (lambda g: work / range_ * np.exp(-g / range_))
    if law == "maugis":
        return ((lambda g: np.where(g <= range_, -work * (1.0 - g / range_), 0.0)),
                (lambda g: np.where(g <= range_, work / range_, 0.0)))
    return (lambda g: np.zeros_like(g)), (lambda g: np.zeros_like(g))


def solve_tamaas_adhesion(heights, e_star, mean_gap, law, work, range_, tol, length, max_iter):
    """Adhesive contact at imposed mean gap with Tamaas' PolonskyKeerRey (gap primal, gap constraint).

    This is the algorithm of Rey, Anciaux & Molinari (2017): PolonskyKeerRey(model, h, tol,
    PolonskyKeerRey.gap, PolonskyKeerRey.gap) plus addFunctionalTerm(<law>AdhesionFunctional).
    Tamaas 2.9's C++ source is not shipped in the wheel (only _tamaas.so, built from upstream
    src/solvers/polonsky_keer_rey.cpp and the tamaas::functional adhesion classes). The
    conventions below come from the pybind docstrings, from calling the functionals'
    computeF/computeGradF on known gaps, and from a numpy re-implementation of the gap-primal
    loop. That re-implementation reproduces Tamaas' gap field to 1e-16 and its logged error to
    all printed digits at every iteration, for no adhesion, exponential and Maugis.

    Model: basic_2d, model.E = E*, nu = 0 (E_star = E/(1-nu^2) = E*), the same Westergaard kernel
    as solve_tamaas. Gradients are pointwise (stress units). The Dirichlet stiffness of the
    elastic part is pi E* |k| (k in cycles per length) with a zero k = 0 mode.

    Energies: each functional's computeF sums its energy over the nodes, and its computeGradF
    ADDS the gradient pointwise. With w = parameters['surface_energy'] (energy per unit area,
    the work of adhesion: phi(0) = -w, phi(inf) = 0) and rho = parameters['rho'] (a length):
      * ExponentialAdhesionFunctional ("F = -γ·exp(-g/ρ)"): phi(g) = -w exp(-g/rho),
        phi'(g) = (w/rho) exp(-g/rho); its peak tensile stress is w/rho, at g = 0.
      * MaugisAdhesionFunctional: the docstring "F = H(g - ρ)·γ/ρ" is misleading. What it
        computes is the Dugdale/Maugis law phi(g) = -w (1 - g/rho) for g <= rho (the bound
        included) and 0 beyond; phi'(g) = w/rho (constant stress sigma0 = w/rho) for g <= rho,
        0 beyond.
    ElasticFunctionalGap: F = 0.5 mean((g+h) K(g+h)) (energy PER UNIT AREA) and gradF = K(g+h).
    So Tamaas' printed Cost_f mixes a mean (elastic) with a node sum (adhesion) and is not an
    energy. The solver uses only the gradients, which are consistent. The equilibrium solved is
    K u + phi'(g) = lambda + c, lambda >= 0, g >= 0, lambda g = 0, where the constant c carries
    the mean-gap constraint. So w is per unit area, and the discrete problem does not depend on
    the pixel area. The functionals' `surface` argument only gives the shape.

    solve(mean_gap), gap primal: the initial g is uniform and equal to mean_gap. Each iteration
    (the primal update order is from memory of PolonskyKeerRey::updatePrimal; the steps were
    confirmed by the 1e-16 reproduction):
      1. d = K(g+h) + phi'(g);
      2. d -= mean of d over {g > 0} (meanOnUnsaturated);
      3. conjugate direction on {g > 0}; step tau from K applied to the direction;
      4. g -= tau*dir, projected with max(g, 0); nodes with g == 0 and d < 0 are reopened
         (g = -tau d);
      5. enforceMeanValue: g *= mean_gap / mean(g), so the MEAN GAP (a length, in the
         heights' units) is imposed exactly.
    Contact gaps are exact zeros. The mean of g is mean_gap, whatever mean(h) is.

    After solve (enforceAdmissibleState):
      * model.displacement = g + h;
      * model.traction = K(g+h) - min_i[K(g+h) + phi'(g)]_i. This is the TOTAL normal traction,
        compressive positive and adhesive (tensile) negative. It is Neumann-consistent with the
        displacement (u - N(t) is constant) and equals -phi'(g) on g > 0. Its mean, the mean
        pressure, is -min(d), which is set by the constraint multiplier.
    In our convention (u with zero mean, g = u + d - h), u = u_tamaas - mean(u_tamaas) and the
    mean-plane separation is d = mean_gap + mean(h).

    Error (PolonskyKeerRey::computeError, gap primal):
        err = |sum_i g_i (d_i - min_j d_j)| / (|sum_i d_i| * std(h, ddof=1)).
    Here d is the dbar-shifted gradient of step 2, taken BEFORE the update, and g is the
    updated primal. sum d ~ the total contact (repulsive) force in nodal units, so err is a
    multiplier-weighted mean gap over std(h). The loop stops when err <= tol or after max_iter
    + 1 updates. If nothing is in contact, sum d = 0 and err ~ 1e16-1e18: such a state never
    'converges' and runs to max_iter even when its field is right (flagged as no_contact).

    Contact area: the fraction of nodes with g == 0 exactly. The projection writes exact zeros,
    and u - h recovers them exactly. A_gap_le_1e-12sigma is reported as a check.
    Iterations: 'iterations' is Tamaas' last logged counter, the convention of solve_tamaas. It
    is the number of primal updates minus 1 when converged, and equals it when max_iter stopped
    the run. 'primal_updates' is the exact count.
    """
    import tamaas as tm

    if law not in ADHESION_LAWS:
        raise ValueError(f"law must be one of {ADHESION_LAWS}")
    if law != "none" and not (work >= 0 and range_ > 0):
        raise ValueError("need work >= 0 and range > 0")
    start = time.perf_counter()
    model, surface, solver = _tamaas_solver(heights, e_star, tol, length, max_iter, "gap")
    functional = None
    if law != "none":
        cls = {"exponential": tm.ExponentialAdhesionFunctional, "maugis": tm.MaugisAdhesionFunctional}[law]
        functional = cls(surface)
        functional.parameters = {"rho": float(range_), "surface_energy": float(work)}
        solver.addFunctionalTerm(functional)  # `functional` stays referenced until the end
    tm.set_log_level(tm.LogLevel.info)
    solver.dump_freq = 10 ** 9  # only the first and the final rows (see solve_tamaas)
    setup = time.perf_counter() - start
    with _CaptureStderr() as log:
        start, cpu = time.perf_counter(), time.process_time()
        error = solver.solve(float(mean_gap))
        solve_time, cpu = time.perf_counter() - start, time.process_time() - cpu
    tm.set_log_level(tm.LogLevel.error)
    rows = [line.split() for line in log.text.splitlines()]
    counts = [int(r[0]) for r in rows if len(r) == 3 and r[0].isdigit()]
    converged = bool(error <= tol)
    iterations = counts[-1] if counts else None
    updates = None if iterations is None else iterations + (1 if converged else 0)

    pressure = np.array(model.traction, dtype=np.float64).reshape(heights.shape)
    displacement = np.array(model.displacement, dtype=np.float64).reshape(heights.shape)
    gap = displacement - surface
    phi, dphi = _adhesion_law(law, work, range_)
    contact = gap == 0.0
    free = ~contact
    sigma = float(np.std(surface))
    # Checks: the traction on g > 0 must be -phi'(g), and lambda = p + phi'(g) >= 0 on contact.
    free_residual = float(np.abs(pressure + dphi(gap))[free].max()) if free.any() else 0.0
    multiplier_min = float((pressure + dphi(gap))[contact].min()) if contact.any() else None
    u0 = displacement - displacement.mean()
    return {
        "pressure": pressure,
        "gap": gap,
        "iterations": iterations,
        "primal_updates": updates,
        "peer_error": float(error),
        "converged": converged,
        "no_contact": bool(not contact.any()),
        "setup_s": setup,
        "solve_s": solve_time,
        "cpu_s": cpu,
        "version": _version("tamaas", tm.__version__),
        "A": float(np.count_nonzero(contact) / gap.size),
        "A_gap_le_1e-12sigma": float(np.count_nonzero(gap <= 1e-12 * sigma) / gap.size),
        "A_pressure_positive": float(np.count_nonzero(pressure > 0) / gap.size),
        "pbar_out": float(pressure.mean()),
        "pbar_repulsive": float(np.maximum(pressure, 0).mean()),
        "pbar_tensile": float(np.minimum(pressure, 0).mean()),
        "mean_gap_out": float(gap.mean()),
        "d_separation": float(mean_gap + surface.mean()),
        "energy_elastic_per_area": float(0.5 * np.mean(u0 * pressure)),
        "energy_adhesive_per_area": float(np.mean(phi(gap))),
        "check_free_traction_residual": free_residual,
        "check_min_contact_multiplier": multiplier_min,
        "settings": {"tolerance": tol, "max_iter": max_iter, "primal": "gap", "constraint": "gap",
                     "mean_gap": mean_gap, "law": law, "surface_energy": work, "rho": range_,
                     "E": e_star, "nu": 0.0, "contact": "gap == 0",
                     "error": "|sum g (d - min d)| / (|sum d| std(h, ddof=1))"},
    }


def solve_contactmechanics(heights, e_star, pbar, tol, length, max_iter, hardness=None):
    import ContactMechanics
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients  # noqa: F401
    from ContactMechanics.Optimization.ConstrainedConjugateGradients import constrained_conjugate_gradients as ccg
    from SurfaceTopography import Topography

    start = time.perf_counter()
    n0, n1 = heights.shape
    sizes = (length, length * n1 / n0)
    substrate = PeriodicFFTElasticHalfSpace((n0, n1), e_star, sizes, stiffness_q0=0.0)
    topography = Topography(np.asarray(heights, dtype=np.float64), physical_sizes=sizes, periodic=True)
    area = sizes[0] * sizes[1]
    external_force = pbar * area
    rms = float(np.sqrt(np.mean((heights - heights.mean()) ** 2)))
    pentol = tol * rms
    forcetol = tol * external_force / (n0 * n1)
    iterations = {"n": 0}

    def callback(it, forces, info):
        iterations["n"] = it

    setup = time.perf_counter() - start
    start, cpu = time.perf_counter(), time.process_time()
    # CCG's hardness caps the force of a pixel: the pressure cap times the area of a pixel.
    cap = None if hardness is None else hardness * substrate.area_per_pt
    result = ccg(substrate, topography, hardness=cap, external_force=external_force, pentol=pentol,
                 forcetol=forcetol, thermotol=tol, maxiter=max_iter, callback=callback)
    solve_time, cpu = time.perf_counter() - start, time.process_time() - cpu
    pressure = np.asarray(result.jac, dtype=np.float64) / substrate.area_per_pt
    return {
        "pressure": pressure,
        "iterations": int(result.nit),
        "peer_error": {k: float(v) for k, v in getattr(result, "maxcv", {}).items()},
        "converged": bool(result.success),
        "message": str(result.message),
        "setup_s": setup,
        "solve_s": solve_time,
        "cpu_s": cpu,
        "version": _version("ContactMechanics", ContactMechanics.__version__),
        "settings": {"tolerance": tol, "pentol": pentol, "forcetol": forcetol, "thermotol": tol,
                     "maxiter": max_iter, "external_force": external_force, "stiffness_q0": 0.0,
                     "hardness": hardness},
    }


def check_kernels(n=32, length=1.0, e_star=2.5):
    """Apply each peer's compliance to single Fourier modes and compare with 1/(pi E* |k|)."""
    y, x = np.meshgrid(np.arange(n) / n * length, np.arange(n) / n * length, indexing="ij")
    out = {}
    for k0, k1 in [(1, 0), (0, 3), (3, 2), (n // 2, n // 2 - 1)]:
        p = np.cos(2 * np.pi * (k0 * y + k1 * x) / length) + 0.7  # + a mean pressure
        expected = (p - 0.7) * length / (np.pi * e_star * np.hypot(k0, k1))
        import tamaas as tm

        model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [length, length], [n, n])
        model.E, model.nu = e_star, 0.0
        model.traction[:] = p
        model.solveNeumann()
        u_tm = np.array(model.displacement).reshape(n, n)
        from ContactMechanics import PeriodicFFTElasticHalfSpace

        substrate = PeriodicFFTElasticHalfSpace((n, n), e_star, (length, length), stiffness_q0=0.0)
        u_cm = substrate.evaluate_disp(-p * substrate.area_per_pt)  # compressive force is negative
        scale = np.abs(expected).max()
        out[f"{k0},{k1}"] = {"tamaas": float(np.abs(u_tm - expected).max() / scale),
                             "contactmechanics": float(np.abs(u_cm - expected).max() / scale)}
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("surface", nargs="?")
    parser.add_argument("e_star", nargs="?", type=float)
    parser.add_argument("pbar", nargs="?", type=float)
    parser.add_argument("peer", nargs="?", choices=("tamaas", "contactmechanics"))
    parser.add_argument("tol", nargs="?", type=float)
    parser.add_argument("out", nargs="?", help="output prefix (.npy and .json are added)")
    parser.add_argument("--length", type=float, default=1.0, help="cell side along axis 0 (default 1)")
    parser.add_argument("--max-iter", type=int, default=100000)
    parser.add_argument("--hardness", type=float, default=None,
                        help="contactmechanics only: the pressure cap H (perfect plasticity, CCG's hardness)")
    parser.add_argument("--check-kernels", action="store_true",
                        help="only compare both peers' compliance with 1/(pi E* |k|) and exit")
    parser.add_argument("--adhesion", choices=ADHESION_LAWS, default=None,
                        help="tamaas only: adhesive contact at imposed mean gap (gap primal); "
                             "'none' = the same displacement-controlled solve without adhesion")
    parser.add_argument("--work", type=float, default=None, help="--adhesion: work of adhesion w (energy/area)")
    parser.add_argument("--range", dest="range_", type=float, default=None,
                        help="--adhesion: range rho (length)")
    parser.add_argument("--mean-gap", type=float, default=None,
                        help="--adhesion: imposed mean gap (length); if omitted, the PBAR positional is used")
    args = parser.parse_args()
    if args.check_kernels:
        print(json.dumps(check_kernels(), indent=1))
        return
    if None in (args.surface, args.e_star, args.pbar, args.peer, args.tol, args.out):
        parser.error("SURFACE E_STAR PBAR PEER TOL OUT are required")
    heights = np.load(args.surface)
    if heights.ndim != 2 or not np.all(np.isfinite(heights)):
        sys.exit(f"{args.surface}: need a finite 2-D height array")
    if args.adhesion is not None:
        if args.peer != "tamaas" or args.hardness is not None:
            sys.exit("--adhesion: only with tamaas and without --hardness")
        mean_gap = args.pbar if args.mean_gap is None else args.mean_gap
        if args.mean_gap is not None and args.pbar != args.mean_gap:
            print(f"note: PBAR positional {args.pbar} ignored, --mean-gap {args.mean_gap} used", file=sys.stderr)
        if args.adhesion != "none" and (args.work is None or args.range_ is None):
            parser.error("--adhesion exponential|maugis needs --work and --range")
        result = solve_tamaas_adhesion(heights, args.e_star, mean_gap, args.adhesion,
                                       0.0 if args.work is None else args.work,
                                       1.0 if args.range_ is None else args.range_,
                                       args.tol, args.length, args.max_iter)
        pressure, gap = result.pop("pressure"), result.pop("gap")
        result.update({
            "peer": "tamaas", "mode": "adhesion", "n": list(pressure.shape), "numpy": np.__version__,
            "threads_env": {k: os.environ.get(k) for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                                          "MKL_NUM_THREADS", "FFTW_NUM_THREADS")},
        })
        np.save(args.out + ".npy", pressure)
        np.save(args.out + ".gap.npy", gap)
        with open(args.out + ".json.tmp", "w") as f:
            json.dump(result, f, indent=1)
        os.replace(args.out + ".json.tmp", args.out + ".json")
        print(json.dumps(result))
        return
    if args.peer == "tamaas":
        if args.hardness is not None:
            sys.exit("--hardness: only with contactmechanics")
        result = solve_tamaas(heights, args.e_star, args.pbar, args.tol, args.length, args.max_iter)
    else:
        result = solve_contactmechanics(heights, args.e_star, args.pbar, args.tol, args.length, args.max_iter,
                                        args.hardness)
    pressure = result.pop("pressure")
    in_contact = pressure > 0
    result.update({
        "peer": args.peer,
        "A": float(np.count_nonzero(in_contact) / pressure.size),
        "pbar_out": float(pressure.mean()),
        "n": list(pressure.shape),
        "numpy": np.__version__,
        "threads_env": {k: os.environ.get(k) for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                                      "MKL_NUM_THREADS", "FFTW_NUM_THREADS")},
    })
    np.save(args.out + ".npy", pressure)
    with open(args.out + ".json.tmp", "w") as f:
        json.dump(result, f, indent=1)
    os.replace(args.out + ".json.tmp", args.out + ".json")
    print(json.dumps(result))


if __name__ == "__main__":
    main()
