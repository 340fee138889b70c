"""DSMC of mixtures: the law and chi per pair of species, against the one-component DSMC (bit
for bit), the collision rates of kinetic theory, and the homogeneous cooling state of
Garzó & Dufty (1999)."""

import math

import numpy as np
import pytest

from granulargas.contact import prefactor_from_damping, restitution_table
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule
from granulargas.errors import ConfigError
from granulargas.theory.mixture import hcs_temperature_ratios

from tests.dsmc.factories import gas, maxwell


TABLE = restitution_table(3.0)
IDENTICAL = {
    "elastic": (CollisionRule.elastic(), CollisionRule.elastic(species=3)),
    "constant": (CollisionRule.constant(0.8), CollisionRule.constant(np.full((3, 3), 0.8))),
    "viscoelastic": (CollisionRule.viscoelastic(prefactor_from_damping(0.1), TABLE),
                     CollisionRule.viscoelastic(np.full((3, 3), prefactor_from_damping(0.1)), TABLE)),
}


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("rule", sorted(IDENTICAL))
@pytest.mark.parametrize("poly", [False, True], ids=["mono", "poly"])
def test_identical_species_are_the_one_component_dsmc_bit_for_bit(dim, rule, poly):
    """Three labels on one kind of particle (a chi table of one value): the same collisions,
    to the last bit, as the DSMC without species."""
    n = 600
    radii = np.random.default_rng(2).uniform(0.4, 0.6, n) if poly else 0.5
    species = np.random.default_rng(3).integers(0, 3, n)
    one, three = IDENTICAL[rule]
    a = DSMC(gas(maxwell(n, dim, 4), radii), one, packing_fraction=0.1, seed=9)
    b = DSMC(gas(maxwell(n, dim, 4), radii, species=species), three, packing_fraction=0.1, seed=9,
             chi=np.full((3, 3), a.chi))
    for t in (1.0, 5.0, 30.0):
        a.run(t)
        b.run(t)
    assert a.collisions == b.collisions > 3 * n
    np.testing.assert_array_equal(a.velocities, b.velocities)
    assert a.dissipated_energy == b.dissipated_energy
    assert np.triu(b.species_collisions).sum() == b.collisions


def test_continuation_of_a_mixture_is_bit_for_bit():
    n = 500
    species = np.repeat([0, 1], [200, 300])
    masses = np.where(species == 0, 3.0, 1.0)
    rule = CollisionRule.constant([[0.7, 0.8], [0.8, 0.9]])
    chi = np.array([[1.2, 1.5], [1.5, 1.9]])
    st = gas(maxwell(n, 3, 1, masses), np.where(species == 0, 0.7, 0.5), masses, species=species)
    a = DSMC(st, rule, packing_fraction=0.2, seed=3, chi=chi)
    a.run(10.0)
    b = DSMC(a.state, rule, packing_fraction=0.2, seed=123, chi=chi)
    a.run(30.0)
    b.run(30.0)
    np.testing.assert_array_equal(a.velocities, b.velocities)
    np.testing.assert_array_equal(a.species_collisions, b.species_collisions)


def test_pair_collision_rates_follow_chi_and_cross_sections():
    """Elastic equilibrium (all species at one temperature): pairs (i, j) collide at the rate
    n_i n_j chi_ij sigma_ij^2 pi sqrt(8 T / (pi mu_ij)) (times 1/2 for i = j), mu_ij the reduced
    mass -- the counts per pair of species against that, with a chi table far from one value."""
    n = 20000
    species = np.repeat([0, 1], [8000, 12000])
    sigma = np.array([1.6, 1.0])
    mass = np.array([5.0, 1.0])
    chi = np.array([[1.0, 2.5], [2.5, 1.6]])
    st = gas(maxwell(n, 3, 7, mass[species]), 0.5 * sigma[species], mass[species], species=species)
    sim = DSMC(st, CollisionRule.elastic(species=2), volume=4.0e5, seed=1, chi=chi)
    sim.run(np.inf, max_collisions=400_000)
    counts = sim.species_collisions
    got = np.array([counts[0, 0], counts[0, 1], counts[1, 1]], dtype=float)
    nn = np.bincount(species).astype(float)
    rate = np.zeros(3)
    for k, (i, j) in enumerate([(0, 0), (0, 1), (1, 1)]):
        mu = mass[i] * mass[j] / (mass[i] + mass[j])
        pairs = nn[i] * (nn[i] - 1) / 2 if i == j else nn[i] * nn[j]
        rate[k] = pairs * chi[i, j] * (0.5 * (sigma[i] + sigma[j])) ** 2 / math.sqrt(mu)
    want = rate / rate.sum() * got.sum()
    # multinomial counts: standard deviation sqrt(N p (1 - p)) < 350 here
    assert np.all(np.abs(got - want) < 4 * np.sqrt(want)), (got, want)


@pytest.mark.parametrize("mass_ratio, size_ratio, eps", [(4.0, 1.0, 0.8), (8.0, 2.0, 0.8), (1.0, 2.0, 0.7)])
def test_dilute_hcs_temperature_ratio_against_garzo_dufty(mass_ratio, size_ratio, eps):
    """The homogeneous cooling state of a dilute binary mixture (chi = 1, equal numbers): the
    temperature ratio after the transient against the Maxwellian theory of Garzó & Dufty (1999),
    which Montanero & Garzó (2002) found within a few per cent of DSMC at these parameters."""
    n = 20000
    species = np.repeat([0, 1], n // 2)
    mass = np.array([mass_ratio, 1.0])
    sigma = np.array([size_ratio, 1.0])
    st = gas(maxwell(n, 3, 5, mass[species]), 0.5 * sigma[species], mass[species], species=species)
    sim = DSMC(st, CollisionRule.constant(np.full((2, 2), eps)), packing_fraction=0.01, seed=2, chi=1.0)
    sim.run(np.inf, max_collisions=15 * n)  # the transient: some 30 collisions per particle
    ratios = []
    for _ in range(20):
        sim.run(np.inf, max_collisions=n)
        v, m = sim.velocities, sim.masses
        t = [np.mean(m[species == s] * np.sum(v[species == s] ** 2, axis=1)) / 3 for s in (0, 1)]
        ratios.append(t[0] / t[1])
    theory = hcs_temperature_ratios(mass, sigma, [0.5, 0.5], eps)
    assert np.mean(ratios) == pytest.approx(theory[0] / theory[1], rel=0.02)


def test_bad_chi_table():
    st = gas(maxwell(100, 3, 1), 0.5, 1.0, species=np.zeros(100, dtype=int))
    with pytest.raises(ConfigError, match="needs a rule with a table per pair"):
        DSMC(st, CollisionRule.constant(0.9), packing_fraction=0.1, chi=np.ones((2, 2)))
    with pytest.raises(ConfigError, match="symmetric"):
        DSMC(st, CollisionRule.constant(np.full((2, 2), 0.9)), packing_fraction=0.1,
             chi=np.array([[1.0, 2.0], [1.5, 1.0]]))
