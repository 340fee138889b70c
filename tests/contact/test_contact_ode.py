"""Direct integration of the contact ODE against closed forms and a second integrator."""

import numpy as np
import pytest

from granulargas.contact import ode
from tests.contact.truths import C1, C2, HERTZ_DURATION

BETAS = [1e-7, 1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0, 2.0, 5.0, 10.0]


def test_closed_form_constants_are_the_published_numbers():
    # guards the truths themselves (Ramirez et al. 1999 print C1 = 1.15344, C2 = 0.79826)
    assert C1 == pytest.approx(1.153449, abs=1e-6)
    assert C2 == pytest.approx(0.798267, abs=1e-6)
    assert HERTZ_DURATION == pytest.approx(3.21807, abs=1e-5)


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_elastic_limit_is_hertz(end):
    sol = ode.solve_contact(0.0, end)
    assert sol.restitution == pytest.approx(1.0, abs=1e-14)
    assert sol.duration == pytest.approx(HERTZ_DURATION, rel=1e-13)
    # maximum compression of the elastic contact: x_max = (5/4)^{2/5} (energy conservation)
    assert sol.max_compression == pytest.approx(1.25 ** 0.4, rel=1e-13)


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_slope_at_zero_is_minus_c1(end):
    # sensitivity equations at beta = 0 against the closed form of C1
    sol = ode.solve_contact(0.0, end)
    assert sol.restitution_derivative == pytest.approx(-C1, rel=1e-12)


def test_first_order_duration_is_seed_eq_33():
    # Schwager & Pöschel (1997), eq. (33): tau_c = Theta_c^0 (1 + C1 beta / 10) + O(beta^2)
    sol = ode.solve_contact(0.0, "overlap")
    assert sol.duration_derivative == pytest.approx(HERTZ_DURATION * C1 / 10, rel=1e-12)


def test_second_order_coefficient_is_c2():
    # (eps - 1 + C1 b) / b^2 -> C2 = (3/5) C1^2
    b = np.array([1e-3, 2e-3])
    eps = ode.solve_many(b, "overlap")[:, 0]
    c2 = (eps - 1 + C1 * b) / b ** 2
    # Richardson: c2(b) = C2 + c3 b
    assert 2 * c2[0] - c2[1] == pytest.approx(C2, rel=1e-6)


@pytest.mark.parametrize("end", ["overlap", "force"])
@pytest.mark.parametrize("beta", BETAS)
def test_taylor_agrees_with_scipy_dop853(end, beta):
    # two independent integrators of the regularised system: a Taylor-series method (ours)
    # and scipy's DOP853 Runge-Kutta with its own event location
    a = ode.solve_contact(beta, end)
    e, t = ode.solve_contact_scipy(beta, end, method="DOP853", rtol=1e-13, atol=1e-16)
    assert e == pytest.approx(a.restitution, rel=1e-10)
    assert t == pytest.approx(a.duration, rel=1e-10)


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_taylor_converged_in_its_own_tolerance(end):
    b = np.array(BETAS)
    ref = ode.solve_many(b, end)
    loose = ode.solve_many(b, end, order=20, tol=1e-14)
    np.testing.assert_allclose(loose[:, :2], ref[:, :2], rtol=1e-11, atol=0)


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_derivatives_match_finite_differences(end):
    b = np.array([0.05, 0.5, 3.0])
    d = 1e-5
    rows = ode.solve_many(b, end)
    fd = (ode.solve_many(b + d, end)[:, :2] - ode.solve_many(b - d, end)[:, :2]) / (2 * d)
    np.testing.assert_allclose(rows[:, 2:4], fd, rtol=1e-7, atol=1e-9)


def test_restitution_decreases_and_ends_agree_to_second_order():
    b = np.geomspace(1e-4, 10, 60)
    e_o = ode.solve_many(b, "overlap")[:, 0]
    e_f = ode.solve_many(b, "force")[:, 0]
    assert np.all(np.diff(e_o) < 0) and np.all(np.diff(e_f) < 0)
    assert np.all((e_o > 0) & (e_o < 1)) and np.all((e_f > 0) & (e_f < 1))
    # the force end keeps more energy (no tensile phase) ...
    assert np.all(e_f >= e_o)
    # ... and differs from beta^{5/2} on: the ratio settles to a constant for small beta
    small = b < 1e-3
    ratio = (e_f - e_o)[small] / b[small] ** 2.5
    assert np.ptp(ratio) < 0.05 * abs(ratio.mean())


def test_overlap_end_tau_difference_is_beta_at_small_beta():
    # near x = 0 the force end comes earlier by x / |x'| = beta (x + beta x' = 0)
    b = 1e-5
    t_o = ode.solve_contact(b, "overlap").duration
    t_f = ode.solve_contact(b, "force").duration
    assert t_o - t_f == pytest.approx(b, rel=1e-3)


def test_negative_or_nan_beta_rejected():
    with pytest.raises(ValueError):
        ode.solve_many([-0.1])
    with pytest.raises(ValueError):
        ode.solve_many([np.nan])
    with pytest.raises(ValueError):
        ode.solve_many([0.1], end="sideways")


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_numpy_twin_of_the_compiled_kernel_agrees(end):
    # the table is built by the numpy-vectorised twin (no compile); it must be the same integrator
    b = np.array([0.0, 1e-9, 1e-4, 0.3, 1.0, 4.0, 10.0])
    a = ode.solve_many(b, end, backend="numpy")
    r = ode.solve_many(b, end)
    np.testing.assert_allclose(a[:, :4], r[:, :4], rtol=1e-12, atol=1e-14)
