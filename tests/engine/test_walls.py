"""Flat hard walls: event sequence against the naive reference, single bounces against the
contact ODE, invariants, conservation, restart equality, bad input."""

import math

import numpy as np
import pytest

from granulargas.contact import restitution, restitution_table
from granulargas.engine import CollisionRule, Simulation
from granulargas.engine.invariants import check
from granulargas.errors import ConfigError
from granulargas.state import State

from tests.engine.factories import hermite_table, pade_eps, walled_state
from tests.engine.reference import next_event, restitution as ref_eps, run_reference

RULES = {
    "elastic": CollisionRule.elastic(),
    "constant": CollisionRule.constant(0.8, wall_restitution=0.6),
    "viscoelastic": CollisionRule.viscoelastic(0.4, hermite_table(pade_eps)),
}
CASES = [  # (dimension, wall axes, packing, N)
    (3, (2,), 0.25, 40),
    (3, (0, 1, 2), 0.15, 60),
    (2, (1,), 0.45, 40),
    (2, (0, 1), 0.4, 50),
]


def next_engine_event(sim):
    """Advance the engine to its next velocity-changing event, guided by the reference.

    Checks that the engine did what the reference predicts from the engine's state:
    same kind, same particles, same time (rel 1e-9). Returns (kind, time, i, j) with
    i < j for a pair, j = -1 - axis for a wall.
    """
    d = sim.dimension
    walls = tuple(a for a in range(d) if sim.boundary[a] == "wall")
    pos, vel = sim.positions, sim.velocities
    kind, dt, i, j = next_event(pos, vel, sim.radii, sim.box, walls)
    t0, c0, w0 = sim.time, sim.collisions, sim.wall_collisions
    if kind == "pair":
        sim.run(np.inf, max_collisions=1)
        assert sim.wall_collisions == w0, "a wall collision came before the predicted pair"
        changed = np.flatnonzero(np.any(sim.velocities != vel, axis=1))
        assert sorted(changed.tolist()) == sorted([i, j])
        assert sim.time - t0 == pytest.approx(dt, rel=1e-9, abs=1e-12)
        return kind, sim.time, min(i, j), max(i, j)
    sim.run(t0 + dt * (1 + 1e-9) + 1e-13)
    assert (sim.collisions, sim.wall_collisions) == (c0, w0 + 1)
    changed = np.flatnonzero(np.any(sim.velocities != vel, axis=1))
    assert changed.tolist() == [i]
    v_after = sim.velocities[i, j]
    assert np.sign(v_after) == -np.sign(vel[i, j])
    # the contact time from where the sphere is now: x = R + |v'| (t - t_c) at the wall
    r = sim.radii[i]
    x = sim.positions[i, j]
    gap = x - r if vel[i, j] < 0 else sim.box[j] - r - x
    t_contact = sim.time - gap / abs(v_after)
    assert t_contact - t0 == pytest.approx(dt, rel=1e-9, abs=1e-10)
    # the bounce by the rule, sphere-plane contact R_eff = R_i, m_eff = m_i
    eps = ref_eps(sim.rule, abs(vel[i, j]), r, sim.masses[i])
    if sim.rule.kind == "constant":
        eps = sim.rule.wall_restitution
    assert v_after == pytest.approx(-eps * vel[i, j], rel=1e-12)
    return kind, t_contact, i, -1 - j


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}D-walls{''.join(map(str, c[1]))}")
@pytest.mark.parametrize("rule", list(RULES), ids=list(RULES))
def test_next_event_with_walls_matches_reference_every_step(case, rule):
    d, walls, packing, n = case
    st = walled_state(n, packing, d, walls, seed=d + len(walls))
    sim = Simulation(st, RULES[rule])
    kinds = [next_engine_event(sim)[0] for _ in range(200)]
    assert kinds.count("wall") > 10 and kinds.count("pair") > 50
    assert check(sim) == []


@pytest.mark.parametrize("d, walls", [(3, (2,)), (2, (0, 1))])
@pytest.mark.parametrize("rule", ["elastic", "constant"])
def test_free_running_sequence_with_walls_matches_reference(d, walls, rule):
    """Independent runs agree while chaos has not amplified round-off (first 60 events)."""
    st = walled_state(60, 0.3, d, walls, seed=11)
    r = RULES[rule]
    sim = Simulation(st, r)
    eps = 1.0 if rule == "elastic" else r.restitution
    wall_eps = 1.0 if rule == "elastic" else r.wall_restitution
    ref, _, vel = run_reference(sim.positions, sim.velocities, sim.radii, sim.masses, sim.box, 60,
                                eps=eps, walls=walls, wall_eps=wall_eps)
    assert sum(j < 0 for _, _, j in ref) >= 3
    for t, i, j in ref:
        _, te, a, b = next_engine_event(sim)
        assert (a, b) == (i, j)
        assert te == pytest.approx(t, rel=1e-8)
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("end", ["overlap", "force"])
@pytest.mark.parametrize("d", [2, 3])
def test_single_sphere_bounce_follows_the_restitution_of_the_sphere_plane_contact(end, d):
    """v_n' = -eps(beta) v_n with beta = k (R g / m^2)^(1/5) (R_eff = R, m_eff = m), eps from
    the contact ODE, to 1e-8; for several speeds, radii and masses."""
    k = 0.6
    table = restitution_table(3.0, end=end)
    rule = CollisionRule.viscoelastic(k, table)
    for speed, radius, mass in [(0.3, 0.5, 1.0), (2.0, 0.5, 1.0), (1.0, 0.8, 3.0), (7.0, 0.3, 0.2)]:
        box = np.full(d, 10.0)
        pos = np.array([[5.0] * (d - 1) + [4.0], [2.0] * d])
        vel = np.zeros((2, d))
        vel[0, -1] = -speed
        sim = Simulation(State(pos, vel, [radius, 0.5], [mass, 1.0], box,
                               boundary=("periodic",) * (d - 1) + ("wall",)), rule)
        sim.run((4.0 - radius) / speed * 1.5)
        assert sim.wall_collisions == 1 and sim.collisions == 0
        beta = k * (radius * speed / mass**2) ** 0.2
        eps = restitution(beta, method="ode", end=end)
        assert sim.velocities[0, -1] / speed == pytest.approx(eps, abs=1e-8)
        loss = 0.5 * mass * speed**2 * (1 - eps**2)
        assert sim.dissipated_energy == pytest.approx(loss, rel=1e-7)
        np.testing.assert_array_equal(sim.images, 0)


def test_wall_collision_elastic_constant_and_separate_wall_restitution():
    box = np.full(3, 6.0)
    for rule, eps in [(CollisionRule.elastic(), 1.0), (CollisionRule.constant(0.7), 0.7),
                      (CollisionRule.constant(0.7, wall_restitution=0.9), 0.9)]:
        sim = Simulation(State([[3.0, 3.0, 5.0], [1.0, 1.0, 1.0]], [[0.0, 0.0, 2.0], [0, 0, 0]],
                               0.5, 1.0, box, boundary=("periodic", "periodic", "wall")), rule)
        sim.run(1.0)  # contact at z = 5.5 after 0.25
        assert sim.wall_collisions == 1
        assert sim.velocities[0, 2] == pytest.approx(-2.0 * eps, rel=1e-15)
        assert sim.positions[0, 2] == pytest.approx(5.5 - 2.0 * eps * 0.75, rel=1e-14)
        imp = sim.wall_impulse()
        assert imp[2, 1] == pytest.approx((1 + eps) * 2.0, rel=1e-15) and imp.sum() == imp[2, 1]


@pytest.mark.parametrize("d, walls, packing", [(3, (2,), 0.4), (3, (0, 1, 2), 0.3), (2, (0,), 0.6)])
def test_invariants_and_energy_with_walls(d, walls, packing):
    st = walled_state(400, packing, d, walls, seed=3)
    sim = Simulation(st, CollisionRule.constant(0.9))
    e0 = sim.kinetic_energy
    for t in (0.5, 1.0, 3.0):
        sim.run(t)
        assert check(sim) == [], (d, walls, t)
    assert sim.wall_collisions > 100
    assert sim.kinetic_energy + sim.dissipated_energy == pytest.approx(e0, rel=1e-12)
    pos = sim.positions
    for a in walls:
        assert np.all(pos[:, a] >= sim.radii * (1 - 1e-9))
        assert np.all(pos[:, a] <= sim.box[a] - sim.radii * (1 - 1e-9))
        np.testing.assert_array_equal(sim.images[:, a], 0)
    periodic = [a for a in range(d) if a not in walls]
    if periodic:  # momentum along the periodic axes is still conserved
        p0 = (st.masses[:, None] * st.velocities).sum(axis=0)
        np.testing.assert_allclose(sim.momentum[periodic], p0[periodic], atol=1e-10)


@pytest.mark.parametrize("d", [2, 3])
def test_restart_equality_with_walls_bit_for_bit(d):
    walls = (d - 1,)
    st = walled_state(200, 0.35, d, walls, seed=5)
    rule = CollisionRule.constant(0.8, tc_time=1e-3, wall_restitution=0.7)
    a = Simulation(st, rule)
    a.run(3.0)
    a.synchronise()
    saved = a.state
    a.run(6.0)
    b = Simulation(saved, rule)
    b.run(6.0)
    assert a.collisions == b.collisions and a.wall_collisions == b.wall_collisions > 0
    assert a.events == b.events
    for k in ("positions", "velocities", "images", "last_collision"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert a.dissipated_energy == b.dissipated_energy


def test_periodic_runs_ignore_the_wall_code():
    """An all-periodic boundary given explicitly is the default, bit for bit."""
    st = walled_state(150, 0.3, 3, (), seed=2)
    a = Simulation(st, CollisionRule.constant(0.9))
    b = Simulation(st.replace(boundary=("periodic",) * 3), CollisionRule.constant(0.9))
    a.run(4.0)
    b.run(4.0)
    np.testing.assert_array_equal(a.positions, b.positions)
    assert b.wall_collisions == 0 and math.isnan(b.wall_pressure_window())


@pytest.mark.parametrize("kwargs, match", [
    (dict(boundary=("periodic", "wall")), "2 entries for a 3D system"),
    (dict(boundary=("periodic", "periodic", "mirror")), "'mirror' is not one of"),
    (dict(boundary="wall"), "one entry per axis"),
    (dict(positions=[[5.0, 5.0, 0.3], [2.0, 2.0, 2.0]]), "overlaps a wall"),
    (dict(positions=[[5.0, 5.0, 9.8], [2.0, 2.0, 2.0]]), "overlaps a wall"),
    (dict(box=[10.0, 10.0, 2.5]), r"too short: z \(wall\)"),
    (dict(images=[[0, 0, 1], [0, 0, 0]]), "must be 0 on wall axes"),
])
def test_bad_wall_input_raises_config_error(kwargs, match):
    base = dict(positions=[[5.0, 5.0, 1.0], [2.0, 2.0, 2.0]], velocities=np.zeros((2, 3)),
                radii=0.5, masses=1.0, box=[10.0, 10.0, 10.0],
                boundary=("periodic", "periodic", "wall"))
    base.update(kwargs)
    with pytest.raises(ConfigError, match=match):
        Simulation(State(**base), CollisionRule.elastic())


def _wall_pressure_against_eos(d, n, packing, t_end, seed=1):
    """(wall pressure, EOS pressure at the bulk density and T, bulk density error) of an elastic
    gas between walls on the last axis, averaged from t = 20 to t_end."""
    from granulargas import theory

    st = walled_state(n, packing, d, (d - 1,), seed=seed)
    sim = Simulation(st, CollisionRule.elastic())
    sim.run(20.0)
    sim.wall_pressure_window()
    L = sim.box[-1]
    counts = []
    for t in np.arange(20.5, t_end + 1e-9, 0.5):
        sim.run(t)
        z = sim.positions[:, -1]
        counts.append(np.sum((z > 0.25 * L) & (z < 0.75 * L)))
    p_wall = sim.wall_pressure_window()
    # degrees of freedom: momentum along the periodic axes is conserved
    temperature = 2.0 * sim.kinetic_energy / (d * sim.n - (d - 1))
    slab = np.prod(sim.box) / 2.0
    blocks = np.array(counts[: len(counts) // 20 * 20], float).reshape(20, -1).mean(axis=1)
    n_bulk = blocks.mean() / slab
    eta = float(theory.packing_fraction(n_bulk, d))
    p_eos = n_bulk * temperature * float(theory.compressibility_factor(eta, d))
    return p_wall, p_eos, blocks.std(ddof=1) / np.sqrt(20) / blocks.mean()


def test_wall_pressure_is_the_bulk_pressure():
    """Mechanical equilibrium: the momentum an elastic gas delivers to the walls per area and
    time equals the equation-of-state pressure n T Z(eta) of the bulk density (middle half of
    the slab; the density next to the walls differs). 3 % here (short run, 3D, N = 1000);
    1 % in the slow test."""
    p_wall, p_eos, err = _wall_pressure_against_eos(3, 1000, 0.1, 300.0)
    assert err < 0.005
    assert p_wall == pytest.approx(p_eos, rel=0.03)


@pytest.mark.slow
@pytest.mark.parametrize("d, packing", [(3, 0.1), (2, 0.3)])
def test_wall_pressure_is_the_bulk_pressure_precise(d, packing):
    """As above within 1 %: N = 2000, t = 1000 (3D eta = 0.1: the equation of state is within
    0.1 %, and the bulk density is known to 0.1 %, which moves P_eos by 0.2 %)."""
    p_wall, p_eos, err = _wall_pressure_against_eos(d, 2000, packing, 1000.0)
    assert err < 0.002
    assert p_wall == pytest.approx(p_eos, rel=0.01)
