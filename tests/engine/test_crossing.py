"""The cell-crossing neighbour search: event sequence against the naive reference loop,
restart equality, invariants, walls and driving, Enskog's collision rate."""

import math

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation, WhiteNoise
from granulargas.engine.invariants import check
from granulargas.engine.simulation import neighbour_mode
from granulargas.errors import ConfigError
from granulargas.initial import random_state

from tests.engine.factories import hermite_table, make_sim, next_engine_collision, pade_eps, walled_state
from tests.engine.reference import next_collision, run_reference
from tests.engine.test_physics import enskog_frequency, z_theory
from tests.engine.test_walls import RULES as WALL_RULES, next_engine_event

CASES = [
    dict(n=40, packing=0.05, dimension=3, seed=1),
    dict(n=30, packing=0.3, dimension=3, seed=2),
    dict(n=40, packing=0.05, dimension=2, seed=3),
    dict(n=40, packing=0.5, dimension=2, seed=4),
]
VISCOELASTIC = CollisionRule.viscoelastic(0.4, hermite_table(pade_eps))


def cells(**kw):
    return make_sim(neighbours="cells", **kw)


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c['dimension']}D-{c['packing']}")
@pytest.mark.parametrize("rule", [CollisionRule.elastic(), CollisionRule.constant(0.8), VISCOELASTIC],
                         ids=["elastic", "constant", "viscoelastic"])
def test_next_event_matches_reference_every_step(case, rule):
    """From the engine's synchronised state, the reference predicts its next collision."""
    sim = cells(rule=rule, **case)
    assert sim.neighbours == "cells"
    for _ in range(300):
        dt, i, j = next_collision(sim.positions, sim.velocities, sim.radii, sim.box)
        t0 = sim.time
        t, a, b = next_engine_collision(sim)
        assert (a, b) == (min(i, j), max(i, j))
        assert t - t0 == pytest.approx(dt, rel=1e-9, abs=1e-12)
    c = sim._engine.counters[0]
    assert c["crossings"] > 50 and c["expiries"] == 0
    assert check(sim) == []


@pytest.mark.parametrize("dimension", [2, 3])
def test_polydisperse_next_event_matches_reference(dimension):
    n = 60
    radii = np.random.default_rng(7).uniform(0.3, 0.5, n)
    st = random_state(n, 0.1, dimension, seed=5, radii=radii)
    sim = Simulation(st, CollisionRule.constant(0.7), neighbours="cells")
    for _ in range(300):
        dt, i, j = next_collision(sim.positions, sim.velocities, sim.radii, sim.box)
        t0 = sim.time
        t, a, b = next_engine_collision(sim)
        assert (a, b) == (min(i, j), max(i, j))
        assert t - t0 == pytest.approx(dt, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c['dimension']}D-{c['packing']}")
def test_free_running_sequence_matches_reference(case):
    """Independent runs agree while chaos has not amplified round-off (first 40 collisions)."""
    sim = cells(**case)
    ref, _, vel = run_reference(sim.positions, sim.velocities, sim.radii, sim.masses, sim.box, 40)
    for t, i, j in ref:
        te, a, b = next_engine_collision(sim)
        assert (a, b) == (i, j)
        assert te == pytest.approx(t, rel=1e-8)
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("d, walls", [(3, (2,)), (2, (0, 1))])
def test_walls_sequence_matches_reference(d, walls):
    """Pair and wall events, first 60, against the reference loop with walls."""
    st = walled_state(60, 0.1, d, walls, seed=11)
    r = WALL_RULES["constant"]
    sim = Simulation(st, r, neighbours="cells")
    ref, _, vel = run_reference(sim.positions, sim.velocities, sim.radii, sim.masses, sim.box, 60,
                                eps=r.restitution, walls=walls, wall_eps=r.wall_restitution)
    assert sum(j < 0 for _, _, j in ref) >= 3
    for t, i, j in ref:
        _, te, a, b = next_engine_event(sim)
        assert (a, b) == (i, j)
        assert te == pytest.approx(t, rel=1e-8)
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-6, atol=1e-8)
    assert check(sim) == []


@pytest.mark.parametrize("rule", [CollisionRule.elastic(), CollisionRule.constant(0.8, tc_time=1e-3),
                                  VISCOELASTIC], ids=["elastic", "constant-tc", "viscoelastic"])
@pytest.mark.parametrize("d", [2, 3])
def test_restart_equality_bit_for_bit(rule, d):
    """run(t); synchronise; run(2t)  ==  restart from the state at t; run(2t)."""
    a = cells(n=200, packing=0.08, dimension=d, seed=5, rule=rule)
    a.run(5.0)
    a.synchronise()
    saved = a.state
    a.run(10.0)
    b = Simulation(saved, rule, neighbours="cells")
    b.run(10.0)
    assert a.collisions == b.collisions > saved.collisions + 100
    assert a.events == b.events
    for k in ("positions", "velocities", "images", "last_collision"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert a.dissipated_energy == b.dissipated_energy


@pytest.mark.parametrize("d", [2, 3])
def test_driven_restart_equality_and_energy_balance(d):
    """Driving with cell crossings: injected - dissipated = change of kinetic energy; momentum
    kept; a restart continues bit for bit."""
    st = random_state(200, 0.08, d, seed=6)
    rule = CollisionRule.constant(0.7)
    drive = WhiteNoise(0.3, 0.037, seed=5)
    a = Simulation(st, rule, driving=drive, neighbours="cells")
    e0, p0 = a.kinetic_energy, a.momentum
    a.run(3.0)
    a.synchronise()
    saved = a.state
    a.run(6.0)
    assert a.kinetic_energy == pytest.approx(e0 + a.injected_energy - a.dissipated_energy, rel=1e-10)
    np.testing.assert_allclose(a.momentum, p0, atol=1e-12)
    b = Simulation(saved, rule, driving=drive, neighbours="cells")
    b.run(6.0)
    assert a.collisions == b.collisions and a.events == b.events
    np.testing.assert_array_equal(a.velocities, b.velocities)
    np.testing.assert_array_equal(a.positions, b.positions)
    assert check(a) == []


@pytest.mark.parametrize("d, rule", [(3, "elastic"), (2, "elastic"), (3, "viscoelastic"), (2, "constant")])
def test_invariants_momentum_energy_no_overlap(d, rule):
    """Long dilute runs: momentum kept, kinetic + dissipated energy kept, every particle in its
    cell, no overlaps."""
    r = {"elastic": CollisionRule.elastic(), "constant": CollisionRule.constant(0.9),
         "viscoelastic": VISCOELASTIC}[rule]
    sim = cells(n=400, packing=0.05, dimension=d, seed=8, rule=r)
    e0, p0 = sim.kinetic_energy, sim.momentum
    for _ in range(4):
        sim.run(np.inf, max_collisions=10_000)
        assert check(sim) == []
    assert sim.kinetic_energy + sim.dissipated_energy == pytest.approx(e0, rel=1e-12)
    if rule == "elastic":
        assert sim.dissipated_energy == 0.0
    np.testing.assert_allclose(sim.momentum, p0, atol=1e-12 * math.sqrt(sim.n))


@pytest.mark.parametrize("d", [2, 3])
def test_collision_frequency_and_pressure_vs_enskog_at_packing_005(d):
    """omega against Enskog and Z against Carnahan-Starling / Henderson at packing 0.05 (2 %);
    cell crossings per collision against free streaming between Enskog collisions (3 %).

    A particle crosses the faces normal to axis a at the rate <|v_a|>/w_a, with
    <|v_a|> = sqrt(2T/(pi m)) for a Maxwell distribution; N omega / 2 collisions happen in
    the same time, so a collision costs 2 sum_a <|v_a|>/w_a / omega crossings (in 3D at
    equal widths 3 lambda / w, lambda the Enskog mean free path)."""
    sim = cells(n=1000, packing=0.05, dimension=d, seed=21)
    sim.run(5.0)
    sim.pressure_window()
    c0 = sim._engine.counters[0].copy()
    sim.run(60.0)
    c1 = sim._engine.counters[0]
    z = sim.pressure_window() * np.prod(sim.box) / (sim.n * sim.temperature)
    assert z == pytest.approx(z_theory(0.05, d), rel=0.02)
    omega = enskog_frequency(0.05, d, sim.temperature)
    assert sim.collision_rate == pytest.approx(omega, rel=0.02)
    widths = np.asarray(sim.box, dtype=float) / np.asarray(sim._space.ncell[:d], dtype=float)
    mean_abs = math.sqrt(2.0 * sim.temperature / math.pi)
    per_collision = (c1["crossings"] - c0["crossings"]) / float(c1["collisions"] - c0["collisions"])
    assert per_collision == pytest.approx(2.0 * np.sum(mean_abs / widths) / omega, rel=0.03)


def test_the_modes_agree_until_round_off_separates_them():
    """Lists and cells process different events but the same collisions: the first 200
    collisions agree."""
    a = make_sim(n=300, packing=0.1, dimension=3, seed=9, neighbours="lists")
    b = make_sim(n=300, packing=0.1, dimension=3, seed=9, neighbours="cells")
    for _ in range(200):
        ta, ia, ja = next_engine_collision(a)
        tb, ib, jb = next_engine_collision(b)
        assert (ia, ja) == (ib, jb)
        assert ta == pytest.approx(tb, rel=1e-10)


def test_cells_refuse_collisions_that_take_time_and_unknown_modes():
    from granulargas.contact import oblique_table, restitution_table

    with pytest.raises(ConfigError, match="neighbours"):
        make_sim(neighbours="grid")
    rule = CollisionRule.viscoelastic(0.1, restitution_table(1.0), duration="resolved", compression=1e-3,
                                      oblique=oblique_table(0.39, 0.125))
    with pytest.raises(ConfigError, match='neighbours = "cells"'):
        make_sim(rule=rule, neighbours="cells")


def test_auto_mode_follows_the_measured_crossover():
    from granulargas.engine.simulation import CELLS_BELOW

    for d in (2, 3):
        below = CELLS_BELOW[d]
        assert neighbour_mode("auto", below * 1.01 + 1e-9, d) == "lists"
        if below > 0:
            assert neighbour_mode("auto", below * 0.99, d) == "cells"
    assert neighbour_mode("cells", 0.5, 3) == "cells" and neighbour_mode("lists", 0.01, 3) == "lists"


def test_cells_are_at_least_one_diameter_and_capped_per_particle():
    from granulargas.engine.simulation import CELLS_PER_PARTICLE

    sim = cells(n=200, packing=0.01, dimension=3, seed=1)
    ncell = sim._space.ncell
    assert np.prod(ncell) <= CELLS_PER_PARTICLE * sim.n
    assert np.all(sim.box / ncell >= 1.0)
    assert check(sim) == []
