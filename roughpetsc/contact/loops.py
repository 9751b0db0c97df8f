"""The elementwise work of the solvers fused into compiled loops (numba, why: docs/solvers.md) over local flat arrays.

Polonsky-Keer, the adhesive gap CG and its certificate, and the callbacks of TAO's bound types. The hardness
cap is ``upper`` (``inf`` without one). Masks are 0.0/1.0 floats (``contact``, ``free``) or booleans
(``open_nodes``).
"""

import math

from numba import njit


@njit(cache=True, fastmath={"reassoc"})
def contact_and_gap(p, displacement, heights, gap, contact, upper):
    """``gap = K p - h``, ``contact`` the set ``0 < p < upper``; local ``(|C|, sum of gap over C, sum of p)``."""
    count = gap_sum = total = 0.0
    for i in range(p.size):
        g = displacement[i] - heights[i]
        gap[i] = g
        inside = 1.0 if 0.0 < p[i] < upper else 0.0
        contact[i] = inside
        count += inside
        gap_sum += g * inside
        total += p[i]
    return count, gap_sum, total


@njit(cache=True, fastmath={"reassoc"})
def natural_residual(p, gap, separation, scale, upper):
    """``gap += separation``; local ``max |mid(p / scale, g, (p - upper) / scale)|`` and ``sum(p g)`` below the cap."""
    natural = complementarity = 0.0
    inverse = 1.0 / scale
    high = upper * inverse
    for i in range(p.size):
        g = gap[i] + separation
        gap[i] = g
        pressure = p[i] * inverse
        residual = min(max(g, pressure - high), pressure)
        natural = max(natural, abs(residual))
        if p[i] < upper:
            complementarity += p[i] * g
    return natural, complementarity


@njit(cache=True, fastmath={"reassoc"})
def free_set(p, gap, contact, upper, overlapping):
    """The free set F into ``contact``; local ``(|F|, sum of gap over F)``.

    F: the elastic contact set, capped nodes whose gap opens, and with ``overlapping`` (BCCG) negative gaps.
    """
    count = gap_sum = 0.0
    for i in range(p.size):
        g = gap[i]
        if p[i] >= upper:
            inside = g > 0.0
        else:
            inside = p[i] > 0.0 or (overlapping and g < 0.0)
        value = 1.0 if inside else 0.0
        contact[i] = value
        count += value
        gap_sum += g * value
    return count, gap_sum


@njit(cache=True, fastmath={"reassoc"})
def conjugacy_sums(residual, direction, previous, t, contact, keep_previous):
    """Local ``(r'z, r_old'z, sum of t over F, sum of z)`` with z = ``direction``; ``previous = residual``
    afterwards when ``keep_previous`` (the Polak-Ribiere beta needs the last residual)."""
    rz = previous_z = t_free = direction_sum = 0.0
    for i in range(residual.size):
        z = direction[i]
        rz += residual[i] * z
        previous_z += previous[i] * z
        t_free += t[i] * contact[i]
        direction_sum += z
        if keep_previous:
            previous[i] = residual[i]
    return rz, previous_z, t_free, direction_sum


@njit(cache=True, fastmath={"reassoc"})
def new_direction(t, contact, beta, shift, direction):
    """``t = (beta t - shift)`` on the free set ``+ direction``: the conjugate direction, less ``shift`` on F."""
    for i in range(t.size):
        t[i] = contact[i] * (beta * t[i] - shift) + direction[i]


@njit(cache=True, fastmath={"reassoc"})
def step_sums(response, contact, t, gap):
    """Local ``(sum of K t over F, sum of t, g't, t'K t)``: what the exact step along t needs."""
    response_free = t_sum = numerator = curvature = 0.0
    for i in range(t.size):
        response_free += response[i] * contact[i]
        t_sum += t[i]
        numerator += gap[i] * t[i]
        curvature += response[i] * t[i]
    return response_free, t_sum, numerator, curvature


@njit(cache=True, fastmath={"reassoc"})
def take_step(p, t, displacement, response, step, upper, moved_nodes, moved_by):
    """``p -= step t`` onto [0, upper], ``K p -= step K t``; local ``(nodes the projection moved, sum of p)``.

    The first ``moved_nodes.size`` nodes the projection moved are listed in ``moved_nodes`` (local flat
    indices), with what it added to each in ``moved_by`` (empty arrays: none listed).
    """
    clipped = 0
    total = 0.0
    room = moved_nodes.size
    for i in range(p.size):
        displacement[i] -= step * response[i]
        trial = p[i] - step * t[i]
        value = trial
        if value < 0.0:
            value = 0.0
            clipped += 1
        elif value > upper:
            value = upper
            clipped += 1
        if value != trial and clipped <= room:  # moved: clipped counts it already
            moved_nodes[clipped - 1] = i
            moved_by[clipped - 1] = value - trial
        p[i] = value
        total += value
    return clipped, total


@njit(cache=True, fastmath={"reassoc"})
def rescale(p, displacement, factor):
    """``p *= factor`` and ``K p *= factor``."""
    for i in range(p.size):
        p[i] *= factor
        displacement[i] *= factor


@njit(cache=True, fastmath={"reassoc"})
def capped_load(p, upper):
    """Local ``(number of nodes at the cap, sum of p)``."""
    capped = 0
    total = 0.0
    for i in range(p.size):
        if p[i] >= upper:
            capped += 1
        total += p[i]
    return capped, total


@njit(cache=True, fastmath={"reassoc"})
def scale_below_cap(p, upper, factor):
    """``p *= factor`` below the cap, capping a node lifted above it; the local number so capped."""
    lifted = 0
    for i in range(p.size):
        if p[i] < upper:
            value = p[i] * factor
            if value > upper:
                value = upper
                lifted += 1
            p[i] = value
    return lifted


# --- the adhesive gap CG ---------------------------------------------------------------------------------
@njit(cache=True, fastmath={"reassoc"})
def open_sums(g, r, open_nodes):
    """``open_nodes = g > 0``; local ``(number of open nodes, sum of r over them)``."""
    count = 0
    r_sum = 0.0
    for i in range(g.size):
        is_open = g[i] > 0.0
        open_nodes[i] = is_open
        if is_open:
            count += 1
            r_sum += r[i]
    return count, r_sum


@njit(cache=True, fastmath={"reassoc"})
def gap_natural(g, r, multiplier, scale):
    """Local ``max |min(g, (r - multiplier) / scale)|``."""
    natural = 0.0
    inverse = 1.0 / scale
    for i in range(g.size):
        natural = max(natural, abs(min(g[i], (r[i] - multiplier) * inverse)))
    return natural


@njit(cache=True, fastmath={"reassoc"})
def gap_free_residual(r, multiplier, open_nodes, free, residual):
    """The free set (open nodes and the contact nodes that pull, ``r < multiplier``) into ``free`` and
    ``residual = r - multiplier`` on it; local ``(|F|, sum of the residual)``."""
    count = total = 0.0
    for i in range(r.size):
        value = r[i] - multiplier
        inside = 1.0 if open_nodes[i] or value < 0.0 else 0.0
        free[i] = inside
        residual[i] = value * inside
        count += inside
        total += value * inside
    return count, total


@njit(cache=True, fastmath={"reassoc"})
def masked_sum(v, mask):
    """Local ``sum of v over the mask``."""
    total = 0.0
    for i in range(v.size):
        total += v[i] * mask[i]
    return total


@njit(cache=True)
def shift_on(v, mask, shift, out):
    """``out = (v - shift)`` on the mask, 0 elsewhere (``out`` may be ``v``)."""
    for i in range(v.size):
        out[i] = (v[i] - shift) * mask[i]


@njit(cache=True, fastmath={"reassoc"})
def close_contact_nodes(t, open_nodes):
    """``t = min(t, 0)`` at the contact nodes (a node in contact may only open along -t); local sum of t."""
    total = 0.0
    for i in range(t.size):
        if not open_nodes[i] and t[i] > 0.0:
            t[i] = 0.0
        total += t[i]
    return total


@njit(cache=True, fastmath={"reassoc"})
def shift_open_slope(t, open_nodes, shift, r):
    """``t -= shift`` on the open nodes; local slope ``r't``."""
    slope = 0.0
    for i in range(t.size):
        if open_nodes[i]:
            t[i] -= shift
        slope += r[i] * t[i]
    return slope


@njit(cache=True, fastmath={"reassoc"})
def two_dots(t, response, elastic):
    """Local ``(t'S t, t'S(g + h))`` with ``response`` = S t and ``elastic`` = S (g + h)."""
    curvature = slope = 0.0
    for i in range(t.size):
        curvature += t[i] * response[i]
        slope += t[i] * elastic[i]
    return curvature, slope


@njit(cache=True)
def gap_step(g, t, step):
    """``g -= step t``; the local number of negative gaps after it."""
    negative = 0
    for i in range(g.size):
        value = g[i] - step * t[i]
        g[i] = value
        if value < 0.0:
            negative += 1
    return negative


@njit(cache=True)
def first_breakpoint(g, t):
    """Local ``min g_i / t_i`` over ``t_i > 0``: the step along -t at which the first gap reaches 0 (inf if none)."""
    limit = math.inf
    for i in range(g.size):
        if t[i] > 0.0:
            limit = min(limit, g[i] / t[i])
    return limit


@njit(cache=True)
def close_blocking(g, t, threshold):
    """Set to 0 the gaps at most ``threshold`` that close along -t (t_i > 0); their count."""
    count = 0
    for i in range(g.size):
        if t[i] > 0.0 and g[i] <= threshold:
            g[i] = 0.0
            count += 1
    return count


@njit(cache=True)
def subtract_scaled(v, w, factor):
    """``v -= factor w``."""
    for i in range(v.size):
        v[i] -= factor * w[i]


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

    ``displacement`` is K x (may be ``out``). With ``cached`` (the previous point r and g(r) in ``point`` and
    ``cached_gap``) the dots of s = x - r: their mean is the exact change of a quadratic objective from r to x.
    Afterwards ``point = x``, ``cached_gap = out``. Returns ``(s'g(r), s'g(x), local sum of x)`` (dots 0 uncached).
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
    """The local natural residual ``max |mid(p / scale, g, (p - upper) / scale)|``; ``copy = p`` in the same pass."""
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
    """The free set of a quasi-Newton step into ``mask`` and ``residual = source`` on it; local ``(|F|, sum)``.

    Free: ``0 < p < upper``, or at a bound with the gradient pointing into the box (as BCCG's active set).
    Selects, not branches: a branch per node mispredicts at the contact edges (N = 1024: 6 ms against 3 on
    contact islands, 12 against 4 on a random set).
    """
    count = total = 0.0
    for i in range(p.size):
        value = p[i]
        g = gap[i]
        inside = ((value > 0.0) & (value < upper)) | ((value <= 0.0) & (g < 0.0)) | ((value >= upper) & (g > 0.0))
        kept = source[i] if inside else 0.0
        mask[i] = 1.0 if inside else 0.0
        residual[i] = kept
        count += 1.0 if inside else 0.0
        total += kept
    return count, total


@njit(cache=True)
def finish_initial_hessian(out, source, mask, shift, mean_term, fixed_scale, gamma):
    """``out = gamma (out - shift + mean_term)`` on the mask, ``gamma fixed_scale source`` off it (a select, as
    :func:`free_residual`)."""
    for i in range(out.size):
        free = gamma * (out[i] - shift + mean_term)
        fixed = gamma * fixed_scale * source[i]
        out[i] = free if mask[i] > 0.0 else fixed


@njit(cache=True)
def _exponential_change(gap, trial, work, range_):
    """phi(trial) - phi(gap) of phi = -w exp(-g / rho), continued below 0 by its tangent there, without cancellation
    and without a positive exponent: s phi(min(g, t)) expm1(-|g - t| / rho), s the sign of t - g."""
    above = max(trial, 0.0)
    change = (trial - above) * (work / range_)
    difference = gap - above
    factor = math.copysign(math.expm1(-abs(difference) / range_), difference)
    return change + factor * (-work * math.exp(-min(above, gap) / range_))


@njit(cache=True)
def exponential_changes(gap, trial, work, range_, out):
    """``out = phi(trial) - phi(gap)`` node by node (:func:`_exponential_change`)."""
    for i in range(gap.size):
        out[i] = _exponential_change(gap[i], trial[i], work, range_)
    return out


@njit(cache=True, fastmath={"reassoc"})
def exponential_change_along(gap, direction, step, work, range_):
    """Local sum of phi(g - step d) - phi(g) (:func:`_exponential_change`): the line search's law part, no array."""
    total = 0.0
    for i in range(gap.size):
        total += _exponential_change(gap[i], gap[i] - step * direction[i], work, range_)
    return total


@njit(cache=True, fastmath={"reassoc"})
def exponential_curvature_along(gap, direction, work, range_):
    """Local sum of phi''(g) d^2 = -(w / rho^2) exp(-g / rho) d^2."""
    total = 0.0
    for i in range(gap.size):
        total += math.exp(-gap[i] / range_) * direction[i] * direction[i]
    return -work / (range_ * range_) * total


@njit(cache=True)
def _ramp_primitive(x, width):
    """int_0^x of the ramped Dugdale stress over sigma0, x = g - (h0 - width / 2): 1 below, falling to 0 across."""
    if x <= 0.0:
        return x
    x = min(x, width)
    return x - x * x / (2.0 * width)


@njit(cache=True)
def _ramp_change(gap, delta, stress, start, width):
    """phi(gap + delta) - phi(gap) of the ramped Dugdale law: on one piece in closed form (no cancellation
    against the gap itself, which the line search's tiny steps need), across pieces from the primitive."""
    x, y = gap - start, gap + delta - start
    if x <= 0.0 and y <= 0.0:
        return stress * delta
    if x >= width and y >= width:
        return 0.0
    if 0.0 < x < width and 0.0 < y < width:
        return stress * delta * (1.0 - (x + 0.5 * delta) / width)
    return stress * (_ramp_primitive(y, width) - _ramp_primitive(x, width))


@njit(cache=True, fastmath={"reassoc"})
def ramped_dugdale_change_along(gap, direction, step, stress, start, width):
    """Local sum of phi(g - step d) - phi(g) of the ramped Dugdale law (:func:`_ramp_change`)."""
    total = 0.0
    for i in range(gap.size):
        total += _ramp_change(gap[i], -step * direction[i], stress, start, width)
    return total


@njit(cache=True)
def ramped_dugdale_changes(gap, trial, stress, start, width, out):
    """``out = phi(trial) - phi(gap)`` node by node (:func:`_ramp_change`)."""
    for i in range(gap.size):
        out[i] = _ramp_change(gap[i], trial[i] - gap[i], stress, start, width)
    return out


@njit(cache=True, fastmath={"reassoc"})
def ramped_dugdale_curvature_along(gap, direction, stress, start, width):
    """Local sum of phi''(g) d^2: -sigma0 / width on the ramp, 0 off it."""
    total = 0.0
    for i in range(gap.size):
        x = gap[i] - start
        if 0.0 < x < width:
            total += direction[i] * direction[i]
    return -stress / width * total


@njit(cache=True, fastmath={"reassoc"})
def dugdale_change_along(gap, direction, step, stress, range_):
    """Local sum of phi(g - step d) - phi(g) of the Dugdale law: sigma0 (min(t, h0) - min(g, h0))."""
    total = 0.0
    for i in range(gap.size):
        total += min(gap[i] - step * direction[i], range_) - min(gap[i], range_)
    return stress * total
