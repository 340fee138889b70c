"""Kinetic theory of a homogeneous gas with the exact restitution law eps(beta).

A :class:`Gas` holds what the theory needs (reduced units; identical particles of
the mean diameter ``sigma`` and mass ``m``); nothing is simulated. Used by the
run checks (:mod:`granulargas.run.validity`), the advice on a constant
restitution (:mod:`granulargas.run.advise`) and the analysis of a run
(:mod:`granulargas.analysis`).

Impact speeds
-------------
In a Maxwellian gas the normal component ``g`` of the relative velocity along a
fixed direction is Gaussian with variance ``s^2 = 2T/m``; collisions sample it
with weight ``g`` (the collision kernel), so the normal impact speeds of
collisions follow the Rayleigh law ``p(g) = g/s^2 exp(-g^2/(2 s^2))``. Its
quantiles are ``g_q = s sqrt(-2 ln(1 - q))``; the energy a collision removes
weights it by a further ``g^2``. "Thermal impact speeds" below are the central
90 % of collisions (quantiles 0.05 and 0.95).

Cooling: temperature and a2 together
------------------------------------
The gas cools by the moment equations of the Enskog-Boltzmann equation in the
first Sonine approximation (Brilliantov & Pöschel, Phys. Rev. E 61, 5573 (2000),
who expanded them in the damping; here they are solved with the exact eps(g)):

    dT/dt  = -zeta(T, a2) T,            zeta = (2/d) nu_c mu_2(T, a2),          (G1)
    da2/dt = (4/d) nu_c [mu_2 (1 + a2) - mu_4 / (d + 2)]   (linear in a2),      (G2)
    ds/dt  = omega = nu_c nu_0(a2),     nu_c = chi n sigma^(d-1) sqrt(2T/m),    (G3)

with the collision moments mu_2, mu_4, nu_0 of :mod:`granulargas.theory.moments`
(derivation and equation numbers there) evaluated with eps of the engine's
restitution table at the quadrature nodes of the normal impact speed, s the
collisions per particle and chi the Enskog contact value of the packing fraction
(:func:`granulargas.theory.contact_value`, Kolafa-Labík-Malijevský in 3D, the
resummed virial series in 2D). The gas starts Maxwellian (a2 = 0); a2 relaxes in
a few collisions to a quasi-stationary value that, with the viscoelastic law,
drifts as eps -> 1 on cooling. :func:`cooling_curve` integrates (G1)-(G3) with
scipy's ``solve_ivp`` (LSODA, relative tolerance 1e-10) in the variable
``x = ln(1 + t/t_free)`` (t_free the mean free time at T0), which keeps the step
count small over many decades of time.

Constant restitution: the best reference
----------------------------------------
For a constant eps the first Sonine approximation is off at strong inelasticity (a2 by
up to 28 %, the cooling rate by up to 1.2 %), and the homogeneous cooling state (HCS) is
known better: :func:`granulargas.theory.hcs.hcs_reference` gives a2, the cooling-rate
factor c_zeta = zeta/zeta_M and the collision-frequency factor c_omega = omega/omega_M
of the HCS from a DSMC table (exact up to statistics; first Sonine where the table
ends). With ``reference="best"`` (the default) :func:`cooling_curve` then integrates

    dT/dt  = -zeta_M(T) [c_zeta + (c_zeta(0) - c_zeta) u] T,                     (G1')
    da2/dt = -lambda (a2 - a2_HCS),   du/dt = -lambda u,   u(0) = 1,              (G2')
    ds/dt  = omega = omega_M(T) [c_omega + (c_omega(0) - c_omega) u],             (G3')

with zeta_M, omega_M the Maxwellian values of (G1), (G3) (a2 = 0), c_zeta(0) = 1 + 3 a2(0)/16,
c_omega(0) = 1 - a2(0)/16 the first-Sonine factors at the start, and lambda = r omega: the
factors and a2 relax from the start to the HCS as exp(-r s) in the collisions per particle
s, with the reference's measured rate r (``HCSReference.relaxation_rate``, the rate that
gives the DSMC's offset of ln T after the transient), or, where the table has none, the
first-Sonine rate of (G2), r = -d(da2/dt)/da2 / omega (the DSMC relaxes up to 1.8 times
faster). The transient lasts a few collisions per particle; after it, T(t) is Haff's law
with the reference's cooling rate. ``reference="first_sonine"`` integrates (G1)-(G3) as
they stand.

Limits (the tests check each): for constant eps, (G1)-(G2) is Haff's law with
the van Noije-Ernst a2 once a2 has relaxed, (G1')-(G3') Haff's law with the
reference's c_zeta; at small damping, zeta at a2 = 0
approaches the closed forms of :mod:`granulargas.theory.viscoelastic` (first and
second order in the damping) and T(t) the law ``T0 (1 + t/tau0)^(-5/3)``.

The Maxwellian average ``(1 - eps^2)_eff(T) = <(1 - eps^2) g^3> / <g^3>`` over the
collision kernel (:func:`effective_inelasticity`, the same quadrature at a2 = 0)
sets the constant eps equivalent to the viscoelastic gas at temperature T.

Pressure
--------
A collision transfers the momentum ``m_eff (1 + eps) g_n`` across the distance sigma,
so the collisional part of the pressure carries ``(1 + eps)/2`` averaged with the
weight ``Theta(c_n) c_n^2`` of the normal impact speeds (Enskog's collisional
transfer; for eps = 1 the virial theorem's ``Z = 1 + 2^(d-1) eta chi``):

    Z = P / (n T) = 1 + 2^(d-1) eta chi <(1 + eps)/2>,                           (G4)

:func:`pressure_factor` is the average, with the same quadrature and a2 weight as
the moments; for constant eps it is ``(1 + eps)/2`` whatever a2 (the second
moment of the relative velocity does not depend on a2), the Enskog pressure of
the homogeneous cooling state ``1 + 2^(d-2)(1 + eps) eta chi``.

Shear instability
-----------------
:meth:`Gas.instability_length` is the box length above which the homogeneous
cooling state is unstable (:func:`granulargas.theory.instability_length`) at a
temperature T: with the config's eps and the van Noije-Ernst a2 for a constant
restitution; with the effective ``eps_eff = sqrt(1 - (1 - eps^2)_eff(T))`` and
a2 = 0 for a viscoelastic gas, whose ``L_c`` grows as it cools (smallest at T0).

Mixtures
--------
The engine runs polydisperse gases (a continuous range of diameters). This theory
is that of identical particles: a polydisperse run is described by particles of
the mean diameter and the mass of that diameter, and callers say so (the analysis
report prints a note). A mixture theory would need one temperature and one a2
per species (non-equipartition); it is not attempted.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial.legendre import leggauss

from granulargas.contact import restitution_table
from granulargas.contact.material import pair_constant
from granulargas.errors import TableRangeError
from granulargas.theory.enskog import collision_frequency, contact_value, enskog_cooling_rate, instability_length
from granulargas.theory.hcs import FIRST_SONINE, HCSReference, first_sonine, hcs_reference
from granulargas.theory.moments import eps_powers, flat_weights, moment_coefficients, speed_quadrature

__all__ = [
    "THERMAL_QUANTILES",
    "Gas",
    "CoolingCurve",
    "impact_speed_quantile",
    "restitution_spread",
    "effective_inelasticity",
    "restitution_at_nodes",
    "cooling_rates",
    "pressure_factor",
    "compressibility_factor",
    "cooling_curve",
    "hcs_of",
    "relaxation_collisions",
    "REFERENCES",
    "viscoelastic_cooling",
    "predicted_end",
    "run_temperature_range",
    "collision_mean",
]

#: central fraction of collision impact speeds called "thermal"
THERMAL_QUANTILES = (0.05, 0.95)

_NODES = 96

#: what :func:`cooling_curve` takes for the HCS of a constant restitution
REFERENCES = ("best", "first_sonine")


@functools.lru_cache(maxsize=None)
def _kernel_nodes(power: int, nodes: int = _NODES):
    """Nodes u = g / s and normalised weights for averages over ``g^power exp(-g^2/(2 s^2)) dg``
    (computed once, read-only).

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
    u, w = np.sqrt(2.0 * x), w / w.sum()
    u.flags.writeable = w.flags.writeable = False
    return u, w


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

    # computed once per gas (the ODE right-hand sides ask for them at every step)
    @functools.cached_property
    def chi(self) -> float:
        """Enskog pair correlation at contact of the packing fraction (:func:`granulargas.theory.contact_value`)."""
        return float(contact_value(self.packing_fraction, self.dimension))

    @functools.cached_property
    def collision_frequency(self):
        """Enskog collision frequency per particle at T0 (Maxwellian)."""
        return float(collision_frequency(self.density, self.temperature, self.dimension, self.sigma, self.mass,
                                         chi=self.chi))

    @functools.cached_property
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


def restitution_at_nodes(gas: Gas, temperature, restitution=None, table=None):
    """eps at the normal impact speeds ``g_j = v_T u_j`` of the collision-moment quadrature.

    Parameters
    ----------
    temperature : float or array (K,)
    restitution : callable, optional
        ``eps(beta)`` (vectorised) to use instead of the exact law (to predict the
        effect of an approximation, e.g. a truncated series).
    table : RestitutionTable, optional
        A table covering the betas needed (saves building one per call).

    Returns
    -------
    array (J,) or (K, J)
        eps at the nodes ``granulargas.theory.moments.speed_quadrature(d).u``.
    """
    u = speed_quadrature(gas.dimension).u
    T = np.asarray(temperature, dtype=float)
    shape = T.shape + u.shape
    if gas.model == "constant" and gas.restitution is not None:
        return np.full(shape, float(gas.restitution))
    if gas.model != "viscoelastic" or not gas.pair_constant:
        return np.ones(shape)
    g = np.sqrt(2.0 * T / gas.mass)[..., None] * u
    beta = gas.beta(g)
    if restitution is not None:
        return np.asarray(restitution(beta), dtype=float)
    if table is None or not table.covers(float(beta.max())):
        return _eps(beta, gas.end)
    return table.restitution(beta)


def effective_inelasticity(gas: Gas, temperature, restitution=None):
    """``(1 - eps^2)_eff(T) = <(1 - eps^2) g^3> / <g^3>`` over the Maxwellian collision kernel.

    The quadrature of :mod:`granulargas.theory.moments` at a2 = 0: ``mu_2(T) / mu_2(eps = 0)``.

    Parameters
    ----------
    temperature : float or array (K,)
    restitution : callable, optional
        ``eps(beta)``, see :func:`restitution_at_nodes`.

    Returns
    -------
    float or array (K,)
    """
    eps = restitution_at_nodes(gas, np.atleast_1d(np.asarray(temperature, dtype=float)), restitution)
    _, mu2, _ = moment_coefficients(eps, gas.dimension)
    _, mu2_inelastic, _ = moment_coefficients(np.zeros(eps.shape[-1]), gas.dimension)
    out = mu2[..., 0] / mu2_inelastic[0]
    return out if np.ndim(temperature) else float(out[0])


def _collision_scale(gas: Gas, temperature):
    """nu_c = chi n sigma^(d-1) sqrt(2T/m) of eq. (G3)."""
    return gas.chi * gas.density * gas.sigma ** (gas.dimension - 1) * np.sqrt(2.0 * np.asarray(temperature) / gas.mass)


def cooling_rates(gas: Gas, temperature, a2, restitution=None, table=None):
    """Right-hand sides of (G1)-(G3) (module doc).

    Parameters
    ----------
    temperature : float or array (K,)
    a2 : float or array (K,)

    Returns
    -------
    zeta, da2_dt, omega : float or arrays (K,)
        Cooling rate (dT/dt = -zeta T), rate of change of a2, and collision
        frequency per particle.
    """
    eps = restitution_at_nodes(gas, temperature, restitution, table)
    nu, mu2, mu4 = (np.moveaxis(c, -1, 0) for c in moment_coefficients(eps, gas.dimension))
    return _rates(gas.dimension, _collision_scale(gas, temperature), nu, mu2, mu4, np.asarray(a2, dtype=float))


def _rates(d, scale, nu, mu2, mu4, a):
    """(G1)-(G3) from nu_c (``scale``), the moment coefficients ``(a2^0, a2^1)`` of nu_0, mu_2, mu_4
    and a2."""
    zeta = 2.0 / d * scale * (mu2[0] + a * mu2[1])
    # mu_2 (1 + a2) - mu_4 / (d + 2), linear in a2
    source = mu2[0] + (mu2[0] + mu2[1]) * a - (mu4[0] + mu4[1] * a) / (d + 2)
    da2 = 4.0 / d * scale * source
    omega = scale * (nu[0] + a * nu[1])
    return zeta, da2, omega


def _rates_at(gas: Gas, restitution=None, table=None):
    """:func:`cooling_rates` at one temperature and a2, as floats, with what does not depend on
    them computed once (the ODE's right-hand side)."""
    d, mass = gas.dimension, gas.mass
    factor = gas.chi * gas.density * gas.sigma ** (d - 1)  # nu_c / sqrt(2T/m), eq. (G3)
    nu, weights = flat_weights(d)
    nu = nu.tolist()
    b = gas.pair_constant
    if restitution is None and not (gas.model == "viscoelastic" and b):  # eps does not depend on T
        fixed = restitution_at_nodes(gas, gas.temperature)

        def eps_at(T):
            return fixed
    elif restitution is not None:
        def eps_at(T):
            return restitution_at_nodes(gas, T, restitution)
    else:
        u = speed_quadrature(d).u

        def eps_at(T):  # restitution_at_nodes
            beta = b * (math.sqrt(2.0 * T / mass) * u) ** 0.2
            if table is not None:
                try:
                    return table.restitution(beta)
                except TableRangeError:
                    pass
            return _eps(beta, gas.end)

    def rates(T, a2):
        mu = (eps_powers(eps_at(T)).reshape(-1) @ weights).tolist()  # moment_coefficients
        zeta, da2, omega = _rates(d, factor * math.sqrt(2.0 * T / mass), nu, mu[:2], mu[2:], a2)
        return float(zeta), float(da2), float(omega)

    return rates


def pressure_factor(gas: Gas, temperature, a2=0.0, restitution=None):
    """``<(1 + eps)/2>`` of eq. (G4) at temperature T and Sonine coefficient a2.

    Returns
    -------
    float or array (K,)
    """
    q = speed_quadrature(gas.dimension)
    eps = restitution_at_nodes(gas, temperature, restitution)
    a = np.asarray(a2, dtype=float)[..., None]
    w = (q.nu[:, 0] + a * q.nu[:, 1]) * q.u  # Theta(c_n) c_n^2 with the a2 weight
    out = (w * 0.5 * (1.0 + eps)).sum(-1) / w.sum(-1)
    return out if np.ndim(out) else float(out)


def compressibility_factor(gas: Gas, temperature, a2=0.0, restitution=None):
    """``Z = P / (n T)`` of the gas, eq. (G4)."""
    d = gas.dimension
    return 1.0 + 2.0 ** (d - 1) * gas.packing_fraction * gas.chi * pressure_factor(gas, temperature, a2, restitution)


@dataclass(frozen=True)
class CoolingCurve:
    """Kinetic-theory cooling from (G1)-(G3): T, a2 and collisions per particle against time.

    Attributes ``time``, ``temperature``, ``collisions`` (per particle), ``a2``: arrays (K,)
    on a grid from t = 0 (uniform in ``ln(1 + t/t_free)``); the methods interpolate
    the ODE solution itself (dense output), not the grid.
    """

    temperature: np.ndarray
    time: np.ndarray
    collisions: np.ndarray
    a2: np.ndarray | None = None
    solution: object = field(default=None, repr=False, compare=False)
    time_scale: float = 1.0
    hcs: HCSReference | None = None  # constant eps: the HCS reference the curve relaxes to

    @property
    def name(self) -> str:
        """What the curve is (reports, legends)."""
        if self.hcs is None:
            return "moment equations, first Sonine"
        if self.hcs.name == FIRST_SONINE:
            return f"moment equations, {FIRST_SONINE}"
        return f"{self.hcs.name} (cooling rate, a2), relaxed from the start"

    def _state(self, t):
        t = np.asarray(t, dtype=float)
        x = np.log1p(np.clip(t, 0.0, None) / self.time_scale)
        y = np.asarray(self.solution(np.atleast_1d(x).ravel()))
        y = y[:3].reshape((3,) + t.shape)
        beyond = t > self.time[-1] * (1.0 + 1e-12)
        return np.where(beyond, np.nan, y)

    def temperature_at(self, t):
        """T at times t (nan beyond the curve)."""
        if self.solution is None:
            lt = np.interp(np.asarray(t, dtype=float), self.time, np.log(self.temperature), right=np.nan)
            return np.exp(lt)
        return np.exp(self._state(t)[0])

    def a2_at(self, t):
        """a2 at times t (nan beyond the curve)."""
        return self._state(t)[1]

    def collisions_at(self, t):
        """Collisions per particle by time t (nan beyond the curve)."""
        return self._state(t)[2]

    def temperature_after(self, s):
        """T after s collisions per particle."""
        lt = np.interp(np.asarray(s, dtype=float), self.collisions, np.log(self.temperature), right=np.nan)
        return np.exp(lt)


def hcs_of(gas: Gas, reference: str = "best") -> HCSReference | None:
    """The HCS reference of a constant-restitution gas (None for other models; module doc).

    ``reference``: ``"best"`` (:func:`granulargas.theory.hcs.hcs_reference`) or
    ``"first_sonine"`` (van Noije & Ernst 1998).
    """
    if reference not in REFERENCES:
        raise ValueError(f"reference = {reference!r}: one of {', '.join(REFERENCES)}")
    if gas.model != "constant" or gas.restitution is None:
        return None
    if reference == "first_sonine":
        return first_sonine(gas.restitution, gas.dimension)
    return hcs_reference(gas.restitution, gas.dimension)


def relaxation_collisions(gas: Gas, fraction: float = 0.01, a2: float = 0.0) -> float:
    """Collisions per particle after which a2 of (G2) has come within ``fraction`` of the way to its
    stationary value: ``ln(1/fraction) omega / lambda`` at the gas's T0 (for a constant eps a
    number of eps and d). First Sonine: the DSMC's a2 relaxes as fast or up to 1.8 times faster,
    so this errs on the long side, the safe side for a mean that must start after the relaxation."""
    _, d0, omega = cooling_rates(gas, gas.temperature, a2)
    _, d1, _ = cooling_rates(gas, gas.temperature, a2 + 1.0)
    rate = -(float(d1) - float(d0))
    if not rate > 0.0:
        return math.inf
    return math.log(1.0 / fraction) * float(omega) / rate


def _hcs_rhs(gas: Gas, ref: HCSReference, a2_initial: float, t_free: float):
    """Right-hand side of (G1')-(G3') in x = ln(1 + t/t_free), state (ln T, a2, s, u)."""
    zeta_m, d0, omega_m = (float(x) for x in cooling_rates(gas, 1.0, 0.0))  # Maxwellian, T = 1
    _, d1, _ = cooling_rates(gas, 1.0, 1.0)
    rate = ref.relaxation_rate  # per collision per particle
    if not (math.isfinite(rate) and rate > 0.0):
        rate = -(float(d1) - d0) / omega_m  # first Sonine
    c_zeta0, c_omega0 = 1.0 + 3.0 * a2_initial / 16.0, 1.0 - a2_initial / 16.0

    def rhs(x, y):
        t_plus = t_free * math.exp(x)
        root = math.exp(0.5 * y[0])  # every rate scales as sqrt(T)
        u = y[3]
        zeta = zeta_m * root * (ref.zeta_factor + (c_zeta0 - ref.zeta_factor) * u)
        omega = omega_m * root * (ref.omega_factor + (c_omega0 - ref.omega_factor) * u)
        lam = rate * omega
        return [-zeta * t_plus, -lam * (y[1] - ref.a2) * t_plus, omega * t_plus, -lam * u * t_plus]

    return rhs


def cooling_curve(gas: Gas, t_end: float | None = None, t_min_ratio: float | None = 1e-12, points: int = 600,
                  a2_initial: float = 0.0, restitution=None, rtol: float = 1e-10,
                  reference: str = "best") -> CoolingCurve:
    """Integrate (G1)-(G3) from T0, a2 = ``a2_initial`` (module doc); for a constant restitution
    and ``reference="best"``, (G1')-(G3') with the HCS of :func:`hcs_of`.

    Parameters
    ----------
    t_end : float, optional
        Stop at this time.
    t_min_ratio : float, optional
        Stop when T falls to ``t_min_ratio T0`` (whichever comes first; at least one
        of the two must be given; an elastic gas needs ``t_end``).
    points : int
        Grid points of the returned arrays.
    restitution : callable, optional
        ``eps(beta)``, see :func:`restitution_at_nodes`.
    reference : str
        ``"best"`` or ``"first_sonine"``: the HCS of a constant restitution (:func:`hcs_of`).
    """
    T0 = gas.temperature
    hcs = hcs_of(gas, reference)
    inelastic = not (gas.model == "elastic" or (gas.model == "constant" and gas.restitution == 1.0)
                     or (gas.model == "viscoelastic" and not gas.pair_constant))
    if t_end is None and (t_min_ratio is None or not inelastic):
        raise ValueError("cooling_curve needs t_end (an elastic gas does not cool)")
    t_free = 1.0 / float(cooling_rates(gas, T0, a2_initial, restitution)[2])
    table = None
    if gas.model == "viscoelastic" and gas.pair_constant and restitution is None:
        u_max = float(speed_quadrature(gas.dimension).u.max())
        table = restitution_table(float(gas.beta(math.sqrt(4.0 * T0 / gas.mass) * u_max)) * 1.01, end=gas.end)

    rates = _rates_at(gas, restitution, table)

    def rhs(x, y):
        t_plus = t_free * math.exp(x)  # dt/dx = t + t_free
        zeta, da2, omega = rates(math.exp(y[0]), y[1])
        return [-zeta * t_plus, da2 * t_plus, omega * t_plus]

    y0 = [math.log(T0), float(a2_initial), 0.0]
    atol = [1e-12, 1e-12, 1e-10]
    if hcs is not None and hcs.name != FIRST_SONINE and restitution is None:
        rhs = _hcs_rhs(gas, hcs, float(a2_initial), t_free)
        y0, atol = y0 + [1.0], atol + [1e-12]

    x_end = math.log1p(t_end / t_free) if t_end is not None else math.inf
    events = None
    if inelastic and t_min_ratio is not None:
        ln_stop = math.log(t_min_ratio)

        def cooled(x, y):
            return y[0] - math.log(T0) - ln_stop

        cooled.terminal = True
        events = cooled
        if not math.isfinite(x_end):
            # t = t_free e^200: the event comes first for any cooling gas, unless t_free is so
            # long (a very dilute gas) that the time would leave float64's range first
            x_end = min(200.0, math.log(np.finfo(np.float64).max) - math.log(t_free) - 1.0)
    from scipy.integrate import solve_ivp  # here, not at the top: a run's start-up loads no scipy

    sol = solve_ivp(rhs, (0.0, x_end), y0, method="LSODA", rtol=rtol, atol=atol, dense_output=True, events=events)
    if sol.status < 0:
        raise RuntimeError(f"cooling_curve: the ODE solver failed ({sol.message})")
    x_last = float(sol.t[-1])
    x = np.linspace(0.0, x_last, points)
    y = sol.sol(x)
    t = t_free * np.expm1(x)
    t[-1] = t_free * math.expm1(x_last)
    return CoolingCurve(np.exp(y[0]), t, y[2], y[1], solution=sol.sol, time_scale=t_free, hcs=hcs)


def viscoelastic_cooling(gas: Gas, t_min_ratio: float = 1e-12, points: int = 600,
                         restitution=None) -> CoolingCurve:
    """Cooling curve of the gas from T0 down to ``t_min_ratio T0`` (:func:`cooling_curve`).

    ``restitution``: optional eps(beta) callable, see :func:`restitution_at_nodes`.
    """
    return cooling_curve(gas, t_end=None, t_min_ratio=t_min_ratio, points=points, restitution=restitution)


def _haff_end(gas: Gas):
    """(t_end, ln T_end) of a constant-eps run: Haff's law with the cooling rate and collision
    frequency of the HCS reference (:func:`hcs_of`); in logarithms so that runs cooling past
    float64 are still reported."""
    eps, T0 = gas.restitution, gas.temperature
    t_end = gas.end_time
    omega0 = gas.collision_frequency
    if eps >= 1.0:
        return (t_end if t_end is not None else gas.collisions_per_particle / omega0), math.log(T0)
    hcs = hcs_of(gas)
    omega0 *= hcs.omega_factor
    zeta0 = float(enskog_cooling_rate(eps, gas.density, T0, gas.dimension, gas.sigma, gas.mass, chi=gas.chi, a2=0.0))
    tau0 = 2.0 / (zeta0 * hcs.zeta_factor)
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
