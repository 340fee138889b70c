"""Analysis of a run of rough particles: two temperatures against the two-temperature theory.

A run with ``[collision.tangential]`` stores the translational temperature
(``temperature``), the rotational one (``rotational_temperature``) and the cumulants
``cumulant_a20``, ``cumulant_a02``, ``cumulant_a11`` at every observables sample
(:mod:`granulargas.observables`). The analysis compares

* T_tr(t), T_rot(t) and theta = T_rot / T_tr with the Maxwellian energy balances
  (:mod:`granulargas.theory.rough`, eq. (R5)) integrated from the run's first sample,
  for the run's normal law (constant eps, or the exact viscoelastic eps(g)), tangential
  law (constant beta_t or Walton's model), moment of inertia and driving;
* theta after the relaxation: against the theory curve over the same samples, and a
  cooling run's against the homogeneous cooling state
  (eq. (R7); for the viscoelastic law at the run's last T_tr, since it drifts), a
  driven run's steady theta and T_tr against the driven steady state. The relaxed part
  is, for a cooling run, the samples from :data:`RELAXATION_COLLISIONS` collisions per
  particle on (theta relaxes in a few collisions) and at least the second half of the run in
  collisions; for a driven run, as :mod:`granulargas.analysis.driven`, the samples after
  five cooling times of the steady state. Errors are standard errors of block means
  (:func:`granulargas.analysis.cooling.block_mean`);
* the cumulants: their means over the relaxed part (the Maxwellian theory has none: 0).

The theory is for identical particles of the mean diameter and mass; the Maxwellian theta
is known to miss the simulations by a few per cent (documentation page "Rough grains").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas.analysis.cooling import block_mean, collisions_per_particle
from granulargas.analysis.run import RunInfo, _clean, run_identity
from granulargas.errors import InputFileError
from granulargas.io.h5md import read_observables
from granulargas.theory import rough as R

__all__ = ["RoughHistory", "RoughAnalysis", "analyze_rough", "rough_gas", "RELAXATION_COLLISIONS"]

#: collisions per particle left out of a cooling run as theta's relaxation
RELAXATION_COLLISIONS = 10.0
#: cooling times of the steady state left out of a driven run (as analysis.driven)
RELAXATION_TIMES = 5.0


@dataclass(frozen=True)
class RoughHistory:
    """The rough observables against time (arrays (K,))."""

    time: np.ndarray
    translational: np.ndarray
    rotational: np.ndarray
    collisions: np.ndarray  # per particle
    a20: np.ndarray
    a02: np.ndarray
    a11: np.ndarray

    @property
    def ratio(self) -> np.ndarray:
        return self.rotational / self.translational


def rough_history(path, particles: int) -> RoughHistory:
    """The rough observables of a file (:class:`RoughHistory`)."""
    obs = read_observables(path)
    if "rotational_temperature" not in obs:
        raise InputFileError(f"{path}: no observables/rotational_temperature (not a run of rough particles)")
    _, t, T = obs["temperature"]
    t, idx = np.unique(np.asarray(t, dtype=float), return_index=True)

    def column(name):
        value = np.asarray(obs[name][2], dtype=float) if name in obs else np.full(len(T), np.nan)
        return value[idx] if len(value) == len(T) else np.full(len(idx), np.nan)

    coll = column("collisions")
    return RoughHistory(t, np.asarray(T, float)[idx], column("rotational_temperature"),
                        collisions_per_particle(coll, particles), column("cumulant_a20"), column("cumulant_a02"),
                        column("cumulant_a11"))


def rough_gas(info: RunInfo, T_tr: float, T_rot: float) -> R.RoughGas:
    """The run as a :class:`granulargas.theory.rough.RoughGas` starting at (T_tr, T_rot)."""
    tg = info.parameters.get("tangential", {}) or {}
    drv = info.parameters.get("driving", {}) or {}
    return R.RoughGas(info.gas(T_tr), float(tg.get("inertia", R.DEFAULT_INERTIA[info.dimension])),
                      tangential=str(tg.get("model", "constant")),
                      tangential_restitution=float(tg.get("restitution", -1.0)),
                      friction=float(tg.get("friction", 0.0)), rotational_temperature=float(T_rot),
                      heating_rate=float(drv.get("heating_rate", 0.0)),
                      rotational_fraction=float(drv.get("rotational_fraction", 0.0)))


@dataclass(frozen=True)
class RoughAnalysis:
    """A rough run's two temperatures against the two-temperature theory (:func:`analyze_rough`)."""

    info: RunInfo
    history: RoughHistory
    gas: R.RoughGas
    curve: object  # T_tr(t), T_rot(t) of the theory on the run's clock
    driven: bool
    t_relaxed: float
    theta_theory: float  # theta_HCS (cooling; viscoelastic: at the last T_tr) or theta_st (driven)
    T_steady_theory: float  # driven: T_tr of the steady state (nan otherwise)
    kind: str = "rough"

    @property
    def time(self) -> np.ndarray:
        return self.history.time

    @property
    def theory_name(self) -> str:
        normal = "exact eps(g)" if self.info.model == "viscoelastic" else "constant eps"
        tangential = ("Walton's Coulomb model, exact Maxwellian averages" if self.gas.tangential == "coulomb"
                      else "constant beta_t")
        return f"two-temperature Maxwellian energy balances (theory.rough), {normal}, {tangential}"

    @property
    def relaxed(self) -> np.ndarray:
        return self.time >= self.t_relaxed

    def mean(self, values):
        """(mean, standard error) of a series over the relaxed part (block means)."""
        return block_mean(np.asarray(values)[self.relaxed])

    def summary(self) -> dict:
        """JSON-friendly numbers (``granulargas analyze --json``)."""
        h = self.history
        theta, theta_err = self.mean(h.ratio)
        out = {
            **run_identity(self.info, self.kind),
            "kind": self.kind,
            "model": self.info.model,
            "tangential": self.gas.tangential,
            "tangential_restitution": self.gas.tangential_restitution,
            "friction": self.gas.friction if self.gas.tangential == "coulomb" else None,
            "inertia": self.gas.inertia,
            "dimension": self.info.dimension,
            "particles": self.info.particles,
            "driven": self.driven,
            "theory": self.theory_name,
            "t_final": float(h.time[-1]),
            "T_tr_final": float(h.translational[-1]),
            "T_rot_final": float(h.rotational[-1]),
            "T_final": float(h.translational[-1]),  # the temperature: the translational one
            "T_tr_final_theory": float(self.curve.translational_at(h.time[-1])),
            "T_rot_final_theory": float(self.curve.rotational_at(h.time[-1])),
            "relaxed_from": self.t_relaxed,
            "theta": theta,
            "theta_error": theta_err,
            "theta_theory": self.theta_theory,
            "theta_ratio": theta / self.theta_theory if self.theta_theory and math.isfinite(self.theta_theory)
            else None,
            # the theory curve over the same samples (a run that has not reached the state yet)
            "theta_theory_samples": float(np.mean(self.curve.ratio_at(h.time[self.relaxed])))
            if self.relaxed.any() else None,
        }
        for name in ("a20", "a02", "a11"):
            m, e = self.mean(getattr(h, name))
            out[f"cumulant_{name}"], out[f"cumulant_{name}_error"] = m, e
        if self.driven:
            T, T_err = self.mean(h.translational)
            out.update(T_steady=T, T_steady_error=T_err, T_steady_theory=self.T_steady_theory,
                       T_ratio=T / self.T_steady_theory)
        return _clean(out)


def analyze_rough(path, t_range=None, with_sonine: bool = True, **_) -> RoughAnalysis:
    """Analyse a rough run's file (``t_range`` and ``with_sonine`` are not used)."""
    info = RunInfo.from_file(path)
    h = rough_history(path, info.particles)
    ok = np.isfinite(h.translational) & np.isfinite(h.rotational)
    if not ok.any():
        raise InputFileError(f"{path}: no finite temperature samples")
    t0 = float(h.time[0])
    gas = rough_gas(info, float(h.translational[0]), float(h.rotational[0]))
    driven = gas.heating_rate > 0.0
    t_span = float(h.time[-1]) - t0
    curve = _shifted(R.two_temperature_curve(gas, max(t_span, 1e-12)), t0)
    if driven:
        T_st, R_st = R.driven_state(gas)
        theta_th = R_st / T_st
        zeta = gas.heating_rate / T_st
        t_relaxed = t0 + max(RELAXATION_TIMES / zeta, 0.1 * t_span)
    else:
        T_st = math.nan
        theta_th = R.hcs_ratio(gas, float(h.translational[-1]))
        s = h.collisions
        s_from = max(s[0] + RELAXATION_COLLISIONS, 0.5 * (s[0] + s[-1]))
        after = np.flatnonzero(s >= s_from)
        t_relaxed = float(h.time[after[0]]) if after.size else math.inf
    return RoughAnalysis(info, h, gas, curve, driven, float(t_relaxed), float(theta_th), float(T_st))


class _Shifted:
    """A theory curve whose clock starts at the run's first sample (a restart's absolute clock)."""

    def __init__(self, curve, t0):
        self._curve, self._t0 = curve, t0

    def translational_at(self, t):
        return self._curve.translational_at(np.asarray(t, dtype=float) - self._t0)

    def rotational_at(self, t):
        return self._curve.rotational_at(np.asarray(t, dtype=float) - self._t0)

    def ratio_at(self, t):
        return self._curve.ratio_at(np.asarray(t, dtype=float) - self._t0)

    def collisions_at(self, t):
        return self._curve.collisions_at(np.asarray(t, dtype=float) - self._t0)


def _shifted(curve, t0):
    return _Shifted(curve, t0)
