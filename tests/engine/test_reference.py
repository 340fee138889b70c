"""The engine's event sequence against a naive O(N^2) all-pairs, all-images loop."""

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state

from tests.engine.factories import make_sim, next_engine_collision
from tests.engine.reference import next_collision, run_reference

CASES = [
    dict(n=24, packing=0.2, dimension=3, seed=1),
    dict(n=30, packing=0.35, dimension=3, seed=2),
    dict(n=24, packing=0.4, dimension=2, seed=3),
    dict(n=40, packing=0.6, dimension=2, seed=4),
]


def _poly(n, seed):
    return np.random.default_rng(seed).uniform(0.3, 0.5, n)


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("rule", [CollisionRule.elastic(), CollisionRule.constant(0.8)],
                         ids=["elastic", "constant"])
def test_next_event_matches_reference_every_step(case, rule):
    """From the engine's synchronised state, the reference predicts its next collision."""
    sim = make_sim(rule=rule, **case)
    for _ in range(300):
        dt, i, j = next_collision(sim.positions, sim.velocities, sim.radii, sim.box)
        t0 = sim.time
        t, a, b = next_engine_collision(sim)
        assert (a, b) == (min(i, j), max(i, j))
        assert t - t0 == pytest.approx(dt, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("dimension", [2, 3])
def test_polydisperse_next_event_matches_reference(dimension):
    n = 60
    radii = _poly(n, 7)
    st = random_state(n, 0.3, dimension, seed=5, radii=radii)
    sim = Simulation(st, CollisionRule.constant(0.7))
    for _ in range(300):
        dt, i, j = next_collision(sim.positions, sim.velocities, sim.radii, sim.box)
        t0 = sim.time
        t, a, b = next_engine_collision(sim)
        assert (a, b) == (min(i, j), max(i, j))
        assert t - t0 == pytest.approx(dt, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("case", CASES[:1] + CASES[2:3])
def test_free_running_sequence_matches_reference(case):
    """Independent runs agree while chaos has not amplified round-off (first 40 collisions)."""
    sim = make_sim(**case)
    ref, _, vel = run_reference(sim.positions, sim.velocities, sim.radii, sim.masses, sim.box, 40)
    for t, i, j in ref:
        te, a, b = next_engine_collision(sim)
        assert (a, b) == (i, j)
        assert te == pytest.approx(t, rel=1e-8)
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-6, atol=1e-8)
