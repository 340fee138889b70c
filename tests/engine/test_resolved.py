"""Collisions that take time (resolved viscoelastic rule) in the engine.

Checked against the head-on contact (eps(beta), tau_c(beta) by ODE), the
independent Cartesian integration of the two-sphere contact
(:func:`granulargas.contact.oblique.solve_oblique_cartesian`), conservation
laws, the naive reference loop and restart equality.
"""

import math

import numpy as np
import pytest

from granulargas.contact import duration, oblique_table, restitution, restitution_table
from granulargas.contact.oblique import solve_oblique_cartesian
from granulargas.engine import CollisionRule, Simulation
from granulargas.errors import ConfigError
from granulargas.initial import random_state

from tests.engine.factories import next_engine_collision, two_spheres
from tests.engine.reference import run_reference

#: pair prefactor k (beta = k g_n^(1/5) for two reference spheres)
K = 0.1


@pytest.fixture(scope="module")
def tables():
    """Test-size tables (beta < 0.39, delta < 0.125; cached on disk)."""
    return restitution_table(1.0), oblique_table(0.39, 0.125)


def resolved(tables, q):
    tab, ob = tables
    return CollisionRule.viscoelastic(K, tab, duration="resolved", compression=q, oblique=ob)


def touch_time(p1, p2, v1, v2, dist):
    dr, dv = np.subtract(p1, p2), np.subtract(v1, v2)
    a, b, c = dv @ dv, dr @ dv, dr @ dr - dist**2
    return (-b - math.sqrt(b * b - a * c)) / a


def test_head_on_gives_the_restitution_and_duration_of_the_contact(tables):
    """Head-on: outgoing speed eps(beta) g and contact duration tau_c(beta) X / g (ODE)."""
    q = 0.05
    g = 1.3
    sim = two_spheres([1.0, 1.0, 1.0], [2.5, 1.0, 1.0], [g, 0, 0], [0, 0, 0], rule=resolved(tables, q))
    t0 = touch_time([1.0, 1.0, 1.0], [2.5, 1.0, 1.0], [g, 0, 0], [0, 0, 0], 1.0)
    sim.run(2.0)
    assert sim.collisions == 1
    beta = K * g**0.2  # R_eff = 1/4, m_eff = 1/2: (R_eff / m_eff^2)^(1/5) = 1
    x_scale = q * g**0.8
    eps = float(restitution(beta, "ode"))
    tc = float(duration(beta, "ode")) * x_scale / g
    v = sim.velocities
    assert (v[0, 0] - v[1, 0]) == pytest.approx(-eps * g, abs=1e-9)
    assert sim.contact_until[0] - t0 == pytest.approx(tc, rel=1e-9)
    # after the contact the pair is at D + eps g (t - t0 - tc): the outgoing line starts at separation
    gap = sim.positions[1, 0] - sim.positions[0, 0]
    assert gap == pytest.approx(1.0 + eps * g * (2.0 - t0 - tc), abs=1e-9)
    np.testing.assert_array_equal(sim.contact_partner, [1, 0])


@pytest.mark.parametrize("offset, end", [(0.3, "overlap"), (0.7, "overlap"), (0.95, "overlap"),
                                         (0.7, "force")])
def test_oblique_trajectory_after_contact_matches_direct_integration(tables, offset, end):
    """Post-contact relative position and velocity against the Cartesian DOP853 integration."""
    if end == "force":
        tab, ob = restitution_table(1.0, end="force"), oblique_table(0.39, 0.125, end="force")
        tables = (tab, ob)
    q = 0.05
    p1, p2 = np.array([1.0, 1.0, 1.0]), np.array([2.6, 1.0 + offset, 1.2])
    v1, v2 = np.array([1.2, 0.1, 0.0]), np.array([-0.3, 0.0, 0.2])
    sim = two_spheres(p1, p2, v1, v2, box=6.0, rule=resolved(tables, q))
    t0 = touch_time(p1, p2, v1, v2, 1.0)
    r0 = (p1 + v1 * t0) - (p2 + v2 * t0)
    u = v1 - v2
    n0 = r0 / np.linalg.norm(r0)
    g_n = -u @ n0
    vt = u + g_n * n0
    g_t = np.linalg.norm(vt)
    e_t = vt / g_t
    beta = K * g_n**0.2
    delta = q * g_n**0.8 / 1.0
    c = delta * (g_t / g_n) ** 2
    ref = solve_oblique_cartesian(beta, c, delta, end=end)
    tc = ref["duration"] * q * g_n**0.8 / g_n
    t_end = t0 + tc + 0.5
    sim.run(t_end)
    assert sim.collisions == 1
    v_rel = g_n * (ref["velocity"][0] * n0 + ref["velocity"][1] * e_t)
    r_rel = ref["position"][0] * n0 + ref["position"][1] * e_t + v_rel * (t_end - t0 - tc)
    v = sim.velocities
    r = sim.unwrapped_positions
    np.testing.assert_allclose(v[0] - v[1], v_rel, rtol=0, atol=1e-8)
    np.testing.assert_allclose(r[0] - r[1], r_rel, rtol=0, atol=1e-8)
    # the centre of mass moves on as if nothing happened
    np.testing.assert_allclose(0.5 * (r[0] + r[1]), 0.5 * (p1 + p2 + (v1 + v2) * t_end), atol=1e-12)
    assert sim.contact_until[0] - t0 == pytest.approx(tc, rel=1e-8)


@pytest.mark.parametrize("dimension", [2, 3])
def test_gas_conserves_momentum_and_balances_energy(tables, dimension):
    st = random_state(40, 0.2, dimension, seed=3)
    sim = Simulation(st, resolved(tables, 0.02), remove_drift=False)
    e0, p0 = sim.kinetic_energy, sim.momentum
    sim.run(np.inf, max_collisions=600)
    assert sim.dissipated_energy > 0.01 * e0
    assert sim.kinetic_energy + sim.dissipated_energy == pytest.approx(e0, rel=1e-12)
    np.testing.assert_allclose(sim.momentum, p0, atol=1e-12)


@pytest.mark.parametrize("dimension", [2, 3])
def test_event_sequence_matches_reference_loop(tables, dimension):
    """Independent runs of the engine and the naive loop (same rule) agree collision by collision."""
    st = random_state(24, 0.25, dimension, seed=11)
    rule = resolved(tables, 0.02)
    sim = Simulation(st, rule, remove_drift=False)
    ref, _, vel = run_reference(sim.positions, sim.velocities, sim.radii, sim.masses, sim.box, 40, rule=rule)
    for t, i, j in ref:
        te, a, b = next_engine_collision(sim)
        assert (a, b) == (i, j)
        assert te == pytest.approx(t, rel=1e-8)
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-6, atol=1e-8)


def test_restart_from_public_state_is_bit_identical(tables):
    """A run to 2t synchronised at t (as at a snapshot) equals a run to t rebuilt from its
    public state (contacts under way included)."""
    st = random_state(60, 0.3, 3, seed=5)
    rule = resolved(tables, 0.02)
    full = Simulation(st, rule, remove_drift=False)
    full.run(0.3)
    full.synchronise()
    full.run(0.6)
    half = Simulation(st, rule, remove_drift=False)
    half.run(0.3)
    half.synchronise()
    assert np.any(half.contact_until > half.time)  # contacts under way at the restart
    again = Simulation(half.state, rule, remove_drift=False)
    again.run(0.6)
    np.testing.assert_array_equal(again.positions, full.positions)
    np.testing.assert_array_equal(again.velocities, full.velocities)
    assert again.collisions == full.collisions
    assert again.three_body_contacts == full.three_body_contacts
    np.testing.assert_array_equal(again.contact_until, full.contact_until)


def test_third_particles_are_counted_in_a_dense_soft_gas_only(tables):
    dense = Simulation(random_state(60, 0.35, 3, seed=7), resolved(tables, 0.02))
    dense.run(np.inf, max_collisions=1000)
    dilute = Simulation(random_state(60, 0.05, 3, seed=7), resolved(tables, 1e-5))
    dilute.run(np.inf, max_collisions=1000)
    assert dense.three_body_contacts > 0
    assert dilute.three_body_contacts == 0


def test_resolved_rule_needs_stiffness_and_table(tables):
    tab, ob = tables
    with pytest.raises(ConfigError, match="compression"):
        CollisionRule.viscoelastic(K, tab, duration="resolved", oblique=ob)
    with pytest.raises(ConfigError, match="oblique"):
        CollisionRule.viscoelastic(K, tab, duration="resolved", compression=0.1)
    with pytest.raises(ConfigError, match="duration"):
        CollisionRule.viscoelastic(K, tab, duration="slow")
    with pytest.raises(ConfigError, match="walls"):
        st = random_state(20, 0.1, 3, seed=1, boundary=("periodic", "periodic", "wall"))
        Simulation(st, resolved(tables, 0.02))


def test_impact_beyond_the_table_extends_it(tables):
    """An impact with delta beyond the table: the run extends the table and goes on."""
    q, g = 0.05, 6.0
    rule = resolved(tables, q)
    delta = q * g**0.8
    assert delta > rule.oblique.delta_limit
    sim = two_spheres([1.0, 1.0, 1.0], [2.5, 1.0, 1.0], [g, 0, 0], [0, 0, 0], rule=rule)
    sim.run(0.3)
    assert sim.collisions == 1 and sim.rule.oblique.delta_limit > delta
    eps = float(restitution(K * g**0.2, "ode"))
    v = sim.velocities
    assert (v[0, 0] - v[1, 0]) == pytest.approx(-eps * g, abs=1e-8)


def test_driven_gas_balances_energy(tables):
    """White-noise kicks with contacts under way: KE + dissipated - injected stays E0."""
    from granulargas.engine import WhiteNoise

    st = random_state(40, 0.2, 3, seed=4)
    sim = Simulation(st, resolved(tables, 0.02), driving=WhiteNoise(0.5, 0.05, seed=2),
                     remove_drift=False)
    e0 = sim.kinetic_energy
    sim.run(2.0)
    assert sim.injected_energy > 0 and sim.dissipated_energy > 0
    assert sim.kinetic_energy + sim.dissipated_energy - sim.injected_energy == pytest.approx(e0, rel=1e-11)


def test_pressure_of_a_contact_equals_the_force_integral(tables):
    """Kinetic + virial integral over a window containing one head-on contact equals that of the
    force-based trajectory (scipy integration of the contact ODE): m_eff(a.v' - r0.u) is exact."""
    from scipy.integrate import solve_ivp

    q, g = 0.05, 1.3
    sim = two_spheres([1.0, 1.0, 1.0], [2.5, 1.0, 1.0], [g / 2, 0, 0], [-g / 2, 0, 0], rule=resolved(tables, q))
    sim.pressure_window()
    t_end = 1.0
    sim.run(t_end)
    p = sim.pressure_window() * 3 * 125.0 * t_end  # sum over the window of m v^2 dt + r . dp
    m_eff, dist = 0.5, 1.0
    x_scale = q * 1.0  # (m_eff^2 / R_eff)^(1/5) = 1
    rho = x_scale ** -2.5
    a_diss = 2.0 * K * x_scale / 3.0

    def rhs(t, y):
        xi, v = max(y[0], 0.0), y[1]
        acc = -rho * (xi**1.5 + 1.5 * a_diss * math.sqrt(xi) * v)
        return [v, acc, v * v, -(dist - xi) * acc]

    def apart(t, y):
        return y[0]

    apart.terminal, apart.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 10.0), [0.0, g, 0.0, 0.0], events=apart, rtol=1e-12, atol=1e-14,
                    first_step=1e-8)
    tc = sol.t_events[0][0]
    _, v_out, kin_contact, virial = sol.y_events[0][0]
    t0 = 0.5 / g  # gap 0.5 closed at speed g
    expected = m_eff * (g * g * t0 + kin_contact + virial + v_out * v_out * (t_end - t0 - tc))
    assert p == pytest.approx(expected, rel=1e-7)


@pytest.mark.parametrize("dimension", [2, 3])
def test_gravity_in_a_periodic_box_leaves_the_contacts_unchanged(tables, dimension):
    """Uniform gravity moves a pair's centre of mass only: the jump onto the outgoing line
    (relative position and velocity) is the same, so a run with gravity has the collisions of
    the run without it, positions shifted by g t^2 / 2 and velocities by g t."""
    st = random_state(40, 0.2, dimension, seed=3)
    g = np.array([0.3, -0.7, 0.5])[:dimension]
    plain = Simulation(st, resolved(tables, 0.02), remove_drift=False)
    fall = Simulation(st, resolved(tables, 0.02), remove_drift=False, gravity=g)
    for k in range(80):
        plain.run(np.inf, max_collisions=1)
        fall.run(np.inf, max_collisions=1)
        t = fall.time
        assert t == pytest.approx(plain.time, rel=1e-10, abs=1e-12), k
        np.testing.assert_allclose(fall.velocities, plain.velocities + g * t, rtol=0, atol=1e-8)
        np.testing.assert_allclose(fall.unwrapped_positions, plain.unwrapped_positions + 0.5 * g * t * t,
                                   rtol=0, atol=1e-8)
    assert plain.three_body_contacts == fall.three_body_contacts
    assert fall.dissipated_energy == pytest.approx(plain.dissipated_energy, rel=1e-10)
