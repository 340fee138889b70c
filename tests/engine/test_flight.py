"""The flight (straight or under gravity): streaming, pair times from a common time, and the
one-particle event times against brute-force sampling of the motion."""

import math

import numpy as np
import pytest

from tests.engine import kernels as K


def first_crossing(f, horizon, n=200_001):
    """First s in [0, horizon] where f (vectorised) turns <= 0 from > 0, by dense sampling and
    bisection (inf if none is sampled)."""
    s = np.linspace(0.0, horizon, n)
    y = f(s)
    bad = np.flatnonzero(y <= 0.0)
    if len(bad) == 0:
        return math.inf
    k = bad[0]
    if k == 0:
        return 0.0
    lo, hi = s[k - 1], s[k]
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if f(np.array([mid]))[0] > 0.0:
            lo = mid
        else:
            hi = mid
    return hi


def test_descend_root_is_the_first_closing_root():
    rng = np.random.default_rng(1)
    for _ in range(2000):
        h = abs(rng.normal()) * 10.0 ** rng.uniform(-6, 1)
        u, a = rng.normal(size=2) * 10.0 ** rng.uniform(-2, 1, size=2)
        s = K.descend_root(h, u, a)
        ref = first_crossing(lambda x: h + u * x + 0.5 * a * x * x, 50.0)
        if math.isinf(ref):
            # nothing within the horizon: the root, if any, lies beyond it
            assert s > 50.0 * (1 - 1e-9)
            continue
        assert s == pytest.approx(ref, rel=1e-9, abs=1e-12)
        assert u + a * s <= 1e-12  # the gap closes there


@pytest.mark.parametrize("h, u, a, expected", [
    (0.0, -1.0, 0.0, 0.0),          # touching, closing: now
    (-1e-17, -1.0, -1.0, 0.0),      # round-off overlap, closing: now
    (0.0, 1.0, -2.0, 1.0),          # touching, opening under a pull back: when it returns
    (0.0, 1.0, 0.0, math.inf),      # touching, opening, no pull: never
    (1.0, 0.0, 0.0, math.inf),      # at rest: never
    (1.0, 0.0, -2.0, 1.0),          # dropped from rest: sqrt(2 h / |a|)
    (1.0, -1.0, 0.0, 1.0),          # straight flight
    (1.0, -1.0, 4.0, math.inf),     # turns round before the gap closes (disc < 0)
])
def test_descend_root_cases(h, u, a, expected):
    assert K.descend_root(h, u, a) == pytest.approx(expected)


def test_streaming_follows_the_parabola_and_wraps():
    g = np.array([0.3, -1.0, 0.0])
    rec = np.zeros((1, 8))
    rec[0, :3] = [1.0, 6.0, 0.5]
    rec[0, 3:6] = [0.5, 0.25, 0.0]
    rec[0, 6] = 2.0
    img = np.zeros((1, 3), dtype=np.int32)
    period = np.array([3.0, np.inf, 1.0])
    K.stream(0, 5.0, rec, img, period, g)
    dt = 3.0
    x = np.array([1.0, 6.0, 0.5]) + np.array([0.5, 0.25, 0.0]) * dt + 0.5 * g * dt**2
    assert rec[0, 6] == 5.0
    np.testing.assert_allclose(rec[0, 3:6], [0.5 + 0.3 * dt, 0.25 - dt, 0.0], rtol=1e-15)
    assert rec[0, 0] == pytest.approx(x[0] - 3.0)  # one wrap on the periodic axis
    assert img[0, 0] == 1
    assert rec[0, 1] == pytest.approx(x[1]) and img[0, 1] == 0  # no wrap on a wall axis


def test_straight_streaming_is_the_straight_line_bit_for_bit():
    rng = np.random.default_rng(2)
    rec = rng.uniform(0, 1, size=(5, 8))
    rec[:, 6] = 0.25
    img = np.zeros((5, 3), dtype=np.int32)
    period = np.full(3, 10.0)
    ref = rec[:, :3] + rec[:, 3:6] * (1.0 - 0.25)
    for i in range(5):
        K.stream(i, 1.0, rec, img, period, None)
    assert np.array_equal(rec[:, :3], ref)


@pytest.mark.parametrize("g", [None, np.array([0.0, 0.0, -2.0]), np.array([0.7, -0.4, 1.1])])
def test_pair_time_from_a_partner_on_its_flight(g):
    """The relative motion under uniform gravity is straight: the pair time computed from
    j streamed on its parabola equals the straight-line time of the two streamed together."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        rec = np.zeros((2, 8))
        rec[:, :3] = rng.uniform(0, 4, size=(2, 3))
        rec[:, 3:6] = rng.normal(size=(2, 3))
        rec[:, 7] = 0.5
        rec[1, 6] = -rng.uniform(0, 1)  # j's clock is behind
        t = 0.0
        period = np.full(3, np.inf)
        s = K.pair_delay(1, t, *rec[0, :3], *rec[0, 3:6], 0.5, rec, period, g)
        gg = np.zeros(3) if g is None else g
        dtj = t - rec[1, 6]
        rj = rec[1, :3] + rec[1, 3:6] * dtj + 0.5 * gg * dtj**2
        vj = rec[1, 3:6] + gg * dtj
        dr, dv = rec[0, :3] - rj, rec[0, 3:6] - vj
        if np.linalg.norm(dr) < 1.0:
            continue  # overlapping states are not the engine's
        ref = first_crossing(lambda x: np.linalg.norm(dr[None] + dv[None] * x[:, None], axis=1) - 1.0, 20.0)
        if math.isinf(ref):
            assert s == math.inf or s > 20.0
        else:
            assert s == pytest.approx(ref, rel=1e-8, abs=1e-10)


@pytest.mark.parametrize("gscale, worst", [(0.1, 0.99), (1.0, 0.9), (10.0, 0.2)])
def test_expiry_under_gravity_is_never_late_and_close(gscale, worst):
    """|g| radius / v^2 ~ 0.03, 0.3, 3 (a vibrated bed: about 0.1): the bound is never late,
    and it is close (the list is rebuilt only a little early)."""
    rng = np.random.default_rng(4)
    radius = 0.3
    late = []
    for _ in range(300):
        g = rng.normal(size=3) * gscale
        d = rng.normal(size=3)
        d *= rng.uniform(0, radius) / np.linalg.norm(d)
        v = rng.normal(size=3)
        s = K.expiry_delay(*d, *v, radius, g)
        ref = first_crossing(lambda x: radius - np.linalg.norm(d[None] + v[None] * x[:, None]
                                                               + 0.5 * g[None] * x[:, None] ** 2, axis=1),
                             10.0)
        assert s <= ref * (1 + 1e-12) + 1e-15, "the expiry bound must never be late"
        late.append(s / ref)
    assert np.median(late) > 0.9999 and np.percentile(late, 5) > 0.999 and np.min(late) > worst


def test_expiry_straight_is_the_exact_root():
    s = K.expiry_delay(0.1, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, None)
    assert s == pytest.approx(0.4, rel=1e-15)
    assert K.expiry_delay(0.6, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, np.array([0.0, 0.0, -1.0])) == 0.0


def test_face_and_plane_times_under_gravity():
    rng = np.random.default_rng(5)
    for _ in range(500):
        rel, v, g = rng.uniform(0, 1), rng.normal(), rng.normal() * 3
        s, side = K.face_delay(rel, v, g, 1.0, True, True)
        ref = first_crossing(lambda x: np.minimum(rel + v * x + 0.5 * g * x * x,
                                                  1.0 - rel - v * x - 0.5 * g * x * x), 20.0)
        if math.isinf(ref):
            assert s > 20.0
            continue
        assert s == pytest.approx(ref, rel=1e-9, abs=1e-12)
        x = rel + v * s + 0.5 * g * s * s
        assert side == (1 if x > 0.5 else 0)
    # a face at a wall is never crossed: the particle turns round and leaves through the other
    s, side = K.face_delay(0.5, 1.0, -1.0, 1.0, True, False)
    assert side == 0 and s == pytest.approx(1.0 + math.sqrt(2.0))
    # a sphere thrown up under a lid touches the lid, else falls back onto the floor
    s, side = K.plane_delay(2.0, 1.0, -1.0, 0.5, 0.0, 3.0)
    assert side == 1 and s == pytest.approx(1.0 - math.sqrt(1.0 - 1.0))
    s, side = K.plane_delay(2.0, 1.0, -1.0, 0.5, 0.0, 5.0)
    assert side == 0 and s == pytest.approx(1.0 + math.sqrt(1.0 + 3.0))
