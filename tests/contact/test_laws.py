"""The adhesive laws' one-pass sums along a line, which the gap CG's line search takes, against 40-digit sums; the
ramped Dugdale law against its definition."""

import mpmath
import numpy as np
import pytest

from roughpetsc.contact.laws import Dugdale, Exponential


def exact_phi(law, g):
    """phi(g) in 40 digits, continued below g = 0 by its tangent there (both laws' convention)."""
    g, w = mpmath.mpf(g), mpmath.mpf(law.work)
    if g < 0:
        return -w + mpmath.mpf(law.peak_stress) * g
    if law.name == "dugdale" and law.ramp:
        # The stress falls linearly over [h0 - ramp / 2, h0 + ramp / 2]: phi is the integral of it from infinity.
        s, start, width = mpmath.mpf(law.stress), mpmath.mpf(law.ramp_start), mpmath.mpf(law.ramp)
        across = min(max(g - start, mpmath.mpf(0)), width)
        return min(s * g - w, -s * width / 2) + s * (across - across ** 2 / (2 * width))
    if law.name == "dugdale":
        return min(mpmath.mpf(law.stress) * g - w, mpmath.mpf(0))
    return -w * mpmath.exp(-g / mpmath.mpf(law.range))


@pytest.mark.parametrize("law", [Exponential(2.0, 0.3), Exponential(1e-3, 1e-6), Dugdale(2.0, 5.0),
                                 Dugdale(2.0, 5.0, 0.3), Dugdale(1e-3, 1e2, 5e-6)])
def test_energy_change_and_curvature_along_a_line(law):
    mpmath.mp.dps = 40
    rng = np.random.default_rng(4)
    gaps = np.concatenate([[0.0, 0.0], rng.uniform(0.0, 3.0 * law.range, 60)])
    direction = rng.normal(size=gaps.size) * law.range
    for step in (1e-9, 0.3, 2.0):
        # The ramped law's kernel takes the change -step d itself, not the trial gap rounded: so does its reference.
        trials = ([mpmath.mpf(g) - mpmath.mpf(step) * mpmath.mpf(d) for g, d in zip(gaps, direction)]
                  if law.name == "dugdale" and law.ramp else gaps - step * direction)
        exact = mpmath.fsum(exact_phi(law, t) - exact_phi(law, g) for g, t in zip(gaps, trials))
        # The sum of changes of either sign: accurate to the round-off of its largest terms.
        scale = law.work * gaps.size * max(step * np.abs(direction).max() / law.range, 1e-16)
        assert abs(law.energy_change_along(gaps, direction, step) - float(exact)) <= 1e-13 * scale
    if law.name == "exponential":
        exact = mpmath.fsum(-mpmath.mpf(law.work) / mpmath.mpf(law.range) ** 2 * mpmath.exp(-mpmath.mpf(g) / law.range)
                            * mpmath.mpf(d) ** 2 for g, d in zip(gaps, direction))
        assert law.curvature_along(gaps, direction) == pytest.approx(float(exact), rel=1e-13)
    elif law.ramp:
        on_ramp = (gaps > law.ramp_start) & (gaps < law.ramp_start + law.ramp)
        assert on_ramp.sum() >= 5  # the sample reaches the ramp
        assert law.curvature_along(gaps, direction) == pytest.approx(
            -law.stress / law.ramp * float(np.sum(direction[on_ramp] ** 2)), rel=1e-13)
    else:
        assert law.curvature_along(gaps, direction) == 0.0


@pytest.mark.parametrize("ramp", [0.0, 0.05, 0.6])
def test_the_ramped_dugdale_law_keeps_the_work_and_its_stress_is_the_energys_slope(ramp):
    """phi(0) = -w and phi = 0 beyond h0 + ramp / 2 (the work unchanged); force = phi' and curvature = phi'' by
    central differences of 40-digit energies; the stress falls from sigma0 to 0 across the ramp, half of it at h0."""
    mpmath.mp.dps = 40
    law = Dugdale(1.5, 3.0, ramp)  # h0 = 0.5
    assert law.energy(np.array([0.0]))[0] == pytest.approx(-1.5, rel=1e-15)
    assert law.energy(np.array([0.5 + ramp / 2 + 1e-9, 2.0])) == pytest.approx([0.0, 0.0], abs=1e-15)
    gaps = np.array([0.1, 0.3, 0.49, 0.5, 0.51, 0.52, 0.7, 1.0])
    gaps = gaps[np.abs(gaps - law.ramp_start) > 1e-3]
    gaps = gaps[np.abs(gaps - law.ramp_start - ramp) > 1e-3]
    delta = mpmath.mpf("1e-12")
    for g, force, curvature in zip(gaps, law.force(gaps), law.curvature(gaps)):
        plus, minus, mid = (exact_phi(law, mpmath.mpf(g) + k * delta) for k in (1, -1, 0))
        assert force == pytest.approx(float((plus - minus) / (2 * delta)), abs=1e-12)
        assert curvature == pytest.approx(float((plus - 2 * mid + minus) / delta ** 2), abs=1e-6)
        assert law.energy(np.array([g]))[0] == pytest.approx(float(mid), abs=1e-15)
    if ramp:
        assert law.force(np.array([0.5]))[0] == pytest.approx(1.5)
        assert law.curved and law.ramp_start == pytest.approx(0.5 - ramp / 2)
    else:
        assert not law.curved
