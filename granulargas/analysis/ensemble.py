"""Aggregating a sweep: averages over seeds and parameter scans.

A sweep (:mod:`granulargas.run.sweep`) leaves ``index.json`` beside its H5MD files,
one entry per run with its varied parameters. This module groups the finished
runs by every varied parameter except the seed, and for each group gives

* the ensemble temperature history: mean and standard error of T(t) over seeds
  (every member of a group shares its observables schedule, so the samples line
  up; a member whose times differ is rejected rather than interpolated);
* a cooling-law fit per seed (:func:`granulargas.analysis.cooling.fit_cooling_law`)
  and the mean and standard error of the fitted tau0 over seeds, e.g. tau0
  against the restitution for a Haff-law scan.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from granulargas.analysis.cooling import fit_cooling_law
from granulargas.io.h5md import read_observables
from granulargas.io.sweep_index import read_index

SEED_KEY = "system.seed"


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
        self.runs = [e for e in data["runs"] if e.get("status") == "done"]
        self.failed = [e for e in data["runs"] if e.get("status") != "done"]
        keys = set()
        for entry in data["runs"]:
            keys.update(entry["parameters"])
        self.varied = sorted(keys - {SEED_KEY})

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
