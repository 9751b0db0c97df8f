"""Solve one load-controlled contact problem with a peer library (runs INSIDE .peers-venv).

    .peers-venv/bin/python studies/peers/run_peer.py SURFACE.npy E_STAR PBAR PEER TOL OUT_PREFIX [--length L]

PEER is ``tamaas`` (PolonskyKeerRey, pressure primal) or ``contactmechanics``
(constrained conjugate gradients, Polonsky-Keer, under ``external_force``).
Writes ``OUT_PREFIX.npy`` (the pressure field, pressure units, same layout as the
surface) and ``OUT_PREFIX.json`` (A* by node count, gbar, iterations, solve and
setup wall time, versions, the peer's own error measure).

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


def solve_tamaas(heights, e_star, pbar, tol, length, max_iter):
    import tamaas as tm

    tm.set_log_level(tm.LogLevel.error)
    start = time.perf_counter()
    n0, n1 = heights.shape
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [length, length * n1 / n0], [n0, n1])
    model.E = e_star
    model.nu = 0.0
    surface = np.ascontiguousarray(heights, dtype=np.float64)
    solver = tm.PolonskyKeerRey(model, surface, tol, tm.PolonskyKeerRey.pressure, tm.PolonskyKeerRey.pressure)
    solver.max_iter = max_iter
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
    pressure = np.array(model.traction, dtype=np.float64).reshape(n0, n1)
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
    args = parser.parse_args()
    if args.check_kernels:
        print(json.dumps(check_kernels(), indent=1))
        return
    if None in (args.surface, args.e_star, args.pbar, args.peer, args.tol, args.out):
        parser.error("SURFACE E_STAR PBAR PEER TOL OUT are required")
    heights = np.load(args.surface)
    if heights.ndim != 2 or not np.all(np.isfinite(heights)):
        sys.exit(f"{args.surface}: need a finite 2-D height array")
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
