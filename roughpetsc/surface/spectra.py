"""Spectral moments, bandwidth parameters and the pressure surface (the dissertation, ch. 2 and sec. 7.2).

Conventions (docs/conventions.md): Fourier pair (2.1)/(2.2), wavenumbers ``k`` in cycles/length, angular
wavenumbers ``2 pi k`` only inside moments (2.12); axis 0 = rows = ``y``, axis 1 = ``x``. Moments of a field
``f`` (h [length] or p_c [pressure]) along one direction come from the discrete spectrum, (2.12)/(2.13), or from
finite differences (7.6)/(7.7). The dissertation's "Num" columns (Tables 7.2-7.6, 8.2, 8.3) are the
finite-difference moments with the stencils of :data:`SEED_STENCILS`; an isotropic surface's ``m_n`` is the mean
of its x and y moments (sec. 7.2.2).
"""

from math import prod

import numpy as np

from ..errors import ParameterError

MOMENT_ORDERS = (0, 2, 4, 6)
AXES = {"x": 1, "y": 0}

# "seed" reproduces the dissertation's tables; "central" is the literal reading of sec. 7.2.1
# ("central differentiation of the derivative of order n - 1"). Stencils: :func:`fd_derivative`.
SEED_STENCILS = "seed"
FD_SCHEMES = ("seed", "central")


# --- Moments of a discrete field

def rfft_multiplicity(n1):
    """How often each ``rfft2`` column appears in the full spectrum, shape (1, n1 // 2 + 1).

    1 for the zero (and, for even ``n1``, the Nyquist) column, 2 for the others (their Hermitian twins).
    """
    weights = np.full((1, n1 // 2 + 1), 2.0)
    weights[0, 0] = 1.0
    if n1 % 2 == 0:
        weights[0, -1] = 1.0
    return weights


def power_spectrum(grid, field):
    """Discrete power ``|DFT(f)_k|^2 / (n0 n1)^2`` [f^2] in the ``rfft2`` layout, Hermitian weights included."""
    spectrum = np.fft.rfft2(field)
    power = spectrum.real ** 2 + spectrum.imag ** 2
    power *= rfft_multiplicity(grid.n1) / float(grid.size) ** 2
    return power


def radial_bin_width(grid):
    """Annulus width of :func:`radial_psd_sums`: the fundamental wavenumber 1 / max(l0, l1) [cycles/length]."""
    return 1.0 / max(grid.l0, grid.l1)


def mode_psd(grid, field):
    """``(|k|, S, multiplicity)`` of every mode of the ``rfft2`` layout of a periodic field.

    ``S(k) = |DFT(f)_k|^2 A / (n0 n1)^2`` is the PSD estimate whose expectation is the PSD of (2.12)
    that :func:`roughpetsc.surfaces.fractal` filters by ((2.18) for its surfaces); ``multiplicity``
    counts the Hermitian twin a column stands for. Units: |k| cycles/length, S [field]^2 length^2.
    """
    k0, k1 = grid.rfft_wavenumbers()
    multiplicity = np.broadcast_to(rfft_multiplicity(grid.n1), (grid.n0, grid.n1 // 2 + 1))
    psd = power_spectrum(grid, field) * grid.area / multiplicity
    return np.hypot(k0, k1), psd, multiplicity


def radial_psd_sums(grid, field):
    """Sums of the PSD over annuli of |k|, to average over annuli and surfaces: ``{"modes", "psd"}`` arrays.

    Annulus ``b = 1, 2, ...`` holds the modes with ``round(|k| / dk) = b`` (:func:`radial_bin_width`) up
    to the Nyquist wavenumber of the coarser direction, where the annuli are whole; ``modes`` counts
    them and ``psd`` sums their S (:func:`mode_psd`).
    """
    k, psd, multiplicity = mode_psd(grid, field)
    width = radial_bin_width(grid)
    count = int(np.floor(min(grid.n0 / grid.l0, grid.n1 / grid.l1) / 2.0 / width + 1e-9))
    annulus = np.rint(k / width).astype(int)
    inside = (annulus >= 1) & (annulus <= count)
    index = annulus[inside] - 1
    return {"modes": np.bincount(index, multiplicity[inside], count),
            "psd": np.bincount(index, (multiplicity * psd)[inside], count)}


def radial_psd(grid, sums):
    """Radially averaged PSD ``(k, psd, modes)`` of :func:`radial_psd_sums`: annulus centres, mean S per mode."""
    k = radial_bin_width(grid) * np.arange(1, sums["modes"].size + 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return k, np.where(sums["modes"] > 0, sums["psd"] / sums["modes"], np.nan), sums["modes"]


def fit_fractal_psd(grid, field, band):
    """Fit (2.18), ``S = C k^-2(1+H)``, to the PSD of the modes of a periodic field with ``|k|`` in ``band``.

    H from the least-squares line ln S = ln C - 2 (1 + H) ln k (a log's bias moves the line, not its slope),
    then C as the mean of S k^2(1+H) (unbiased). ``band = (k_min, k_max)`` [cycles/length]. Returns
    ``{"hurst", "C", "modes", "rms_log_residual"}`` (C in [field]^2 length^(4 - 2H)), or None when fewer than
    two distinct |k| with power lie in the band.
    """
    k, psd, multiplicity = mode_psd(grid, field)
    chosen = (k >= band[0] * (1 - 1e-12)) & (k <= band[1] * (1 + 1e-12)) & (psd > 0)
    if np.unique(k[chosen]).size < 2:
        return None
    w, x, y = multiplicity[chosen], np.log(k[chosen]), np.log(psd[chosen])
    mean_x, mean_y = np.average(x, weights=w), np.average(y, weights=w)
    slope = np.sum(w * (x - mean_x) * (y - mean_y)) / np.sum(w * (x - mean_x) ** 2)
    residual = y - mean_y - slope * (x - mean_x)
    amplitude = np.average(psd[chosen] * k[chosen] ** -slope, weights=w)
    return {"hurst": float(-slope / 2.0 - 1.0), "C": float(amplitude), "modes": float(np.sum(w)),
            "rms_log_residual": float(np.sqrt(np.average(residual ** 2, weights=w)))}


def spectral_moments(grid, field, orders=MOMENT_ORDERS):
    """Directional spectral moments ``m_n0`` (x) and ``m_0n`` (y) of a periodic field, eq. (2.12)/(2.13).

    Parameters
    ----------
    grid : Grid
    field : ndarray, shape grid.shape
        Heights [length] or pressures [pressure].
    orders : sequence of even int

    Returns
    -------
    dict
        ``{"x": {n: m_n0}, "y": {n: m_0n}}`` [field^2 / length^n], from :func:`power_spectrum` without the
        k = 0 mode (``m_0`` is the variance).
    """
    k0, k1 = grid.rfft_wavenumbers()
    power = power_spectrum(grid, field).copy()  # C order (rfft2's is not): the order of the sums below
    power[0, 0] = 0.0
    angular = {"x": 2.0 * np.pi * k1, "y": 2.0 * np.pi * k0}
    return {direction: {n: float(np.sum(power * (w ** 2) ** (n // 2))) for n in orders}
            for direction, w in angular.items()}


def fd_derivative(field, spacing, axis, order, scheme=SEED_STENCILS):
    """Periodic finite-difference derivative along one axis.

    Parameters
    ----------
    field, spacing : ndarray, float
        The field and its node spacing Delta along ``axis`` [length].
    axis, order : int
        0 (y, rows) or 1 (x); order 1, 2 or 3.
    scheme : {"seed", "central"}
        ``"seed"``: ``(f[i+1] - f[i-1]) / (2 Delta)``, ``(f[i+1] - 2 f[i] + f[i-1]) / Delta^2`` and the central
        difference of the latter for order 3; ``"central"``: the central difference ``order`` times.

    Returns
    -------
    ndarray, same shape
        [field] / length^order.
    """
    if scheme not in FD_SCHEMES:
        raise ParameterError("scheme", f"unknown finite-difference scheme {scheme!r}; use one of {FD_SCHEMES}")
    if order not in (1, 2, 3):
        raise ParameterError("order", f"the derivative order must be 1, 2 or 3, got {order}")

    def central(f):
        return (np.roll(f, -1, axis) - np.roll(f, 1, axis)) / (2.0 * spacing)

    def three_point(f):
        return (np.roll(f, -1, axis) - 2.0 * f + np.roll(f, 1, axis)) / spacing ** 2

    if scheme == "central":
        result = field
        for _ in range(order):
            result = central(result)
        return result
    if order == 1:
        return central(field)
    if order == 2:
        return three_point(field)
    return central(three_point(field))


def fd_moments(grid, field, orders=MOMENT_ORDERS, scheme=SEED_STENCILS):
    """Directional moments by finite differences, eqs. (7.6) (x) and (7.7) (y): ``m_n0 = < (d^(n/2) f / dx^(n/2))^2 >``
    over the nodes, ``m_0 = <(f - <f>)^2>``.

    Parameters
    ----------
    grid, field :
        As in :func:`spectral_moments`.
    orders : sequence of even int in (0, 2, 4, 6)
    scheme : {"seed", "central"}
        See :func:`fd_derivative`.

    Returns
    -------
    dict
        ``{"x": {n: m_n0}, "y": {n: m_0n}}`` [field^2 / length^n].
    """
    spacing = {"x": grid.l1 / grid.n1, "y": grid.l0 / grid.n0}
    variance = float(np.mean((field - field.mean()) ** 2))
    return {direction: {n: float(np.mean(fd_derivative(field, spacing[direction], axis, n // 2, scheme) ** 2))
                        if n else variance for n in orders}
            for direction, axis in AXES.items()}


def fd_symbol_squared(k, spacing, order, scheme=SEED_STENCILS):
    """``|symbol|^2`` of :func:`fd_derivative` at ``k`` [cycles/length], in 1 / length^(2 order).

    The expected finite-difference moment of a field with discrete power ``P_k`` is ``sum_k P_k |symbol(k)|^2``.
    """
    theta = 2.0 * np.pi * np.asarray(k, dtype=float) * spacing
    central = (np.sin(theta) / spacing) ** 2
    if scheme == "central":
        return central ** order
    three_point = (2.0 * np.sin(theta / 2.0) / spacing) ** 4
    return {1: central, 2: three_point, 3: central * three_point}[order]


def isotropic_mean(moments):
    """Direction-free moments ``m_n = (m_n0 + m_0n) / 2`` as in sec. 7.2.2 (``{n: m_n}``)."""
    return {n: 0.5 * (moments["x"][n] + moments["y"][n]) for n in moments["x"]}


# --- Bandwidth parameters

def bandwidth(m0, m2, m4):
    """Nayak's bandwidth parameter alpha = m0 m4 / m2^2, eq. (2.16) (also (2.54) with p-moments). Dimensionless."""
    return m0 * m4 / m2 ** 2


def pressure_bandwidth_from_heights(m2h, m4h, m6h):
    """alpha^p = 27/20 m2^h m6^h / (m4^h)^2, eq. (2.54) (for an isotropic Gaussian surface). Dimensionless."""
    return 27.0 / 20.0 * m2h * m6h / m4h ** 2


# --- Closed forms for the self-affine PSD (2.18)

def isotropy_factor(n):
    """``1*3*...*(n-1) / (2*4*...*n)`` of (2.15); 1 for n = 0."""
    if n % 2:
        raise ParameterError("n", f"the moment order must be even, got {n}")
    half = n // 2
    return prod(2 * j - 1 for j in range(1, half + 1)) / prod(2 * j for j in range(1, half + 1))


def fractal_height_moment(n, k_l, k_s, hurst, amplitude, k_r=None):
    """Moment m_n^h [length^(2 - n)] of the PSD (2.18), eq. (2.19); (2.20) when ``k_r = k_l`` (default).

    Cut-offs ``k_l <= k_r <= k_s`` [cycles/length], ``amplitude`` C of (2.18) [length^(2 - 2H)].
    n = 0, 2, 4, 6 give (2.21)-(2.24).
    """
    k_r = k_l if k_r is None else k_r
    plateau = k_r ** (-2.0 * (1.0 + hurst)) / (n + 2) * (k_r ** (n + 2) - k_l ** (n + 2))
    power_law = (k_s ** (n - 2.0 * hurst) - k_r ** (n - 2.0 * hurst)) / (n - 2.0 * hurst)
    return (2.0 * np.pi) ** (n + 1) * isotropy_factor(n) * amplitude * (plateau + power_law)


def fractal_height_bandwidth(k_l, k_s, hurst):
    """alpha^h of the PSD (2.18) with k_r = k_l, eq. (2.25) (zeta = k_s / k_l). Dimensionless."""
    zeta = k_s / k_l
    h = hurst
    return (1.5 * (1 - h) ** 2 / (h * (2 - h))
            * (1 - zeta ** (-2 * h)) * (zeta ** (4 - 2 * h) - 1) / (zeta ** (2 - 2 * h) - 1) ** 2)


def fractal_pressure_moment(n, k_l, k_s, hurst, amplitude, e_star=1.0):
    """Moment m_n^p of the pressure surface for the PSD (2.18), k_r = k_l, eq. (2.55).

    n = 0, 2, 4 give (2.56)-(2.58). Units: pressure^2 / length^n with ``e_star`` in pressure units.
    """
    exponent = n + 2 - 2.0 * hurst
    return (e_star ** 2 * isotropy_factor(n) * (2.0 * np.pi) ** (n + 3) * amplitude
            / (4.0 * exponent) * (k_s ** exponent - k_l ** exponent))


def fractal_pressure_bandwidth(k_l, k_s, hurst):
    """alpha^p of the PSD (2.18) with k_r = k_l, eq. (2.59) (zeta = k_s / k_l). Dimensionless."""
    zeta = k_s / k_l
    h = hurst
    return (1.5 * (2 - h) ** 2 / ((1 - h) * (3 - h))
            * (zeta ** (2 - 2 * h) - 1) * (zeta ** (6 - 2 * h) - 1) / (zeta ** (4 - 2 * h) - 1) ** 2)


def pressure_moment_from_heights(n, height_moments, e_star=1.0):
    """m_n^p = (n + 2) / (4 (n + 1)) E*^2 m_(n+2)^h, eq. (2.52)/(2.53).

    ``height_moments`` maps order to m^h; needs order ``n + 2``. Units: pressure^2 / length^n.
    """
    return (n + 2) / (4.0 * (n + 1)) * e_star ** 2 * height_moments[n + 2]


def fractal_closed_forms(k_l, k_s, hurst, amplitude, e_star=1.0):
    """All closed forms of a fractal group: m_n^h (2.21-2.24), alpha^h (2.25), m_n^p (2.56-2.58), alpha^p (2.59).

    Parameters
    ----------
    k_l, k_s, hurst : float
        As in :func:`fractal`.
    amplitude, e_star : float
        PSD amplitude C of (2.18) and composite modulus E* (1.6) [pressure].

    Returns
    -------
    dict
        ``"h"`` ({0, 2, 4, 6: m_n^h}), ``"p"`` ({0, 2, 4: m_n^p}), ``"alpha_h"`` and ``"alpha_p"``.
    """
    return {
        "h": {n: fractal_height_moment(n, k_l, k_s, hurst, amplitude) for n in MOMENT_ORDERS},
        "p": {n: fractal_pressure_moment(n, k_l, k_s, hurst, amplitude, e_star) for n in (0, 2, 4)},
        "alpha_h": fractal_height_bandwidth(k_l, k_s, hurst),
        "alpha_p": fractal_pressure_bandwidth(k_l, k_s, hurst),
    }


# --- Pressure surface

def pressure_surface(grid, heights, e_star=1.0):
    """Complete-contact pressure p_c = F^-1[pi E* k F[h]], eq. (2.47) (over the ranks:
    :meth:`roughpetsc.westergaard.Westergaard.pressure_surface`).

    Parameters
    ----------
    grid : Grid
    heights : ndarray, shape grid.shape
        Heights [length].
    e_star : float
        Composite modulus E* (1.6) [pressure].

    Returns
    -------
    ndarray, shape grid.shape
        p_c [pressure], zero mean; the dissertation's "pressure surface" is ``-p_c``.
    """
    return np.fft.irfft2(np.fft.rfft2(heights) * complete_contact_symbol(grid, e_star), s=grid.shape)


def complete_contact_symbol(grid, e_star):
    """pi E* |k| on the ``rfft2`` layout of ``grid`` (|k| in cycles/length): complete-contact pressure over height."""
    k0, k1 = grid.rfft_wavenumbers()
    return np.pi * e_star * np.hypot(k0, k1)


def heights_from_pressure_surface(grid, complete_contact_pressure, e_star=1.0):
    """Zero-mean heights whose complete-contact pressure is the given field: the inverse of :func:`pressure_surface`.

    Parameters
    ----------
    grid, e_star :
        As in :func:`pressure_surface`.
    complete_contact_pressure : ndarray, shape grid.shape
        p_c [pressure].

    Returns
    -------
    ndarray, shape grid.shape
        h = F^-1[F[p_c] / (pi E* k)] [length] without the k = 0 mode: its p_c is ``p_c - mean(p_c)``.
    """
    symbol = complete_contact_symbol(grid, e_star)
    symbol[0, 0] = 1.0
    spectrum = np.fft.rfft2(complete_contact_pressure) / symbol
    spectrum[0, 0] = 0.0
    return np.fft.irfft2(spectrum, s=grid.shape)


# --- Everything for one surface

def surface_moment_summary(grid, heights, e_star=1.0, scheme=SEED_STENCILS):
    """Moments and bandwidths of a surface and of its pressure surface.

    Returns a dict: ``"h_fd"``, ``"h_spectral"``: directional moments of h, n = 0..6 ((7.6)/(7.7) and (2.12));
    ``"p_fd"``, ``"p_spectral"``: the same for p_c (2.47), n = 0..4; ``"alpha_h"``, ``"alpha_p"``: (2.16)/(2.54)
    from the finite-difference moments ("Num"); ``"alpha_h_spectral"``, ``"alpha_p_spectral"``: from the
    spectrum; ``"alpha_p_from_h"``: 27/20 m2 m6 / m4^2 (2.54) with the spectral m^h.
    """
    pressure = pressure_surface(grid, heights, e_star)
    summary = {
        "h_fd": fd_moments(grid, heights, MOMENT_ORDERS, scheme),
        "h_spectral": spectral_moments(grid, heights, MOMENT_ORDERS),
        "p_fd": fd_moments(grid, pressure, (0, 2, 4), scheme),
        "p_spectral": spectral_moments(grid, pressure, (0, 2, 4)),
    }
    for key, source in (("", "fd"), ("_spectral", "spectral")):
        mh = isotropic_mean(summary["h_" + source])
        mp = isotropic_mean(summary["p_" + source])
        summary["alpha_h" + key] = bandwidth(mh[0], mh[2], mh[4])
        summary["alpha_p" + key] = bandwidth(mp[0], mp[2], mp[4])
    mh = isotropic_mean(summary["h_spectral"])
    summary["alpha_p_from_h"] = pressure_bandwidth_from_heights(mh[2], mh[4], mh[6])
    return summary
