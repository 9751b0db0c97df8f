"""Asperities (summits) of a surface and their probability densities (the dissertation, sec. 2.4-2.6, 7.2.2).

A summit is a node strictly higher than its eight periodic neighbours (sec. 7.2.2); finite-difference second
derivatives there give the mean curvature (2.31) and the geometric curvature (2.32). The same routines serve ``h``
and the pressure surface ``-p_c`` (sec. 2.6). Dimensionless variables (2.34)/(2.36): ``xi* = xi / sqrt(m0)``,
``kappa* = kappa / sqrt(m4)``, with the moments of the same field.
"""

from dataclasses import dataclass

import numpy as np
from scipy.special import erf, erfc, erfcx

NEIGHBOUR_OFFSETS = tuple((di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1) if (di, dj) != (0, 0))


@dataclass(frozen=True)
class Summits:
    """Summits of one field: node indices, height xi above the mean plane [field], kappa_m = -(f_xx + f_yy) / 2
    (2.31) [field / length^2], f_xx f_yy - f_xy^2 [field^2 / length^4] (negative where the discrete Hessian is not
    definite) and the cell's area [length^2]."""

    rows: np.ndarray
    cols: np.ndarray
    height: np.ndarray
    mean_curvature: np.ndarray
    hessian_determinant: np.ndarray
    area: float

    @property
    def count(self):
        return int(self.height.size)

    @property
    def density(self):
        """Summits per unit area [1 / length^2] (compare eta of (2.43))."""
        return self.count / self.area

    @property
    def geometric_curvature(self):
        """kappa_g = sqrt(f_xx f_yy - f_xy^2), eq. (2.32); NaN where the determinant is negative."""
        det = self.hessian_determinant
        return np.where(det >= 0.0, np.sqrt(np.abs(det)), np.nan)


def summit_mask(field):
    """Boolean mask of the nodes strictly higher than all eight periodic neighbours."""
    mask = np.ones(field.shape, dtype=bool)
    for di, dj in NEIGHBOUR_OFFSETS:
        mask &= field > np.roll(field, (di, dj), axis=(0, 1))
    return mask


def hessian_at(grid, field, rows, cols):
    """Second derivatives ``(f_xx, f_yy, f_xy)`` [field / length^2] at the given nodes: three-point stencils for
    ``f_xx``, ``f_yy`` and the four-point central stencil for ``f_xy`` (periodic)."""
    dx = grid.l1 / grid.n1
    dy = grid.l0 / grid.n0

    def at(di, dj):
        return field[(rows + di) % grid.n0, (cols + dj) % grid.n1]

    centre = at(0, 0)
    f_xx = (at(0, 1) - 2.0 * centre + at(0, -1)) / dx ** 2
    f_yy = (at(1, 0) - 2.0 * centre + at(-1, 0)) / dy ** 2
    f_xy = (at(1, 1) - at(1, -1) - at(-1, 1) + at(-1, -1)) / (4.0 * dx * dy)
    return f_xx, f_yy, f_xy


def find_summits(grid, field):
    """:class:`Summits` of ``field`` (``h`` [length] or ``-p_c`` [pressure]) by eight nearest neighbours."""
    rows, cols = np.nonzero(summit_mask(field))
    f_xx, f_yy, f_xy = hessian_at(grid, field, rows, cols)
    return Summits(rows=rows, cols=cols, height=field[rows, cols] - field.mean(),
                   mean_curvature=-0.5 * (f_xx + f_yy),
                   hessian_determinant=f_xx * f_yy - f_xy ** 2, area=grid.area)


# --- Closed-form densities of an isotropic Gaussian surface

def summit_height_pdf(xi, alpha):
    """PDF of the summit height xi* = xi / sqrt(m0), eq. (2.42) (Nayak; Greenwood, App. A); alpha (2.16) > 1.5."""
    xi = np.asarray(xi, dtype=float)
    c1 = alpha / (2.0 * alpha - 3.0)
    beta = xi * np.sqrt(3.0 / (2.0 * (2.0 * alpha - 3.0)))
    gamma = xi * np.sqrt(alpha / (2.0 * (alpha - 1.0) * (2.0 * alpha - 3.0)))
    first = 3.0 / (2.0 * np.pi) * np.sqrt(2.0 * alpha - 3.0) / alpha * xi * np.exp(-c1 * xi ** 2)
    second = (3.0 * np.sqrt(3.0) / (2.0 * np.sqrt(2.0 * np.pi)) / alpha * (xi ** 2 - 1.0)
              * np.exp(-0.5 * xi ** 2) * (1.0 + erf(beta)))
    third = (np.sqrt(alpha / (2.0 * np.pi * (alpha - 1.0)))
             * np.exp(-alpha * xi ** 2 / (2.0 * (alpha - 1.0))) * (1.0 + erf(gamma)))
    return first + second + third


def summit_mean_curvature_pdf(kappa):
    """PDF of the dimensionless summit mean curvature kappa_m* = kappa_m / sqrt(m4), eq. (7.8) (Greenwood).

    Zero for kappa_m* < 0 (a summit of a Gaussian surface has kappa_m > 0).
    """
    kappa = np.asarray(kappa, dtype=float)
    pdf = 1.5 / np.sqrt(np.pi) * ((3.0 * kappa ** 2 - 2.0) * np.exp(-0.75 * kappa ** 2)
                                  + 2.0 * np.exp(-2.25 * kappa ** 2))
    return np.where(kappa >= 0.0, pdf, 0.0)


def summit_height_geometric_curvature_pdf(xi, kappa_g, alpha):
    """Joint PDF of (xi*, kappa_g*) of the summits of a Gaussian surface, eq. (2.41) (Greenwood).

    ``kappa_g* = kappa_g / sqrt(m4)``; zero for ``kappa_g* < 0``. Dimensionless.
    """
    xi = np.asarray(xi, dtype=float)
    kappa = np.maximum(np.asarray(kappa_g, dtype=float), 0.0)
    mu = np.sqrt(0.5 * (alpha - 1.0) / (2.0 * alpha - 3.0))
    z = mu * (3.0 * kappa - xi * np.sqrt(alpha) / (alpha - 1.0))
    exponent = -alpha * xi ** 2 / (2.0 * (alpha - 1.0)) + 1.5 * kappa ** 2
    # erfc(z) exp(E) without overflow: erfcx(z) exp(E - z^2) for z > 0
    tail = np.where(z > 0.0, erfcx(np.abs(z)) * np.exp(exponent - z ** 2), erfc(z) * np.exp(exponent))
    pdf = 4.5 / np.sqrt(2.0 * np.pi) * np.sqrt(alpha / (alpha - 1.0)) * kappa ** 3 * tail
    return np.where(np.asarray(kappa_g) >= 0.0, pdf, 0.0)


def summit_geometric_curvature_pdf(kappa_g):
    """Marginal PDF of kappa_g* = kappa_g / sqrt(m4): (2.41) integrated over xi*, for any alpha.

    ``(9/2) k^3 exp(3 k^2 / 2) erfc(3 k / 2)``; zero for ``kappa_g* < 0``.
    """
    kappa = np.maximum(np.asarray(kappa_g, dtype=float), 0.0)
    pdf = 4.5 * kappa ** 3 * erfcx(1.5 * kappa) * np.exp(-0.75 * kappa ** 2)
    return np.where(np.asarray(kappa_g) >= 0.0, pdf, 0.0)


def gaussian_pdf(z):
    """Standard normal density, the height PDF of a Gaussian surface in units of sqrt(m0)."""
    z = np.asarray(z, dtype=float)
    return np.exp(-0.5 * z ** 2) / np.sqrt(2.0 * np.pi)


def mccool_gw_inputs(m0, m2, m4):
    """Inputs of the Greenwood-Williamson model from the moments, McCool's relations (2.43)-(2.46).

    Returns ``eta`` [1/length^2] (2.43), ``mean_summit_height`` [length] (2.44), ``radius`` R^h [length] (2.45),
    ``summit_height_rms`` [length] (2.46) and ``alpha`` (2.16).
    """
    alpha = m0 * m4 / m2 ** 2
    return {
        "eta": m4 / m2 / (6.0 * np.sqrt(3.0) * np.pi),
        "mean_summit_height": 4.0 * np.sqrt(m0 / (np.pi * alpha)),
        "radius": 3.0 / 8.0 * np.sqrt(np.pi / m4),
        "summit_height_rms": np.sqrt(1.0 - 0.8968 / alpha) * np.sqrt(m0),
        "alpha": alpha,
    }


def measured_gw_inputs(summits):
    """The measured counterparts of :func:`mccool_gw_inputs` (``radius`` = 1 / mean kappa_m, as McCool's R^h)."""
    return {
        "eta": summits.density,
        "mean_summit_height": float(np.mean(summits.height)),
        "radius": float(1.0 / np.mean(summits.mean_curvature)),
        "summit_height_rms": float(np.std(summits.height)),
    }


# --- Measured densities and their distance to a closed form

def binned_counts(values, edges):
    """``(counts, total)``: counts of ``values`` in the bins of ``edges`` and the number of finite values."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    counts, _ = np.histogram(values, bins=edges)
    return counts, int(values.size)


def density_from_counts(counts, total, edges):
    """Counts normalised as a density over the whole sample ``total`` [1 / unit of values]."""
    return np.asarray(counts) / (max(total, 1) * np.diff(edges))


def density_histogram(values, edges):
    """Histogram of ``values`` normalised as a density over the whole sample (NaNs dropped)."""
    counts, total = binned_counts(values, edges)
    return density_from_counts(counts, total, edges)


def bin_probabilities(pdf, edges, points=8):
    """Probability of each bin under ``pdf`` by Gauss-Legendre quadrature with ``points`` nodes per bin."""
    nodes, weights = np.polynomial.legendre.leggauss(points)
    lo, hi = edges[:-1, None], edges[1:, None]
    x = 0.5 * (hi - lo) * nodes[None, :] + 0.5 * (hi + lo)
    return np.sum(pdf(x) * weights[None, :], axis=1) * 0.5 * (hi[:, 0] - lo[:, 0])


def l1_distance_from_counts(counts, total, edges, pdf):
    """``(distance, noise)``: L1 distance between binned counts and ``pdf`` (twice the total variation).

    ``sum_b |n_b / n - P_b| + |n_out / n - P_out|``, "out" outside ``edges``; ``noise`` is its expectation for a
    sample of ``pdf`` of the same size, ``sum sqrt(2 P (1 - P) / (pi n))``: the floor set by sampling alone.
    """
    measured = np.append(counts, total - np.sum(counts)) / total
    expected = bin_probabilities(pdf, edges)
    expected = np.append(expected, max(0.0, 1.0 - expected.sum()))
    distance = float(np.sum(np.abs(measured - expected)))
    expected = np.clip(expected, 0.0, 1.0)  # rounding can leave -1e-20 in a far tail bin
    noise = float(np.sum(np.sqrt(2.0 * expected * (1.0 - expected) / (np.pi * total))))
    return distance, noise


def l1_distance(values, edges, pdf):
    """:func:`l1_distance_from_counts` for a sample ``values`` (NaNs dropped)."""
    counts, total = binned_counts(values, edges)
    return l1_distance_from_counts(counts, total, edges, pdf)


def normalised_summits(summits, m0, m4):
    """Dimensionless summit heights and mean curvatures (2.34)/(2.36): ``(xi*, kappa_m*)``."""
    return summits.height / np.sqrt(m0), summits.mean_curvature / np.sqrt(m4)
