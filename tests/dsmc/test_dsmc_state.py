"""DSMC driver: run semantics, bit-exact continuation and restart, bookkeeping, bad input."""

import math

import numpy as np
import pytest

from tests.dsmc.factories import gas, make_dsmc, maxwell
from granulargas import theory
from granulargas.contact import prefactor_from_damping, restitution_table
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule
from granulargas.errors import ConfigError, TableRangeError

RULES = {
    "elastic": lambda: CollisionRule.elastic(),
    "constant": lambda: CollisionRule.constant(0.8),
    "viscoelastic": lambda: CollisionRule.viscoelastic(prefactor_from_damping(0.1),
                                                       restitution_table(2.0)),
}


def _same(a, b):
    assert np.array_equal(a.velocities, b.velocities)
    assert a.time == b.time
    assert a.collisions == b.collisions
    assert a.dissipated_energy == b.dissipated_energy
    sa, sb = a.continuation, b.continuation
    assert np.array_equal(sa.rng, sb.rng)
    assert sa.candidates == sb.candidates and sa.pending_pair == sb.pending_pair
    assert sa.pending_time == sb.pending_time or (math.isnan(sa.pending_time)
                                                  and math.isnan(sb.pending_time))


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("rule", sorted(RULES))
def test_run_to_2t_equals_run_to_t_continued(dim, rule):
    a = make_dsmc(n=300, dim=dim, rule=RULES[rule](), seed=5, packing=0.1)
    b = make_dsmc(n=300, dim=dim, rule=RULES[rule](), seed=5, packing=0.1)
    t = 20.0
    a.run(2 * t)
    for k in range(1, 9):  # many stops, one of them at every pending collision's doorstep
        b.run(2 * t * k / 8)
    _same(a, b)
    assert a.time == 2 * t and a.collisions > 1000


@pytest.mark.parametrize("dim", [2, 3])
def test_restart_from_state_is_bit_exact(dim):
    radii = np.where(np.arange(200) % 3 == 0, 0.7, 0.5)
    masses = (2 * radii) ** dim
    kw = dict(radii=radii, masses=masses, rule=CollisionRule.constant(0.9), seed=9, n=200, dim=dim)
    a = make_dsmc(**kw)
    b = make_dsmc(**kw)
    a.run(30.0)
    b.run(12.0)
    c = DSMC(b.state, b.rule, volume=b.volume)
    c.run(30.0)
    _same(a, c)


def test_max_collisions_stops_at_the_collision_and_continues_exactly():
    a = make_dsmc(n=100, rule=CollisionRule.constant(0.9))
    b = make_dsmc(n=100, rule=CollisionRule.constant(0.9))
    a.run(np.inf, max_collisions=2000)
    b.run(np.inf, max_collisions=700)
    t_stop = b.time
    b.run(1e9, max_collisions=1300)
    assert 0 < t_stop < b.time < 1e9
    _same(a, b)
    # a stop by collision count leaves time at that collision
    c = make_dsmc(n=100, rule=CollisionRule.constant(0.9))
    c.run(1e9, max_collisions=5)
    assert c.collisions == 5 and c.time < 1e9


def test_progress_and_counters():
    sim = make_dsmc(n=100, rule=CollisionRule.constant(0.9))
    seen = []
    sim.run(50.0, progress=lambda s: seen.append((s.time, s.collisions)))
    assert seen[-1] == (50.0, sim.collisions)
    assert sim.candidates >= sim.collisions > 0
    assert 0 < sim.acceptance <= 1
    assert sim.collision_rate == pytest.approx(2 * sim.collisions / (sim.n * 50.0))
    assert sim.majorant_rate > 0
    assert "DSMC(N=100" in repr(sim)


@pytest.mark.parametrize("dim", [2, 3])
def test_momentum_and_energy_bookkeeping(dim):
    n = 400
    radii = np.where(np.arange(n) % 2 == 0, 0.5, 0.8)
    masses = np.where(np.arange(n) % 2 == 0, 1.0, 3.0)
    v = maxwell(n, dim, seed=3, masses=masses)
    sim = DSMC(gas(v, radii, masses), CollisionRule.constant(0.7), number_density=0.05, seed=2)
    p0, e0 = sim.momentum, sim.kinetic_energy
    sim.run(np.inf, max_collisions=10 * n)
    assert np.allclose(sim.momentum, p0, atol=1e-12 * math.sqrt(e0))
    assert sim.kinetic_energy + sim.dissipated_energy == pytest.approx(e0, rel=1e-12)
    assert sim.dissipated_energy > 0.5 * e0


def test_elastic_conserves_energy_and_seed_matters():
    a = make_dsmc(n=100, seed=1)
    e0 = a.kinetic_energy
    a.run(100.0)
    assert a.kinetic_energy == pytest.approx(e0, rel=1e-12) and a.dissipated_energy == 0.0
    b = DSMC(gas(maxwell(100, 3, 1), 0.5, 1.0), CollisionRule.elastic(), packing_fraction=0.01, seed=2)
    b.run(100.0)
    assert not np.array_equal(a.velocities, b.velocities)


def test_viscoelastic_beyond_the_table_raises():
    table = restitution_table(1e-3)
    rule = CollisionRule.viscoelastic(prefactor_from_damping(0.5), table)
    sim = make_dsmc(n=100, rule=rule)
    with pytest.raises(TableRangeError, match="beyond the restitution table"):
        sim.run(100.0)


def test_density_arguments():
    v = maxwell(50, 3)
    n_from_phi = DSMC(gas(v, 0.5, 1.0), CollisionRule.elastic(), packing_fraction=0.1)
    assert n_from_phi.number_density == pytest.approx(0.6 / math.pi * 0.1 * 10)  # 6 phi / pi
    assert n_from_phi.chi == pytest.approx(float(theory.contact_value(0.1, 3)), rel=1e-14)
    by_n = DSMC(gas(v, 0.5, 1.0), CollisionRule.elastic(), number_density=n_from_phi.number_density)
    assert by_n.packing_fraction == pytest.approx(0.1)
    by_v = DSMC(gas(v, 0.5, 1.0), CollisionRule.elastic(), volume=50 / n_from_phi.number_density)
    assert by_v.packing_fraction == pytest.approx(0.1)
    two = DSMC(gas(maxwell(50, 2), 0.5, 1.0), CollisionRule.elastic(), packing_fraction=0.2)
    assert two.number_density == pytest.approx(4 * 0.2 / math.pi)
    assert two.chi == pytest.approx(float(theory.contact_value(0.2, 2)), rel=1e-14)
    assert DSMC(gas(v, 0.5, 1.0), CollisionRule.elastic(), packing_fraction=0.1, chi=1.0).chi == 1.0


@pytest.mark.parametrize("kwargs, message", [
    (dict(), "needs a density"),
    (dict(packing_fraction=0.1, volume=10.0), "at most one of"),
    (dict(packing_fraction=-0.1), "packing_fraction = -0.1"),
    (dict(packing_fraction=1.5), "must be < 1"),
    (dict(volume=0.0), "volume = 0.0"),
    (dict(number_density=float("inf")), "number_density = inf"),
    (dict(packing_fraction=0.1, chi=-1.0), "chi = -1.0"),
])
def test_bad_density_input(kwargs, message):
    with pytest.raises(ConfigError, match=message):
        DSMC(gas(maxwell(10, 3), 0.5, 1.0), CollisionRule.elastic(), **kwargs)


def test_bad_particles_and_rules():
    rule = CollisionRule.elastic()
    with pytest.raises(ConfigError, match="expected"):
        DSMC(gas(np.zeros((10, 4)), 0.5, 1.0), rule, packing_fraction=0.1)
    with pytest.raises(ConfigError, match="at least 2"):
        DSMC(gas(np.zeros((1, 3)), 0.5, 1.0), rule, packing_fraction=0.1)
    with pytest.raises(ConfigError, match="radii"):
        DSMC(gas(maxwell(10, 3), -0.5, 1.0), rule, packing_fraction=0.1)
    with pytest.raises(ConfigError, match="masses"):
        DSMC(gas(maxwell(10, 3), 0.5, np.nan), rule, packing_fraction=0.1)
    with pytest.raises(ConfigError, match="non-finite"):
        DSMC(gas(np.full((10, 3), np.inf), 0.5, 1.0), rule, packing_fraction=0.1)
    with pytest.raises(ConfigError, match="TC model"):
        DSMC(gas(maxwell(10, 3), 0.5, 1.0), CollisionRule.constant(0.5, tc_time=1e-3), packing_fraction=0.1)
    with pytest.raises(TypeError):
        DSMC(gas(maxwell(10, 3), 0.5, 1.0), "elastic", packing_fraction=0.1)


def test_bad_run_arguments():
    sim = make_dsmc(n=10)
    sim.run(1.0)
    with pytest.raises(ValueError, match="already at time"):
        sim.run(0.5)
    with pytest.raises(ValueError, match="needs max_collisions"):
        sim.run(np.inf)
    still = DSMC(gas(np.zeros((10, 3)), 0.5, 1.0), CollisionRule.elastic(), packing_fraction=0.1)
    with pytest.raises(Exception, match="all velocities are zero"):
        still.run(1.0)


def test_state_record_of_a_dsmc():
    """dsmc.state: no positions, events = collisions, the continuation, the box the volume came
    from (None when a density was given), the fields the DSMC does not use carried through."""
    from granulargas.initial import random_state

    st = random_state(200, 0.05, 3, seed=2)
    species = (np.arange(200) % 3).astype(np.int32)
    a = DSMC(st.replace(species=species), CollisionRule.constant(0.8), seed=3)
    assert a.volume == float(np.prod(st.box))
    a.run(5.0)
    s = a.state
    assert s.positions is None and s.images is None and s.events == s.collisions == a.collisions > 0
    np.testing.assert_array_equal(s.box, st.box)
    np.testing.assert_array_equal(s.species, species)
    assert s.dsmc.candidates == a.candidates and s.time == 5.0
    b = DSMC(s, CollisionRule.constant(0.8))  # the volume from the state's box, seed unused
    a.run(10.0)
    b.run(10.0)
    _same(a, b)
    assert make_dsmc(n=20).state.box is None


def test_walls_are_refused():
    with pytest.raises(ConfigError, match="without walls"):
        DSMC(gas(maxwell(10, 3), boundary=("periodic", "periodic", "wall")), CollisionRule.elastic(),
             packing_fraction=0.1)
