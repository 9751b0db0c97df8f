"""The surface layer: the grid, generated and measured surfaces, spectra and moments, summits, seeds (ch. 2, 7).

Surfaces are plain numpy arrays of shape ``(n0, n1)`` on a :class:`Grid`; nothing here imports PETSc.
"""

from ..lazy import exports

__getattr__, __dir__, __all__ = exports(__name__, {
    "Grid": ("grid", "Grid"),
    "square_grid": ("grid", "square_grid"),
    "fractal": ("generators", "fractal"),
    "fractal_amplitude": ("generators", "fractal_amplitude"),
    "fractal_psd": ("generators", "fractal_psd"),
    "wave": ("generators", "wave"),
    "bisinusoid": ("generators", "bisinusoid"),
    "hertz_sphere": ("generators", "hertz_sphere"),
    "load": ("files", "load"),
    "level": ("files", "level"),
    "validate": ("files", "validate"),
    "spectral_moments": ("spectra", "spectral_moments"),
    "fd_moments": ("spectra", "fd_moments"),
    "isotropic_mean": ("spectra", "isotropic_mean"),
    "bandwidth": ("spectra", "bandwidth"),
    "pressure_surface": ("spectra", "pressure_surface"),
    "heights_from_pressure_surface": ("spectra", "heights_from_pressure_surface"),
    "fractal_closed_forms": ("spectra", "fractal_closed_forms"),
    "surface_moments": ("moments", "surface_moments"),
    "surface_seed": ("seeds", "surface_seed"),
})
