"""Tests of roughpetsc.asperities: summit detection, curvatures, closed-form PDFs, McCool's relations."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from roughpetsc.surface import summits as asperities, spectra
from roughpetsc.surface.grid import Grid
from roughpetsc.surface.generators import bisinusoid, fractal

# --- summits of deterministic fields ------------------------------------------------


def test_summits_of_bisinusoid_heights_and_discrete_curvatures():
    grid = Grid(48, 64, 0.75, 1.0)
    a, lam_y, lam_x = 0.02, 0.75 / 3, 1.0 / 4
    h = bisinusoid(grid, a, lam_y, lam_x)
    summits = asperities.find_summits(grid, h)
    # cos(wx x) cos(wy y) = 1 at (i lam_x, j lam_y) and at the half-shifted lattice: 2 * 4 * 3 maxima
    assert summits.count == 2 * 4 * 3
    assert set(zip(summits.rows % 8, summits.cols % 8)) == {(0, 0)}  # 48/6 = 64/8 = 8 nodes per half period
    np.testing.assert_allclose(summits.height, a, rtol=1e-12)
    dx, dy = grid.l1 / grid.n1, grid.l0 / grid.n0
    wx, wy = 2 * np.pi / lam_x, 2 * np.pi / lam_y
    # three-point stencil on a cos(w x) at a maximum: -2 a (1 - cos(w d)) / d^2
    f_xx = -2 * a * (1 - np.cos(wx * dx)) / dx ** 2
    f_yy = -2 * a * (1 - np.cos(wy * dy)) / dy ** 2
    np.testing.assert_allclose(summits.mean_curvature, -(f_xx + f_yy) / 2, rtol=1e-12)
    np.testing.assert_allclose(summits.geometric_curvature, np.sqrt(f_xx * f_yy), rtol=1e-12)
    # and close to the continuous curvatures a w^2 (second-order error)
    np.testing.assert_allclose(summits.mean_curvature, a * (wx ** 2 + wy ** 2) / 2, rtol=0.03)


def test_summit_on_periodic_boundary_and_plateau_is_not_a_summit():
    grid = Grid(6, 6, 1.0, 1.0)
    field = np.zeros(grid.shape)
    field[0, 0] = 1.0           # corner: neighbours wrap around
    field[3, 3] = field[3, 4] = 0.5  # a two-node plateau: neither is strictly higher
    summits = asperities.find_summits(grid, field)
    assert list(zip(summits.rows, summits.cols)) == [(0, 0)]
    assert summits.height[0] == pytest.approx(1.0 - field.mean())


def test_mixed_derivative_of_saddle_term():
    # f = b x y near the node + a paraboloid; f_xy of the stencil is exact for a bilinear term.
    grid = Grid(16, 16, 1.0, 1.0)
    y, x = grid.coordinates()
    field = -((x - 0.5) ** 2) - 2 * (y - 0.5) ** 2 + 0.3 * (x - 0.5) * (y - 0.5)
    rows, cols = np.array([8]), np.array([8])
    f_xx, f_yy, f_xy = asperities.hessian_at(grid, field, rows, cols)
    np.testing.assert_allclose([f_xx[0], f_yy[0], f_xy[0]], [-2.0, -4.0, 0.3], rtol=1e-9)


# --- closed forms -----------------------------------------------------------------

@pytest.mark.parametrize("alpha", [1.6, 2.0, 2.7861, 5.0, 50.0])
def test_summit_height_pdf_is_normalised_and_consistent_with_mccool(alpha):
    pdf = lambda x: asperities.summit_height_pdf(x, alpha)  # noqa: E731
    total = quad(pdf, -np.inf, np.inf)[0]
    mean = quad(lambda x: x * pdf(x), -np.inf, np.inf)[0]
    variance = quad(lambda x: x * x * pdf(x), -np.inf, np.inf)[0] - mean ** 2
    gw = asperities.mccool_gw_inputs(1.0, 1.0, alpha)  # m0 = m2 = 1 so that alpha = m4
    assert total == pytest.approx(1.0, abs=1e-10)
    assert mean == pytest.approx(gw["mean_summit_height"], rel=1e-10)        # (2.44)
    assert np.sqrt(variance) == pytest.approx(gw["summit_height_rms"], rel=1e-4)  # (2.46), 0.8968 rounded


def test_summit_height_pdf_tends_to_gaussian_for_wide_band():
    x = np.linspace(-4, 4, 81)
    np.testing.assert_allclose(asperities.summit_height_pdf(x, 1e8), asperities.gaussian_pdf(x), atol=1e-4)


def test_mean_curvature_pdf_is_normalised_and_consistent_with_mccool_radius():
    pdf = asperities.summit_mean_curvature_pdf
    assert quad(pdf, 0, np.inf)[0] == pytest.approx(1.0, abs=1e-12)
    mean_kappa = quad(lambda k: k * pdf(k), 0, np.inf)[0]
    # (2.45): R = (3/8) sqrt(pi / m4) is 1 / <kappa_m>; with m4 = 1
    assert 1.0 / mean_kappa == pytest.approx(asperities.mccool_gw_inputs(1.0, 1.0, 1.0)["radius"], rel=1e-12)
    assert pdf(-0.5) == 0.0


def test_mccool_relations_formulas():
    m0, m2, m4 = 1.2e-8, 2e-4, 9.0
    gw = asperities.mccool_gw_inputs(m0, m2, m4)
    alpha = m0 * m4 / m2 ** 2
    assert gw["eta"] == pytest.approx(m4 / m2 / (6 * np.sqrt(3) * np.pi))
    assert gw["mean_summit_height"] == pytest.approx(4 * np.sqrt(m0 / (np.pi * alpha)))
    assert gw["radius"] == pytest.approx(3 / 8 * np.sqrt(np.pi / m4))
    assert gw["summit_height_rms"] == pytest.approx(np.sqrt(1 - 0.8968 / alpha) * np.sqrt(m0))


# --- histogram and distance ------------------------------------------------------------

def test_density_histogram_integrates_to_fraction_inside():
    values = np.array([-10.0, 0.1, 0.2, 0.3, 0.9, np.nan])
    edges = np.linspace(0.0, 1.0, 5)
    density = asperities.density_histogram(values, edges)
    assert np.sum(density * np.diff(edges)) == pytest.approx(4 / 5)


def test_l1_distance_of_exact_sample_is_at_noise_level_and_detects_a_shift():
    rng = np.random.default_rng(7)
    edges = np.linspace(-5, 5, 41)
    sample = rng.standard_normal(200_000)
    distance, noise = asperities.l1_distance(sample, edges, asperities.gaussian_pdf)
    assert distance < 2.0 * noise
    shifted, _ = asperities.l1_distance(sample + 0.2, edges, asperities.gaussian_pdf)
    assert shifted == pytest.approx(2 * (2 * 0.5 * (1 + math.erf(0.1 / np.sqrt(2))) - 1), rel=0.1)


# --- group #1: Gaussianity of the generated surfaces ---------------------------------------

@pytest.fixture(scope="module")
def group1_fields():
    """Four realisations of group #1 (16, 64, 0.8), N = 1024, m2 = 2e-4 (seeds 1..4)."""
    grid = Grid(1024, 1024, 1.0, 1.0)
    fields = []
    for seed in range(1, 5):
        h = fractal(grid, 16.0, 64.0, 0.8, 2e-4, seed)
        fields.append((h, spectra.pressure_surface(grid, h)))
    return grid, fields


def pooled(grid, fields, which):
    """Pooled dimensionless heights, summit heights, summit curvatures and mean alpha of h or of -p_c."""
    heights, xis, kappas, alphas = [], [], [], []
    for h, p in fields:
        field = h if which == "h" else -p
        m = spectra.isotropic_mean(spectra.fd_moments(grid, field, (0, 2, 4)))
        summits = asperities.find_summits(grid, field)
        xi, kappa = asperities.normalised_summits(summits, m[0], m[4])
        heights.append(field.ravel() / np.sqrt(m[0]))
        xis.append(xi)
        kappas.append(kappa)
        alphas.append(spectra.bandwidth(m[0], m[2], m[4]))
    return np.concatenate(heights), np.concatenate(xis), np.concatenate(kappas), float(np.mean(alphas))


# Criterion fixed before measuring: L1 distance (twice the total variation) of histograms of bin
# width 0.25 to the closed form at most 0.10, i.e. the binned distributions differ by at most 5 %
# of their mass.
L1_CRITERION = 0.10
EDGES = np.arange(-5.0, 5.0 + 1e-9, 0.25)


def test_group1_pressure_surface_heights_are_gaussian(group1_fields):
    grid, fields = group1_fields
    heights, _, _, _ = pooled(grid, fields, "p")
    distance, _ = asperities.l1_distance(heights, EDGES, asperities.gaussian_pdf)
    assert distance < L1_CRITERION


@pytest.mark.parametrize("which", ["h", "p"])
def test_group1_summit_heights_follow_2_42(group1_fields, which):
    grid, fields = group1_fields
    _, xi, kappa, alpha = pooled(grid, fields, which)
    distance, _ = asperities.l1_distance(xi, EDGES, lambda x: asperities.summit_height_pdf(x, alpha))
    assert distance < L1_CRITERION
    distance, _ = asperities.l1_distance(kappa, EDGES, asperities.summit_mean_curvature_pdf)
    assert distance < L1_CRITERION


def test_group1_summits_match_mccool(group1_fields):
    grid, fields = group1_fields
    measured, predicted = [], []
    for h, _ in fields:
        m = spectra.isotropic_mean(spectra.fd_moments(grid, h, (0, 2, 4)))
        measured.append(asperities.measured_gw_inputs(asperities.find_summits(grid, h)))
        predicted.append(asperities.mccool_gw_inputs(m[0], m[2], m[4]))
    for key in ("eta", "mean_summit_height", "radius", "summit_height_rms"):
        assert np.mean([m[key] for m in measured]) == pytest.approx(np.mean([p[key] for p in predicted]),
                                                                     rel=0.03), key


@pytest.mark.parametrize("alpha", [1.8, 2.7861, 10.0])
def test_geometric_curvature_joint_pdf_2_41_is_normalised_and_has_the_stated_marginal(alpha):
    from scipy.integrate import dblquad

    joint = asperities.summit_height_geometric_curvature_pdf
    total = dblquad(lambda xi, k: joint(xi, k, alpha), 0, 8, -12, 12)[0]
    assert total == pytest.approx(1.0, abs=1e-8)
    for kappa in (0.3, 1.0, 2.0, 3.5):
        marginal = quad(lambda xi: joint(xi, kappa, alpha), -12, 12, epsabs=1e-13)[0]
        assert asperities.summit_geometric_curvature_pdf(kappa) == pytest.approx(marginal, rel=1e-8)


def test_l1_from_counts_equals_l1_from_values():
    rng = np.random.default_rng(3)
    sample = rng.standard_normal(1000) * 1.1
    edges = np.linspace(-3, 3, 25)
    counts, total = asperities.binned_counts(sample, edges)
    assert asperities.l1_distance_from_counts(counts, total, edges, asperities.gaussian_pdf) == \
        asperities.l1_distance(sample, edges, asperities.gaussian_pdf)
