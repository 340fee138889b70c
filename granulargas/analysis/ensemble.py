"""Aggregating a sweep: averages over seeds and parameter scans.

A sweep (:mod:`granulargas.run.sweep`) leaves ``index.json`` beside its H5MD files,
one entry per run with its varied parameters. This module groups the finished
runs by every varied parameter except the seed, and for each group gives

* the ensemble temperature history: mean and standard error of T(t) over seeds
  (every member of a group shares its observables schedule, so the samples line
  up; a member whose times differ is rejected rather than interpolated);
* a cooling-law fit per seed (:func:`granulargas.analysis.cooling.fit_cooling_law`)
  and the mean and standard error of the fitted tau0 over seeds, e.g. tau0
  against the restitution for a Haff-law scan;
* :meth:`SweepResults.summaries`: every run analysed by the analysis of its kind
  (:func:`granulargas.analysis.kinds.analyze_file`) and, per group, the fitted
  quantity (tau0 of the fixed-exponent law for cooling runs, Z for elastic ones),
  the final temperature and T / T_theory, each as mean +- standard error over the
  seeds, beside the kinetic theory's value (``granulargas analyze DIR``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from granulargas.analysis.cooling import fit_cooling_law
from granulargas.analysis.kinds import analyze_file
from granulargas.io.h5md import read_observables
from granulargas.io.sweep_index import read_index

SEED_KEY = "system.seed"


def _order_key(v):
    """Sort numbers numerically and anything else by its text."""
    return (0, float(v), "") if isinstance(v, (int, float)) and not isinstance(v, bool) else (1, 0.0, str(v))


@dataclass(frozen=True)
class EnsembleHistory:
    """Temperature history of one parameter group, over its seeds."""

    parameters: dict  # the group's varied parameters (seed excluded)
    files: tuple[str, ...]
    time: np.ndarray  # (S,)
    temperatures: np.ndarray  # (n_seeds, S)

    @property
    def mean(self) -> np.ndarray:
        return self.temperatures.mean(axis=0)

    @property
    def stderr(self) -> np.ndarray:
        n = self.temperatures.shape[0]
        if n < 2:
            return np.full(self.time.shape, np.nan)
        return self.temperatures.std(axis=0, ddof=1) / np.sqrt(n)


@dataclass(frozen=True)
class ParameterScan:
    """A fitted quantity against one varied parameter (mean +- stderr over seeds)."""

    parameter: str
    values: np.ndarray
    mean: np.ndarray
    stderr: np.ndarray
    seeds: np.ndarray  # runs per point


def _mean_err(values):
    """(mean, standard error of the mean) over seeds; error nan for a single value."""
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if v.size == 0:
        return math.nan, math.nan
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(v.size)) if v.size > 1 else math.nan


@dataclass(frozen=True)
class GroupSummary:
    """One parameter set of a sweep over its seeds (:meth:`SweepResults.summaries`).

    ``quantity`` is the fitted quantity: ``"tau0"`` (fixed-exponent cooling law) for
    cooling runs, ``"Z"`` for elastic ones; ``value``/``error`` its mean and standard
    error over seeds, ``theory`` the kinetic theory's value (the same fit applied
    to the theory curve, or the equation of state). ``ratio_time``/``ratio_mean``/
    ``ratio_error`` hold T / T_theory against time over the seeds (empty if the
    members' sample times differ).
    """

    parameters: dict
    files: tuple
    kind: str
    theory_name: str
    quantity: str
    value: float
    error: float
    theory: float
    T_final: float
    T_final_error: float
    T_theory_final: float
    T_ratio_final: float
    T_ratio_final_error: float
    ratio_time: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))
    ratio_mean: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))
    ratio_error: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))

    @property
    def seeds(self) -> int:
        return len(self.files)

    def as_dict(self) -> dict:
        """JSON-ready (non-finite numbers -> None)."""
        out = {"parameters": self.parameters, "seeds": self.seeds, "files": list(self.files), "kind": self.kind,
               "theory": self.theory_name, "quantity": self.quantity}
        for key, name in (("value", "value"), ("error", "error"), ("theory", "theory_value"), ("T_final", "T_final"),
                          ("T_final_error", "T_final_error"), ("T_theory_final", "T_theory_final"),
                          ("T_ratio_final", "T_ratio_final"), ("T_ratio_final_error", "T_ratio_final_error")):
            v = getattr(self, key)
            out[name] = float(v) if v is not None and math.isfinite(v) else None
        return out


class SweepResults:
    """The finished runs of a sweep, grouped by parameters other than the seed.

    Parameters
    ----------
    index : path
        ``index.json`` or the sweep's output directory.
    """

    def __init__(self, index):
        path = Path(index)
        data = read_index(path)
        self.path = path if path.is_dir() else path.parent
        self.runs = [e for e in data["runs"] if e.get("status") == "done"]
        self.failed = [e for e in data["runs"] if e.get("status") != "done"]
        keys = set()
        for entry in data["runs"]:
            keys.update(entry["parameters"])
        self.varied = sorted(keys - {SEED_KEY})
        self.seeded = SEED_KEY in keys

    def __repr__(self):
        groups = self.groups()
        values = ", ".join(f"{k} ({len({e['parameters'].get(k) for e in self.runs})} values)" for k in self.varied)
        seeds = len({e["parameters"].get(SEED_KEY) for e in self.runs}) if self.seeded else 1
        return (f"SweepResults('{self.path}': {len(self.runs)} runs done, {len(self.failed)} not done; "
                f"{len(groups)} parameter sets" + (f" varying {values}" if values else "")
                + f"; {seeds} seed{'s' if seeds != 1 else ''} each)")

    def summaries(self, t_range=None) -> list[GroupSummary]:
        """Every finished run analysed by its kind's analysis, summarised per group (class doc).

        Groups are ordered by their parameter values.
        """
        out = []
        for key, entries in sorted(self.groups().items(), key=lambda kv: tuple(_order_key(v) for v in kv[0])):
            analyses = [analyze_file(e["file"], t_range=t_range, with_sonine=False) for e in entries]
            sums = [a.summary() for a in analyses]
            kind = analyses[0].kind
            if kind == "cooling":
                quantity, value, theory_value = "tau0", [s["tau0_fit"] for s in sums], [s["tau0_theory"] for s in sums]
            else:
                quantity, value, theory_value = "Z", [s["Z"] for s in sums], [s["Z_theory"] for s in sums]
            v, v_err = _mean_err(value)
            T, T_err = _mean_err([s["T_final"] for s in sums])
            r, r_err = _mean_err([s["T_ratio_final"] for s in sums])
            times = [a.time for a in analyses]
            ratio_t = ratio_m = ratio_e = np.empty(0)
            if kind == "cooling" and all(t.shape == times[0].shape and np.allclose(t, times[0]) for t in times):
                ratios = np.vstack([a.ratio for a in analyses])
                ratio_t, ratio_m = times[0], ratios.mean(axis=0)
                ratio_e = (ratios.std(axis=0, ddof=1) / math.sqrt(len(analyses)) if len(analyses) > 1
                           else np.full(ratio_t.shape, np.nan))
            out.append(GroupSummary(
                parameters=dict(zip(self.varied, key)), files=tuple(e["file"] for e in entries), kind=kind,
                theory_name=analyses[0].theory_name, quantity=quantity, value=v, error=v_err,
                theory=_mean_err(theory_value)[0], T_final=T, T_final_error=T_err,
                T_theory_final=_mean_err([s["T_theory_final"] for s in sums])[0],
                T_ratio_final=r, T_ratio_final_error=r_err, ratio_time=ratio_t, ratio_mean=ratio_m,
                ratio_error=ratio_e))
        return out

    def groups(self) -> dict[tuple, list[dict]]:
        """``{(value, ...) in order of self.varied: [entries]}``."""
        out: dict[tuple, list[dict]] = {}
        for entry in self.runs:
            key = tuple(entry["parameters"].get(k) for k in self.varied)
            out.setdefault(key, []).append(entry)
        return out

    def temperature(self) -> list[EnsembleHistory]:
        """Mean and spread of T(t) over seeds, one history per group."""
        histories = []
        for key, entries in self.groups().items():
            time = None
            rows = []
            for entry in entries:
                _, t, T = read_observables(entry["file"])["temperature"]
                if time is None:
                    time = t
                elif t.shape != time.shape or not np.array_equal(t, time):
                    raise ValueError(
                        f"{entry['file']}: its observables times differ from {entries[0]['file']}; "
                        "members of a group must share the output schedule"
                    )
                rows.append(T)
            histories.append(
                EnsembleHistory(
                    parameters=dict(zip(self.varied, key)),
                    files=tuple(e["file"] for e in entries),
                    time=np.asarray(time),
                    temperatures=np.vstack(rows),
                )
            )
        return histories

    def tau0_scan(self, parameter: str, exponent: float | None = 2.0, t_range=None) -> ParameterScan:
        """Fitted tau0 of ``T0 (1 + t/tau0)^(-exponent)`` against ``parameter``.

        Each seed is fitted on its own; the point is the mean over seeds with the
        standard error of that mean. Other varied parameters must be fixed (one
        group per value of ``parameter``).
        """
        if parameter not in self.varied:
            raise ValueError(f"{parameter!r} is not varied in this sweep (varied: {self.varied})")
        histories = self.temperature()
        values = [h.parameters[parameter] for h in histories]
        if len(set(values)) != len(values):
            raise ValueError(f"more than one group per value of {parameter!r}: fix the other parameters first")
        order = np.argsort(values)
        means, errs, counts = [], [], []
        for i in order:
            h = histories[i]
            tau0 = np.array([fit_cooling_law(h.time, T, exponent=exponent, t_range=t_range).tau0 for T in h.temperatures])
            means.append(tau0.mean())
            errs.append(tau0.std(ddof=1) / np.sqrt(tau0.size) if tau0.size > 1 else np.nan)
            counts.append(tau0.size)
        return ParameterScan(
            parameter=parameter,
            values=np.asarray(values, dtype=float)[order],
            mean=np.asarray(means),
            stderr=np.asarray(errs),
            seeds=np.asarray(counts),
        )
