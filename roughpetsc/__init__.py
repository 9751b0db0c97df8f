"""roughpetsc: elastic contact of rough surfaces with PETSc/TAO.

Data flow: options -> surface -> operator -> problem -> solver -> results -> files (docs/architecture.md).
The public API is the names of :data:`__all__`::

    from . import ContactProblem, Grid, fractal, load_path

    grid = Grid(128, 128)
    problem = ContactProblem(grid, fractal(grid, 16, 64, 0.8, 2e-4, seed=1), E_star=1.0)
    for result in load_path(problem, pstars=[0.1, 0.5, 1.0]):
        print(result.pstar, result.A, result.kkt.natural)

Every name is imported on first use (:mod:`roughpetsc.lazy`); ``ContactProblem``, ``Solver`` and ``load_path``
import PETSc (call ``petsc4py.init(args)`` first to give PETSc options). BLAS and OpenMP get one thread per
rank unless the environment says otherwise (docs/runtime.md).
"""

import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")
del _variable

from .lazy import exports  # noqa: E402  (after the thread limits: it imports nothing heavy)

__version__ = "0.1.0"

# Module -> the public names it defines (renamed ones below).
_EXPORTS = {
    # surfaces (section 7.1 of the dissertation) and their readers
    "surface.grid": "Grid square_grid",
    "surface.generators": "fractal fractal_amplitude fractal_psd wave bisinusoid hertz_sphere",
    "app.presets": "fractal_group read_opts",
    # statistics (chapter 2, section 7.2)
    "surface.spectra": "spectral_moments fd_moments isotropic_mean bandwidth pressure_surface "
                       "heights_from_pressure_surface fractal_closed_forms",
    "surface.moments": "surface_moments",
    # the contact problem (3.41)-(3.44), its solvers and their results
    "contact.problem": "ContactProblem",
    "contact.result": "Result",
    "elastic.westergaard": "Westergaard",
    "solvers": "Solver load_path",
    # errors
    "errors": "ParameterError",
}

__getattr__, __dir__, __all__ = exports(__name__, _EXPORTS, submodules=("models",), renamed={
    "load_surface": ("surface.files", "load"), "load_history": ("contact.loads", "history")})
