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
