"""Measured surfaces read from files: .npy, text and CSV matrices or x y z point lists, HDF5, instrument files.

A surface read from a file is levelled (:func:`level`: none, its mean or its least-squares plane) and
checked (:func:`validate`); a large tilt or a jump between opposite edges (a measurement that is not
periodic) is reported in its :class:`Levelling`.
"""

from dataclasses import dataclass
import json
import os

import numpy as np

from ..errors import ParameterError


def load(path):
    """Read a surface from ``.npy``, HDF5, CSV, text or an instrument file.

    HDF5: the dataset ``surface`` (contact-mechanics-challenge layout) or ``heights`` (a roughpetsc output, its
    root attribute ``length`` = ``[l0, l1]``). Suffixes outside :data:`TABLE_SUFFIXES` are instrument files
    (:func:`read_instrument`). CSV and text hold a height matrix (rows along y, >= 4 columns) or an ``x y z``
    point list (:func:`points_to_grid`). Raises :class:`ParameterError` (``path``) naming the file if it is
    missing, unreadable or not a finite 2-D array.

    Returns
    -------
    heights : ndarray, shape (n0, n1)
        Heights [length], zero mean.
    length : float or None
        The recorded cell length along x [length], or None.
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


TABLE_SUFFIXES = (".txt", ".csv", ".dat", ".asc", ".xyz", "")


def _read_array(path):
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

    Rows run along y. Without SurfaceTopography (``bash tools/surfacetopography.sh``) a table is still read.
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
    """The numbers of a CSV or text file as a 2-D array; ``#`` comments and one header line are skipped."""
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
        raise ParameterError("path", "the lines hold different numbers of values "
                                     f"({', '.join(map(str, sorted(widths)))})")
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

    Every node must be given once; rows run along y. The cell is the grid's extent plus one spacing.
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
    """The least-squares plane ``mean + slope_x (x - xc) + slope_y (y - yc)`` about the nodes' centre."""
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
    """What :func:`level` did to a measured surface and found: the plane's slopes, whether it was removed, its
    rms ``tilt_rms``, the surface's ``rms``, its :func:`edge_jumps` and the ``notes`` to print."""

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


# A tilt or a non-periodic measurement makes the step from the last column (row) to the first many times that
# between neighbours; warned of when also above this fraction of the rms height (a tilt took a measured
# surface's alpha_h from 2.5 to 61).
EDGE_WARNING = 0.25
# ... and this many times the neighbours' rms step (jump) or the rms over the columns of their mean step (rise).
EDGE_STEPS = 5.0


def edge_jumps(heights):
    """``{"x": (rise, rms mean step, jump, rms step), "y": ...}`` [length]: the last column (row) against the first.

    ``rise``, ``jump``: mean and rms of last - first; the steps: the same between neighbours.
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
    """Level a measured surface: ``(heights, Levelling)``, the heights with zero mean (:func:`validate`).

    ``how``: ``none``, ``mean`` or ``plane`` (:func:`fit_plane` removed). The notes warn when a tilt left in
    place or a jump between opposite edges is large against the rms height.
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
    """Check a height array (finite, real, non-flat, 2-D, >= 2x2) and return it as float64 with zero mean."""
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


HDF5_SUFFIXES = (".h5", ".hdf5", ".hdf")
