"""White-noise driving: the heating rate of one kick, momentum, the random stream, restart
equality, and the driven steady state against kinetic theory."""

import math

import numpy as np
import pytest

from granulargas import theory
from granulargas.engine import CollisionRule, Simulation, WhiteNoise
from granulargas.initial import random_state
from granulargas.errors import ConfigError

from tests.engine.factories import walled_state
from tests.engine.kernels import kick_normals


def test_one_kick_from_rest_heats_by_h_dt_equally_for_every_mass_and_keeps_momentum_zero():
    n, d, h, dt = 20000, 3, 2.0, 0.05
    st = random_state(n, 0.1, d, seed=4)
    masses = np.where(np.arange(n) % 2 == 0, 1.0, 3.0)
    sim = Simulation(st.replace(velocities=np.zeros((n, d)), masses=masses), CollisionRule.elastic(),
                     driving=WhiteNoise(h, dt, seed=9))
    assert sim.kick_step == 0
    sim.run(0.5 * dt)  # the step at t = dt / 2 (a step due at the end of a run is executed)
    assert sim.kick_step == 1 and sim.events == 1 and sim.collisions == 0
    v = sim.velocities
    # <m c^2>/d = H dt for the light and the heavy particles alike (2/(dN) relative spread)
    for sel in (masses == 1.0, masses == 3.0):
        t_sel = np.mean(masses[sel, None] * v[sel] ** 2) 
        assert t_sel == pytest.approx(h * dt, rel=5 * math.sqrt(2 / (d * n / 2)))
    assert sim.temperature == pytest.approx(h * dt, rel=5 * math.sqrt(2 / (d * n)))
    np.testing.assert_allclose(sim.momentum, 0.0, atol=1e-13 * math.sqrt(n))
    assert sim.injected_energy == pytest.approx(sim.kinetic_energy, rel=1e-12)


def test_kick_normals_are_standard_normal_and_independent():
    seed = np.uint64(12345)
    g = np.array([kick_normals(seed, k, i) for k in range(1, 60) for i in range(500)])
    assert g.shape == (59 * 500, 3)
    assert np.abs(g.mean(axis=0)).max() < 5 / math.sqrt(len(g))
    np.testing.assert_allclose(g.var(axis=0), 1.0, atol=5 * math.sqrt(2 / len(g)))
    c = np.corrcoef(g.T)
    assert np.abs(c - np.eye(3)).max() < 5 / math.sqrt(len(g))
    # fourth moment of a normal: 3
    np.testing.assert_allclose((g**4).mean(axis=0), 3.0, atol=5 * math.sqrt(96 / len(g)))
    # a pure function of (seed, step, id)
    assert kick_normals(seed, 7, 3) == kick_normals(seed, 7, 3) != kick_normals(seed, 7, 4)
    assert kick_normals(seed, 7, 3) != kick_normals(np.uint64(12346), 7, 3)


def test_driven_energy_balance_and_momentum():
    st = random_state(300, 0.2, 2, seed=3)
    sim = Simulation(st, CollisionRule.constant(0.8),
                     driving=WhiteNoise(0.5, 0.02, seed=1))
    e0 = sim.kinetic_energy
    p0 = sim.momentum
    sim.run(10.0)
    assert sim.kick_step == 500  # kicks at 0.01, 0.03, ..., 9.99
    assert sim.kinetic_energy == pytest.approx(e0 + sim.injected_energy - sim.dissipated_energy,
                                               rel=1e-10)
    assert sim.injected_energy > e0 and sim.dissipated_energy > e0
    np.testing.assert_allclose(sim.momentum, p0, atol=1e-12)


@pytest.mark.parametrize("walls", [False, True])
@pytest.mark.parametrize("d", [2, 3])
def test_restart_equality_with_driving_bit_for_bit(d, walls):
    """run(t); synchronise; run(2t) == restart from the state at t; run(2t): the kicks'
    random stream continues from the saved step index."""
    if walls:
        st = walled_state(200, 0.3, d, (d - 1,), seed=6)
    else:
        st = random_state(200, 0.3, d, seed=6)
    rule = CollisionRule.constant(0.7, wall_restitution=0.9)
    drive = WhiteNoise(0.3, 0.037, seed=5)
    a = Simulation(st, rule, driving=drive)
    a.run(3.0)
    a.synchronise()
    saved = a.state
    a.run(6.0)
    b = Simulation(saved, rule, driving=drive)
    b.run(6.0)
    assert a.kick_step == b.kick_step == 162 and a.collisions == b.collisions
    assert a.events == b.events and a.wall_collisions == b.wall_collisions
    for k in ("positions", "velocities", "images"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert a.injected_energy == b.injected_energy and a.dissipated_energy == b.dissipated_energy
    # another seed, another stream
    c = Simulation(saved, rule, driving=WhiteNoise(0.3, 0.037, seed=6))
    c.run(6.0)
    assert not np.array_equal(c.velocities, b.velocities)


def test_chunking_does_not_change_a_driven_run():
    st = random_state(150, 0.3, 3, seed=7)
    drive = WhiteNoise(0.2, 0.05, seed=2)
    a = Simulation(st, CollisionRule.constant(0.9), driving=drive)
    b = Simulation(st, CollisionRule.constant(0.9), driving=drive)
    for t in np.linspace(0.3, 4.0, 9):
        a.run(t)
        a.temperature, a.positions
    b.run(4.0)
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.velocities, b.velocities)


@pytest.mark.parametrize("kwargs, match", [
    (dict(heating_rate=-0.1, interval=0.1), "heating_rate = -0.1"),
    (dict(heating_rate=0.1, interval=0.0), "interval = 0.0"),
    (dict(heating_rate=float("nan"), interval=0.1), "heating_rate"),
    (dict(heating_rate=0.1, interval=0.1, seed=-1), "seed"),
])
def test_bad_driving_raises_config_error(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        WhiteNoise(**kwargs)


def test_kick_step_must_lie_ahead():
    st = random_state(50, 0.1, 3, seed=1)
    with pytest.raises(ConfigError, match="kick_step"):
        Simulation(st.replace(time=1.0, kick_step=1), CollisionRule.elastic(),
                   driving=WhiteNoise(0.1, 0.5))  # (1 + 1/2) 0.5 < 1


def _steady_state(d, eps, packing, n, h, measure, seed=1):
    """(mean T / T_theory, its error) over ``measure`` cooling times after 5 of relaxation.

    T is sampled at multiples of dt_k, half-way between kicks, where it equals its
    average over a kick interval to second order in zeta dt_k (right after a kick it
    is higher by H dt_k / 2)."""
    n_dens = theory.number_density(packing, d)
    t_th = float(theory.driven_temperature(h, eps, n_dens, d))
    zeta = float(theory.enskog_cooling_rate(eps, n_dens, t_th, d,
                                            a2=theory.driven_sonine_a2(eps, d)))
    dt_k = theory.driving_interval(zeta)
    st = random_state(n, packing, d, temperature=t_th, seed=seed)
    sim = Simulation(st, CollisionRule.constant(eps),
                     driving=WhiteNoise(h, dt_k, seed=seed))
    spacing = max(1, round(0.25 / zeta / dt_k))  # kicks between samples
    first = round(5.0 / zeta / dt_k)
    temps = []
    for k in range(int(4 * measure)):
        sim.run((first + k * spacing) * dt_k)
        temps.append(sim.temperature)
    blocks = np.array(temps[: len(temps) // 10 * 10]).reshape(10, -1).mean(axis=1)
    return blocks.mean() / t_th, blocks.std(ddof=1) / math.sqrt(10) / t_th


@pytest.mark.parametrize("d, eps, packing", [(3, 0.9, 0.05), (2, 0.9, 0.05)])
def test_driven_steady_temperature_matches_enskog_theory(d, eps, packing):
    """zeta(T_ss) T_ss = H with the Enskog cooling rate and the driven a2: within 2 %
    (the statistical error of 40 cooling times is ~0.5 %)."""
    ratio, err = _steady_state(d, eps, packing, 600, 0.1, measure=40)
    assert err < 0.008
    assert ratio == pytest.approx(1.0, abs=0.02)
