"""A single ball on a vibrating floor: the engine's bounces against the exact impact map and the
period-n orbits of the bouncing ball (Holmes 1982; Luck & Mehta 1993); Zeno traps and their
remedies.

The ball shares a 2D box with a second ball that stays out of its way (no horizontal motion;
its own bounces are told apart by the first ball's velocity);
each bounce is measured from the engine's public state only: after the wall-collision count
rises, the impact time is the root of the ball's flight traced back to the plate (brentq),
and the take-off velocity that flight's velocity there.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from granulargas.engine import CollisionRule, Simulation, Wall, Walls
from granulargas.errors import InelasticCollapseError
from granulargas.state import State
from granulargas.theory import vibrated as V

G = 1.0
OMEGA = 2 * math.pi  # frequency 1


def _ball(z, vz, t0, amp, e, phase=0.0, waveform="sine", box=(8.0, 40.0), **kw):
    """The ball at height z (centre) moving at vz, the spectator at rest on the other side."""
    pos = np.array([[2.0, z], [6.0, box[1] - 1.0]])
    vel = np.array([[0.0, vz], [0.0, 0.0]])
    st = State(pos, vel, 0.5, 1.0, np.array(box), boundary=("periodic", "wall"), time=t0)
    walls = Walls(y_low=Wall.vibrating(amp, OMEGA / (2 * math.pi), waveform, phase))
    return Simulation(st, CollisionRule.constant(e, **kw), gravity=[0.0, -G], walls=walls)


def _bounces(sim, count, amp, phase=0.0, dt=0.01):
    """(impact time, take-off velocity) of the ball's next ``count`` bounces (module doc)."""
    out = []
    plate = sim.walls.side(1, 0)
    while len(out) < count:
        w0, t0, v0 = sim.wall_collisions, sim.time, sim.velocities[0, 1]
        sim.run(sim.time + dt)
        z, v, t = sim.positions[0, 1], sim.velocities[0, 1], sim.time
        if sim.wall_collisions == w0 or abs(v - (v0 - G * (t - t0))) < 1e-12:
            continue  # no bounce, or the spectator's

        def gap(tc):  # the flight traced back to tc, less the plate there
            s = t - tc
            return z - v * s - 0.5 * G * s * s - 0.5 - float(plate.position(40.0, 0, tc))

        # the last upward crossing of the plate (the impact; one right at t0 or t too)
        grid = np.linspace(t0 - 0.5 * dt, t + 0.5 * dt, 4001)
        up = np.flatnonzero((np.array([gap(x) for x in grid[:-1]]) < 0) & (np.array([gap(x) for x in grid[1:]]) >= 0))
        tc = brentq(gap, grid[up[-1]], grid[up[-1] + 1], xtol=1e-14, rtol=1e-15)
        out.append((tc, v + G * (t - tc)))
    return out


@pytest.mark.parametrize("n", [1, 2])
def test_period_n_orbit(n):
    """Started on the period-n orbit (take-off at pi n g / omega at the orbit's phase), the ball
    comes back every n periods at the same phase with the same take-off speed."""
    e = 0.6
    gamma = 1.1 * V.bouncing_ball_threshold(n, e)  # within the orbit's range of stability
    amp = gamma * G / OMEGA**2
    orbit = V.period_orbit(n, e, amp, OMEGA, G)
    phase = orbit["phases"][0]
    t0 = phase / OMEGA
    z0 = amp + amp * math.sin(phase) + 0.5
    sim = _ball(z0 + 1e-12, orbit["takeoff"], t0, amp, e)
    for k, (tc, v) in enumerate(_bounces(sim, 6, amp), start=1):
        assert tc - t0 == pytest.approx(k * n, abs=1e-7)
        assert v == pytest.approx(orbit["takeoff"], rel=1e-7)


def test_no_period_one_orbit_below_the_threshold():
    """Below Gamma_1 = pi (1 - e)/(1 + e) the plate cannot return the ball's take-off speed: the
    same start decays to rest on the plate instead of repeating."""
    e = 0.6
    amp = 0.9 * V.bouncing_ball_threshold(1, e) * G / OMEGA**2
    assert not V.period_orbit(1, e, amp, OMEGA, G)["exists"]
    up = math.pi * G / OMEGA
    sim = _ball(amp + 0.5 + 1e-9, up, 0.0, amp, e, elastic_below=1e-4)
    speeds = [v for _, v in _bounces(sim, 8, amp)]
    assert speeds[-1] < 0.5 * up


@pytest.mark.parametrize("waveform, e, gamma", [("sine", 0.5, 3.0), ("sine", 0.8, 1.5)])
def test_bounces_follow_the_exact_impact_map(waveform, e, gamma):
    """Any start, a chaotic regime included: each measured bounce is the exact map (theory,
    brentq on a fine bracket) applied to the measured bounce before it."""
    amp = gamma * G / OMEGA**2
    sim = _ball(amp + 0.5 + 0.3, 0.2, 0.37, amp, e)
    bounces = _bounces(sim, 15, amp)
    for (t0, v0), (t1, v1) in zip(bounces[:-1], bounces[1:]):
        tm, vm = V.bounce_map(t0, v0, amp, OMEGA, G, e)
        assert t1 == pytest.approx(tm, abs=1e-9)
        assert v1 == pytest.approx(vm, rel=1e-7, abs=1e-9)


def _dropped(rule_kw, t_end=10.0):
    pos = np.array([[2.0, 2.0], [6.0, 7.0]])
    vel = np.array([[0.0, 0.0], [0.0, 0.0]])
    st = State(pos, vel, 0.5, 1.0, np.array([8.0, 8.0]), boundary=("periodic", "wall"))
    sim = Simulation(st, CollisionRule.constant(0.5, **rule_kw), gravity=[0.0, -1.0])
    return sim.run(t_end)


def test_a_grain_coming_to_rest_is_a_zeno_trap_that_names_its_remedy():
    with pytest.raises(InelasticCollapseError, match="elastic_below") as err:
        _dropped({})
    assert "\n" not in str(err.value) and "tc_time" in str(err.value)


@pytest.mark.parametrize("rule_kw", [{"elastic_below": 1e-3}, {"tc_time": 1e-3}])
def test_the_remedies_keep_the_grain_bouncing(rule_kw):
    sim = _dropped(rule_kw, t_end=50.0)
    assert sim.time == 50.0
    # both grains bounce on at a small speed: their energy stays above what the floor allows
    v = sim.velocities[:, 1]
    heights = sim.positions[:, 1] - 0.5
    energy = 0.5 * v * v + heights
    floor = rule_kw.get("elastic_below", 0.0)
    assert np.all(energy >= 0.5 * (0.5 * floor) ** 2 * 0.99)
    assert np.all(heights < 0.01)
