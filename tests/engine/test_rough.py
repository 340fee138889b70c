"""Rough particles in the engine: the smooth limit bit for bit, the naive reference loop event by
event, exact restarts, energy accounting, the spin kicks, the TC model, and the input checks."""

import math

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation, TangentialRule, WhiteNoise
from granulargas.errors import ConfigError
from granulargas.initial import random_state
from tests.engine.reference import run_reference

RULES = {"constant": TangentialRule.constant(0.3, wall_restitution=-0.4),
         "coulomb": TangentialRule.coulomb(0.5, 0.2, wall_restitution=0.1, wall_friction=0.4)}


def rough_state(n=40, packing=0.2, dimension=3, seed=1, walls=(), mixed=False):
    """A random state with random spins and (``mixed``) sizes, masses and kappa."""
    rng = np.random.default_rng(seed + 100)
    radii = rng.uniform(0.35, 0.5, n) if mixed else 0.5
    masses = rng.uniform(0.5, 2.0, n) if mixed else None
    boundary = tuple("wall" if a in walls else "periodic" for a in range(dimension))
    st = random_state(n, packing, dimension, seed=seed, radii=radii, masses=masses, boundary=boundary)
    spins = rng.normal(size=(n, 3 if dimension == 3 else 1)) * 2.0
    kmax = 2.0 / 3.0 if dimension == 3 else 1.0
    kappa = rng.uniform(0.2, kmax, n) if mixed else np.full(n, 0.4 if dimension == 3 else 0.5)
    return st.replace(angular_velocities=spins, inertia=kappa)


def energy(sim):
    return sim.kinetic_energy + sim.rotational_energy


# ---------------------------------------------------------------- the smooth limit


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
@pytest.mark.parametrize("dimension, walls, driven", [(3, (), False), (2, (), False), (3, (2,), False),
                                                      (2, (0,), True)])
def test_smooth_limit_gives_the_smooth_trajectories_bit_for_bit(neighbours, dimension, walls, driven):
    """beta_t = -1 (pairs and walls): positions, velocities, counters and pressure of the smooth
    engine exactly; the spins never change."""
    st = rough_state(60, 0.2, dimension, seed=3, walls=walls, mixed=True)
    rule = CollisionRule.constant(0.85)
    drv = WhiteNoise(0.05, 0.1, seed=7) if driven else None
    smooth = Simulation(st, rule, neighbours=neighbours, driving=drv)
    rough = Simulation(st, rule, neighbours=neighbours, driving=drv, tangential=TangentialRule.constant(-1.0))
    for t in (3.0, 7.5):
        smooth.run(t)
        rough.run(t)
        assert np.array_equal(smooth.positions, rough.positions)
        assert np.array_equal(smooth.velocities, rough.velocities)
        assert np.array_equal(rough.angular_velocities, st.angular_velocities)
        assert (smooth.collisions, smooth.events, smooth.wall_collisions) == (
            rough.collisions, rough.events, rough.wall_collisions)
        assert smooth.dissipated_energy == rough.dissipated_energy
        assert smooth.injected_energy == rough.injected_energy
        assert smooth.pressure_window() == rough.pressure_window()
    assert smooth.collisions > 100


# ---------------------------------------------------------------- against the naive loop


@pytest.mark.parametrize("model", sorted(RULES))
@pytest.mark.parametrize("dimension, walls, mixed", [(3, (), True), (2, (), True), (3, (1,), False),
                                                     (2, (0,), True)])
def test_events_velocities_and_spins_match_the_reference(model, dimension, walls, mixed):
    """40 events of the engine against the reference loop with its rigid-body impulse: the same
    pairs and walls at the same times, then the same velocities and spins."""
    n = 24 if not walls else 40
    st = rough_state(n, 0.25 if not walls else 0.15, dimension, seed=5, walls=walls, mixed=mixed)
    tg = RULES[model]
    spin3 = np.zeros((n, 3))
    spin3[:, 3 - st.angular_velocities.shape[1]:] = st.angular_velocities
    rough = {"spin": spin3, "inertia": st.inertia, "beta": tg.restitution,
             "mu": tg.friction if model == "coulomb" else None, "wall_beta": tg.wall_beta,
             "wall_mu": tg.wall_mu if model == "coulomb" else None}
    k = 40
    events, _, vel, spin = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, k + 1,
                                         eps=0.8, walls=walls, wall_eps=0.8, rough=rough)
    _, _, vel_k, spin_k = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, k,
                                        eps=0.8, walls=walls, wall_eps=0.8, rough=rough)
    sim = Simulation(st, CollisionRule.constant(0.8), tangential=tg)
    sim.run(0.5 * (events[k - 1][0] + events[k][0]))  # between the k-th and the next event
    pairs = sum(1 for e in events[:k] if e[2] >= 0)
    assert (sim.collisions, sim.wall_collisions) == (pairs, k - pairs)
    np.testing.assert_allclose(sim.velocities, vel_k, rtol=1e-7, atol=1e-9)
    got = sim.angular_velocities
    np.testing.assert_allclose(got, spin_k[:, 3 - got.shape[1]:], rtol=1e-7, atol=1e-9)
    assert not np.allclose(got, st.angular_velocities)  # the spins did change


def test_each_pair_collision_matches_the_reference_time_and_partners():
    """Collision by collision (the engine stopped after each): partners and times."""
    from tests.engine.factories import next_engine_collision

    st = rough_state(30, 0.25, 3, seed=9, mixed=True)
    tg = RULES["coulomb"]
    rough = {"spin": st.angular_velocities, "inertia": st.inertia, "beta": tg.restitution, "mu": tg.friction}
    ref, _, _, _ = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, 40, eps=0.7,
                                 rough=rough)
    sim = Simulation(st, CollisionRule.constant(0.7), tangential=tg)
    for t, i, j in ref:
        te, a, b = next_engine_collision(sim)
        assert (a, b) == (i, j)
        assert te == pytest.approx(t, rel=1e-8)


# ---------------------------------------------------------------- state and energy


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
@pytest.mark.parametrize("model", sorted(RULES))
def test_restart_from_the_state_is_exact(neighbours, model):
    st = rough_state(80, 0.15, 3, seed=11, walls=(0,), mixed=True)
    drv = WhiteNoise(0.2, 0.05, seed=3, rotational_fraction=0.4)
    kw = dict(neighbours=neighbours, driving=drv, tangential=RULES[model])
    a = Simulation(st, CollisionRule.constant(0.9), **kw)
    a.run(2.0)
    b = Simulation(a.state, CollisionRule.constant(0.9), **kw)
    a.synchronise()
    a.run(5.0)
    b.run(5.0)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)
    assert np.array_equal(a.angular_velocities, b.angular_velocities)
    assert a.state.inertia is not None and np.array_equal(a.state.inertia, st.inertia)
    assert (a.collisions, a.events, a.dissipated_energy, a.injected_energy) == (
        b.collisions, b.events, b.dissipated_energy, b.injected_energy)


@pytest.mark.parametrize("dimension", [2, 3])
@pytest.mark.parametrize("model", sorted(RULES))
def test_energy_accounting_with_walls_and_driving(dimension, model):
    """Translational plus rotational energy: initial + injected - dissipated, to round-off."""
    st = rough_state(120, 0.15, dimension, seed=13, walls=(0,), mixed=True)
    sim = Simulation(st, CollisionRule.constant(0.8), tangential=RULES[model],
                     driving=WhiteNoise(0.3, 0.05, seed=1, rotational_fraction=0.5))
    e0 = energy(sim)
    sim.run(10.0)
    assert sim.wall_collisions > 0 and sim.collisions > 500
    assert energy(sim) == pytest.approx(e0 + sim.injected_energy - sim.dissipated_energy, rel=1e-10)
    # the kinetic part of the pressure follows the translational energy (the loop's running sum)
    assert sim.temperature > 0 and sim.rotational_temperature > 0


@pytest.mark.parametrize("dimension", [2, 3])
def test_one_spin_kick_is_the_counter_based_normals_scaled(dimension):
    """From spins at rest, one driving step gives each particle I_i |dw_i|^2 = s^2 |g_i|^2 with g the
    driving's normals under the spin key and s^2 = lambda H (d_t / d_r) dt: T_rot rises by
    lambda H (d_t / d_r) dt times the sample mean of |g|^2 / d_r, exactly."""
    from granulargas.engine._spin import SPIN_KEY
    from tests.engine.kernels import kick_normals

    n, lam, h, dt, seed = 300, 0.3, 0.05, 0.1, 5
    st = rough_state(n, 0.05, dimension, seed=17, mixed=True)
    st = st.replace(angular_velocities=np.zeros_like(st.angular_velocities))
    sim = Simulation(st, CollisionRule.elastic(), tangential=TangentialRule.constant(-1.0),
                     driving=WhiteNoise(h, dt, seed=seed, rotational_fraction=lam))
    sim.run(0.5 * dt)  # the first step, at dt / 2
    d_t, d_r = (3, 3) if dimension == 3 else (2, 1)
    g = np.array([kick_normals(np.uint64(seed) ^ SPIN_KEY, 0, i) for i in range(n)])[:, :d_r]
    moments = st.inertia * st.masses * st.radii**2
    w = sim.angular_velocities
    np.testing.assert_allclose(np.sqrt(moments)[:, None] * w, math.sqrt(lam * h * d_t / d_r * dt) * g, rtol=1e-12)


@pytest.mark.parametrize("dimension", [2, 3])
def test_spin_kicks_heat_the_rotation_at_lambda_h_dt_over_dr(dimension):
    """Elastic smooth particles decouple the spins: the driving alone raises T_rot at
    lambda H d_t / d_r and T_tr at (1 - lambda) H, on average over the kicks, and the injected
    energy is what the two temperatures gained."""
    n = 800
    st = rough_state(n, 0.05, dimension, seed=17)
    st = st.replace(angular_velocities=np.zeros_like(st.angular_velocities))
    lam, h, t_end = 0.3, 0.05, 40.0
    sim = Simulation(st, CollisionRule.elastic(), tangential=TangentialRule.constant(-1.0),
                     driving=WhiteNoise(h, 0.1, seed=5, rotational_fraction=lam))
    t0, r0 = sim.temperature, sim.rotational_temperature
    sim.run(t_end)
    d_t, d_r = (3, 3) if dimension == 3 else (2, 1)
    kicks = sim.kick_step
    rate_rot = (sim.rotational_temperature - r0) / (kicks * 0.1)
    rate_tr = (sim.temperature - t0) / (kicks * 0.1)
    # the increments random-walk through the cross terms 2 m v.dv: a few per cent here
    assert rate_rot == pytest.approx(lam * h * d_t / d_r, rel=0.1)
    assert rate_tr == pytest.approx((1 - lam) * h, rel=0.1)
    assert sim.injected_energy == pytest.approx(0.5 * n * (d_t * (sim.temperature - t0) + d_r * (
        sim.rotational_temperature - r0)), rel=1e-9)


def test_tc_model_collisions_are_elastic_and_frictionless():
    """Within tc_time of a previous collision a rough collision is elastic and smooth: with every
    particle's last collision at t = 0 and a long tc_time the run is the elastic smooth one."""
    st = rough_state(60, 0.2, 3, seed=19)
    st = st.replace(last_collision=np.zeros(60))
    rough = Simulation(st, CollisionRule.constant(0.5, tc_time=1e9), tangential=RULES["constant"])
    elastic = Simulation(st, CollisionRule.elastic())
    rough.run(5.0)
    elastic.run(5.0)
    assert rough.collisions > 100
    np.testing.assert_array_equal(rough.velocities, elastic.velocities)
    np.testing.assert_array_equal(rough.angular_velocities, st.angular_velocities)
    assert rough.dissipated_energy == 0.0


def test_2d_spins_are_one_column_and_default_values():
    st = random_state(30, 0.2, 2, seed=1)
    sim = Simulation(st, CollisionRule.constant(0.9), tangential=TangentialRule.constant(0.0))
    assert sim.angular_velocities.shape == (30, 1) and np.all(sim.angular_velocities == 0.0)
    assert np.all(sim.inertia == 0.5) and sim.rotational_temperature == 0.0
    sim.run(5.0)
    assert sim.rotational_temperature > 0.0  # the collisions spin the particles up
    smooth = Simulation(st, CollisionRule.constant(0.9))
    assert smooth.angular_velocities is None and math.isnan(smooth.rotational_temperature)
    assert smooth.state.angular_velocities is None


def test_input_checks():
    st = random_state(30, 0.2, 3, seed=1)
    tg = TangentialRule.constant(0.0)
    with pytest.raises(ConfigError, match="inertia"):
        Simulation(st.replace(inertia=np.full(30, 0.7)), CollisionRule.elastic(), tangential=tg)
    with pytest.raises(ConfigError, match="angular_velocities: non-finite"):
        Simulation(st.replace(angular_velocities=np.full((30, 3), np.nan)), CollisionRule.elastic(), tangential=tg)
    with pytest.raises(ConfigError, match="shape"):
        Simulation(st.replace(angular_velocities=np.zeros((30, 1))), CollisionRule.elastic(), tangential=tg)
    with pytest.raises(ConfigError, match="rotational_fraction"):
        Simulation(st, CollisionRule.elastic(), driving=WhiteNoise(0.1, 0.1, rotational_fraction=0.5))
    with pytest.raises(TypeError):
        Simulation(st, CollisionRule.elastic(), tangential=0.3)
