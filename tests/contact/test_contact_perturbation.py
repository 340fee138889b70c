"""The perturbation route of Schwager & Pöschel (1997) (eqs. 13-33) against closed forms and the ODE."""

import pytest
from scipy.integrate import solve_ivp

from granulargas.contact import perturbation
from granulargas.contact.ode import _rhs
from tests.contact.truths import C1, C2, HERTZ_DURATION, HERTZ_MAX_COMPRESSION


def test_perturbation_route_gives_closed_form_constants():
    c = perturbation.perturbation_constants()
    assert c.theta_c0 == pytest.approx(HERTZ_DURATION, rel=1e-12)
    assert c.x0 == pytest.approx(HERTZ_MAX_COMPRESSION, rel=1e-12)
    assert c.C1 == pytest.approx(C1, rel=1e-12)
    assert c.C2 == pytest.approx(C2, rel=1e-12)
    assert c.duration_slope == pytest.approx(HERTZ_DURATION * C1 / 10, rel=1e-12)


def test_perturbation_route_insensitive_to_the_start_time():
    a = perturbation.perturbation_constants(t0=1e-2)
    b = perturbation.perturbation_constants(t0=1e-4)
    assert a.C1 == pytest.approx(b.C1, rel=1e-12) and a.beta26 == pytest.approx(b.beta26, rel=1e-10)


def _x_at(t_target, beta):
    # x(t) from the regularised ODE (w, p, t in s), stopped when t reaches t_target
    def ev(s, y, b):
        return y[2] - t_target
    ev.terminal = True
    sol = solve_ivp(_rhs, (0, 10), [0, 1, 0], method="DOP853", rtol=1e-13, atol=1e-16, events=ev, args=(beta,))
    return sol.y_events[0][0][0] ** 2


@pytest.mark.parametrize("beta", [0.2, 1.0])
def test_eq13_is_the_small_time_solution(beta):
    # the truncation error of eq. 13 must shrink like the first omitted terms (~ t^{13/2})
    errs = []
    for t in (0.1, 0.05):
        x13, _ = perturbation.puiseux_x(t, beta, order=3)
        errs.append(abs(x13 - _x_at(t, beta)))
    assert errs[0] < 1e-6
    assert errs[1] < errs[0] / 2 ** 5.5


def test_eq14_second_order_expansion_of_the_trajectory():
    # x(t) - (x0 + b x1 + b^2 x2) = O(b^3) at fixed t (halving b divides by ~8)
    sol, t_m = perturbation.perturbation_solution(None)
    x0, _, x1, _, x2, _ = sol(t_m)
    errs = [abs(_x_at(t_m, b) - (x0 + b * x1 + b * b * x2)) for b in (0.02, 0.01)]
    assert errs[0] / errs[1] == pytest.approx(8.0, rel=0.1)
