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

from .errors import ParameterError
from .fftw import planner_effort

COMPONENTS = ("xx", "yy", "zz", "xy", "yz", "xz")


class PeriodicTransfer:
    """The transfer functions (3.26) on wavenumbers ``(k0, k1)`` (cycles/length), their depth-free parts made once.

    ``k0`` runs along axis 0 (``y``), ``k1`` along axis 1 (``x``). Each normal and in-plane transfer is
    ``decay (a + kz b)`` with ``decay = exp(-2 pi |k| z)``, ``kz = 2 pi |k| z`` and depth-free ``a``,
    ``b``; the shear ones are ``2 pi i k_{x,y} z decay``. All are zero at ``k = 0`` (module docstring).
    """

    def __init__(self, k0, k1, nu):
        ky, kx = np.broadcast_arrays(k0, k1)
        k = np.hypot(kx, ky)
        positive = k > 0
        safe = np.where(positive, k, 1.0)
        cx2, cy2, cxy = kx * kx / safe ** 2, ky * ky / safe ** 2, kx * ky / safe ** 2
        self.two_pi_k = np.where(positive, 2.0 * np.pi * safe, 0.0)
        self.zero_mode = ~positive
        self.normal = {"xx": (-(cx2 + 2.0 * nu * cy2), cx2), "yy": (-(cy2 + 2.0 * nu * cx2), cy2),
                       "zz": (-np.ones_like(k), -np.ones_like(k)), "xy": (-cxy * (1.0 - 2.0 * nu), cxy)}
        self.shear = {"yz": 2.0 * np.pi * ky, "xz": 2.0 * np.pi * kx}

    def apply(self, source, depth, out):
        """Yield each component's name after writing ``out = transfer * source`` (complex spectra)."""
        kz = self.two_pi_k * depth
        decay = np.exp(-kz)
        np.copyto(decay, 0.0, where=self.zero_mode)
        factor = np.empty_like(decay)
        for name, (a, b) in self.normal.items():
            np.multiply(kz, b, out=factor)
            factor += a
            factor *= decay
            np.multiply(source, factor, out=out)
            yield name
        for name, wavenumber in self.shear.items():
            np.multiply(wavenumber, depth, out=factor)
            factor *= decay
            np.multiply(source, factor, out=out)
            out *= 1j
            yield name


def uniform_state(mean_pressure, nu):
    """Stresses of a uniform pressure over the whole surface: uniaxial strain."""
    lateral = -nu / (1.0 - nu) * mean_pressure
    return {"xx": lateral, "yy": lateral, "zz": -mean_pressure, "xy": 0.0, "yz": 0.0, "xz": 0.0}


def von_mises(s):
    """The von Mises equivalent stress of the components in dict ``s`` (two arrays of scratch, no more)."""
    total = np.subtract(s["xx"], s["yy"])
    total *= total
    difference = np.empty_like(total)
    for first, second in (("yy", "zz"), ("zz", "xx")):
        np.subtract(s[first], s[second], out=difference)
        difference *= difference
        total += difference
    total *= 0.5
    for name in ("xy", "yz", "xz"):
        np.multiply(s[name], s[name], out=difference)
        difference *= 3.0
        total += difference
    return np.sqrt(total, out=total)


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


def periodic_stresses(pressure, lengths, depths, nu):
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

    Yields
    ------
    DepthStresses
        One per depth, in the order given; only one depth's fields are held at a time.
    """
    import pyfftw

    depths = check_depths(depths)
    check_poisson(nu)
    n0, n1 = pressure.shape
    # One forward transform for all depths, one inverse per component and depth, on FFTW plans made once.
    real = pyfftw.empty_aligned((n0, n1), dtype="float64")
    spectrum = pyfftw.empty_aligned((n0, n1 // 2 + 1), dtype="complex128")
    effort = planner_effort("FFTW_ESTIMATE")
    forward = pyfftw.FFTW(real, spectrum, axes=(0, 1), flags=(effort,))
    backward = pyfftw.FFTW(spectrum, real, axes=(0, 1), direction="FFTW_BACKWARD",
                           flags=(effort, "FFTW_DESTROY_INPUT"))
    real[...] = pressure
    forward.execute()
    pressure_spectrum = spectrum / (n0 * n1)  # the unnormalised pair's 1 / (n0 n1)
    k0 = np.fft.fftfreq(n0, d=lengths[0] / n0)[:, None]
    k1 = np.fft.rfftfreq(n1, d=lengths[1] / n1)[None, :]
    uniform = uniform_state(float(pressure.mean()), nu)
    transfer = PeriodicTransfer(k0, k1, nu)
    for depth in depths:
        components = {}
        for name in transfer.apply(pressure_spectrum, depth, spectrum):
            backward.execute()
            components[name] = real + uniform[name]
        equivalent = von_mises(components)
        location = np.unravel_index(int(np.argmax(equivalent)), equivalent.shape)
        yield DepthStresses(float(depth), components, equivalent, float(equivalent[location]),
                            tuple(int(i) for i in location))


def _corner_terms(X, Y, z, nu):
    """The six stresses of a unit pressure on the quarter plane beyond a corner at offsets (X, Y), depth z.

    From Love's potentials of a uniform normal pressure (Johnson, Contact Mechanics, 1985, section 3.2):
    ``psi = int 1/rho`` and ``psi1 = int ln(rho + z)`` over the loaded area, whose derivatives over a
    rectangle are sums over its corners of the elementary terms below (each a primitive in X and Y of
    the point-load integrand). ``z >= 0``; X and Y are never 0 (corners are half a node off the nodes).
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

    The corner sum of :func:`_corner_terms` over the element ``dx x dy``: the free-boundary
    counterpart of (3.31) for the stresses. Offsets are never on an element edge for node-centred
    field points (``|offset| = (i + 1/2) dx`` at the corners).
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


def padded_influence(n0, n1, spacing, depth, nu):
    """:func:`element_influence` at every offset between two nodes of an ``n0 x n1`` grid, in the wrapped
    layout of the zero-padded ``2 n0 x 2 n1`` FFT (offset i at index i mod 2 n0; the offsets of n0 rows
    and n1 columns, which never occur, hold 0).

    Neighbouring elements share corners, so the corner terms are evaluated once on the lattice of the
    (2 n0 + 2) x (2 n1 + 2) corner positions and each element's sum is a difference of the lattice: a
    quarter of the transcendental functions of a sum over each element's own four corners.
    """
    dy, dx = spacing
    corner_y = ((np.arange(2 * n0 + 2) - n0 - 0.5) * dy)[:, None]
    corner_x = ((np.arange(2 * n1 + 2) - n1 - 0.5) * dx)[None, :]
    kernels = {}
    for name, c in _corner_terms(corner_x, corner_y, depth, nu).items():
        # element at unwrapped offset k: corners k - 1/2 and k + 1/2, i.e. lattice k and k + 1 (k = 0 is -n0)
        element = c[1:, 1:] - c[1:, :-1] - c[:-1, 1:] + c[:-1, :-1]
        element = np.roll(element[1:, 1:], (-(n0 - 1), -(n1 - 1)), axis=(0, 1))
        element[n0, :] = 0.0
        element[:, n1] = 0.0
        kernels[name] = element
    return kernels


def free_stresses(pressure, spacing, depths, nu):
    """Stresses at each depth below a pressure on an isolated (non-periodic) half-space.

    The free-boundary counterpart of :func:`periodic_stresses`: the influence of every element
    (:func:`element_influence`, exact for piecewise-constant pressure) convolved with the pressure by
    FFT on the zero-padded ``2 n0 x 2 n1`` grid, like the displacements of :mod:`roughpetsc.love`.

    Parameters
    ----------
    pressure : ndarray (n0, n1)
        The whole surface pressure (pressure units, compression positive); zero outside the grid.
    spacing : (dy, dx)
        Node spacings along axes 0 and 1.
    depths, nu :
        As in :func:`periodic_stresses`.

    Yields
    ------
    DepthStresses
    """
    import pyfftw

    depths = check_depths(depths)
    check_poisson(nu)
    n0, n1 = pressure.shape
    # FFTW plans on the padded grid made once: one forward transform of the pressure, then per component and
    # depth one forward of the kernel and one inverse of the product.
    real = pyfftw.empty_aligned((2 * n0, 2 * n1), dtype="float64")
    spectrum = pyfftw.empty_aligned((2 * n0, n1 + 1), dtype="complex128")
    effort = planner_effort("FFTW_ESTIMATE")
    forward = pyfftw.FFTW(real, spectrum, axes=(0, 1), flags=(effort,))
    backward = pyfftw.FFTW(spectrum, real, axes=(0, 1), direction="FFTW_BACKWARD",
                           flags=(effort, "FFTW_DESTROY_INPUT"))
    real[...] = 0.0
    real[:n0, :n1] = pressure
    forward.execute()
    pressure_spectrum = spectrum / real.size  # the unnormalised pair's 1 / size
    for depth in depths:
        components = {}
        for name, kernel in padded_influence(n0, n1, spacing, depth, nu).items():
            real[...] = kernel
            forward.execute()
            spectrum *= pressure_spectrum
            backward.execute()
            components[name] = real[:n0, :n1].copy()
        equivalent = von_mises(components)
        location = np.unravel_index(int(np.argmax(equivalent)), equivalent.shape)
        yield DepthStresses(float(depth), components, equivalent, float(equivalent[location]),
                            tuple(int(i) for i in location))
