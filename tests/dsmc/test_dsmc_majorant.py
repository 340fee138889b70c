"""Speed classes of the majorant bound: ordering, edges that bound every speed,
histogram bookkeeping through a run."""

import itertools

import numpy as np

from tests.dsmc.factories import make_dsmc
from granulargas.dsmc._majorant import (
    N_CLASSES,
    build_histogram,
    class_edge,
    new_histogram,
    speed_class,
    top_classes,
)
from granulargas.engine import CollisionRule


def test_speed_class_is_monotone_and_in_range():
    rng = np.random.default_rng(0)
    w2 = np.sort(np.concatenate([[0.0, 5e-324, 1e-310, 1e-300, 1.0, 1e300, 1.7e308],
                                 10.0 ** rng.uniform(-300, 300, 5000)]))
    k = np.array([speed_class(x) for x in w2])
    assert np.all(np.diff(k) >= 0)
    assert k.min() >= 0 and k.max() < N_CLASSES


def test_class_edge_bounds_every_speed_of_its_class_tightly():
    rng = np.random.default_rng(1)
    w = np.concatenate([10.0 ** rng.uniform(-100, 100, 20000), [1.0, 2.0, 0.5, 1.5]])
    for x in w:
        k = speed_class(x * x)
        edge = class_edge(k)
        assert x < edge
        # classes are at most sqrt(5/4) wide in speed (w^2 from 1 to 5/4 of an octave)
        assert edge <= x * 1.25 ** 0.5 * (1 + 1e-9)
        # and the edge of the class below lies under the speed
        assert class_edge(k - 1) <= x * (1 + 1e-9)


def test_histogram_and_top_classes():
    rng = np.random.default_rng(2)
    v = np.zeros((500, 4))
    v[:, :3] = rng.standard_normal((500, 3))
    hist = new_histogram()
    top = build_histogram(v, 3, hist)
    assert hist.sum() == 500
    w = np.sqrt((v[:, :3] ** 2).sum(axis=1))
    order = np.argsort(w)
    assert top == speed_class(w[order[-1]] ** 2)
    k1, k2 = top_classes(hist, top + 5)
    assert k1 == top and k2 == speed_class(w[order[-2]] ** 2)
    assert class_edge(k1) + class_edge(k2) >= w[order[-1]] + w[order[-2]]


def test_bound_follows_the_gas_and_bounds_every_pair():
    """After collisions the class counts equal a fresh count of the velocities, and the
    bound exceeds every pair's relative speed while staying within sqrt(5/4) of the sum of
    the two largest speeds."""
    for dim in (2, 3):
        sim = make_dsmc(n=120, dim=dim, rule=CollisionRule.constant(0.7), seed=4)
        for _ in range(5):
            sim.run(np.inf, max_collisions=300)
            v = sim.velocities
            fresh = new_histogram()
            top = build_histogram(sim._rec, dim, fresh)
            assert np.array_equal(fresh, sim._hist)
            k1, k2 = top_classes(sim._hist, top)
            bound = class_edge(k1) + class_edge(k2)
            g = max(np.linalg.norm(v[a] - v[b]) for a, b in itertools.combinations(range(sim.n), 2))
            assert g < bound
            w = np.sort(np.linalg.norm(v, axis=1))
            assert bound <= (w[-1] + w[-2]) * 1.25 ** 0.5 * (1 + 1e-9)
            assert np.isclose(sim.majorant_rate, sim._scal[3] * bound)


def test_bound_keeps_up_with_a_gas_cooled_by_1e100():
    """Strongly inelastic gas cooled by 100 orders of magnitude: the velocities stay
    peculiar (the rounding drift of their mean, ~1e-16 of the initial speeds, is removed
    every 8N collisions), so the gas keeps cooling and the acceptance stays that of a
    fresh gas."""
    sim = make_dsmc(n=2000, dim=2, rule=CollisionRule.constant(0.3), seed=6)
    sim.run(np.inf, max_collisions=20000)
    fresh = sim.acceptance
    temps = []
    for _ in range(5):
        sim.run(np.inf, max_collisions=100 * 2000)  # 200 collisions per particle
        temps.append(sim.temperature)
    assert temps[-1] < 1e-100 and temps[-1] < 1e-30 * temps[-2]
    sim.run(np.inf, max_collisions=20000)
    assert sim.acceptance > 0.7 * fresh
    assert np.linalg.norm(sim.velocities, axis=1).max() < 10 * np.sqrt(sim.temperature)
