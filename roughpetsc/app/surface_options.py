"""The surface options of the command line (``-surface_*``): their table, defaults and the surface they name."""

from ..errors import ParameterError, UserError
from ..surface.files import level, load, validate
from ..surface.generators import DEFAULT_GENERATOR, bisinusoid, fractal, hertz_sphere, wave
from ..surface.grid import square_grid


# The one place of the surface defaults: a surface of group #1 of Table 7.1, (k_l, k_s, H) = (16, 64, 0.8),
# m2 = 2e-4, N = 256.
SURFACE_OPTIONS = [
    ("surface_type", "fractal", "fractal | bisinusoid | wave | sphere (an error with -surface_file)"),
    ("surface_file", "", "read heights from PATH: .npy, a text or CSV height matrix or x y z point list on a grid, "
                         ".h5/.hdf5 dataset 'surface', a roughpetsc output (dataset 'heights' and its recorded "
                         "cell length), or an instrument file (with the optional SurfaceTopography)"),
    ("surface_detrend", "mean", "-surface_file: none | mean | plane (remove the least-squares plane, reported); a "
                                "tilt or a jump between opposite edges large against the rms height is warned of"),
    ("surface_N", 256, "nodes per side (N x N grid)"),
    ("surface_N0", 0, "rows (axis 0) if different from -surface_N; e.g. a few rows for a 1-D wave"),
    ("surface_L", 1.0, "cell length along axis 1 (x); axis 0 gets L * N0 / N (square nodes)"),
    ("surface_kl", 16.0, "fractal: long-wavelength cut-off k_l = k_r [cycles/length]"),
    ("surface_ks", 64.0, "fractal: short-wavelength cut-off k_s [cycles/length]"),
    ("surface_H", 0.8, "fractal: Hurst exponent H in (0, 1)"),
    ("surface_m2", 2e-4, "fractal: prescribed m2^h (mean square slope along x), sets C by (7.1)"),
    ("surface_seed", 1, "fractal: seed of the white noise (same surface on any number of ranks)"),
    ("surface_generator", DEFAULT_GENERATOR, "fractal: filter (white noise filtered by sqrt(PSD): random amplitudes) "
                                             "| xu ((7.2)-(7.5): exact amplitude sqrt(PSD), random phase; the group "
                                             "presets')"),
    ("surface_amplitude", 0.01, "bisinusoid: Delta of (3.52); wave: h of 2h sin^2(pi x/lambda) [length]"),
    ("surface_wavelength", 0.0, "bisinusoid/wave: wavelength along x (0 = the cell length)"),
    ("surface_radius", 10.0, "sphere: radius R of the paraboloid -r^2/(2R) [length]"),
]


# The options each surface type reads besides the grid (-surface_N, -surface_N0, -surface_L).
TYPE_OPTIONS = {
    "fractal": ("surface_kl", "surface_ks", "surface_H", "surface_m2", "surface_seed", "surface_generator"),
    "bisinusoid": ("surface_amplitude", "surface_wavelength"),
    "wave": ("surface_amplitude", "surface_wavelength"),
    "sphere": ("surface_radius",),
}


# The keyword of :func:`fractal` that each fractal option sets.
FRACTAL_KEYWORDS = {"surface_kl": "k_l", "surface_ks": "k_s", "surface_H": "hurst", "surface_m2": "m2",
                    "surface_seed": "seed", "surface_generator": "generator"}


def option_default(name):
    """The default of the surface option ``name`` (:data:`SURFACE_OPTIONS`)."""
    return next(default for option, default, _ in SURFACE_OPTIONS if option == name)


def option_values(opts, names):
    """``{name: value}`` of the surface options ``names`` from ``opts``, with the types and defaults of the table."""
    read = {int: opts.getInt, float: opts.getReal, str: opts.getString}
    return {name: read[type(default)](name, default) for name in names for default in (option_default(name),)}


def parameters(opts):
    """The surface's parameters as used, defaults included, for output files: ``{option name: value}``."""
    if opts.getString("surface_file", ""):
        return option_values(opts, ("surface_file", "surface_L", "surface_detrend"))
    kind = opts.getString("surface_type", "fractal")
    return option_values(opts, ("surface_type", "surface_N", "surface_N0", "surface_L") + TYPE_OPTIONS.get(kind, ()))


def grid_from_options(opts):
    """The :class:`Grid` named by ``-surface_N``, ``-surface_N0`` and ``-surface_L``."""
    given = option_values(opts, ("surface_N", "surface_N0", "surface_L"))
    if given["surface_N0"] < 0 or given["surface_N0"] == 1:
        raise UserError(f"-surface_N0 must be 0 (as many rows as -surface_N) or at least 2 rows, "
                        f"got {given['surface_N0']}")
    return square_grid(given["surface_N"], given["surface_N0"], given["surface_L"])


def from_options(opts, seed=None, notes=None):
    """Build the surface named by the options: ``(grid, heights)``, heights of shape ``grid.shape``.

    ``seed`` overrides ``-surface_seed``. The whole array is built on every rank, so the surface does not depend
    on the number of ranks. A surface file's :class:`Levelling` (``-surface_detrend``) is appended to ``notes``.
    """
    path = opts.getString("surface_file", "")
    if path:
        heights, recorded_length = load(path)
        # An explicit -surface_L wins over the length a file records.
        length = opts.getReal("surface_L", recorded_length or 1.0)
        n0, n1 = heights.shape
        grid = square_grid(n1, n0, length)
        try:
            heights, levelling = level(grid, heights, opts.getString("surface_detrend", "mean"))
        except ParameterError as error:
            raise ParameterError("detrend", str(error)) from None
        if notes is not None:
            notes.append(levelling)
        return grid, heights
    grid = grid_from_options(opts)
    kind = opts.getString("surface_type", "fractal")
    if kind not in TYPE_OPTIONS:
        raise ParameterError("kind", f"unknown surface type '{kind}' (fractal, bisinusoid, wave, sphere)")
    given = option_values(opts, TYPE_OPTIONS[kind])
    if kind == "fractal":
        if given["surface_seed"] < 0:
            raise UserError(f"-surface_seed must be a non-negative integer, got {given['surface_seed']}")
        keywords = {FRACTAL_KEYWORDS[name]: value for name, value in given.items()}
        heights = fractal(grid, **dict(keywords, seed=keywords["seed"] if seed is None else seed))
    elif kind == "sphere":
        heights = hertz_sphere(grid, given["surface_radius"])
    else:
        amplitude, wavelength = given["surface_amplitude"], given["surface_wavelength"] or grid.l1
        heights = wave(grid, amplitude, wavelength) if kind == "wave" else \
            bisinusoid(grid, amplitude, wavelength * grid.l0 / grid.l1, wavelength)
    return grid, validate(heights)
