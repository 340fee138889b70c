"""DSMC against kinetic theory: Enskog collision frequency, the exact finite-N elastic
equilibrium, a binary mixture, Haff's law."""

import math

import numpy as np
import pytest
from scipy.special import gamma

from tests.dsmc.factories import gas, make_dsmc, maxwell, microcanonical_rate
from granulargas import theory
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule
from granulargas.observables import finite_sample_sonine


@pytest.mark.parametrize("dim", [2, 3])
def test_elastic_collision_rate_and_sonine_coefficients(dim):
    """Elastic gas of N = 100: the collision frequency is Enskog's for the N - 1 partners
    (exact mean relative speed of the finite-N equilibrium), and a2, a3 average to the
    exact finite-N values -2/(D+2), -16/((D+2)(D+4)), D = d(N-1)."""
    sim = make_dsmc(n=100, dim=dim, seed=3, packing=0.05)
    omega = microcanonical_rate(sim)
    # Enskog's omega(n, T) of the theory module for the partner density (N-1)/V and the
    # temperature per degree of freedom of the zero-momentum shell, T N/(N-1); the rest
    # of the finite-N correction is O(1/D)
    n, big_d = sim.n, dim * (sim.n - 1)
    enskog = theory.collision_frequency((n - 1) / sim.volume, sim.temperature * n / (n - 1), dim,
                                        chi=sim.chi)
    assert omega == pytest.approx(enskog, rel=0.5 / big_d)
    samples = 1500
    a2, a3 = np.empty(samples), np.empty(samples)
    for s in range(samples):
        sim.run(sim.time + 10.0 / omega)  # 5 collisions per particle between samples
        a2[s], a3[s] = sim.sonine_a2, sim.sonine_a3
    rate = 2.0 * sim.collisions / (sim.n * sim.time)
    assert rate == pytest.approx(omega, rel=4.0 / math.sqrt(sim.collisions))
    exact_a2, exact_a3 = finite_sample_sonine(sim.n, dim)
    err2 = a2.std() / math.sqrt(samples)
    err3 = a3.std() / math.sqrt(samples)
    assert abs(a2.mean() - exact_a2) < 4 * err2
    assert abs(a3.mean() - exact_a3) < 4 * err3
    # the finite-N value is resolved: a2 differs from 0 by more than its error
    assert exact_a2 < -3 * err2


@pytest.mark.parametrize("dim", [2, 3])
def test_binary_mixture_equipartition_and_collision_rate(dim):
    """Elastic binary mixture (radii 0.5/0.8, masses 1/3): equal species temperatures, and
    the collision rate sum over pairs of chi B_d sigma_ab^(d-1) <g_ab> / V with the
    Maxwellian <g_ab> = sqrt(2T/mu_ab) Gamma((d+1)/2)/Gamma(d/2)."""
    n = 1000
    species = np.arange(n) % 2
    radii = np.where(species == 0, 0.5, 0.8)
    masses = np.where(species == 0, 1.0, 3.0)
    v = maxwell(n, dim, seed=7, masses=masses)
    sim = DSMC(gas(v, radii, masses), CollisionRule.elastic(), packing_fraction=0.05, seed=7)
    temp = sim.temperature
    b_d = math.pi ** ((dim - 1) / 2) / math.gamma((dim + 1) / 2)
    count = [n // 2, n // 2]
    total = 0.0
    for a, b in ((0, 0), (0, 1), (1, 1)):
        pairs = count[a] * (count[a] - 1) / 2 if a == b else count[a] * count[b]
        ra, rb = (0.5, 0.8)[a], (0.5, 0.8)[b]
        ma, mb = (1.0, 3.0)[a], (1.0, 3.0)[b]
        mu = ma * mb / (ma + mb)
        mean_g = math.sqrt(2 * temp / mu) * gamma((dim + 1) / 2) / gamma(dim / 2)
        total += pairs * sim.chi * b_d * (ra + rb) ** (dim - 1) * mean_g / sim.volume
    ratios = []
    for _ in range(200):
        sim.run(sim.time + 2000.0 / total)
        vel = sim.velocities
        t_sp = [float((masses[species == s][:, None] * vel[species == s] ** 2).sum())
                / (dim * count[s]) for s in (0, 1)]
        ratios.append(t_sp[1] / t_sp[0])
    measured = sim.collisions / sim.time
    assert measured == pytest.approx(total, rel=4.0 / math.sqrt(sim.collisions) + 1e-3)
    ratios = np.array(ratios)
    assert abs(ratios.mean() - 1.0) < 4 * ratios.std() / math.sqrt(len(ratios)) + 2e-3


@pytest.mark.parametrize("dim", [2, 3])
def test_haff_law(dim):
    """Constant eps = 0.9: T(t) follows Haff's law with the Enskog cooling rate
    (theory.haff_tau0, van Noije-Ernst a2) within 1 % over a factor ~15 in temperature
    (the run-to-run scatter of T at N = 20000 is ~0.2 %)."""
    eps, packing, n = 0.9, 0.05, 20000
    sim = make_dsmc(n=n, dim=dim, rule=CollisionRule.constant(eps), seed=11, packing=packing)
    t0 = sim.temperature
    nd = theory.number_density(packing, dim)
    tau0 = theory.haff_tau0(eps, (n - 1) / n * nd, t0, dim, chi=sim.chi)
    worst = 0.0
    for t in tau0 * np.array([0.5, 1.0, 2.0, 3.0]):
        sim.run(t)
        worst = max(worst, abs(sim.temperature / theory.haff_temperature(t, t0, tau0) - 1.0))
    assert theory.haff_temperature(3 * tau0, t0, tau0) < t0 / 15
    assert worst < 0.01
