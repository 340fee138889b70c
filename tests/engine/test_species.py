"""Mixtures: the collision law per pair of species, checked against the naive reference loop,
the one-component engine (bit for bit), and the collision rule itself (hypothesis)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from granulargas.contact import restitution_table
from granulargas.contact.lookup import table_lookup
from granulargas.engine import CollisionRule, Simulation
from granulargas.errors import ConfigError
from granulargas.initial import random_state
from granulargas.state import State

from tests.engine.factories import next_engine_collision, walled_state
from tests.engine.reference import next_collision, run_reference

EPS3 = np.array([[0.9, 0.7, 0.8], [0.7, 0.6, 0.75], [0.8, 0.75, 0.95]])


def _mixture(n, packing, d, seed, sizes=(0.5, 0.35, 0.6), masses=(1.0, 4.0, 0.3), boundary=None):
    """A random state of three species (radii ``sizes``, masses ``masses``), species i.i.d."""
    rng = np.random.default_rng(seed)
    of = rng.integers(0, len(sizes), n).astype(np.int32)
    radii = np.asarray(sizes)[of]
    st = random_state(n, packing, d, seed=seed, radii=radii, boundary=boundary)
    return st.replace(masses=np.asarray(masses)[of], species=of)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("neighbours", ["lists", "cells"])
def test_next_event_of_a_mixture_matches_reference(d, neighbours):
    st = _mixture(40, 0.3, d, seed=d)
    sim = Simulation(st, CollisionRule.constant(EPS3), neighbours=neighbours)
    for _ in range(200):
        dt, i, j = next_collision(sim.positions, sim.velocities, sim.radii, sim.box)
        t0 = sim.time
        t, a, b = next_engine_collision(sim)
        assert (a, b) == (min(i, j), max(i, j))
        assert t - t0 == pytest.approx(dt, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("walls", [(), (0,)])
def test_free_running_mixture_matches_reference(d, walls):
    """Restitution per pair of species and per species at the walls, unequal masses and sizes:
    the engine and the reference agree event by event while chaos has not amplified round-off."""
    boundary = tuple("wall" if a in walls else "periodic" for a in range(d))
    st = _mixture(50 if d == 2 else 80, 0.3 if d == 2 else 0.15, d, seed=10 + d, boundary=boundary)
    wall_eps = [0.5, 0.85, 0.65]
    rule = CollisionRule.constant(EPS3, wall_restitution=wall_eps if walls else None)
    sim = Simulation(st, rule)
    ref, _, vel = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, 60, eps=EPS3,
                                walls=walls, wall_eps=wall_eps if walls else None, species=st.species)
    if walls:
        assert sum(j < 0 for _, _, j in ref) >= 3
    for t, i, j in ref:
        if j >= 0:
            te, a, b = next_engine_collision(sim)
            assert (a, b) == (i, j)
        else:  # a wall event: up to just past it
            w0, c0 = sim.wall_collisions, sim.collisions
            sim.run(t + 1e-9)
            assert (sim.wall_collisions, sim.collisions) == (w0 + 1, c0)
            te = t
        assert te == pytest.approx(t, rel=1e-8)
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-6, atol=1e-8)


def test_viscoelastic_mixture_matches_reference():
    """A prefactor k_ij per pair of species with the engine's restitution table: eps(beta) with
    beta = k_ij (R_eff g_n / m_eff^2)^(1/5) in the reference, pair by pair."""
    table = restitution_table(10.0)
    k = np.array([[0.2, 0.5, 0.3], [0.5, 0.05, 0.4], [0.3, 0.4, 0.6]])

    def eps(si, sj, g, r_eff, m_eff):
        return table_lookup(k[si, sj] * (r_eff * g / m_eff**2) ** 0.2, table.inv_h, table.coeffs)

    st = _mixture(40, 0.25, 3, seed=4)
    sim = Simulation(st, CollisionRule.viscoelastic(k, table))
    ref, _, vel = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, 50, eps=eps,
                                species=st.species)
    for t, i, j in ref:
        te, a, b = next_engine_collision(sim)
        assert (a, b) == (i, j)
        assert te == pytest.approx(t, rel=1e-8)
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-6, atol=1e-8)


def test_collision_counts_per_pair_of_species():
    st = _mixture(60, 0.3, 3, seed=8)
    sim = Simulation(st, CollisionRule.constant(EPS3))
    ref, _, _ = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, 40, eps=EPS3,
                              species=st.species)
    sim.run(np.inf, max_collisions=40)
    want = np.zeros((3, 3), dtype=np.int64)
    for _, i, j in ref:
        a, b = st.species[i], st.species[j]
        want[a, b] += 1
        if a != b:
            want[b, a] += 1
    np.testing.assert_array_equal(sim.species_collisions, want)
    assert np.triu(sim.species_collisions).sum() == sim.collisions == 40
    # they continue across a synchronise and a restart from the state
    sim.run(sim.time + 1.0)
    counts = sim.species_collisions
    again = Simulation(sim.synchronise().state, sim.rule)
    np.testing.assert_array_equal(again.species_collisions, counts)
    sim.run(sim.time + 2.0)
    again.run(again.time + 2.0)
    np.testing.assert_array_equal(again.species_collisions, sim.species_collisions)
    np.testing.assert_array_equal(again.velocities, sim.velocities)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("neighbours", ["lists", "cells"])
@pytest.mark.parametrize("kind", ["constant", "viscoelastic", "elastic"])
def test_identical_species_give_the_one_component_run_bit_for_bit(d, neighbours, kind):
    """Three species with one law for every pair: the same trajectory, to the last bit, as the
    gas without species (walls on one axis)."""
    boundary = ("periodic",) * (d - 1) + ("wall",)
    st = walled_state(80, 0.3, d, (d - 1,), seed=3)
    st = st.replace(species=np.random.default_rng(1).integers(0, 3, 80))
    table = restitution_table(10.0)
    one, three = {
        "constant": (CollisionRule.constant(0.8, wall_restitution=0.7),
                     CollisionRule.constant(np.full((3, 3), 0.8), wall_restitution=0.7)),
        "viscoelastic": (CollisionRule.viscoelastic(0.3, table), CollisionRule.viscoelastic(np.full((3, 3), 0.3), table)),
        "elastic": (CollisionRule.elastic(), CollisionRule.elastic(species=3)),
    }[kind]
    a = Simulation(st, one, neighbours=neighbours)
    b = Simulation(st, three, neighbours=neighbours)
    assert st.boundary == boundary
    for t in (0.5, 2.0, 5.0):
        a.run(t)
        b.run(t)
    assert a.collisions == b.collisions > 250 and a.wall_collisions == b.wall_collisions > 0
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.velocities, b.velocities)
    assert a.dissipated_energy == b.dissipated_energy
    assert a.species_collisions is None and np.triu(b.species_collisions).sum() == b.collisions


@settings(max_examples=60, deadline=None)
@given(mi=st.floats(0.01, 100.0), mj=st.floats(0.01, 100.0), ri=st.floats(0.2, 0.8), rj=st.floats(0.2, 0.8),
       si=st.integers(0, 2), sj=st.integers(0, 2), g=st.floats(0.05, 20.0), tang=st.floats(-5.0, 5.0),
       theta=st.floats(0.0, math.pi), phi=st.floats(0.0, 2 * math.pi))
def test_energy_and_momentum_per_collision_unequal_masses(mi, mj, ri, rj, si, sj, g, tang, theta, phi):
    """One collision of two particles of species si, sj with unequal masses: momentum conserved,
    tangential relative velocity kept, normal one reversed and scaled by eps of the pair
    (whatever the order of the two), and the kinetic energy lost (1 - eps^2) m_eff g_n^2 / 2."""
    n = np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])
    t = np.cross(n, [0.3, -0.7, 0.2])
    t /= np.linalg.norm(t)
    vi, vj = -0.5 * g * n + tang * t, 0.5 * g * n
    u = vi - vj
    centre = np.full(3, 5.0)
    rij = (ri + rj) * n - u * (0.1 / np.linalg.norm(u))
    st = State(np.array([centre + 0.5 * rij, centre - 0.5 * rij]), np.array([vi, vj]), np.array([ri, rj]),
               np.array([mi, mj]), np.full(3, 10.0), species=np.array([si, sj]))
    sim = Simulation(st, CollisionRule.constant(EPS3))
    p0 = (sim.masses[:, None] * sim.velocities).sum(axis=0)
    e0 = sim.kinetic_energy
    sim.run(np.inf, max_collisions=1)
    v1 = sim.velocities
    pos = sim.positions
    nn = pos[0] - pos[1]
    nn /= np.linalg.norm(nn)
    un0 = float(np.dot(vi - vj, nn))
    un1 = float(np.dot(v1[0] - v1[1], nn))
    eps = EPS3[si, sj]
    assert un1 == pytest.approx(-eps * un0, rel=1e-9)
    np.testing.assert_allclose((v1[0] - v1[1]) - un1 * nn, (vi - vj) - un0 * nn, rtol=1e-9, atol=1e-9 * g)
    p1 = (sim.masses[:, None] * v1).sum(axis=0)
    np.testing.assert_allclose(p1, p0, rtol=1e-12, atol=1e-12 * (mi + mj) * (g + abs(tang)))
    m_eff = mi * mj / (mi + mj)
    loss = 0.5 * (1 - eps**2) * m_eff * un0**2
    assert e0 - sim.kinetic_energy == pytest.approx(loss, rel=1e-8, abs=1e-12 * e0)
    assert sim.dissipated_energy == pytest.approx(loss, rel=1e-12)
    want = np.zeros((3, 3), dtype=np.int64)
    want[si, sj] = want[sj, si] = 1
    np.testing.assert_array_equal(sim.species_collisions, want)


def test_bad_species():
    st = _mixture(30, 0.2, 3, seed=1)
    with pytest.raises(ConfigError, match="species: particle .* has species 2, but the rule's pair table has 2"):
        Simulation(st, CollisionRule.constant([[0.9, 0.8], [0.8, 0.9]]))
    with pytest.raises(ConfigError, match="symmetric"):
        CollisionRule.constant([[0.9, 0.8], [0.7, 0.9]])
    with pytest.raises(ConfigError, match=r"\[1\]\[1\] = 1.2"):
        CollisionRule.constant([[0.9, 0.8], [0.8, 1.2]])
    with pytest.raises(ConfigError, match="one value per species"):
        CollisionRule.constant(EPS3, wall_restitution=[0.9, 0.8])
    with pytest.raises(ConfigError, match="resolved"):
        CollisionRule.viscoelastic(np.full((2, 2), 0.1), restitution_table(1.0), duration="resolved")
