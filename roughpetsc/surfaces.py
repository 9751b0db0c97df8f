"""Periodic surfaces on a uniform grid: generated, deterministic and measured.

Array layout: a surface is a real array of shape ``(n0, n1)``; axis 0 ("rows",
``y``) is the one distributed over MPI ranks, axis 1 (``x``) is contiguous.
Heights are returned with zero mean (docs/conventions.md). Wavenumbers are in
cycles per length, as in the Fourier pair (2.1)/(2.2) of the dissertation.

Bad values raise :class:`~roughpetsc.errors.ParameterError` naming the Python
parameter; the command line names the option (``roughpetsc.cli``).
"""

from dataclasses import dataclass
import json
import os

import numpy as np

from .errors import ParameterError


@dataclass(frozen=True)
class Grid:
    """A periodic cell of ``n0 x n1`` nodes and size ``l0 x l1`` (length units).

    Raises :class:`ParameterError` naming ``n0``, ``n1``, ``l0`` or ``l1`` for a count of nodes that is
    not a positive whole number or a side that is not positive and finite.
    """

    n0: int
    n1: int
    l0: float = 1.0
    l1: float = 1.0

    def __post_init__(self):
        for name in ("n0", "n1"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ParameterError(name, f"the number of nodes {name} must be a positive whole number, got {value!r}")
        for name in ("l0", "l1"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float, np.integer, np.floating)) and value > 0 and np.isfinite(value)):
                raise ParameterError(name, f"the cell side {name} must be positive and finite, got {value!r}")

    @property
    def shape(self):
        return (self.n0, self.n1)

    @property
    def size(self):
        return self.n0 * self.n1

    @property
    def area(self):
        return self.l0 * self.l1

    def coordinates(self):
        """Node coordinates ``(y, x)`` as broadcastable column and row arrays."""
        y = np.arange(self.n0)[:, None] * (self.l0 / self.n0)
        x = np.arange(self.n1)[None, :] * (self.l1 / self.n1)
        return y, x

    def rfft_wavenumbers(self, rows=slice(None)):
        """Wavenumbers (k0, k1) in cycles/length of the ``rfft2`` layout.

        ``k0`` has shape ``(m, 1)`` for the selected rows of the full frequency
        axis 0 and ``k1`` has shape ``(1, n1 // 2 + 1)``.
        """
        k0 = np.fft.fftfreq(self.n0, d=self.l0 / self.n0)[rows][:, None]
        k1 = np.fft.rfftfreq(self.n1, d=self.l1 / self.n1)[None, :]
        return k0, k1


def fractal_amplitude(k_l, k_s, hurst, m2):
    """PSD amplitude C of (2.18) with k_r = k_l from a prescribed m2^h, eq. (7.1).

    ``C = 4 (1 - H) m2 / ((2 pi)^3 (k_s^(2-2H) - k_l^(2-2H)))`` [length^(4-2H)] with ``k_l``,
    ``k_s`` in cycles/length and ``m2`` dimensionless. The one source of C: the models call it
    ``psd_amplitude`` (:mod:`roughpetsc.models.persson`).
    """
    return 4.0 * (1.0 - hurst) * m2 / ((2.0 * np.pi) ** 3 * (k_s ** (2 - 2 * hurst) - k_l ** (2 - 2 * hurst)))


def fractal_psd(k, k_l, k_s, hurst, amplitude):
    """Isotropic self-affine PSD (2.18) with k_r = k_l: C k^-2(1+H) on [k_l, k_s], else 0."""
    k = np.asarray(k, dtype=float)
    inside = (k >= k_l) & (k <= k_s)
    psd = np.zeros_like(k)
    psd[inside] = amplitude * k[inside] ** (-2.0 * (1.0 + hurst))
    return psd


def check_fractal_parameters(grid, k_l, k_s, hurst, m2):
    """Raise :class:`ParameterError` for a PSD (2.18) that the grid cannot hold or that does not exist."""
    nyquist = min(grid.n0 / grid.l0, grid.n1 / grid.l1) / 2.0
    if not 0.0 < hurst < 1.0:
        raise ParameterError("hurst", f"the Hurst exponent must lie in (0, 1), got {hurst}")
    if not m2 > 0.0:
        raise ParameterError("m2", f"the mean square slope m2 must be positive, got {m2}")
    if not 0.0 < k_l < k_s:
        raise ParameterError("k_l", f"need 0 < k_l < k_s for the cut-off wavenumbers, got k_l={k_l}, k_s={k_s}")
    if k_s > nyquist:
        raise ParameterError("k_s", f"the cut-off k_s={k_s} exceeds the Nyquist wavenumber {nyquist} of the grid")
    if k_l < 1.0 / max(grid.l0, grid.l1):
        raise ParameterError("k_l", f"the cut-off k_l={k_l} is below the fundamental wavenumber of the cell")


GENERATORS = ("filter", "xu")


def fractal(grid, k_l, k_s, hurst, m2, seed, generator="filter"):
    """Gaussian isotropic self-affine surface of section 7.1, with the PSD (2.18) (k_r = k_l, C from (7.1)).

    White Gaussian noise (unit variance, one sample per node, drawn from
    ``numpy.random.default_rng(seed)``) is transformed and shaped in Fourier space:

    * ``generator="filter"``: multiplied by ``sqrt(S(k) n0 n1 / A0)``, so that the *expected* discrete
      spectrum is the PSD; the amplitude of each mode is random, as the noise's.
    * ``generator="xu"``: (7.2)-(7.5) of the dissertation (Xu and Jackson's algorithm): divided by the
      noise's own spectrum (its modulus, ``S[h0]`` of (7.4)) and multiplied by the same factor, so that
      every realisation carries the prescribed amplitude ``sqrt(S(k))`` exactly and only the phase (that
      of the noise, uniform and Hermitian-symmetric; the random phase theta of (7.5) is absorbed in it)
      is random. Spectral moments are then the same for every seed.

    The Hermitian symmetry (7.5) holds because the noise is real. The result is the same array on every
    MPI rank: each rank computes the whole surface and keeps its rows.

    Returns
    -------
    ndarray, shape (n0, n1): heights with zero mean, length units.
    """
    check_fractal_parameters(grid, k_l, k_s, hurst, m2)
    if generator not in GENERATORS:
        raise ParameterError("generator", f"the surface generator is one of {', '.join(GENERATORS)}, "
                                          f"got '{generator}'")
    amplitude = fractal_amplitude(k_l, k_s, hurst, m2)
    noise = np.random.default_rng(seed).standard_normal(grid.shape)
    spectrum = np.fft.rfft2(noise)
    del noise
    if generator == "xu":
        # The noise's expected |F|^2 is n0 n1: dividing by |F| and multiplying by sqrt(n0 n1) keeps the
        # scale of the filter, so both generators have the same expected moments.
        modulus = np.abs(spectrum)
        spectrum *= np.where(modulus > 0, np.sqrt(grid.size) / np.where(modulus > 0, modulus, 1.0), 0.0)
    k0, k1 = grid.rfft_wavenumbers()
    k = np.hypot(k0, k1)
    spectrum *= np.sqrt(fractal_psd(k, k_l, k_s, hurst, amplitude) * grid.size / grid.area)
    spectrum[0, 0] = 0.0
    return np.fft.irfft2(spectrum, s=grid.shape)


def check_waviness(amplitude, *wavelengths):
    """Raise :class:`ParameterError` unless the amplitude and the wavelengths (length units) are positive."""
    if not amplitude > 0:
        raise ParameterError("amplitude", f"the amplitude must be positive, got {amplitude}")
    if not all(wavelength > 0 for wavelength in wavelengths):
        raise ParameterError("wavelength", f"the wavelength must be positive, got {', '.join(map(str, wavelengths))}")


def check_divides(cell, wavelength):
    """Raise :class:`ParameterError` unless ``wavelength`` divides the periodic cell's side ``cell`` (length units).

    A wave that does not fit a whole number of times into the cell is cut at the cell's edge, and the
    periodic cell repeats that cut: another surface than the one asked for.
    """
    count = cell / wavelength
    if not (round(count) >= 1 and abs(count - round(count)) <= 1e-9 * count):
        raise ParameterError("wavelength", f"the wavelength {wavelength:g} does not divide the cell side {cell:g} "
                                           f"({count:.6g} wavelengths); give the side divided by a whole number "
                                           f"({cell:g}, {cell / 2:g}, {cell / 3:g}, ...)")


def bisinusoid(grid, amplitude, wavelength0, wavelength1):
    """Bisinusoidal waviness (3.52): Delta cos(2 pi y / lambda_y) cos(2 pi x / lambda_x), length units.

    Each wavelength must divide its side of the cell (:func:`check_divides`).
    """
    check_waviness(amplitude, wavelength0, wavelength1)
    check_divides(grid.l0, wavelength0)
    check_divides(grid.l1, wavelength1)
    y, x = grid.coordinates()
    return amplitude * np.cos(2 * np.pi * y / wavelength0) * np.cos(2 * np.pi * x / wavelength1)


def wave(grid, amplitude, wavelength):
    """One-dimensional wave along axis 1 (Westergaard's problem), zero mean.

    The profile ``2 h sin^2(pi x / lambda)`` less its mean ``h``, i.e.
    ``-h cos(2 pi x / lambda)`` with ``h`` = ``amplitude``. Its complete-contact
    pressure is ``p_star = pi E* h / lambda`` (Johnson, Contact Mechanics, 13.2). The wavelength must
    divide the cell length (:func:`check_divides`).
    """
    check_waviness(amplitude, wavelength)
    check_divides(grid.l1, wavelength)
    _, x = grid.coordinates()
    return np.broadcast_to(-amplitude * np.cos(2 * np.pi * x / wavelength), grid.shape).copy()


def hertz_sphere(grid, radius):
    """A paraboloid cap ``-r^2 / (2 R)`` centred in the cell, zero mean (a sphere in a large cell)."""
    if not radius > 0:
        raise ParameterError("radius", f"the radius of the sphere must be positive, got {radius}")
    y, x = grid.coordinates()
    r2 = (y - grid.l0 / 2) ** 2 + (x - grid.l1 / 2) ** 2
    heights = -r2 / (2.0 * radius)
    return heights - heights.mean()


def load(path):
    """Read a surface from ``.npy``, HDF5, CSV or a text file.

    HDF5: the dataset ``surface`` (contact-mechanics-challenge layout) or
    ``heights`` (a roughpetsc output, whose root attribute ``length`` records
    the cell size ``[l0, l1]``). Other suffixes than those of :data:`TABLE_SUFFIXES`
    are instrument files, read by SurfaceTopography (:func:`read_instrument`).
    CSV (``.csv``, commas) and text (blanks) hold
    a height matrix (rows along y, at least 4 columns) or an ``x y z`` point
    list (three columns, one point a line) whose points lie on a uniform grid of
    square nodes (:func:`points_to_grid`); one header line of words is skipped.

    Returns
    -------
    heights : ndarray (n0, n1), length units, zero mean.
    length : float or None
        The recorded cell length along axis 1 (x), length units: that of a roughpetsc
        file, or the number of columns times the node spacing of a point list; None
        if the file does not record one.

    Raises :class:`ParameterError` (parameter ``path``) naming the file if it
    is missing, unreadable or not a finite 2-D array.
    """
    if not os.path.isfile(path):
        raise ParameterError("path", f"no such file: {path}")
    try:
        heights, length = _read_array(path)
    except ParameterError as error:
        raise ParameterError("path", str(error) if str(error).startswith(str(path)) else f"{path}: {error}") from None
    except Exception as exc:  # any reader failure is the file's fault
        raise ParameterError("path", f"{path}: cannot read it ({type(exc).__name__}: {exc})") from None
    try:
        return validate(heights), length
    except ParameterError as error:
        raise ParameterError("path", f"{path}: {error}") from None


# Files read as tables (a height matrix or an x y z point list) by their suffix; HDF5 and .npy by their own
# readers; any other suffix by SurfaceTopography when that optional extra is installed (tools/surfacetopography.sh).
TABLE_SUFFIXES = (".txt", ".csv", ".dat", ".asc", ".xyz", "")
HDF5_SUFFIXES = (".h5", ".hdf5", ".hdf")


def _read_array(path):
    """``(heights as stored, recorded length or None)`` of a surface file, by its suffix."""
    suffix = os.path.splitext(path)[1].lower()
    if suffix == ".npy":
        return np.load(path, allow_pickle=False), None
    if suffix in TABLE_SUFFIXES:
        return table_surface(read_table(path), path)
    if suffix not in HDF5_SUFFIXES:
        return read_instrument(path)
    import h5py

    with h5py.File(path, "r") as f:
        if "surface" in f:
            return f["surface"][()], None
        if "heights" in f:
            length = float(json.loads(f.attrs["length"])[1]) if "length" in f.attrs else None
            return f["heights"][()], length
    raise ParameterError("path", f"{path}: no dataset 'surface' or 'heights' in the HDF5 file")


def read_instrument(path):
    """``(heights, cell length along x or None)`` of an instrument file, read by SurfaceTopography.

    Rows of the result run along y. The length is the file's physical size along x (in the unit of
    its heights), None where the file records none. Without SurfaceTopography (an optional extra,
    ``bash tools/surfacetopography.sh``) the file is read as a table if it is one, else refused.
    """
    try:
        from SurfaceTopography import open_topography
    except ImportError:
        try:
            return table_surface(read_table(path), path)
        except (ParameterError, UnicodeDecodeError):
            raise ParameterError("path", f"{path}: not a format roughpetsc reads (.npy, HDF5, text, CSV); instrument "
                                         "formats are read by SurfaceTopography, an optional extra: bash "
                                         "tools/surfacetopography.sh") from None
    reader = open_topography(path)
    channel = reader.default_channel
    sizes = channel.physical_sizes
    # A file that records its physical sizes fixes them; one that does not gets unit node spacing.
    topography = reader.topography() if sizes is not None else reader.topography(physical_sizes=channel.nb_grid_pts)
    if topography.dim != 2 or not getattr(topography, "is_uniform", True):
        raise ParameterError("path", f"{path}: a line scan or non-uniform data, not a surface on a grid")
    heights = np.asarray(topography.heights()).T  # SurfaceTopography: axis 0 = x
    if sizes is None:
        return heights, None
    nx, ny = channel.nb_grid_pts
    if abs(sizes[0] / nx - sizes[1] / ny) > 1e-6 * sizes[0] / nx:
        raise ParameterError("path", f"{path}: nodes {sizes[0] / nx:.6g} apart along x and {sizes[1] / ny:.6g} along "
                                     "y: the grid needs square nodes")
    return heights, float(sizes[0])


def read_table(path):
    """The numbers of a CSV or text file as a 2-D array; ``#`` comments and one header line of words are skipped.

    The delimiter is the comma for ``.csv`` and for a file whose first line of numbers has one, else blanks.
    """
    with open(path) as handle:
        lines = [line.split("#", 1)[0].strip() for line in handle]
    lines = [line for line in lines if line]
    if not lines:
        raise ParameterError("path", "the file holds no numbers")
    delimiter = "," if path.lower().endswith(".csv") or "," in lines[-1] else None

    def numbers(line):
        return [float(item) for item in line.split(delimiter)]

    try:
        numbers(lines[0])
    except ValueError:  # a header of column names
        lines = lines[1:]
    rows = []
    for number, line in enumerate(lines, 1):
        try:
            rows.append(numbers(line))
        except ValueError:
            raise ParameterError("path", f"a line of data is not numbers: '{line[:60]}'") from None
    widths = {len(row) for row in rows}
    if len(widths) != 1:
        raise ParameterError("path", f"the lines hold different numbers of values ({', '.join(map(str, sorted(widths)))})")
    return np.array(rows, dtype=float).reshape(len(rows), widths.pop())


def table_surface(table, path):
    """``(heights, length)`` of a table: an ``x y z`` point list (3 columns) or a height matrix (4 columns or more)."""
    if table.shape[1] == 3 and table.shape[0] > 3:
        return points_to_grid(table)
    if table.shape[1] < 4:
        raise ParameterError("path", f"{table.shape[0]} rows of {table.shape[1]} values: neither an x y z point list "
                                     "(3 columns, one point a line) nor a height matrix (at least 4 columns)")
    return table, None


def _axis_nodes(values, name):
    """The distinct coordinates ``values`` of a point list along one axis, checked to be equally spaced."""
    nodes = np.unique(values)
    if nodes.size < 2:
        raise ParameterError("path", f"the points of the x y z list have a single {name} coordinate")
    steps = np.diff(nodes)
    spacing = (nodes[-1] - nodes[0]) / (nodes.size - 1)
    if np.abs(steps - spacing).max() > 1e-6 * spacing:
        raise ParameterError("path", f"the {name} coordinates of the x y z list are not equally spaced (steps "
                                     f"{steps.min():.6g} to {steps.max():.6g}): the points do not lie on a grid")
    return nodes, spacing


def points_to_grid(points):
    """The heights of an ``x y z`` point list on a uniform grid of square nodes: ``(heights, cell length along x)``.

    Every node of the grid must be given exactly once; rows of the result run along y (axis 0),
    columns along x. The cell is the grid's extent plus one spacing (the periodic cell repeats
    the nodes). Raises :class:`ParameterError` with the figures when the points do not lie on such a grid.
    """
    x_nodes, dx = _axis_nodes(points[:, 0], "x")
    y_nodes, dy = _axis_nodes(points[:, 1], "y")
    if x_nodes.size * y_nodes.size != points.shape[0]:
        raise ParameterError("path", f"{points.shape[0]} points of an x y z list, but their {x_nodes.size} x and "
                                     f"{y_nodes.size} y coordinates make {x_nodes.size * y_nodes.size} nodes: the "
                                     "points do not fill a grid")
    if abs(dx - dy) > 1e-6 * max(dx, dy):
        raise ParameterError("path", f"the x y z list has spacings {dx:.6g} along x and {dy:.6g} along y: the grid "
                                     "needs square nodes")
    column = np.rint((points[:, 0] - x_nodes[0]) / dx).astype(int)
    row = np.rint((points[:, 1] - y_nodes[0]) / dy).astype(int)
    heights = np.full((y_nodes.size, x_nodes.size), np.nan)
    heights[row, column] = points[:, 2]
    taken = np.zeros(heights.shape, dtype=int)
    np.add.at(taken, (row, column), 1)
    if taken.max() > 1:
        raise ParameterError("path", f"the x y z list gives {int((taken > 1).sum())} node(s) more than once")
    return heights, x_nodes.size * dx


DETRENDS = ("none", "mean", "plane")


def fit_plane(grid, heights):
    """The least-squares plane of ``heights`` over the nodes: ``(mean, slope along x, slope along y)``.

    Slopes in length / length; the plane is ``mean + slope_x (x - xc) + slope_y (y - yc)`` about the
    cell's centre of nodes (xc, yc).
    """
    y, x = grid.coordinates()
    x = np.broadcast_to(x - x.mean(), grid.shape)
    y = np.broadcast_to(y - y.mean(), grid.shape)
    mean = heights.mean()
    slope_x = float(np.sum(x * (heights - mean)) / np.sum(x * x))
    slope_y = float(np.sum(y * (heights - mean)) / np.sum(y * y)) if grid.n0 > 1 else 0.0
    return float(mean), slope_x, slope_y


def plane_heights(grid, slope_x, slope_y):
    """The zero-mean plane ``slope_x (x - xc) + slope_y (y - yc)`` on the nodes, length units."""
    y, x = grid.coordinates()
    return slope_x * (x - x.mean()) + slope_y * (y - y.mean())


@dataclass(frozen=True)
class Levelling:
    """What :func:`level` did to a measured surface and what it found, with the figures of its warnings.

    ``slope_x``, ``slope_y``: the least-squares plane's slopes; ``removed``: whether it was removed;
    ``tilt_rms``: the rms of that plane over the cell; ``rms``: the rms height of the surface used;
    ``edge_jump``: :func:`edge_jumps` of the surface used; ``notes``: the lines to print (``warning: ...``
    for a warning).
    """

    how: str
    slope_x: float
    slope_y: float
    removed: bool
    tilt_rms: float
    rms: float
    edge_jump: dict
    notes: tuple

    def record(self):
        """A JSON-ready summary for the output files."""
        return {"detrend": self.how, "plane_slope_x": self.slope_x, "plane_slope_y": self.slope_y,
                "plane_removed": self.removed, "tilt_rms": self.tilt_rms, "rms": self.rms,
                "edge_jump": {axis: list(values) for axis, values in self.edge_jump.items()},
                "notes": list(self.notes)}


# Edges are compared with neighbouring nodes: a periodic surface steps from its last column (row) to its first as
# from any column to the next. A tilt makes that step a rise of the whole cell, a measurement that is not periodic
# an rms jump, many times those of neighbours; warned of when also above this fraction of the rms height (a tilt
# took alpha_h of a measured surface from 2.5 to 61).
EDGE_WARNING = 0.25
# ... and this many times the neighbours' rms step (jump) or the rms over the columns of their mean step (rise).
EDGE_STEPS = 5.0


def edge_jumps(heights):
    """``{"x": (rise, rms mean step, jump, rms step), "y": ...}``: the last column (row) against the first.

    ``rise`` is the mean of last - first (a tilt across the cell), ``jump`` the rms of that difference;
    ``rms mean step`` is the rms over neighbouring columns (rows) of their mean difference, ``rms step``
    the rms of their differences: what a periodic surface's edges would show. Length units.
    """
    found = {}
    for axis, name in ((1, "x"), (0, "y")):
        if heights.shape[axis] < 3:
            continue
        other = 1 - axis
        difference = np.take(heights, -1, axis=axis) - np.take(heights, 0, axis=axis)
        steps = np.diff(heights, axis=axis)
        found[name] = (float(np.mean(difference)), float(np.sqrt(np.mean(np.mean(steps, axis=other) ** 2))),
                       float(np.sqrt(np.mean(difference ** 2))), float(np.sqrt(np.mean(steps ** 2))))
    return found


def level(grid, heights, how="mean"):
    """Level a measured surface: ``(heights, Levelling)``.

    ``how``: ``none`` (as given), ``mean`` (the mean removed; the contact does not see it, the operator
    has no k = 0 mode) or ``plane`` (the least-squares plane removed, :func:`fit_plane`). The heights
    returned have zero mean whatever ``how`` (:func:`validate`). The notes report the plane removed,
    and warn, with the figures, when a tilt left in place or a jump between opposite edges (a
    measurement that is not periodic: the cell repeats it with a step) is large against the rms height.
    """
    if how not in DETRENDS:
        raise ParameterError("detrend", f"the levelling is one of {', '.join(DETRENDS)}, got '{how}'")
    _, slope_x, slope_y = fit_plane(grid, heights)
    tilt = plane_heights(grid, slope_x, slope_y)
    tilt_rms = float(np.sqrt(np.mean(tilt ** 2)))
    removed = how == "plane"
    if removed:
        heights = heights - tilt
    heights = validate(heights)
    rms = float(np.sqrt(np.mean(heights ** 2)))
    notes = []
    slopes = f"slopes {slope_x:.4g} along x and {slope_y:.4g} along y"
    jumps = edge_jumps(heights)
    if removed:
        notes.append(f"-surface_detrend plane removed the plane of {slopes} (rms {tilt_rms:.4g} over the cell); "
                     f"rms height left {rms:.4g}")
    else:
        rises = {axis: rise for axis, (rise, mean_step, _, _) in jumps.items()
                 if abs(rise) > EDGE_WARNING * rms and abs(rise) > EDGE_STEPS * mean_step}
        if rises:
            said = ", ".join(f"{rise:.4g} from the first to the last {'column' if axis == 'x' else 'row'} "
                             f"({abs(rise) / rms:.3g} of the rms height {rms:.4g})" for axis, rise in rises.items())
            notes.append(f"warning: the surface is tilted: its heights rise on average by {said}; its best-fit "
                         f"plane has {slopes}; -surface_detrend plane levels it")
    for axis, (_, _, jump, step) in jumps.items():
        if jump > EDGE_STEPS * step and jump > EDGE_WARNING * rms:
            notes.append(f"warning: the heights jump by {jump:.4g} rms ({jump / rms:.3g} of the rms height) between "
                         f"the first and last {'columns' if axis == 'x' else 'rows'}, against {step:.4g} between "
                         f"neighbours: the measurement is not periodic, and the periodic cell repeats it with a "
                         f"step at its edges along {axis}")
    return heights, Levelling(how, slope_x, slope_y, removed, tilt_rms, rms, jumps, tuple(notes))


def validate(heights):
    """Check a height array and return it as float64 with zero mean.

    Raises :class:`ParameterError` (parameter ``heights``) for anything but a
    finite, real, non-flat 2-D array of at least 2x2 nodes.
    """
    heights = np.asarray(heights)
    if heights.ndim != 2 or min(heights.shape) < 2:
        raise ParameterError("heights", "a surface must be a 2-D array with at least 2x2 nodes, "
                                        f"got shape {heights.shape}")
    if not np.issubdtype(heights.dtype, np.number) or np.iscomplexobj(heights):
        raise ParameterError("heights", f"heights must be real numbers, got dtype {heights.dtype}")
    heights = heights.astype(np.float64)
    bad = ~np.isfinite(heights)
    if bad.any():
        raise ParameterError("heights", f"{int(bad.sum())} height(s) are NaN or Inf")
    heights = heights - heights.mean()
    # A second pass removes the rounding left by a large offset (heights offset by 1e6 rms).
    heights -= heights.mean()
    if not np.any(heights):
        raise ParameterError("heights", "the surface is flat (all heights equal)")
    return heights


def square_grid(n1, n0=0, length=1.0):
    """The :class:`Grid` of ``n0 x n1`` square nodes (``n0 = 0``: ``n1``) and cell length ``length`` along x."""
    n0 = n0 or n1
    if n1 < 2 or n0 < 1:
        raise ParameterError("n1", f"the grid needs at least 2 columns and 1 row, got {n0} x {n1} nodes")
    if not (length > 0 and np.isfinite(length)):
        raise ParameterError("length", f"the cell length must be positive and finite, got {length}")
    return Grid(n0, n1, length * n0 / n1, length)


# Options of the surface, with defaults: the embedded default is a surface of
# group #1 of Table 7.1, (k_l, k_s, H) = (16, 64, 0.8), m2 = 2e-4, N = 256.
# The one place of these defaults: from_options, parameters and roughpetsc.presets read them here.
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
    ("surface_generator", "filter", "fractal: filter (white noise filtered by sqrt(PSD): random amplitudes) | xu "
                                    "((7.2)-(7.5): exact amplitude sqrt(PSD), random phase; the group presets')"),
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
    """``{name: value}`` of the surface options ``names``, read with the type and default of :data:`SURFACE_OPTIONS`.

    ``opts`` is a ``petsc4py.PETSc.Options`` (or anything with its ``get*`` methods).
    """
    read = {int: opts.getInt, float: opts.getReal, str: opts.getString}
    return {name: read[type(default)](name, default) for name in names for default in (option_default(name),)}


def parameters(opts):
    """The surface's parameters as used, defaults included: ``{option name: value}`` (for output files).

    A surface read from a file is recorded by its path, -surface_L and -surface_detrend.
    """
    if opts.getString("surface_file", ""):
        return option_values(opts, ("surface_file", "surface_L", "surface_detrend"))
    kind = opts.getString("surface_type", "fractal")
    return option_values(opts, ("surface_type", "surface_N", "surface_N0", "surface_L") + TYPE_OPTIONS.get(kind, ()))


def grid_from_options(opts):
    """The :class:`Grid` named by ``-surface_N``, ``-surface_N0`` and ``-surface_L``."""
    given = option_values(opts, ("surface_N", "surface_N0", "surface_L"))
    return square_grid(given["surface_N"], given["surface_N0"], given["surface_L"])


def from_options(opts, seed=None, notes=None):
    """Build the surface named by the options: ``(grid, heights)``, heights of shape ``grid.shape``.

    ``opts`` is a ``petsc4py.PETSc.Options`` (or anything with its ``get*``
    methods). ``seed`` overrides ``-surface_seed`` (ensembles). The full array
    is built on every rank, so the surface does not depend on the number of
    ranks. A surface file is levelled by ``-surface_detrend`` (:func:`level`); its
    :class:`Levelling` is appended to the list ``notes`` if one is given.
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
        keywords = {FRACTAL_KEYWORDS[name]: value for name, value in given.items()}
        heights = fractal(grid, **dict(keywords, seed=keywords["seed"] if seed is None else seed))
    elif kind == "sphere":
        heights = hertz_sphere(grid, given["surface_radius"])
    else:
        amplitude, wavelength = given["surface_amplitude"], given["surface_wavelength"] or grid.l1
        heights = wave(grid, amplitude, wavelength) if kind == "wave" else \
            bisinusoid(grid, amplitude, wavelength * grid.l0 / grid.l1, wavelength)
    return grid, validate(heights)
