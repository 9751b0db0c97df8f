"""The gap CG's breakpoint helpers (roughpetsc.contact.loops) against a direct numpy evaluation."""

import math

import numpy as np

from roughpetsc.contact import loops


def random_gap_and_direction(seed, size=1000):
    rng = np.random.default_rng(seed)
    g = np.abs(rng.standard_normal(size))
    t = rng.standard_normal(size)
    contact = rng.random(size) < 0.2
    g[contact] = 0.0
    t[contact] = -np.abs(t[contact])  # feasible: a contact node may only open along -t
    return g, t


def test_first_breakpoint_is_where_the_first_gap_reaches_zero():
    for seed in range(5):
        g, t = random_gap_and_direction(seed)
        rising = t > 0
        expected = np.min(g[rising] / t[rising])
        limit = loops.first_breakpoint(g, t)
        assert limit == expected
        assert np.all(g - limit * t >= -1e-15 * np.abs(g).max())  # no gap crosses 0 up to it
        assert limit > 0 and np.count_nonzero(g - 1.01 * limit * t < 0) == 1  # and one does just past it


def test_first_breakpoint_is_infinite_when_no_gap_closes():
    g, t = random_gap_and_direction(7)
    assert loops.first_breakpoint(g, -np.abs(t)) == math.inf


def test_close_blocking_closes_exactly_the_closing_gaps_at_or_below_the_threshold():
    g, t = random_gap_and_direction(11)
    g[:40] = np.geomspace(1e-17, 1e-10, 40)  # gaps at round-off and above it, half of them closing along -t
    t[:40:2] = np.abs(t[:40:2])
    t[1:40:2] = -np.abs(t[1:40:2])
    threshold = 1e-12
    blocking = (t > 0) & (g <= threshold)
    expected = np.where(blocking, 0.0, g)
    closed = loops.close_blocking(g, t, threshold)
    assert closed == np.count_nonzero(blocking) == np.count_nonzero(np.geomspace(1e-17, 1e-10, 40)[::2] <= 1e-12)
    np.testing.assert_array_equal(g, expected)
