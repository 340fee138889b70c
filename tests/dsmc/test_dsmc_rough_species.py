"""Rough particles in a mixture in the DSMC: energy accounting with unequal masses and kappa,
exact continuation, identical species giving the one-component rough DSMC bit for bit."""

import numpy as np
import pytest

from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, TangentialRule, WhiteNoise
from granulargas.state import State

RULES = {"constant": TangentialRule.constant(0.2), "coulomb": TangentialRule.coulomb(0.6, 0.15)}


def rough_gas(n, dim, seed, species=None, mixed=True):
    rng = np.random.default_rng(seed)
    of = rng.integers(0, 2, n) if species is None else species
    radii = np.array([0.6, 0.4])[of] if mixed else np.full(n, 0.5)
    masses = np.array([3.0, 0.5])[of] if mixed else np.ones(n)
    kappa = np.array([0.4, 0.25])[of] if mixed else np.full(n, 0.4)
    return State(None, rng.normal(size=(n, dim)) / np.sqrt(masses)[:, None], radii, masses, None, species=of,
                 angular_velocities=rng.normal(size=(n, 3 if dim == 3 else 1)), inertia=kappa)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("model", sorted(RULES))
def test_rough_mixture_energy_and_continuation(dim, model):
    rule = CollisionRule.constant([[0.7, 0.8], [0.8, 0.9]])
    chi = np.array([[1.2, 1.5], [1.5, 1.9]])
    kw = dict(packing_fraction=0.2, chi=chi, tangential=RULES[model],
              driving=WhiteNoise(0.05, 0.05, seed=4, rotational_fraction=0.3))
    a = DSMC(rough_gas(400, dim, 1), rule, seed=3, **kw)
    e0 = a.kinetic_energy + a.rotational_energy
    a.run(8.0)
    b = DSMC(a.state, rule, **kw)
    a.run(20.0)
    b.run(20.0)
    assert a.collisions > 2000 and np.all(a.species_collisions > 0)
    np.testing.assert_array_equal(a.velocities, b.velocities)
    np.testing.assert_array_equal(a.angular_velocities, b.angular_velocities)
    np.testing.assert_array_equal(a.species_collisions, b.species_collisions)
    assert a.kinetic_energy + a.rotational_energy == pytest.approx(
        e0 + a.injected_energy - a.dissipated_energy, rel=1e-10)


@pytest.mark.parametrize("dim", [2, 3])
def test_identical_rough_species_are_the_one_component_rough_dsmc_bit_for_bit(dim):
    n = 500
    species = np.random.default_rng(3).integers(0, 3, n)
    one = DSMC(rough_gas(n, dim, 2, species=np.zeros(n, dtype=int), mixed=False).replace(species=None),
               CollisionRule.constant(0.8), packing_fraction=0.1, seed=9, tangential=RULES["coulomb"])
    three = DSMC(rough_gas(n, dim, 2, species=species, mixed=False), CollisionRule.constant(np.full((3, 3), 0.8)),
                 packing_fraction=0.1, seed=9, chi=np.full((3, 3), one.chi), tangential=RULES["coulomb"])
    for t in (1.0, 20.0):
        one.run(t)
        three.run(t)
    assert one.collisions == three.collisions > 1500
    np.testing.assert_array_equal(one.velocities, three.velocities)
    np.testing.assert_array_equal(one.angular_velocities, three.angular_velocities)
    assert one.dissipated_energy == three.dissipated_energy
