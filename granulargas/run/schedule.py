"""The output schedule of a run: when to sample observables and write snapshots.

The schedule is a pure function of the config, never of the start time, so a
run to 2t and a run to t followed by a restart to 2t synchronise the engine at
the same times (restart equality). Targets are times (``run.end_time`` set) or
total pair-collision counts (``run.collisions_per_particle`` alone).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas import theory
from granulargas.io.config import RunConfig
from granulargas.run.prepare import DEFAULT_OBSERVABLE_SAMPLES, mean_particle

__all__ = ["DEFAULT_OBSERVABLE_SAMPLES", "Schedule", "collision_budget", "mean_free_time", "output_schedule"]


@dataclass(frozen=True)
class Schedule:
    """Output targets. ``clock`` is "time" or "collisions" (targets are then
    total collision counts); ``snapshot[k]`` tells whether target k is also a
    snapshot (every target samples the observables)."""

    clock: str
    targets: np.ndarray
    snapshot: np.ndarray


def mean_free_time(config: RunConfig) -> float:
    """Enskog estimate of the mean time between collisions of a particle at the
    initial temperature (:func:`granulargas.theory.collision_frequency`), with the
    mean diameter and its mass (:func:`granulargas.run.prepare.mean_particle`).

    chi is the closed form (Carnahan-Starling, Henderson), fixed: the schedule only
    needs an estimate, and its output times must not move when the theory's chi is
    refined, because a run resynchronises at every snapshot and so its trajectory
    depends on the snapshot times."""
    d = config.system.dimension
    sigma, mass = mean_particle(config)
    eta = config.system.packing_fraction
    n = theory.number_density(eta, d, sigma)
    chi = theory.contact_value(eta, d, "closed")
    return 1.0 / float(theory.collision_frequency(n, config.initial.temperature, d, sigma, mass, chi=chi))


def collision_budget(config: RunConfig) -> int:
    """Pair collisions for ``run.collisions_per_particle``: each collision counts
    for both partners (the kinetic-theory s = 2 C / N), so C = s N / 2."""
    return max(1, int(round(0.5 * config.run.collisions_per_particle * config.system.particles)))


def _even(interval: float, end: float) -> np.ndarray:
    """Multiples of ``interval`` up to ``end``, and ``end`` itself (exactly, last).

    A multiple within round-off of ``end`` (27.5 / 200 * 200 = 27.500000000000004)
    is dropped: ``end`` closes the list, so no target lies past it.
    """
    k = np.arange(1, int(math.floor(end / interval * (1 + 1e-12))) + 1)
    t = k * interval
    return np.append(t[t < end * (1 - 1e-12)], end)


def output_schedule(config: RunConfig) -> Schedule:
    """The output schedule of a config (start time 0; a restart skips the
    targets at or before its start)."""
    out, run = config.output, config.run
    nsnap = out.snapshot_count
    if run.end_time is not None:
        end = run.end_time
        if out.snapshot_interval is not None:
            snaps = _even(out.snapshot_interval, end)
        elif nsnap <= 2:
            snaps = np.array([end])
        else:
            first = out.first_snapshot if out.first_snapshot is not None else mean_free_time(config)
            if first >= end:
                snaps = np.linspace(0.0, end, nsnap)[1:]
            else:
                snaps = np.geomspace(first, end, nsnap - 1)
        obs_dt = out.observables_interval or end / DEFAULT_OBSERVABLE_SAMPLES
        obs = _even(obs_dt, end)
        clock = "time"
    else:
        total = collision_budget(config)
        n = max(1, config.system.particles // 2)  # one collision per particle
        if nsnap <= 2:
            snaps = np.array([total])
        elif total <= n:
            snaps = np.unique(np.linspace(0, total, nsnap).round().astype(np.int64)[1:])
        else:
            snaps = np.unique(np.geomspace(n, total, nsnap - 1).round().astype(np.int64))
        obs = np.unique(np.linspace(0, total, DEFAULT_OBSERVABLE_SAMPLES + 1).round().astype(np.int64)[1:])
        clock = "collisions"
    targets = np.union1d(snaps, obs)
    targets = targets[targets > 0]
    snapshot = np.isin(targets, snaps)
    return Schedule(clock, targets, snapshot)
