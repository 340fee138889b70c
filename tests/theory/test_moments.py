"""Collision moments of the first Sonine approximation (granulargas.theory.moments) against
closed forms for constant eps (van Noije & Ernst 1998; Brilliantov & Pöschel 2004), the full
Gauss-Hermite product grid node by node, and a direct Monte Carlo average of the collision
integral for the viscoelastic eps(g)."""

import math

import numpy as np
import pytest

from granulargas import theory as th
from granulargas.contact import restitution_table
from granulargas.theory.moments import collision_moments, moment_coefficients, solid_angle, speed_quadrature


def _const(eps, dim):
    return np.full(speed_quadrature(dim).u.size, eps)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("eps", [0.3, 0.8, 0.95, 1.0])
def test_constant_restitution_closed_forms(dim, eps):
    # mu_2 = (Omega_d / (2 sqrt(2 pi))) (1 - eps^2)(1 + 3 a2/16): the Enskog cooling rate
    # zeta = omega_0 (1 - eps^2)(1 + 3 a2/16)/d; nu_0 = Omega_d / sqrt(2 pi) (1 - a2/16)
    pref = solid_angle(dim) / math.sqrt(2 * math.pi)
    for a2 in (0.0, 0.1, -0.05):
        nu, mu2, mu4 = collision_moments(_const(eps, dim), a2, dim)
        assert nu == pytest.approx(pref * (1 - a2 / 16), rel=1e-12)
        assert mu2 == pytest.approx(pref / 2 * (1 - eps**2) * (1 + 3 * a2 / 16), rel=1e-10, abs=1e-13)
    # mu_4 at a2 = 0: Brilliantov & Pöschel (2004), 3D sqrt(2 pi)(9/2 + eps^2)(1 - eps^2);
    # 2D sqrt(pi/2)(7/2 + eps^2)(1 - eps^2)
    _, _, mu4 = collision_moments(_const(eps, dim), 0.0, dim)
    assert mu4 == pytest.approx(pref / 2 * (dim + 1.5 + eps**2) * (1 - eps**2), rel=1e-10, abs=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("eps", [0.2, 0.5, 0.7, 0.9, 0.99])
def test_stationary_a2_is_van_noije_ernst(dim, eps):
    # da2/dt = 0 in eq. (6), linear in a2, gives van Noije & Ernst's a2 exactly
    _, mu2, mu4 = moment_coefficients(_const(eps, dim), dim)
    (A0, A1), (B0, B1) = mu2, mu4
    a2 = (B0 - (dim + 2) * A0) / ((dim + 2) * (A0 + A1) - B1)
    assert a2 == pytest.approx(th.sonine_a2(eps, dim), rel=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_elastic_gas_keeps_the_maxwellian_and_relaxes_a2(dim):
    _, mu2, mu4 = moment_coefficients(_const(1.0, dim), dim)
    assert abs(mu2[0]) < 1e-13 and abs(mu2[1]) < 1e-13
    assert abs(mu4[0]) < 1e-12
    assert mu4[1] > 0  # da2/dt = -(4/d) nu_c mu_4 / (d + 2): a2 decays


@pytest.mark.parametrize("dim", [2, 3])
def test_quadrature_is_the_product_grid(dim):
    # speed_quadrature merges transverse grid points and reads the eps-polynomial off five
    # samples; here the full 5^(2d-1)-point Gauss-Hermite product grid over C and the transverse
    # part of c, with the collision rule (3) applied at each eps directly: the averages of
    # Delta(c1^p + c2^p) at every node c_n = u_j, per unit nu_0 weight, with the a2 weight or not
    q = speed_quadrature(dim)
    z, wz = np.polynomial.hermite_e.hermegauss(5)
    k = 2 * dim - 1
    pts = np.stack(np.meshgrid(*[z] * k, indexing="ij"), axis=-1).reshape(-1, k)
    wts = np.prod(np.stack(np.meshgrid(*[wz / math.sqrt(2 * math.pi)] * k, indexing="ij"), axis=-1).reshape(-1, k), 1)
    C = 0.5 * pts[:, None, :dim]  # (G, 1, d)
    c = np.concatenate([np.broadcast_to(pts[:, None, dim:], (wts.size, q.u.size, dim - 1)),
                        np.broadcast_to(q.u[None, :, None], (wts.size, q.u.size, 1))], axis=-1)  # (G, J, d)
    c1, c2 = C + 0.5 * c, C - 0.5 * c
    x1, x2 = (c1 * c1).sum(-1), (c2 * c2).sum(-1)
    s2 = sum(0.5 * x * x - 0.5 * (dim + 2) * x + dim * (dim + 2) / 8 for x in (x1, x2))
    np.testing.assert_allclose(q.nu[:, 1] / q.nu[:, 0], wts @ s2, rtol=1e-12, atol=1e-12)
    for eps in (0.0, 0.37, 0.8, 1.0):
        e = np.zeros(dim)
        e[-1] = 1.0
        kick = (0.5 * (1 + eps) * q.u)[None, :, None] * e
        y1, y2 = ((v * v).sum(-1) for v in (c1 - kick, c2 + kick))
        powers = eps ** np.arange(5)
        for name, p in (("mu2", 1), ("mu4", 2)):
            change = y1**p + y2**p - x1**p - x2**p
            size = y1**p + y2**p + x1**p + x2**p  # the round-off of the sum scales with its terms
            ours = np.einsum("jkl,k->jl", getattr(q, name), powers) / q.nu[:, :1]
            for col, weight in ((0, 1.0), (1, s2)):
                direct = -0.5 * (wts @ (change * weight))
                scale = 0.5 * (wts @ (size * np.abs(weight)))
                assert np.all(np.abs(ours[:, col] - direct) <= 1e-13 * scale), (name, eps, col)


def test_quadrature_converges():
    q, fine = speed_quadrature(3), speed_quadrature(3, nodes=192, hermite=7)
    for a, b in ((q.nu.sum(0), fine.nu.sum(0)), (q.mu2.sum(0), fine.mu2.sum(0)), (q.mu4.sum(0), fine.mu4.sum(0))):
        np.testing.assert_allclose(a, b, rtol=1e-11, atol=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_viscoelastic_moments_against_monte_carlo(dim):
    # Direct Monte Carlo of eqs. (4), (8): c1, c2 ~ phi (variance 1/2 per component),
    # e uniform, the viscoelastic eps(g_n) of a gas at temperature T with pair constant b;
    # both a2 coefficients (weights 1 and S2(c1^2) + S2(c2^2)).
    rng = np.random.default_rng(7)
    N, b, T = 400_000, 0.3, 2.0
    vT = math.sqrt(2 * T)
    c1, c2 = rng.normal(0, math.sqrt(0.5), (2, N, dim))
    e = rng.normal(size=(N, dim))
    e /= np.linalg.norm(e, axis=1)[:, None]
    cn = np.einsum("ij,ij->i", c1 - c2, e)
    keep = cn > 0
    c1, c2, e, cn = c1[keep], c2[keep], e[keep], cn[keep]
    beta = b * (vT * cn) ** 0.2
    u = speed_quadrature(dim).u
    table = restitution_table(b * (vT * max(u.max(), cn.max())) ** 0.2 * 1.01)
    eps = table.restitution(beta)
    p1 = c1 - (0.5 * (1 + eps) * cn)[:, None] * e
    p2 = c2 + (0.5 * (1 + eps) * cn)[:, None] * e
    x1, x2, y1, y2 = ((v * v).sum(1) for v in (c1, c2, p1, p2))
    s2 = 0.5 * x1**2 - 0.5 * (dim + 2) * x1 + 0.5 * x2**2 - 0.5 * (dim + 2) * x2 + 2 * dim * (dim + 2) / 8
    omega = solid_angle(dim)
    samples = {
        "nu": omega * cn, "mu2": -0.5 * omega * cn * (y1 + y2 - x1 - x2),
        "mu4": -0.5 * omega * cn * (y1**2 + y2**2 - x1**2 - x2**2),
    }
    nodes = table.restitution(b * (vT * u) ** 0.2)
    ours = dict(zip(("nu", "mu2", "mu4"), moment_coefficients(nodes, dim)))
    for name, s in samples.items():
        for weight, col in ((np.ones_like(s2), 0), (s2, 1)):
            x = np.zeros(N)
            x[keep] = s * weight  # the Theta(c_n) = 0 samples count as zeros
            mc, se = x.mean(), x.std() / math.sqrt(N)
            assert abs(ours[name][col] - mc) < 5 * se, (name, col, ours[name][col], mc, se)
