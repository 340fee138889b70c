"""Rough particles in the DSMC: the engine's collision law, exact continuation, energy
accounting, the spin kicks, and the smooth loop untouched."""

import numpy as np
import pytest

from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, TangentialRule, WhiteNoise
from granulargas.errors import ConfigError
from granulargas.state import State


def rough_state(n=400, dim=3, seed=1, mixed=False):
    rng = np.random.default_rng(seed)
    radii = rng.uniform(0.35, 0.5, n) if mixed else np.full(n, 0.5)
    masses = rng.uniform(0.5, 2.0, n) if mixed else np.ones(n)
    kmax = 2.0 / 3.0 if dim == 3 else 1.0
    kappa = rng.uniform(0.2, kmax, n) if mixed else np.full(n, 0.4 if dim == 3 else 0.5)
    return State(None, rng.normal(size=(n, dim)), radii, masses, None,
                 angular_velocities=rng.normal(size=(n, 3 if dim == 3 else 1)) * 2.0, inertia=kappa)


RULES = {"constant": TangentialRule.constant(0.2), "coulomb": TangentialRule.coulomb(0.6, 0.15)}


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("model", sorted(RULES))
@pytest.mark.parametrize("mixed", [False, True])
def test_continuation_is_exact_and_energy_is_accounted(dim, model, mixed):
    st = rough_state(300, dim, seed=2, mixed=mixed)
    kw = dict(packing_fraction=0.2, tangential=RULES[model],
              driving=WhiteNoise(0.05, 0.05, seed=4, rotational_fraction=0.3))
    a = DSMC(st, CollisionRule.constant(0.9), seed=3, **kw)
    e0 = a.kinetic_energy + a.rotational_energy
    a.run(8.0)
    b = DSMC(a.state, CollisionRule.constant(0.9), **kw)
    a.run(20.0)
    b.run(20.0)
    assert np.array_equal(a.velocities, b.velocities)
    assert np.array_equal(a.angular_velocities, b.angular_velocities)
    assert (a.collisions, a.dissipated_energy, a.injected_energy) == (b.collisions, b.dissipated_energy,
                                                                      b.injected_energy)
    assert a.collisions > 1000
    assert a.kinetic_energy + a.rotational_energy == pytest.approx(
        e0 + a.injected_energy - a.dissipated_energy, rel=1e-10)
    assert np.array_equal(a.state.inertia, st.inertia)


def test_smooth_limit_keeps_the_spins_and_the_energy_balance_of_the_smooth_law():
    """beta_t = -1: the spins never change and the loss is the smooth one (the rough DSMC draws
    the same pairs and normals as the smooth one; the velocities agree to round-off)."""
    st = rough_state(300, 3, seed=6)
    rough = DSMC(st, CollisionRule.constant(0.8), packing_fraction=0.05, seed=1,
                 tangential=TangentialRule.constant(-1.0))
    smooth = DSMC(st, CollisionRule.constant(0.8), packing_fraction=0.05, seed=1)
    rough.run(10.0)
    smooth.run(10.0)
    assert rough.collisions == smooth.collisions > 500
    assert np.array_equal(rough.angular_velocities, st.angular_velocities)
    np.testing.assert_allclose(rough.velocities, smooth.velocities, rtol=1e-9, atol=1e-9)
    assert rough.dissipated_energy == pytest.approx(smooth.dissipated_energy, rel=1e-9)


def test_rough_collisions_exchange_energy_with_the_spins():
    st = rough_state(400, 3, seed=7)
    st = st.replace(angular_velocities=np.zeros((400, 3)))
    sim = DSMC(st, CollisionRule.elastic(), packing_fraction=0.05, seed=2, tangential=TangentialRule.constant(1.0))
    sim.run(20.0)
    assert sim.rotational_temperature > 0.3 * sim.temperature  # equipartition is the end point
    assert sim.dissipated_energy == pytest.approx(0.0, abs=1e-9)
    assert sim.angular_velocities.shape == (400, 3)


def test_input_checks():
    st = rough_state(50, 3)
    with pytest.raises(ConfigError, match="rotational_fraction"):
        DSMC(st, CollisionRule.elastic(), packing_fraction=0.05, driving=WhiteNoise(0.1, 0.1, rotational_fraction=1))
    with pytest.raises(ConfigError, match="inertia"):
        DSMC(st.replace(inertia=np.full(50, 2.0)), CollisionRule.elastic(), packing_fraction=0.05,
             tangential=TangentialRule.constant(0.0))
    smooth = DSMC(st, CollisionRule.elastic(), packing_fraction=0.05)
    assert smooth.angular_velocities is None
    assert np.array_equal(smooth.state.angular_velocities, st.angular_velocities)  # carried as given
