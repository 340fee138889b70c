"""Analysis of an elastic run (energy conserved): energy drift, pressure, collision frequency.

An elastic gas does not cool, so there is no cooling law to fit; what a run shows is

* the **energy drift** ``(E(t) - E(0)) / E(0)`` of the kinetic energy: zero up to
  round-off in an event-driven simulation (each collision conserves energy to a
  few ulp);
* the **compressibility factor** ``Z = P / (n T)`` from the pressure the engine
  averages over each observation window (kinetic plus collisional virial), against
  the equation of state of :func:`granulargas.theory.compressibility_factor`
  (Kolafa-Labík-Malijevský in 3D, the resummed hard-disk virial series of Clisby
  & McCoy in 2D; Carnahan-Starling / Henderson for reference);
* the **collision frequency** per particle ``omega = 2 dC / (N dt)`` against
  Enskog's ``omega = (2 pi^((d-1)/2) / Gamma(d/2)) chi n sigma^(d-1) sqrt(T/m)`` with the
  same chi (:func:`granulargas.theory.collision_frequency`).

The first :data:`EQUILIBRATION` of the run (at least :data:`EQUILIBRATION_FREE_TIMES`
mean free times) is left out of the averages: the initial state has not yet the
equilibrium pair correlation. Errors are standard errors of block means (blocks
of consecutive windows, :data:`BLOCKS` of them), which allows for the correlation
of neighbouring windows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas import theory
from granulargas.observables import finite_sample_sonine
from granulargas.analysis.run import (
    CoolingHistory,
    PressureSamples,
    RunInfo,
    _clean,
    cooling_history,
    history_span,
    pressure_samples,
    run_identity,
    sonine_history,
    theory_name,
)
from granulargas.analysis.cooling import BLOCKS, block_mean  # noqa: F401 (re-exported: the one error estimate)
from granulargas.errors import InputFileError

__all__ = ["ElasticAnalysis", "analyze_elastic", "block_mean", "EQUILIBRATION", "EQUILIBRATION_FREE_TIMES", "BLOCKS"]

#: fraction of the run left out of the averages
EQUILIBRATION = 0.1
#: ... but at least this many mean free times
EQUILIBRATION_FREE_TIMES = 5.0


@dataclass(frozen=True)
class ElasticAnalysis:
    """An elastic run against the equation of state and Enskog's collision frequency."""

    info: RunInfo
    history: CoolingHistory
    pressure: PressureSamples
    t_equilibrated: float  # averages use times >= this
    sonine: tuple  # (time, a2, a3) of the snapshots
    kind: str = "elastic"

    @property
    def time(self) -> np.ndarray:
        return self.history.time

    @property
    def theory_name(self) -> str:
        return theory_name(self.info)

    @property
    def energy_drift(self) -> np.ndarray:
        """``(E(t) - E(0)) / E(0)`` of the kinetic energy (from T if the file has no energy), (S,)."""
        e = self.history.kinetic_energy
        if not np.all(np.isfinite(e)):
            e = self.history.temperature
        return e / e[0] - 1.0

    @property
    def temperature(self) -> float:
        return float(np.mean(self.history.temperature))

    @property
    def Z_windows(self):
        """(mid time, Z) of the pressure windows after equilibration."""
        p = self.pressure
        sel = p.start >= self.t_equilibrated
        return 0.5 * (p.start + p.end)[sel], p.Z[sel]

    @property
    def Z_measured(self):
        """(mean, standard error) of Z after equilibration."""
        return block_mean(self.Z_windows[1])

    @property
    def Z_theory(self) -> float:
        return float(theory.compressibility_factor(self.info.packing_fraction, self.info.dimension))

    @property
    def Z_reference(self) -> float:
        """Carnahan-Starling (3D) or Henderson (2D), for comparison."""
        return float(theory.compressibility_factor(self.info.packing_fraction, self.info.dimension, "closed"))

    @property
    def collision_windows(self):
        """(mid time, omega) per observation interval after equilibration: 2 dC / (N dt)."""
        h = self.history
        ok = (h.collisions >= 0) & (h.time >= self.t_equilibrated)
        t, c = h.time[ok], h.collisions[ok].astype(float)
        if t.size < 2:
            return np.empty(0), np.empty(0)
        return 0.5 * (t[1:] + t[:-1]), 2.0 * np.diff(c) / (self.info.particles * np.diff(t))

    @property
    def collision_frequency(self):
        """(mean, standard error) of the measured collision frequency per particle."""
        t, omega = self.collision_windows
        if t.size == 0:
            return math.nan, math.nan
        h = self.history
        ok = (h.collisions >= 0) & (h.time >= self.t_equilibrated)
        t_ok, c = h.time[ok], h.collisions[ok].astype(float)
        mean = 2.0 * (c[-1] - c[0]) / (self.info.particles * (t_ok[-1] - t_ok[0]))
        return mean, block_mean(omega)[1]

    @property
    def collision_frequency_theory(self) -> float:
        i = self.info
        return float(theory.collision_frequency(i.number_density, self.temperature, i.dimension, i.diameter, i.mass))

    def summary(self) -> dict:
        """The numbers of the analysis as a flat, JSON-ready dict (``granulargas analyze --json``)."""
        info, h = self.info, self.history
        z, z_err = self.Z_measured
        om, om_err = self.collision_frequency
        drift = self.energy_drift
        ts, a2, _ = self.sonine
        a2_mean, a2_err = block_mean(a2[ts >= self.t_equilibrated]) if np.any(ts >= self.t_equilibrated) else (None, None)
        a2_theory = finite_sample_sonine(info.particles, info.dimension)[0]  # N particles on their energy shell
        return _clean({
            **run_identity(info, self.kind),
            **history_span(h),
            "theory": self.theory_name,
            "T_theory_final": float(h.temperature[0]),
            "T_ratio_final": float(h.temperature[-1] / h.temperature[0]),
            "tau0_fit": None,
            "tau0_theory": None,
            "exponent_fit": None,
            "exponent_theory": None,
            "energy_drift_final": float(drift[-1]),
            "energy_drift_max": float(np.max(np.abs(drift))),
            "a2_mean": a2_mean,
            "a2_error": a2_err,
            "a2_theory": a2_theory,
            "Z": z,
            "Z_error": z_err,
            "Z_theory": self.Z_theory,
            "Z_theory_name": theory.eos_name(info.dimension),
            "Z_reference": self.Z_reference,
            "Z_reference_name": theory.eos_name(info.dimension, "closed"),
            "collision_frequency": om,
            "collision_frequency_error": om_err,
            "collision_frequency_theory": self.collision_frequency_theory,
        })


def analyze_elastic(path, with_sonine: bool = True, **_ignored) -> ElasticAnalysis:
    """Energy drift, Z and collision frequency of an elastic run (module doc)."""
    info = RunInfo.from_file(path)
    hist = cooling_history(path, info.particles)
    if hist.time.size == 0:
        raise InputFileError(f"{path}: no temperature samples")
    T = float(hist.temperature[0])
    t_free = 1.0 / float(theory.collision_frequency(info.number_density, T, info.dimension, info.diameter, info.mass))
    t0, t1 = float(hist.time[0]), float(hist.time[-1])
    t_eq = t0 + max(EQUILIBRATION * (t1 - t0), EQUILIBRATION_FREE_TIMES * t_free)
    if t_eq >= t1:  # a very short run: keep its second half
        t_eq = t0 + 0.5 * (t1 - t0)
    son = sonine_history(path) if with_sonine else (np.empty(0),) * 3
    return ElasticAnalysis(info, hist, pressure_samples(hist, info.number_density), t_eq, son)
