"""From material constants to the dimensionless damping beta, and the model's validity range.

Schwager & Pöschel (1997), eq. (3): rho = 2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2)). The rescaled contact
equation depends on the pair and the impact speed g only through

    beta = (3/2) A rho^{2/5} g^{1/5} = k (R_eff g / m_eff^2)^{1/5},
    k = (3/2) A (2 Y / (3 (1 - nu^2)))^{2/5}                       (ARCHITECTURE.md)

so a run needs one material prefactor k and, per pair, b_ij = k (R_eff/m_eff^2)^{1/5}
with beta = b_ij g^{1/5}. Two materials in contact (a mixture) have k_ij of the effective modulus
1/Y* = (1 - nu_i^2)/Y_i + (1 - nu_j^2)/Y_j and the compliance-weighted dissipative constant
(:func:`pair_prefactor_from_materials`). Physical durations are t_c = tau_c(beta) rho^{-2/5} g^{-1/5}.

Validity (Brilliantov, Spahn, Hertzsch & Pöschel 1996): the viscoelastic force is a
quasi-static theory. It needs the dissipative time A well below the collision
time, which with A / t_c = (2/3) beta / tau_c(beta) means beta well below ~3 (we
warn above ``BETA_VALID_MAX`` = 1), and impact speeds far below the speed of sound
(we warn above ``MACH_VALID_MAX`` = 0.1 of the bar speed sqrt(Y / density)).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

BETA_VALID_MAX = 1.0
MACH_VALID_MAX = 0.1


class ContactValidityWarning(UserWarning):
    """The viscoelastic contact model is used outside its range of validity."""


def _positive(name, value):
    if not (np.all(np.asarray(value) > 0) and np.all(np.isfinite(value))):
        raise ValueError(f"{name} must be positive and finite, got {value}")


def effective(a_i, a_j):
    """Reduced quantity a_i a_j / (a_i + a_j) (effective radius or mass)."""
    return a_i * a_j / (a_i + a_j)


def rho_from_material(young_modulus, poisson_ratio, radius_eff, mass_eff):
    """Schwager & Pöschel (1997), eq. (3): rho = 2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2)), in SI (m^{-1/2} s^{-2})."""
    _positive("young_modulus", young_modulus)
    if not (-1.0 < poisson_ratio < 0.5):
        raise ValueError(f"poisson_ratio must lie in (-1, 0.5), got {poisson_ratio}")
    return 2.0 * young_modulus * np.sqrt(radius_eff) / (3.0 * mass_eff * (1.0 - poisson_ratio ** 2))


def prefactor_from_material(young_modulus: float, poisson_ratio: float, dissipation_time: float) -> float:
    """Material prefactor k = (3/2) A (2 Y / (3 (1 - nu^2)))^{2/5}.

    Parameters
    ----------
    young_modulus : float
        Y in Pa.
    poisson_ratio : float
        nu, in (-1, 0.5).
    dissipation_time : float
        A in s (Brilliantov et al. 1996), >= 0.

    Returns
    -------
    float
        k in SI units (s^{1/5} kg^{2/5} m^{-2/5}), such that
        beta = k (R_eff g / m_eff^2)^{1/5} with R_eff in m, g in m/s, m_eff in kg.
    """
    _positive("young_modulus", young_modulus)
    if not (-1.0 < poisson_ratio < 0.5):
        raise ValueError(f"poisson_ratio must lie in (-1, 0.5), got {poisson_ratio}")
    if not (dissipation_time >= 0.0 and math.isfinite(dissipation_time)):
        raise ValueError(f"dissipation_time must be >= 0, got {dissipation_time}")
    return 1.5 * dissipation_time * (2.0 * young_modulus / (3.0 * (1.0 - poisson_ratio ** 2))) ** 0.4


def effective_modulus(young_i, poisson_i, young_j, poisson_j):
    """Y* of two materials in contact, 1/Y* = (1 - nu_i^2)/Y_i + (1 - nu_j^2)/Y_j (Hertz; Johnson,
    *Contact Mechanics* (1985), eq. (4.22); Brilliantov & Pöschel, *Kinetic Theory of Granular
    Gases* (2004), ch. 2). One material: Y* = Y / (2 (1 - nu^2))."""
    return 1.0 / ((1.0 - poisson_i**2) / young_i + (1.0 - poisson_j**2) / young_j)


def pair_dissipation_time(young_i, poisson_i, dissipation_i, young_j, poisson_j, dissipation_j):
    """The dissipative constant A_ij of a contact of two materials: the compliance-weighted mean

        A_ij = (c_i A_i + c_j A_j) / (c_i + c_j),   c = (1 - nu^2) / Y.

    Derivation. The viscoelastic force of one material, F = rho xi^(3/2) + (3/2) A rho xi^(1/2) dxi/dt
    (Brilliantov, Spahn, Hertzsch & Pöschel 1996), is F = F_el(xi) + A dF_el/dt: each body responds
    to the contact force like a Kelvin-Voigt element of relaxation time A. In a Hertz contact of two
    bodies the compression splits as xi_k = xi c_k / (c_i + c_j) (each body's displacement is its
    compliance times the same pressure integral), so body k gives xi_k = g_k(F) - A_k dg_k/dt at first
    order in A_k, with g_k(F) = c_k g(F) / (c_i + c_j). Summing the two and inverting at the same
    order: F = F_el(xi) + A_ij dF_el/dt with A_ij above. The viscoelastic theory itself holds at
    first order in A / t_c (quasi-static), so nothing is lost. One material: A_ij = A.
    """
    ci = (1.0 - poisson_i**2) / young_i
    cj = (1.0 - poisson_j**2) / young_j
    return (ci * dissipation_i + cj * dissipation_j) / (ci + cj)


def pair_prefactor_from_materials(young_i: float, poisson_i: float, dissipation_i: float,
                                  young_j: float, poisson_j: float, dissipation_j: float) -> float:
    """Material prefactor k_ij of a contact of two materials (SI), k_ij = (3/2) A_ij (4 Y*/3)^(2/5),
    with Y* of :func:`effective_modulus` and A_ij of :func:`pair_dissipation_time`: beta =
    k_ij (R_eff g / m_eff^2)^(1/5), the rho of Schwager & Pöschel (1997), eq. (3), being
    (4/3) Y* sqrt(R_eff) / m_eff. One material gives :func:`prefactor_from_material` exactly
    (the same floating-point expression)."""
    if (young_i, poisson_i, dissipation_i) == (young_j, poisson_j, dissipation_j):
        return prefactor_from_material(young_i, poisson_i, dissipation_i)
    for y, nu, a in ((young_i, poisson_i, dissipation_i), (young_j, poisson_j, dissipation_j)):
        prefactor_from_material(y, nu, a)  # the same checks of each material
    y_star = effective_modulus(young_i, poisson_i, young_j, poisson_j)
    a_ij = pair_dissipation_time(young_i, poisson_i, dissipation_i, young_j, poisson_j, dissipation_j)
    return 1.5 * a_ij * (4.0 * y_star / 3.0) ** 0.4


def prefactor_from_damping(damping: float, radius: float = 0.5, mass: float = 1.0) -> float:
    """Prefactor k such that two reference particles colliding at g = 1 have beta = damping.

    Parameters
    ----------
    damping : float
        beta at unit impact speed for two reference particles (reduced units).
    radius, mass : float
        Reference particle radius and mass (reduced units: diameter 1, mass 1).

    Returns
    -------
    float
        k = damping / (R_eff_ref / m_eff_ref^2)^{1/5}, R_eff_ref = radius/2, m_eff_ref = mass/2.
    """
    if not (damping >= 0.0 and math.isfinite(damping)):
        raise ValueError(f"damping must be >= 0, got {damping}")
    _positive("radius", radius)
    _positive("mass", mass)
    return damping / ((0.5 * radius) / (0.5 * mass) ** 2) ** 0.2


def damping_from_prefactor(prefactor: float, radius: float = 0.5, mass: float = 1.0) -> float:
    """The config's ``damping`` for prefactor k: beta at g = 1 for two reference particles.

    Inverse of :func:`prefactor_from_damping`: ``damping = k (R_eff_ref / m_eff_ref^2)^{1/5}``
    (= :func:`pair_constant` of two reference particles; equal to k in reduced units).
    """
    return float(pair_constant(prefactor, radius, radius, mass, mass))


def pair_constant(prefactor, radius_i, radius_j, mass_i, mass_j):
    """b_ij = k (R_eff / m_eff^2)^{1/5}, so that beta = b_ij g^{1/5} (vectorised).

    The one place where the pair prefactor k becomes a pair's damping: the
    engine's kernel computes the same b_ij per collision. For two reference
    particles b is the config's ``damping`` (:func:`damping_from_prefactor`).
    """
    r_eff = effective(radius_i, radius_j)
    m_eff = effective(mass_i, mass_j)
    return prefactor * (r_eff / m_eff ** 2) ** 0.2


def dissipation_time_from_prefactor(prefactor: float, young_modulus: float, poisson_ratio: float) -> float:
    """A such that :func:`prefactor_from_material` gives k: A = (2/3) k / (2 Y / (3 (1 - nu^2)))^{2/5}."""
    return (2.0 / 3.0) * prefactor / (2.0 * young_modulus / (3.0 * (1.0 - poisson_ratio ** 2))) ** 0.4


def beta_from_material(young_modulus, poisson_ratio, dissipation_time, radius_eff, mass_eff, impact_speed):
    """beta = (3/2) A rho^{2/5} g^{1/5} (SI inputs; vectorised over impact_speed)."""
    rho = rho_from_material(young_modulus, poisson_ratio, radius_eff, mass_eff)
    return 1.5 * dissipation_time * rho ** 0.4 * np.asarray(impact_speed, dtype=float) ** 0.2


def time_unit(young_modulus, poisson_ratio, radius_eff, mass_eff, impact_speed):
    """rho^{-2/5} g^{-1/5}: multiply tau_c by this to get the duration in seconds."""
    rho = rho_from_material(young_modulus, poisson_ratio, radius_eff, mass_eff)
    return rho ** -0.4 * np.asarray(impact_speed, dtype=float) ** -0.2


def sound_speed(young_modulus, density):
    """Bar speed of sound sqrt(Y / density) in m/s."""
    _positive("density", density)
    return math.sqrt(young_modulus / density)


def validity_problems(beta=None, impact_speed=None, speed_of_sound=None,
                      beta_max=BETA_VALID_MAX, mach_max=MACH_VALID_MAX) -> list[str]:
    """Reasons why the viscoelastic model is questionable for these values (empty if fine).

    Parameters
    ----------
    beta : float or array, optional
        Dimensionless damping(s); the largest is checked.
    impact_speed, speed_of_sound : float, optional
        Same units; the Mach number g / c is checked.
    """
    problems = []
    if beta is not None:
        b = float(np.max(beta))
        if b > beta_max:
            problems.append(
                f"beta = {b:.3g} > {beta_max:g}: the quasi-static viscoelastic force needs the dissipative "
                f"time A well below the contact time (beta well below ~3)")
    if impact_speed is not None and speed_of_sound is not None:
        mach = float(np.max(impact_speed)) / float(speed_of_sound)
        if mach > mach_max:
            problems.append(
                f"impact speed / speed of sound = {mach:.3g} > {mach_max:g}: the quasi-static contact "
                f"theory needs impact speeds far below the speed of sound")
    return problems


def check_validity(beta=None, impact_speed=None, speed_of_sound=None, *, warn: bool = True,
                   beta_max=BETA_VALID_MAX, mach_max=MACH_VALID_MAX) -> bool:
    """True if the model is in its range; else emit ContactValidityWarning(s) (if warn) and return False."""
    problems = validity_problems(beta, impact_speed, speed_of_sound, beta_max, mach_max)
    if warn:
        for p in problems:
            warnings.warn(p, ContactValidityWarning, stacklevel=2)
    return not problems
