"""Analysis of a uniform shear flow run: the steady state against the Grad solution.

A sheared gas (``[shear]``) settles where viscous heating balances the collisional loss
(or the thermostat's rescaling). From the observables after the relaxation (the
pressure tensor of each sampling interval, the temperature, the dissipated energy) a run
gives

* the steady temperature T and the reduced shear rate a* = a / nu0(T);
* the reduced viscosity eta* = -P_xy / (a eta0(T)) and the pressure tensor over
  p = tr P / d, with the normal stress differences (P_xx - P_yy)/p and (P_yy - P_zz)/p;
* the energy balance: viscous heating -a P_xy V against the rate of the dissipated
  energy (and of the thermostat's removal), which steady state makes equal;

each with the standard error of block means (:func:`granulargas.analysis.cooling.block_mean`),
against the Grad solution of :mod:`granulargas.theory.shear` (the Enskog equation at the
run's packing fraction; constant restitution, or a viscoelastic gas's effective
restitution at the steady temperature; with the thermostat at the run's a*), and the
Navier-Stokes viscosity (:func:`granulargas.theory.shear.navier_stokes_viscosity_reduced`)
that an elastic gas approaches at small a*. nu0 and eta0 are those of eq. (S1) there:
nu0 = n T / eta0, eta0 the dilute elastic first-Sonine viscosity.

The relaxation left out: the first :data:`RELAXATION_FRACTION` of the run, or longer if
the dilute Grad transient (:func:`granulargas.theory.shear.grad_transient`) needs it to
bring T within :data:`REACHED` of its steady value, plus :data:`RELAXATION_COLLISIONS`
mean free times at the steady temperature.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas import theory
from granulargas.analysis.cooling import block_mean
from granulargas.analysis.run import RunInfo, _clean, run_identity
from granulargas.errors import InputFileError
from granulargas.io.h5md import read_observables

__all__ = ["ShearAnalysis", "analyze_shear", "shear_theory", "RELAXATION_FRACTION", "RELAXATION_COLLISIONS"]

#: at least this fraction of the run is left out as relaxation
RELAXATION_FRACTION = 0.25
#: ... and these many mean free times after the transient reaches the steady temperature ...
RELAXATION_COLLISIONS = 5.0
#: ... to within this fraction (the dilute Grad transient, constant restitution)
REACHED = 0.02


@dataclass(frozen=True)
class ShearTheory:
    """The Grad solution for a run (:class:`granulargas.theory.shear.ShearState`), the
    temperature it predicts (nan with a thermostat: the thermostat's), and the Navier-Stokes
    viscosity at the run's restitution."""

    name: str
    state: object
    temperature: float
    eta_ns: float


def shear_theory(info: RunInfo, rate: float, temperature: float, thermostat: float | None) -> ShearTheory:
    """:class:`ShearTheory` of a run at its measured steady ``temperature``."""
    d = info.dimension
    phi = info.solid_fraction
    n = info.particles / info.volume
    sigma, m = info.diameter, info.mass
    if info.model == "viscoelastic" and info.prefactor:
        eps = float(theory.effective_restitution(info.prefactor, temperature, d, sigma, m, info.contact_end))
        how = f"effective eps {eps:.4f} at T"
    elif info.model == "constant" and info.restitution is not None:
        eps = float(info.restitution)
        how = f"eps {eps:g}"
    else:
        eps = 1.0
        how = "elastic"
    density = f"Enskog, packing {phi:.3g}" if phi > 1e-3 else "Boltzmann"
    if thermostat is not None:
        a_star = rate / float(theory.shear.reference_frequency(n, temperature, d, sigma, m))
        st = theory.shear.grad_usf(eps, d, phi, a_star=a_star)
        T = float(thermostat)
        name = f"Grad solution of USF ({density}; {how}), Gaussian thermostat at a* = {a_star:.4g}"
    else:
        st = theory.shear.grad_usf(eps, d, phi)
        if info.model == "viscoelastic" and info.prefactor:
            prefactor, end = info.prefactor, info.contact_end
            T = theory.shear.steady_temperature(
                rate, lambda t: float(theory.effective_restitution(prefactor, t, d, sigma, m, end)), n, d, sigma,
                m, phi)
        else:
            T = theory.shear.steady_temperature(rate, eps, n, d, sigma, m, phi)
        name = f"Grad solution of USF ({density}; {how}), viscous heating = collisional loss"
    eta_ns = float(theory.shear.navier_stokes_viscosity_reduced(eps, d, phi))
    return ShearTheory(name, st, float(T), eta_ns)


@dataclass(frozen=True)
class ShearAnalysis:
    """A sheared run's steady state against the Grad solution (see :func:`analyze_shear`)."""

    info: RunInfo
    rate: float
    thermostat: float | None
    time: np.ndarray  # sample times
    temperature: np.ndarray  # T at each sample
    tensor: np.ndarray  # (S, d, d) mean pressure tensor over the interval ending at each sample
    dissipated: np.ndarray
    injected: np.ndarray
    t_relaxed: float
    theory: ShearTheory
    kind: str = "shear"

    @property
    def theory_name(self) -> str:
        return self.theory.name

    @property
    def steady(self) -> np.ndarray:
        """Samples whose interval lies after the relaxation (the first sample has no interval)."""
        ok = np.zeros(self.time.size, dtype=bool)
        ok[1:] = self.time[:-1] >= self.t_relaxed
        return ok & np.all(np.isfinite(self.tensor.reshape(self.time.size, -1)), axis=1)

    def _reference(self, T):
        info = self.info
        n = info.particles / info.volume
        nu0 = theory.shear.reference_frequency(n, T, info.dimension, info.diameter, info.mass)
        eta0 = theory.shear.dilute_viscosity(T, info.dimension, info.diameter, info.mass)
        return nu0, eta0

    def _interval_temperature(self):
        """T averaged over each sampling interval (trapezoid of the samples at its ends)."""
        T = self.temperature
        out = np.full(T.size, np.nan)
        out[1:] = 0.5 * (T[1:] + T[:-1])
        return out

    def reduced(self) -> dict:
        """Per-interval reduced quantities of the steady samples: a*, eta*, P/p, N1, N2."""
        sel = self.steady
        P = self.tensor[sel]
        T = self._interval_temperature()[sel]
        nu0, eta0 = self._reference(T)
        p = np.trace(P, axis1=1, axis2=2) / self.info.dimension
        out = {
            "T": T,
            "a_star": self.rate / nu0,
            "eta_star": -P[:, 0, 1] / (self.rate * eta0),
            "P_xx": P[:, 0, 0] / p,
            "P_yy": P[:, 1, 1] / p,
            "P_xy": P[:, 0, 1] / p,
            "N1": (P[:, 0, 0] - P[:, 1, 1]) / p,
            "Z": p / (self.info.particles / self.info.volume * T),
        }
        if self.info.dimension == 3:
            out["P_zz"] = P[:, 2, 2] / p
            out["N2"] = (P[:, 1, 1] - P[:, 2, 2]) / p
        return out

    def energy_balance(self):
        """(viscous heating rate -a P_xy V, dissipation rate, thermostat removal rate) over the
        steady part (means of the intervals; rates per unit time)."""
        sel = self.steady
        idx = np.flatnonzero(sel)
        if idx.size == 0:
            return math.nan, math.nan, math.nan
        t0, t1 = self.time[idx[0] - 1], self.time[idx[-1]]
        dt = np.diff(self.time)[idx - 1]
        heat = float(np.sum(-self.rate * self.tensor[idx, 0, 1] * self.info.volume * dt) / (t1 - t0))
        diss = float((self.dissipated[idx[-1]] - self.dissipated[idx[0] - 1]) / (t1 - t0))
        removed = float(-(self.injected[idx[-1]] - self.injected[idx[0] - 1]) / (t1 - t0))
        return heat, diss, removed

    def summary(self) -> dict:
        """JSON-friendly numbers (``granulargas analyze --json``)."""
        r = self.reduced()
        st = self.theory.state
        out = {**run_identity(self.info, self.kind), "method": self.info.method,
               "solid_fraction": self.info.solid_fraction, "shear_rate": self.rate,
               "thermostat_temperature": self.thermostat, "theory": self.theory.name,
               "relaxed_from": self.t_relaxed, "t_final": float(self.time[-1]),
               "samples": int(np.count_nonzero(self.steady))}
        pairs = [("T_steady", "T", self.theory.temperature), ("a_star", "a_star", st.a_star),
                 ("eta_star", "eta_star", st.eta_star), ("P_xx_over_p", "P_xx", st.pressure[0, 0]),
                 ("P_yy_over_p", "P_yy", st.pressure[1, 1]), ("P_xy_over_p", "P_xy", st.pressure[0, 1]),
                 ("N1", "N1", st.normal_stress_differences[0]), ("Z", "Z", st.temperature_ratio)]
        if self.info.dimension == 3:
            pairs += [("P_zz_over_p", "P_zz", st.pressure[2, 2]), ("N2", "N2", st.normal_stress_differences[1])]
        for name, key, th in pairs:
            m, e = block_mean(r[key])
            out[name], out[name + "_error"], out[name + "_theory"] = m, e, float(th)
        out["eta_star_navier_stokes"] = self.theory.eta_ns
        heat, diss, removed = self.energy_balance()
        out.update(viscous_heating=heat, dissipation_rate=diss, thermostat_removal=removed)
        return _clean(out)


def analyze_shear(path, **_) -> ShearAnalysis:
    """Analyse a sheared run's file (module doc)."""
    info = RunInfo.from_file(path)
    sh = info.parameters.get("shear", {}) or {}
    rate = float(sh.get("rate", math.nan))
    thermostat = sh.get("thermostat_temperature")
    thermostat = None if thermostat is None else float(thermostat)
    obs = read_observables(path)
    if "pressure_tensor" not in obs:
        raise InputFileError(f"{path}: the file holds no pressure_tensor observable, which the analysis of a "
                             "sheared run needs (granulargas run and RunWriter write it)")
    _, t, T = obs["temperature"]
    t, idx = np.unique(np.asarray(t, dtype=float), return_index=True)
    T = np.asarray(T, dtype=float)[idx]
    tensor = np.asarray(obs["pressure_tensor"][2], dtype=float)[idx]
    diss = np.asarray(obs["dissipated_energy"][2], dtype=float)[idx]
    inj = np.asarray(obs["injected_energy"][2], dtype=float)[idx] if "injected_energy" in obs else np.zeros(t.size)
    T_end = float(np.mean(T[t >= t[0] + 0.5 * (t[-1] - t[0])]))
    th = shear_theory(info, rate, T_end, thermostat)
    n = info.particles / info.volume
    d = info.dimension
    chi = float(theory.contact_value(info.solid_fraction, d)) if info.solid_fraction > 0 else 1.0
    T_s = th.temperature
    free = 1.0 / float(theory.collision_frequency(n, T_s, d, info.diameter, info.mass, chi=chi))
    relax = RELAXATION_FRACTION * (t[-1] - t[0])
    if thermostat is None:
        eps = info.restitution if info.model == "constant" else None
        if eps is not None:
            t_reach, _ = theory.shear.grad_transient(rate, eps, n, float(T[0]), d, info.diameter, info.mass, chi,
                                                     t_end=float(t[-1] - t[0]), tolerance=REACHED)
            if math.isfinite(t_reach):
                relax = max(relax, t_reach + RELAXATION_COLLISIONS * free)
    else:
        relax = max(relax, RELAXATION_COLLISIONS * free)
    t_relaxed = float(t[0] + relax)
    if t_relaxed >= t[-2]:
        raise InputFileError(f"{path}: the run ends at t = {t[-1]:.4g}, before the relaxation to the steady shear flow "
                         f"(t = {t_relaxed:.4g}); run it longer")
    # the theory at the measured steady temperature (a viscoelastic gas's effective eps, a* with thermostat)
    a = ShearAnalysis(info, rate, thermostat, t, T, tensor, diss, inj, t_relaxed, th)
    T_ss = block_mean(a.reduced()["T"])[0]
    th = shear_theory(info, rate, T_ss, thermostat)
    return ShearAnalysis(info, rate, thermostat, t, T, tensor, diss, inj, t_relaxed, th)
