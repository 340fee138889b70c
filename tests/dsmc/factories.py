"""Small DSMC systems and compiled probes for the dsmc tests (same dtypes: kernels compile once)."""

import math

import numpy as np
from scipy.special import gammaln

from granulargas._numba import jit
from granulargas.dsmc import DSMC
from granulargas.dsmc._collide import apply_pair_update, normal_part_2d, normal_part_3d
from granulargas.dsmc._random import next_u64, pair_of, uniform
from granulargas.engine import CollisionRule
from granulargas.state import STATE_FIELDS, State


def maxwell(n, dim, seed=0, masses=None):
    """Gaussian velocities (N, d), zero total momentum, temperature 1 for unit masses."""
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((n, dim))
    m = np.ones(n) if masses is None else np.broadcast_to(np.asarray(masses, float), (n,))
    v /= np.sqrt(m)[:, None]
    v -= (m[:, None] * v).sum(axis=0) / m.sum()
    return v


def gas(velocities, radii=0.5, masses=1.0, **fields) -> State:
    """A DSMC state: no positions, no box (the DSMC's density is then a setting)."""
    return State(None, velocities, radii, masses, None, **fields)


def make_dsmc(n=200, dim=3, rule=None, seed=1, packing=0.01, radii=0.5, masses=1.0, **kw):
    """A Maxwellian DSMC; keyword arguments that name fields of the state (``time=``, ...) go
    into the state, the others are settings."""
    fields = {k: kw.pop(k) for k in list(kw) if k in STATE_FIELDS}
    return DSMC(gas(maxwell(n, dim, seed), radii, masses, **fields), rule or CollisionRule.elastic(),
                packing_fraction=packing, seed=seed, **kw)


def microcanonical_rate(sim):
    """Exact mean collision frequency per particle of identical particles spread uniformly
    on their energy-momentum shell (the elastic equilibrium of N particles): the pair rate
    chi B_d sigma^(d-1) <|v_i - v_j|> / V times the N - 1 partners, with <|v_i - v_j|> of
    the uniform law on the sphere of dimension D = d (N - 1) and radius R = sqrt(N d T / m).
    """
    n, d = sim.n, sim.dimension
    big_d = d * (n - 1)
    m = float(sim.masses[0])
    radius = math.sqrt(n * d * sim.temperature / m)
    # |v_i - v_j|^2 = 2 R^2 Beta(d/2, (D - d)/2)
    mean_g = radius * math.sqrt(2.0) * math.exp(gammaln((d + 1) / 2) + gammaln(big_d / 2)
                                                 - gammaln(d / 2) - gammaln((big_d + 1) / 2))
    b_d = math.pi ** ((d - 1) / 2) / math.gamma((d + 1) / 2)
    sigma = 2.0 * float(sim.radii[0])
    return sim.chi * b_d * sigma ** (d - 1) * (n - 1) / sim.volume * mean_g


@jit
def draw_pairs(key, start, count, n, out):
    for k in range(count):
        i, j = pair_of(key, start + k, n)
        out[k, 0] = i
        out[k, 1] = j


@jit
def draw_uniforms(state, out):
    for k in range(out.shape[0]):
        out[k] = uniform(state)


@jit
def draw_u64(state, out):
    for k in range(out.shape[0]):
        out[k] = next_u64(state)


@jit
def draw_normal_parts(state, g, out):
    """Rows (p_1..p_d, g_n^2) for ``out.shape[0]`` draws at relative velocity g (d,)."""
    d = g.shape[0]
    g2 = 0.0
    for a in range(d):
        g2 += g[a] * g[a]
    for k in range(out.shape[0]):
        if d == 3:
            px, py, pz, gn2 = normal_part_3d(state, g[0], g[1], g[2], g2)
            out[k, 0] = px
            out[k, 1] = py
            out[k, 2] = pz
            out[k, 3] = gn2
        else:
            px, py, gn2 = normal_part_2d(state, g[0], g[1], g2)
            out[k, 0] = px
            out[k, 1] = py
            out[k, 2] = gn2


@jit
def pair_update(rec, i, j, dim, p, eps, mi, mj):
    apply_pair_update(rec, i, j, dim, p[0], p[1], p[2] if dim == 3 else 0.0, eps, mi, mj)
