"""Gravity and wall kinds end to end: the exact checks that need no theory.

* In a periodic box gravity changes no pair collision: the sequence of a run with gravity
  is that of the same state without it, positions shifted by g t^2 / 2, event by event,
  and both agree with the naive reference loop with parabolic flights.
* Walls of every kind under gravity against the reference loop, event by event.
* Energy bookkeeping: kinetic + potential + dissipated - wall work is conserved.
* A run continued from its state is the uninterrupted run, bit for bit.
"""

import math

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation, TangentialRule, Wall, Walls, WhiteNoise
from granulargas.errors import ConfigError
from granulargas.engine.invariants import check
from granulargas.initial import random_state
from tests.engine.factories import hermite_table, pade_eps
from tests.engine.reference import run_scene

RULES = {
    "elastic": CollisionRule.elastic(),
    "constant": CollisionRule.constant(0.8),
    "viscoelastic": CollisionRule.viscoelastic(0.4, hermite_table(pade_eps)),
}
G3 = np.array([0.3, -0.7, 0.5])


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
@pytest.mark.parametrize("rule", list(RULES))
@pytest.mark.parametrize("d", [2, 3])
def test_gravity_leaves_the_pair_collisions_of_a_periodic_box_unchanged(d, rule, neighbours):
    st = random_state(40, 0.25 if d == 3 else 0.4, d, seed=7 + d)
    g = G3[:d]
    plain = Simulation(st, RULES[rule], neighbours=neighbours, remove_drift=False)
    fall = Simulation(st, RULES[rule], neighbours=neighbours, remove_drift=False, gravity=g)
    t_prev = 0.0
    for k in range(60):
        v0a, v0b = plain.velocities, fall.velocities
        plain.run(np.inf, max_collisions=1)
        fall.run(np.inf, max_collisions=1)
        t = fall.time
        assert t == pytest.approx(plain.time, rel=1e-10, abs=1e-12), k
        # the same pair changed course; the velocities differ by g t
        ca = np.flatnonzero(np.any(plain.velocities != v0a, axis=1)).tolist()
        cb = np.flatnonzero(np.any(np.abs(fall.velocities - v0b - g * (t - t_prev)) > 1e-9, axis=1)).tolist()
        assert ca == cb and len(ca) == 2, k
        np.testing.assert_allclose(fall.velocities, plain.velocities + g * t, rtol=0, atol=1e-8)
        # the positions are shifted by g t^2 / 2 (unwrapped)
        np.testing.assert_allclose(fall.unwrapped_positions, plain.unwrapped_positions + 0.5 * g * t * t,
                                   rtol=0, atol=1e-8)
        t_prev = t
    assert check(fall) == []


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
def test_gravity_leaves_a_driven_periodic_box_unchanged(neighbours):
    """White-noise kicks add the same velocities with and without gravity (they depend on the
    step and the particle only), so the driven runs differ by g t and g t^2 / 2 too."""
    st = random_state(40, 0.2, 3, seed=5)
    drive = WhiteNoise(0.5, 0.05, seed=3)
    plain = Simulation(st, RULES["constant"], neighbours=neighbours, remove_drift=False, driving=drive)
    fall = Simulation(st, RULES["constant"], neighbours=neighbours, remove_drift=False, driving=drive, gravity=G3)
    plain.run(3.0)
    fall.run(3.0)
    assert fall.collisions == plain.collisions > 50 and fall.injected_energy == pytest.approx(
        plain.injected_energy, rel=1e-9)
    t = fall.time
    np.testing.assert_allclose(fall.velocities, plain.velocities + G3 * t, rtol=0, atol=1e-8)
    np.testing.assert_allclose(fall.unwrapped_positions, plain.unwrapped_positions + 0.5 * G3 * t * t,
                               rtol=0, atol=1e-7)


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
def test_free_fall_in_a_periodic_box_against_the_reference(neighbours):
    st = random_state(40, 0.3, 3, seed=2)
    sim = Simulation(st, CollisionRule.constant(0.7), neighbours=neighbours, remove_drift=False, gravity=G3)
    ref, pos, vel, _ = run_scene(st.positions, st.velocities, st.radii, st.masses, st.box, 50, gravity=G3,
                                 eps=0.7)
    t_prev = 0.0
    for t, i, j in ref:
        v0 = sim.velocities
        sim.run(np.inf, max_collisions=1)
        assert sim.time == pytest.approx(t, rel=1e-9)
        changed = np.flatnonzero(np.any(np.abs(sim.velocities - v0 - G3 * (sim.time - t_prev)) > 1e-9,
                                        axis=1)).tolist()
        assert changed == [i, j]
        t_prev = sim.time
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-7, atol=1e-8)


SCENES = {  # (d, walls, gravity)
    "floor-lid": (2, Walls(), [0.0, -1.0]),
    "thermal-floor": (3, Walls(z_low=Wall.thermal(1.5), seed=4), [0.0, 0.0, -1.0]),
    "sine-floor": (2, Walls(y_low=Wall.vibrating(0.15, 1.2, "sine", phase=0.3)), [0.0, -1.0]),
    "triangle-floor": (3, Walls(z_low=Wall.vibrating(0.2, 0.8, "triangle")), [0.0, 0.0, -1.5]),
    "biparabolic-floor-thermal-lid": (2, Walls(y_low=Wall.vibrating(0.1, 1.5, "biparabolic", phase=1.0),
                                               y_high=Wall.thermal(0.5), seed=9), [0.0, -0.8]),
    "shaken-cell": (3, Walls(z_low=Wall.vibrating(0.2, 0.7), z_high=Wall.vibrating(0.2, 0.7)), None),
}


def _kinds(walls, d):
    out = {}
    for a, side, w in walls.given():
        out[(a, side)] = {"kind": w.kind, "amplitude": w.amplitude, "frequency": w.frequency,
                          "waveform": w.waveform, "phase": w.phase, "temperature": w.temperature}
    return out


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
@pytest.mark.parametrize("scene", list(SCENES))
def test_walls_under_gravity_against_the_reference(scene, neighbours):
    """The engine's event sequence (pairs and walls of every kind) against the reference loop,
    event by event: the engine is run to half-way between the reference's events and must
    have done exactly that event; velocities at the end."""
    d, walls, g = SCENES[scene]
    axis = d - 1
    margins = np.zeros((d, 2))
    margins[axis] = [walls.side(axis, 0).reach, walls.side(axis, 1).reach]
    st = random_state(30, 0.12, d, seed=3, boundary=("periodic",) * (d - 1) + ("wall",), margins=margins)
    rule = CollisionRule.constant(0.85, wall_restitution=0.9)
    sim = Simulation(st, rule, neighbours=neighbours, gravity=g, walls=walls)
    ref, _, vel, work = run_scene(st.positions, st.velocities, st.radii, st.masses, st.box, 80, walls=(axis,),
                                  gravity=g, kinds=_kinds(walls, d), eps=0.85, wall_eps=0.9, seed=walls.seed)
    assert sum(j < 0 for _, _, j in ref) >= 8
    times = [t for t, _, _ in ref]
    for k, (t, i, j) in enumerate(ref):
        nxt = times[k + 1] if k + 1 < len(times) else t + 1e-6
        v0 = sim.velocities
        t0 = sim.time
        sim.run(0.5 * (t + nxt))
        assert sim.collisions + sim.wall_collisions == k + 1, (k, t)
        drift = 0.0 if g is None else np.asarray(g) * (sim.time - t0)
        changed = np.flatnonzero(np.any(np.abs(sim.velocities - v0 - drift) > 1e-9, axis=1)).tolist()
        assert changed == ([i, j] if j >= 0 else [i]), (k, t, changed)
    gv = 0.0 if g is None else np.asarray(g) * (sim.time - times[-1])
    np.testing.assert_allclose(sim.velocities, vel + gv, rtol=1e-6, atol=1e-8)
    assert sim.wall_work == pytest.approx(work, rel=1e-6, abs=1e-9)
    assert check(sim) == []


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
def test_energy_bookkeeping_is_exact(neighbours):
    """Kinetic + potential + dissipated - wall work stays constant to round-off with a thermal
    lid, a vibrating floor, gravity and inelastic collisions."""
    walls = Walls(y_low=Wall.vibrating(0.1, 2.0, "sine"), y_high=Wall.thermal(1.0), seed=3)
    st = random_state(60, 0.1, 2, seed=1, boundary=("periodic", "wall"), margins=[[0, 0], [0.2, 0]])
    sim = Simulation(st, CollisionRule.constant(0.9, wall_restitution=0.95, elastic_below=1e-3),
                     gravity=[0.0, -1.0], walls=walls, neighbours=neighbours)

    def total(s):
        return s.kinetic_energy + s.potential_energy + s.dissipated_energy - s.wall_work

    e0 = total(sim)
    for _ in range(5):
        sim.run(sim.time + 10.0)
        assert total(sim) == pytest.approx(e0, abs=1e-9 * (abs(e0) + sim.dissipated_energy + abs(sim.wall_work)))
    assert sim.wall_collisions > 100 and sim.dissipated_energy > 0 and sim.wall_work != 0


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
def test_a_continued_run_is_the_uninterrupted_one(neighbours):
    walls = Walls(z_low=Wall.vibrating(0.1, 1.0, "triangle"), z_high=Wall.thermal(2.0), seed=5)
    st = random_state(50, 0.08, 3, seed=6, boundary=("periodic", "periodic", "wall"),
                      margins=[[0, 0], [0, 0], [0.2, 0]])
    rule = CollisionRule.constant(0.8, elastic_below=1e-3)
    kw = dict(neighbours=neighbours, gravity=[0.0, 0.0, -1.0], walls=walls)
    whole = Simulation(st, rule, **kw).run(10.0).synchronise().run(20.0)  # as a run that writes a frame at 10
    half = Simulation(st, rule, **kw).run(10.0)
    rest = Simulation(half.state, rule, **kw).run(20.0)
    for a, b in ((whole.state.positions, rest.state.positions), (whole.state.velocities, rest.state.velocities)):
        assert np.array_equal(a, b)
    assert (whole.collisions, whole.wall_collisions, whole.wall_work, whole.dissipated_energy) == (
        rest.collisions, rest.wall_collisions, rest.wall_work, rest.dissipated_energy)


def test_bad_scenes_are_refused():
    st = random_state(30, 0.1, 2, seed=1, boundary=("periodic", "wall"))
    rule = CollisionRule.elastic()
    from granulargas.errors import ConfigError

    with pytest.raises(ConfigError, match="gravity"):
        Simulation(st, rule, gravity=[0.0, -1.0, 0.0])
    with pytest.raises(ConfigError, match="needs a \"wall\" axis"):
        Simulation(st, rule, walls=Walls(x_low=Wall.thermal(1.0)))
    with pytest.raises(ConfigError, match="no room for a particle"):
        Simulation(st, rule, walls=Walls(y_low=Wall.vibrating(st.box[1] / 4, 1.0), y_high=Wall.vibrating(st.box[1] / 4, 1.0)))
    with pytest.raises(ConfigError, match="overlaps a wall"):
        Simulation(st, rule, walls=Walls(y_low=Wall.vibrating(2.0, 1.0, phase=math.pi / 2)))


EPS_PAIRS = np.array([[0.9, 0.7], [0.7, 0.8]])
WALL_EPS = [0.6, 0.95]


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
@pytest.mark.parametrize("scene", ["sine-floor", "biparabolic-floor-thermal-lid", "triangle-floor"])
def test_a_mixture_under_gravity_against_the_reference(scene, neighbours):
    """A mixture of two species (masses 1 and 3, a restitution per pair and per species at the
    walls) under gravity on a moving floor: the engine against the reference loop, event by event."""
    d, walls, g = SCENES[scene]
    axis = d - 1
    margins = np.zeros((d, 2))
    margins[axis] = [walls.side(axis, 0).reach, walls.side(axis, 1).reach]
    st = random_state(30, 0.12, d, seed=5, boundary=("periodic",) * (d - 1) + ("wall",), margins=margins)
    of = np.arange(30, dtype=np.int32) % 2
    st = st.replace(masses=np.array([1.0, 3.0])[of], species=of)
    sim = Simulation(st, CollisionRule.constant(EPS_PAIRS, wall_restitution=WALL_EPS), neighbours=neighbours,
                     gravity=g, walls=walls)
    ref, _, vel, work = run_scene(st.positions, st.velocities, st.radii, st.masses, st.box, 80, walls=(axis,),
                                  gravity=g, kinds=_kinds(walls, d), eps=EPS_PAIRS, wall_eps=WALL_EPS,
                                  seed=walls.seed, species=of)
    assert sum(j < 0 for _, _, j in ref) >= 8
    times = [t for t, _, _ in ref]
    for k, (t, i, j) in enumerate(ref):
        nxt = times[k + 1] if k + 1 < len(times) else t + 1e-6
        sim.run(0.5 * (t + nxt))
        assert sim.collisions + sim.wall_collisions == k + 1, (k, t)
    gv = np.asarray(g) * (sim.time - times[-1])
    np.testing.assert_allclose(sim.velocities, vel + gv, rtol=1e-6, atol=1e-7)
    assert sim.wall_work == pytest.approx(work, rel=1e-6, abs=1e-9)
    assert np.triu(sim.species_collisions).sum() == sim.collisions  # symmetric: each pair once


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
@pytest.mark.parametrize("d", [2, 3])
def test_gravity_leaves_rough_collisions_unchanged(d, neighbours):
    """Rough particles (Walton's Coulomb model): gravity moves every centre alike and turns no
    spin, so the collisions are those of the run without it, velocities shifted by g t,
    positions by g t^2 / 2, spins the same."""
    st = random_state(40, 0.2, d, seed=4 + d)
    tangential = TangentialRule.coulomb(0.4, 0.3)
    g = G3[:d]
    plain = Simulation(st, RULES["constant"], neighbours=neighbours, remove_drift=False, tangential=tangential)
    fall = Simulation(st, RULES["constant"], neighbours=neighbours, remove_drift=False, tangential=tangential,
                      gravity=g)
    for k in range(60):
        plain.run(np.inf, max_collisions=1)
        fall.run(np.inf, max_collisions=1)
        t = fall.time
        assert t == pytest.approx(plain.time, rel=1e-10, abs=1e-12), k
        np.testing.assert_allclose(fall.velocities, plain.velocities + g * t, rtol=0, atol=1e-8)
        np.testing.assert_allclose(fall.angular_velocities, plain.angular_velocities, rtol=0, atol=1e-8)
        np.testing.assert_allclose(fall.unwrapped_positions, plain.unwrapped_positions + 0.5 * g * t * t,
                                   rtol=0, atol=1e-8)
    assert fall.dissipated_energy == pytest.approx(plain.dissipated_energy, rel=1e-9)


def test_rough_particles_take_no_moving_walls():
    st = random_state(30, 0.1, 2, seed=1, boundary=("periodic", "wall"), margins=[[0, 0], [0.2, 0]])
    with pytest.raises(ConfigError, match="hard walls at rest"):
        Simulation(st, CollisionRule.constant(0.9), walls=Walls(y_low=Wall.vibrating(0.1, 1.0)),
                   tangential=TangentialRule.constant(0.5))
