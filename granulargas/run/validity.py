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

Rough particles
---------------
With ``[collision.tangential]`` the predicted translational temperature is that of the
two-temperature theory (:mod:`granulargas.theory.rough`, Maxwellian energy balances):
T_tr(t) from (T0, T_rot0) to the run's end (a stop in collisions per particle: where
the theory's collision count reaches it), or, driven, towards its steady state.

The shear instability
---------------------
A homogeneous cooling gas in a periodic box longer than the shear-instability
length ``L_c`` (:meth:`granulargas.theory.gas.Gas.instability_length`, at T0)
develops shear modes and then clusters (Goldhirsch & Zanetti 1993); its T(t) then
leaves the homogeneous prediction (T/T_theory grew to 6 by 100 collisions per
particle for 1000 disks at packing 0.05, eps = 0.8, box 1.4 L_c). The run summary
warns for such an engine run (:class:`granulargas.io.scene.Scene`: cooling, with
space); a viscoelastic gas's L_c grows as it cools, so its clusters may dissolve
later. DSMC has no space and stays homogeneous; a driven or elastic gas has no
such instability.

The engine and DSMC both remove the centre-of-mass velocity that round-off leaves
(:meth:`granulargas.engine.Simulation.run`, :class:`granulargas.dsmc.DSMC`), so a
gas cooling by many decades needs no restart for it.

Shear flow
----------
A sheared gas ([shear]) heads for the steady state where viscous heating balances the
collisional loss (:mod:`granulargas.theory.shear`: the Grad solution, ``T_s`` of
:func:`granulargas.theory.shear.steady_temperature`, a viscoelastic gas at its effective
restitution), or is held at the thermostat's temperature. A run is refused when its
shear rate drives the gas there more slowly than the run lasts: the dilute Grad moment
equations (collision rates times chi) from T0 do not bring T within a factor 1.25 of
``T_s`` by ``end_time`` or within ``collisions_per_particle``
(:func:`granulargas.theory.shear.grad_transient`); and, as any run, when the clock at
the end cannot resolve the events at ``T_s``. A thermostat holds the temperature only
if the viscous heating changes it little between two rescalings: an interval with
rate x interval above ``THERMOSTAT_STRAIN_MAX`` is refused (the default interval is
0.1 of the shorter of the mean free time and 1/rate).

Runner API (one line each, for the run summary)
-----------------------------------------------
* :func:`check_run` ``(config) -> RunValidity``: all the numbers;
* :func:`summary_lines` ``(config) -> list[str]``: one-line reports and warnings;
* :func:`contact_time_ratio` ``(config, temperature=None) -> float | None``;
* :func:`raise_if_invalid` ``(config)``: ConfigError when a run cannot be right.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, fields, replace

import numpy as np

from granulargas import theory
from granulargas.contact import restitution_table
from granulargas.contact.material import damping_from_prefactor, effective_modulus, rho_from_material
from granulargas.errors import ConfigError, TableRangeError
from granulargas.io.config import TABLE_BETA_MAX, RunConfig
from granulargas.io.scene import Scene
from granulargas.theory import rough as rough_theory
from granulargas.theory.moments import speed_quadrature
from granulargas.run.prepare import (mean_particle, mean_restitution, mixture_of_config, pair_weights, reduced_prefactor,
                                     species_fractions)
from granulargas.run.vibrated import scene_lines
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
    "cooling_of",
    "run_temperature_range",
    "contact_time_ratio",
    "box_length",
    "mean_particle_volume",
    "driven_end",
    "check_run",
    "summary_lines",
    "raise_if_invalid",
]

#: warn when t_c / t_free exceeds this (2 % of collisions would be three-body contacts)
TC_RATIO_WARN = 0.01
#: refuse runs whose predicted final temperature (in units of m, reduced) falls below this
UNDERFLOW_T = 1e-250
#: the float64 clock must resolve this fraction of the time between a particle's events
CLOCK_RESOLUTION = 1e-6
#: largest shear strain a x thermostat_interval between two rescalings of a thermostatted
#: shear flow (the viscous heating's relative change of T over one interval is at most
#: (2/d) a dt |P_xy|/p, and |P_xy| <= p)
THERMOSTAT_STRAIN_MAX = 0.5
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


def cooling_of(gas: Gas) -> CoolingCurve:
    """:func:`viscoelastic_cooling` of ``gas``, solved once per process for each gas: the run's
    checks, the advice and the run summary all predict with it. The curve is a function of the
    gas alone (not of when the run stops, nor of a :class:`RunGas`'s other fields)."""
    return _cooling(Gas(**{f.name: getattr(gas, f.name) for f in fields(Gas)
                           if f.name not in ("end_time", "collisions_per_particle")}))


@functools.lru_cache(maxsize=16)
def _cooling(gas: Gas) -> CoolingCurve:
    return viscoelastic_cooling(gas)


def mean_particle_volume(config) -> float:
    """Mean volume of the config's particles: that of the diameter for identical ones; for
    diameters uniform in [a, b], ``<sigma^d> = (b^(d+1) - a^(d+1)) / ((d + 1)(b - a))`` times
    the volume prefactor; a mixture's: the mean over its species."""
    s, p = config.system, config.particles
    d = s.dimension
    if config.species:  # a mixture: the number-weighted mean of its species' volumes
        x = species_fractions(config)
        return float(np.dot(x, theory.particle_volume(np.array([sp.diameter for sp in config.species]), d)))
    if not p.polydisperse or p.diameter_max <= p.diameter_min:
        return float(theory.particle_volume(p.diameter, d))
    a, b = p.diameter_min, p.diameter_max
    moment = (b ** (d + 1) - a ** (d + 1)) / ((d + 1) * (b - a))
    return float(theory.particle_volume(1.0, d)) * moment


def gas_from_config(config) -> RunGas:
    """The gas of a :class:`~granulargas.io.config.RunConfig`: particles of the mean
    diameter (:func:`granulargas.run.prepare.mean_particle`) at the config's number density
    (``system.packing_fraction`` over the mean particle volume, :func:`mean_particle_volume`;
    the gas's packing fraction is that of mean-diameter particles at that density, as
    ``granulargas analyze`` takes it), the reduced prefactor
    (:func:`granulargas.run.prepare.reduced_prefactor`), the stop conditions. A mixture is
    checked as the one-component gas of its mean particle, mean restitution
    (:func:`granulargas.run.prepare.mean_restitution`) and mean prefactor: the run checks need
    its temperature range and collision times, which that gas gives to within the spread of
    the species' temperatures."""
    s, c = config.system, config.collision
    d = s.dimension
    sigma, mass = mean_particle(config)
    k = float(reduced_prefactor(config)) if c.model == "viscoelastic" else None
    density = s.packing_fraction / mean_particle_volume(config)
    return RunGas(
        dimension=d, packing_fraction=float(theory.packing_fraction(density, d, sigma)), density=float(density),
        sigma=sigma, mass=mass, temperature=config.initial.temperature, model=c.model,
        restitution=mean_restitution(config) if c.model == "constant" else c.restitution,
        prefactor=k, end=c.contact_end, end_time=config.run.end_time,
        collisions_per_particle=config.run.collisions_per_particle,
        tc_time=c.tc_time, material=_mean_material(config), source=config.source, duration=c.duration,
    )


def _mean_material(config):
    """``[collision.material]``; a mixture's: the contact stiffness of its mean pair, Y / (1 - nu^2)
    = sum_ij w_ij 2 Y*_ij (weights :func:`granulargas.run.prepare.pair_weights`, Y* the pair's
    effective modulus; nu = 0), for the collision times of the mean particle."""
    m = config.collision.material
    if m is None or not config.species:
        return m
    consts = [(sp.young_modulus or m.young_modulus, sp.poisson_ratio if sp.poisson_ratio is not None
               else m.poisson_ratio) for sp in config.species]
    w = pair_weights(config)
    stiffness = sum(w[i, j] * 2.0 * effective_modulus(*a, *b) for i, a in enumerate(consts) for j, b in enumerate(consts))
    return replace(m, young_modulus=float(stiffness), poisson_ratio=0.0)


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
    t_end, T_start, T_end : float
        Predicted end time, T0 and the temperature at the end (a driven run: on its way
        from T0 to the steady temperature ``T_steady``).
    spread : dict or None
        :func:`restitution_spread` over the run (viscoelastic only).
    tc_ratio : float or None
        :func:`contact_time_ratio` at T0.
    scene : Scene
        The kind of run (:class:`granulargas.io.scene.Scene`): which checks apply.
    box, instability_length : float
        Longest box edge and the shear-instability length at T0 (cooling engine runs;
        otherwise nan).
    T_stable : float
        A viscoelastic gas in a box above L_c at T0: the temperature at which its growing
        L_c passes the box (nan if it does not during the run, or for other gases).
    T_steady : float
        Driven runs: the steady temperature of the driving (nan otherwise).
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
    scene: Scene = field(default_factory=Scene)
    box: float = math.nan
    instability_length: float = math.nan
    T_steady: float = math.nan
    instability_warning: str | None = None
    T_stable: float = math.nan
    #: what holds the steady state of a sheared run (None: not sheared)
    steady: str | None = None
    #: a vibrated scene's lines (gravity, thermal or vibrating walls: :mod:`granulargas.run.vibrated`),
    #: in place of the homogeneous gas's temperature range
    vibrated: list = field(default_factory=list)

    @property
    def driven(self) -> bool:
        return self.scene.kind == "driven"

    @property
    def unstable(self) -> bool:
        """A cooling engine run in a box longer than the shear-instability length."""
        return self.box > self.instability_length

    def lines(self) -> list[str]:
        """Report lines for the run summary (numbers, then warnings and errors)."""
        if self.vibrated:
            out = [x for x in self.vibrated if not x.startswith("warning: ")]
            out += [f"warning: {w}" for w in self.warnings]
            out += [f"error: {e}" for e in self.errors]
            return out
        theory_name = "two-temperature theory" if self.scene.rough else "Enskog theory"
        if self.steady is not None:
            out = [f"validity     T {self.T_start:.3g} -> {self.T_end:.3g} (steady shear flow: {self.steady})"]
        elif self.driven and math.isfinite(self.T_steady):
            at = f"at t = {self.t_end:.4g}; " if math.isfinite(self.t_end) else ""
            out = [f"validity     T {self.T_start:.3g} -> {self.T_end:.3g} ({at}steady state of the driving "
                   f"{self.T_steady:.4g}, {theory_name})"]
        elif self.driven:
            out = [f"validity     T {self.T_start:.3g} -> {self.T_end:.3g} (elastic collisions heated by the "
                   f"driving, T0 + H t; predicted by t = {self.t_end:.4g})"]
        else:
            out = [f"validity     T {self.T_start:.3g} -> {self.T_end:.3g} (predicted by t = {self.t_end:.4g}"
                   + (", two-temperature theory)" if self.scene.rough else ")")]
        if self.spread is not None:
            sp = self.spread
            out.append(f"validity     beta {sp['beta_min']:.3g}..{sp['beta_max']:.3g}, "
                       f"eps {sp['eps_min']:.4f}..{sp['eps_max']:.4f} over thermal impacts")
        if self.tc_ratio is not None:
            out.append(f"validity     t_c/t_free = {self.tc_ratio:.3g} at T0 (warn above {TC_RATIO_WARN:g})")
        elif self.scene.shows("contact_time_unknown"):
            out.append("validity     t_c/t_free not determined (damping fixes beta only; "
                       "give [collision.material] to check)")
        out += [f"warning: {w}" for w in self.warnings]
        out += [f"error: {e}" for e in self.errors]
        return out


def _damping_key(gas: RunGas) -> str:
    """The config key that sets a viscoelastic gas's damping, with its value."""
    return ("collision.material" if gas.material is not None
            else f"collision.damping = {damping_from_prefactor(gas.prefactor):.6g}")


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
    return (f"{gas.source}: {_damping_key(gas)}: fast thermal impacts ({u_max:.3g} thermal speeds) reach beta = {beta:.3g}, "
            f"beyond the restitution table's {TABLE_BETA_MAX:g} (the viscoelastic model holds for beta well "
            "below 3)")


def box_length(config) -> float:
    """Box edge of a config's gas: its particles (of the mean volume, :func:`mean_particle_volume`)
    at the config's packing fraction."""
    s = config.system
    return (s.particles * mean_particle_volume(config) / s.packing_fraction) ** (1.0 / s.dimension)


def rough_gas_from_config(config):
    """The config's rough gas (:class:`granulargas.theory.rough.RoughGas`; None for smooth particles
    or a gas that is not a config's)."""
    t = getattr(getattr(config, "collision", None), "tangential", None)
    if t is None:
        return None
    drv = config.driving
    return rough_theory.RoughGas(
        gas_from_config(config), config.particles.inertia, tangential=t.model, tangential_restitution=t.restitution,
        friction=t.friction or 0.0, rotational_temperature=config.initial.rotational_temperature,
        heating_rate=0.0 if drv is None else drv.heating_rate,
        rotational_fraction=0.0 if drv is None else drv.spin_fraction)


def rough_end(rough, t_end: float | None, collisions: float | None):
    """(t_end, ln T_tr at t_end) of a rough gas by the two-temperature theory: the first of
    ``t_end`` and the time its collisions per particle reach ``collisions`` (solved once per
    process for each gas and stop condition: the run's checks and the advice both ask)."""
    try:
        hash(rough)
    except TypeError:  # a gas with an unhashable field: solved each time
        return _rough_end.__wrapped__(rough, t_end, collisions)
    return _rough_end(rough, t_end, collisions)


@functools.lru_cache(maxsize=16)
def _rough_end(rough, t_end: float | None, collisions: float | None):
    t = t_end if t_end is not None else 1.0 / rough.gas.collision_frequency
    for _ in range(200):
        curve = rough_theory.two_temperature_curve(rough, t, points=50)
        if collisions is None or curve.collisions[-1] >= collisions or t_end is not None:
            break
        t *= 2.0
    if collisions is not None and curve.collisions[-1] >= collisions:
        k = int(np.searchsorted(curve.collisions, collisions))
        lo, hi = curve.time[max(k - 1, 0)], curve.time[k]
        for _ in range(60):  # bisection on the dense solution
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if curve.collisions_at(mid) < collisions else (lo, mid)
        t = hi
    return float(t), float(np.log(curve.translational_at(t)))


def driven_end(gas: Gas, heating_rate: float, t_end: float | None) -> tuple[float, float]:
    """(T at ``t_end``, steady temperature) of a driven gas starting at T0: the steady state of
    the moment equations with the heating term (:func:`granulargas.theory.driven_state`, what
    ``granulargas analyze`` compares with) and the relaxation towards it
    (:func:`granulargas.theory.relaxation_temperature`); elastic collisions: ``T0 + H t``
    and no steady state (inf). Without ``t_end`` the steady temperature."""
    if gas.model == "elastic" or (gas.model == "viscoelastic" and not gas.pair_constant > 0):
        T_ss = math.inf
    else:
        T_ss = float(theory.driven_state(gas, heating_rate)[0])
    if t_end is None or not math.isfinite(t_end):
        return T_ss, T_ss
    T = theory.relaxation_temperature([0.0, float(t_end)], gas.temperature, heating_rate, T_ss)
    return float(T[-1]), T_ss


def _check_driven(config, gas, scene) -> RunValidity:
    """Checks of a driven run: it heads for the steady temperature of the driving
    (:mod:`granulargas.theory.driven`) instead of cooling."""
    h = config.driving.heating_rate
    rough = rough_gas_from_config(config)
    if rough is not None and (gas.model != "elastic" or rough.sticking_factor > 0.0):
        T_ss = float(rough_theory.driven_state(rough)[0])
        T_end = T_ss if gas.end_time is None else math.exp(rough_end(rough, gas.end_time, None)[1])
    else:
        T_end, T_ss = driven_end(gas, h, gas.end_time)
    spread = None
    if gas.model == "viscoelastic" and gas.pair_constant > 0:
        spread = restitution_spread(gas, max(gas.temperature, T_ss), min(gas.temperature, T_ss))
    rv = RunValidity(gas, float(gas.end_time if gas.end_time is not None else math.nan), gas.temperature,
                     float(T_end), spread, scene=scene, T_steady=T_ss)
    rv.tc_ratio = contact_time_ratio(gas, max(gas.temperature, T_ss if math.isfinite(T_ss) else T_end))
    _warn_contact(rv, gas, spread)
    return rv


def _check_sheared(config, gas, scene) -> RunValidity:
    """Checks of a sheared run (module doc, "Shear flow")."""
    sh = config.shear
    src = gas.source
    d, n, sigma, m = gas.dimension, gas.density, gas.sigma, gas.mass
    chi = float(theory.contact_value(gas.packing_fraction, d))
    if sh.thermostat_temperature is not None:
        rv = RunValidity(gas, float(gas.end_time or math.nan), gas.temperature, sh.thermostat_temperature,
                         scene=scene, T_steady=float(sh.thermostat_temperature))
        rv.steady = "the thermostat"
        dt = sh.thermostat_interval
        if dt is not None and sh.rate * dt > THERMOSTAT_STRAIN_MAX:
            rv.errors.append(f"{src}: shear.thermostat_interval = {dt:g}: rate x interval = {sh.rate * dt:.3g} > "
                             f"{THERMOSTAT_STRAIN_MAX:g}: the viscous heating changes the temperature by order one "
                             f"between two rescalings, so the thermostat does not hold it; give an interval "
                             f"below {THERMOSTAT_STRAIN_MAX / sh.rate:.3g} (or leave it out) or a lower shear.rate")
            return rv
        t_end = gas.end_time if gas.end_time is not None else math.nan
        clock = _clock_error(gas, t_end, math.log(sh.thermostat_temperature), "run.end_time")
        if clock:
            rv.errors.append(clock)
        return rv
    if gas.model == "constant":
        eps = gas.restitution
    else:
        prefactor = gas.prefactor

        def eps(T):
            return float(theory.effective_restitution(prefactor, T, d, sigma, m, gas.end))
    T_s = theory.shear.steady_temperature(sh.rate, eps, n, d, sigma, m, gas.packing_fraction)
    rv = RunValidity(gas, float(gas.end_time or math.nan), gas.temperature, float(T_s), scene=scene,
                     T_steady=float(T_s))
    rv.steady = "viscous heating = collisional loss, Grad solution"
    if not (UNDERFLOW_T < T_s / m < 1e100):
        rv.errors.append(f"{src}: shear.rate = {sh.rate:g}: the steady temperature would be T = {T_s:.3g} (Grad "
                         "solution), out of float64's range for squared speeds; choose a rate near the steady "
                         f"one at T0 ({sh.rate * math.sqrt(gas.temperature / T_s):.4g})")
        return rv
    horizon = gas.end_time if gas.end_time is not None else math.inf
    t_reach, s_reach = theory.shear.grad_transient(sh.rate, eps, n, gas.temperature, d, sigma, m, chi,
                                                   t_end=horizon if math.isfinite(horizon) else math.inf,
                                                   T_steady=float(T_s))
    short_t = gas.end_time is not None and not t_reach <= gas.end_time
    short_s = gas.collisions_per_particle is not None and not s_reach <= gas.collisions_per_particle
    if short_t or short_s:
        key = "run.end_time" if short_t else "run.collisions_per_particle"
        value = gas.end_time if short_t else gas.collisions_per_particle
        need = (f"t = {t_reach:.3g}" if short_t else f"{s_reach:.3g} collisions per particle")
        if not math.isfinite(t_reach):
            need = "longer than the run"
        a_near = sh.rate * math.sqrt(gas.temperature / T_s)
        rv.errors.append(f"{src}: shear.rate = {sh.rate:g}: the gas would move from T0 = {gas.temperature:g} to its "
                         f"steady T = {T_s:.3g} (Grad solution) in {need}, beyond {key} = {value:g}: the run would "
                         f"end far from the steady state; lengthen the run or choose a rate near {a_near:.4g} "
                         "(steady at T0)")
        return rv
    t_end = gas.end_time if gas.end_time is not None else t_reach
    clock = _clock_error(gas, float(t_end), math.log(T_s), "run.end_time" if gas.end_time is not None
                         else "run.collisions_per_particle")
    if clock:
        rv.errors.append(clock)
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


def stable_temperature(gas: Gas, box: float, T_end: float) -> float:
    """Temperature at which the instability length of a cooling gas grows past ``box``: L_c(T) =
    box for a viscoelastic gas (whose effective restitution rises as it cools); nan if L_c stays
    below the box down to ``T_end``, or does not depend on T (constant eps)."""
    if gas.model != "viscoelastic" or not gas.pair_constant > 0 or not T_end > 0:
        return math.nan
    if gas.instability_length(T_end) <= box:
        return math.nan
    from scipy.optimize import brentq

    f = lambda log_t: gas.instability_length(math.exp(log_t)) - box  # noqa: E731
    return math.exp(brentq(f, math.log(T_end), math.log(gas.temperature), xtol=1e-6))


def _scene(config, gas: RunGas) -> Scene:
    """The scene of a config (or, given only its gas, of a periodic engine run of that gas)."""
    if not isinstance(config, RunGas):
        return Scene.from_config(config)
    damping = 1.0 if gas.prefactor is None else gas.prefactor
    return Scene(dimension=gas.dimension, model=gas.model,
                 kind=("cooling" if (gas.model == "constant" and gas.restitution < 1.0) or (
                     gas.model == "viscoelastic" and damping > 0.0) else "elastic"),
                 tc_model=gas.tc_time is not None, material=gas.material is not None,
                 resolved=gas.duration == "resolved")


def check_run(config) -> RunValidity:
    """All run-level checks for a config (module doc); no simulation."""
    gas = config if isinstance(config, RunGas) else gas_from_config(config)
    scene = _scene(config, gas)
    table = table_range_error(gas)
    if table:  # the predictions below would need the table beyond its range
        rv = RunValidity(gas, math.nan, gas.temperature, math.nan, scene=scene)
        rv.errors.append(table)
        return rv
    if scene.kind == "shear":
        return _check_sheared(config, gas, scene)
    if scene.kind == "driven":
        return _check_driven(config, gas, scene)
    if scene.kind == "vibrated" and isinstance(config, RunConfig):
        # the walls put energy in (or, under gravity alone, the gas comes to rest on the floor): no
        # cooling curve to predict; the scene's numbers instead
        lines = scene_lines(config)
        rv = RunValidity(gas, float(gas.end_time or math.nan), gas.temperature, math.nan, scene=scene,
                         vibrated=lines)
        rv.tc_ratio = contact_time_ratio(gas)
        _warn_contact(rv, gas, None)
        rv.warnings += [x[len("warning: "):] for x in lines if x.startswith("warning: ")]
        return rv
    src = gas.source
    spread = curve = None
    if gas.model == "viscoelastic" and gas.pair_constant > 0:
        curve = cooling_of(gas)
    t_end, ln_T_end = predicted_end(gas, curve)
    rough = rough_gas_from_config(config)
    if rough is not None:  # two temperatures: the rough theory's T_tr
        try:
            t_end, ln_T_end = rough_end(rough, gas.end_time, gas.collisions_per_particle)
        except TableRangeError:  # the rotational energy fed back makes impacts faster than at T0
            rv = RunValidity(gas, math.nan, gas.temperature, math.nan, scene=scene)
            rv.errors.append(f"{src}: {_damping_key(gas)}: the fastest impacts of the two-temperature theory "
                             f"reach beyond the restitution table's beta = {TABLE_BETA_MAX:g} (the "
                             "viscoelastic model holds for beta well below 3)")
            return rv
    elif not isinstance(config, RunGas) and config.species and gas.model != "elastic":
        t_end, ln_T_end = _mixture_end(config, gas)
    T_end = math.exp(ln_T_end)
    if curve is not None:
        spread = restitution_spread(gas, gas.temperature, max(T_end, 1e-300))
    rv = RunValidity(gas, float(t_end), gas.temperature, float(T_end), spread, scene=scene)
    rv.tc_ratio = contact_time_ratio(gas)
    _warn_contact(rv, gas, spread)
    if scene.shows("instability") and not isinstance(config, RunGas):
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):  # absurdly dilute configs: inf
            rv.box, rv.instability_length = box_length(config), gas.instability_length()
        if rv.unstable and math.isfinite(rv.instability_length):
            rv.T_stable = stable_temperature(gas, rv.box, T_end)
            grows = ""
            if gas.model == "viscoelastic":
                grows = (f" (L_c grows as a viscoelastic gas cools and passes the box at T = {rv.T_stable:.3g}: "
                         "clusters seeded before may dissolve later)" if math.isfinite(rv.T_stable) else
                         " (it grows as a viscoelastic gas cools, but stays below the box over this run)")
            rv.instability_warning = (
                f"{src}: box length {rv.box:.4g} is above the shear-instability length L_c = "
                f"{rv.instability_length:.4g} at T0{grows}: shear modes and clusters can grow, and T(t) then "
                "leaves the homogeneous prediction above; a box below L_c (fewer particles, or run.method = \"dsmc\" for "
                "the homogeneous gas) keeps it")
            rv.warnings.append(rv.instability_warning)
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


def _mixture_end(config, gas) -> tuple[float, float]:
    """(t_end, ln T_end) of a mixture: its own Maxwellian theory, every species cooling at its
    rate (:meth:`granulargas.theory.mixture.Mixture.predicted_end`); T = sum x_i T_i."""
    return _mixture_prediction(mixture_of_config(config), gas.temperature, gas.end_time, gas.collisions_per_particle)


@functools.lru_cache(maxsize=16)
def _mixture_prediction(mix, temperature: float, end_time, collisions_per_particle) -> tuple[float, float]:
    """:func:`_mixture_end`, solved once per process for each mixture and stop condition (the
    run's checks and the advice both predict with it)."""
    t_end, temps = mix.predicted_end(temperature, end_time, collisions_per_particle)
    return float(t_end), math.log(float(mix.fractions @ temps))


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
