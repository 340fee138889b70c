"""Material constants -> beta (Schwager & Pöschel (1997), eq. (3)), prefactors, validity range."""

import math
import warnings

import numpy as np
import pytest

from granulargas.contact import material
from granulargas.contact import prefactor_from_damping, prefactor_from_material


def test_prefactor_reproduces_beta_from_seed_eq3():
    Y, nu, A = 2.0e9, 0.3, 1.0e-6
    R1, R2, m1, m2, g = 1e-3, 2e-3, 4e-6, 3e-5, 0.7
    r_eff, m_eff = R1 * R2 / (R1 + R2), m1 * m2 / (m1 + m2)
    rho = 2 * Y * math.sqrt(r_eff) / (3 * m_eff * (1 - nu ** 2))
    beta_direct = 1.5 * A * rho ** 0.4 * g ** 0.2
    k = prefactor_from_material(Y, nu, A)
    assert k * (r_eff * g / m_eff ** 2) ** 0.2 == pytest.approx(beta_direct, rel=1e-14)
    assert material.pair_constant(k, R1, R2, m1, m2) * g ** 0.2 == pytest.approx(beta_direct, rel=1e-14)
    assert material.beta_from_material(Y, nu, A, r_eff, m_eff, g) == pytest.approx(beta_direct, rel=1e-14)


def test_prefactor_from_damping_gives_damping_for_reference_pair():
    k = prefactor_from_damping(0.2)
    assert material.pair_constant(k, 0.5, 0.5, 1.0, 1.0) * 1.0 ** 0.2 == pytest.approx(0.2, rel=1e-14)
    k2 = prefactor_from_damping(0.2, radius=1.0, mass=3.0)
    assert material.pair_constant(k2, 1.0, 1.0, 3.0, 3.0) == pytest.approx(0.2, rel=1e-14)


def test_time_unit_scales_duration():
    # t_c = tau_c rho^{-2/5} g^{-1/5}: doubling g shortens the Hertz contact by 2^{-1/5}
    t1 = material.time_unit(1e9, 0.3, 1e-3, 1e-6, 1.0)
    t2 = material.time_unit(1e9, 0.3, 1e-3, 1e-6, 2.0)
    assert t2 / t1 == pytest.approx(2 ** -0.2, rel=1e-14)


def test_bad_inputs_rejected():
    with pytest.raises(ValueError):
        prefactor_from_material(-1.0, 0.3, 1e-6)
    with pytest.raises(ValueError):
        prefactor_from_material(1e9, 0.6, 1e-6)
    with pytest.raises(ValueError):
        prefactor_from_damping(-0.1)


def test_validity_range_warns_outside():
    assert material.validity_problems(beta=0.1, impact_speed=1.0, speed_of_sound=2000.0) == []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert material.check_validity(beta=np.array([0.01, 0.5]))
    with pytest.warns(material.ContactValidityWarning, match="beta"):
        assert not material.check_validity(beta=2.5)
    with pytest.warns(material.ContactValidityWarning, match="speed of sound"):
        assert not material.check_validity(impact_speed=500.0, speed_of_sound=2000.0)
    assert len(material.validity_problems(beta=3.0, impact_speed=500.0, speed_of_sound=2000.0)) == 2


# --- two materials in contact (mixtures)

GLASS = (6.3e10, 0.24, 2.0e-9)
STEEL = (2.1e11, 0.29, 1.0e-9)


def test_one_material_pair_is_the_material_prefactor_exactly():
    assert material.pair_prefactor_from_materials(*GLASS, *GLASS) == material.prefactor_from_material(*GLASS)
    y, nu, a = GLASS
    assert material.effective_modulus(y, nu, y, nu) == pytest.approx(y / (2 * (1 - nu**2)), rel=1e-15)
    assert material.pair_dissipation_time(y, nu, a, y, nu, a) == pytest.approx(a, rel=1e-15)
    # the general expression agrees with the one-material prefactor to rounding
    k = 1.5 * a * (4.0 * material.effective_modulus(y, nu, y, nu) / 3.0) ** 0.4
    assert k == pytest.approx(material.prefactor_from_material(*GLASS), rel=1e-14)


def test_two_materials_pair_is_symmetric_and_between_the_two():
    k_gs = material.pair_prefactor_from_materials(*GLASS, *STEEL)
    assert k_gs == material.pair_prefactor_from_materials(*STEEL, *GLASS)
    # Y* of glass on steel: 1 / ((1 - 0.24^2)/6.3e10 + (1 - 0.29^2)/2.1e11) = 4.8e10 Pa
    assert material.effective_modulus(6.3e10, 0.24, 2.1e11, 0.29) == pytest.approx(
        1.0 / ((1 - 0.24**2) / 6.3e10 + (1 - 0.29**2) / 2.1e11), rel=1e-15)
    a = material.pair_dissipation_time(*GLASS, *STEEL)
    assert STEEL[2] < a < GLASS[2]
    # the softer glass takes most of the compression: its A weighs more
    assert a > 0.5 * (GLASS[2] + STEEL[2])


def test_rigid_partner_limit():
    """Against a body that does not deform (Y_j -> inf) the contact is the first material's
    against a rigid plane: Y* = Y_i / (1 - nu_i^2) and A_ij = A_i."""
    y, nu, a = GLASS
    assert material.effective_modulus(y, nu, 1e300, 0.3) == pytest.approx(y / (1 - nu**2), rel=1e-12)
    assert material.pair_dissipation_time(y, nu, a, 1e300, 0.3, 5e-9) == pytest.approx(a, rel=1e-12)
