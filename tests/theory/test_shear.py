"""Tests of granulargas.theory.shear: the Grad solution of uniform shear flow and the
Navier-Stokes viscosity, each against something it was not computed from."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from granulargas import theory as th
from granulargas.theory import shear


def test_grad_usf_3d_alpha_08_published_numbers():
    # Brey, Ruiz-Montero & Moreno (1997); Santos, Garzó & Dufty (2004): alpha = 0.8 in 3D
    s = shear.grad_usf(0.8, 3)
    assert s.a_star == pytest.approx(0.512, abs=6e-4)
    assert s.eta_star == pytest.approx(0.857, abs=6e-4)
    assert s.pressure[1, 1] == pytest.approx(0.849, abs=6e-4)
    assert s.pressure[2, 2] == pytest.approx(0.849, abs=6e-4)
    assert s.pressure[0, 0] == pytest.approx(1.303, abs=6e-4)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("alpha", [0.5, 0.8, 0.95])
def test_dilute_closed_form_matches_quadrature_of_the_collision_moments(dim, alpha):
    """The closed form (S6) against the quadrature of (S3) at a contact value a hair from 1
    (which takes the quadrature path at a vanishing density)."""
    closed = shear.grad_usf(alpha, dim)
    quad = shear.grad_usf(alpha, dim, chi=1.0 + 1e-12)
    assert quad.a_star == pytest.approx(closed.a_star, rel=1e-5)
    assert quad.eta_star == pytest.approx(closed.eta_star, rel=1e-5)
    np.testing.assert_allclose(quad.pressure, closed.pressure, atol=1e-5)
    assert quad.zeta_star == pytest.approx(closed.zeta_star, rel=1e-5)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("packing", [0.0, 0.1, 0.3])
def test_steady_state_energy_balance(dim, packing):
    """Viscous heating -a P_xy (kinetic + collisional) equals the collisional loss, an
    integral of its own ((w.k)^3 against the moments' (w.k)^2 and trace)."""
    s = shear.grad_usf(0.7, dim, packing)
    heating = s.a_star * (-s.pressure[0, 1]) * s.temperature_ratio
    assert heating == pytest.approx(0.5 * dim * s.zeta_star, rel=1e-8)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("a_star", [0.1, 0.5, 1.0])
def test_thermostatted_elastic_dilute_closed_form(dim, a_star):
    """Gaussian thermostat, alpha = 1, dilute: (S2) with Lambda = -nu0 Pi gives
    eta* = 1 / (1 + 2 z)^2 with z = a*^2 / (d (1 + 2 z)^2) (derived by hand)."""
    s = shear.grad_usf(1.0, dim, a_star=a_star)
    z = brentq(lambda z: z - a_star**2 / (dim * (1 + 2 * z) ** 2), 0.0, 10.0)
    assert s.zeta_th_star == pytest.approx(z, rel=1e-5)
    assert s.eta_star == pytest.approx(1.0 / (1.0 + 2.0 * z) ** 2, rel=1e-5)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("packing", [0.1, 0.3])
def test_grad_elastic_small_shear_is_enskog_viscosity(dim, packing):
    """The Enskog Grad USF at a* -> 0 (thermostatted, elastic) has Enskog's first-Sonine
    viscosity (theory.shear_viscosity, Chapman & Cowling; Gass 1971), including the
    collisional transfer of the shear over sigma."""
    s = shear.grad_usf(1.0, dim, packing, a_star=0.01)
    n = th.number_density(packing, dim)
    enskog = th.shear_viscosity(n, 1.0, dim) / shear.dilute_viscosity(1.0, dim)
    assert s.eta_star == pytest.approx(enskog, rel=3e-4)  # O(a*^2) away


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("packing", [1e-9, 0.05, 0.2, 0.4])
def test_navier_stokes_viscosity_elastic_limit_is_enskog(dim, packing):
    n = th.number_density(packing, dim)
    enskog = th.shear_viscosity(n, 1.0, dim) / shear.dilute_viscosity(1.0, dim)
    assert shear.navier_stokes_viscosity_reduced(1.0, dim, packing) == pytest.approx(enskog, rel=1e-12)


@pytest.mark.parametrize("alpha", [0.5, 0.7, 0.9])
def test_navier_stokes_dilute_3d_brey_dufty_kim_santos_form(alpha):
    # Brey, Dufty, Kim & Santos (1998): eta* = 1 / (nu* - zeta*/2) with
    # nu* = (1 - (1 - alpha)^2/4)(1 - c/64), zeta* = (5/12)(1 - alpha^2)(1 + 3c/32),
    # c = 32 (1 - alpha)(1 - 2 alpha^2) / (81 - 17 alpha + 30 alpha^2 (1 - alpha))
    c = 32 * (1 - alpha) * (1 - 2 * alpha**2) / (81 - 17 * alpha + 30 * alpha**2 * (1 - alpha))
    nu = (1 - (1 - alpha) ** 2 / 4) * (1 - c / 64)
    zeta = 5 / 12 * (1 - alpha**2) * (1 + 3 * c / 32)
    assert shear.navier_stokes_viscosity_reduced(alpha, 3) == pytest.approx(1 / (nu - zeta / 2), rel=1e-12)


def test_reference_frequency_3d():
    assert shear.reference_frequency(0.3, 2.0, 3) == pytest.approx(16 / 5 * 0.3 * math.sqrt(math.pi * 2.0))
    assert shear.dilute_viscosity(1.0, 2) == pytest.approx(1 / (2 * math.sqrt(math.pi)))


def test_normal_stress_differences_and_bad_input():
    s = shear.grad_usf(0.8, 3)
    n1, n2 = s.normal_stress_differences
    assert n1 == pytest.approx(s.pressure[0, 0] - s.pressure[1, 1])
    assert n2 == pytest.approx(0.0, abs=1e-12)  # Grad: P_yy = P_zz in the dilute gas
    assert shear.grad_usf(0.8, 3, 0.3).normal_stress_differences[1] > 0.0  # Enskog: P_yy > P_zz
    with pytest.raises(ValueError):
        shear.grad_usf(1.0, 3)
    with pytest.raises(ValueError):
        shear.grad_usf(1.2, 3)


def test_transient_of_a_gas_already_at_the_enskog_steady_temperature_is_zero():
    """At finite density the dilute moment equations (rates times chi) have their own steady
    temperature; started at the caller's steady T (Enskog) the gas has arrived, and one 40 % above
    it takes a finite time."""
    packing, eps, d = 0.1, 0.9, 3
    n = float(th.number_density(packing, d))
    chi = float(th.contact_value(packing, d))
    rate = 0.4
    t_s = float(shear.steady_temperature(rate, eps, n, d, 1.0, 1.0, packing))
    assert shear.grad_transient(rate, eps, n, t_s, d, chi=chi, t_end=1.0, T_steady=t_s) == (0.0, 0.0)
    t_reach, _ = shear.grad_transient(rate, eps, n, 1.4 * t_s, d, chi=chi, T_steady=t_s)
    assert 0.0 < t_reach < math.inf
