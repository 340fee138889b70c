"""Collision normals drawn with the weight Theta(g.k)(g.k) of the collision integral,
and the smooth-sphere velocity update."""

import numpy as np
import pytest
from scipy import stats

from tests.dsmc.factories import draw_normal_parts, pair_update
from granulargas.dsmc._random import seed_state

G3 = np.array([0.3, -1.2, 0.7])
G2 = np.array([-0.8, 0.45])


def test_3d_normals_cosine_weighted_and_isotropic_in_azimuth():
    out = np.empty((100_000, 4))
    draw_normal_parts(seed_state(1), G3, out)
    p, gn2 = out[:, :3], out[:, 3]
    g = np.linalg.norm(G3)
    gn = np.linalg.norm(p, axis=1)
    assert np.allclose(gn * gn, gn2, rtol=1e-12, atol=1e-15)
    # p is the projection of g on k: (g - p) . p = 0
    assert np.allclose(((G3 - p) * p).sum(axis=1), 0.0, atol=1e-12)
    k = p / gn[:, None]
    cos = k @ G3 / g
    assert cos.min() >= 0.0
    # density of cos(theta) is 2 cos(theta): cos^2 is uniform
    assert stats.kstest(cos**2, "uniform").pvalue > 1e-4
    # azimuth of k about g is uniform
    e1 = np.cross(G3, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(G3 / g, e1)
    phi = np.arctan2(k @ e2, k @ e1)
    assert stats.kstest(phi, "uniform", args=(-np.pi, 2 * np.pi)).pvalue > 1e-4


def test_2d_normals_cosine_weighted():
    out = np.empty((100_000, 3))
    draw_normal_parts(seed_state(2), G2, out)
    p, gn2 = out[:, :2], out[:, 2]
    g = np.linalg.norm(G2)
    gn = np.linalg.norm(p, axis=1)
    assert np.allclose(gn * gn, gn2, rtol=1e-12, atol=1e-15)
    assert np.allclose(((G2 - p) * p).sum(axis=1), 0.0, atol=1e-12)
    k = p / gn[:, None]
    perp = np.array([-G2[1], G2[0]]) / g
    assert (k @ G2).min() >= 0.0
    # the angle theta between k and g has density cos(theta)/2: sin(theta) is uniform
    assert stats.kstest(k @ perp, "uniform", args=(-1.0, 2.0)).pvalue > 1e-4


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("eps", [1.0, 0.6])
def test_pair_update_is_the_smooth_sphere_rule(dim, eps):
    rng = np.random.default_rng(3)
    width = 4 if dim == 3 else 2
    rec = np.zeros((2, width))
    rec[:, :dim] = rng.standard_normal((2, dim))
    v = rec[:, :dim].copy()
    mi, mj = 1.3, 0.4
    g = v[0] - v[1]
    k = rng.standard_normal(dim)
    k /= np.linalg.norm(k)
    if g @ k < 0:
        k = -k
    p = np.zeros(3)
    p[:dim] = (g @ k) * k
    pair_update(rec, 0, 1, dim, p, eps, mi, mj)
    # the collision rule with n = -k the unit vector from j to i (g . n < 0)
    n = -k
    un = g @ n
    vi = v[0] - (1 + eps) * mj / (mi + mj) * un * n
    vj = v[1] + (1 + eps) * mi / (mi + mj) * un * n
    assert np.allclose(rec[0, :dim], vi, rtol=1e-14, atol=1e-14)
    assert np.allclose(rec[1, :dim], vj, rtol=1e-14, atol=1e-14)
    assert np.allclose(mi * rec[0, :dim] + mj * rec[1, :dim], mi * v[0] + mj * v[1], atol=1e-14)
    loss = 0.5 * (mi * (v[0] @ v[0]) + mj * (v[1] @ v[1])
                  - mi * (rec[0, :dim] @ rec[0, :dim]) - mj * (rec[1, :dim] @ rec[1, :dim]))
    m_eff = mi * mj / (mi + mj)
    assert np.isclose(loss, 0.5 * (1 - eps**2) * m_eff * un**2, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_viscoelastic_restitution_of_each_collision_is_the_engines(end):
    """Two unlike particles (the only pair): from every collision's velocity change follow
    g_n and eps; eps equals the restitution table at beta = k (R_eff g_n / m_eff^2)^(1/5)
    (both contact ends), and the energy lost is (1 - eps^2) m_eff g_n^2 / 2."""
    from granulargas.contact import restitution_table
    from granulargas.dsmc import DSMC
    from granulargas.engine import CollisionRule
    from granulargas.state import State

    table = restitution_table(3.0, end=end)
    k = 0.3
    radii, masses = np.array([0.5, 0.8]), np.array([1.0, 2.5])
    r_eff, m_eff = radii.prod() / radii.sum(), masses.prod() / masses.sum()
    sim = DSMC(State(None, [[1.0, 0.2, -0.4], [-0.3, 0.1, 0.6]], radii, masses, None),
               CollisionRule.viscoelastic(k, table), volume=10.0, seed=3)
    for _ in range(20):
        v0, e0 = sim.velocities, sim.kinetic_energy
        sim.run(np.inf, max_collisions=1)
        dv = sim.velocities[0] - v0[0]
        k_hat = -dv / np.linalg.norm(dv)  # v_i' = v_i - (1 + eps) m_j/M (g.k) k
        gn = (v0[0] - v0[1]) @ k_hat
        gn_after = (sim.velocities[0] - sim.velocities[1]) @ k_hat
        eps = -gn_after / gn
        beta = k * (r_eff * gn / m_eff**2) ** 0.2
        assert eps == pytest.approx(float(table.restitution(beta)), abs=1e-12)
        assert e0 - sim.kinetic_energy == pytest.approx(0.5 * (1 - eps**2) * m_eff * gn**2, rel=1e-9)
