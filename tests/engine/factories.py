"""Small-system factories for the engine tests (same dtypes: kernels compile once)."""

import numpy as np
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.state import STATE_FIELDS, State


def simulation(state, rule=None, **kw):
    """``Simulation(state, rule, ...)`` with keyword arguments that name fields of the state
    (``time=``, ``boundary=``, ...) put into the state and the others passed as settings."""
    changes = {k: kw.pop(k) for k in list(kw) if k in STATE_FIELDS}
    return Simulation(state.replace(**changes) if changes else state, rule or CollisionRule.elastic(), **kw)


def make_sim(n=24, packing=0.2, dimension=3, seed=0, rule=None, radii=0.5, **kw):
    return simulation(random_state(n, packing, dimension, seed=seed, radii=radii), rule, **kw)


def two_spheres(p1, p2, v1, v2, box=5.0, radii=(0.5, 0.5), masses=(1.0, 1.0), rule=None, **kw):
    d = len(p1)
    st = State(np.array([p1, p2], float), np.array([v1, v2], float), np.array(radii, float),
               np.array(masses, float), np.full(d, box))
    return simulation(st, rule, **kw)


def next_engine_collision(sim):
    """Advance to the next collision; return (time, i, j) with i < j from changed velocities."""
    v0 = sim.velocities
    c0 = sim.collisions
    sim.run(np.inf, max_collisions=1)
    assert sim.collisions == c0 + 1
    changed = np.flatnonzero(np.any(sim.velocities != v0, axis=1))
    assert len(changed) == 2, changed
    return sim.time, int(changed[0]), int(changed[1])




C1 = 1.15344


def pade_eps(beta):
    """Müller & Pöschel (2011) Padé approximant of the viscoelastic eps(beta)."""
    u = np.sqrt(beta)
    a = 2.0 / (3.0 * C1**2)
    return (1 + a * u) / (1 + a * u + C1 * u**2 + a * C1 * u**3 + 0.4 * C1**2 * u**4)


def hermite_table(func, beta_max=25.0, n=4000):
    """A restitution-table stand-in: cubic Hermite pieces of func(s^2) on a uniform grid in s."""
    h = np.sqrt(beta_max) / n
    s = np.arange(n + 1) * h
    f = func(s**2)
    ds = 1e-6 * h
    fp = (func((s + ds) ** 2) - func(np.abs(s - ds) ** 2)) / (2 * ds)
    fp[0] = (func(ds**2) - f[0]) / ds
    f0, f1, d0, d1 = f[:-1], f[1:], h * fp[:-1], h * fp[1:]
    coeffs = np.stack([f0, d0, 3 * (f1 - f0) - 2 * d0 - d1, 2 * (f0 - f1) + d0 + d1], axis=1)
    from types import SimpleNamespace

    return SimpleNamespace(inv_h=1.0 / h, coeffs=np.ascontiguousarray(coeffs), beta_max=beta_max)


def walled_state(n, packing, dimension, walls, seed=0, radii=0.5, temperature=1.0):
    """A random state in a box with flat walls on the axes ``walls`` (no sphere overlapping one)."""
    boundary = tuple("wall" if a in walls else "periodic" for a in range(dimension))
    return random_state(n, packing, dimension, temperature=temperature, seed=seed, radii=radii,
                        boundary=boundary)
