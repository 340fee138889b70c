"""The output schedule of a run: when to sample observables and write snapshots.

The schedule is a pure function of the config, never of the start time, so a
run to 2t and a run to t followed by a restart to 2t synchronise the engine at
the same times (restart equality). Targets are times (``run.end_time`` set) or
total pair-collision counts (``run.collisions_per_particle`` alone).
"""

from __future__ import annotations

import math
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from granulargas import theory
from granulargas.errors import ConfigError
from granulargas.io.config import RunConfig
from granulargas.run.prepare import DEFAULT_OBSERVABLE_SAMPLES, mean_particle
from granulargas.run.resources import available_memory, format_bytes

#: memory of the schedule per output time (the arrays output_schedule builds and merges)
SCHEDULE_BYTES_PER_TARGET = 64.0


@dataclass(frozen=True)
class Schedule:
    """Output targets. ``clock`` is "time" or "collisions" (targets are then
    total collision counts); ``snapshot[k]`` tells whether target k is also a
    snapshot; ``sample[k]`` whether the observables are sampled there (False for
    the engine's pacing stops, :func:`pacing_stops`)."""

    clock: str
    targets: np.ndarray
    snapshot: np.ndarray
    sample: np.ndarray | None = None

    def __post_init__(self):
        if self.sample is None:
            object.__setattr__(self, "sample", np.ones(len(self.targets), dtype=bool))


#: significant digits of computed output times (the mean free time, log-spaced snapshots)
TIME_DIGITS = 9


def rounded_time(t: float) -> float:
    """``t`` rounded to ``TIME_DIGITS`` significant digits.

    The engine resynchronises at every snapshot, so a trajectory depends on the last
    bits of the snapshot times, and those of a computed time (``np.geomspace``'s
    ``power``, the powers in the mean free time) can differ between numpy's SIMD kernels
    (AVX-512 or not) and between C libraries. Rounded to 9 digits, the times are the
    same on every machine unless the exact time lies within ~1e-15 of a rounding
    boundary."""
    return float(f"{t:.{TIME_DIGITS}g}")


def mean_free_time(config: RunConfig) -> float:
    """Enskog estimate of the mean time between collisions of a particle at the
    initial temperature (:func:`granulargas.theory.collision_frequency`), with the
    mean diameter and its mass (:func:`granulargas.run.prepare.mean_particle`).

    chi is the closed form (Carnahan-Starling, Henderson), fixed: the schedule only
    needs an estimate, and its output times must not move when the theory's chi is
    refined, because a run resynchronises at every snapshot and so its trajectory
    depends on the snapshot times. For the same reason it is rounded to ``TIME_DIGITS``
    significant digits (:func:`rounded_time`)."""
    d = config.system.dimension
    sigma, mass = mean_particle(config)
    eta = config.system.packing_fraction
    n = theory.number_density(eta, d, sigma)
    chi = theory.contact_value(eta, d, "closed")
    return rounded_time(1.0 / float(theory.collision_frequency(n, config.initial.temperature, d, sigma, mass, chi=chi)))


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


def log_spaced(first: float, end: float, count: int) -> np.ndarray:
    """``count`` times from ``first`` to ``end`` (both exactly) equally spaced in log t,
    those between rounded by :func:`rounded_time`."""
    t = np.geomspace(first, end, count)
    return np.array([float(first)] + [rounded_time(x) for x in t[1:-1]] + [float(end)])[:count]


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
                snaps = log_spaced(first, end, nsnap - 1)
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
    outputs = np.union1d(snaps, obs)
    targets = np.union1d(outputs, pacing_stops(config)) if clock == "time" else outputs
    targets = targets[targets > 0]
    snapshot = np.isin(targets, snaps)
    sample = np.isin(targets, outputs)
    return Schedule(clock, targets, snapshot, sample)


def pacing_stops(config: RunConfig) -> np.ndarray:
    """Times t_free 2^k (k = 0, 1, ...) below ``run.end_time``, t_free the Enskog mean free
    time at T0: the engine stops there without output.

    At the start of each ``run`` call the engine matches its event calendar to the
    current event rate; a gas cooling by many orders of magnitude within one call (Haff
    cooling over 1e20 mean free times) would leave the calendar's window far too
    narrow, and its scan for the next event would stall the compiled loop. Between
    stops a factor 2 apart in time, a cooling gas's event rate changes by a factor 4
    at most. The stops depend on the config only (never on the start time), so a
    restart makes the same calls as the uninterrupted run."""
    first, end = mean_free_time(config), config.run.end_time
    if not (first > 0 and math.isfinite(first)) or end is None or first >= end:
        return np.empty(0)
    count = int(math.floor(math.log2(end / first))) + 1
    return np.ldexp(first, np.arange(count, dtype=np.intc))  # exact, as exp2 need not be


def output_counts(config: RunConfig) -> tuple[float, float]:
    """(snapshots, observables-only samples) of the config's schedule, counted without
    building it (floats: inf or astronomically large counts are possible)."""
    out, run = config.output, config.run
    if run.end_time is not None:
        end = run.end_time
        snaps = end / out.snapshot_interval + 1 if out.snapshot_interval is not None else float(out.snapshot_count)
        samples = end / out.observables_interval + 1 if out.observables_interval is not None else float(
            DEFAULT_OBSERVABLE_SAMPLES + 1)
        return snaps, samples
    return float(out.snapshot_count), float(DEFAULT_OBSERVABLE_SAMPLES + 1)


def frame_columns(config: RunConfig) -> int:
    """Float64/int64 values stored per particle in one snapshot of the run's H5MD file.

    Event-driven runs: position, velocity and image (3 d), plus the last collision
    times of the TC model (1) or the contacts under way of collisions that take time
    (2: ``contact_until``, ``contact_partner``). DSMC runs store velocities only (d).
    """
    d = config.system.dimension
    if config.run.method == "dsmc":
        return d
    c = config.collision
    extra = 1 if c.model == "constant" and c.tc_time is not None else 0
    return 3 * d + extra + (2 if c.duration == "resolved" else 0)


def check_output_size(config: RunConfig, n: int | None = None, *, available: float | None = None,
                      free_disk: float | None = None) -> tuple[float, float]:
    """Refuse a schedule that does not fit in memory, or an output file that does not fit
    on its disk (one line naming the key), before :func:`output_schedule` allocates it.

    Memory: 64 B per output time (the arrays the schedule builds and merges). Disk:
    8 B per particle, frame and stored column (:func:`frame_columns`), 8 (8 + d) B per
    observables sample. Returns (schedule bytes, file bytes)."""
    s, out = config.system, config.output
    n = s.particles if n is None else int(n)
    d = s.dimension
    snaps, obs = output_counts(config)
    samples = snaps + obs
    if obs > snaps:
        key, value = "output.observables_interval", out.observables_interval
    elif out.snapshot_interval is not None:
        key, value = "output.snapshot_interval", out.snapshot_interval
    else:
        key, value = "output.snapshots", out.snapshot_count
    schedule = SCHEDULE_BYTES_PER_TARGET * samples
    if available is None:
        available = available_memory()
    src = config.source
    if not math.isfinite(samples) or (available is not None and schedule > available):
        raise ConfigError(f"{src}: {key} = {value!r}: {samples:.3g} output times; the schedule alone needs "
                          f"{format_bytes(schedule)} of memory, {format_bytes(available) if available is not None else 'an unknown amount'} are available")
    frame = n * 8.0 * frame_columns(config)
    file_bytes = snaps * frame + samples * 8.0 * (8 + d) + n * 24.0
    if free_disk is None:
        directory = Path(out.file).parent
        try:
            free_disk = float(shutil.disk_usage(directory if str(directory) else ".").free)
        except OSError:
            free_disk = None
    if free_disk is not None and file_bytes > free_disk:
        raise ConfigError(f"{src}: {key} = {value!r}: the output file would need about {format_bytes(file_bytes)} "
                          f"({snaps:.6g} snapshots of {format_bytes(frame)}), the disk holding "
                          f"{Path(out.file).parent or Path('.')} has {format_bytes(free_disk)} free")
    return schedule, file_bytes
