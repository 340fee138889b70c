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


# ---------------------------------------------------------------- the reference with rotation


def _rough_case(dimension, seed, walls=()):
    n = 20 if dimension == 2 or not walls else 40
    packing = 0.3 if not walls else 0.15
    boundary = tuple("wall" if a in walls else "periodic" for a in range(dimension))
    st = random_state(n, packing, dimension, seed=seed, boundary=boundary)
    rng = np.random.default_rng(seed)
    spin = rng.normal(size=(n, 3))
    if dimension == 2:
        spin[:, :2] = 0.0
    kappa = rng.uniform(0.2, 0.6, n)
    return st, spin, kappa


def _energy(vel, spin, radii, masses, kappa):
    return 0.5 * np.sum(masses * np.sum(vel**2, 1)) + 0.5 * np.sum(kappa * masses * radii**2 * np.sum(spin**2, 1))


@pytest.mark.parametrize("dimension", [2, 3])
def test_reference_smooth_limit_keeps_the_smooth_events_and_the_spins(dimension):
    """beta_t = -1: the rough reference runs the smooth event sequence; spins never change."""
    st, spin, kappa = _rough_case(dimension, 11)
    smooth = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, 60, eps=0.8)
    rough = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, 60, eps=0.8,
                          rough={"spin": spin, "inertia": kappa, "beta": -1.0})
    assert [e[1:] for e in rough[0]] == [e[1:] for e in smooth[0]]
    np.testing.assert_allclose([e[0] for e in rough[0]], [e[0] for e in smooth[0]], rtol=1e-12)
    np.testing.assert_allclose(rough[2], smooth[2], atol=1e-12)
    np.testing.assert_allclose(rough[3], spin, atol=1e-12)  # the impulse solve rounds


@pytest.mark.parametrize("dimension, walls", [(2, ()), (3, ()), (3, (0,)), (2, (1,))])
def test_reference_perfectly_rough_elastic_run_conserves_energy_and_momentum(dimension, walls):
    """eps = beta_t = 1 (walls too): the kinetic energy, translation plus rotation, is kept;
    without walls also the momentum. Energy moves between translation and rotation."""
    st, spin, kappa = _rough_case(dimension, 12, walls)
    e0 = _energy(st.velocities, spin, st.radii, st.masses, kappa)
    ev, _, vel, spin1 = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, 80, eps=1.0,
                                      walls=walls, rough={"spin": spin, "inertia": kappa, "beta": 1.0})
    assert _energy(vel, spin1, st.radii, st.masses, kappa) == pytest.approx(e0, rel=1e-12)
    rot0 = np.sum(kappa * st.masses * st.radii**2 * np.sum(spin**2, 1))
    rot1 = np.sum(kappa * st.masses * st.radii**2 * np.sum(spin1**2, 1))
    assert abs(rot1 - rot0) > 1e-3 * rot0
    if walls:
        assert any(j < 0 for _, _, j in ev)
    else:
        np.testing.assert_allclose(st.masses @ vel, st.masses @ st.velocities, atol=1e-12)
    if dimension == 2:
        assert np.all(spin1[:, :2] == 0.0)
