"""Tests of roughpetsc.spectra against analytic moments, quadrature of (2.15)/(2.51) and the dissertation's tables."""

import numpy as np
import pytest
from scipy.integrate import quad

from roughpetsc.surface import spectra
from roughpetsc.surface.grid import Grid
from roughpetsc.surface.generators import bisinusoid, fractal, fractal_amplitude, fractal_psd

ORDERS = (0, 2, 4, 6)


def sinusoid(grid, amplitude, cycles_x, phase):
    """a cos(2 pi m x / L1 + phase), constant along y."""
    _, x = grid.coordinates()
    return np.broadcast_to(amplitude * np.cos(2 * np.pi * cycles_x * x / grid.l1 + phase), grid.shape).copy()


# --- a single sinusoid -------------------------------------------------------

@pytest.mark.parametrize("n0, n1, l0, l1, cycles", [(8, 32, 0.5, 2.0, 3), (16, 16, 1.0, 1.0, 7), (4, 64, 0.1, 4.0, 31)])
def test_spectral_moments_exact_on_sinusoid(n0, n1, l0, l1, cycles):
    grid = Grid(n0, n1, l0, l1)
    a = 0.37
    moments = spectra.spectral_moments(grid, sinusoid(grid, a, cycles, 0.4), ORDERS)
    w = 2 * np.pi * cycles / l1
    for n in ORDERS:
        assert moments["x"][n] == pytest.approx(a ** 2 / 2 * w ** n, rel=1e-12)
    assert moments["y"][0] == pytest.approx(a ** 2 / 2, rel=1e-12)
    for n in (2, 4, 6):
        assert moments["y"][n] == 0.0


@pytest.mark.parametrize("scheme", ["seed", "central"])
def test_fd_moments_exact_on_sinusoid(scheme):
    # Stencils applied to a cos(w x): exact trigonometric identities.
    grid = Grid(8, 64, 1.0, 2.0)
    a, cycles = 1.3, 5
    dx = grid.l1 / grid.n1
    w = 2 * np.pi * cycles / grid.l1
    central = np.sin(w * dx) / dx                    # |(f(x+d) - f(x-d)) / 2d| / |f'| amplitude factor
    three_point = 2 * (1 - np.cos(w * dx)) / dx ** 2  # |f(x+d) - 2 f + f(x-d)| / d^2 amplitude
    if scheme == "seed":
        amplitudes = {2: central, 4: three_point, 6: central * three_point}
    else:
        amplitudes = {2: central, 4: central ** 2, 6: central ** 3}
    moments = spectra.fd_moments(grid, sinusoid(grid, a, cycles, 1.1), ORDERS, scheme)
    assert moments["x"][0] == pytest.approx(a ** 2 / 2, rel=1e-12)
    for n in (2, 4, 6):
        assert moments["x"][n] == pytest.approx(a ** 2 / 2 * amplitudes[n] ** 2, rel=1e-10)
        assert moments["y"][n] == pytest.approx(0.0, abs=1e-20)


def test_fd_moments_converge_to_spectral_with_resolution():
    errors = []
    for n1 in (64, 128, 256):
        grid = Grid(4, n1, 1.0, 1.0)
        h = sinusoid(grid, 1.0, 3, 0.0)
        fd = spectra.fd_moments(grid, h, ORDERS)["x"]
        exact = spectra.spectral_moments(grid, h, ORDERS)["x"]
        errors.append([abs(fd[n] / exact[n] - 1) for n in (2, 4, 6)])
    errors = np.array(errors)
    # second-order accurate: halving Delta divides the error by 4
    np.testing.assert_allclose(errors[:-1] / errors[1:], 4.0, rtol=0.02)


def test_fd_symbol_matches_fd_moments_on_sinusoid():
    grid = Grid(4, 128, 1.0, 1.0)
    dx = grid.l1 / grid.n1
    h = sinusoid(grid, 1.0, 9, 0.3)
    for scheme in spectra.FD_SCHEMES:
        fd = spectra.fd_moments(grid, h, ORDERS, scheme)["x"]
        for n in (2, 4, 6):
            assert fd[n] == pytest.approx(0.5 * spectra.fd_symbol_squared(9.0, dx, n // 2, scheme), rel=1e-10)


# --- a bisinusoid ---------------------------------------------------------------

def test_moments_exact_on_bisinusoid():
    grid = Grid(32, 64, 0.5, 1.0)
    a, lam_y, lam_x = 0.02, 0.5 / 3, 1.0 / 5
    h = bisinusoid(grid, a, lam_y, lam_x)
    spectral = spectra.spectral_moments(grid, h, ORDERS)
    fd = spectra.fd_moments(grid, h, ORDERS)
    wx, wy = 2 * np.pi / lam_x, 2 * np.pi / lam_y
    dx, dy = grid.l1 / grid.n1, grid.l0 / grid.n0
    for n in ORDERS:
        assert spectral["x"][n] == pytest.approx(a ** 2 / 4 * wx ** n, rel=1e-12)
        assert spectral["y"][n] == pytest.approx(a ** 2 / 4 * wy ** n, rel=1e-12)
    for w, d, key in ((wx, dx, "x"), (wy, dy, "y")):
        c = np.sin(w * d) / d
        t = 2 * (1 - np.cos(w * d)) / d ** 2
        expected = {0: a ** 2 / 4, 2: a ** 2 / 4 * c ** 2, 4: a ** 2 / 4 * t ** 2, 6: a ** 2 / 4 * (c * t) ** 2}
        for n in ORDERS:
            assert fd[key][n] == pytest.approx(expected[n], rel=1e-10)


def test_pressure_surface_of_bisinusoid():
    grid = Grid(32, 32, 1.0, 1.0)
    a, e_star = 0.01, 2.5
    h = bisinusoid(grid, a, 1.0 / 2, 1.0 / 3)
    k = np.hypot(2.0, 3.0)
    np.testing.assert_allclose(spectra.pressure_surface(grid, h, e_star), np.pi * e_star * k * h, atol=1e-14)


def test_pressure_surface_of_sinusoid_and_its_moments():
    grid = Grid(4, 64, 0.25, 2.0)
    a, e_star, cycles = 0.1, 3.0, 4
    h = sinusoid(grid, a, cycles, 0.2)
    p = spectra.pressure_surface(grid, h, e_star)
    np.testing.assert_allclose(p, np.pi * e_star * cycles / grid.l1 * h, atol=1e-13)
    moments = spectra.spectral_moments(grid, p, (0, 2))
    assert moments["x"][0] == pytest.approx((np.pi * e_star * cycles / grid.l1 * a) ** 2 / 2, rel=1e-12)


# --- closed forms against quadrature of (2.15) and (2.51) -------------------------

PSD_CASES = [(16.0, 64.0, 0.8), (4.0, 128.0, 0.1), (1.0, 512.0, 0.5), (16.0, 128.0, 0.9)]


def isotropic_quadrature(psd, n, extra_power, k_lo, k_hi):
    """(2.15): 2 pi factor(n) int S(k) (2 pi k)^(n + extra) k dk."""
    factor = spectra.isotropy_factor(n)
    # in u = ln k (dk = k du) so that wide bands k_s / k_l are integrated accurately
    value, _ = quad(lambda u: psd(np.exp(u)) * (2 * np.pi * np.exp(u)) ** (n + extra_power) * np.exp(2 * u),
                    np.log(k_lo), np.log(k_hi), epsrel=1e-12, limit=200)
    return 2 * np.pi * factor * value


@pytest.mark.parametrize("k_l, k_s, hurst", PSD_CASES)
def test_height_moments_closed_form_equal_quadrature(k_l, k_s, hurst):
    c = fractal_amplitude(k_l, k_s, hurst, 2e-4)
    psd = lambda k: fractal_psd(k, k_l, k_s, hurst, c)  # noqa: E731
    for n in ORDERS:
        closed = spectra.fractal_height_moment(n, k_l, k_s, hurst, c)
        assert closed == pytest.approx(isotropic_quadrature(psd, n, 0, k_l, k_s), rel=1e-9)
    # (7.1) prescribes m2
    assert spectra.fractal_height_moment(2, k_l, k_s, hurst, c) == pytest.approx(2e-4, rel=1e-12)


def test_height_moment_with_rolloff_equal_quadrature():
    k_l, k_r, k_s, hurst, c = 2.0, 8.0, 100.0, 0.6, 1e-9

    def psd(k):
        return c * max(k, k_r) ** (-2 * (1 + hurst)) if k_l <= k <= k_s else 0.0

    for n in ORDERS:
        closed = spectra.fractal_height_moment(n, k_l, k_s, hurst, c, k_r=k_r)
        quadrature = (isotropic_quadrature(psd, n, 0, k_l, k_r) + isotropic_quadrature(psd, n, 0, k_r, k_s))
        assert closed == pytest.approx(quadrature, rel=1e-9)


def test_named_closed_forms_221_to_224():
    k_l, k_s, h = 16.0, 64.0, 0.8
    c = fractal_amplitude(k_l, k_s, h, 2e-4)
    two_pi = 2 * np.pi
    eq = {0: np.pi * c / h * (k_l ** (-2 * h) - k_s ** (-2 * h)),
          2: 0.25 * two_pi ** 3 * c / (1 - h) * (k_s ** (2 - 2 * h) - k_l ** (2 - 2 * h)),
          4: 3 / 16 * two_pi ** 5 * c / (2 - h) * (k_s ** (4 - 2 * h) - k_l ** (4 - 2 * h)),
          6: 5 / 32 * two_pi ** 7 * c / (3 - h) * (k_s ** (6 - 2 * h) - k_l ** (6 - 2 * h))}
    for n in ORDERS:
        assert spectra.fractal_height_moment(n, k_l, k_s, h, c) == pytest.approx(eq[n], rel=1e-13)


@pytest.mark.parametrize("k_l, k_s, hurst", PSD_CASES)
def test_pressure_moments_closed_form_equal_quadrature(k_l, k_s, hurst):
    c = fractal_amplitude(k_l, k_s, hurst, 2e-4)
    e_star = 7.0
    psd = lambda k: fractal_psd(k, k_l, k_s, hurst, c)  # noqa: E731
    heights = {n: spectra.fractal_height_moment(n, k_l, k_s, hurst, c) for n in ORDERS}
    for n in (0, 2, 4):
        closed = spectra.fractal_pressure_moment(n, k_l, k_s, hurst, c, e_star)
        # (2.51): E*^2 pi/2 factor(n) int S (2 pi k)^(n+2) k dk = (E*^2 / 4) * (2.15 with two extra powers)
        assert closed == pytest.approx(e_star ** 2 / 4 * isotropic_quadrature(psd, n, 2, k_l, k_s), rel=1e-9)
        assert closed == pytest.approx(spectra.pressure_moment_from_heights(n, heights, e_star), rel=1e-12)
    assert spectra.fractal_pressure_moment(0, k_l, k_s, hurst, c, e_star) == pytest.approx(e_star ** 2 * 1e-4)


@pytest.mark.parametrize("k_l, k_s, hurst", PSD_CASES)
def test_bandwidth_closed_forms(k_l, k_s, hurst):
    c = 1.0
    m = {n: spectra.fractal_height_moment(n, k_l, k_s, hurst, c) for n in ORDERS}
    p = {n: spectra.fractal_pressure_moment(n, k_l, k_s, hurst, c) for n in (0, 2, 4)}
    assert spectra.fractal_height_bandwidth(k_l, k_s, hurst) == pytest.approx(
        spectra.bandwidth(m[0], m[2], m[4]), rel=1e-12)
    assert spectra.fractal_pressure_bandwidth(k_l, k_s, hurst) == pytest.approx(
        spectra.bandwidth(p[0], p[2], p[4]), rel=1e-12)
    assert spectra.fractal_pressure_bandwidth(k_l, k_s, hurst) == pytest.approx(
        spectra.pressure_bandwidth_from_heights(m[2], m[4], m[6]), rel=1e-12)


# Closed-form columns of the dissertation (3 significant digits): Tables 7.4, 7.6, 8.2, 8.3, and alpha of 8.2/8.3.
SEED_CLOSED = [
    # (k_l, k_s, H, m0h, m4h, m6h, m2p, m4p, alpha_h, alpha_p)
    (16, 64, 0.8, 1.19e-8, 9.16, 6.97e5, 3.05, 2.09e5, None, None),
    (4, 128, 0.1, 5.58e-9, 46.05, 1.63e7, 15.35, 4.88e6, None, None),
    (16, 64, 0.1, 7.75e-9, 12.46, None, 4.15, 3.32e5, 2.41, 1.92),
    (16, 128, 0.9, 8.33e-9, 25.66, None, 8.55, 2.20e6, 5.34, 3.00),
]


@pytest.mark.parametrize("k_l, k_s, hurst, m0h, m4h, m6h, m2p, m4p, alpha_h, alpha_p", SEED_CLOSED)
def test_closed_forms_reproduce_seed_tables(k_l, k_s, hurst, m0h, m4h, m6h, m2p, m4p, alpha_h, alpha_p):
    forms = spectra.fractal_closed_forms(k_l, k_s, hurst, fractal_amplitude(k_l, k_s, hurst, 2e-4))
    assert forms["h"][0] == pytest.approx(m0h, rel=5e-3)
    assert forms["h"][4] == pytest.approx(m4h, rel=5e-3)
    if m6h is not None:
        assert forms["h"][6] == pytest.approx(m6h, rel=5e-3)
    assert forms["p"][2] == pytest.approx(m2p, rel=5e-3)
    assert forms["p"][4] == pytest.approx(m4p, rel=5e-3)
    if alpha_h is not None:
        assert forms["alpha_h"] == pytest.approx(alpha_h, rel=5e-3)
        assert forms["alpha_p"] == pytest.approx(alpha_p, rel=5e-3)


# --- generated surfaces: the dissertation's "Num" columns ---------------------------------

def ensemble_summaries(k_l, k_s, hurst, n, seeds):
    grid = Grid(n, n, 1.0, 1.0)
    return [spectra.surface_moment_summary(grid, fractal(grid, k_l, k_s, hurst, 2e-4, seed)) for seed in seeds]


@pytest.fixture(scope="module")
def group1():
    """16 realisations of group #1 (16, 64, 0.8), N = 1024, m2 = 2e-4 (seeds 1..16)."""
    return ensemble_summaries(16.0, 64.0, 0.8, 1024, range(1, 17))


def test_group1_moments_match_table_7_4(group1):
    # Table 7.4, group #1, "Num": m0h, m2h, m4h, m6h, m0p*, m2p*, m4p*
    mh = [spectra.isotropic_mean(s["h_fd"]) for s in group1]
    mp = [spectra.isotropic_mean(s["p_fd"]) for s in group1]
    mean_h = {n: np.mean([m[n] for m in mh]) for n in ORDERS}
    mean_p = {n: np.mean([m[n] for m in mp]) for n in (0, 2, 4)}
    assert mean_h[0] == pytest.approx(1.20e-8, rel=0.02)
    assert mean_h[2] == pytest.approx(1.97e-4, rel=0.02)
    assert mean_h[4] == pytest.approx(9.01, rel=0.02)
    assert mean_h[6] == pytest.approx(6.59e5, rel=0.05)
    assert mean_p[0] == pytest.approx(1.00e-4, rel=0.02)
    assert mean_p[2] == pytest.approx(2.98, rel=0.02)
    assert mean_p[4] == pytest.approx(2.05e5, rel=0.02)


def test_group1_bandwidths_within_table_7_7_spread(group1):
    alpha_h = np.mean([s["alpha_h"] for s in group1])
    alpha_p = np.mean([s["alpha_p"] for s in group1])
    assert abs(alpha_h - 2.7861) <= 0.2144
    assert abs(alpha_p - 2.3146) <= 0.2144


def test_group1_isotropy_of_mean_moments(group1):
    for field, orders in (("h_fd", (2, 4, 6)), ("p_fd", (2, 4)), ("h_spectral", (2, 4, 6))):
        for n in orders:
            x = np.array([s[field]["x"][n] for s in group1])
            y = np.array([s[field]["y"][n] for s in group1])
            difference = x - y
            standard_error = difference.std(ddof=1) / np.sqrt(difference.size)
            assert abs(difference.mean()) <= 3.0 * standard_error, (field, n)
            assert abs(x.mean() / y.mean() - 1.0) < 0.02, (field, n)


def test_group1_spectral_mean_matches_expected_lattice_sum(group1):
    # The generator draws E|DFT(h)|^2 / (n0 n1)^2 = S(k) / A0 on every lattice point of [k_l, k_s]; the
    # mean spectral and finite-difference moments must approach those lattice sums.
    n = 1024
    c = fractal_amplitude(16.0, 64.0, 0.8, 2e-4)
    kx = np.fft.fftfreq(n, 1.0 / n)[None, :]
    ky = np.fft.fftfreq(n, 1.0 / n)[:, None]
    power = fractal_psd(np.hypot(kx, ky), 16.0, 64.0, 0.8, c)
    dx = 1.0 / n
    for n_order in (2, 4, 6):
        spectral = np.mean([s["h_spectral"]["x"][n_order] for s in group1])
        fd = np.mean([s["h_fd"]["x"][n_order] for s in group1])
        assert spectral == pytest.approx(np.sum(power * (2 * np.pi * kx) ** n_order), rel=0.02)
        assert fd == pytest.approx(np.sum(power * spectra.fd_symbol_squared(kx, dx, n_order // 2)), rel=0.02)


@pytest.mark.parametrize("k_l, k_s, hurst, n, seeds, alpha_h_seed, alpha_p_seed", [
    (16.0, 64.0, 0.1, 1024, range(1, 9), 2.50, 2.00),    # group 18, Tables 8.2/8.3 "Num"
    (16.0, 128.0, 0.9, 2048, range(1, 5), 5.44, 3.10),   # group 27
])
def test_table_8_groups_bandwidths(k_l, k_s, hurst, n, seeds, alpha_h_seed, alpha_p_seed):
    summaries = ensemble_summaries(k_l, k_s, hurst, n, seeds)
    assert np.mean([s["alpha_h"] for s in summaries]) == pytest.approx(alpha_h_seed, rel=0.03)
    assert np.mean([s["alpha_p"] for s in summaries]) == pytest.approx(alpha_p_seed, rel=0.03)


def test_xu_generator_has_the_prescribed_amplitude_in_every_realisation():
    """(7.2)-(7.5): |F[h]| = sqrt(S(k) n0 n1 / A0) for every seed, so the spectral moments do not vary;
    the filter's amplitudes are random, with the same expected moments."""
    from roughpetsc.surface.grid import Grid
    from roughpetsc.surface.generators import fractal, fractal_amplitude, fractal_psd

    grid = Grid(128, 128)
    k0, k1 = grid.rfft_wavenumbers()
    expected = np.sqrt(fractal_psd(np.hypot(k0, k1), 4, 32, 0.8, fractal_amplitude(4, 32, 0.8, 2e-4))
                       * grid.size / grid.area) * np.sqrt(grid.size)
    expected[0, 0] = 0.0
    moments = {"xu": [], "filter": []}
    for seed in range(6):
        for generator in moments:
            heights = fractal(grid, 4, 32, 0.8, 2e-4, seed, generator=generator)
            if generator == "xu":
                assert np.allclose(np.abs(np.fft.rfft2(heights)), expected, rtol=1e-10, atol=1e-12 * expected.max())
            moments[generator].append(spectra.spectral_moments(grid, heights)["x"][2])
    assert np.std(moments["xu"]) < 1e-12 * np.mean(moments["xu"])
    assert np.std(moments["filter"]) > 1e-3 * np.mean(moments["filter"])
    assert np.mean(moments["filter"]) == pytest.approx(np.mean(moments["xu"]), rel=0.1)
    # The same seed, the same phases: the two generators differ only in the amplitudes.
    a = np.fft.rfft2(fractal(grid, 4, 32, 0.8, 2e-4, 3, generator="xu"))
    b = np.fft.rfft2(fractal(grid, 4, 32, 0.8, 2e-4, 3, generator="filter"))
    inside = expected > 0
    assert np.allclose(np.angle(a[inside] * np.conj(b[inside])), 0.0, atol=1e-9)


def test_heights_from_pressure_surface_inverts_the_pressure_surface():
    from roughpetsc.surface.spectra import heights_from_pressure_surface, pressure_surface
    from roughpetsc.surface.grid import Grid

    grid = Grid(32, 48, 1.0, 1.5)
    target = np.random.default_rng(3).standard_normal(grid.shape)
    heights = heights_from_pressure_surface(grid, target, 2.5)
    assert abs(heights.mean()) < 1e-15
    np.testing.assert_allclose(pressure_surface(grid, heights, 2.5), target - target.mean(), atol=1e-12)
