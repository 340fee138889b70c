"""The random streams of the DSMC: xoshiro256** against a plain-Python reference,
uniformity of the counter-based pair stream, seeding."""

import numpy as np
import pytest
from scipy import stats

from tests.dsmc.factories import draw_pairs, draw_u64, draw_uniforms
from granulargas.dsmc._random import seed_state

MASK = (1 << 64) - 1


def xoshiro_reference(state, count):
    """xoshiro256** as published by Blackman & Vigna (2021), in Python integers."""
    s = [int(x) for x in state[:4]]

    def rotl(x, k):
        return ((x << k) | (x >> (64 - k))) & MASK

    out = []
    for _ in range(count):
        out.append(rotl((s[1] * 5) & MASK, 7) * 9 & MASK)
        t = (s[1] << 17) & MASK
        s[2] ^= s[0]
        s[3] ^= s[1]
        s[1] ^= s[2]
        s[0] ^= s[3]
        s[2] ^= t
        s[3] = rotl(s[3], 45)
    return out, s


def test_xoshiro_matches_reference():
    state = seed_state(12345)
    ref, ref_state = xoshiro_reference(state, 200)
    out = np.zeros(200, dtype=np.uint64)
    draw_u64(state, out)
    assert [int(x) for x in out] == ref
    assert [int(x) for x in state[:4]] == ref_state


def test_seed_state_is_deterministic_and_seed_dependent():
    a, b, c = seed_state(7), seed_state(7), seed_state(8)
    assert a.dtype == np.uint64 and a.shape == (5,)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_uniforms_in_unit_interval_and_uniform():
    state = seed_state(3)
    u = np.empty(200_000)
    draw_uniforms(state, u)
    assert u.min() >= 0.0 and u.max() < 1.0
    assert stats.kstest(u, "uniform").pvalue > 1e-4


@pytest.mark.parametrize("n", [2, 3, 7])
def test_pair_stream_uniform_over_ordered_pairs(n):
    key = seed_state(11)[4]
    count = 60_000 * n
    out = np.empty((count, 2), dtype=np.int64)
    draw_pairs(key, 0, count, n, out)
    i, j = out[:, 0], out[:, 1]
    assert np.all((i >= 0) & (i < n) & (j >= 0) & (j < n))
    assert np.all(i != j)
    counts = np.bincount(i * n + j, minlength=n * n).reshape(n, n)
    observed = counts[~np.eye(n, dtype=bool)]
    assert stats.chisquare(observed).pvalue > 1e-4


def test_pair_stream_is_a_pure_function_of_the_counter():
    key = seed_state(5)[4]
    a = np.empty((100, 2), dtype=np.int64)
    b = np.empty((50, 2), dtype=np.int64)
    draw_pairs(key, 1000, 100, 1_000_003, a)
    draw_pairs(key, 1050, 50, 1_000_003, b)
    assert np.array_equal(a[50:], b)
    # neighbouring candidates are not correlated
    c = np.empty((100_000, 2), dtype=np.int64)
    draw_pairs(key, 0, 100_000, 1_000_003, c)
    r = np.corrcoef(c[:-1, 0], c[1:, 0])[0, 1]
    assert abs(r) < 5.0 / np.sqrt(100_000)
