"""The periodic compliance of a few point loads without an FFT pair of the grid: a near stencil and a coarse far field.

A projected CG step of Polonsky-Keer moves p at a few hundred nodes (the projection's correction c) and then
needs ``K c`` to keep ``u = K p`` exact: one FFT pair of the whole grid per such step. Here the kernel (the
response to a unit load, a column of K) is split smoothly at ``R/2 < r < R`` nodes,

    K = K (1 - w) + K w,    w(r) = s^2 (3 - 2 s), s = clip((r - R/2) / (R/2), 0, 1),

and ``K c`` is applied as

- the near part ``K (1 - w)`` (offsets up to R nodes) by a stencil, exactly: (2 R + 1)^2 operations per node;
- the far part ``K w``, smooth (the kernel's 1/r singularity lies in the near part), on the grid coarsened
  by a factor ``coarsening``: the loads restricted to the coarse nodes by the transpose of the interpolation,
  one FFT pair of the coarse grid with ``K w`` sampled at its nodes, and the response interpolated back
  (``transfer``: ``bilinear``, or ``cubic``, 4-point Lagrange). Its error falls like (coarsening / R)^2 of the
  far field with bilinear transfers; cubic ones cut it 3-5 times at R = 32-64 (rms 1.45e-4 -> 4.2e-5 of
  max |K c| at R = 32, coarsening 4) for about 1.5x the interpolation's time. It costs ``coarsening^-2`` of a
  grid pair.

The caller keeps the error bounded by computing ``K p`` afresh now and then (Polonsky-Keer's
``-pk_split_refresh``). Every rank adds the responses on its own rows from the loads of all ranks (gathered,
a few numbers each) and does the same coarse FFT, so parallel runs add exactly what a serial run adds.

Needs a periodic operator (:class:`~roughpetsc.elastic.Westergaard`), square cells, grid sides divisible by
``coarsening`` and at least ``2 R + 1`` nodes (:func:`applicable` says why not).
"""

import numpy as np
from numba import njit

from ..parallel import allsum


# The interpolations from the coarse grid, by name: coarse nodes -offset .. width - 1 - offset around a fine node.
TRANSFERS = ("bilinear", "cubic")


def transfer_weights(transfer, s):
    """``(weights, offset)``: ``weights[f]`` of the coarse nodes ``-offset, ..., width - 1 - offset`` (from the
    one at or below) at the fraction f / s of a coarse interval, f = 0 .. s - 1; bilinear (exact for linear
    functions) or cubic (4-point Lagrange, exact for cubics)."""
    t = np.arange(s) / s
    if transfer == "bilinear":
        return np.stack([1.0 - t, t], axis=1), 0
    if transfer == "cubic":
        return np.stack([-t * (t - 1) * (t - 2) / 6, (t + 1) * (t - 1) * (t - 2) / 2,
                         -(t + 1) * t * (t - 2) / 2, (t + 1) * t * (t - 1) / 6], axis=1), 1
    raise ValueError(f"unknown transfer {transfer!r} (one of {', '.join(TRANSFERS)})")


def applicable(operator, radius, coarsening):
    """None if the split applies to ``operator``, else the reason it does not (a phrase)."""
    grid = operator.grid
    if getattr(operator, "boundary", None) != "periodic":
        return "the elastic operator is not periodic"
    if not np.isclose(grid.l0 / grid.n0, grid.l1 / grid.n1, rtol=1e-12, atol=0.0):
        return "the cells are not square"
    if radius < 2 or coarsening < 1:
        return "the radius must be at least 2 nodes and the coarsening at least 1"
    if min(grid.n0, grid.n1) < 2 * radius + 1:
        return f"the grid has fewer than 2 x {radius} + 1 nodes per side"
    if grid.n0 % coarsening or grid.n1 % coarsening:
        return f"the grid's sides are not divisible by {coarsening}"
    return None


def smooth_step(r, inner, outer):
    """The cubic step w of the module docstring: 0 up to ``inner``, 1 from ``outer``."""
    s = np.clip((r - inner) / (outer - inner), 0.0, 1.0)
    return s * s * (3.0 - 2.0 * s)


def periodic_offsets(n):
    """|offset| of each index of a periodic axis of n nodes from index 0."""
    index = np.arange(n)
    return np.minimum(index, n - index).astype(float)


class SplitCompliance:
    """``u += K c`` for point loads c, as the module docstring says, on the rows this rank owns.

    Parameters
    ----------
    operator : Westergaard
        The periodic compliance; its :attr:`applications` count the one pair of the set-up (the kernel).
    radius : int
        R, the reach of the near stencil in nodes.
    coarsening : int
        The far field's grid is ``coarsening`` times coarser per side.
    pressure, work : petsc4py.PETSc.Vec
        Two Vecs of the operator's layout, for the set-up only (overwritten).
    transfer : str
        The far field's interpolation, one of :data:`TRANSFERS`.

    Attributes
    ----------
    coarse_applications : float
        The coarse FFT pairs so far, in pairs of the grid (``coarsening^-2`` each).
    """

    def __init__(self, operator, radius, coarsening, pressure, work, comm, transfer="bilinear"):
        reason = applicable(operator, radius, coarsening)
        if reason:
            raise ValueError(reason)
        self.comm = comm
        self.radius = radius
        self.coarsening = coarsening
        self.n0, self.n1 = operator.grid.n0, operator.grid.n1
        self.row0 = operator.local_rows.start
        self.coarse_applications = 0.0
        self._coarse = np.zeros((self.n0 // coarsening, self.n1 // coarsening))
        self._weights, self._offset = transfer_weights(transfer, coarsening)
        kernel = self._kernel(operator, pressure, work)
        self.near, self.far_symbol = self._split(kernel)

    def _kernel(self, operator, pressure, work):
        """This rank's rows of the response to a unit load at node (0, 0): one pair."""
        local = operator.local(pressure)
        local[...] = 0.0
        if self.row0 == 0:
            local[0, 0] = 1.0
        operator.displacement(pressure, work)
        return operator.local(work, readonly=True)

    def _gathered(self, kernel, rows, cols):
        """``K[rows][:, cols]`` on every rank, from each rank's own rows (``rows`` sorted, global)."""
        mine = (rows >= self.row0) & (rows < self.row0 + kernel.shape[0])
        part = np.zeros((rows.size, cols.size))
        part[mine] = kernel[rows[mine] - self.row0][:, cols]
        return allsum(self.comm, part.ravel()).reshape(part.shape) if self.comm.Get_size() > 1 else part

    def _split(self, kernel):
        radius, s = self.radius, self.coarsening
        window = np.arange(-radius, radius + 1)
        rows, cols = window % self.n0, window % self.n1
        near_kernel = self._gathered(kernel, rows, cols)
        r = np.hypot(np.abs(window)[:, None], np.abs(window)[None, :]).astype(float)
        near = near_kernel * (1.0 - smooth_step(r, radius / 2, radius))
        coarse_rows, coarse_cols = np.arange(0, self.n0, s), np.arange(0, self.n1, s)
        sampled = self._gathered(kernel, coarse_rows, coarse_cols)
        r = np.hypot(periodic_offsets(self.n0)[::s, None], periodic_offsets(self.n1)[None, ::s])
        far = sampled * smooth_step(r, radius / 2, radius)
        return np.ascontiguousarray(near), np.fft.rfft2(far)

    def add(self, rows, cols, values, out):
        """``out += K c`` on this rank's rows (``out``: local ``(rows, n1)``) for the loads ``values`` at the
        global nodes ``(rows, cols)`` of every rank (the same arrays on every rank)."""
        if values.size == 0:
            return
        add_near(out, self.row0, rows, cols, values, self.near, self.radius, self.n0, self.n1)
        s = self.coarsening
        coarse = self._coarse
        coarse.fill(0.0)
        restrict_points(coarse, rows, cols, values, self._weights, self._offset)
        response = np.fft.irfft2(np.fft.rfft2(coarse) * self.far_symbol, s=coarse.shape)
        self.coarse_applications += 1.0 / (s * s)
        add_interpolated(out, self.row0, response, self._weights, self._offset)


@njit(cache=True)
def add_near(out, row0, rows, cols, values, near, radius, n0, n1):
    """``out[i + a, j + b] += v near[a, b]`` (periodic) on the local rows ``row0 .. row0 + len(out)``."""
    local = out.shape[0]
    width = 2 * radius + 1
    for k in range(values.size):
        value = values[k]
        first = cols[k] - radius
        inside = first >= 0 and first + width <= n1  # no wrap across the columns: a contiguous run
        for a in range(width):
            row = (rows[k] + a - radius) % n0 - row0
            if row < 0 or row >= local:
                continue
            target = out[row]
            stencil = near[a]
            if inside:
                for b in range(width):
                    target[first + b] += value * stencil[b]
            else:
                for b in range(width):
                    target[(first + b) % n1] += value * stencil[b]


@njit(cache=True)
def restrict_points(coarse, rows, cols, values, weights, offset):
    """Point loads onto the coarse nodes: the transpose of :func:`add_interpolated`."""
    m0, m1 = coarse.shape
    s, width = weights.shape
    for k in range(values.size):
        y, x = rows[k] // s - offset, cols[k] // s - offset
        wy, wx = weights[rows[k] % s], weights[cols[k] % s]
        for a in range(width):
            row = (y + a) % m0
            value = values[k] * wy[a]
            for b in range(width):
                coarse[row, (x + b) % m1] += value * wx[b]


def add_interpolated(out, row0, coarse, weights, offset):
    """``out += `` the periodic interpolation of ``coarse`` by ``weights`` and ``offset`` (:func:`transfer_weights`)
    on the local rows ``row0 ..``: the transpose of :func:`restrict_points`."""
    if weights.shape[1] == 2:
        add_bilinear(out, row0, coarse, weights.shape[0])
    else:
        add_cubic(out, row0, coarse, weights)


@njit(cache=True)
def add_bilinear(out, row0, coarse, s):
    """:func:`add_interpolated`, bilinear: separably, each fine row from two coarse rows, then along the row."""
    m0, m1 = coarse.shape
    line = np.empty(m1 + 1)
    for i in range(out.shape[0]):
        row = row0 + i
        y, fy = row // s, (row % s) / s
        y1 = (y + 1) % m0
        for x in range(m1):
            line[x] = (1.0 - fy) * coarse[y, x] + fy * coarse[y1, x]
        line[m1] = line[0]
        target = out[i]
        for x in range(m1):
            low, step = line[x], (line[x + 1] - line[x]) / s
            for f in range(s):
                target[x * s + f] += low + f * step


@njit(cache=True)
def add_cubic(out, row0, coarse, weights):
    """:func:`add_interpolated`, cubic: separably, each fine row from four coarse rows, then along the row."""
    m0, m1 = coarse.shape
    s = weights.shape[0]
    line = np.empty(m1 + 3)  # the row's coarse values from node -1 to m1 + 1, wrapped
    for i in range(out.shape[0]):
        row = row0 + i
        y, wy = row // s, weights[row % s]
        for x in range(m1):
            total = 0.0
            for a in range(4):
                total += wy[a] * coarse[(y - 1 + a) % m0, x]
            line[x + 1] = total
        line[0] = line[m1]
        line[m1 + 1] = line[1]
        line[m1 + 2] = line[2]
        target = out[i]
        for x in range(m1):
            for f in range(s):
                w = weights[f]
                target[x * s + f] += w[0] * line[x] + w[1] * line[x + 1] + w[2] * line[x + 2] + w[3] * line[x + 3]
