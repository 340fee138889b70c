"""High-order series: closed forms, the ODE, the radius of convergence, divergence beyond it."""

import warnings

import numpy as np
import pytest

from granulargas.contact import ode, restitution, series, series_coefficients
from granulargas.contact.series import SeriesDivergenceWarning
from tests.contact.truths import C1, C2, HERTZ_DURATION


def test_overlap_coefficients_start_with_closed_forms():
    c = series_coefficients(6, end="overlap")
    assert c[0] == pytest.approx(1.0, abs=1e-15)
    assert c[1] == pytest.approx(-C1, rel=1e-13)
    assert c[2] == pytest.approx(C2, rel=1e-13)


def test_duration_series_starts_with_hertz_and_seed_eq_33():
    d = series.duration_coefficients(4, end="overlap")
    assert d[0] == pytest.approx(HERTZ_DURATION, rel=1e-14)
    assert d[1] == pytest.approx(HERTZ_DURATION * C1 / 10, rel=1e-12)


def test_force_series_in_sqrt_beta():
    c = series_coefficients(8, end="force")
    o = series_coefficients(4, end="overlap")
    # same as overlap through beta^2 = u^4, then a u^5 term
    np.testing.assert_allclose(c[[0, 2, 4]], o[[0, 1, 2]], rtol=1e-13)
    assert c[1] == 0 and c[3] == 0
    # c5 = 4/15: also the u^5 coefficient of the Mueller-Poeschel Pade approximant (independent)
    assert c[5] == pytest.approx(4 / 15, rel=1e-12)
    # the force duration ends earlier by beta at first order: tau = Theta - ... with d2 = d1(overlap) - 1
    d = series.duration_coefficients(4, end="force")
    assert d[2] == pytest.approx(HERTZ_DURATION * C1 / 10 - 1.0, rel=1e-12)


@pytest.mark.parametrize("end,order,beta,tol", [
    ("overlap", 20, 0.1, 1e-14), ("overlap", 20, 0.5, 1e-8),
    ("force", 30, 0.1, 1e-13), ("force", 30, 0.4, 1e-7),
])
def test_high_order_sums_match_the_ode(end, order, beta, tol):
    e = ode.solve_many(beta, end)[0]
    assert restitution(beta, method="series", end=end, order=order) == pytest.approx(e[0], abs=tol)
    tau = series.duration_series(beta, end=end, order=order)
    assert tau == pytest.approx(e[1], abs=10 * tol)


def test_overlap_radius_from_coefficients_matches_the_ode_fold():
    # independent: Domb-Sykes ratio fit on the coefficients vs B* = max beta eps^{1/5} from the ODE
    r_ode = series.radius_of_convergence("overlap")
    assert r_ode == pytest.approx(1.38836, abs=1e-4)
    # fit window: after the irregular low orders (the duration ratios settle from k ~ 8), up to the
    # last reliable order
    r_coeff = series.domb_sykes_radius(series.restitution_coefficients(22, "overlap"), 10, 22)
    assert r_coeff == pytest.approx(r_ode, rel=1e-2)  # ratio fits converge slowly
    r_tau = series.domb_sykes_radius(series.duration_coefficients(22, "overlap"), 10, 22)
    assert r_tau == pytest.approx(r_ode, rel=1e-2)


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_partial_sums_converge_inside_and_diverge_outside(end):
    # the truncated series is useless beyond the radius: errors grow with the order there
    R = series.radius_of_convergence(end)
    n = series.MAX_RELIABLE_ORDER[end]
    c = series.restitution_coefficients(n, end)
    k = np.arange(n + 1)

    def errors(beta):
        x = beta if end == "overlap" else np.sqrt(beta)
        return np.abs(np.cumsum(c * x ** k) - ode.solve_many(beta, end)[0, 0])

    inside, outside = errors(0.6 * R), errors(1.4 * R)
    assert inside[-1] < 1e-4 and inside[-1] < 1e-2 * inside[4]
    assert outside[-1] > 1.0 and outside[-1] > 10 * outside[4]


def test_series_beyond_radius_warns_or_raises():
    with pytest.warns(SeriesDivergenceWarning, match="radius of convergence"):
        restitution(2.0, method="series")
    with pytest.raises(ValueError, match="radius of convergence"):
        series.restitution_series(2.0, on_divergence="raise")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        restitution(0.5, method="series")
        restitution(0.5, method="series", end="force")


def test_unreliable_order_warns():
    with pytest.warns(SeriesDivergenceWarning, match="round-off"):
        series_coefficients(series.MAX_RELIABLE_ORDER["overlap"] + 5)
