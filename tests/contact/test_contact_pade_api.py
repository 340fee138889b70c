"""Public API by each method, Pade approximant, and where the methods fail."""


import numpy as np
import pytest

from granulargas.contact import duration, ode, restitution, restitution_table
from granulargas.contact.pade import restitution_pade
from tests.contact.truths import C1, C2, HERTZ_DURATION


def test_duration_zero_is_hertz():
    assert duration(0.0) == pytest.approx(HERTZ_DURATION, rel=1e-14)
    assert duration(0.0, end="force") == pytest.approx(HERTZ_DURATION, rel=1e-14)
    assert duration(0.0, method="series") == pytest.approx(HERTZ_DURATION, rel=1e-14)


@pytest.mark.parametrize("method", ["ode", "series", "table"])
@pytest.mark.parametrize("end", ["overlap", "force"])
def test_methods_agree_where_all_are_valid(method, end, cache_dir):
    b = np.array([[0.0, 1e-3], [0.01, 0.05]])
    e = restitution(b, method=method, end=end, order=10)
    assert e.shape == b.shape
    np.testing.assert_allclose(e, restitution(b, end=end), atol=1e-8)
    assert isinstance(restitution(0.01, method=method, end=end), float)


def test_pade_is_percent_accurate_for_the_force_end():
    b = np.geomspace(1e-4, 10, 50)
    exact = ode.solve_many(b, "force")[:, 0]
    p = restitution(b, method="pade", end="force")
    assert np.max(np.abs(p - exact)) < 0.01
    # through u^5 it is the force series: 1 - C1 b + C2 b^2 + (4/15) b^{5/2}
    b = 1e-4
    expected = 1 - C1 * b + C2 * b ** 2 + 4 / 15 * b ** 2.5
    assert restitution_pade(b) == pytest.approx(expected, abs=1e-12)  # next term ~ u^6 = 1e-12
    with pytest.warns(UserWarning, match="force"):
        restitution(0.1, method="pade", end="overlap")


def test_bad_method_or_end():
    with pytest.raises(ValueError, match="method"):
        restitution(0.1, method="magic")
    with pytest.raises(ValueError, match="end"):
        restitution(0.1, end="middle")
    with pytest.raises(ValueError):
        duration(0.1, method="pade")


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_naive_integrator_from_x0_loses_accuracy(end):
    # RK4 on x(t) started at x = 0 (end located to fourth order): the sqrt(x) singularity caps the
    # observed order near 3/2 instead of 4
    b = 0.5
    exact = ode.solve_many(b, end)[0, 0]
    dts = np.array([0.02, 0.01, 0.005])
    errs = np.array([abs(ode.solve_contact_naive(b, end, dt)[0] - exact) for dt in dts])
    order = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert 1.0 < order < 2.5
    # even at 650 steps it is far worse than the regularised integrator's ~15 steps (1e-15)
    assert errs[-1] > 1e-7
    assert ode.solve_many(b, end)[0, 5] < 30


def test_table_method_refuses_beyond(cache_dir):
    from granulargas.errors import TableRangeError

    t = restitution_table(0.5)
    with pytest.raises(TableRangeError):
        t.restitution(0.6)
    # the API builds a table large enough instead of extrapolating
    assert restitution(0.6, method="table") == pytest.approx(restitution(0.6), abs=1e-8)


def test_written_out_c1_is_scipys_gamma_expression():
    # pade.C1 is a literal (the contact module loads no scipy): it must be the bits of the expression
    import math

    from scipy.special import gamma

    from granulargas.contact import pade

    expected = gamma(0.6) * math.sqrt(math.pi) / (2 ** 0.2 * 5 ** 0.4 * gamma(2.1))
    assert type(pade.C1) is type(expected) and pade.C1 == expected
    assert pade.C2 == 0.6 * expected ** 2
