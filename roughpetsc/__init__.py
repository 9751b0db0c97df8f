"""roughpetsc: elastic contact of rough surfaces with PETSc/TAO.

Data flow: options -> surface -> operator -> problem -> solver -> results -> files
(docs/architecture.md). The statistical models (:mod:`roughpetsc.models`) depend on
spectral moments only.

The public API is the names of :data:`__all__`, imported from here::

    from roughpetsc import ContactProblem, Grid, fractal, load_path

    grid = Grid(128, 128)
    problem = ContactProblem(grid, fractal(grid, 16, 64, 0.8, 2e-4, seed=1), E_star=1.0)
    for result in load_path(problem, pstars=[0.1, 0.5, 1.0]):
        print(result.pstar, result.A, result.kkt.natural)

Every name is imported on first use (PEP 562 ``__getattr__``): ``import roughpetsc`` loads
neither numpy nor PETSc, so the command line can hand PETSc its options
(``petsc4py.init(argv)``) before anything imports ``petsc4py.PETSc``. Names of the surface,
statistics and model parts never import PETSc; ``ContactProblem``, ``Solver`` and
``load_path`` do (call ``petsc4py.init(args)`` first to give PETSc options).

One thread per MPI rank: unless the environment says otherwise, the BLAS and
OpenMP thread pools are limited to one thread before numpy loads them (this
takes effect when roughpetsc is imported before numpy, as ``python -m
roughpetsc`` does). A threaded BLAS splits our long dot products over the
cores that the other ranks need: on 2 cores it made one 512^2 load history
11 % slower alone and two of them side by side 40 % slower. FFTW's threads
are an option of their own (``-fft_threads``).
"""

import importlib
import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")
del _variable

__version__ = "0.1.0"

# Public name -> (module, name in that module).
_EXPORTS = {
    # surfaces (section 7.1 of the dissertation) and their readers
    "Grid": ("surfaces", "Grid"),
    "square_grid": ("surfaces", "square_grid"),
    "fractal": ("surfaces", "fractal"),
    "fractal_amplitude": ("surfaces", "fractal_amplitude"),
    "fractal_psd": ("surfaces", "fractal_psd"),
    "wave": ("surfaces", "wave"),
    "bisinusoid": ("surfaces", "bisinusoid"),
    "hertz_sphere": ("surfaces", "hertz_sphere"),
    "load_surface": ("surfaces", "load"),
    "fractal_group": ("presets", "fractal_group"),
    "read_opts": ("presets", "read_opts"),
    # statistics (chapter 2, section 7.2)
    "spectral_moments": ("spectra", "spectral_moments"),
    "fd_moments": ("spectra", "fd_moments"),
    "isotropic_mean": ("spectra", "isotropic_mean"),
    "bandwidth": ("spectra", "bandwidth"),
    "pressure_surface": ("spectra", "pressure_surface"),
    "heights_from_pressure_surface": ("spectra", "heights_from_pressure_surface"),
    "fractal_closed_forms": ("spectra", "fractal_closed_forms"),
    "surface_moments": ("surface_moments", "surface_moments"),
    # the contact problem (3.41)-(3.44), its solvers and their results
    "ContactProblem": ("contact", "ContactProblem"),
    "Result": ("contact", "Result"),
    "Westergaard": ("westergaard", "Westergaard"),
    "load_history": ("loads", "history"),
    "Solver": ("solvers", "Solver"),
    "load_path": ("solvers", "load_path"),
    # errors
    "ParameterError": ("errors", "ParameterError"),
}

_SUBMODULES = ("models",)

__all__ = sorted(_EXPORTS) + list(_SUBMODULES)


def __getattr__(name):
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    if name in _EXPORTS:
        module, attribute = _EXPORTS[name]
        value = getattr(importlib.import_module(f"{__name__}.{module}"), attribute)
        globals()[name] = value  # later look-ups skip __getattr__
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
