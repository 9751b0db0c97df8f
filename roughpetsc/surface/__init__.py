"""The surface layer: the grid, generated and measured surfaces, spectra and moments, summits, seeds (ch. 2, 7).

Surfaces are plain numpy arrays of shape ``(n0, n1)`` on a :class:`Grid`; nothing here imports PETSc.
"""

from ..lazy import exports

__getattr__, __dir__, __all__ = exports(__name__, {
    "grid": "Grid square_grid",
    "generators": "fractal fractal_amplitude fractal_psd wave bisinusoid hertz_sphere",
    "files": "load level validate",
    "spectra": "spectral_moments fd_moments isotropic_mean bandwidth pressure_surface heights_from_pressure_surface "
               "fractal_closed_forms",
    "moments": "surface_moments",
    "seeds": "surface_seed",
})
