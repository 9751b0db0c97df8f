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


def test_close_blocking_closes_exactly_the_gaps_reaching_zero_by_the_step():
    g, t = random_gap_and_direction(11)
    g[:3] = 1e-14 * t[:3] ** 2 + 1e-300  # tiny gaps closing along -t
    t[:3] = np.abs(t[:3])
    limit = 2e-14 * np.abs(t).max()
    blocking = (t > 0) & (g <= limit * t)
    expected = np.where(blocking, 0.0, g)
    closed = loops.close_blocking(g, t, limit)
    assert closed == np.count_nonzero(blocking) >= 3
    np.testing.assert_array_equal(g, expected)
