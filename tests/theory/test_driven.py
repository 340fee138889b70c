"""The white-noise driven steady state: closed forms against the moment equations."""

import math

import pytest

from granulargas import theory
from granulargas.contact.material import prefactor_from_damping
from granulargas.theory.gas import Gas


def _gas(d, model, packing=0.05, **kw):
    n = theory.number_density(packing, d)
    return Gas(dimension=d, packing_fraction=packing, density=n, sigma=1.0, mass=1.0, temperature=1.0,
               model=model, **kw)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("eps", [0.3, 0.7, 0.9, 0.99])
def test_moment_equations_give_van_noije_ernst_for_constant_eps(d, eps):
    """driven_state integrates the moments numerically (theory.moments); for a constant eps its
    stationary point is the closed form of van Noije & Ernst (1998) (a2) and zeta T = H (T)."""
    gas = _gas(d, "constant", restitution=eps)
    T, a2 = theory.driven_state(gas, 0.1)
    assert a2 == pytest.approx(float(theory.driven_sonine_a2(eps, d)), rel=1e-3, abs=1e-6)
    T_closed = float(theory.driven_temperature(0.1, eps, gas.density, d, a2=a2))
    assert T == pytest.approx(T_closed, rel=1e-6)


def test_driven_a2_is_not_the_cooling_a2():
    # the driving pulls the distribution towards the Maxwellian: smaller |a2| than the HCS
    for eps in (0.5, 0.8, 0.9):
        assert abs(theory.driven_sonine_a2(eps, 3)) < abs(theory.sonine_a2(eps, 3))
    assert theory.driven_sonine_a2(1.0, 3) == 0.0
    assert theory.driven_sonine_a2(0.5 ** 0.5, 2) == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("d", [2, 3])
def test_steady_temperature_balances_heating_and_cooling(d):
    n = theory.number_density(0.1, d)
    T = float(theory.driven_temperature(0.3, 0.8, n, d))
    zeta = float(theory.enskog_cooling_rate(0.8, n, T, d, a2=theory.driven_sonine_a2(0.8, d)))
    assert zeta * T == pytest.approx(0.3, rel=1e-12)
    # T ~ H^(2/3)
    assert float(theory.driven_temperature(2.4, 0.8, n, d)) == pytest.approx(4.0 * T, rel=1e-12)


def test_effective_restitution_at_small_damping_is_the_leading_order_law():
    k = prefactor_from_damping(1e-4)
    b = theory.viscoelastic.identical_pair_constant(k)
    for T in (0.5, 1.0, 4.0):
        eps = theory.effective_restitution(k, T)
        assert 1.0 - eps**2 == pytest.approx(float(theory.effective_inelasticity(b, T)), rel=1e-3)


@pytest.mark.parametrize("damping", [0.05, 0.2])
def test_viscoelastic_driven_state_two_routes(damping):
    """The exact-eps moment equations and the effective-restitution model (Dubey et al. 2013)
    agree on T to the size of the a2 correction (3 a2 / 16 of zeta, T ~ zeta^(-2/3), and the
    a2 weighting of eps(g) in zeta)."""
    k = prefactor_from_damping(damping)
    gas = _gas(3, "viscoelastic", prefactor=k)
    T, a2 = theory.driven_state(gas, 0.1)
    T_eff, a2_eff, eps_eff = theory.viscoelastic_driven_state(0.1, k, gas.density, 3)
    assert 0.0 < eps_eff < 1.0
    assert T == pytest.approx(T_eff, rel=abs(a2 - a2_eff) / 4 + 1e-3)
    # the heated gas reaches higher T with less dissipation
    T_soft, _ = theory.driven_state(_gas(3, "viscoelastic", prefactor=k / 2), 0.1)
    assert T_soft > T


def test_driving_interval():
    assert theory.driving_interval(0.5) == pytest.approx(0.04)
    assert theory.driving_interval(0.5, fraction=0.1) == pytest.approx(0.2)
