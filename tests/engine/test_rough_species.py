"""Rough particles in a mixture: the normal law per pair of species beside one tangential law,
in the engine (against the reference loop with the rigid-body impulse, event by event), energy
accounting with unequal masses, and identical species giving the one-component rough run bit
for bit."""

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation, TangentialRule, WhiteNoise
from granulargas.initial import random_state
from tests.engine.reference import run_reference

EPS3 = np.array([[0.9, 0.6, 0.8], [0.6, 0.5, 0.75], [0.8, 0.75, 0.95]])
WALL3 = [0.5, 0.85, 0.65]
RULES = {"constant": TangentialRule.constant(0.3, wall_restitution=-0.4),
         "coulomb": TangentialRule.coulomb(0.5, 0.2, wall_restitution=0.1, wall_friction=0.4)}


def rough_mixture(n, packing, d, seed, walls=(), sizes=(0.5, 0.35, 0.6), masses=(1.0, 4.0, 0.3),
                  kappas=(0.4, 0.2, 0.6)):
    """Three species of their own radius, mass and kappa, random spins."""
    rng = np.random.default_rng(seed)
    of = rng.integers(0, 3, n).astype(np.int32)
    boundary = tuple("wall" if a in walls else "periodic" for a in range(d))
    st = random_state(n, packing, d, seed=seed, radii=np.asarray(sizes)[of], boundary=boundary)
    spins = rng.normal(size=(n, 3 if d == 3 else 1)) * 2.0
    return st.replace(masses=np.asarray(masses)[of], species=of, angular_velocities=spins,
                      inertia=np.asarray(kappas)[of])


@pytest.mark.parametrize("model", sorted(RULES))
@pytest.mark.parametrize("d, walls", [(3, ()), (2, ()), (3, (1,)), (2, (0,))])
def test_rough_mixture_matches_the_reference(model, d, walls):
    """40 events: eps per pair of species (and per species at the walls), one tangential law,
    unequal masses, sizes and kappa; the same events, velocities and spins as the reference's
    rigid-body impulse."""
    n = 30 if not walls else 40
    st = rough_mixture(n, 0.25 if not walls else 0.15, d, seed=5 + d, walls=walls)
    tg = RULES[model]
    spin3 = np.zeros((n, 3))
    spin3[:, 3 - st.angular_velocities.shape[1]:] = st.angular_velocities
    rough = {"spin": spin3, "inertia": st.inertia, "beta": tg.restitution,
             "mu": tg.friction if model == "coulomb" else None, "wall_beta": tg.wall_beta,
             "wall_mu": tg.wall_mu if model == "coulomb" else None}
    wall_eps = WALL3 if walls else None
    k = 40
    kw = dict(eps=EPS3, walls=walls, wall_eps=wall_eps, rough=rough, species=st.species)
    events, _, _, _ = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, k + 1, **kw)
    _, _, vel_k, spin_k = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, k, **kw)
    sim = Simulation(st, CollisionRule.constant(EPS3, wall_restitution=wall_eps), tangential=tg)
    sim.run(0.5 * (events[k - 1][0] + events[k][0]))
    pairs = sum(1 for e in events[:k] if e[2] >= 0)
    assert (sim.collisions, sim.wall_collisions) == (pairs, k - pairs)
    if walls:
        assert sim.wall_collisions >= 2
    np.testing.assert_allclose(sim.velocities, vel_k, rtol=1e-7, atol=1e-9)
    got = sim.angular_velocities
    np.testing.assert_allclose(got, spin_k[:, 3 - got.shape[1]:], rtol=1e-7, atol=1e-9)
    assert np.triu(sim.species_collisions).sum() == pairs


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("model", sorted(RULES))
def test_energy_and_momentum_of_a_rough_mixture(d, model):
    """Translational plus rotational energy = initial - dissipated to round-off, and the total
    momentum stays put (periodic box), with masses 0.3 to 4 and a restitution per pair."""
    st = rough_mixture(150, 0.2, d, seed=21)
    sim = Simulation(st, CollisionRule.constant(EPS3), tangential=RULES[model])
    p0 = (st.masses[:, None] * st.velocities).sum(axis=0)
    e0 = sim.kinetic_energy + sim.rotational_energy
    sim.run(np.inf, max_collisions=1500)
    assert sim.collisions == 1500
    assert sim.kinetic_energy + sim.rotational_energy == pytest.approx(e0 - sim.dissipated_energy, rel=1e-10)
    p = (sim.masses[:, None] * sim.velocities).sum(axis=0)
    np.testing.assert_allclose(p, p0, atol=1e-10 * np.abs(st.masses[:, None] * st.velocities).sum())


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("neighbours", ["lists", "cells"])
def test_identical_rough_species_give_the_one_component_rough_run_bit_for_bit(d, neighbours):
    """Three labels on one kind of rough particle (one eps for every pair, walls on one axis,
    driving of translation and rotation): the one-component rough trajectory to the last bit."""
    boundary = ("periodic",) * (d - 1) + ("wall",)
    rng = np.random.default_rng(4)
    st = random_state(80, 0.25, d, seed=6, boundary=boundary)
    st = st.replace(angular_velocities=rng.normal(size=(80, 3 if d == 3 else 1)),
                    inertia=np.full(80, 0.4 if d == 3 else 0.5))
    labelled = st.replace(species=rng.integers(0, 3, 80))
    kw = dict(neighbours=neighbours, tangential=RULES["coulomb"],
              driving=WhiteNoise(0.05, 0.1, seed=2, rotational_fraction=0.3))
    a = Simulation(st, CollisionRule.constant(0.8, wall_restitution=0.7), **kw)
    b = Simulation(labelled, CollisionRule.constant(np.full((3, 3), 0.8), wall_restitution=0.7), **kw)
    for t in (1.0, 4.0):
        a.run(t)
        b.run(t)
    assert a.collisions == b.collisions > 200 and a.wall_collisions == b.wall_collisions > 0
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.velocities, b.velocities)
    np.testing.assert_array_equal(a.angular_velocities, b.angular_velocities)
    assert (a.dissipated_energy, a.injected_energy) == (b.dissipated_energy, b.injected_energy)
    # and a restart of the rough mixture continues it exactly
    c = Simulation(b.synchronise().state, b.rule, **kw)
    b.run(6.0)
    c.run(6.0)
    np.testing.assert_array_equal(b.velocities, c.velocities)
    np.testing.assert_array_equal(b.angular_velocities, c.angular_velocities)
    np.testing.assert_array_equal(b.species_collisions, c.species_collisions)
