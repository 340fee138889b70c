"""The restitution floor ``elastic_below``: elastic collisions below a normal speed, against the
naive reference loop event by event; the rule's input checks."""

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation
from granulargas.errors import ConfigError
from tests.engine.factories import walled_state
from tests.engine.reference import run_scene


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
def test_elastic_below_matches_the_reference(neighbours):
    """Constant eps = 0.5 with a floor at the median normal speed: about half the collisions are
    elastic. The engine's sequence (pairs and walls) and final velocities against the reference."""
    st = walled_state(40, 0.25, 3, (2,), seed=5)
    floor = 0.8
    rule = CollisionRule.constant(0.5, wall_restitution=0.7, elastic_below=floor)
    sim = Simulation(st, rule, neighbours=neighbours)
    ref, _, vel, _ = run_scene(sim.positions, sim.velocities, sim.radii, sim.masses, sim.box, 80, walls=(2,),
                               eps=0.5, wall_eps=0.7, elastic_below=floor)
    t_end = ref[-1][0]
    sim.run(t_end * (1 + 1e-12))
    assert sim.collisions + sim.wall_collisions == 80
    assert sim.collisions == sum(j >= 0 for _, _, j in ref)
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-7, atol=1e-9)
    # and the floor mattered
    _, _, vel_no_floor, _ = run_scene(st.positions, st.velocities, st.radii, st.masses, st.box, 80,
                                      walls=(2,), eps=0.5, wall_eps=0.7)
    assert not np.allclose(vel, vel_no_floor, rtol=1e-3)


@pytest.mark.parametrize("value", [0.0, -1.0, float("inf"), float("nan")])
def test_elastic_below_must_be_a_positive_speed(value):
    with pytest.raises(ConfigError, match="elastic_below"):
        CollisionRule.constant(0.8, elastic_below=value)


def test_elastic_below_is_not_for_collisions_that_take_time():
    from tests.engine.factories import hermite_table, pade_eps

    with pytest.raises(ConfigError, match="elastic_below"):
        CollisionRule.viscoelastic(0.3, hermite_table(pade_eps), duration="resolved", compression=0.1,
                                   oblique=object(), elastic_below=0.1)
