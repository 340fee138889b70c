"""Run-level checks: is the model a run asks for valid over the whole run?

Everything here is predicted from a :class:`granulargas.io.config.RunConfig`
before the run, with kinetic theory (:mod:`granulargas.theory`) and the contact
module (:mod:`granulargas.contact`); nothing is simulated. Identical particles
of the config's (mean) diameter ``sigma`` and mass ``m`` are assumed.

The kinetic theory behind the predictions (impact speeds, the viscoelastic
cooling curve with the exact eps(beta)) is :mod:`granulargas.theory.gas`.

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
``t_c = tau_c(beta) rho^(-2/5) g^(-1/5)`` (Schwager & Pöschel (1997), eq. (2), rescaled) needs the
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

The float64 clock
-----------------
Event times are absolute float64 numbers: near time t they are resolved to
``ulp(t) = t 2^-52``. A particle's events are spaced by the shorter of its mean
free time ``1/omega(T)`` and the time it takes to cross one diameter
``sigma / sqrt(T/m)`` (neighbour-list expiries of a dilute gas), both growing as
the gas cools. A run is refused when, at its predicted end, ``ulp(t_end)`` exceeds
``CLOCK_RESOLUTION = 1e-6`` of that spacing: events would then be placed at
times rounded by more than a millionth of their spacing, and further on at the
same float (zero-time events). For an elastic gas this bounds the run to about
``1e-6 2^52 = 4.5e9`` mean free times; a cooling gas, whose event spacing grows
with t, stays resolved much longer.

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

from granulargas import theory
from granulargas.contact import restitution_table
from granulargas.contact.material import damping_from_prefactor, rho_from_material
from granulargas.errors import ConfigError
from granulargas.io.config import TABLE_BETA_MAX, RunConfig
from granulargas.theory.moments import speed_quadrature
from granulargas.run.prepare import mean_particle, reduced_prefactor
from granulargas.run.vibrated import is_vibrated, scene_lines
from granulargas.theory.gas import (  # noqa: F401  (re-exported: what the checks predict with)
    THERMAL_QUANTILES,
    CoolingCurve,
    Gas,
    collision_mean,
    effective_inelasticity,
    impact_speed_quantile,
    predicted_end,
    restitution_spread,
    run_temperature_range,
    viscoelastic_cooling,
)

__all__ = [
    "TC_RATIO_WARN",
    "UNDERFLOW_T",
    "THERMAL_QUANTILES",
    "Gas",
    "RunGas",
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
#: the float64 clock must resolve this fraction of the time between a particle's events
CLOCK_RESOLUTION = 1e-6
#: beta above which the viscoelastic force is questionable (contact.material.BETA_VALID_MAX)
BETA_VALID = 1.0


@dataclass(frozen=True)
class RunGas(Gas):
    """The gas of a config (:class:`granulargas.theory.gas.Gas`) and what the checks
    need besides: the TC-model time, the SI material, the config's file name."""

    tc_time: float | None = None
    material: object = None
    source: str = "<config>"
    duration: str = "instantaneous"


def gas_from_config(config) -> RunGas:
    """The gas of a :class:`~granulargas.io.config.RunConfig`: particles of the mean
    diameter (:func:`granulargas.run.prepare.mean_particle`), the reduced prefactor
    (:func:`granulargas.run.prepare.reduced_prefactor`), the stop conditions."""
    s, c = config.system, config.collision
    d = s.dimension
    sigma, mass = mean_particle(config)
    k = float(reduced_prefactor(config)) if c.model == "viscoelastic" else None
    return RunGas(
        dimension=d, packing_fraction=s.packing_fraction, density=float(theory.number_density(s.packing_fraction, d, sigma)),
        sigma=sigma, mass=mass, temperature=config.initial.temperature, model=c.model, restitution=c.restitution,
        prefactor=k, end=c.contact_end, end_time=config.run.end_time,
        collisions_per_particle=config.run.collisions_per_particle,
        tc_time=c.tc_time, material=c.material, source=config.source, duration=c.duration,
    )


# ---------------------------------------------------------------- t_c / t_free


def contact_time_ratio(config_or_gas, temperature: float | None = None) -> float | None:
    """Collision-averaged contact duration over the mean free time, ``<t_c> omega``.

    Material route: ``t_c = tau_c(beta) rho^(-2/5) g^(-1/5)`` (Schwager & Pöschel (1997), eq. (2), rescaled;
    SI, then divided by the time unit diameter / speed_unit). TC model: ``tc_time
    omega``. Otherwise None (the damping route does not fix the stiffness).

    Parameters
    ----------
    config_or_gas : RunConfig or Gas
    temperature : float, optional
        Default: the initial temperature (where the ratio is largest, ~T^(2/5)).
    """
    gas = config_or_gas if isinstance(config_or_gas, RunGas) else gas_from_config(config_or_gas)
    T = gas.temperature if temperature is None else float(temperature)
    omega = float(theory.collision_frequency(gas.density, T, gas.dimension, gas.sigma, gas.mass))
    if gas.model == "constant" and gas.tc_time is not None:
        return gas.tc_time * omega
    if gas.model != "viscoelastic" or gas.material is None:
        return None
    m = gas.material
    diameter_si = m.diameter * gas.sigma
    mass_si = m.density * float(theory.particle_volume(diameter_si, 3))
    rho = float(rho_from_material(m.young_modulus, m.poisson_ratio, diameter_si / 4.0, mass_si / 2.0))
    time_unit = m.diameter / m.speed_unit  # reduced time unit in s (reference diameter / speed unit)
    g_hi = float(impact_speed_quantile(0.9999, T, gas.mass))
    table = restitution_table(max(float(gas.beta(g_hi)) * 1.01, 1e-6), end=gas.end)

    def t_c(g):
        g = np.maximum(g, 1e-300)
        beta = np.minimum(gas.beta(g), table.beta_limit * (1 - 1e-9))
        return table.duration(beta) * rho**-0.4 * (g * m.speed_unit) ** -0.2 / time_unit

    return collision_mean(t_c, T, gas.mass) * omega


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
    driven: bool = False
    #: a vibrated scene's lines (gravity, thermal or vibrating walls: :mod:`granulargas.run.vibrated`),
    #: in place of the homogeneous gas's temperature range
    scene: list = field(default_factory=list)

    def lines(self) -> list[str]:
        """Report lines for the run summary (numbers, then warnings and errors)."""
        if self.scene:
            out = [x for x in self.scene if not x.startswith("warning: ")]
            out += [f"warning: {w}" for w in self.warnings]
            out += [f"error: {e}" for e in self.errors]
            return out
        if self.driven:
            out = [f"validity     T {self.T_start:.3g} -> {self.T_end:.3g} (steady state of the driving, "
                   "Enskog theory)"]
        else:
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


def table_range_error(gas: RunGas) -> str | None:
    """One line when the fastest impacts the kinetic theory integrates over at T0 (its largest
    speed node, :func:`granulargas.theory.moments.speed_quadrature`) reach beta beyond the
    restitution table (``io.config.TABLE_BETA_MAX``); None otherwise or for other models."""
    if gas.model != "viscoelastic" or not gas.pair_constant > 0:
        return None
    u_max = float(np.max(speed_quadrature(gas.dimension).u))
    beta = float(gas.beta(math.sqrt(2.0 * gas.temperature / gas.mass) * u_max))
    if beta <= TABLE_BETA_MAX / 1.01:
        return None
    key = ("collision.material" if gas.material is not None
           else f"collision.damping = {damping_from_prefactor(gas.prefactor):.6g}")
    return (f"{gas.source}: {key}: fast thermal impacts ({u_max:.3g} thermal speeds) reach beta = {beta:.3g}, "
            f"beyond the restitution table's {TABLE_BETA_MAX:g} (the viscoelastic model holds for beta well "
            "below 3)")


def _check_driven(config, gas) -> RunValidity:
    """Checks of a driven run: it heads for the steady temperature of the driving
    (:mod:`granulargas.theory.driven`) instead of cooling."""
    h = config.driving.heating_rate
    if gas.model == "elastic":  # no steady state: T grows as T0 + H t
        t_end = gas.temperature + h * (gas.end_time if gas.end_time is not None else 0.0)
    elif gas.model == "constant":
        t_end = float(theory.driven_temperature(h, gas.restitution, gas.density, gas.dimension, gas.sigma,
                                                gas.mass))
    else:
        t_end = theory.viscoelastic_driven_state(h, gas.prefactor, gas.density, gas.dimension, gas.sigma,
                                                 gas.mass, end=gas.end)[0]
    spread = None
    if gas.model == "viscoelastic" and gas.pair_constant > 0:
        spread = restitution_spread(gas, max(gas.temperature, t_end), min(gas.temperature, t_end))
    rv = RunValidity(gas, float(gas.end_time or math.nan), gas.temperature, float(t_end), spread,
                     driven=True)
    rv.tc_ratio = contact_time_ratio(gas, max(gas.temperature, t_end))
    _warn_contact(rv, gas, spread)
    return rv


def _warn_contact(rv: RunValidity, gas: RunGas, spread) -> None:
    """Warnings of contacts the event-driven model misstates: contact durations that are not
    short against the mean free time, and damping beyond the quasi-static force's range."""
    if rv.tc_ratio is not None and rv.tc_ratio > TC_RATIO_WARN and gas.duration == "resolved":
        rv.warnings.append(
            f"{gas.source}: contact duration / mean free time = {rv.tc_ratio:.3g} > {TC_RATIO_WARN:g}: of the order "
            f"of {100 * (1 - math.exp(-2 * rv.tc_ratio)):.2g} % of collisions may meet a pair still in contact, "
            "which the resolved two-body contacts do not describe (counted as three_body_contacts)")
    elif rv.tc_ratio is not None and rv.tc_ratio > TC_RATIO_WARN:
        what = "tc_time" if gas.model == "constant" else "contact duration"
        rv.warnings.append(
            f"{gas.source}: {what} / mean free time = {rv.tc_ratio:.3g} > {TC_RATIO_WARN:g}: about "
            f"{100 * (1 - math.exp(-2 * rv.tc_ratio)):.2g} % of collisions overlap a third contact, "
            "so binary instantaneous collisions (event-driven dynamics) misstate the dissipation")
    if spread is not None and spread["beta_max"] > BETA_VALID:
        rv.warnings.append(
            f"{gas.source}: beta of fast thermal impacts = {spread['beta_max']:.3g} > {BETA_VALID:g}: the "
            "quasi-static viscoelastic force needs the dissipative time A well below the contact time")


def check_run(config) -> RunValidity:
    """All run-level checks for a config (module doc); no simulation."""
    gas = config if isinstance(config, RunGas) else gas_from_config(config)
    table = table_range_error(gas)
    if table:  # the predictions below would need the table beyond its range
        rv = RunValidity(gas, math.nan, gas.temperature, math.nan)
        rv.errors.append(table)
        return rv
    driving = getattr(config, "driving", None)
    if driving is not None and driving.heating_rate > 0.0:
        return _check_driven(config, gas)
    if isinstance(config, RunConfig) and is_vibrated(config):
        # the walls put energy in (or, under gravity alone, the gas comes to rest on the floor): no
        # cooling curve to predict; the scene's numbers instead
        lines = scene_lines(config)
        rv = RunValidity(gas, float(gas.end_time or math.nan), gas.temperature, math.nan, scene=lines)
        rv.tc_ratio = contact_time_ratio(gas)
        _warn_contact(rv, gas, None)
        rv.warnings += [x[len("warning: "):] for x in lines if x.startswith("warning: ")]
        return rv
    src = gas.source
    spread = curve = None
    if gas.model == "viscoelastic" and gas.pair_constant > 0:
        curve = viscoelastic_cooling(gas)
    t_end, ln_T_end = predicted_end(gas, curve)
    T_end = math.exp(ln_T_end)
    if curve is not None:
        spread = restitution_spread(gas, gas.temperature, max(T_end, 1e-300))
    rv = RunValidity(gas, float(t_end), gas.temperature, float(T_end), spread)
    rv.tc_ratio = contact_time_ratio(gas)
    _warn_contact(rv, gas, spread)
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
    else:
        clock = _clock_error(gas, float(t_end), ln_T_end, key)
        if clock:
            rv.errors.append(clock)
    return rv


def _clock_error(gas, t_end: float, ln_T_end: float, key: str) -> str | None:
    """The float64-clock check of the module docstring (None when the run is resolved)."""
    if not (t_end > 0 and math.isfinite(t_end)):
        return None
    # logarithms throughout: T_end may be far below T0
    ln_free = -math.log(gas.collision_frequency) + 0.5 * (math.log(gas.temperature) - ln_T_end)
    ln_cross = math.log(gas.sigma) - 0.5 * (ln_T_end - math.log(gas.mass))
    ln_spacing = min(ln_free, ln_cross)
    ln_ulp = math.log(t_end) - 52.0 * math.log(2.0)
    if ln_ulp <= math.log(CLOCK_RESOLUTION) + ln_spacing:
        return None
    limit = math.exp(math.log(CLOCK_RESOLUTION) + ln_spacing + 52.0 * math.log(2.0))
    value = gas.end_time if key == "run.end_time" else gas.collisions_per_particle
    return (f"{gas.source}: {key} = {value:g}: at t = {t_end:.3g} the float64 clock resolves {math.exp(ln_ulp):.3g}, "
            f"more than {CLOCK_RESOLUTION:g} of the time between a particle's events "
            f"({math.exp(ln_spacing):.3g} at the predicted T = {math.exp(ln_T_end):.3g}); the run can reach about "
            f"t = {limit:.3g}")


def summary_lines(config) -> list[str]:
    """One-line validity reports for the run summary (runner hook)."""
    return check_run(config).lines()


def raise_if_invalid(config) -> RunValidity:
    """Run :func:`check_run`; raise ConfigError with the first error if any."""
    rv = check_run(config)
    if rv.errors:
        raise ConfigError(rv.errors[0])
    return rv
