"""Oblique contact: the Taylor integrator against a Cartesian reference, closed forms and the head-on contact."""

import math

import numpy as np
import pytest

from granulargas.contact import duration, ode, restitution
from granulargas.contact import oblique as ob
from tests.contact.truths import HERTZ_DURATION

CASES = [  # beta, c, delta: near head-on, oblique, grazing, strongly damped, soft
    (0.3, 1.0, 0.1), (0.0, 0.5, 0.05), (1.0, 10.0, 0.2), (0.1, 0.01, 0.01),
    (0.05, 100.0, 0.001), (2.0, 0.02, 0.3), (0.5, 3.0, 0.45),
    (2.5, 0.0, 0.36), (1.0, 1e-12, 0.5),  # head-on: the force end's free flight alone limits the step
]


@pytest.mark.parametrize("end", ob.ENDS)
@pytest.mark.parametrize("beta, c, delta", CASES)
def test_taylor_polar_agrees_with_cartesian_dop853(beta, c, delta, end):
    """Two formulations: polar with the centrifugal term (Taylor) vs Cartesian (scipy), nothing shared."""
    a = ob.solve_oblique(beta, c, delta, end)
    r = ob.solve_oblique_cartesian(beta, c, delta, end)
    assert r["drift"] < 1e-11  # the Cartesian run kept w^2 = 1 - |r|
    assert a.restitution == pytest.approx(r["restitution"], abs=1e-11)
    assert a.duration == pytest.approx(r["duration"], rel=1e-11)
    assert a.rotation == pytest.approx(r["rotation"], abs=1e-11)
    assert a.turning == pytest.approx(r["turning"], rel=1e-10)
    assert a.force_duration == pytest.approx(r["force_duration"], rel=1e-11)
    out = ob.frame_outcome(a.restitution, a.duration, a.turning, beta, c, delta, 0.0, 1.0, math.sqrt(c / delta), 1.0)
    np.testing.assert_allclose(out.velocity, r["velocity"], rtol=0, atol=1e-11 * max(1.0, math.sqrt(c / delta)))
    np.testing.assert_allclose(out.position, r["position"], rtol=0, atol=1e-12)


@pytest.mark.parametrize("end", ob.ENDS)
@pytest.mark.parametrize("beta", [0.0, 1e-3, 0.1, 0.7, 2.0])
def test_head_on_is_todays_contact(beta, end):
    """c = 0: eps(beta) and tau_c(beta) of granulargas.contact, for any delta."""
    eps = restitution(beta, end=end)
    tau = duration(beta, end=end)
    for delta in (0.0, 0.01, 0.3):
        s = ob.solve_oblique(beta, 0.0, delta, end)
        assert s.restitution == pytest.approx(eps, abs=1e-13)
        assert s.force_restitution == pytest.approx(eps, abs=1e-13)
        assert s.force_duration == pytest.approx(tau, rel=1e-12)
        assert s.rotation == 0.0
        # separation: at the force end the spheres still overlap by x_f and fly apart at eps
        assert s.duration == pytest.approx(tau + s.force_overlap / eps, rel=1e-12)
        if end == "overlap" or beta == 0.0:
            assert s.force_overlap == 0.0 and s.duration == s.force_duration


@pytest.mark.parametrize("end", ob.ENDS)
@pytest.mark.parametrize("c, delta", [(0.3, 0.01), (5.0, 0.2), (1e4, 0.05)])
def test_elastic_contact_conserves_energy(c, delta, end):
    """beta = 0: no loss; at |r| = D the tangential speed is g_t again, so the normal one is g_n."""
    s = ob.solve_oblique(0.0, c, delta, end)
    assert s.restitution == pytest.approx(1.0, abs=1e-13)


def test_grazing_limit_is_the_free_chord():
    """c -> inf: the force is negligible against the centrifugal term, the relative motion a straight
    chord of the circle |r| = D: tau = 2 / (c + delta) and the normal turns by pi - 2 theta."""
    for delta in (0.01, 0.3):
        c = 1e8
        s = ob.solve_oblique(0.2, c, delta)
        theta = math.atan(math.sqrt(c / delta))
        assert s.duration * (c + delta) / 2 == pytest.approx(1.0, abs=1e-9)
        assert s.rotation == pytest.approx(math.pi - 2 * theta, rel=1e-8)
        assert s.restitution == pytest.approx(1.0, abs=1e-9)


def test_instantaneous_limit():
    """delta -> 0 at a fixed angle: the outcome tends to the instantaneous collision with eps(beta),
    the normal stops turning, and the pair lags behind by eps tau_c X along n_0."""
    beta, tan_theta = 0.4, 1.5
    eps, tau = restitution(beta), duration(beta)
    prev = None
    for delta in (1e-2, 1e-3, 1e-4):
        c = delta * tan_theta ** 2
        s = ob.solve_oblique(beta, c, delta)
        out = ob.frame_outcome(s.restitution, s.duration, s.turning, beta, c, delta, eps, 1.0, tan_theta, 1.0)
        err = np.max(np.abs(out.velocity - [eps, tan_theta]))
        assert err < 20 * delta  # first order in delta
        if prev is not None:
            assert 7 < prev / err < 13  # and no better: the correction is O(delta), not O(delta^2)
        prev = err
        x = delta  # X / D
        assert out.displacement[0] / x == pytest.approx(-eps * tau, rel=30 * delta)
        assert abs(out.displacement[1] / x) < 30 * delta


def test_hertz_duration_and_symmetry_of_the_elastic_head_on():
    s = ob.solve_oblique(0.0, 0.0, 0.2)
    assert s.duration == pytest.approx(HERTZ_DURATION, rel=1e-13)
    assert s.max_compression == pytest.approx(1.25 ** 0.4, rel=1e-12)


def test_taylor_converged_in_its_own_tolerance():
    b, c, d = np.array(CASES).T
    for end in ob.ENDS:
        ref = ob.solve_many(b, c, d, end)
        loose = ob.solve_many(b, c, d, end, order=20, tol=1e-14)
        np.testing.assert_allclose(loose[:, :3], ref[:, :3], rtol=1e-11, atol=1e-13)


def test_parameters_from_physical_units():
    """beta, delta, c of eq. (3) from g_n, g_t, D, rho, A; delta of equal spheres is set by the Mach number."""
    rng = np.random.default_rng(3)
    for _ in range(5):
        Y, nu, dens, radius, A = 10 ** rng.uniform(6, 11), rng.uniform(0, 0.45), rng.uniform(500, 8000), \
            10 ** rng.uniform(-4, -1), 10 ** rng.uniform(-8, -5)
        g_n, g_t = 10 ** rng.uniform(-2, 1, 2)
        m = dens * 4 / 3 * math.pi * radius ** 3
        rho = 2 * Y * math.sqrt(radius / 2) / (3 * (m / 2) * (1 - nu ** 2))
        beta, c, delta = ob.parameters(g_n, g_t, 2 * radius, rho, A)
        assert beta == pytest.approx(1.5 * A * rho ** 0.4 * g_n ** 0.2, rel=1e-13)
        assert c == pytest.approx(delta * (g_t / g_n) ** 2, rel=1e-13)
        mach = g_n / math.sqrt(Y / dens)
        assert delta == pytest.approx(0.5 * (math.sqrt(2) * math.pi * (1 - nu ** 2)) ** 0.4 * mach ** 0.8, rel=1e-12)


def test_bad_parameters_are_refused():
    with pytest.raises(ValueError, match="delta"):
        ob.solve_oblique(0.1, 1.0, 0.95)
    with pytest.raises(ValueError, match="beta"):
        ob.solve_oblique(-0.1, 1.0, 0.1)
    with pytest.raises(ValueError, match="end"):
        ob.solve_oblique(0.1, 1.0, 0.1, end="never")


def test_zeta_round_trip():
    c = np.array([0.0, 1e-6, 0.3, 1.0, 7.0, 1e8])
    np.testing.assert_allclose(ob.c_of_zeta(ob.zeta_of_c(c)), c, rtol=1e-8)
    assert ob.zeta_of_c(np.inf) == 1.0 and ob.zeta_of_c(1.0) == 0.5


def test_compression_constant_of_a_pair():
    """X = q (m_eff^2 g^4 / R_eff)^{1/5} equals (g^2 / rho)^{2/5},
    rho = 2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2)) (Schwager & Poeschel 1997)."""
    from granulargas.contact.material import rho_from_material

    Y, nu = 3.3e9, 0.27
    q = ob.compression_prefactor(Y, nu)
    for ri, rj, mi, mj, g in [(0.5, 0.5, 1.0, 1.0, 1.0), (0.3, 0.7, 0.4, 2.5, 0.2), (1e-3, 2e-3, 1e-5, 3e-5, 7.0)]:
        r_eff, m_eff = ri * rj / (ri + rj), mi * mj / (mi + mj)
        rho = rho_from_material(Y, nu, r_eff, m_eff)
        x = ob.pair_compression_constant(q, ri, rj, mi, mj) * g ** 0.8
        assert x == pytest.approx((g * g / rho) ** 0.4, rel=1e-13)
    with pytest.raises(ValueError):
        ob.compression_prefactor(-1.0, 0.3)
