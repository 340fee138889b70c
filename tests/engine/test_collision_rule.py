"""Property tests of the collision rule, through the engine (two spheres about to touch)."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from granulargas.engine import CollisionRule, Simulation
from granulargas.errors import ConfigError, TableRangeError
from granulargas.state import State

from tests.engine.factories import two_spheres

C_LIN = 0.05  # eps = 1 - C_LIN beta stays > 0.7 over the sampled range


def linear_table(h=0.01, n=2000, c=C_LIN):
    """A hand-made table for eps(beta) = 1 - c beta, exact as a polynomial in t (s = (k + t) h)."""
    k = np.arange(n, dtype=float)
    coeffs = np.stack([1 - c * h * h * k**2, -2 * c * h * h * k, np.full(n, -c * h * h), 0 * k], axis=1)
    return SimpleNamespace(inv_h=1.0 / h, coeffs=np.ascontiguousarray(coeffs), beta_max=(n * h) ** 2)


def _pair(direction, g, ri, rj, mi, mj, tangential, rule):
    """Spheres that touch with contact normal ``direction`` at normal speed g.

    They are placed back along their relative velocity by a distance 0.1, so
    the contact is the first one whatever the tangential speed (a pair placed
    0.1 apart along the normal with a large tangential speed would miss, and
    could then circle the periodic box for ever without meeting).
    """
    n = np.asarray(direction, float)
    n /= np.linalg.norm(n)
    t = np.cross(n, [0.3, -0.7, 0.2]) if len(n) == 3 else np.array([-n[1], n[0]])
    t /= np.linalg.norm(t)
    centre = np.full(len(n), 4.0)
    vi = -0.5 * g * n + tangential * t
    vj = 0.5 * g * n
    u = vi - vj
    rij = (ri + rj) * n - u * (0.1 / np.linalg.norm(u))
    pi = centre + 0.5 * rij
    pj = centre - 0.5 * rij
    return two_spheres(pi, pj, vi, vj, box=9.0, radii=(ri, rj), masses=(mi, mj), rule=rule)


def _check(sim, eps_of):
    """Run one collision; check (2) of engine._collide from the state at contact."""
    v0 = sim.velocities
    sim.run(np.inf, max_collisions=1)
    pos = sim.positions
    v1 = sim.velocities
    m = sim.masses
    rij = pos[0] - pos[1]
    rij -= sim.box * np.round(rij / sim.box)
    n = rij / np.linalg.norm(rij)
    assert np.linalg.norm(rij) == pytest.approx(sim.radii.sum(), rel=1e-12)
    un0 = np.dot(v0[0] - v0[1], n)
    un1 = np.dot(v1[0] - v1[1], n)
    eps = eps_of(-un0)
    m_eff = m[0] * m[1] / m.sum()
    np.testing.assert_allclose(m[0] * v1[0] + m[1] * v1[1], m[0] * v0[0] + m[1] * v0[1], atol=1e-13)
    assert un1 == pytest.approx(-eps * un0, rel=1e-11, abs=1e-14)
    tan0 = (v0[0] - v0[1]) - un0 * n
    tan1 = (v1[0] - v1[1]) - un1 * n
    np.testing.assert_allclose(tan1, tan0, atol=1e-12)
    loss = 0.5 * (1 - eps**2) * m_eff * un0**2
    assert sim.dissipated_energy == pytest.approx(loss, rel=1e-10, abs=1e-15)
    e0 = 0.5 * np.sum(m[:, None] * v0**2)
    assert e0 - sim.kinetic_energy == pytest.approx(loss, rel=1e-8, abs=1e-13)


vec3 = st.tuples(*[st.floats(-1, 1) for _ in range(3)]).filter(lambda v: np.linalg.norm(v) > 0.1)
common = dict(g=st.floats(0.01, 5.0), ri=st.floats(0.2, 0.8), rj=st.floats(0.2, 0.8),
              mi=st.floats(0.1, 10.0), mj=st.floats(0.1, 10.0), tangential=st.floats(-2, 2))


@settings(max_examples=40, deadline=None)
@given(direction=vec3, eps=st.floats(0.05, 1.0), **common)
def test_constant_rule_properties(direction, eps, g, ri, rj, mi, mj, tangential):
    sim = _pair(direction, g, ri, rj, mi, mj, tangential, CollisionRule.constant(eps))
    _check(sim, lambda gn: eps)


@settings(max_examples=40, deadline=None)
@given(direction=vec3, k=st.floats(0.0, 1.5), **common)
def test_viscoelastic_rule_properties(direction, k, g, ri, rj, mi, mj, tangential):
    rule = CollisionRule.viscoelastic(prefactor=k, table=linear_table())
    r_eff = ri * rj / (ri + rj)
    m_eff = mi * mj / (mi + mj)
    sim = _pair(direction, g, ri, rj, mi, mj, tangential, rule)
    _check(sim, lambda gn: 1 - C_LIN * k * (r_eff * gn / m_eff**2) ** 0.2)


@settings(max_examples=20, deadline=None)
@given(direction=st.tuples(st.floats(-1, 1), st.floats(-1, 1)).filter(lambda v: np.hypot(*v) > 0.1),
       eps=st.floats(0.05, 1.0), **common)
def test_constant_rule_properties_2d(direction, eps, g, ri, rj, mi, mj, tangential):
    sim = _pair(direction, g, ri, rj, mi, mj, tangential, CollisionRule.constant(eps))
    _check(sim, lambda gn: eps)


def test_elastic_rule_conserves_energy():
    sim = _pair([1, 2, 3], 1.3, 0.5, 0.3, 1.0, 2.0, 0.7, CollisionRule.elastic())
    _check(sim, lambda gn: 1.0)
    assert sim.dissipated_energy == 0.0


def test_impact_beyond_table_raises_with_context():
    table = linear_table(n=10)  # beta <= 0.01
    sim = _pair([1, 0, 0], 3.0, 0.5, 0.5, 1.0, 1.0, 0.0, CollisionRule.viscoelastic(1.0, table))
    with pytest.raises(TableRangeError, match=r"particles \[[01], [01]\]"):
        sim.run(10.0)


@pytest.mark.parametrize("tc_time, second_elastic", [(None, False), (10.0, True), (0.1, False)])
def test_tc_model_makes_quick_recollisions_elastic(tc_time, second_elastic):
    """Three spheres in a row: 0 hits 1 at t = 0.5, then 1 hits 2 at t = 0.5 + 0.5/0.75."""
    eps = 0.5
    sim = Simulation(State(np.array([[1.0, 3, 3], [2.5, 3, 3], [4.0, 3, 3]]),
                           np.array([[1.0, 0, 0], [0, 0, 0], [0, 0, 0]]), np.full(3, 0.5), np.ones(3),
                           np.full(3, 9.0)), CollisionRule.constant(eps, tc_time=tc_time))
    sim.run(np.inf, max_collisions=2)
    assert sim.time == pytest.approx(0.5 + 0.5 / 0.75, rel=1e-13)
    first = 0.5 * (1 - eps**2) * 0.5 * 1.0**2
    second = 0.0 if second_elastic else 0.5 * (1 - eps**2) * 0.5 * 0.75**2
    assert sim.dissipated_energy == pytest.approx(first + second, rel=1e-13)
    np.testing.assert_allclose(sim.last_collision, [0.5, sim.time, sim.time], rtol=1e-14)


@pytest.mark.parametrize("bad", [0.0, -0.1, 1.5])
def test_constant_rule_rejects_bad_restitution(bad):
    with pytest.raises(ConfigError, match="restitution"):
        CollisionRule.constant(bad)


def test_tangential_rule_bounds():
    from granulargas.engine import TangentialRule
    from granulargas.engine._rough import TANGENTIAL_CONSTANT, TANGENTIAL_COULOMB

    r = TangentialRule.constant(0.3)
    assert (r.code, r.restitution, r.wall_beta, r.wall_mu) == (TANGENTIAL_CONSTANT, 0.3, 0.3, 0.0)
    c = TangentialRule.coulomb(0.4, 0.2, wall_restitution=-0.5)
    assert (c.code, c.wall_beta, c.wall_mu) == (TANGENTIAL_COULOMB, -0.5, 0.2)
    for bad in (lambda: TangentialRule.constant(1.01), lambda: TangentialRule.constant(-1.5),
                lambda: TangentialRule.coulomb(0.0, -0.1), lambda: TangentialRule.coulomb(0.0, float("nan")),
                lambda: TangentialRule("stick", 0.0), lambda: TangentialRule("constant", 0.0, 0.3)):
        with pytest.raises(ConfigError):
            bad()
