"""Gases under gravity and on vibrating walls: the hydrostatic profile against an independent
chemical-potential form, the bouncing-ball orbits against the exact impact map, and the dilute
bed's closed form against a numerical balance of input and loss."""

import math

import numpy as np
import pytest
from scipy.integrate import quad, trapezoid
from scipy.optimize import brentq

from granulargas import theory
from granulargas.theory import vibrated as V


def test_barometric_profile_is_normalised_and_exponential():
    z = np.linspace(0.5, 9.5, 200_001)
    n = V.barometric_density(z, 3.0, 2.0, 0.5, mass=1.5, bottom=0.5, top=9.5)
    assert trapezoid(n, z) == pytest.approx(3.0, rel=1e-8)
    ell = 2.0 / (1.5 * 0.5)
    assert n[1000] / n[0] == pytest.approx(math.exp(-(z[1000] - 0.5) / ell), rel=1e-12)
    assert V.barometric_density(0.2, 3.0, 2.0, 0.5, bottom=0.5) == 0.0


def test_hydrostatic_profile_is_barometric_when_dilute():
    z = np.linspace(0.5, 30.0, 3001)
    n = V.hydrostatic_density(z, 1e-3, 1.0, 0.2, dim=3)
    b = V.barometric_density(z, 1e-3, 1.0, 0.2, bottom=0.5)
    np.testing.assert_allclose(n, b, rtol=2e-3)


@pytest.mark.parametrize("dim", [2, 3])
def test_hydrostatic_profile_keeps_the_chemical_potential_uniform(dim):
    """At equilibrium ln n + mu_ex(eta) / T + m g z / T is the same at every height, with
    mu_ex / T = integral_0^eta (Z(x) - 1) / x dx + Z(eta) - 1 (the thermodynamics of the
    equation of state, computed here by quadrature: independent of the ODE that builds the
    profile); and the column holds the particles asked for."""
    T, g, column = 1.0, 0.5, 2.0 if dim == 3 else 1.5
    top = 12.0
    z = np.linspace(0.5, top - 0.5, 801)
    n = V.hydrostatic_density(z, column, T, g, dim=dim, top=top - 0.5)
    eta = n * theory.particle_volume(1.0, dim)
    assert eta[0] > 0.1  # dense enough at the floor for Z to matter

    def mu_ex(e):
        integral = quad(lambda x: (theory.compressibility_factor(x, dim) - 1.0) / x, 0.0, e)[0]
        return integral + theory.compressibility_factor(e, dim) - 1.0

    mu = np.log(n) + np.array([mu_ex(e) for e in eta]) + g * z / T
    assert np.ptp(mu) < 1e-5
    assert trapezoid(n, z) == pytest.approx(column, rel=1e-4)


def test_bouncing_ball_threshold_and_orbit():
    assert V.bouncing_ball_threshold(1, 0.5) == pytest.approx(math.pi / 3)
    assert V.bouncing_ball_threshold(2, 0.8) == pytest.approx(2 * math.pi / 9)
    e, g, omega = 0.5, 1.0, 2 * math.pi
    for gamma, exists in [(1.2, True), (1.0, False)]:
        orbit = V.period_orbit(1, e, gamma * g / omega**2, omega, g)
        assert orbit["exists"] is exists
        assert orbit["takeoff"] == pytest.approx(math.pi * g / omega)
        assert orbit["plate_velocity"] == pytest.approx(math.pi * g * (1 - e) / (omega * (1 + e)))


@pytest.mark.parametrize("n", [1, 2])
def test_period_orbit_is_a_fixed_point_of_the_exact_impact_map(n):
    e, g, omega = 0.6, 1.0, 2 * math.pi
    gamma = 1.3 * V.bouncing_ball_threshold(n, e)
    amp = gamma * g / omega**2
    orbit = V.period_orbit(n, e, amp, omega, g)
    for phase in orbit["phases"]:
        t0 = phase / omega
        t1, v1 = V.bounce_map(t0, orbit["takeoff"], amp, omega, g, e)
        assert t1 - t0 == pytest.approx(n * 2 * math.pi / omega, rel=1e-9)
        assert v1 == pytest.approx(orbit["takeoff"], rel=1e-9)


def test_bounce_map_against_a_flight_from_rest():
    """Dropped from the top of a plate at rest (A -> 0): the flight takes 2 v / g and the
    ball comes back at -v, leaving at e v."""
    t1, v1 = V.bounce_map(0.3, 2.0, 1e-14, 1.0, 1.0, 0.7)
    assert t1 == pytest.approx(0.3 + 4.0, rel=1e-9)
    assert v1 == pytest.approx(1.4, rel=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_bed_temperature_balances_input_and_loss(dim):
    """Eq. (4) is where the plate input (3) meets the collisional loss of the barometric
    column, found here numerically from the Enskog cooling rate (dilute, Maxwellian)."""
    column, e, u2, g = 4.0, 0.9, 0.3, 1.0

    def balance(T):
        n0 = column * g / T  # barometric: n0 T / (m g) = N_A
        return V.plate_input_power(u2, n0, T) - V.bed_loss(column, e, T, g, dim)

    T = brentq(balance, 1e-3, 1e3, rtol=1e-12)
    assert V.vibrated_bed_temperature(column, e, u2, dim) == pytest.approx(T, rel=1e-6)
    p = V.bed_parameters(column, e, 0.01, u2, g, dim)
    assert p["temperature"] == pytest.approx(T, rel=1e-6)
    assert p["dissipation"] == pytest.approx((1 - e * e) * column)
