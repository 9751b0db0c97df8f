"""The elementwise work of the TAO bound types' callbacks, fused into compiled loops (numba).

A TAO iteration at 1024^2 spends most of its time in passes over 8 MB vectors: TAO's own (the quasi-Newton
two-loop, the line search, the projections) and ours, the objective and the convergence test of
:mod:`roughpetsc.solvers.bound_load`. Done with numpy and PETSc Vec calls, ours were about twelve passes
per evaluation (waxpy, two dots and two copies in the objective; the ten passes of
:func:`roughpetsc.kkt.report` and a copy of the best iterate in the test). Each function here does one of
them in one pass and returns its local sums; the sums may be reassociated (``fastmath={"reassoc"}``).

The hardness cap enters as ``upper`` (``inf`` without one), as in :mod:`roughpetsc.kernels`.
"""

from numba import njit


@njit(cache=True, fastmath={"reassoc"})
def local_sum(x):
    """Local ``sum(x)``."""
    total = 0.0
    for i in range(x.size):
        total += x[i]
    return total


@njit(cache=True, fastmath={"reassoc"})
def gradient_step(x, point, cached_gap, displacement, heights, separation, out, cached):
    """The gradient ``out = K x - h + separation`` and the step's dot products with it, in one pass.

    ``displacement`` is K x (it may be ``out``). With ``cached`` (the previous point r and its gradient
    g(r) are in ``point`` and ``cached_gap``) returns the local ``(s'g(r), s'g(x))`` of the step
    s = x - r: their mean is the exact change of a quadratic objective from r to x
    (:class:`roughpetsc.solvers.objective.QuadraticObjective`), and -s'g(r) / (s'g(x) - s'g(r)) the
    exact minimiser along s in units of s. Afterwards ``point = x`` and ``cached_gap = out``.

    Returns ``(s'g(r), s'g(x), local sum of x)``; the dots are 0 without ``cached``.
    """
    before = after = 0.0
    total = 0.0
    for i in range(x.size):
        g = displacement[i] - heights[i] + separation
        value = x[i]
        if cached:
            step = value - point[i]
            before += step * cached_gap[i]
            after += step * g
        out[i] = g
        cached_gap[i] = g
        point[i] = value
        total += value
    return before, after, total


@njit(cache=True, fastmath={"reassoc"})
def natural_and_copy(p, gap, scale, upper, copy):
    """The local natural residual ``max |mid(p / scale, g, (p - upper) / scale)|``; ``copy = p`` in the same pass.

    The residual of :func:`roughpetsc.kkt.report` (docs/conventions.md), without the report's other
    measures, which the convergence test does not use.
    """
    natural = 0.0
    inverse = 1.0 / scale
    high = upper * inverse
    for i in range(p.size):
        pressure = p[i] * inverse
        residual = min(max(gap[i], pressure - high), pressure)
        natural = max(natural, abs(residual))
        copy[i] = p[i]
    return natural


@njit(cache=True, fastmath={"reassoc"})
def free_residual(p, gap, upper, source, mask, residual):
    """The free set of a quasi-Newton step into ``mask`` (1.0/0.0) and ``residual = source`` on it, 0 elsewhere.

    Free: ``0 < p < upper``, or a node at a bound whose gradient points into the box (``p = 0``,
    ``g < 0``; ``p = upper``, ``g > 0``), as in the BCCG active set of Polonsky-Keer.
    Returns the local ``(|F|, sum of the residual)``.
    """
    count = total = 0.0
    for i in range(p.size):
        value = p[i]
        if value <= 0.0:
            inside = gap[i] < 0.0
        elif value >= upper:
            inside = gap[i] > 0.0
        else:
            inside = True
        if inside:
            mask[i] = 1.0
            residual[i] = source[i]
            count += 1.0
            total += source[i]
        else:
            mask[i] = 0.0
            residual[i] = 0.0
    return count, total


@njit(cache=True)
def finish_initial_hessian(out, source, mask, shift, mean_term, fixed_scale, gamma):
    """``out = gamma (out - shift + mean_term)`` on the mask, ``gamma fixed_scale source`` off it."""
    for i in range(out.size):
        if mask[i] > 0.0:
            out[i] = gamma * (out[i] - shift + mean_term)
        else:
            out[i] = gamma * fixed_scale * source[i]
