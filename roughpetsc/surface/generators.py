"""Generated periodic surfaces on a uniform grid: self-affine fractals (7.1)-(7.5), bisinusoid (3.52), wave, sphere.

A surface is a real ``(n0, n1)`` array with zero mean, axis 0 (rows, ``y``) distributed over the ranks; wavenumbers
in cycles per length (2.1)/(2.2). Bad values raise :class:`~roughpetsc.errors.ParameterError` naming the parameter.
"""

import numpy as np

from ..errors import ParameterError


def fractal_amplitude(k_l, k_s, hurst, m2):
    """PSD amplitude C of (2.18) with k_r = k_l from a prescribed m2^h, eq. (7.1).

    C [length^(4-2H)] with ``k_l``, ``k_s`` in cycles/length; the models call it ``psd_amplitude``.
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
    if not (m2 > 0.0 and np.isfinite(m2)):
        raise ParameterError("m2", f"the mean square slope m2 must be positive and finite, got {m2}")
    if not (k_s > 0.0 and np.isfinite(k_s)):
        raise ParameterError("k_s", f"the cut-off k_s must be a positive, finite wavenumber, got {k_s}")
    if not 0.0 < k_l < k_s:
        # Cut-offs in the wrong order: either may be the one meant otherwise.
        parameter = "cut_offs" if 0.0 < k_l < np.inf else "k_l"
        raise ParameterError(parameter, f"need 0 < k_l < k_s for the cut-off wavenumbers, got k_l={k_l}, k_s={k_s}")
    if k_s > nyquist:
        raise ParameterError("k_s", f"the cut-off k_s={k_s} exceeds the Nyquist wavenumber {nyquist} of the grid")
    if k_l < 1.0 / max(grid.l0, grid.l1):
        raise ParameterError("k_l", f"the cut-off k_l={k_l} is below the fundamental wavenumber of the cell")


GENERATORS = ("filter", "xu")
DEFAULT_GENERATOR = "filter"  # the command line's embedded surface and files written before the choice existed


def fractal(grid, k_l, k_s, hurst, m2, seed, generator=DEFAULT_GENERATOR):
    """Gaussian isotropic self-affine surface of section 7.1, with the PSD (2.18) (k_r = k_l, C from (7.1)).

    Parameters
    ----------
    grid : Grid
    k_l, k_s : float
        Cut-off wavenumbers, 0 < k_l < k_s [cycles/length].
    hurst, m2 : float
        Hurst exponent H in (0, 1) and slope moment m2^h [-] (fixes C by (7.1)).
    seed : int
        Seed of the white Gaussian noise (``numpy.random.default_rng``) shaped in Fourier space.
    generator : {"filter", "xu"}
        ``"filter"``: multiplied by ``sqrt(S(k) n0 n1 / A0)``, so the *expected* spectrum is the PSD; ``"xu"``:
        (7.2)-(7.5) (Xu and Jackson), every realisation carries ``sqrt(S(k))`` exactly, only the phase is random.

    Returns
    -------
    ndarray, shape (n0, n1)
        Heights [length], zero mean, the same array on every rank.
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
    """Raise :class:`ParameterError` unless the amplitude (finite) and the wavelengths (length units) are positive."""
    if not (amplitude > 0 and np.isfinite(amplitude)):
        raise ParameterError("amplitude", f"the amplitude must be positive and finite, got {amplitude}")
    if not all(wavelength > 0 for wavelength in wavelengths):
        raise ParameterError("wavelength", f"the wavelength must be positive, got {', '.join(map(str, wavelengths))}")


def check_divides(cell, wavelength):
    """Raise :class:`ParameterError` unless ``wavelength`` divides the cell's side ``cell`` (else the cell cuts it)."""
    count = cell / wavelength
    if not (round(count) >= 1 and abs(count - round(count)) <= 1e-9 * count):
        raise ParameterError("wavelength", f"the wavelength {wavelength:g} does not divide the cell side {cell:g} "
                                           f"({count:.6g} wavelengths); give the side divided by a whole number "
                                           f"({cell:g}, {cell / 2:g}, {cell / 3:g}, ...)")


def bisinusoid(grid, amplitude, wavelength0, wavelength1):
    """Bisinusoidal waviness (3.52): Delta cos(2 pi y / lambda_y) cos(2 pi x / lambda_x) [length]."""
    check_waviness(amplitude, wavelength0, wavelength1)
    check_divides(grid.l0, wavelength0)
    check_divides(grid.l1, wavelength1)
    y, x = grid.coordinates()
    return amplitude * np.cos(2 * np.pi * y / wavelength0) * np.cos(2 * np.pi * x / wavelength1)


def wave(grid, amplitude, wavelength):
    """One-dimensional wave ``-h cos(2 pi x / lambda)`` along axis 1 (Westergaard's problem), h = ``amplitude``.

    Its complete-contact pressure is ``p_star = pi E* h / lambda`` (Johnson, Contact Mechanics, 13.2).
    """
    check_waviness(amplitude, wavelength)
    check_divides(grid.l1, wavelength)
    _, x = grid.coordinates()
    return np.broadcast_to(-amplitude * np.cos(2 * np.pi * x / wavelength), grid.shape).copy()


def hertz_sphere(grid, radius):
    """A paraboloid cap ``-r^2 / (2 R)`` centred in the cell, zero mean (a sphere in a large cell)."""
    if not (radius > 0 and np.isfinite(radius)):
        raise ParameterError("radius", f"the radius of the sphere must be positive and finite, got {radius}")
    y, x = grid.coordinates()
    r2 = (y - grid.l0 / 2) ** 2 + (x - grid.l1 / 2) ** 2
    heights = -r2 / (2.0 * radius)
    return heights - heights.mean()


