"""Small-system factories for the engine tests (same dtypes: kernels compile once)."""

import numpy as np
from granulargas.engine import CollisionRule, Simulation
from granulargas.engine.initial import random_state


def make_sim(n=24, packing=0.2, dimension=3, seed=0, rule=None, radii=0.5, **kw):
    st = random_state(n, packing, dimension, seed=seed, radii=radii)
    return Simulation(**st.as_kwargs(), rule=rule or CollisionRule.elastic(), **kw)


def two_spheres(p1, p2, v1, v2, box=5.0, radii=(0.5, 0.5), masses=(1.0, 1.0), rule=None, **kw):
    d = len(p1)
    return Simulation(np.array([p1, p2], float), np.array([v1, v2], float), np.array(radii, float),
                      np.array(masses, float), np.full(d, box), rule or CollisionRule.elastic(), **kw)


def next_engine_collision(sim):
    """Advance to the next collision; return (time, i, j) with i < j from changed velocities."""
    v0 = sim.velocities
    c0 = sim.collisions
    sim.run(np.inf, max_collisions=1)
    assert sim.collisions == c0 + 1
    changed = np.flatnonzero(np.any(sim.velocities != v0, axis=1))
    assert len(changed) == 2, changed
    return sim.time, int(changed[0]), int(changed[1])


