"""Stresses below the surface of the periodic half-space, from the contact pressure, (3.26).

The transfer functions (3.26) of the dissertation give the six stress components at depth ``z``
(``eta`` there, positive into the body) from the transform of the surface pressure ``p`` (positive
in compression; stresses positive in tension, so ``sigma_zz = -p`` at ``z = 0``). With the Fourier
pair (2.1)/(2.2), a derivative is the factor ``2 pi i k``; the shear transfers are imaginary.

The mean pressure (``k = 0``) is the one mode (3.26) leaves undefined: a uniform pressure on the
whole surface of a half-space strains it uniaxially (no lateral strain, by translation invariance),
so it adds ``sigma_zz = -pbar`` and ``sigma_xx = sigma_yy = -nu / (1 - nu) pbar`` at every depth.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from ..errors import ParameterError
from ..fft.plans import planner_effort

COMPONENTS = ("xx", "yy", "zz", "xy", "yz", "xz")


@njit(cache=True)
def depth_decay(k0, k1, depth, kz, decay):
    """``kz = 2 pi |k| z`` and ``decay = exp(-kz)`` on the half spectrum of ``(k0, k1)`` (cycles per length).

    The rows of ``ky`` and ``-ky`` share their exponentials.
    """
    rows, columns = kz.shape
    for row in range(rows):
        mirror = rows - row
        if row > rows // 2 and k0[mirror] == -k0[row]:
            kz[row] = kz[mirror]
            decay[row] = decay[mirror]
            continue
        for j in range(columns):
            kz[row, j] = 2.0 * np.pi * np.sqrt(k1[j] * k1[j] + k0[row] * k0[row]) * depth
            decay[row, j] = np.exp(-kz[row, j])


@njit(cache=True, error_model="numpy")
def periodic_transfer(source, k0, k1, kz, decay, depth, nu, component, zero_mode, out):
    """``out = transfer * source``: the spectrum of stress ``COMPONENTS[component]`` at ``depth``, (3.26).

    ``source`` is the pressure's half spectrum (already divided by the node count), ``kz`` and ``decay``
    those of :func:`depth_decay`. With ``c_ij = k_i k_j / |k|^2`` and ``w = decay (kz - (1 - 2 nu))``:
    ``sigma_xx = c_xx w - 2 nu decay``, ``sigma_yy = c_yy w - 2 nu decay``, ``sigma_zz = -(1 + kz) decay``,
    ``sigma_xy = c_xy w`` (for ``k != 0``, where ``c_xx + c_yy = 1``) and the shear ones
    ``2 pi i k_{y,x} z decay``. The zero mode is ``zero_mode``, which the unnormalised inverse adds to every
    node (module docstring).
    """
    compliance = 1.0 - 2.0 * nu
    for row in range(source.shape[0]):
        ky = k0[row]
        for j in range(source.shape[1]):
            kx = k1[j]
            s = source[row, j]
            d = decay[row, j]
            if component < 2 or component == 3:
                w = d * (kz[row, j] - compliance) / (kx * kx + ky * ky)
                if component == 0:
                    out[row, j] = s * (kx * kx * w - 2.0 * nu * d)
                elif component == 1:
                    out[row, j] = s * (ky * ky * w - 2.0 * nu * d)
                else:
                    out[row, j] = s * (kx * ky * w)
            elif component == 2:
                out[row, j] = s * (-(1.0 + kz[row, j]) * d)
            else:
                out[row, j] = 1j * s * (2.0 * np.pi * depth * d * (ky if component == 4 else kx))
    out[0, 0] = zero_mode


def uniform_state(mean_pressure, nu):
    """Stresses of a uniform pressure over the whole surface: uniaxial strain."""
    lateral = -nu / (1.0 - nu) * mean_pressure
    return {"xx": lateral, "yy": lateral, "zz": -mean_pressure, "xy": 0.0, "yz": 0.0, "xz": 0.0}


def von_mises(s):
    """The von Mises equivalent stress of the components in dict ``s`` (arrays of one shape)."""
    return _von_mises_and_where_largest(s)[0]


def _von_mises_and_where_largest(s):
    """The von Mises stress of dict ``s`` and the (row, column) of its largest value."""
    equivalent = np.empty(np.shape(s["xx"]))
    flat = (np.ascontiguousarray(s[name], dtype=float).reshape(-1) for name in COMPONENTS)
    where = _von_mises_and_maximum(*flat, equivalent.reshape(-1))
    return equivalent, tuple(int(i) for i in np.unravel_index(where, equivalent.shape))


@njit(cache=True, fastmath={"reassoc"})
def _von_mises_and_maximum(xx, yy, zz, xy, yz, xz, out):
    """``out`` = the von Mises stress of the flat components; returns the index of its first maximum."""
    largest = -1.0
    where = 0
    for i in range(out.size):
        normal = (xx[i] - yy[i]) ** 2 + (yy[i] - zz[i]) ** 2 + (zz[i] - xx[i]) ** 2
        value = np.sqrt(3.0 * (normal / 6.0 + xy[i] * xy[i] + yz[i] * yz[i] + xz[i] * xz[i]))
        out[i] = value
        if value > largest:
            largest = value
            where = i
    return where


def max_shear(s):
    """The maximum shear stress (half the spread of the principal stresses) at every point."""
    tensor = np.stack([np.stack([s["xx"], s["xy"], s["xz"]], -1),
                       np.stack([s["xy"], s["yy"], s["yz"]], -1),
                       np.stack([s["xz"], s["yz"], s["zz"]], -1)], -2)
    principal = np.linalg.eigvalsh(tensor)
    return 0.5 * (principal[..., -1] - principal[..., 0])


@dataclass
class DepthStresses:
    """The stress state at one depth: components (pressure units), von Mises stress and its maximum."""

    depth: float
    components: dict
    von_mises: np.ndarray
    max_von_mises: float
    max_location: tuple  # (row, column) of the node of the maximum


def check_depths(depths):
    depths = np.asarray(depths, dtype=float)
    if depths.ndim != 1 or depths.size == 0 or not np.all(np.isfinite(depths)) or np.any(depths < 0):
        raise ParameterError("depths", f"stress depths must be finite and non-negative, got {depths.tolist()}")
    return depths


def check_poisson(nu):
    if not -1.0 < nu < 0.5:
        raise ParameterError("nu", f"Poisson's ratio must lie in (-1, 0.5), got {nu}")


def fft_pair(shape, effort):
    """FFTW plans ``real -> spectrum`` and back on aligned arrays of ``shape`` (the backward destroys its input)."""
    import pyfftw

    real = pyfftw.empty_aligned(shape, dtype="float64")
    spectrum = pyfftw.empty_aligned((shape[0], shape[1] // 2 + 1), dtype="complex128")
    effort = planner_effort(effort)
    forward = pyfftw.FFTW(real, spectrum, axes=(0, 1), flags=(effort,))
    backward = pyfftw.FFTW(spectrum, real, axes=(0, 1), direction="FFTW_BACKWARD",
                           flags=(effort, "FFTW_DESTROY_INPUT"))
    return real, spectrum, forward, backward


def _inverse_into_new_array(backward, spectrum):
    """The backward transform of ``spectrum`` (destroyed) into a new aligned array."""
    import pyfftw

    out = pyfftw.empty_aligned(backward.output_shape, dtype="float64")
    backward.update_arrays(spectrum, out)
    backward.execute()
    return out


def _depth_result(depth, components):
    """The :class:`DepthStresses` of C-contiguous ``components``, their von Mises stress and its maximum."""
    equivalent, location = _von_mises_and_where_largest(components)
    return DepthStresses(float(depth), components, equivalent, float(equivalent[location]), location)


def periodic_stresses(pressure, lengths, depths, nu, effort="FFTW_MEASURE"):
    """Stresses at each depth below a periodic surface pressure, (3.26); one :class:`DepthStresses` each.

    Parameters
    ----------
    pressure : ndarray (n0, n1)
        The whole surface pressure (pressure units, compression positive).
    lengths : (l0, l1)
        Cell lengths along axes 0 and 1.
    depths : sequence of float
        Depths below the surface (length units, >= 0).
    nu : float
        Poisson's ratio of the elastic body.
    effort : str
        FFTW planner effort (the operator's, so that its plans are reused).

    Yields
    ------
    DepthStresses
        One per depth, in the order given.
    """
    depths = check_depths(depths)
    check_poisson(nu)
    n0, n1 = pressure.shape
    real, spectrum, forward, backward = fft_pair((n0, n1), effort)
    real[...] = pressure
    forward.execute()
    source = spectrum / (n0 * n1)  # the unnormalised pair's 1 / (n0 n1); spectrum is each component's in turn
    k0 = np.fft.fftfreq(n0, d=lengths[0] / n0)
    k1 = np.fft.rfftfreq(n1, d=lengths[1] / n1)
    uniform = uniform_state(float(pressure.mean()), nu)
    kz, decay = np.empty(source.shape), np.empty(source.shape)
    for depth in depths:
        depth_decay(k0, k1, depth, kz, decay)
        components = {}
        for index, name in enumerate(COMPONENTS):
            periodic_transfer(source, k0, k1, kz, decay, depth, nu, index, uniform[name], spectrum)
            components[name] = _inverse_into_new_array(backward, spectrum)
        yield _depth_result(depth, components)


def _corner_terms(X, Y, z, nu):
    """The six stresses of a unit pressure on the quarter plane beyond a corner at offsets (X, Y), depth z >= 0.

    Corner terms of Love's potentials ``psi = int 1/rho``, ``psi1 = int ln(rho + z)`` (Johnson, Contact
    Mechanics, 1985, section 3.2); X and Y are never 0.
    """
    rho = np.sqrt(X * X + Y * Y + z * z)
    xz2, yz2 = X * X + z * z, Y * Y + z * z
    psi_z = -np.arctan2(X * Y, z * rho)  # the solid angle; -pi/2 sign(XY) on the surface
    psi_xx = -X * Y / (xz2 * rho)
    psi_yy = -X * Y / (yz2 * rho)
    psi_zz = X * Y * (rho * rho + z * z) / (rho * xz2 * yz2)
    psi_xy = 1.0 / rho
    psi_xz = -z * Y / (rho * xz2)
    psi_yz = -z * X / (rho * yz2)
    psi1_xx = np.arctan(Y / X) - np.arctan(z * Y / (X * rho))
    psi1_yy = np.arctan(X / Y) - np.arctan(z * X / (Y * rho))
    psi1_xy = np.log(rho + z)
    scale = 1.0 / (2.0 * np.pi)
    return {
        "xx": scale * (2 * nu * psi_z - z * psi_xx - (1 - 2 * nu) * psi1_xx),
        "yy": scale * (2 * nu * psi_z - z * psi_yy - (1 - 2 * nu) * psi1_yy),
        "zz": scale * (psi_z - z * psi_zz),
        "xy": -scale * ((1 - 2 * nu) * psi1_xy + z * psi_xy),
        "xz": -scale * z * psi_xz,
        "yz": -scale * z * psi_yz,
    }


def element_influence(offset_x, offset_y, dx, dy, depth, nu):
    """Stresses at depth under the offsets from the centre of one element carrying unit pressure.

    The corner sum of :func:`_corner_terms` over the element ``dx x dy``, the counterpart of (3.31).
    """
    hx, hy = 0.5 * dx, 0.5 * dy
    total = None
    for sx, sy, sign in ((hx, hy, 1.0), (hx, -hy, -1.0), (-hx, hy, -1.0), (-hx, -hy, 1.0)):
        terms = _corner_terms(offset_x + sx, offset_y + sy, depth, nu)
        if total is None:
            total = {name: sign * value for name, value in terms.items()}
        else:
            for name, value in terms.items():
                total[name] += sign * value
    return total


# Parities of the element influences in (y, x): a normal stress is even in both offsets, sigma_xy odd in
# both, sigma_xz odd in x and sigma_yz odd in y (the point load's, Johnson 1985, (3.1x)).
PARITY = {"xx": (1.0, 1.0), "yy": (1.0, 1.0), "zz": (1.0, 1.0), "xy": (-1.0, -1.0), "xz": (1.0, -1.0),
          "yz": (-1.0, 1.0)}


def padded_influence(n0, n1, spacing, depth, nu, out=None):
    """Yield ``(component, kernel)``: :func:`element_influence` at every offset between two nodes of an
    ``n0 x n1`` grid, in the wrapped layout of the zero-padded ``2 n0 x 2 n1`` FFT, written into ``out`` if given.

    The corner terms are evaluated once on the lattice of corners of the quadrant of offsets >= 0, the rest
    follows by :data:`PARITY`: a sixteenth of the transcendental functions of a sum per element.
    """
    dy, dx = spacing
    corner_y = ((np.arange(n0 + 1) - 0.5) * dy)[:, None]
    corner_x = ((np.arange(n1 + 1) - 0.5) * dx)[None, :]
    for name, c in _corner_terms(corner_x, corner_y, depth, nu).items():
        # element at offset k >= 0: corners k - 1/2 and k + 1/2, i.e. lattice k and k + 1
        quadrant = c[1:, 1:] - c[1:, :-1] - c[:-1, 1:] + c[:-1, :-1]
        sign_y, sign_x = PARITY[name]
        kernel = np.empty((2 * n0, 2 * n1)) if out is None else out
        kernel[n0, :] = 0.0
        kernel[:, n1] = 0.0
        kernel[:n0, :n1] = quadrant
        # offset -m sits at index 2 n - m (m = 1 ... n - 1)
        np.multiply(quadrant[:0:-1, :], sign_y, out=kernel[n0 + 1:, :n1])
        np.multiply(quadrant[:, :0:-1], sign_x, out=kernel[:n0, n1 + 1:])
        np.multiply(quadrant[:0:-1, :0:-1], sign_y * sign_x, out=kernel[n0 + 1:, n1 + 1:])
        yield name, kernel


def free_stresses(pressure, spacing, depths, nu, effort="FFTW_MEASURE"):
    """Stresses at each depth below a pressure on an isolated (non-periodic) half-space.

    :func:`element_influence` convolved with the pressure by FFT on the zero-padded ``2 n0 x 2 n1`` grid.

    Parameters
    ----------
    pressure : ndarray (n0, n1)
        The whole surface pressure (pressure units, compression positive); zero outside the grid.
    spacing : (dy, dx)
        Node spacings along axes 0 and 1.
    depths, nu, effort :
        As in :func:`periodic_stresses`.

    Yields
    ------
    DepthStresses
    """
    depths = check_depths(depths)
    check_poisson(nu)
    n0, n1 = pressure.shape
    real, spectrum, forward, backward = fft_pair((2 * n0, 2 * n1), effort)
    real[...] = 0.0
    real[:n0, :n1] = pressure
    forward.execute()
    pressure_spectrum = spectrum / real.size  # the unnormalised pair's 1 / size
    for depth in depths:
        components = {}
        for name, _ in padded_influence(n0, n1, spacing, depth, nu, out=real):
            forward.execute()
            spectrum *= pressure_spectrum
            backward.execute()
            components[name] = real[:n0, :n1].copy()
        yield _depth_result(depth, components)
