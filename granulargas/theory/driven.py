"""The white-noise driven steady state of a granular gas (Enskog kinetic theory).

A white-noise thermostat (Williams & MacKintosh 1996; van Noije & Ernst 1998)
gives every particle independent Gaussian velocity kicks; alone it raises the
temperature as ``dT/dt = H`` (the heating rate). With collisions the gas settles
where heating balances cooling, ``zeta(T) T = H``.

* Constant restitution: ``zeta`` is the Enskog cooling rate
  (:func:`granulargas.theory.enskog_cooling_rate`) with the driven second Sonine
  coefficient :func:`driven_sonine_a2` (van Noije & Ernst 1998).
* Viscoelastic particles: the effective constant restitution coefficient of Dubey,
  Bodrova, Puri & Brilliantov, arXiv:1209.5326 (2013): at temperature T the gas
  dissipates as one of constant ``eps_eff(T)``, with ``1 - eps_eff^2`` the
  collision-kernel average of ``1 - eps^2`` over the impact speeds
  (:func:`granulargas.theory.gas.effective_inelasticity`, exact eps(beta)); the
  steady state solves ``zeta(eps_eff(T), T) T = H``
  (:func:`viscoelastic_driven_state`).
* Any restitution law, first Sonine with the exact eps(g): the moment equations of
  :mod:`granulargas.theory.moments` with the heating term (:func:`driven_state`);
  for constant eps the same as the first item, for viscoelastic particles it also
  gives a2 without the effective-restitution approximation.
"""

from __future__ import annotations

import math

import numpy as np

from granulargas.theory.enskog import (_check_dim, contact_value, enskog_cooling_rate,
                                       packing_fraction)
from granulargas.theory.gas import Gas, effective_inelasticity

#: cooling times 1/zeta(T_ss) after which a driven gas that starts far from it is taken to be in
#: its steady state (the relaxation ``T_ss - T ~ exp(-3 zeta t / 2)`` near it leaves exp(-7.5))
RELAXATION_TIMES = 5.0

__all__ = [
    "driven_state",
    "driven_sonine_a2",
    "driven_temperature",
    "driving_interval",
    "effective_restitution",
    "relaxation_temperature",
    "viscoelastic_driven_state",
]


def driven_sonine_a2(eps, dim=3):
    """Second Sonine coefficient of the white-noise driven steady state (constant eps).

    van Noije & Ernst, Granular Matter 1, 57 (1998), first Sonine approximation:
    ``a2 = 16 (1 - eps)(1 - 2 eps^2) / [73 + 56 d - 3 eps (35 + 8 d) + 30 eps^2 (1 - eps)]``.

    Derivation (the check of this form): with the collision moments
    ``mu_p = -int c^p I(f, f)`` of the scaled distribution, to first order in a2
    ``mu2 = A (1 - eps^2)(1 + 3 a2/16)`` and ``mu4 = A [(1 - eps^2)(d + 3/2 + eps^2) + a2 B]``.
    The cooling state requires ``mu4 = (d + 2)(1 + a2) mu2``, which with the cooling-state
    a2 (:func:`granulargas.theory.sonine_a2`) fixes ``B``; the driving term
    ``(xi^2/2) nabla_c^2 f`` of white noise gives instead ``mu4 = (d + 2) mu2`` (the
    c^2 and c^4 moments of the Laplacian are 2 d and 4 (d + 2) <c^2>), and eliminating
    B yields the form above.
    """
    _check_dim(dim)
    eps = np.asarray(eps, dtype=float)
    num = 16.0 * (1.0 - eps) * (1.0 - 2.0 * eps**2)
    den = 73.0 + 56.0 * dim - 3.0 * eps * (35.0 + 8.0 * dim) + 30.0 * eps**2 * (1.0 - eps)
    out = num / den
    return out[()] if out.ndim == 0 else out


def driven_temperature(heating_rate, eps, n, dim=3, sigma=1.0, m=1.0, chi=None, a2=None):
    """Steady temperature of a white-noise driven gas, ``zeta(T) T = H`` (constant eps).

    With the Enskog cooling rate ``zeta = Z0 sqrt(T)``: ``T = (H / Z0)^(2/3)``.
    ``heating_rate`` H is dT/dt of the driving alone. Infinite where the gas does not
    cool (``Z0 = 0``: elastic, or a density that underflows).

    Parameters
    ----------
    a2 : float, optional
        Second Sonine coefficient in zeta; default :func:`driven_sonine_a2`.
    """
    if a2 is None:
        a2 = driven_sonine_a2(eps, dim)
    z0 = enskog_cooling_rate(eps, n, 1.0, dim, sigma, m, chi, a2)
    with np.errstate(divide="ignore"):  # a gas that does not cool (z0 = 0) has no steady state: inf
        return (np.asarray(heating_rate, dtype=float) / z0) ** (2.0 / 3.0)


def driving_interval(cooling_rate, fraction=0.02):
    """Interval between white-noise kicks: ``dt_k = fraction / zeta``.

    Between kicks the gas cools by ``zeta dt_k`` of its temperature, and a kick puts
    as much back. Measured with ``scripts/validation/driven_steady_state.py`` (3D, eps = 0.8,
    packing 0.05, N = 2000, 200 cooling times, T sampled half-way between kicks):
    T_ss / T_theory = 1.0071(15), 1.0058(9), 1.0049(17), 1.0025(22), 0.9870(21),
    0.9334(14) for ``zeta dt_k`` = 0.002, 0.01, 0.05, 0.2, 0.5, 1, and a2 the same
    within its error (0.0008) up to 0.5. The steady state is independent of dt_k
    within the statistics for ``zeta dt_k <= 0.05`` (``omega dt_k <= 0.4`` collisions
    per particle between kicks here); the default 0.02 keeps a margin, since the
    deviation grows faster than linearly (-0.5 % at 0.2, -2 % at 0.5, -7 % at 1).
    """
    return fraction / cooling_rate


def effective_restitution(prefactor, T, dim=3, sigma=1.0, m=1.0, end="overlap"):
    """Effective constant restitution coefficient of a viscoelastic gas at temperature T.

    ``eps_eff = sqrt(1 - (1 - eps^2)_eff(T))`` with the collision-kernel average of
    :func:`granulargas.theory.gas.effective_inelasticity` (exact eps(beta)); the constant
    eps that dissipates at the same rate (Dubey, Bodrova, Puri & Brilliantov 2013).
    """
    gas = Gas(dimension=dim, packing_fraction=0.0, density=0.0, sigma=sigma, mass=m,
              temperature=float(T), model="viscoelastic", prefactor=float(prefactor), end=end)
    return math.sqrt(max(1.0 - float(effective_inelasticity(gas, float(T))), 0.0))


def viscoelastic_driven_state(heating_rate, prefactor, n, dim=3, sigma=1.0, m=1.0, chi=None,
                              end="overlap"):
    """Steady temperature and a2 of a white-noise driven viscoelastic gas.

    The effective-restitution model of Dubey, Bodrova, Puri & Brilliantov (2013):
    T solves ``zeta(eps_eff(T), T) T = H`` with the Enskog rate and the driven a2
    of ``eps_eff(T)`` (:func:`effective_restitution`, :func:`driven_sonine_a2`),
    found by fixed-point iteration (a contraction: eps_eff depends on T only through
    beta ~ T^(1/10)). Returns (T, a2, eps_eff).
    """
    if chi is None:
        chi = contact_value(packing_fraction(n, dim, sigma), dim)
    t = float(driven_temperature(heating_rate, effective_restitution(prefactor, 1.0, dim, sigma, m,
                                                                     end), n, dim, sigma, m, chi))
    for _ in range(200):
        e = effective_restitution(prefactor, t, dim, sigma, m, end)
        t_new = float(driven_temperature(heating_rate, e, n, dim, sigma, m, chi))
        if abs(t_new - t) <= 1e-13 * t:
            break
        t = t_new
    return t_new, float(driven_sonine_a2(e, dim)), e


def driven_state(gas, heating_rate):
    """Steady temperature and a2 of a white-noise driven gas with any restitution law.

    The moment equations of :mod:`granulargas.theory.moments` (first Sonine
    approximation with the exact eps(g), :func:`granulargas.theory.gas.cooling_rates`)
    with the white-noise heating added: ``dT/dt = -zeta(T, a2) T + H`` and

        da2/dt = (da2/dt)_cooling - 2 a2 H / T

    (the heating ``(H/m) nabla_v^2 f / 2`` adds ``2 (d + 2) H <v^2> / m`` to
    ``d<v^4>/dt``, and the change of v_T^4 takes ``2 (1 + a2) H / T`` from the
    scaled moment). Both vanish in the steady state, where ``H / T = zeta(T, a2)``;
    to first order in a2 (the a2^2 terms dropped, as in the cooling equations) the
    second reads ``(da2/dt)_cooling - 2 a2 zeta(T, 0) = 0``, linear in a2 at a given
    T, and the first is then solved for T. For a constant eps this is
    :func:`driven_temperature` with :func:`driven_sonine_a2` exactly; for a
    viscoelastic gas it refines the effective-restitution model
    (:func:`viscoelastic_driven_state`, Dubey et al. 2013), whose a2 is the
    constant-eps value at eps_eff. Returns (T, a2).

    Parameters
    ----------
    gas : granulargas.theory.gas.Gas
        The gas (its ``temperature`` is not used).
    heating_rate : float
        H > 0.
    """
    from scipy.optimize import brentq

    from granulargas.theory.gas import cooling_rates

    h = float(heating_rate)

    def a2_at(T):
        z0, d0, _ = cooling_rates(gas, T, 0.0)
        _, d1, _ = cooling_rates(gas, T, 1.0)
        return float(-d0 / ((d1 - d0) - 2.0 * z0))

    def balance(log_t):
        T = math.exp(log_t)
        zeta, _, _ = cooling_rates(gas, T, a2_at(T))
        return math.log(float(zeta) * T / h)

    lo = hi = math.log(max(gas.temperature, 1e-300))
    while balance(lo) > 0.0:
        lo -= 2.0
    while balance(hi) < 0.0:
        hi += 2.0
    T = math.exp(brentq(balance, lo, hi, xtol=1e-13, rtol=1e-13))
    return T, a2_at(T)


def relaxation_temperature(t, T0, heating_rate, T_steady):
    """T(t) of a driven gas relaxing from ``T0`` towards its steady temperature ``T_steady``.

    ``dT/dt = H - zeta(T) T`` with ``zeta(T) ~ sqrt(T)`` at the steady state's a2 and
    eps, so that ``zeta(T) T = H (T / T_ss)^(3/2)``, integrated from ``T(t[0]) = T0``
    (``t`` increasing). Without a steady state (``T_steady`` infinite: elastic
    collisions) ``T = T0 + H (t - t[0])``.
    """
    from scipy.integrate import solve_ivp

    t = np.atleast_1d(np.asarray(t, dtype=float))
    h, T0 = float(heating_rate), float(T0)
    if not math.isfinite(T_steady):
        return T0 + h * (t - t[0])
    if t[-1] == t[0]:
        return np.full(t.shape, T0)
    sol = solve_ivp(lambda _, y: [h * (1.0 - (y[0] / T_steady) ** 1.5)], (t[0], t[-1]), [T0], t_eval=t,
                    rtol=1e-10, atol=1e-14 * min(T0, T_steady), method="LSODA")
    return sol.y[0]
