"""The rough collision law (engine/_rough.py) on random contacts: every invariant of the rule,
checked from the velocities and spins before and after, and the outcome against the
reference's rigid-body impulse (tests/engine/reference.py), 2D and 3D, mixed sizes and masses."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from granulargas.engine._rough import TANGENTIAL_CONSTANT, TANGENTIAL_COULOMB
from tests.engine import kernels
from tests.engine.reference import apply_rough_impulse, rough_impulse

speed = st.floats(-3.0, 3.0)
positive = st.floats(0.2, 5.0)


@st.composite
def contacts(draw, dim=None):
    """A pair at contact, approaching: (dim, v_i, v_j, w_i, w_j, n, m_i, m_j, kappa_i, kappa_j, R_i, R_j)."""
    dim = draw(st.sampled_from([2, 3])) if dim is None else dim
    kmax = 2.0 / 3.0 if dim == 3 else 1.0
    n = np.array([draw(st.floats(-1, 1)) for _ in range(3)])
    if dim == 2:
        n[2] = 0.0
    if np.linalg.norm(n) < 0.1:
        n = np.array([1.0, 0.0, 0.0])
    n /= np.linalg.norm(n)
    vi = np.array([draw(speed) for _ in range(3)])
    vj = np.array([draw(speed) for _ in range(3)])
    wi = np.array([draw(speed) for _ in range(3)])
    wj = np.array([draw(speed) for _ in range(3)])
    if dim == 2:
        vi[2] = vj[2] = 0.0
        wi[:2] = wj[:2] = 0.0
    un = (vi - vj) @ n
    if un > -0.05:  # make it approach
        vi -= (un + 0.05 + draw(st.floats(0.0, 2.0))) * n
    ks = st.floats(0.05 * kmax, kmax)
    return (dim, vi, vj, wi, wj, n, draw(positive), draw(positive), draw(ks), draw(ks),
            draw(st.floats(0.1, 2.0)), draw(st.floats(0.1, 2.0)))


def contact_velocity(vi, vj, wi, wj, n, ri, rj):
    """g = (v_i + w_i x (-R_i n)) - (v_j + w_j x (R_j n)): from the definition, not the kernel."""
    return (vi + np.cross(wi, -ri * n)) - (vj + np.cross(wj, rj * n))


def split(g, n):
    gn = (g @ n) * n
    return gn, g - gn


def energy(v, w, m, k, r):
    return 0.5 * m * v @ v + 0.5 * k * m * r * r * w @ w


def collide(c, eps, model, beta, mu):
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    out = [a.copy() for a in (vi, vj, wi, wj)]
    loss, impulse = kernels.rough_pair(*out, n, mi, mj, ki, kj, ri, rj, eps, model, beta, mu)
    return out, loss, impulse


def scale(c):
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    g = contact_velocity(vi, vj, wi, wj, n, ri, rj)
    return 1.0 + float(np.linalg.norm(g)) + float(np.linalg.norm(vi - vj))


@settings(max_examples=300, deadline=None)
@given(contacts(), st.floats(0.0, 1.0), st.floats(-1.0, 1.0))
def test_constant_model_reverses_normal_and_tangential_contact_velocity(c, eps, beta):
    """g_n' = -eps g_n and g_t' = -beta_t g_t (the sign convention: beta_t = -1 smooth)."""
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    (vi2, vj2, wi2, wj2), _, _ = collide(c, eps, TANGENTIAL_CONSTANT, beta, 0.0)
    gn, gt = split(contact_velocity(vi, vj, wi, wj, n, ri, rj), n)
    gn2, gt2 = split(contact_velocity(vi2, vj2, wi2, wj2, n, ri, rj), n)
    tol = 1e-12 * scale(c)
    np.testing.assert_allclose(gn2, -eps * gn, atol=tol)
    np.testing.assert_allclose(gt2, -beta * gt, atol=tol)


@settings(max_examples=300, deadline=None)
@given(contacts(), st.floats(0.0, 1.0), st.floats(-1.0, 1.0), st.floats(0.0, 2.0),
       st.sampled_from([TANGENTIAL_CONSTANT, TANGENTIAL_COULOMB]))
def test_momentum_and_angular_momentum_about_the_contact_point(c, eps, beta, mu, model):
    """Linear momentum and each particle's angular momentum about the contact point are conserved
    (the impulse acts there), hence also the total angular momentum about any point."""
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    (vi2, vj2, wi2, wj2), _, _ = collide(c, eps, model, beta, mu)
    tol = 1e-12 * scale(c) * (1.0 + mi + mj) * (1.0 + ri + rj) ** 2
    np.testing.assert_allclose(mi * vi2 + mj * vj2, mi * vi + mj * vj, atol=tol)
    xi, xj = ri * n, -rj * n  # centres relative to the contact point
    for x, m, k, r, v, w, v2, w2 in ((xi, mi, ki, ri, vi, wi, vi2, wi2), (xj, mj, kj, rj, vj, wj, vj2, wj2)):
        before = m * np.cross(x, v) + k * m * r * r * w
        after = m * np.cross(x, v2) + k * m * r * r * w2
        np.testing.assert_allclose(after, before, atol=tol)
    origin = np.array([0.3, -1.1, 0.7])
    total = [mi * np.cross(xi - origin, a) + ki * mi * ri * ri * b + mj * np.cross(xj - origin, c2)
             + kj * mj * rj * rj * d for a, b, c2, d in ((vi, wi, vj, wj), (vi2, wi2, vj2, wj2))]
    np.testing.assert_allclose(total[1], total[0], atol=tol * 10)


@settings(max_examples=300, deadline=None)
@given(contacts(), st.floats(0.0, 1.0), st.floats(-1.0, 1.0), st.floats(0.0, 2.0),
       st.sampled_from([TANGENTIAL_CONSTANT, TANGENTIAL_COULOMB]))
def test_energy_loss_is_the_kinetic_energy_lost_and_the_closed_form(c, eps, beta, mu, model):
    """The reported loss equals the drop of translational plus rotational energy; for the constant
    model it is (m_eff/2)(1 - eps^2) g_n^2 + (m_t/2)(1 - beta_t^2)|g_t|^2 with
    1/m_t = 1/m_i + 1/m_j + 1/(kappa_i m_i) + 1/(kappa_j m_j)."""
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    (vi2, vj2, wi2, wj2), loss, impulse = collide(c, eps, model, beta, mu)
    e0 = energy(vi, wi, mi, ki, ri) + energy(vj, wj, mj, kj, rj)
    e1 = energy(vi2, wi2, mi, ki, ri) + energy(vj2, wj2, mj, kj, rj)
    tol = 1e-11 * (1.0 + e0)
    assert loss == pytest.approx(e0 - e1, abs=tol)
    assert loss >= -tol
    gn, gt = split(contact_velocity(vi, vj, wi, wj, n, ri, rj), n)
    m_eff = mi * mj / (mi + mj)
    assert impulse == pytest.approx((1.0 + eps) * m_eff * float(gn @ n), rel=1e-12)
    if model == TANGENTIAL_CONSTANT:
        m_t = 1.0 / (1 / mi + 1 / mj + 1 / (ki * mi) + 1 / (kj * mj))
        closed = 0.5 * m_eff * (1 - eps**2) * gn @ gn + 0.5 * m_t * (1 - beta**2) * gt @ gt
        assert loss == pytest.approx(closed, abs=tol)


@settings(max_examples=100, deadline=None)
@given(contacts(), st.floats(0.0, 1.0), st.floats(-1.0, 1.0))
def test_equal_particles_lose_the_textbook_energy(c, eps, beta):
    """Identical particles: (m_eff/2)(1 - eps^2) g_n^2 + (m_eff/2)(kappa/(1 + kappa))(1 - beta^2)|g_t|^2."""
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    c = (dim, vi, vj, wi, wj, n, mi, mi, ki, ki, ri, ri)
    _, loss, _ = collide(c, eps, TANGENTIAL_CONSTANT, beta, 0.0)
    gn, gt = split(contact_velocity(vi, vj, wi, wj, n, ri, ri), n)
    m_eff = mi / 2
    expected = 0.5 * m_eff * (1 - eps**2) * gn @ gn + 0.5 * m_eff * ki / (1 + ki) * (1 - beta**2) * gt @ gt
    assert loss == pytest.approx(expected, rel=1e-11, abs=1e-13)


@settings(max_examples=300, deadline=None)
@given(contacts(), st.floats(0.0, 1.0), st.floats(-1.0, 1.0), st.floats(0.0, 2.0))
def test_coulomb_sticks_within_the_cone_and_slides_on_it(c, eps, beta0, mu):
    """Walton's model: the tangential impulse is at most mu |J_n|; a sticking contact gets
    g_t' = -beta_0 g_t, a sliding one keeps the slip direction with g_t' between -beta_0 g_t
    and g_t."""
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    (vi2, vj2, wi2, wj2), _, _ = collide(c, eps, TANGENTIAL_COULOMB, beta0, mu)
    J = mi * (vi2 - vi)
    Jn, Jt = split(J, n)
    gn, gt = split(contact_velocity(vi, vj, wi, wj, n, ri, rj), n)
    _, gt2 = split(contact_velocity(vi2, vj2, wi2, wj2, n, ri, rj), n)
    tol = 1e-10 * scale(c) * (1 + mi)
    assert np.linalg.norm(Jt) <= mu * np.linalg.norm(Jn) + tol
    stuck = np.allclose(gt2, -beta0 * gt, atol=tol)
    if not stuck:
        assert np.linalg.norm(Jt) == pytest.approx(mu * np.linalg.norm(Jn), abs=tol)
        g2 = float(gt @ gt)
        ratio = float(gt2 @ gt) / g2  # -beta_t of the collision
        np.testing.assert_allclose(gt2, ratio * gt, atol=tol)
        assert -beta0 - 1e-9 <= ratio <= 1.0 + 1e-9


@settings(max_examples=200, deadline=None)
@given(contacts(), st.floats(0.0, 1.0), st.floats(-1.0, 1.0), st.one_of(st.none(), st.floats(0.0, 2.0)))
def test_kernel_matches_the_reference_impulse(c, eps, beta, mu):
    """The engine's closed form (eqs. (2)-(3) of engine/_rough.py) against the reference's
    rigid-body impulse solved with the 3x3 matrix K."""
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    model = TANGENTIAL_CONSTANT if mu is None else TANGENTIAL_COULOMB
    (vi2, vj2, wi2, wj2), _, _ = collide(c, eps, model, beta, 0.0 if mu is None else mu)
    Ii, Ij = ki * mi * ri**2, kj * mj * rj**2
    J = rough_impulse(vi, vj, wi, wj, n, mi, mj, Ii, Ij, ri, rj, eps, beta, mu)
    ref = apply_rough_impulse(vi, vj, wi, wj, n, mi, mj, Ii, Ij, ri, rj, J)
    tol = 1e-10 * scale(c) * (1 + 1 / min(mi, mj)) * (1 + 1 / min(ri, rj)) * (1 + 1 / min(ki, kj))
    for a, b in zip((vi2, vj2, wi2, wj2), ref):
        np.testing.assert_allclose(a, b, atol=tol)


@settings(max_examples=100, deadline=None)
@given(contacts(dim=2), st.floats(0.0, 1.0), st.floats(-1.0, 1.0), st.floats(0.0, 2.0),
       st.sampled_from([TANGENTIAL_CONSTANT, TANGENTIAL_COULOMB]))
def test_disks_stay_in_the_plane(c, eps, beta, mu, model):
    """2D: v_z stays 0 and only the z spin changes."""
    (vi2, vj2, wi2, wj2), _, _ = collide(c, eps, model, beta, mu)
    assert vi2[2] == vj2[2] == 0.0
    assert wi2[0] == wi2[1] == wj2[0] == wj2[1] == 0.0


@settings(max_examples=200, deadline=None)
@given(contacts(), st.floats(0.0, 1.0))
def test_smooth_limit_is_the_smooth_law_bit_for_bit(c, eps):
    """beta_t = -1: velocities, loss and impulse of the smooth law exactly, spins untouched."""
    dim, vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj = c
    (vi2, vj2, wi2, wj2), loss, impulse = collide(c, eps, TANGENTIAL_CONSTANT, -1.0, 0.0)
    si, sj = vi.copy(), vj.copy()
    loss_s, impulse_s = kernels.smooth_pair(si, sj, n, mi, mj, eps)
    assert np.array_equal(vi2, si) and np.array_equal(vj2, sj)
    assert np.array_equal(wi2, wi) and np.array_equal(wj2, wj)
    assert loss == loss_s and impulse == impulse_s


@st.composite
def wall_contacts(draw):
    dim = draw(st.sampled_from([2, 3]))
    axis = draw(st.integers(0, dim - 1))
    side = draw(st.integers(0, 1))
    n = np.zeros(3)
    n[axis] = 1.0 if side == 0 else -1.0
    v = np.array([draw(speed) for _ in range(3)])
    w = np.array([draw(speed) for _ in range(3)])
    if dim == 2:
        v[2] = 0.0
        w[:2] = 0.0
    vn = v @ n
    if vn > -0.05:
        v -= (vn + 0.05 + draw(st.floats(0.0, 2.0))) * n
    kmax = 2.0 / 3.0 if dim == 3 else 1.0
    return dim, v, w, n, draw(positive), draw(st.floats(0.05 * kmax, kmax)), draw(st.floats(0.1, 2.0))


@settings(max_examples=300, deadline=None)
@given(wall_contacts(), st.floats(0.0, 1.0), st.floats(-1.0, 1.0), st.floats(0.0, 2.0),
       st.sampled_from([TANGENTIAL_CONSTANT, TANGENTIAL_COULOMB]))
def test_rough_wall(c, eps, beta, mu, model):
    """A wall at rest: normal contact velocity -eps, tangential -beta_t (constant model), angular
    momentum about the contact point conserved, the loss the energy lost, the reference's impulse."""
    dim, v, w, n, m, k, r = c
    v2, w2 = v.copy(), w.copy()
    loss, momentum = kernels.rough_wall(v2, w2, n, m, k, r, eps, model, beta, mu)
    g = v + np.cross(w, -r * n)
    g2 = v2 + np.cross(w2, -r * n)
    gn, gt = split(g, n)
    gn2, gt2 = split(g2, n)
    tol = 1e-12 * (1 + np.linalg.norm(g)) * (1 + m) * (1 + r) ** 2
    np.testing.assert_allclose(gn2, -eps * gn, atol=tol)
    if model == TANGENTIAL_CONSTANT:
        np.testing.assert_allclose(gt2, -beta * gt, atol=tol)
    x = r * n
    np.testing.assert_allclose(m * np.cross(x, v2) + k * m * r * r * w2, m * np.cross(x, v) + k * m * r * r * w,
                               atol=tol)
    assert loss == pytest.approx(energy(v, w, m, k, r) - energy(v2, w2, m, k, r), abs=1e-11 * (1 + m * v @ v))
    assert momentum == pytest.approx((1 + eps) * m * abs(v @ n), rel=1e-12)
    zero = np.zeros(3)
    J = rough_impulse(v, zero, w, zero, n, m, np.inf, k * m * r * r, np.inf, r, 0.0, eps, beta,
                      None if model == TANGENTIAL_CONSTANT else mu)
    ref_v, _, ref_w, _ = apply_rough_impulse(v, zero, w, zero, n, m, np.inf, k * m * r * r, np.inf, r, 0.0, J)
    np.testing.assert_allclose(v2, ref_v, atol=tol * 10)
    np.testing.assert_allclose(w2, ref_w, atol=tol * 10 / (k * r))


def test_perfectly_rough_elastic_collision_conserves_energy():
    """eps = beta_t = 1 loses nothing, whatever the spins (a sanity case of eq. (4))."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        vi, vj, wi, wj = rng.normal(size=(4, 3))
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        if (vi - vj) @ n >= 0:
            vi, vj = vj, vi
        c = (3, vi, vj, wi, wj, n, 1.3, 0.7, 0.4, 0.5, 0.6, 0.4)
        _, loss, _ = collide(c, 1.0, TANGENTIAL_CONSTANT, 1.0, 0.0)
        assert abs(loss) < 1e-13 * 100
