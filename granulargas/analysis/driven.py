"""Analysis of a white-noise driven run: the steady state against kinetic theory.

A driven gas (``[driving] model = "white_noise"``) does not cool towards zero: its
temperature relaxes to the steady value where the heating rate H balances the
collisional cooling, ``zeta(T) T = H`` (:mod:`granulargas.theory.driven`). What a
run shows is

* the **steady temperature**: the mean of T over the observables samples after
  the relaxation (the first :data:`RELAXATION_TIMES` cooling times 1/zeta(T_ss),
  at least :data:`RELAXATION_FRACTION` of the run), against the theory
  (:func:`granulargas.theory.driven_state`: the Enskog-Boltzmann moment equations in
  the first Sonine approximation with the exact eps(g) and the heating term; for
  constant eps van Noije & Ernst's driven state);
* the **second Sonine coefficient** a2 of the snapshots after the relaxation
  (corrected for the -2/(dN) bias of the estimator over N particles) against the
  driven first-Sonine value of the same theory;
* T(t) with the theoretical relaxation from T0 (``dT/dt = H - zeta(T) T``
  integrated with the steady a2), for the figure.

Errors are standard errors of block means (:func:`granulargas.analysis.elastic.block_mean`).
The engine kicks at the times (k + 1/2) dt_k and the runner makes the observables
interval a multiple of dt_k, so every sample lies half-way between two kicks,
where T equals its average over a kick interval.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from granulargas import theory
from granulargas.analysis.elastic import block_mean
from granulargas.analysis.run import (CoolingHistory, RunInfo, _clean, cooling_history, run_identity,
                                      sonine_history)

__all__ = ["DrivenAnalysis", "analyze_driven", "RELAXATION_TIMES", "RELAXATION_FRACTION"]

#: cooling times 1/zeta(T_ss) left out as relaxation
RELAXATION_TIMES = theory.driven.RELAXATION_TIMES
#: ... and at least this fraction of the run
RELAXATION_FRACTION = 0.1


@dataclass(frozen=True)
class DrivenTheory:
    """The steady state kinetic theory predicts for a driven run."""

    name: str
    temperature: float  # T_ss
    a2: float
    cooling_rate: float  # zeta(T_ss) = H / T_ss
    eps: float  # constant or effective restitution coefficient at T_ss


def driven_theory(info: RunInfo, heating_rate: float) -> DrivenTheory:
    """:class:`DrivenTheory` of a run (identical particles of the mean diameter): the moment
    equations with the exact eps(g) and the heating term (:func:`granulargas.theory.driven_state`);
    for constant eps this is van Noije & Ernst's driven state."""
    d = info.dimension
    if info.model == "viscoelastic" and info.prefactor:
        gas = info.gas(1.0)
        T, a2 = theory.driven_state(gas, heating_rate)
        eps = theory.effective_restitution(info.prefactor, T, d, info.diameter, info.mass, info.contact_end)
        name = ("Enskog-Boltzmann, first Sonine with the exact eps(g): zeta(T, a2) T = H and the driven "
                "a2 equation")
    elif info.model == "constant" and info.restitution is not None and info.restitution < 1.0:
        eps = info.restitution
        T, a2 = theory.driven_state(info.gas(1.0), heating_rate)
        name = "Enskog, zeta(T) T = H, driven first-Sonine a2 (van Noije & Ernst 1998)"
    else:
        return DrivenTheory("elastic: no steady state, T = T0 + H t", math.inf, 0.0, 0.0, 1.0)
    return DrivenTheory(name, T, a2, heating_rate / T, eps)


@dataclass(frozen=True)
class DrivenAnalysis:
    """A driven run's steady state against kinetic theory (see :func:`analyze_driven`)."""

    info: RunInfo
    history: CoolingHistory
    heating_rate: float
    interval: float
    theory: DrivenTheory
    t_relaxed: float
    sonine: tuple  # (time, a2, a3) of the snapshots
    kind: str = "driven"

    @property
    def time(self) -> np.ndarray:
        return self.history.time

    @property
    def theory_name(self) -> str:
        return self.theory.name

    @property
    def steady(self) -> np.ndarray:
        return self.history.time >= self.t_relaxed

    @property
    def temperature_mean(self):
        """(mean, standard error) of T after the relaxation."""
        return block_mean(self.history.temperature[self.steady])

    @property
    def a2_mean(self):
        """(mean, standard error) of a2 of the snapshots after the relaxation, bias-corrected."""
        t, a2, _ = self.sonine
        sel = t >= self.t_relaxed
        if not np.any(sel):
            return math.nan, math.nan
        bias = -2.0 / (self.info.dimension * self.info.particles)
        m, e = block_mean(a2[sel])
        return m - bias, e

    def temperature_theory(self, t) -> np.ndarray:
        """T(t) from T0 by ``dT/dt = H - zeta(T) T`` (zeta ~ sqrt(T) at the steady a2 and eps;
        :func:`granulargas.theory.relaxation_temperature`)."""
        return theory.relaxation_temperature(t, float(self.history.temperature[0]), self.heating_rate,
                                             self.theory.temperature)

    def summary(self) -> dict:
        """JSON-friendly numbers (``granulargas analyze --json``)."""
        T, T_err = self.temperature_mean
        a2, a2_err = self.a2_mean
        th = self.theory
        return _clean({
            **run_identity(self.info, self.kind),
            "t_final": float(self.time[-1]),
            "T_final": float(self.history.temperature[-1]),
            "theory": th.name,
            "heating_rate": self.heating_rate,
            "kick_interval": self.interval,
            "relaxed_from": self.t_relaxed,
            "T_steady": T,
            "T_steady_error": T_err,
            "T_steady_theory": th.temperature,
            "T_ratio": T / th.temperature if math.isfinite(th.temperature) else None,
            "T_ratio_error": T_err / th.temperature if math.isfinite(th.temperature) else None,
            "a2_mean": a2,
            "a2_error": a2_err,
            "a2_theory": th.a2,
            "eps_effective": th.eps,
            "zeta_dt_k": th.cooling_rate * self.interval,
        })


def analyze_driven(path, t_range=None, with_sonine: bool = True, **_) -> DrivenAnalysis:
    """Analyse a driven run's file (``t_range`` is not used: the steady state has no fit)."""
    info = RunInfo.from_file(path)
    drv = info.parameters.get("driving", {}) or {}
    h = float(drv.get("heating_rate", math.nan))
    history = cooling_history(path, info.particles)
    th = driven_theory(info, h)
    t = history.time
    relax = RELAXATION_TIMES / th.cooling_rate if th.cooling_rate > 0 else 0.0
    t_relaxed = float(t[0] + max(relax, RELAXATION_FRACTION * (t[-1] - t[0])))
    if t_relaxed >= t[-1]:
        raise ValueError(f"the run ends at t = {t[-1]:.4g}, before the relaxation to the steady state "
                         f"({RELAXATION_TIMES:g} cooling times, t = {t_relaxed:.4g}); run it longer")
    sonine = sonine_history(path) if with_sonine else (np.empty(0), np.empty(0), np.empty(0))
    return DrivenAnalysis(info, history, h, float(drv.get("interval", math.nan)), th, t_relaxed, sonine)
