"""Two spheres head-on in LAMMPS vs the viscoelastic contact ODE (Schwager & Pöschel (1997), eq. (2)).

LAMMPS ``pair_style granular`` (hertz/material + damping viscoelastic, mapped
by :class:`granulargas.dem.lammps.DemContact`) is an independent integrator of
the same contact law: with ``limit_damping`` it must converge to the ``force``
end of contact, without it to the ``overlap`` end, at first order in the
timestep. The reference eps(beta) is an independent ODE solve written here
(w = sqrt(x), dt = 2 w ds removes the sqrt singularity at x = 0), and our
contact module when it is importable.

The LAMMPS tests need the ``lmp`` executable and skip with a reason otherwise.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from granulargas.dem.lammps import DemContact, find_lmp, head_on_restitution

needs_lmp = pytest.mark.skipif(find_lmp() is None, reason="LAMMPS executable `lmp` not installed (apt-get install lammps)")


def eps_reference(beta, end):
    """eps of x'' + beta sqrt(x) x' + x^{3/2} = 0, x(0) = 0, x'(0) = 1.

    With x = w^2 and dt = 2 w ds: w_s = v, v_s = -2 beta w^2 v - 2 w^4,
    t_s = 2 w (polynomial, regular at w = 0). ``overlap`` ends at w = 0,
    ``force`` where the force w (w^2 + beta v) first vanishes with w > 0.
    """

    def rhs(s, y):
        w, v, _ = y
        return [v, -2.0 * beta * w * w * v - 2.0 * w**4, 2.0 * w]

    def overlap(s, y):
        return y[0]

    def force(s, y):
        return y[0] ** 2 + beta * y[1]

    event = overlap if end == "overlap" else force
    event.terminal, event.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 1e4), [0.0, 1.0, 0.0], events=event, method="DOP853",
                    rtol=1e-12, atol=1e-14, first_step=1e-6)
    return -sol.y_events[0][0][1]


def test_reference_matches_series():
    # Ramirez et al. (1999): eps = 1 - C1 beta + C2 beta^2 - ..., C2 = (3/5) C1^2
    c1 = math.gamma(0.6) * math.sqrt(math.pi) / (2**0.2 * 5**0.4 * math.gamma(2.1))
    beta = 1e-3
    for end in ("overlap", "force"):
        assert eps_reference(beta, end) == pytest.approx(1 - c1 * beta + 0.6 * c1**2 * beta**2, abs=1e-8)


def _contact(beta, end, speed=1.0):
    return DemContact.from_beta(beta, speed, young_modulus=1e4, end=end)


@needs_lmp
@pytest.mark.parametrize("end", ["force", "overlap"])
def test_limit_damping_selects_the_end_of_contact(tmp_path, end):
    """At beta = 0.1 the two ends differ by 7e-4; LAMMPS at t_c/800 must pick the right one."""
    beta = 0.1
    eps = head_on_restitution(_contact(beta, end), 1.0, 800, tmp_path)
    other = "overlap" if end == "force" else "force"
    assert abs(eps - eps_reference(beta, end)) < 1e-5
    assert abs(eps - eps_reference(beta, other)) > 5e-4


@needs_lmp
@pytest.mark.parametrize("end", ["force", "overlap"])
def test_first_order_convergence_in_timestep(tmp_path, end):
    """beta = 1: the error halves with the timestep; Richardson extrapolation hits the ODE."""
    beta = 1.0
    ref = eps_reference(beta, end)
    eps = [head_on_restitution(_contact(beta, end), 1.0, n, tmp_path / str(n)) for n in (400, 800, 1600)]
    err = np.array(eps) - ref
    ratios = err[:-1] / err[1:]
    assert np.all((ratios > 1.6) & (ratios < 2.4)), err
    assert abs(2 * eps[2] - eps[1] - ref) < 1e-5
    assert abs(err[2]) < 1e-4


@needs_lmp
def test_impact_speed_scaling(tmp_path):
    """One material, two impact speeds: beta scales as g^{1/5} (Schwager & Pöschel (1997), eq. (2), rescaled)."""
    contact = _contact(1.0, "force", speed=1.0)
    speed = 0.05
    beta = contact.beta(speed, 0.25, 0.5)
    assert beta == pytest.approx(speed**0.2)
    eps = head_on_restitution(contact, speed, 1600, tmp_path)
    assert abs(eps - eps_reference(beta, "force")) < 1e-4


@needs_lmp
def test_against_contact_module(tmp_path):
    """LAMMPS vs our contact module (the same comparison as the ODE above, at beta = 0.3)."""
    from granulargas.contact import restitution

    for beta, end in [(0.3, "force"), (0.3, "overlap")]:
        eps = head_on_restitution(_contact(beta, end), 1.0, 1600, tmp_path / end)
        assert abs(eps - float(restitution(beta, method="ode", end=end))) < 3e-5


@needs_lmp
@pytest.mark.parametrize("end", ["force", "overlap"])
def test_unequal_spheres(tmp_path, end):
    """Radii 0.3 / 0.7, masses 0.4 / 2.5: eta_n0 per type pair makes LAMMPS's eps the
    eps(beta) of our pair prefactor, beta = k (R_eff g / m_eff^2)^{1/5} (ARCHITECTURE.md)."""
    k = 0.4
    contact = DemContact.from_prefactor(k, young_modulus=3e4, end=end)
    radii, masses = (0.3, 0.7), (0.4, 2.5)
    r_eff, m_eff = 0.21, 0.4 * 2.5 / 2.9
    speed = 1.7
    beta = k * (r_eff * speed / m_eff**2) ** 0.2
    eps = head_on_restitution(contact, speed, 800, tmp_path, radii=radii, masses=masses)
    assert abs(eps - eps_reference(beta, end)) < 1e-4
    # with one eta_n0 for all pairs (that of two reference particles) it would be off
    assert abs(eps_reference(beta * m_eff / 0.5, end) - eps_reference(beta, end)) > 1e-2
