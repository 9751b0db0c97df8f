"""Cascaded Polonsky-Keer under load control, and an edge-band preconditioner: a prototype (issue 39).

Self-contained (numpy and numba on one rank, the operators of :class:`~roughpetsc.Westergaard`),
so that it can be ported into the solver stack as a backend. Everything is in the scaled units of
:class:`~roughpetsc.contact.ContactProblem` (rms height 1, cell length 1, E* = 1).

The problem (3.41)-(3.44) of the dissertation under load control::

    min 1/2 p'Kp - h'p   subject to   p >= 0,   mean(p) = pbar,

with the gap ``g = K p + d - h`` (d the rigid separation, the multiplier of the load) and the natural
KKT residual ``max |min(p / pbar, g)|`` (:mod:`roughpetsc.contact.certificate`, docs/conventions.md).

What is here
------------

* :class:`Level`: one grid, its compliance ``K`` and stiffness ``S`` (one FFT pair each), the pairs it
  spent, weighted by its size ``(n_level / n_fine)^2``.
* Preconditioners on a free set F for directions that keep the load (zero sum on F):

  - :class:`FourierPC` ``B r = P (S r)|_F`` with P the removal of the mean on F: the Fourier
    preconditioner of :mod:`roughpetsc.preconditioner` under load control (Vollebregt 2014).
  - :class:`BandPC`, the edge-band (harmonic extension) preconditioner ``B = P E' S E P``: the residual
    on F is extended into a band O of the nodes outside F by ``u_O = -M S_OF r`` (M a few Jacobi sweeps on
    the near-field stencil of ``S_OO``), ``S`` is applied by FFT to the extended field, and the result is
    restricted back by ``E'``. The exact inverse of ``K_FF`` is the Schur complement
    ``S_FF - S_FO S_OO^-1 S_OF`` (S = K^-1 on the whole grid); the Fourier preconditioner drops the second
    term, i.e. takes the displacement outside F to be zero, which overestimates the stiffness of the
    modes at the contact edge (the large eigenvalues of ``B K`` there). ``E' S E`` is symmetric positive
    definite for any symmetric M, and costs one FFT pair plus local stencil work on the band.
  - :class:`SchurPC` ``B = P (S_FF - S_FO M S_OF) P``: the same Schur term with the coupling by FFT (two
    pairs per application); measured worse per pair than :class:`BandPC` (the study's ``schur*`` rows).

* :func:`fixed_set_pcg`: preconditioned CG on a fixed contact set (the floor of issue 39, item 1), its CG
  coefficients, and :func:`lanczos_extremes`, the extreme eigenvalues of the preconditioned operator on
  the set from them (the Lanczos tridiagonal matrix of CG).
* :class:`CascadePK`: the cold solver. Its defaults are the candidate of issue 39
  (``studies/solver_scaling.py``, variant ``best``):

  1. Levels: N/2^k, ..., N/2, N, the coarsest with at least ``coarsest`` = 256 nodes per side
     (:func:`coarsening_factors`; none at N <= 256). Coarse heights by injection (every 2^k-th node of the
     scaled fine heights; the scaled units and pbar are those of the fine grid). A level's FFT pairs count
     ``(N_c / N)^2`` each.
  2. On the coarsest level: start from the uniform pressure pbar. On every finer level: start from the
     coarser solution (p_c, g_c) prolongated as ``p = max(bilinear(p_c - s g_c), 0)``, s the diagonal of
     the coarse stiffness S (``signed``: the contact edge is the zero line of an interpolated signed field,
     not the one-cell dilation that interpolating p gives), rescaled to mean pbar.
  3. On each level, projected preconditioned CG (Polonsky-Keer with Vollebregt's BCCG free set):
     ``u = K p`` (one pair at the start of a level); each iteration: ``d = -mean_C(u - h)`` over
     C = {p > 0}, ``g = u - h + d``, natural residual ``max |min(p/pbar, g)|``; free set
     ``F = C + {p = 0, g < 0}``; ``r = g - mean_F(g)`` on F; ``z = B_F r`` (one pair; the edge-band
     preconditioner ``band:width=2,radius=1.5,sweeps=4``, its band rebuilt when F changed by more than
     1 %); ``beta = max(<r - r_old, z> / <r_old, z_old>, 0)`` (Polak-Ribiere+, never restarted);
     ``t = z + beta t|_F`` less its mean on F; ``q = K t`` (one pair); ``alpha = <g, t> / <t, q>``;
     ``p <- max(p - alpha t, 0)``, ``u <- u - alpha q``; if the projection moved p, ``u += K c`` for its
     correction c: by shifted copies of the kernel when it moved at most ``point_corrections`` = 16
     nodes (no pair), else one pair; then ``p, u *= n pbar / sum(p)``.
  4. A coarse level stops at a natural residual of ``coarse_rtol`` = 1e-3 on its updated gap; the fine
     level at ``rtol`` on its updated gap, then recomputes ``u = K p`` (the certificate, one pair) and
     stops if the residual on that fresh gap is still at most ``rtol`` (else it continues).

  Options kept for the record of what was measured worse (the study's variants): restarting CG when
  the free set changes by more than a fraction of its size (``restart_fraction``), interpolating p
  itself (``prolong="bilinear"``), spectral coarse heights, deferring the projection's corrections
  (``lazy_until``, ``lazy_ratio``) and cutting the direction ahead of the projection (``clip_ahead``); and the
  projection's corrections by the split kernel (``near_radius``, ``far_ratio``, ``split_coarsening``,
  ``refresh_ratio``: the prototype of ``-pk_split_radius``).

Pairs are counted as the FFT pairs of every level weighted by its size, the certificate included. The
prototype runs on one rank (the band's sparse matrices and the kernel copies are serial).
"""

from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

from roughpetsc import Grid, Westergaard


# --- grids ------------------------------------------------------------------------------------------------
class Level:
    """One grid of the cascade: the periodic operators on an ``n x n`` unit cell and the heights on it.

    Parameters
    ----------
    heights : ndarray (n, n)
        Scaled heights on this grid (those of the fine problem, restricted).
    n_fine : int
        Nodes per side of the finest grid: the pairs of this level count ``(n / n_fine)^2`` each.
    effort : str
        FFTW planner effort.

    Attributes
    ----------
    h : ndarray (n*n,)
        The heights, flat.
    """

    def __init__(self, heights, n_fine, effort="FFTW_MEASURE"):
        self.n = heights.shape[0]
        self.size = self.n * self.n
        self.weight = (self.n / n_fine) ** 2
        self.operator = Westergaard(Grid(self.n, self.n), 1.0, PETSc.COMM_SELF, effort=effort)
        self.h = np.ascontiguousarray(heights, dtype=np.float64).ravel()
        self._in, self._out = self.operator.vec(), self.operator.vec()
        self._in_array = self._in.getArray()
        self._out_array = self._out.getArray()
        self.pairs = 0
        self.diagonal = self.operator.diagonal  # K_00, the largest entry of K
        self._kernel = None

    @property
    def weighted_pairs(self):
        """FFT pairs spent on this level, in fine-grid pairs."""
        return self.pairs * self.weight

    def compliance(self, x, out):
        """``out = K x`` (flat arrays): one FFT pair."""
        self._in_array[...] = x
        self.operator.displacement(self._in, self._out)
        out[...] = self._out_array
        self.pairs += 1

    def add_point_responses(self, nodes, values, out):
        """``out += K c`` for c = ``values`` at the flat indices ``nodes`` (few), by shifted copies of the
        compliance's real-space kernel: no FFT pair, about one sweep of the grid per node.

        The kernel (one column of K) is computed by one FFT the first time (a set-up cost of the grid, not
        counted in :attr:`pairs`, like the FFTW plans).
        """
        grid = out.reshape(self.n, self.n)
        kernel = self._real_kernel()
        n = self.n
        for node, value in zip(nodes, values):
            i, j = divmod(int(node), n)
            # out[(i + a) % n, (j + b) % n] += value kernel[a, b], in four blocks without wrap-around
            grid[i:, j:] += value * kernel[:n - i, :n - j]
            if j:
                grid[i:, :j] += value * kernel[:n - i, n - j:]
            if i:
                grid[:i, j:] += value * kernel[n - i:, :n - j]
                if j:
                    grid[:i, :j] += value * kernel[n - i:, n - j:]

    def _real_kernel(self):
        if self._kernel is None:
            delta = np.zeros(self.size)
            delta[0] = 1.0
            self._in_array[...] = delta
            self.operator.displacement(self._in, self._out)
            self._kernel = self._out_array.copy().reshape(self.n, self.n)
        return self._kernel

    def near_window(self, radius):
        """The kernel on the offsets ``|a|, |b| <= radius`` and the largest |K| outside them (the bound of the
        far field of a unit load)."""
        kernel = self._real_kernel()
        offsets = np.arange(-radius, radius + 1) % self.n
        window = kernel[np.ix_(offsets, offsets)].copy()
        outside = np.abs(kernel).copy()
        outside[np.ix_(offsets, offsets)] = 0.0
        return window, float(outside.max())

    def add_near_responses(self, nodes, values, out, radius):
        """``out += K_near c``: the responses of point loads ``values`` at flat ``nodes`` within ``radius``
        nodes (periodic), about (2 radius + 1)^2 operations per node, no FFT pair."""
        window, _ = self.near_window(radius) if getattr(self, "_window_radius", None) != radius else \
            (self._window, None)
        self._window, self._window_radius = window, radius
        grid = out.reshape(self.n, self.n)
        offsets = np.arange(-radius, radius + 1)
        for node, value in zip(nodes, values):
            i, j = divmod(int(node), self.n)
            grid[np.ix_((i + offsets) % self.n, (j + offsets) % self.n)] += value * window

    def split_kernel(self, inner, outer, coarsening):
        """The compliance kernel split smoothly at ``inner`` < r < ``outer`` nodes: ``K = K (1 - w) + K w``,
        w the cubic step in r. Returns the near part on the offsets ``|a|, |b| <= outer`` and the rfft2 of the
        far part sampled every ``coarsening`` nodes (smooth: no singularity, so sampling it coarsely and
        interpolating bilinearly costs O((coarsening / inner)^2) of its value)."""
        kernel = self._real_kernel()
        n = self.n
        offsets = np.minimum(np.arange(n), n - np.arange(n)).astype(float)
        r = np.hypot(offsets[:, None], offsets[None, :])
        step = np.clip((r - inner) / (outer - inner), 0.0, 1.0)
        far = kernel * step * step * (3.0 - 2.0 * step)
        window = np.arange(-outer, outer + 1) % n
        near = (kernel - far)[np.ix_(window, window)].copy()
        return near, np.fft.rfft2(far[::coarsening, ::coarsening])

    def add_split_responses(self, nodes, values, out, split, outer, coarsening):
        """``out += K c`` for point loads c: the near part exactly by the stencil, the far part by one FFT
        pair on the grid coarsened by ``coarsening`` (counted as ``coarsening^-2`` pairs) between the
        bilinear restriction of c and the bilinear interpolation of its response."""
        near, far_hat = split
        n, s = self.n, coarsening
        m = n // s
        grid = out.reshape(n, n)
        stencil = np.arange(-outer, outer + 1)
        rows, cols = np.divmod(np.asarray(nodes, dtype=np.int64), n)
        for i, j, value in zip(rows, cols, values):
            grid[np.ix_((i + stencil) % n, (j + stencil) % n)] += value * near
        coarse = np.zeros((m, m))
        fy, fx = (rows % s) / s, (cols % s) / s
        y0, x0 = rows // s, cols // s
        for dy, wy in ((0, 1.0 - fy), (1, fy)):
            for dx, wx in ((0, 1.0 - fx), (1, fx)):
                np.add.at(coarse, ((y0 + dy) % m, (x0 + dx) % m), values * wy * wx)
        response = np.fft.irfft2(np.fft.rfft2(coarse) * far_hat, s=(m, m))
        self.pairs += 1.0 / (s * s)
        frac = (np.arange(n) % s) / s
        low, high = np.arange(n) // s, (np.arange(n) // s + 1) % m
        rows_interp = (1.0 - frac)[:, None] * response[low] + frac[:, None] * response[high]
        grid += (1.0 - frac)[None, :] * rows_interp[:, low] + frac[None, :] * rows_interp[:, high]

    def stiffness(self, x, out):
        """``out = S x``, S the symbol ``pi max(|k|, 1)`` (the preconditioner's inverse compliance): one pair."""
        shape = (self.n, self.n)
        self.operator.stiffness(x.reshape(shape), out.reshape(shape))
        self.pairs += 1

    def stiffness_stencil(self, radius):
        """The real-space kernel of ``S`` at the offsets within ``radius`` (Euclidean), as
        ``(offsets (m, 2) int, values (m,))``, the centre first. Computed once by one FFT (not counted: a
        set-up cost independent of the problem)."""
        delta = np.zeros(self.size)
        delta[0] = 1.0
        kernel = np.empty(self.size)
        self.operator.stiffness(delta.reshape(self.n, self.n), kernel.reshape(self.n, self.n))
        kernel = kernel.reshape(self.n, self.n)
        reach = int(np.floor(radius))
        offsets = [(0, 0)] + [(a, b) for a in range(-reach, reach + 1) for b in range(-reach, reach + 1)
                              if (a, b) != (0, 0) and a * a + b * b <= radius * radius + 1e-9]
        values = np.array([kernel[a % self.n, b % self.n] for a, b in offsets])
        return np.array(offsets, dtype=np.int64), values

    def destroy(self):
        self._in.destroy()
        self._out.destroy()
        self.operator.destroy()


def restrict_heights(heights, factor, how="inject"):
    """Heights of a grid coarser by ``factor``: ``inject`` (every factor-th node) or ``spectral`` (the
    Fourier modes the coarse grid resolves, the rest dropped)."""
    n = heights.shape[0]
    if how == "inject":
        return np.ascontiguousarray(heights[::factor, ::factor])
    m = n // factor
    spectrum = np.fft.rfft2(heights)
    half = m // 2
    coarse = np.zeros((m, m // 2 + 1), dtype=complex)
    coarse[:half, :half + 1] = spectrum[:half, :half + 1]
    coarse[-half:, :half + 1] = spectrum[-half:, :half + 1]
    return np.fft.irfft2(coarse, s=(m, m)) / factor ** 2


def coarsening_factors(n, coarsest):
    """The factors of the levels N/2^k that have at least ``coarsest`` nodes per side, coarsest first
    (``(4, 2)`` for N = 1024 and 256; ``()`` for N <= 256)."""
    factors = []
    factor = 2
    while n // factor >= coarsest and n % factor == 0:
        factors.insert(0, factor)
        factor *= 2
    return tuple(factors)


def prolong_bilinear(coarse):
    """Bilinear interpolation (periodic) of a field from an ``m x m`` grid to ``2m x 2m``: coarse node
    (i, j) is fine node (2i, 2j)."""
    m = coarse.shape[0]
    fine = np.empty((2 * m, 2 * m))
    right = np.roll(coarse, -1, axis=1)
    below = np.roll(coarse, -1, axis=0)
    diagonal = np.roll(below, -1, axis=1)
    fine[0::2, 0::2] = coarse
    fine[0::2, 1::2] = 0.5 * (coarse + right)
    fine[1::2, 0::2] = 0.5 * (coarse + below)
    fine[1::2, 1::2] = 0.25 * (coarse + right + below + diagonal)
    return fine


# --- preconditioners on a free set -------------------------------------------------------------------------
def remove_mean_on(v, mask, count):
    """``v -= mean of v over the mask`` on the mask, 0 off it (in place)."""
    v -= v[mask].sum() / count if count else 0.0
    v[~mask] = 0.0


class FourierPC:
    """``B r = P (S r)|_F``: the Fourier preconditioner under load control (``r`` has zero sum on F)."""

    name = "fourier"

    def __init__(self, level):
        self.level = level

    def setup(self, free):
        """Called whenever the free set may have changed (nothing to do here)."""

    def apply(self, r, out, free, count):
        self.level.stiffness(r, out)
        remove_mean_on(out, free, count)


class BandPC:
    """The edge-band (harmonic extension) preconditioner ``B = P E' S E P`` of the module docstring.

    ``E r = (r on F, u_O = -M A_OF r on the band O)``, ``E' y = y_F - A_OF' M y_O``, with ``A_OF`` the
    near field of S (offsets within ``radius``) from F to O and ``M`` ``sweeps`` damped Jacobi sweeps on
    ``(D + A_OO) u = b`` (D the diagonal of S, ``A_OO`` its near field within O) from u = 0, a fixed
    polynomial in ``D^-1 A_OO`` times ``D^-1``, so symmetric. ``B`` is then symmetric positive definite on
    F whatever the band and the stencil.

    The band and the sparse matrices are built for the free set of the last :meth:`setup` that changed
    it by more than ``rebuild`` of its size; in between, band nodes that became free are masked out of
    the band (rows and columns of M), which keeps B symmetric.

    Parameters
    ----------
    level : Level
    width : int
        The band O: nodes outside F within this (Chebyshev) distance of F.
    radius : float
        The near-field stencil of S kept in ``A_OF`` and ``A_OO`` (Euclidean offsets, grid units).
    sweeps : int
        Jacobi sweeps of M (1: ``M = omega D^-1``).
    damping : float
        Jacobi damping omega.
    rebuild : float
        Fraction of |F| of changed nodes since the last build that triggers a new one.
    """

    name = "band"

    def __init__(self, level, width=1, radius=1.5, sweeps=1, damping=1.0, rebuild=0.01):
        self.level = level
        self.width, self.radius, self.sweeps, self.damping, self.rebuild = width, radius, sweeps, damping, rebuild
        offsets, values = level.stiffness_stencil(radius)
        self.diagonal = values[0]
        self.offsets, self.values = offsets[1:], values[1:]  # off-diagonal near field
        self.extended = np.zeros(level.size)
        self.built_for = None
        self.valid = None

    def setup(self, free):
        """Rebuild the band for ``free`` if it changed enough since the last build; mask it otherwise."""
        if self.built_for is not None:
            changed = np.count_nonzero(free != self.built_for)
            if changed <= self.rebuild * np.count_nonzero(free):
                self.valid = ~free[self.band]
                return
        self._build(free)

    def _build(self, free):
        from scipy import sparse
        from scipy.ndimage import maximum_filter

        n = self.level.n
        grid = free.reshape(n, n)
        near_free = maximum_filter(grid, size=2 * self.width + 1, mode="wrap")
        self.band = np.flatnonzero((near_free & ~grid).ravel())
        self.built_for = free.copy()
        self.valid = np.ones(self.band.size, dtype=bool)
        rows_i, cols_j = np.divmod(self.band, n)
        local = np.full(n * n, -1, dtype=np.int64)
        local[self.band] = np.arange(self.band.size)
        of_rows, of_cols, of_vals, oo_rows, oo_cols, oo_vals = [], [], [], [], [], []
        for (a, b), value in zip(self.offsets, self.values):
            neighbour = ((rows_i + a) % n) * n + (cols_j + b) % n
            to_free = free[neighbour]
            of_rows.append(np.flatnonzero(to_free))
            of_cols.append(neighbour[to_free])
            of_vals.append(np.full(of_cols[-1].size, value))
            in_band = local[neighbour] >= 0
            oo_rows.append(np.flatnonzero(in_band))
            oo_cols.append(local[neighbour[in_band]])
            oo_vals.append(np.full(oo_cols[-1].size, value))
        size = self.band.size
        self.coupling = sparse.csr_matrix((np.concatenate(of_vals), (np.concatenate(of_rows),
                                                                     np.concatenate(of_cols))), shape=(size, n * n))
        self.coupling_t = self.coupling.T.tocsr()
        self.within = sparse.csr_matrix((np.concatenate(oo_vals), (np.concatenate(oo_rows),
                                                                   np.concatenate(oo_cols))), shape=(size, size))

    def _solve_band(self, rhs):
        """``M rhs``: damped Jacobi sweeps on the band (the valid nodes) from u = 0; ``sweeps=0``: the
        near-field band matrix ``D + A_OO`` solved exactly (sparse LU; a diagnostic of the stencil's limit)."""
        rhs = rhs * self.valid
        if self.sweeps == 0:
            if getattr(self, "_factor_for", None) is not self.within:
                from scipy import sparse
                from scipy.sparse.linalg import splu

                matrix = (self.within + sparse.identity(self.band.size) * self.diagonal).tocsc()
                self._factor, self._factor_for = splu(matrix), self.within
            return self._factor.solve(rhs) * self.valid
        u = self.damping / self.diagonal * rhs
        for _ in range(self.sweeps - 1):
            u += self.damping / self.diagonal * (rhs - self.within @ u - self.diagonal * u)
            u *= self.valid
        return u

    def apply(self, r, out, free, count):
        extended = self.extended
        extended[...] = r  # r vanishes off F
        extended[self.band] += self._solve_band(-(self.coupling @ r))  # E r
        self.level.stiffness(extended, out)
        out -= self.coupling_t @ self._solve_band(out[self.band])  # E' y
        remove_mean_on(out, free, count)


class SchurPC(BandPC):
    """The Schur-complement preconditioner ``B = P (S_FF - S_FO M S_OF) P`` with the whole coupling by FFT.

    Two FFT pairs per application: ``y = S r`` gives ``S_OF r`` on the band O exactly (every range, not
    the near field), ``w = M y_O`` with M the band's Jacobi polynomial (:class:`BandPC`), and
    ``B r = y - S w`` on F. ``K_FF^-1 = S_FF - S_FO S_OO^-1 S_OF`` exactly when O is every node outside F
    and ``M = S_OO^-1``; B is symmetric, and positive definite when ``M <= S_OO^-1`` (damped Jacobi with
    ``damping <= 1 / lambda_max(D^-1 S_OO)``, about 0.5 here).
    """

    name = "schur"

    def apply(self, r, out, free, count):
        self.level.stiffness(r, out)
        extended = self.extended
        extended[...] = 0.0
        extended[self.band] = self._solve_band(out[self.band])
        correction = np.empty_like(out)
        self.level.stiffness(extended, correction)
        out -= correction
        remove_mean_on(out, free, count)


def make_preconditioner(level, spec):
    """A preconditioner from its spec: ``"fourier"`` or ``"band:width=1,radius=1.5,sweeps=1,damping=1"``."""
    name, _, arguments = spec.partition(":")
    if name == "fourier":
        return FourierPC(level)
    if name in ("band", "schur"):
        kwargs = {}
        for item in filter(None, arguments.split(",")):
            key, value = item.split("=")
            kwargs[key] = float(value) if key in ("radius", "damping", "rebuild") else int(value)
        return (BandPC if name == "band" else SchurPC)(level, **kwargs)
    raise ValueError(f"unknown preconditioner '{spec}' (fourier, band:...)")


# --- residuals -----------------------------------------------------------------------------------------------
def natural_residual(p, gap, pbar):
    """``max |min(p / pbar, g)|``: the natural KKT residual (docs/conventions.md), scaled units."""
    return float(np.abs(np.minimum(p * (1.0 / pbar), gap)).max())


def contact_separation(p, elastic_gap, contact=None):
    """d making the mean gap on the contact set zero (PK's choice); ``elastic_gap`` is ``K p - h``."""
    contact = p > 0 if contact is None else contact
    return -elastic_gap[contact].mean()


# --- the floor: CG on a fixed contact set -----------------------------------------------------------------
@dataclass
class FixedSetRun:
    """What :func:`fixed_set_pcg` returns.

    pairs : FFT pairs to the tolerance, the first K p and the certificate included (``2 k + 2`` for k
        iterations of a one-pair preconditioner); None if the tolerance was not reached.
    iterations : CG iterations to the tolerance.
    certified : natural residual on a fresh gap at that point.
    alphas, betas : CG coefficients of every iteration run (for :func:`lanczos_extremes`).
    history : natural residual (on the updated gap) per iteration.
    """

    pairs: int = None
    iterations: int = None
    certified: float = np.nan
    alphas: list = field(default_factory=list)
    betas: list = field(default_factory=list)
    history: list = field(default_factory=list)


def fixed_set_pcg(level, contact, pbar, preconditioner, rtol=1e-8, extra_rtol=None, max_it=2000, start=None):
    """Preconditioned CG for the load-controlled QP on the fixed contact set ``contact`` (bool, flat).

    The floor of issue 39: ``K_CC p + d = h_C``, ``sum p = n pbar``, p = 0 off C, from the natural start
    ``p = n pbar / |C|`` on C (the uniform pressure carrying the load on the exact set: nothing but the set
    is known), or from ``start`` (a pressure, flat) set to zero off C and scaled to carry the load (the warm
    floor of a load step). Each iteration costs two pairs (``B r`` and ``K t``); the gap is updated (``u -= alpha K t``),
    and the natural residual of the whole grid, ``max |min(p / pbar, g)|`` with ``d = -mean_C(K p - h)``,
    is checked on it; the first time it is at most ``rtol`` the residual is recomputed on a fresh
    ``K p`` (the certificate), and the pairs are ``1 + 2 k + 1``. With ``extra_rtol`` CG then continues
    to that relative residual reduction (for the Lanczos estimates of the spectrum); those iterations
    are not counted in ``pairs``.
    """
    size = contact.size
    count = int(contact.sum())
    start_pairs = level.pairs
    if start is None:
        p = np.where(contact, size * pbar / count, 0.0)
    else:
        p = np.where(contact, start, 0.0)
        p *= size * pbar / p.sum()
    u, q, z, t, r = (np.zeros(size) for _ in range(5))
    level.compliance(p, u)
    preconditioner.setup(contact)
    run = FixedSetRun()
    rz_old = None
    r0 = None
    for iteration in range(max_it + 1):
        gap = u - level.h
        d = -gap[contact].mean()
        gap += d
        natural = natural_residual(p, gap, pbar)
        run.history.append(natural)
        np.copyto(r, np.where(contact, gap, 0.0))  # zero mean on C already (d)
        r_norm = np.linalg.norm(r)
        r0 = r_norm if r0 is None else r0
        if run.pairs is None and natural <= rtol:
            fresh = np.empty(size)
            level.compliance(p, fresh)
            gap = fresh - level.h
            gap += -gap[contact].mean()
            run.certified = natural_residual(p, gap, pbar)
            run.pairs, run.iterations = level.pairs - start_pairs, iteration
            if extra_rtol is None:
                break
        if run.pairs is not None and (extra_rtol is None or r_norm <= extra_rtol * r0):
            break
        preconditioner.apply(r, z, contact, count)
        rz = float(r @ z)
        beta = 0.0 if rz_old is None else rz / rz_old
        rz_old = rz
        t *= beta
        t += z
        level.compliance(t, q)
        alpha = rz / float(t @ q)
        run.alphas.append(alpha)
        run.betas.append(beta)
        p -= alpha * t
        u -= alpha * q
    return run


def lanczos_extremes(alphas, betas):
    """Extreme eigenvalues of the preconditioned operator from the coefficients of (P)CG.

    The Lanczos tridiagonal matrix of CG (Saad, Iterative Methods, sec. 6.7.3):
    ``T_11 = 1/alpha_1``, ``T_jj = 1/alpha_j + beta_j/alpha_{j-1}``, ``T_j,j-1 = sqrt(beta_j)/alpha_{j-1}``,
    with ``beta_j`` the coefficient of ``t_j = z_j + beta_j t_{j-1}``. Its extreme eigenvalues (Ritz values)
    converge to those of ``B A`` on the Krylov space from the outside in.
    """
    from scipy.linalg import eigh_tridiagonal

    a = np.asarray(alphas)
    b = np.asarray(betas)
    k = a.size
    diagonal = 1.0 / a
    diagonal[1:] += b[1:] / a[:-1]
    off = np.sqrt(b[1:]) / a[:-1]
    values = eigh_tridiagonal(diagonal, off, eigvals_only=True)
    return float(values[0]), float(values[-1]), k


# --- the cold solver ---------------------------------------------------------------------------------------
@dataclass
class LevelSolve:
    """One level's projected CG: iterations, FFT pairs (this level's own), residuals, restarts."""

    n: int
    iterations: int = 0
    pairs: int = 0
    corrections: int = 0
    point_corrections: int = 0
    restarts: int = 0
    natural: float = np.nan
    history: list = field(default_factory=list)
    trace: list = field(default_factory=list)  # per iteration: (|F|, nodes that changed F, clipped, restart)


@dataclass
class CascadeResult:
    """A cold solve: the pressure (scaled, flat), its certified natural residual, the pairs of every level
    weighted by size (``pairs``), and the levels' own records."""

    pressure: np.ndarray
    separation: float
    natural: float
    load_error: float
    converged: bool
    pairs: float
    levels: list


@dataclass
class CascadeOptions:
    """The options of :class:`CascadePK` (documented there); the defaults are the issue-39 candidate."""

    cascade: object = "auto"
    coarsest: int = 256
    coarse_rtol: float = 1e-3
    restart_fraction: float = np.inf
    preconditioner: str = "band:width=2,radius=1.5,sweeps=4"
    restrict: str = "inject"
    prolong: str = "signed"
    prolong_scale: float = 1.0
    point_corrections: int = 16
    max_it: int = 5000
    lazy_until: float = np.inf
    lazy_ratio: float = 0.0
    clip_ahead: float = 0.0
    near_radius: int = 0
    far_ratio: float = 0.0
    split_coarsening: int = 0
    refresh_ratio: float = 0.0


class CascadePK:
    """Projected preconditioned CG (PK with the BCCG free set) on a cascade of grids.

    Parameters
    ----------
    heights : ndarray (n, n)
        Scaled heights of the fine problem (``problem.local(problem.heights)``).
    cascade : sequence of int or "auto"
        Coarsening factors of the coarse levels, coarsest first: (4, 2) solves at N/4, N/2, then N;
        () is a one-level (cold, uniform start) solve; ``"auto"``: halve down to ``coarsest`` nodes per
        side (:func:`coarsening_factors`).
    coarse_rtol : float
        Natural residual at which a coarse level stops (checked on its updated gap, no certificate).
    restart_fraction : float
        CG keeps its direction (Polak-Ribiere, clipped at 0) while the free set changes by at most
        this fraction of its size in one iteration; a larger change restarts it (beta = 0). inf: never.
    preconditioner : str
        Spec of :func:`make_preconditioner` (every level gets its own).
    restrict : str
        How coarse heights are made: ``inject`` or ``spectral`` (:func:`restrict_heights`).
    prolong : str
        ``bilinear``: the coarse pressure interpolated; ``signed``: ``max(interp(p - s g), 0)`` with s the
        diagonal of S, so that the contact edge is the zero line of an interpolated signed field instead
        of the interpolation's dilation of the coarse set.
    effort : str
        FFTW planner effort of the levels.
    lazy_until : float
        The K p of the projection's corrections (the pressure the projection onto p >= 0 added) is
        computed only once the natural residual is at most this (inf: every iteration that clipped);
        until then they accumulate and the gap is that of ``p - pending``.
    lazy_ratio : float
        And only when their bound on the gap error, ``K_00 sum(pending)``, exceeds this fraction of the
        natural residual (0: always).
    clip_ahead : float
        0: the step is projected (and a pair corrects K p when that moved p). c > 0: before ``K t`` the
        direction is cut at the nodes that a step of c times the previous step length would drive
        negative (so they land on zero), and the step is capped there: the projection never acts.
    near_radius : int
        > 0: the projection's corrections c go into K p as ``K c`` split at this many nodes: the near part
        by the kernel's stencil at once (no pair), and the far part by a pair when its bound
        ``max|K_far| sum(c)`` passes ``far_ratio`` times the residual (or at the end); with
        ``split_coarsening`` instead, the far part at once on the grid coarsened that many times
        (``Level.add_split_responses``, roughpetsc.elastic.split in the solver) and K p afresh each time the
        residual has fallen by ``refresh_ratio`` (0: only for the certificate).
    far_ratio, split_coarsening, refresh_ratio : float, int, float
        See ``near_radius``.
    """

    def __init__(self, heights, effort="FFTW_MEASURE", **options):
        n = heights.shape[0]
        self.options = CascadeOptions(**options)
        cascade = self.options.cascade
        if cascade == "auto":
            cascade = coarsening_factors(n, self.options.coarsest)
        self.cascade = tuple(cascade)
        restrict = self.options.restrict
        self.levels = [Level(restrict_heights(heights, f, restrict), n, effort) for f in self.cascade]
        self.levels.append(Level(heights, n, effort))

    def destroy(self):
        for level in self.levels:
            level.destroy()

    def solve(self, pbar, rtol=1e-8, start=None, start_displacement=None):
        """Solve at mean pressure ``pbar`` (scaled) to a natural residual ``rtol``, certified on a fresh gap.

        ``start`` (flat, fine grid) replaces the cascade: a warm start (load paths), scaled to the load;
        ``start_displacement`` is its K p if known (saves a pair).
        """
        for level in self.levels:
            level.pairs = 0
        records = []
        if start is None:
            p, gap = None, None
            for index, level in enumerate(self.levels):
                last = index == len(self.levels) - 1
                if p is None:
                    p = np.full(level.size, pbar)
                else:
                    p = self._prolongate(p, gap, self.levels[index - 1], level, pbar)
                p, gap, record = self._level_solve(level, p, None, pbar, rtol if last else self.options.coarse_rtol,
                                                   certify=last)
                records.append(record)
        else:
            level = self.levels[-1]
            p = start * (level.size * pbar / start.sum())
            u = None if start_displacement is None else start_displacement * (level.size * pbar / start.sum())
            p, gap, record = self._level_solve(level, p, u, pbar, rtol, certify=True)
            records.append(record)
        fine = self.levels[-1]
        load_error = abs(p.mean() - pbar) / pbar
        natural = records[-1].natural
        return CascadeResult(pressure=p, separation=self._separation, natural=natural, load_error=load_error,
                             converged=natural <= rtol and load_error <= rtol,
                             pairs=sum(level.weighted_pairs for level in self.levels), levels=records)

    def _prolongate(self, p_coarse, gap_coarse, coarse, fine, pbar):
        m = coarse.n
        if self.options.prolong == "signed":
            scale = self.options.prolong_scale * coarse.stiffness_stencil(0.0)[1][0]
            signed = p_coarse - scale * np.maximum(gap_coarse, 0.0)
            p = np.maximum(prolong_bilinear(signed.reshape(m, m)), 0.0).ravel()
        else:
            p = prolong_bilinear(p_coarse.reshape(m, m)).ravel()
        return p * (fine.size * pbar / p.sum())

    @staticmethod
    def _apply_far(level, far_pending, work, u, radius):
        """``u += (K - K_near) c`` for the pending corrections c: one pair."""
        level.compliance(far_pending, work)
        u += work
        nodes = np.flatnonzero(far_pending)
        level.add_near_responses(nodes, -far_pending[nodes], u, radius)
        far_pending[...] = 0.0

    def _level_solve(self, level, p, u, pbar, rtol, certify):
        """Projected PCG on one level from ``p`` (mean pbar); returns ``(p, gap, LevelSolve)``."""
        size = level.size
        preconditioner = make_preconditioner(level, self.options.preconditioner)
        record = LevelSolve(level.n)
        start_pairs = level.pairs
        if u is None:
            u = np.empty(size)
            level.compliance(p, u)
        q, z, t, r, r_old = (np.zeros(size) for _ in range(5))
        pending = np.zeros(size)  # projection corrections not yet applied to u = K (p - pending)
        far_pending = np.zeros(size)  # corrections whose near field is in u but not their far field
        radius = self.options.near_radius
        coarsening = self.options.split_coarsening if level.n >= 4 * self.options.split_coarsening else 0
        split = level.split_kernel(radius // 2, radius, coarsening) if radius and coarsening else None
        far_bound = level.near_window(radius)[1] if radius and not split else 0.0
        approximated, refreshed_at = False, np.inf
        alpha_previous = None
        free_previous = None
        rz_old = 1.0
        fresh = True
        for iteration in range(self.options.max_it + 1):
            elastic = u - level.h
            contact = p > 0
            d = contact_separation(p, elastic, contact)
            gap = elastic + d
            natural = natural_residual(p, gap, pbar)
            if split is not None and self.options.refresh_ratio and approximated and \
                    (natural <= rtol or natural < self.options.refresh_ratio * refreshed_at):
                level.compliance(p, u)  # the split corrections' errors, cleared by a fresh K p
                approximated = False
                refreshed_at = natural
                record.corrections += 1
                continue
            if natural <= rtol and far_pending.any():
                self._apply_far(level, far_pending, z, u, radius)
                record.corrections += 1
                continue
            if natural <= rtol and pending.any():
                level.compliance(pending, z)
                u += z
                pending[...] = 0.0
                record.corrections += 1
                continue
            if natural <= rtol and certify and not fresh:
                level.compliance(p, u)  # the certificate: a fresh gap
                fresh = True
                continue
            record.history.append(natural)
            if natural <= rtol or iteration == self.options.max_it:
                break
            free = contact | (gap < 0)
            count = int(free.sum())
            changed = count if free_previous is None else int(np.count_nonzero(free != free_previous))
            restart = changed > self.options.restart_fraction * count
            if restart or free_previous is None:
                preconditioner.setup(free)
                record.restarts += 1
            elif changed:
                preconditioner.setup(free)
            free_previous = free
            np.copyto(r, np.where(free, gap, 0.0))
            remove_mean_on(r, free, count)
            preconditioner.apply(r, z, free, count)
            rz = float(r @ z)
            if restart:
                beta = 0.0
            else:
                beta = max((rz - float(r_old @ z)) / rz_old, 0.0)
            rz_old = rz
            np.copyto(r_old, r)
            t[~free] = 0.0
            t *= beta
            t += z
            remove_mean_on(t, free, count)
            limit = np.inf
            if self.options.clip_ahead and alpha_previous is not None:
                # Nodes that a step of the predicted length would drive below zero get the direction that
                # lands them on zero; the step is then capped at that length, so the projection never
                # moves p and K p stays exact without a correction pair.
                limit = self.options.clip_ahead * alpha_previous
                hit = t * limit > p
                t[hit] = p[hit] / limit
                ahead = int(np.count_nonzero(hit))
            level.compliance(t, q)
            curvature = float(t @ q)
            alpha = min(float(gap @ t) / curvature, limit)
            alpha_previous = alpha
            trial = p - alpha * t
            p = np.maximum(trial, 0.0)
            u -= alpha * q
            pending += p
            pending -= trial
            fresh = False
            clipped = int(np.count_nonzero(p != trial))
            record.trace.append((count, changed, clipped, bool(restart)))
            if clipped and split is not None:
                nodes = np.flatnonzero(pending)
                level.add_split_responses(nodes, pending[nodes], u, split, radius, coarsening)
                approximated = True
                pending[...] = 0.0
                record.point_corrections += 1
            elif clipped and radius:
                nodes = np.flatnonzero(pending)
                level.add_near_responses(nodes, pending[nodes], u, radius)
                far_pending[nodes] += pending[nodes]
                pending[...] = 0.0
                record.point_corrections += 1
                if far_bound * far_pending.sum() > self.options.far_ratio * natural:
                    self._apply_far(level, far_pending, z, u, radius)
                    record.corrections += 1
            # |K pending|_inf <= K_00 sum(pending): the gap error of skipping the correction, against the residual
            if clipped and natural <= self.options.lazy_until and \
                    level.diagonal * pending.sum() > self.options.lazy_ratio * natural:
                nodes = np.flatnonzero(pending)
                if nodes.size <= self.options.point_corrections:
                    level.add_point_responses(nodes, pending[nodes], u)
                    record.point_corrections += 1
                else:
                    level.compliance(pending, z)  # z is free again: K of the projection's corrections
                    u += z
                    record.corrections += 1
                pending[...] = 0.0
            factor = size * pbar / p.sum()
            p *= factor
            u *= factor
            pending *= factor
            far_pending *= factor
            record.iterations = iteration + 1
        record.pairs = level.pairs - start_pairs
        record.natural = natural
        self._separation = d
        self.last_displacement = u  # K p of the returned p (fresh after the certificate)
        return p, gap, record
