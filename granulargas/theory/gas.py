"""Kinetic theory of a homogeneous gas with the exact restitution law eps(beta).

A :class:`Gas` holds what the theory needs (reduced units; identical particles of
the mean diameter ``sigma`` and mass ``m``); nothing is simulated. Used by the
run checks (:mod:`granulargas.run.validity`), the advice on a constant
restitution (:mod:`granulargas.run.advise`) and the analysis of a run
(:mod:`granulargas.analysis.run`).

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
frequency ``omega`` (:func:`granulargas.theory.collision_frequency`, a2 = 0) and
the energy-weighted kernel average ``(1 - eps^2)_eff = <(1 - eps^2(beta(g))) g^3> / <g^3>``,
evaluated with the exact eps(beta) (restitution table, error 2e-10) by
Gauss-Legendre quadrature (:func:`_kernel_nodes`). Time and collisions per
particle are then quadratures in ``ln T``:

    t(T) = d int_T^T0 dT' / (omega (1-eps^2)_eff T'),
    s(T) = d int_T^T0 dT' / ((1-eps^2)_eff T').

At small beta this reduces to ``T = T0 (1 + t/tau0)^(-5/3)``
(:func:`granulargas.theory.viscoelastic_tau0`; the tests check it).

Shear instability
-----------------
:meth:`Gas.instability_length` is the box length above which the homogeneous
cooling state is unstable (:func:`granulargas.theory.instability_length`) at a
temperature T: with the config's eps and the van Noije-Ernst a2 for a constant
restitution; with the effective ``eps_eff = sqrt(1 - (1 - eps^2)_eff(T))`` and
a2 = 0 for a viscoelastic gas, whose ``L_c`` grows as it cools (smallest at T0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial.legendre import leggauss

from granulargas.contact import restitution_table
from granulargas.contact.material import pair_constant
from granulargas.theory.enskog import collision_frequency, haff_tau0, instability_length

__all__ = [
    "THERMAL_QUANTILES",
    "Gas",
    "CoolingCurve",
    "impact_speed_quantile",
    "restitution_spread",
    "effective_inelasticity",
    "viscoelastic_cooling",
    "predicted_end",
    "run_temperature_range",
    "collision_mean",
]

#: central fraction of collision impact speeds called "thermal"
THERMAL_QUANTILES = (0.05, 0.95)

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
    """A homogeneous gas of identical particles (reduced units) and how long it cools.

    Attributes
    ----------
    dimension : int
    packing_fraction : float
    density : float
        Number density n (sigma^-d).
    sigma, mass : float
        Particle diameter and mass (for a polydisperse run: the mean diameter and
        the mass of a particle of that diameter).
    temperature : float
        Initial temperature T0.
    model : str
        "elastic", "constant" or "viscoelastic".
    restitution : float or None
        Constant eps.
    prefactor : float or None
        Viscoelastic pair prefactor k (reduced): beta = k (R_eff g / m_eff^2)^(1/5).
    end : str
        Contact end ("overlap" or "force").
    end_time, collisions_per_particle : float or None
        Stop conditions of the cooling (whichever comes first).
    """

    dimension: int
    packing_fraction: float
    density: float
    sigma: float
    mass: float
    temperature: float
    model: str
    restitution: float | None = None
    prefactor: float | None = None
    end: str = "overlap"
    end_time: float | None = None
    collisions_per_particle: float | None = None

    @property
    def collision_frequency(self):
        """Enskog collision frequency per particle at T0."""
        return float(collision_frequency(self.density, self.temperature, self.dimension, self.sigma, self.mass))

    @property
    def pair_constant(self) -> float:
        """b of two particles, beta = b g^(1/5) (:func:`granulargas.contact.material.pair_constant`);
        0 unless viscoelastic."""
        if self.model != "viscoelastic" or not self.prefactor:
            return 0.0
        r = 0.5 * self.sigma
        return float(pair_constant(self.prefactor, r, r, self.mass, self.mass))

    def beta(self, g):
        """beta of two particles at normal impact speed g."""
        return self.pair_constant * np.asarray(g, dtype=float) ** 0.2

    def instability_length(self, temperature: float | None = None) -> float:
        """Shear-instability length L_c at temperature T (default T0; module docstring).

        inf for elastic collisions.
        """
        if self.model == "constant" and self.restitution is not None and self.restitution < 1.0:
            return float(instability_length(self.restitution, self.density, self.dimension, self.sigma))
        if self.model == "viscoelastic" and self.pair_constant > 0.0:
            T = self.temperature if temperature is None else float(temperature)
            inelasticity = effective_inelasticity(self, T)
            eps_eff = math.sqrt(max(1.0 - inelasticity, 0.0))
            return float(instability_length(eps_eff, self.density, self.dimension, self.sigma, a2=0.0))
        return math.inf


def impact_speed_quantile(q, temperature, mass=1.0):
    """Normal impact speed below which a fraction q of collisions lie (Rayleigh law, module doc)."""
    s = np.sqrt(2.0 * np.asarray(temperature, dtype=float) / mass)
    return s * np.sqrt(-2.0 * np.log1p(-np.asarray(q, dtype=float)))


def _eps(beta, end):
    """Exact eps(beta) through the engine's restitution table (2e-10)."""
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
    omega = collision_frequency(gas.density, T, gas.dimension, gas.sigma, gas.mass)
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
    tau0 = float(haff_tau0(eps, gas.density, T0, gas.dimension, gas.sigma, gas.mass))
    ln_ratio = math.inf if t_end is None else 2.0 * math.log1p(t_end / tau0)
    if gas.collisions_per_particle is not None:
        # s = omega0 tau0 ln(1 + t/tau0) (granulargas.theory.haff_collisions), so ln(T0/T) = 2 s / (omega0 tau0)
        ln_s = 2.0 * gas.collisions_per_particle / (omega0 * tau0)
        if ln_s < ln_ratio:
            ln_ratio = ln_s
            t_end = tau0 * math.expm1(min(0.5 * ln_s, 700.0))
    return t_end, math.log(T0) - ln_ratio


def predicted_end(gas: Gas, curve: CoolingCurve | None = None):
    """(t_end, ln T_end) of the run (whichever stop condition comes first)."""
    if gas.model == "elastic" or (gas.model == "viscoelastic" and not gas.pair_constant):
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
    t_end, ln_T = predicted_end(gas, curve)
    return t_end, math.exp(ln_T)


def collision_mean(fn, temperature, mass, nodes=_NODES):
    """<fn(g)> over the Rayleigh law of collision impact speeds (weight g exp(-g^2/(2 s^2)))."""
    u, w = _kernel_nodes(1, nodes)
    s = math.sqrt(2.0 * temperature / mass)
    return float(fn(s * u) @ w)
