"""The event calendar against a naive reference (argmin over all event times)."""

import math

import numpy as np
import pytest

from granulargas.engine._calendar import allocate_calendar, cal_build, cal_check
from tests.engine.kernels import cal_peek, cal_update


def _width(c):
    return float(c.state[0]["width"])


def _origin(c):
    return float(c.state[0]["t0"])


@pytest.mark.parametrize("n, spread", [(5, 1.0), (300, 1.0), (2000, 1e-3), (1000, 1e6)])
def test_calendar_pops_in_time_order_like_a_naive_argmin(n, spread):
    rng = np.random.default_rng(n)
    c = allocate_calendar(n)
    now = 10.0
    c.qt[:] = now + rng.exponential(spread, n)
    c.qt[rng.random(n) < 0.05] = math.inf  # particles at rest
    cal_build(now, c)
    assert cal_check(c)
    ref = c.qt.copy()
    for step in range(20 * n):
        i = cal_peek(c)
        k = int(np.argmin(ref))
        if ref[k] == math.inf:
            assert i == -1
            break
        assert ref[i] == ref[k], f"step {step}: popped {ref[i]} but the earliest is {ref[k]}"
        now = ref[i]
        # the popped particle and a random other one get new times (later or equal to now;
        # sometimes far beyond the ring, sometimes inf, sometimes exactly now)
        for p in (i, int(rng.integers(n))):
            u = rng.random()
            t = math.inf if u < 0.02 else now if u < 0.05 else now + rng.exponential(spread) * (
                1e4 if u > 0.97 else 1.0)
            ref[p] = t
            cal_update(p, t, c)
        if step % 97 == 0:
            assert cal_check(c)
    assert cal_check(c)


def test_calendar_empty_ring_jumps_to_overflow():
    c = allocate_calendar(10)
    c.qt[:] = math.inf
    c.qt[3] = 1e12
    cal_build(0.0, c)
    assert cal_peek(c) == 3
    cal_update(3, math.inf, c)
    assert cal_peek(c) == -1


@pytest.mark.parametrize("capacity", [2, 5])
def test_calendar_with_a_tiny_window_heap_narrows_and_stays_exact(capacity):
    """A small heap far too small for the windows forces the halve-and-replace path."""
    n = 400
    rng = np.random.default_rng(capacity)
    c = allocate_calendar(n, capacity=capacity)
    now = 0.0
    c.qt[:] = rng.exponential(1.0, n)
    assert cal_build(now, c)
    assert cal_check(c)
    w0 = _width(c)
    ref = c.qt.copy()
    for step in range(4000):
        i = cal_peek(c)
        assert i >= 0
        k = int(np.argmin(ref))
        assert ref[i] == ref[k]
        now = ref[i]
        for p in (i, int(rng.integers(n))):
            t = now + rng.exponential(1.0) * (1e-3 if rng.random() < 0.3 else 1.0)
            ref[p] = t
            assert cal_update(p, t, c)
    assert cal_check(c)
    assert _width(c) < w0  # it did narrow


def test_calendar_reports_more_simultaneous_events_than_it_holds():
    c = allocate_calendar(50, capacity=4)
    c.qt[:] = 1.0  # 50 events at the same time
    if cal_build(0.0, c):  # placed in a bucket: the failure comes when it is due
        assert cal_peek(c) == -2
    c.qt[:] = 0.0  # due at once
    assert not cal_build(0.0, c)


def test_calendar_with_the_smallest_chunk_pool_compacts_and_stays_exact():
    """The smallest pool (live entries only) runs dry on stale entries again and again;
    each time all events are placed anew at the same width, in the same order."""
    n = 500
    rng = np.random.default_rng(7)
    c = allocate_calendar(n, pool=1)
    now = 0.0
    c.qt[:] = rng.exponential(1.0, n)
    assert cal_build(now, c)
    w0 = _width(c)
    ref = c.qt.copy()
    compactions = 0
    for step in range(6000):
        i = cal_peek(c)
        assert ref[i] == ref[int(np.argmin(ref))]
        now = ref[i]
        # the popped particle and three others get new times: many entries go stale
        for p in (i, *rng.integers(n, size=3).tolist()):
            t = now + rng.exponential(1.0)
            ref[p] = t
            t0 = _origin(c)
            assert cal_update(p, t, c)
            compactions += _origin(c) != t0  # only placing all anew moves the origin
        if step % 101 == 0:
            assert cal_check(c)
    assert compactions > 5
    assert _width(c) == w0  # compaction never narrows the window


def test_calendar_skips_a_second_entry_of_a_particle_that_came_back():
    """Lazy deletion: a particle moved out of a bucket and back has two entries there."""
    c = allocate_calendar(50)
    c.qt[:] = np.linspace(1.0, 2.0, 50)
    assert cal_build(0.0, c)
    w = _width(c)
    t_far = 0.0 + 30.5 * w
    cal_update(7, t_far, c)
    cal_update(7, t_far + 40 * w, c)
    cal_update(7, t_far, c)
    assert cal_check(c)
    popped = []
    while (i := cal_peek(c)) >= 0:
        popped.append(i)
        cal_update(i, math.inf, c)
    assert sorted(popped) == list(range(50))
