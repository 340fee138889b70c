"""Run-level checks: is the model a run asks for valid over the whole run?

Everything here is predicted from a :class:`granulargas.io.config.RunConfig`
before the run, with kinetic theory (:mod:`granulargas.theory`) and the contact
module (:mod:`granulargas.contact`); nothing is simulated. Identical particles
of the config's (mean) diameter ``sigma`` and mass ``m`` are assumed.

Impact speeds
-------------
In a Maxwellian gas the normal component ``g`` of the relative velocity along a
fixed direction is Gaussian with variance ``s^2 = 2T/m``; collisions sample it
with weight ``g`` (the collision kernel), so the normal impact speeds of
collisions follow the Rayleigh law ``p(g) = g/s^2 exp(-g^2/(2 s^2))``. Its
quantiles are ``g_q = s sqrt(-2 ln(1 - q))``; the energy a collision removes
weights it by a further ``g^2``. "Thermal impact speeds" below are the central
90 % of collisions (quantiles 0.05 and 0.95).

Cooling with the viscoelastic law (no power-law approximation)
--------------------------------------------------------------
``dT/dt = -omega(T) (1 - eps^2)_eff(T) T / d`` with the Enskog collision
frequency ``omega`` (physics.md sec. 2, a2 = 0) and the energy-weighted kernel
average ``(1 - eps^2)_eff = <(1 - eps^2(beta(g))) g^3> / <g^3>``, evaluated with
the exact eps(beta) (restitution table, error 2e-10) by Gauss-Laguerre
quadrature in ``x = g^2/(2 s^2)``. Time and collisions per particle are then
quadratures in ``ln T``:

    t(T) = d int_T^T0 dT' / (omega (1-eps^2)_eff T'),
    s(T) = d int_T^T0 dT' / ((1-eps^2)_eff T').

At small beta this reduces to ``T = T0 (1 + t/tau0)^(-5/3)``
(:func:`granulargas.theory.viscoelastic_tau0`; the tests check it).

Instantaneous collisions: t_c / t_free
--------------------------------------
Event-driven dynamics assumes binary, instantaneous collisions. During a contact
of duration ``t_c`` each of the two particles meets a third at rate ``omega =
1/t_free``, so a fraction ``f = 1 - exp(-2 t_c / t_free) ~ 2 t_c/t_free`` of
collisions are in truth three-body contacts. Such a contact changes the energy
dissipated in the collisions involved by an amount of their own order, so the
relative error of the cooling rate is of order ``f``. We warn when ``f`` exceeds
2 %, i.e. ``t_c / t_free > TC_RATIO_WARN = 0.01``: the same 2 % that
:mod:`granulargas.run.advise` takes as the default tolerance of T(t). The duration
``t_c = tau_c(beta) rho^(-2/5) g^(-1/5)`` (seed eq. 2 rescaled) needs the
stiffness rho, known only on the material route; the ``damping`` route fixes
beta alone (hard spheres: ``t_c -> 0``), and the ratio is then reported as not
determined. For the TC model the ratio ``tc_time / t_free`` is reported (a
collision within tc_time of the previous one is made elastic). The ratio grows
as ``T^(2/5)``, so it is largest at the start of a cooling run, where it is
evaluated (collision-averaged t_c at T0).

Velocity underflow
------------------
Squared speeds ``~ T/m`` enter the pair predictions; below about 1e-300 they
become subnormal (slow, inexact) and then zero. A run whose predicted final
temperature falls below ``UNDERFLOW_T = 1e-250`` (margin for products of speeds
and small distances) is refused: constant eps reaches it after
``s = 250 d ln(10) / (1 - eps^2)`` collisions per particle (2400 for eps = 0.5 in
3D); a viscoelastic gas, whose ``T ~ t^(-5/3)``, never does in practice.

Centre-of-mass drift
--------------------
Zero total momentum holds only to round-off: the centre-of-mass velocity stays
at ~1e-16 of the *initial* thermal speed (measured: 7e-17 for 300 particles).
When the thermal speed falls below it (T/T0 ~ 1e-32) the whole gas drifts,
neighbour-list events per collision grow without bound (x500 by T/T0 = 1e-40,
``tests/engine/test_stability.py``), though collisions stay right. We warn when
the predicted ``T_end / T0 < DRIFT_T_RATIO = 1e-30``; the remedy is a restart
with the centre-of-mass velocity removed.

Runner API (one line each, for the run summary)
-----------------------------------------------
* :func:`check_run` ``(config) -> RunValidity``: all the numbers;
* :func:`summary_lines` ``(config) -> list[str]``: one-line reports and warnings;
* :func:`contact_time_ratio` ``(config, temperature=None) -> float | None``;
* :func:`raise_if_invalid` ``(config)``: ConfigError when a run cannot be right.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial.legendre import leggauss

from granulargas import theory
from granulargas.contact import restitution_table
from granulargas.contact.material import rho_from_material
from granulargas.errors import ConfigError
from granulargas.run.prepare import reduced_prefactor

__all__ = [
    "TC_RATIO_WARN",
    "UNDERFLOW_T",
    "THERMAL_QUANTILES",
    "Gas",
    "RunValidity",
    "gas_from_config",
    "impact_speed_quantile",
    "restitution_spread",
    "effective_inelasticity",
    "viscoelastic_cooling",
    "run_temperature_range",
    "contact_time_ratio",
    "check_run",
    "summary_lines",
    "raise_if_invalid",
]

#: warn when t_c / t_free exceeds this (2 % of collisions would be three-body contacts)
TC_RATIO_WARN = 0.01
#: refuse runs whose predicted final temperature (in units of m, reduced) falls below this
UNDERFLOW_T = 1e-250
#: warn when the predicted T_end / T0 falls below this: the centre-of-mass velocity left by
#: round-off (~1e-16 of the initial thermal speed) then overtakes the thermal speed
DRIFT_T_RATIO = 1e-30
#: central fraction of collision impact speeds called "thermal"
THERMAL_QUANTILES = (0.05, 0.95)
#: beta above which the viscoelastic force is questionable (contact.material.BETA_VALID_MAX)
BETA_VALID = 1.0

_NODES = 96


def _kernel_nodes(power: int, nodes: int = _NODES):
    """Nodes u = g / s and normalised weights for averages over ``g^power exp(-g^2/(2 s^2)) dg``.

    eps depends on g through g^(1/5) (and on sqrt of that for the ``force`` end), so
    Gauss-Laguerre in x = g^2/(2 s^2) converges slowly (x^(1/10) is not smooth at 0).
    With x = y^10 every factor is smooth in y: Gauss-Legendre on y in [0, 60^(1/10)]
    (e^-60 neglected) gives ~1e-12.
    """
    y, w = leggauss(nodes)
    y_max = 60.0**0.1
    y = 0.5 * y_max * (y + 1.0)
    w = 0.5 * y_max * w
    x = y**10
    w = w * x ** (0.5 * (power - 1)) * np.exp(-x) * 10.0 * y**9
    return np.sqrt(2.0 * x), w / w.sum()


@dataclass(frozen=True)
class Gas:
    """What the checks need from a config (reduced units).

    Attributes
    ----------
    dimension : int
    packing_fraction : float
    density : float
        Number density n (sigma^-d) of particles of the mean diameter.
    sigma, mass : float
        Mean diameter and the mass of a particle of that diameter.
    temperature : float
        Initial temperature T0.
    model : str
        "elastic", "constant" or "viscoelastic".
    restitution : float or None
        Constant eps.
    tc_time : float or None
    prefactor : float or None
        Viscoelastic k (reduced).
    damping : float or None
        Pair constant b of two mean particles: beta = b g^(1/5).
    end : str
        Contact end ("overlap" or "force").
    material : object or None
        ``config.collision.material`` (SI) when given.
    end_time, collisions_per_particle : float or None
        The run's stop conditions.
    source : str
    """

    dimension: int
    packing_fraction: float
    density: float
    sigma: float
    mass: float
    temperature: float
    model: str
    restitution: float | None = None
    tc_time: float | None = None
    prefactor: float | None = None
    damping: float | None = None
    end: str = "overlap"
    material: object = None
    end_time: float | None = None
    collisions_per_particle: float | None = None
    source: str = "<config>"

    @property
    def collision_frequency(self):
        """Enskog collision frequency per particle at T0."""
        return float(theory.collision_frequency(self.density, self.temperature, self.dimension, self.sigma,
                                                self.mass))

    def beta(self, g):
        """beta of two mean particles at normal impact speed g."""
        return self.damping * np.asarray(g, dtype=float) ** 0.2


def gas_from_config(config) -> Gas:
    """Collect the parameters of a :class:`~granulargas.io.config.RunConfig`."""
    s, p, c = config.system, config.particles, config.collision
    d = s.dimension
    sigma = p.diameter
    vol = math.pi * sigma**3 / 6.0 if d == 3 else math.pi * sigma**2 / 4.0
    mass = p.mass if p.mass is not None else p.density * vol
    k = b = None
    if c.model == "viscoelastic":
        k = float(reduced_prefactor(config))
        b = float(theory.pair_damping(k, sigma, mass))
    return Gas(
        dimension=d, packing_fraction=s.packing_fraction, density=s.packing_fraction / vol, sigma=sigma,
        mass=mass, temperature=config.initial.temperature, model=c.model, restitution=c.restitution,
        tc_time=c.tc_time, prefactor=k, damping=b, end=c.contact_end, material=c.material,
        end_time=config.run.end_time, collisions_per_particle=config.run.collisions_per_particle,
        source=config.source,
    )


# ---------------------------------------------------------------- impact speeds


def impact_speed_quantile(q, temperature, mass=1.0):
    """Normal impact speed below which a fraction q of collisions lie (Rayleigh law, module doc)."""
    s = np.sqrt(2.0 * np.asarray(temperature, dtype=float) / mass)
    return s * np.sqrt(-2.0 * np.log1p(-np.asarray(q, dtype=float)))


def _eps(beta, end):
    """Exact eps(beta) through the engine's table (2e-10)."""
    b = np.asarray(beta, dtype=float)
    table = restitution_table(max(float(np.max(b)) * 1.001, 1e-6), end=end)
    return table.restitution(b)


def restitution_spread(gas: Gas, t_high, t_low, quantiles=THERMAL_QUANTILES):
    """Range of eps over the thermal impact speeds between two temperatures.

    Returns
    -------
    dict
        ``eps_min``, ``eps_max`` (eps of the fast collisions at ``t_high`` and
        of the slow ones at ``t_low``), ``beta_max``, ``beta_min``, ``spread`` =
        eps_max - eps_min.
    """
    g_hi = impact_speed_quantile(quantiles[1], t_high, gas.mass)
    g_lo = impact_speed_quantile(quantiles[0], t_low, gas.mass)
    b_hi, b_lo = float(gas.beta(g_hi)), float(gas.beta(g_lo))
    e_lo, e_hi = _eps([b_hi, b_lo], gas.end)
    return {"eps_min": float(e_lo), "eps_max": float(e_hi), "beta_max": b_hi, "beta_min": b_lo,
            "spread": float(e_hi - e_lo)}


def effective_inelasticity(gas: Gas, temperature, nodes: int = _NODES, restitution=None):
    """``(1 - eps^2)_eff(T) = <(1 - eps^2) g^3> / <g^3>`` over the collision kernel.

    Quadrature of :func:`_kernel_nodes` (weight ``g^3 exp(-g^2/(2 s^2))``).

    Parameters
    ----------
    temperature : float or array (K,)
    restitution : callable, optional
        ``eps(beta)`` (vectorised) to use instead of the exact law (to predict the
        effect of an approximation, e.g. a truncated series).

    Returns
    -------
    float or array (K,)
    """
    u, w = _kernel_nodes(3, nodes)
    T = np.atleast_1d(np.asarray(temperature, dtype=float))
    s = np.sqrt(2.0 * T / gas.mass)
    g = s[:, None] * u[None, :]
    eps = _eps(gas.beta(g), gas.end) if restitution is None else restitution(gas.beta(g))
    out = (1.0 - eps**2) @ w
    return out if np.ndim(temperature) else float(out[0])


@dataclass(frozen=True)
class CoolingCurve:
    """Kinetic-theory cooling on a grid of temperatures (decreasing).

    Attributes ``temperature``, ``time``, ``collisions`` (per particle), all (K,).
    """

    temperature: np.ndarray
    time: np.ndarray
    collisions: np.ndarray

    def temperature_at(self, t):
        """T at times t (log-linear interpolation; t beyond the grid -> nan)."""
        t = np.asarray(t, dtype=float)
        lt = np.interp(t, self.time, np.log(self.temperature), right=np.nan)
        return np.exp(lt)

    def temperature_after(self, s):
        """T after s collisions per particle."""
        lt = np.interp(np.asarray(s, dtype=float), self.collisions, np.log(self.temperature), right=np.nan)
        return np.exp(lt)


def viscoelastic_cooling(gas: Gas, t_min_ratio: float = 1e-12, points: int = 600,
                         restitution=None) -> CoolingCurve:
    """Cooling curve of the viscoelastic gas from T0 down to ``t_min_ratio T0`` (module doc).

    ``restitution``: optional eps(beta) callable, see :func:`effective_inelasticity`.
    """
    T0 = gas.temperature
    lnT = np.linspace(math.log(T0), math.log(T0 * t_min_ratio), points)
    T = np.exp(lnT)
    inel = effective_inelasticity(gas, T, restitution=restitution)
    omega = theory.collision_frequency(gas.density, T, gas.dimension, gas.sigma, gas.mass)
    ds = gas.dimension / inel          # d s / d(-ln T)
    dt = ds / omega                     # d t / d(-ln T)
    step = -np.diff(lnT)
    s = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * step)])
    t = np.concatenate([[0.0], np.cumsum(0.5 * (dt[1:] + dt[:-1]) * step)])
    return CoolingCurve(T, t, s)


def _haff_end(gas: Gas):
    """(t_end, ln T_end) of a constant-eps run: Haff's law with the van Noije-Ernst a2
    (:func:`granulargas.theory.haff_tau0`); in logarithms so that runs cooling past
    float64 are still reported."""
    eps, T0 = gas.restitution, gas.temperature
    t_end = gas.end_time
    omega0 = gas.collision_frequency
    if eps >= 1.0:
        return (t_end if t_end is not None else gas.collisions_per_particle / omega0), math.log(T0)
    tau0 = float(theory.haff_tau0(eps, gas.density, T0, gas.dimension, gas.sigma, gas.mass))
    ln_ratio = math.inf if t_end is None else 2.0 * math.log1p(t_end / tau0)
    if gas.collisions_per_particle is not None:
        # s = omega0 tau0 ln(1 + t/tau0) (theory.haff_collisions), so ln(T0/T) = 2 s / (omega0 tau0)
        ln_s = 2.0 * gas.collisions_per_particle / (omega0 * tau0)
        if ln_s < ln_ratio:
            ln_ratio = ln_s
            t_end = tau0 * math.expm1(min(0.5 * ln_s, 700.0))
    return t_end, math.log(T0) - ln_ratio


def _predicted_end(gas: Gas, curve: CoolingCurve | None = None):
    """(t_end, ln T_end) of the run (whichever stop condition comes first)."""
    if gas.model == "elastic" or (gas.model == "viscoelastic" and not gas.damping):
        t_end = gas.end_time
        if t_end is None:
            t_end = gas.collisions_per_particle / gas.collision_frequency
        return float(t_end), math.log(gas.temperature)
    if gas.model == "constant":
        return _haff_end(gas)
    curve = curve or viscoelastic_cooling(gas)
    ends = []
    if gas.end_time is not None:
        ends.append(gas.end_time)
    if gas.collisions_per_particle is not None:
        s_end = gas.collisions_per_particle
        if s_end <= curve.collisions[-1]:
            ends.append(float(np.interp(s_end, curve.collisions, curve.time)))
        else:  # late times: s ~ 6 omega tau0 (t/tau0)^(1/6), so t ~ (s/s_last)^6 t_last
            ends.append(float(curve.time[-1] * (s_end / curve.collisions[-1]) ** 6))
    t_end = min(ends)
    if t_end <= curve.time[-1]:
        return float(t_end), float(np.log(curve.temperature_at(t_end)))
    # cooled below the grid: continue with the late-time law T ~ t^(-5/3)
    return float(t_end), float(math.log(curve.temperature[-1]) - 5.0 / 3.0 * math.log(t_end / curve.time[-1]))


def run_temperature_range(gas: Gas, curve: CoolingCurve | None = None):
    """Predicted (t_end, T_end) of the run (whichever stop condition comes first).

    Viscoelastic: :func:`viscoelastic_cooling`; constant: Haff's law; elastic: T0.
    """
    t_end, ln_T = _predicted_end(gas, curve)
    return t_end, math.exp(ln_T)


# ---------------------------------------------------------------- t_c / t_free


def _collision_mean(fn, temperature, mass, nodes=_NODES):
    """<fn(g)> over the Rayleigh law of collision impact speeds (weight g exp(-g^2/(2 s^2)))."""
    u, w = _kernel_nodes(1, nodes)
    s = math.sqrt(2.0 * temperature / mass)
    return float(fn(s * u) @ w)


def contact_time_ratio(config_or_gas, temperature: float | None = None) -> float | None:
    """Collision-averaged contact duration over the mean free time, ``<t_c> omega``.

    Material route: ``t_c = tau_c(beta) rho^(-2/5) g^(-1/5)`` (seed eq. 2 rescaled;
    SI, then divided by the time unit diameter / speed_unit). TC model: ``tc_time
    omega``. Otherwise None (the damping route does not fix the stiffness).

    Parameters
    ----------
    config_or_gas : RunConfig or Gas
    temperature : float, optional
        Default: the initial temperature (where the ratio is largest, ~T^(2/5)).
    """
    gas = config_or_gas if isinstance(config_or_gas, Gas) else gas_from_config(config_or_gas)
    T = gas.temperature if temperature is None else float(temperature)
    omega = float(theory.collision_frequency(gas.density, T, gas.dimension, gas.sigma, gas.mass))
    if gas.model == "constant" and gas.tc_time is not None:
        return gas.tc_time * omega
    if gas.model != "viscoelastic" or gas.material is None:
        return None
    m = gas.material
    diameter_si = m.diameter * gas.sigma
    mass_si = m.density * math.pi * diameter_si**3 / 6.0
    rho = float(rho_from_material(m.young_modulus, m.poisson_ratio, diameter_si / 4.0, mass_si / 2.0))
    time_unit = m.diameter / m.speed_unit  # reduced time unit in s (reference diameter / speed unit)
    g_hi = float(impact_speed_quantile(0.9999, T, gas.mass))
    table = restitution_table(max(float(gas.beta(g_hi)) * 1.01, 1e-6), end=gas.end)

    def t_c(g):
        g = np.maximum(g, 1e-300)
        beta = np.minimum(gas.beta(g), table.beta_limit * (1 - 1e-9))
        return table.duration(beta) * rho**-0.4 * (g * m.speed_unit) ** -0.2 / time_unit

    return _collision_mean(t_c, T, gas.mass) * omega


# ---------------------------------------------------------------- all checks


@dataclass
class RunValidity:
    """Predicted model validity of a run (see the module doc for each check).

    Attributes
    ----------
    t_end, t_start, T_end : float
        Predicted end time, T0 and final temperature.
    spread : dict or None
        :func:`restitution_spread` over the run (viscoelastic only).
    tc_ratio : float or None
        :func:`contact_time_ratio` at T0.
    warnings, errors : list of str
        One-line messages; errors mean the run cannot be right.
    """

    gas: Gas
    t_end: float
    T_start: float
    T_end: float
    spread: dict | None = None
    tc_ratio: float | None = None
    warnings: list = field(default_factory=list)
    errors: list = field(default_factory=list)

    def lines(self) -> list[str]:
        """Report lines for the run summary (numbers, then warnings and errors)."""
        out = [f"validity     T {self.T_start:.3g} -> {self.T_end:.3g} (predicted by t = {self.t_end:.4g})"]
        if self.spread is not None:
            sp = self.spread
            out.append(f"validity     beta {sp['beta_min']:.3g}..{sp['beta_max']:.3g}, "
                       f"eps {sp['eps_min']:.4f}..{sp['eps_max']:.4f} over thermal impacts")
        if self.tc_ratio is not None:
            out.append(f"validity     t_c/t_free = {self.tc_ratio:.3g} at T0 (warn above {TC_RATIO_WARN:g})")
        elif self.gas.model == "viscoelastic":
            out.append("validity     t_c/t_free not determined (damping fixes beta only; "
                       "give [collision.material] to check)")
        out += [f"warning: {w}" for w in self.warnings]
        out += [f"error: {e}" for e in self.errors]
        return out


def check_run(config) -> RunValidity:
    """All run-level checks for a config (module doc); no simulation."""
    gas = config if isinstance(config, Gas) else gas_from_config(config)
    src = gas.source
    spread = curve = None
    if gas.model == "viscoelastic" and gas.damping > 0:
        curve = viscoelastic_cooling(gas)
    t_end, ln_T_end = _predicted_end(gas, curve)
    T_end = math.exp(ln_T_end)
    if curve is not None:
        spread = restitution_spread(gas, gas.temperature, max(T_end, 1e-300))
    rv = RunValidity(gas, float(t_end), gas.temperature, float(T_end), spread)
    rv.tc_ratio = contact_time_ratio(gas)
    if rv.tc_ratio is not None and rv.tc_ratio > TC_RATIO_WARN:
        what = "tc_time" if gas.model == "constant" else "contact duration"
        rv.warnings.append(
            f"{src}: {what} / mean free time = {rv.tc_ratio:.3g} > {TC_RATIO_WARN:g}: about "
            f"{100 * (1 - math.exp(-2 * rv.tc_ratio)):.2g} % of collisions overlap a third contact, "
            "so binary instantaneous collisions (event-driven dynamics) misstate the dissipation")
    if spread is not None and spread["beta_max"] > BETA_VALID:
        rv.warnings.append(
            f"{src}: beta of fast thermal impacts = {spread['beta_max']:.3g} > {BETA_VALID:g}: the quasi-static "
            "viscoelastic force needs the dissipative time A well below the contact time")
    if ln_T_end - math.log(gas.temperature) < math.log(DRIFT_T_RATIO) and not (
            ln_T_end - math.log(gas.mass) < math.log(UNDERFLOW_T)):
        rv.warnings.append(
            f"{src}: T falls below {DRIFT_T_RATIO:g} T0: the centre-of-mass velocity left by round-off "
            "(~1e-16 of the initial thermal speed) overtakes the thermal speed and the event cost per "
            "collision grows; restart from a snapshot with the centre-of-mass velocity removed")
    key = "run.collisions_per_particle" if gas.collisions_per_particle is not None and (
        gas.end_time is None) else "run.end_time"
    if ln_T_end - math.log(gas.mass) < math.log(UNDERFLOW_T):
        rv.errors.append(
            f"{src}: {key}: the gas would cool to T ~ 1e{ln_T_end / math.log(10):.0f} (T0 = {gas.temperature:g}), below "
            f"{UNDERFLOW_T:g}, where squared velocities underflow float64; shorten the run or rescale it "
            "(restart with [initial] temperature)")
    return rv


def summary_lines(config) -> list[str]:
    """One-line validity reports for the run summary (runner hook)."""
    return check_run(config).lines()


def raise_if_invalid(config) -> RunValidity:
    """Run :func:`check_run`; raise ConfigError with the first error if any."""
    rv = check_run(config)
    if rv.errors:
        raise ConfigError(rv.errors[0])
    return rv
