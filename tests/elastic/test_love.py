"""Love's influence coefficients (3.31) and their padded-FFT application (free boundary)."""

import numpy as np
import pytest

from roughpetsc.elastic.love import direct_displacement, influence, padded_symbol


def dissertation_form(R, S, dx, dy):
    """(3.31) exactly as printed: four logarithms of ratios."""
    def root(u, v):
        return np.sqrt(u * u + v * v)

    hx, hy = dx / 2, dy / 2
    return ((R + hx) * np.log(((S + hy) + root(S + hy, R + hx)) / ((S - hy) + root(S - hy, R + hx)))
            + (S + hy) * np.log(((R + hx) + root(S + hy, R + hx)) / ((R - hx) + root(S + hy, R - hx)))
            + (R - hx) * np.log(((S - hy) + root(S - hy, R - hx)) / ((S + hy) + root(S + hy, R - hx)))
            + (S - hy) * np.log(((R - hx) + root(S - hy, R - hx)) / ((R + hx) + root(S - hy, R + hx))))


@pytest.mark.parametrize("offset", [(0, 0), (1, 0), (0, 2), (3, 5), (40, 7)])
def test_influence_equals_the_printed_form_and_the_integral_of_one_over_r(offset):
    from scipy.integrate import dblquad

    dx, dy = 1.0, 0.7
    R, S = offset[0] * dx, offset[1] * dy
    value = influence(R, S, dx, dy)
    assert value == pytest.approx(dissertation_form(R, S, dx, dy), rel=1e-12)
    if offset != (0, 0):  # quadrature of the singular integrand is the printed form's job there
        integral = dblquad(lambda y, x: 1 / np.hypot(R - x, S - y), -dx / 2, dx / 2, -dy / 2, dy / 2,
                           epsabs=1e-13, epsrel=1e-12)[0]
        assert value == pytest.approx(integral, rel=1e-10)


def test_far_field_is_the_point_load():
    """Far from the element, the coefficient tends to area / distance (Boussinesq)."""
    assert influence(1000.0, 300.0, 1.0, 0.5) == pytest.approx(0.5 / np.hypot(1000.0, 300.0), rel=1e-6)


@pytest.mark.parametrize("shape", [(6, 9), (8, 8), (7, 4)])
def test_padded_fft_equals_the_direct_sum(shape):
    n0, n1 = shape
    pressure = np.random.default_rng(1).random(shape)
    dy, dx, E_star = 0.3, 0.2, 2.0
    padded = np.zeros((2 * n0, 2 * n1))
    padded[:n0, :n1] = pressure
    # numpy's irfft2 divides by 4 n0 n1 itself, which padded_symbol folds in: multiply it back.
    symbol = padded_symbol(n0, n1, dy, dx, E_star) * (4 * n0 * n1)
    fast = np.fft.irfft2(np.fft.rfft2(padded) * symbol, s=padded.shape)[:n0, :n1]
    direct = direct_displacement(pressure, dy, dx, E_star)
    assert np.abs(fast - direct).max() < 1e-13 * np.abs(direct).max()
