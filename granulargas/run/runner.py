"""The run loop: progress bar, H5MD writing and the summary.

Order of operations of :func:`run_config` (everything before the output file
is created can fail without leaving a file)::

    check the output path (exists without overwrite? same as the restart file?)
    setup = run.prepare.prepare(config)       # rule, table, initial state
    sim = Simulation(...); sim.run(until=start)   # JIT compile / queue build, untimed
    writer = H5MDWriter(...)                     # the file exists from here on
    sample observables and write a snapshot at the start time
    for each output target (time, or collision count without run.end_time):
        sim.run(until=target, max_collisions=budget)   # compiled chunks
        sample observables (pressure: mean over the interval just ended)
        if snapshot target: sim.synchronise(); write the frame; flush
    write the summary into parameters/

The schedule (:mod:`granulargas.run.schedule`) is a pure function of the config (never of the start time), so a
run to 2t and a run to t followed by a restart to 2t synchronise at the same
times and do the same arithmetic (restart equality; the engine rebuilds its
queue from the synchronised state).
"""

from __future__ import annotations

import math
import os
import sys
import time as _time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tqdm import tqdm

from granulargas.engine import Simulation
from granulargas.errors import ConfigError, InputFileError, SimulationError
from granulargas.io.config import RunConfig
from granulargas.io.h5md import H5MDWriter
from granulargas.run.prepare import prepare
from granulargas.run.schedule import (  # noqa: F401  (re-exported: the runner's public names)
    DEFAULT_OBSERVABLE_SAMPLES,
    Schedule,
    collision_budget,
    mean_free_time,
    output_schedule,
)


@dataclass(frozen=True)
class RunSummary:
    """What a finished run reports (also written to ``parameters/summary``)."""

    output: Path
    collisions: int
    events: int
    time: float
    wall_time: float
    collisions_per_second: float
    final_temperature: float
    snapshots: int
    stop_reason: str
    particles: int = 0
    warnings: tuple = field(default_factory=tuple)
    startup_time: float = 0.0

    def lines(self) -> list[str]:
        per = 2.0 * self.collisions / self.particles if self.particles else float("nan")
        return [
            f"collisions   {self.collisions} ({per:.4g} per particle), {self.events} events",
            f"time         {self.time:.6g} (stopped by {self.stop_reason})",
            f"wall time    {self.wall_time:.3g} s ({self.collisions_per_second:.4g} collisions/s)"
            f" + {self.startup_time:.3g} s start-up (JIT compile or cache load, queue build)",
            f"temperature  {self.final_temperature:.6g} (final)",
            f"output       {self.output} ({self.snapshots} snapshots)",
        ]


# --------------------------------------------------------------------- progress


class _Progress:
    """tqdm bar over simulated time (or collisions): time, collisions, rate, ETA."""

    def __init__(self, total: float, clock: str, start: float, sim):
        self.clock = clock
        self.wall0 = _time.perf_counter()
        self.c0 = sim.collisions
        self.bar = tqdm(
            total=float(total),
            initial=float(start),
            unit="" if clock == "time" else "coll",
            desc="t" if clock == "time" else "collisions",
            bar_format="{desc} {n:.4g}/{total:.4g} |{bar}| {percentage:3.0f}% [{elapsed}<{remaining}{postfix}]",
            file=sys.stderr,
            dynamic_ncols=True,
            leave=False,
        )

    def __call__(self, sim):
        pos = sim.time if self.clock == "time" else sim.collisions
        self.bar.n = float(pos)
        wall = _time.perf_counter() - self.wall0
        rate = (sim.collisions - self.c0) / wall if wall > 0 else 0.0
        self.bar.set_postfix_str(f"{sim.collisions:.3e} coll, {rate:.3g} coll/s", refresh=False)
        self.bar.refresh()

    def close(self):
        self.bar.close()


def _want_progress(quiet: bool, progress) -> bool:
    if progress is not None and not isinstance(progress, bool):
        return True
    if progress is not None:
        return bool(progress)
    if quiet:
        return False
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


# --------------------------------------------------------------------- the run


def check_output(config: RunConfig, overwrite: bool) -> Path:
    """Refuse an existing output without ``overwrite`` and an output that is the
    restart file; check that the directory can be written. Creates nothing."""
    path = Path(config.output.file)
    where = f"{config.source}: output.file"
    if path.is_dir():
        raise InputFileError(f'{where} = "{path}": is a directory')
    if config.initial.from_file is not None:
        src = Path(config.initial.from_file)
        if src.exists() and path.exists() and src.resolve() == path.resolve():
            raise InputFileError(
                f'{where} = "{path}": is the restart file; write the continuation to another file (--output)'
            )
    if path.exists() and not overwrite:
        raise InputFileError(f'{where} = "{path}": file exists (use --overwrite to replace it)')
    parent = path.parent if str(path.parent) else Path(".")
    probe = parent
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if not probe.is_dir():
        raise InputFileError(f'{where} = "{path}": {probe} is not a directory')
    if not os.access(probe, os.W_OK | os.X_OK):
        raise InputFileError(f'{where} = "{path}": directory {probe} is not writable')
    return path


def _observables(sim, pressure: bool) -> dict:
    out = {
        "temperature": float(sim.temperature),
        "kinetic_energy": float(sim.kinetic_energy),
        "collisions": int(sim.collisions),
        "events": int(sim.events),
        "dissipated_energy": float(sim.dissipated_energy),
        "momentum": np.asarray(sim.momentum, dtype=np.float64),
        "pressure": float(sim.pressure_window()) if pressure else math.nan,
    }
    if "wall" in sim.boundary:
        out["wall_collisions"] = int(sim.wall_collisions)
        out["wall_pressure"] = float(sim.wall_pressure_window()) if pressure else math.nan
    if sim.driving is not None:
        out["injected_energy"] = float(sim.injected_energy)
        out["kick_step"] = int(sim.kick_step)
    return out


def run_config(config: RunConfig, *, overwrite: bool = False, quiet: bool = True, progress=None,
               log=None) -> RunSummary:
    """Run a validated config to the end and write its H5MD file.

    Parameters
    ----------
    config : RunConfig
        From :func:`granulargas.io.config.load_config` (restart: ``initial.from``).
    overwrite : bool
        Replace an existing output file.
    quiet : bool
        No progress bar (the default for scripts and sweeps).
    progress : None, bool or callable
        None: a bar when not quiet and stderr is a terminal; True/False force it;
        a callable ``progress(sim)`` is called between compiled chunks instead.
    log : callable, optional
        Receives one-line warnings (model validity); default: print to stderr.

    Returns
    -------
    RunSummary

    Raises
    ------
    UserError
        Bad input (nothing written) or a run that cannot continue
        (:class:`SimulationError`; the file keeps the snapshots written so far).
    """
    path = check_output(config, overwrite)
    setup = prepare(config)
    for w in setup.warnings:
        (log or _stderr)(w)
    schedule = output_schedule(config)
    st = setup.state
    run = config.run
    if run.end_time is not None and st.time >= run.end_time:
        raise ConfigError(f"{config.source}: run.end_time = {run.end_time:g}: the restart file "
                          f"{st.source} is already at t = {st.time:g}; nothing to run")
    if run.collisions_per_particle is not None and st.collisions >= collision_budget(config):
        raise ConfigError(f"{config.source}: run.collisions_per_particle = {run.collisions_per_particle:g}: the "
                          f"restart file {st.source} already has {st.collisions} collisions; nothing to run")

    sim = Simulation(
        st.positions, st.velocities, st.radii, st.masses, st.box, setup.rule,
        time=st.time, collisions=st.collisions, images=st.images, last_collision=st.last_collision,
        events=st.events, dissipated_energy=st.dissipated_energy, boundary=st.boundary,
        wall_collisions=st.wall_collisions, driving=setup.driving, kick_step=st.kick_step,
        injected_energy=st.injected_energy,
    )
    # a zero-length run compiles (or loads) the engine and builds its queue before
    # the file exists and outside the timed part, so collisions/s measures the
    # event loop; both paths of a restart do it, so restart equality is unaffected
    w = _time.perf_counter()
    sim.run(until=sim.time)
    startup = _time.perf_counter() - w

    start_key = st.time if schedule.clock == "time" else st.collisions
    keep = schedule.targets > start_key
    targets, is_snap = schedule.targets[keep], schedule.snapshot[keep]
    budget = None
    if config.run.collisions_per_particle is not None:
        budget = collision_budget(config)

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputFileError(f'{config.source}: output.file = "{path}": cannot create its directory '
                             f"({exc.strerror or exc})") from None
    tc = setup.rule_name == "constant" and config.collision.tc_time is not None
    writer = H5MDWriter(path, st.box, st.radii, st.masses, st.species, parameters=setup.parameters,
                        last_collision=tc, overwrite=overwrite, boundary=sim.boundary,
                        driven=sim.driving is not None)

    show = _want_progress(quiet, progress)
    bar = None
    callback = None
    if show:
        if callable(progress) and not isinstance(progress, bool):
            callback = progress
        else:
            total = targets[-1] if len(targets) else start_key
            bar = _Progress(total, schedule.clock, start_key, sim)
            callback = bar

    def snapshot():
        sim.synchronise()
        lc = np.asarray(sim.last_collision) if tc else None
        writer.write_snapshot(sim.events, sim.time, sim.positions, sim.velocities, sim.images, lc)

    wall0 = _time.perf_counter()
    c0 = sim.collisions
    stop_reason = "end_time" if schedule.clock == "time" else "collisions_per_particle"
    try:
        writer.write_observables(sim.events, sim.time, _observables(sim, False), flush=False)
        snapshot()
        for target, snap in zip(targets, is_snap):
            if schedule.clock == "time":
                left = None if budget is None else budget - sim.collisions
                sim.run(until=float(target), max_collisions=left, progress=callback)
                hit_budget = budget is not None and sim.collisions >= budget and sim.time < target
            else:
                sim.run(until=math.inf, max_collisions=int(target) - sim.collisions, progress=callback)
                hit_budget = False
            writer.write_observables(sim.events, sim.time, _observables(sim, True), flush=False)
            if snap or hit_budget:
                snapshot()
            if callback is not None:
                callback(sim)
            if hit_budget:
                stop_reason = "collisions_per_particle"
                break
    except BaseException as exc:
        reason = "interrupted" if isinstance(exc, KeyboardInterrupt) else f"error: {exc}"
        try:
            writer.set_parameters({"summary": {"stop_reason": reason, "time": float(sim.time),
                                               "collisions": int(sim.collisions)}})
            kept = writer.frames
        finally:
            writer.close()
            if bar is not None:
                bar.close()
        if isinstance(exc, SimulationError) and type(exc).__init__ is Exception.__init__:
            raise type(exc)(f"{exc} ({path} keeps {kept} snapshots)") from None
        raise
    wall = _time.perf_counter() - wall0
    done = sim.collisions - c0
    summary = RunSummary(
        output=path,
        collisions=int(sim.collisions),
        events=int(sim.events),
        time=float(sim.time),
        wall_time=wall,
        collisions_per_second=done / wall if wall > 0 else math.nan,
        final_temperature=float(sim.temperature),
        snapshots=writer.frames,
        stop_reason=stop_reason,
        particles=len(st.radii),
        warnings=tuple(setup.warnings),
        startup_time=startup,
    )
    writer.set_parameters({"summary": {
        "stop_reason": stop_reason, "time": summary.time, "collisions": summary.collisions,
        "events": summary.events, "wall_time": wall, "collisions_per_second": summary.collisions_per_second,
        "startup_time": startup,
    }})
    writer.close()
    if bar is not None:
        bar.close()
    return summary


def _stderr(msg: str):
    print(msg, file=sys.stderr)
