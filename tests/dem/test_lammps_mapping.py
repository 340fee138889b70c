"""The mapping of Schwager & Pöschel (1997), eq. (2), to LAMMPS parameters, and the log parser (no LAMMPS needed)."""

import math

import numpy as np
import pytest

from granulargas.dem.lammps import (
    HERTZ_DURATION,
    DemContact,
    enskog_mean_free_time,
    parse_thermo,
    read_thermo,
    stiffness_for_contact_time,
)


def lammps_normal_force(E, nu, eta_n0, r1, r2, m1, m2, delta, delta_dot, limit_damping):
    """LAMMPS pair granular, hertz/material + damping viscoelastic, as documented:
    F = (4/3) E_eff a delta + eta_n0 a m_eff delta_dot, a = sqrt(R_eff delta),
    E_eff = 1 / ((1 - nu^2)/E + (1 - nu^2)/E)."""
    r_eff = r1 * r2 / (r1 + r2)
    m_eff = m1 * m2 / (m1 + m2)
    e_eff = 1.0 / (2.0 * (1.0 - nu**2) / E)
    a = math.sqrt(r_eff * delta)
    f = 4.0 / 3.0 * e_eff * a * delta + eta_n0 * a * m_eff * delta_dot
    return max(f, 0.0) if limit_damping else f


def seed_force(Y, nu, A, r_eff, m_eff, xi, xi_dot):
    """Schwager & Pöschel (1997), eq. (2): F = m_eff rho sqrt(xi) (xi + (3/2) A xi')."""
    rho = 2.0 * Y * math.sqrt(r_eff) / (3.0 * m_eff * (1.0 - nu**2))
    return m_eff * rho * math.sqrt(xi) * (xi + 1.5 * A * xi_dot)


@pytest.mark.parametrize("seed", range(5))
def test_lammps_force_equals_seed_force(seed):
    rng = np.random.default_rng(seed)
    Y, A = 10 ** rng.uniform(2, 8), 10 ** rng.uniform(-6, -2)
    nu = rng.uniform(0.0, 0.49)
    r1, r2, m1, m2 = rng.uniform(0.2, 2.0, 4)
    r_eff, m_eff = r1 * r2 / (r1 + r2), m1 * m2 / (m1 + m2)
    contact = DemContact(Y, nu, A, "overlap")
    for xi, xi_dot in [(1e-3, 0.7), (2e-4, -0.3), (1e-5, -2.0)]:
        f_l = lammps_normal_force(Y, nu, contact.eta_n0(m_eff), r1, r2, m1, m2, xi, xi_dot, False)
        assert f_l == pytest.approx(seed_force(Y, nu, A, r_eff, m_eff, xi, xi_dot), rel=1e-12)
    # the form of the mapping in docs/interoperability.md: eta_n0 = 3 A rho / (2 sqrt(R_eff))
    assert contact.eta_n0(m_eff) == pytest.approx(1.5 * A * contact.rho(r_eff, m_eff) / math.sqrt(r_eff), rel=1e-13)


def test_prefactor_round_trip_and_beta():
    """k from (A, Y) and back; beta = k (R_eff g / m_eff^2)^{1/5} (ARCHITECTURE.md)."""
    k, Y = 0.137, 3.3e5
    c = DemContact.from_prefactor(k, Y, 0.25, "force")
    assert c.prefactor() == pytest.approx(k, rel=1e-13)
    for r_eff, m_eff, g in [(0.25, 0.5, 1.0), (0.1, 0.3, 2.5), (0.4, 2.0, 0.01)]:
        assert c.beta(g, r_eff, m_eff) == pytest.approx(k * (r_eff * g / m_eff**2) ** 0.2, rel=1e-13)
    # the config's damping is beta at g = 1 for two reference particles
    c2 = DemContact.from_beta(0.2, 1.0, young_modulus=7e4)
    assert c2.beta(1.0, 0.25, 0.5) == pytest.approx(0.2, rel=1e-13)


def test_pair_coeff_line():
    c = DemContact(1e5, 0.3, 1e-3, "force")
    words = c.pair_coeff(1, 2, 0.4).split()
    assert words[:4] == ["pair_coeff", "1", "2", "hertz/material"]
    assert float(words[4]) == 1e5 and float(words[6]) == 0.3
    assert float(words[5]) == pytest.approx(1e-3 * 1e5 / (1 - 0.09) / 0.4, rel=1e-15)
    assert words[7:9] == ["damping", "viscoelastic"]
    assert words[-1] == "limit_damping"
    assert "limit_damping" not in DemContact(1e5, 0.3, 1e-3, "overlap").pair_coeff(1, 1, 0.5)


def test_hertz_duration_and_stiffness():
    # (4/5)(5/4)^{2/5} B(2/5, 1/2) = 3.218 (Hertz)
    assert HERTZ_DURATION == pytest.approx(3.2180, abs=1e-4)
    Y = stiffness_for_contact_time(0.004, 2.0, 0.25, 0.5, 0.3)
    c = DemContact(Y, 0.3, 0.0)
    assert c.hertz_contact_time(2.0, 0.25, 0.5) == pytest.approx(0.004, rel=1e-12)
    # stiffer by 10^{5/2} -> 10x shorter contact (t_c ~ rho^{-2/5})
    c10 = DemContact(Y * 10**2.5, 0.3, 0.0)
    assert c10.hertz_contact_time(2.0, 0.25, 0.5) == pytest.approx(0.0004, rel=1e-12)


def test_enskog_mean_free_time_dilute_limit():
    # dilute 3D (chi -> 1): omega = 4 sqrt(pi) n sigma^2 sqrt(T/m)
    eta = 1e-6
    n = 6 * eta / math.pi
    assert enskog_mean_free_time(3, eta) == pytest.approx(1.0 / (4 * math.sqrt(math.pi) * n), rel=1e-5)
    # chi > 1 shortens the mean free time
    assert enskog_mean_free_time(2, 0.3) < 1.0 / (2 * math.sqrt(math.pi) * 4 * 0.3 / math.pi)


LOG = """\
LAMMPS (29 Sep 2021 - Update 2)
Per MPI rank memory allocation (min/avg/max) = 4.339 | 4.339 | 4.339 Mbytes
Step Time c_granT CPU 
       0            0            1            0 
      10        0.001   0.99876543    0.0012345 
WARNING: Communication cutoff adjusted (src/comm.cpp:739)
      20        0.002   0.99770001    0.0023456 
Loop time of 0.0025 on 1 procs for 20 steps with 2 atoms

Step Time c_granT CPU 
      20        0.002   0.99770001            0 
      30        0.003        0.997    0.0011111 
Loop time of 0.0012 on 1 procs for 10 steps with 2 atoms
"""


def test_parse_thermo(tmp_path):
    tables = parse_thermo(LOG)
    assert len(tables) == 2
    np.testing.assert_array_equal(tables[0]["Step"], [0, 10, 20])
    np.testing.assert_allclose(tables[0]["c_granT"], [1, 0.99876543, 0.99770001])
    path = tmp_path / "log.lammps"
    path.write_text(LOG)
    th = read_thermo(path)
    np.testing.assert_array_equal(th["Step"], [0, 10, 20, 30])
    np.testing.assert_allclose(th["Time"], [0, 0.001, 0.002, 0.003])


def test_parse_truncated_log():
    text = LOG.split("Loop time of 0.0025")[0]
    tables = parse_thermo(text)
    assert len(tables) == 1 and len(tables[0]["Step"]) == 3
