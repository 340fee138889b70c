"""Cooling of a viscoelastic gas at leading order in the damping (closed forms).

The engine uses ``beta = k (R_eff g_n / m_eff^2)^(1/5)`` (ARCHITECTURE.md) and the
restitution coefficient ``eps = 1 - C1 beta + C2 beta^2 - ...`` with
``C1 = Gamma(3/5) sqrt(pi) / (2^(1/5) 5^(2/5) Gamma(21/10)) = 1.15345``, ``C2 = (3/5) C1^2``
(Schwager & Pöschel 1997, eq. (32); Ramírez, Pöschel, Brilliantov & Schwager,
PRE 60, 4465 (1999)). Two identical particles of diameter ``sigma`` and mass ``m``
have ``beta = b g_n^(1/5)`` with the pair constant
``b = k ((sigma/4) / (m/2)^2)^(1/5)`` (:func:`granulargas.contact.material.pair_constant`);
for reference particles (``sigma = m = 1``) ``b = k``, the config's ``damping``.

The functions here take the prefactor k and the particles' ``sigma``, ``m``; the
kinetic theory with the exact eps(beta) is :mod:`granulargas.theory.gas`.
"""

from __future__ import annotations

import warnings

import numpy as np

from granulargas.contact.material import pair_constant
from granulargas.contact.pade import C1, C2
from granulargas.theory.enskog import collision_frequency

__all__ = [
    "C1",
    "C2",
    "pair_damping",
    "effective_inelasticity",
    "viscoelastic_cooling_rate",
    "viscoelastic_tau0",
    "viscoelastic_temperature",
    "viscoelastic_collisions",
]


def identical_pair_constant(prefactor, sigma=1.0, m=1.0):
    """Pair constant ``b`` of two identical particles (diameter ``sigma``, mass ``m``):
    :func:`granulargas.contact.material.pair_constant` with ``R = sigma/2``."""
    return pair_constant(prefactor, 0.5 * sigma, 0.5 * sigma, m, m)


def pair_damping(prefactor, sigma=1.0, m=1.0):
    """Deprecated name of the pair constant ``b`` of two identical particles
    (use :func:`granulargas.contact.material.pair_constant`)."""
    warnings.warn("theory.pair_damping is deprecated: use granulargas.contact.material.pair_constant "
                  "(the pair constant b, beta = b g^(1/5))", DeprecationWarning, stacklevel=2)
    return identical_pair_constant(prefactor, sigma, m)


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
    from scipy.special import gamma as _gamma  # here, not at the top: a run's start-up loads no scipy

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
    b = identical_pair_constant(prefactor, sigma, m)
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
