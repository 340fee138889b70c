"""Closed-form kinetic theory of granular gases, the yardstick for the simulator.

Everything is for identical smooth hard spheres (``dim = 3``) or disks
(``dim = 2``) of diameter ``sigma`` and mass ``m`` at number density ``n``;
temperature ``T = m <c^2> / dim`` with ``k_B = 1`` (see ``shared/physics.md``).
Defaults are the code's reduced units ``sigma = m = 1``.

Contents, with the equations they implement:

* packing fraction ``eta`` (3D ``pi n sigma^3 / 6``, 2D ``pi n sigma^2 / 4``);
* pair correlation at contact ``chi``: Carnahan & Starling, J. Chem. Phys. 51,
  635 (1969), ``chi = (1 - eta/2) / (1 - eta)^3``; Henderson, Mol. Phys. 30,
  971 (1975), ``chi = (1 - 7 eta/16) / (1 - eta)^2``;
* compressibility factor ``Z = P / (n T)``: virial route ``1 + 2^(d-1) eta chi``,
  which equals the CS and Henderson closed forms;
* second Sonine coefficient of the homogeneous cooling state, van Noije & Ernst,
  Granular Matter 1, 57 (1998) (first Sonine approximation, the form quoted in
  physics.md section 2);
* Enskog collision frequency ``omega`` and cooling rate ``zeta``,
  ``zeta = omega (1 - eps^2)(1 + 3 a2/16) / d`` (van Noije & Ernst 1998;
  Brilliantov & Pöschel, *Kinetic Theory of Granular Gases* (OUP 2004), ch. 6);
  Haff's law ``T = T0 / (1 + t/tau0)^2`` with ``1/tau0 = zeta(T0)/2``
  (Haff, J. Fluid Mech. 134, 401 (1983));
* the same in collisions per particle ``s``: ``T = T0 exp(-(1-eps^2)(1+3a2/16) s/d)``;
* mean free path ``l = <|v|> / omega``;
* the shear-instability length ``L_c`` from linearised hydrodynamics of the
  homogeneous cooling state (see :func:`instability_length`);
* viscoelastic cooling ``T = T0 (1 + t/tau0)^(-5/3)`` with ``tau0`` derived below
  (:func:`viscoelastic_tau0`);
* the white-noise driven steady state (:func:`driven_sonine_a2`,
  :func:`driven_temperature`, :func:`driving_interval`), and for viscoelastic
  particles the effective constant restitution coefficient of Dubey, Bodrova, Puri &
  Brilliantov (2013) (:func:`effective_restitution`,
  :func:`viscoelastic_driven_temperature`).

The viscoelastic pair constant
------------------------------
The engine uses ``beta = k (R_eff g_n / m_eff^2)^(1/5)`` (ARCHITECTURE.md), and the
restitution coefficient ``eps = 1 - C1 beta + C2 beta^2 - ...`` with
``C1 = Gamma(3/5) sqrt(pi) / (2^(1/5) 5^(2/5) Gamma(21/10)) = 1.15345``
(Schwager & Pöschel 1997, seed eq. (32); Ramírez et al., PRE 60, 4465 (1999)).
For two reference particles (``R = sigma/2``, so ``R_eff = sigma/4``, ``m_eff = m/2``)
``beta = b g_n^(1/5)`` with ``b = k (sigma / m^2)^(1/5)``; in reduced units ``b = k``,
which is the config's ``damping``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gamma as _gamma

__all__ = [
    "C1",
    "C2",
    "packing_fraction",
    "number_density",
    "contact_value",
    "compressibility_factor",
    "pressure",
    "sonine_a2",
    "collision_frequency",
    "mean_free_path",
    "enskog_cooling_rate",
    "haff_tau0",
    "haff_temperature",
    "haff_collisions",
    "temperature_vs_collisions",
    "shear_viscosity",
    "instability_length",
    "pair_damping",
    "effective_inelasticity",
    "viscoelastic_cooling_rate",
    "viscoelastic_tau0",
    "viscoelastic_temperature",
    "viscoelastic_collisions",
    "driven_sonine_a2",
    "driven_temperature",
    "driving_interval",
    "effective_restitution",
    "viscoelastic_driven_state",
]

#: First and second coefficients of eps(beta) = 1 - C1 beta + C2 beta^2 (seed eq. 32).
C1 = math.gamma(0.6) * math.sqrt(math.pi) / (2.0**0.2 * 5.0**0.4 * math.gamma(2.1))
C2 = 0.6 * C1**2


def _check_dim(dim):
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")


def packing_fraction(n, dim=3, sigma=1.0):
    """Packing (area/volume) fraction of spheres or disks.

    ``eta = pi n sigma^3 / 6`` (3D), ``pi n sigma^2 / 4`` (2D).
    """
    _check_dim(dim)
    return np.pi * n * sigma**3 / 6.0 if dim == 3 else np.pi * n * sigma**2 / 4.0


def number_density(eta, dim=3, sigma=1.0):
    """Inverse of :func:`packing_fraction`: number density for packing fraction ``eta``."""
    _check_dim(dim)
    return 6.0 * eta / (np.pi * sigma**3) if dim == 3 else 4.0 * eta / (np.pi * sigma**2)


def contact_value(eta, dim=3):
    """Pair correlation function at contact, chi = g(sigma+).

    3D: Carnahan–Starling, ``chi = (1 - eta/2) / (1 - eta)^3``.
    2D: Henderson, ``chi = (1 - 7 eta/16) / (1 - eta)^2``.

    Parameters
    ----------
    eta : float or array
        Packing fraction, 0 <= eta < 1.
    """
    _check_dim(dim)
    eta = np.asarray(eta, dtype=float)
    if dim == 3:
        out = (1.0 - 0.5 * eta) / (1.0 - eta) ** 3
    else:
        out = (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2
    return out[()] if out.ndim == 0 else out


def compressibility_factor(eta, dim=3, form="closed"):
    """Equation of state of elastic hard spheres/disks, ``Z = P / (n T)``.

    ``form="closed"``: Carnahan–Starling ``(1 + eta + eta^2 - eta^3)/(1 - eta)^3`` (3D)
    or Henderson ``(1 + eta^2/8)/(1 - eta)^2`` (2D).
    ``form="virial"``: ``1 + 2^(d-1) eta chi(eta)`` (identical in 3D, to O(eta^3)
    in 2D; physics.md section 5).
    """
    _check_dim(dim)
    eta = np.asarray(eta, dtype=float)
    if form == "virial":
        out = 1.0 + 2.0 ** (dim - 1) * eta * contact_value(eta, dim)
    elif form == "closed":
        if dim == 3:
            out = (1.0 + eta + eta**2 - eta**3) / (1.0 - eta) ** 3
        else:
            out = (1.0 + eta**2 / 8.0) / (1.0 - eta) ** 2
    else:
        raise ValueError(f"form must be 'closed' or 'virial', got {form!r}")
    return out[()] if np.ndim(out) == 0 else out


def pressure(n, T, dim=3, sigma=1.0, form="closed"):
    """Pressure ``P = n T Z(eta)`` of elastic hard spheres/disks."""
    return n * T * compressibility_factor(packing_fraction(n, dim, sigma), dim, form)


def sonine_a2(eps, dim=3):
    """Second Sonine coefficient of the homogeneous cooling state (constant eps).

    van Noije & Ernst, Granular Matter 1, 57 (1998), first Sonine approximation:
    ``a2 = 16 (1 - eps)(1 - 2 eps^2) / [9 + 24 d - eps (41 - 8 d) + 30 eps^2 (1 - eps)]``.
    Zero for eps = 1; negative for 1/sqrt(2) < eps < 1.
    """
    _check_dim(dim)
    eps = np.asarray(eps, dtype=float)
    num = 16.0 * (1.0 - eps) * (1.0 - 2.0 * eps**2)
    den = 9.0 + 24.0 * dim - eps * (41.0 - 8.0 * dim) + 30.0 * eps**2 * (1.0 - eps)
    out = num / den
    return out[()] if out.ndim == 0 else out


def _solid_angle_factor(dim):
    # 2 pi^((d-1)/2) / Gamma(d/2): 4 sqrt(pi) in 3D, 2 sqrt(pi) in 2D.
    return 2.0 * math.pi ** ((dim - 1) / 2.0) / math.gamma(dim / 2.0)


def collision_frequency(n, T, dim=3, sigma=1.0, m=1.0, chi=None, a2=0.0):
    """Enskog collision frequency per particle (collisions per particle per unit time).

    ``omega = 4 sqrt(pi) chi n sigma^2 sqrt(T/m) (1 - a2/16)`` in 3D,
    ``omega = 2 sqrt(pi) chi n sigma sqrt(T/m) (1 - a2/16)`` in 2D
    (cross-section times mean relative speed, e.g. ``pi sigma^2 n sqrt(16 T/(pi m))``
    in 3D, times the Enskog factor chi; the ``a2`` factor is the first Sonine
    correction, Brilliantov & Pöschel 2004, ch. 6). The total pair-collision rate of N particles is ``N omega / 2``.

    Parameters
    ----------
    n : float
        Number density, sigma^-d.
    T : float or array
        Temperature.
    chi : float, optional
        Contact value; default :func:`contact_value` of the packing fraction.
    a2 : float
        Second Sonine coefficient (0 = Maxwellian).
    """
    _check_dim(dim)
    if chi is None:
        chi = contact_value(packing_fraction(n, dim, sigma), dim)
    return _solid_angle_factor(dim) * chi * n * sigma ** (dim - 1) * np.sqrt(np.asarray(T) / m) * (1.0 - a2 / 16.0)


def mean_free_path(n, dim=3, sigma=1.0, chi=None):
    """Enskog mean free path ``l = <|v|> / omega`` (Maxwellian, independent of T).

    3D ``l = 1 / (sqrt(2) pi chi n sigma^2)``; 2D ``l = 1 / (2 sqrt(2) chi n sigma)``.
    """
    _check_dim(dim)
    if chi is None:
        chi = contact_value(packing_fraction(n, dim, sigma), dim)
    if dim == 3:
        return 1.0 / (math.sqrt(2.0) * math.pi * chi * n * sigma**2)
    return 1.0 / (2.0 * math.sqrt(2.0) * chi * n * sigma)


def enskog_cooling_rate(eps, n, T, dim=3, sigma=1.0, m=1.0, chi=None, a2=None):
    """Enskog cooling rate ``zeta`` in ``dT/dt = -zeta T`` (constant restitution).

    3D: ``zeta = (4 sqrt(pi)/3)(1 - eps^2) chi n sigma^2 sqrt(T/m)(1 + 3 a2/16)``;
    2D: ``zeta = sqrt(pi)(1 - eps^2) chi n sigma sqrt(T/m)(1 + 3 a2/16)``,
    i.e. ``zeta = omega_0 (1 - eps^2)(1 + 3 a2/16) / d`` with the Maxwellian
    collision frequency ``omega_0`` (van Noije & Ernst 1998).

    Parameters
    ----------
    a2 : float, optional
        Second Sonine coefficient; default :func:`sonine_a2` (pass 0 for the
        Maxwellian estimate).
    """
    if a2 is None:
        a2 = sonine_a2(eps, dim)
    omega0 = collision_frequency(n, T, dim, sigma, m, chi)
    return omega0 * (1.0 - eps**2) * (1.0 + 3.0 * a2 / 16.0) / dim


def haff_tau0(eps, n, T0=1.0, dim=3, sigma=1.0, m=1.0, chi=None, a2=None):
    """Haff time ``tau0 = 2 / zeta(T0)`` of ``T = T0 / (1 + t/tau0)^2``."""
    return 2.0 / enskog_cooling_rate(eps, n, T0, dim, sigma, m, chi, a2)


def haff_temperature(t, T0, tau0):
    """Haff's law ``T(t) = T0 / (1 + t/tau0)^2`` (Haff 1983)."""
    return T0 / (1.0 + np.asarray(t, dtype=float) / tau0) ** 2


def haff_collisions(t, tau0, omega0):
    """Collisions per particle by time t under Haff's law.

    ``s(t) = int_0^t omega dt = omega0 tau0 ln(1 + t/tau0)``, since omega is
    proportional to sqrt(T) = sqrt(T0)/(1 + t/tau0).
    """
    return omega0 * tau0 * np.log1p(np.asarray(t, dtype=float) / tau0)


def temperature_vs_collisions(s, eps, dim=3, a2=None, T0=1.0):
    """Temperature after ``s`` collisions per particle (constant restitution).

    ``T = T0 exp(-(1 - eps^2)(1 + 3 a2/16) s / d)``: ``dT/ds = -zeta T / omega``
    with ``zeta / omega = (1 - eps^2)(1 + 3 a2/16)/d`` (the ``a2`` correction of
    omega itself is left out, as in physics.md section 2). Independent of density.
    """
    if a2 is None:
        a2 = sonine_a2(eps, dim)
    return T0 * np.exp(-(1.0 - eps**2) * (1.0 + 3.0 * a2 / 16.0) * np.asarray(s, dtype=float) / dim)


def shear_viscosity(n, T, dim=3, sigma=1.0, m=1.0, chi=None):
    """Enskog shear viscosity of elastic hard spheres/disks (first Sonine order).

    3D: ``eta_s = eta_0 [1/chi + (4/5)(4 eta) + (4/25)(1 + 12/pi)(4 eta)^2 chi]``,
    ``eta_0 = (5 / (16 sigma^2)) sqrt(m T / pi)`` (Chapman & Cowling, ch. 16).
    2D: ``eta_s = eta_0 [1/chi + 2 eta + (1 + 8/pi) eta^2 chi]``,
    ``eta_0 = (1 / (2 sigma)) sqrt(m T / pi)`` (Gass, J. Chem. Phys. 54, 1898 (1971)).
    ``eta`` is the packing fraction. Inelastic corrections (Brey et al. 1998) are
    of relative order 1 - eps and left out.
    """
    _check_dim(dim)
    eta = packing_fraction(n, dim, sigma)
    if chi is None:
        chi = contact_value(eta, dim)
    if dim == 3:
        eta0 = 5.0 / (16.0 * sigma**2) * np.sqrt(m * T / np.pi)
        b = 4.0 * eta
        return eta0 * (1.0 / chi + 0.8 * b + 4.0 / 25.0 * (1.0 + 12.0 / np.pi) * b**2 * chi)
    eta0 = 1.0 / (2.0 * sigma) * np.sqrt(m * T / np.pi)
    return eta0 * (1.0 / chi + 2.0 * eta + (1.0 + 8.0 / np.pi) * eta**2 * chi)


def instability_length(eps, n, dim=3, sigma=1.0, chi=None, a2=None):
    """Box length above which the homogeneous cooling state is unstable to shear modes.

    Criterion (linearised hydrodynamics of the HCS; Goldhirsch & Zanetti,
    PRL 70, 1619 (1993); McNamara, Phys. Fluids A 5, 3056 (1993); Brey, Ruiz-Montero
    & Cubero, PRE 54, 3664 (1996)): a transverse velocity mode of wavenumber k decays
    viscously at rate ``nu k^2`` (kinematic viscosity ``nu = eta_s / (n m)``) while
    the thermal speed decays at rate ``zeta / 2``; the mode grows relative to the
    thermal speed when ``nu k^2 < zeta / 2``. Both rates scale with sqrt(T), so the
    critical wavenumber ``k_c = sqrt(zeta n m / (2 eta_s))`` is time-independent, and
    a periodic box whose smallest wavenumber ``2 pi / L`` is below ``k_c`` is unstable:

        ``L_c = 2 pi / k_c = 2 pi sqrt(2 eta_s / (zeta n m))``.

    Dilute limit: ``L_c = 10.78 l / sqrt(1 - eps^2)`` (3D) and ``10.03 l / sqrt(1 - eps^2)``
    (2D), with ``l`` the mean free path (physics.md section 4 quotes ~10 l).
    Density clusters (the longitudinal mode) follow the shear modes nonlinearly.

    Returns
    -------
    float
        ``L_c`` in units of sigma; independent of T.
    """
    if chi is None:
        chi = contact_value(packing_fraction(n, dim, sigma), dim)
    zeta = enskog_cooling_rate(eps, n, 1.0, dim, sigma, 1.0, chi, a2)
    eta_s = shear_viscosity(n, 1.0, dim, sigma, 1.0, chi)
    return 2.0 * np.pi * np.sqrt(2.0 * eta_s / (zeta * n))


# --------------------------------------------------------------------------------------
# Viscoelastic cooling
# --------------------------------------------------------------------------------------


def pair_damping(prefactor, sigma=1.0, m=1.0):
    """Pair constant ``b`` in ``beta = b g_n^(1/5)`` for two identical particles.

    ``b = k (R_eff / m_eff^2)^(1/5)`` with ``R_eff = sigma/4``, ``m_eff = m/2``
    (ARCHITECTURE.md), i.e. ``b = k (sigma / m^2)^(1/5)``; ``b = k`` in reduced units.
    """
    return prefactor * (0.25 * sigma / (0.5 * m) ** 2) ** 0.2


def effective_inelasticity(b, T, m=1.0, order=1):
    """Collision-kernel average of ``1 - eps^2`` at leading order in beta.

    The energy a collision removes is ``(1 - eps^2) m_eff g_n^2 / 2`` and collisions
    with normal speed ``g_n`` occur at a rate proportional to ``g_n`` (Enskog kernel),
    so the cooling rate involves ``<(1 - eps^2) g_n^3>`` over the distribution of
    ``g_n = g . n_hat``. For a Maxwellian, the component of the relative velocity
    along a fixed ``n_hat`` is Gaussian with variance ``2T/m`` in any dimension, and

        ``int_0^inf x^p exp(-x^2 / (2 s^2)) dx  ~  s^p 2^(p/2) Gamma((p+1)/2)``.

    With ``1 - eps^2 = 2 C1 beta + O(beta^2) = 2 C1 b g_n^(1/5)`` the ratio of the
    ``p = 16/5`` to the ``p = 3`` moment gives the effective constant-restitution
    value entering ``zeta = omega (1 - eps^2)_eff / d``:

        ``(1 - eps^2)_eff = 2 C1 b Gamma(21/10) (4 T / m)^(1/10)``.

    Relative corrections are of order ``beta`` at thermal speed: with
    ``order=2`` the next term of ``1 - eps^2 = 2 C1 beta - (C1^2 + 2 C2) beta^2``
    is averaged the same way (``p = 17/5``), adding
    ``-(C1^2 + 2 C2) b^2 Gamma(11/5) (4 T / m)^(1/5)``.
    """
    x = 4.0 * np.asarray(T, dtype=float) / m
    out = 2.0 * C1 * b * _gamma(2.1) * x**0.1
    if order == 2:
        out = out - (C1**2 + 2.0 * C2) * b**2 * _gamma(2.2) * x**0.2
    elif order != 1:
        raise ValueError(f"order must be 1 or 2, got {order!r}")
    return out


def viscoelastic_cooling_rate(prefactor, n, T, dim=3, sigma=1.0, m=1.0, chi=None, order=1):
    """Leading-order cooling rate of a viscoelastic gas, ``dT/dt = -zeta(T) T``.

    ``zeta(T) = omega_0(T) (1 - eps^2)_eff(T) / d`` with
    :func:`effective_inelasticity`; so ``zeta`` is proportional to ``T^(3/5)``.
    In 3D: ``zeta = (8 sqrt(pi)/3) C1 Gamma(21/10) b (4T/m)^(1/10) chi n sigma^2 sqrt(T/m)``.
    The Sonine correction to the velocity distribution is of order beta and left out;
    ``order=2`` adds the second-order term of eps(beta) (see
    :func:`effective_inelasticity`), which is not a power of T.

    Parameters
    ----------
    prefactor : float
        ``k`` of ``beta = k (R_eff g_n / m_eff^2)^(1/5)`` (the config's ``damping``
        in reduced units).
    """
    b = pair_damping(prefactor, sigma, m)
    omega0 = collision_frequency(n, T, dim, sigma, m, chi)
    return omega0 * effective_inelasticity(b, T, m, order) / dim


def viscoelastic_tau0(prefactor, n, T0=1.0, dim=3, sigma=1.0, m=1.0, chi=None, order=1):
    """Time constant of viscoelastic cooling ``T = T0 (1 + t/tau0)^(-5/3)``.

    Derivation: ``dT/dt = -zeta(T) T`` with ``zeta(T) = zeta_0 (T/T0)^(3/5)``
    (:func:`viscoelastic_cooling_rate`) gives ``d(T^(-3/5))/dt = (3/5) zeta_0 T0^(-3/5)``,
    hence ``(T/T0)^(-3/5) = 1 + (3/5) zeta_0 t`` and

        ``1/tau0 = (3/5) zeta(T0)``,   ``T = T0 (1 + t/tau0)^(-5/3)``.

    In 3D this is ``1/tau0 = (8 sqrt(pi)/5) C1 Gamma(21/10) b (4 T0/m)^(1/10)
    chi n sigma^2 sqrt(T0/m)``. It agrees with Brilliantov & Pöschel, PRE 61, 5573
    (2000) (also Schwager & Pöschel, PRE 57, 650 (1998)), written there as
    ``1/tau0 = (16/5) q0 delta / tau_c(0)`` with ``q0 = 2^(1/5) Gamma(21/10) C1 / 8``,
    ``delta = A kappa^(2/5) (T0/m)^(1/10)`` and ``1/tau_c(0) = 4 sqrt(pi) chi n sigma^2
    sqrt(T0/m)``, where their expansion ``eps = 1 - C1 A kappa^(2/5) g^(1/5)`` has
    ``A kappa^(2/5) = b`` (our ``beta = (3/2) A rho^(2/5) g^(1/5)``, i.e. ``kappa =
    (3/2)^(5/2) rho``; papers expanding in ``q = 2 beta / 3`` carry ``(3/2) C1``
    instead). The check is ``tests/test_theory.py``.

    ``order=2`` returns ``1 / ((3/5) zeta(T0))`` with the second-order cooling rate:
    the time scale of the initial decay, which the fitted tau0 of a run with
    damping ``b`` approaches better (relative shift ~ 1.5 b at T0 = 1); the
    late-time law is the leading-order one since beta -> 0 as the gas cools.
    """
    return 1.0 / (0.6 * viscoelastic_cooling_rate(prefactor, n, T0, dim, sigma, m, chi, order))


def viscoelastic_temperature(t, T0, tau0):
    """Viscoelastic cooling law ``T(t) = T0 (1 + t/tau0)^(-5/3)``."""
    return T0 * (1.0 + np.asarray(t, dtype=float) / tau0) ** (-5.0 / 3.0)


def viscoelastic_collisions(t, tau0, omega0):
    """Collisions per particle by time t under the viscoelastic law.

    ``omega ~ sqrt(T) = sqrt(T0)(1 + t/tau0)^(-5/6)``, so
    ``s(t) = 6 omega0 tau0 [(1 + t/tau0)^(1/6) - 1]``.
    """
    return 6.0 * omega0 * tau0 * ((1.0 + np.asarray(t, dtype=float) / tau0) ** (1.0 / 6.0) - 1.0)


# ---------------------------------------------------------------- driven gases
def driven_sonine_a2(eps, dim=3):
    """Second Sonine coefficient of the white-noise driven steady state (constant eps).

    van Noije & Ernst, Granular Matter 1, 57 (1998), first Sonine approximation:
    ``a2 = 16 (1 - eps)(1 - 2 eps^2) / [73 + 56 d - 3 eps (35 + 8 d) + 30 eps^2 (1 - eps)]``.

    Derivation (the check of this form): with the collision moments
    ``mu_p = -int c^p I(f, f)`` of the scaled distribution, to first order in a2
    ``mu2 = A (1 - eps^2)(1 + 3 a2/16)`` and ``mu4 = A [(1 - eps^2)(d + 3/2 + eps^2) + a2 B]``.
    The cooling state requires ``mu4 = (d + 2)(1 + a2) mu2``, which with the cooling-state
    a2 of :func:`sonine_a2` fixes ``B``; the driving term ``(xi^2/2) nabla_c^2 f`` of
    white noise gives instead ``mu4 = (d + 2) mu2`` (the c^2 and c^4 moments of the
    Laplacian are 2 d and 4 (d + 2) <c^2>), and eliminating B yields the form above.
    """
    _check_dim(dim)
    eps = np.asarray(eps, dtype=float)
    num = 16.0 * (1.0 - eps) * (1.0 - 2.0 * eps**2)
    den = 73.0 + 56.0 * dim - 3.0 * eps * (35.0 + 8.0 * dim) + 30.0 * eps**2 * (1.0 - eps)
    out = num / den
    return out[()] if out.ndim == 0 else out


def driven_temperature(heating_rate, eps, n, dim=3, sigma=1.0, m=1.0, chi=None, a2=None):
    """Steady temperature of a white-noise driven gas, ``zeta(T) T = H`` (constant eps).

    With the Enskog cooling rate (:func:`enskog_cooling_rate`) ``zeta = Z0 sqrt(T)``:
    ``T = (H / Z0)^(2/3)``. ``heating_rate`` H is dT/dt of the driving alone.

    Parameters
    ----------
    a2 : float, optional
        Second Sonine coefficient in zeta; default :func:`driven_sonine_a2`.
    """
    if a2 is None:
        a2 = driven_sonine_a2(eps, dim)
    z0 = enskog_cooling_rate(eps, n, 1.0, dim, sigma, m, chi, a2)
    return (np.asarray(heating_rate, dtype=float) / z0) ** (2.0 / 3.0)


def driving_interval(cooling_rate, fraction=0.01):
    """Interval between white-noise kicks: ``dt_k = fraction / zeta``.

    Between kicks the gas cools by ``zeta dt_k``; a kick adds as much. The steady
    state (T and a2) is independent of dt_k to within the statistics of a long run
    for ``zeta dt_k <= 0.02``, measured with ``scripts/driven_steady_state.py``;
    the default keeps a safety factor of 2.
    """
    return fraction / cooling_rate


def effective_restitution(prefactor, T, m=1.0, sigma=1.0, end="overlap"):
    """Effective constant restitution coefficient of a viscoelastic gas at temperature T.

    The constant eps_eff that gives the same Enskog cooling rate as the impact-speed
    dependent eps(beta), beta = b g_n^(1/5) (:func:`pair_damping`), for a
    Maxwellian gas (Dubey, Bodrova, Puri & Brilliantov, arXiv:1209.5326 (2013)):
    collisions with normal speed g_n occur at a rate ~ g_n and remove
    (1 - eps^2) m_eff g_n^2 / 2, and g_n along a fixed direction is Gaussian with
    variance 2 T / m, so

        1 - eps_eff^2 = int (1 - eps(b g^(1/5))^2) g^3 exp(-g^2 / (4 T/m)) dg
                        / int g^3 exp(-g^2 / (4 T/m)) dg,

    evaluated by adaptive quadrature (scipy) in u = g^2 / (4 T/m) with eps(beta) from the
    engine's restitution table (:func:`granulargas.contact.restitution_table`, within 1e-8
    of the contact ODE). To leading order in beta it is :func:`effective_inelasticity`.
    """
    from scipy.integrate import quad

    from granulargas.contact import restitution_table

    b = pair_damping(prefactor, sigma, m)
    scale = 4.0 * float(T) / m
    u_max = 200.0  # u e^-u < 1e-84 beyond
    table = restitution_table(max(b * (scale * u_max) ** 0.1 * 1.01, 1e-3), end=end)

    def lost(u):
        eps = float(table.restitution(b * (scale * u) ** 0.1))
        return u * math.exp(-u) * (1.0 - eps * eps)

    loss = quad(lost, 0.0, u_max, epsabs=1e-13, epsrel=1e-11, limit=200, points=[1.0, 10.0])[0]
    return math.sqrt(1.0 - loss)  # int u exp(-u) du = 1


def viscoelastic_driven_state(heating_rate, prefactor, n, dim=3, sigma=1.0, m=1.0, chi=None,
                              end="overlap"):
    """Steady temperature and a2 of a white-noise driven viscoelastic gas.

    The effective-restitution model of Dubey, Bodrova, Puri & Brilliantov (2013): at the
    steady temperature T the gas behaves as one of constant eps_eff(T)
    (:func:`effective_restitution`), so T solves ``zeta(eps_eff(T), T) T = H`` with the
    Enskog rate and a2 = :func:`driven_sonine_a2` (eps_eff(T)) in it; a2 is that value
    at the solution. Returns (T, a2, eps_eff).
    """
    t = float(driven_temperature(heating_rate, 1.0 - effective_inelasticity(
        pair_damping(prefactor, sigma, m), 1.0, m) / 2.0, n, dim, sigma, m, chi))
    # fixed point T -> T_ss(eps_eff(T)): a contraction (eps_eff depends on T^(1/10))
    for _ in range(100):
        e = effective_restitution(prefactor, t, m, sigma, end)
        t_new = float(driven_temperature(heating_rate, e, n, dim, sigma, m, chi))
        if abs(t_new - t) <= 1e-13 * t:
            break
        t = t_new
    return t_new, float(driven_sonine_a2(e, dim)), e
