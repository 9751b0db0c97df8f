"""The adhesive laws' one-pass sums along a line, which the gap CG's line search takes, against 40-digit sums."""

import mpmath
import numpy as np
import pytest

from roughpetsc.contact.laws import Dugdale, Exponential


def exact_phi(law, g):
    """phi(g) in 40 digits, continued below g = 0 by its tangent there (both laws' convention)."""
    g, w = mpmath.mpf(float(g)), mpmath.mpf(law.work)
    if g < 0:
        return -w + mpmath.mpf(law.peak_stress) * g
    if law.name == "dugdale":
        return min(mpmath.mpf(law.stress) * g - w, mpmath.mpf(0))
    return -w * mpmath.exp(-g / mpmath.mpf(law.range))


@pytest.mark.parametrize("law", [Exponential(2.0, 0.3), Exponential(1e-3, 1e-6), Dugdale(2.0, 5.0)])
def test_energy_change_and_curvature_along_a_line(law):
    mpmath.mp.dps = 40
    rng = np.random.default_rng(4)
    gaps = np.concatenate([[0.0, 0.0], rng.uniform(0.0, 3.0 * law.range, 60)])
    direction = rng.normal(size=gaps.size) * law.range
    for step in (1e-9, 0.3, 2.0):
        exact = mpmath.fsum(exact_phi(law, g - step * d) - exact_phi(law, g) for g, d in zip(gaps, direction))
        # The sum of changes of either sign: accurate to the round-off of its largest terms.
        scale = law.work * gaps.size * max(step * np.abs(direction).max() / law.range, 1e-16)
        assert abs(law.energy_change_along(gaps, direction, step) - float(exact)) <= 1e-13 * scale
    if law.name == "exponential":
        exact = mpmath.fsum(-mpmath.mpf(law.work) / mpmath.mpf(law.range) ** 2 * mpmath.exp(-mpmath.mpf(g) / law.range)
                            * mpmath.mpf(d) ** 2 for g, d in zip(gaps, direction))
        assert law.curvature_along(gaps, direction) == pytest.approx(float(exact), rel=1e-13)
    else:
        assert law.curvature_along(gaps, direction) == 0.0
