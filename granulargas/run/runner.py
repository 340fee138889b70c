"""The run loop: progress bar, H5MD writing, stopping on a signal, and the summary.

Order of operations of :func:`run_config` (everything before the output file
is created or opened can fail without leaving a file or changing one)::

    check the output path (directory exists? exists without overwrite? the restart file?)
    --append: the config keeps the file's physics
    setup = run.prepare.prepare(config)       # memory check, rule, table, initial state
    check the schedule's memory and the output file's size against the disk
    sim = Simulation(...); sim.run(until=start)   # JIT compile / queue build, untimed
    writer = H5MDWriter(...)                     # the file exists from here on
             (--append: H5MDWriter.append, the file cut back to its last frame)
    sample observables and write a snapshot at the start time (not with --append:
    the file holds both)
    for each output target (time, or collision count without run.end_time):
        sim.run(until=target, max_collisions=budget)   # compiled chunks
        sample observables (pressure: mean over the interval just ended)
        if snapshot target: sim.synchronise(); write the frame; flush
    write the summary into parameters/

The schedule (:mod:`granulargas.run.schedule`) is a pure function of the config (never of the start time), so a
run to 2t and a run to t followed by a restart to 2t synchronise at the same
times and do the same arithmetic (restart equality; the engine rebuilds its
queue from the synchronised state). The same holds for a run continued into its
own file (``--append``): the file is then frame for frame the uninterrupted run's.

Signals (:func:`stop_on_signals`, :class:`StopRequest`): SIGINT and SIGTERM set a
request that the runner checks between the engine's compiled chunks (and between
output targets); the run stops at that chunk boundary, where every event up to
the current time is processed, samples the observables, writes the synchronised
state as a last frame listed in ``parameters/interrupted_frames``, closes the file
and raises :class:`RunInterrupted` (exit 130 / 143). ``--restart FILE [--append]``
continues from that frame to the config's absolute end. Such a continuation
synchronises the engine at a time the uninterrupted run does not, so it equals
the run that stops and restarts at that same time bit for bit, and the
uninterrupted run only up to round-off. A run killed outright (SIGKILL) leaves
every frame flushed before.
"""

from __future__ import annotations

import math
import os
import signal
import sys
import time as _time
from contextlib import contextmanager
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from tqdm import tqdm

from granulargas._numba import CompileWatch, announcement
from granulargas.engine import Simulation
from granulargas.errors import ConfigError, InelasticCollapseError, InputFileError, SimulationError, UserError
from granulargas.io.config import RunConfig, parse_config
from granulargas.io.h5md import H5MDWriter, read_parameters, read_text
from granulargas.io.paths import existing_directory, output_file
from granulargas.run.advise import RESOLVED_THREE_BODY_CHECKED
from granulargas.run.dsmc_run import make_dsmc
from granulargas.run.prepare import prepare
from granulargas.run.record import observables as _observables  # one sample, as RunWriter takes it
from granulargas.run.variants import describe, variants_for
from granulargas.run.schedule import (  # noqa: F401  (re-exported: the runner's public names)
    DEFAULT_OBSERVABLE_SAMPLES,
    Schedule,
    check_output_size,
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
    compile_time: float = 0.0  # of the start-up: compiling kernels not yet in numba's cache
    three_body_contacts: int | None = None  # collisions that take time only
    method: str = "edmd"
    candidates: int | None = None  # DSMC: candidate pairs drawn (accepted or not)

    def lines(self) -> list[str]:
        per = 2.0 * self.collisions / self.particles if self.particles else float("nan")
        counts = (f"{self.events} events" if self.candidates is None else
                  f"DSMC, {self.candidates} candidate pairs drawn")
        extra = []
        if self.three_body_contacts is not None:
            share = self.three_body_contacts / self.collisions if self.collisions else 0.0
            note = (f"; more than the {100 * RESOLVED_THREE_BODY_CHECKED:.2g} % met at the longest contacts for which "
                    "the resolved scheme was checked against LAMMPS (scripts/lammps/resolved_collisions.py): use DEM"
                    if share > RESOLVED_THREE_BODY_CHECKED else "")
            extra.append(f"three-body   {self.three_body_contacts} collisions with a pair still in contact "
                         f"({100.0 * share:.3g} % of the collisions{note})")
        return [
            f"collisions   {self.collisions} ({per:.4g} per particle), {counts}", *extra,
            f"time         {self.time:.6g} (stopped by {self.stop_reason})",
            f"wall time    {self.wall_time:.3g} s ({self.collisions_per_second:.4g} collisions/s)"
            f" + {self.startup_time:.3g} s start-up ({self.startup_parts()})",
            f"temperature  {self.final_temperature:.6g} (final)",
            f"output       {self.output} ({self.snapshots} snapshots)",
        ]


    def startup_parts(self) -> str:
        """What the start-up was spent on (initial state, compiling or loading the compiled
        code, the event queue)."""
        if self.compile_time > 0.0:
            return f"{self.compile_time:.3g} s of it compiling, once; initial state, queue build"
        return "initial state, compiled code from the cache, queue build"


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


# --------------------------------------------------------------------- stopping on a signal


class StopRequest:
    """What a signal asks of a run: stop at the next chunk boundary and keep the state.

    :func:`stop_on_signals` installs handlers that call :meth:`request`. Before the
    runner has created its output file (:meth:`arm`) there is nothing to keep and a
    signal raises :class:`Interrupted` at once; afterwards the first signal only sets
    the request, which the runner checks between the engine's compiled chunks, and a
    second one raises at once (the file still holds every frame flushed before).
    """

    def __init__(self):
        self.signum: int | None = None
        self.armed = False

    def request(self, signum, frame=None):  # noqa: ARG002 (signal handler signature)
        if not self.armed or self.signum is not None:
            self.signum = signum
            raise Interrupted(signum)
        self.signum = signum

    def arm(self):
        self.armed = True
        if self.signum is not None:
            raise Interrupted(self.signum)

    def __bool__(self) -> bool:
        return self.signum is not None


class Interrupted(KeyboardInterrupt):
    """A signal stopped the program before there was a state to keep (exit 128 + signal)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = int(signum)


@contextmanager
def stop_on_signals(signals=(signal.SIGINT, signal.SIGTERM)):
    """Handlers for ``signals`` that fill a :class:`StopRequest` (yielded); the previous
    handlers are restored on exit. Outside the main thread nothing is installed."""
    stop = StopRequest()
    previous = {}
    try:
        for signum in signals:
            previous[signum] = signal.signal(signum, stop.request)
    except ValueError:  # not the main thread
        pass
    try:
        yield stop
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


class RunInterrupted(UserError):
    """The run stopped on a signal at a chunk boundary; its state is the file's last frame.

    ``exit_code`` is 128 + the signal number (130 for SIGINT, 143 for SIGTERM)."""

    prefix = "interrupted"

    def __init__(self, message: str, *, signum: int, time: float, collisions: int, output: Path):
        super().__init__(message)
        self.signum, self.time, self.collisions, self.output = int(signum), time, collisions, output
        self.exit_code = 128 + int(signum)


class _Stop(Exception):
    """Raised between compiled chunks when a stop was requested (never leaves the runner)."""


# --------------------------------------------------------------------- the run


def check_output(config: RunConfig, overwrite: bool, append: bool = False) -> Path:
    """Refuse an output that cannot or must not be written, before anything is created:
    a directory, a directory that does not exist (it is never created: a typo would go
    unnoticed), a directory that cannot be written, an existing file without
    ``overwrite``, the restart file itself (unless ``append``, which needs it)."""
    path = Path(config.output.file)
    where = f'{config.source}: output.file = "{path}"'
    if path.is_dir():
        raise InputFileError(f"{where}: is a directory")
    existing_directory(path, where)
    same = False
    if config.initial.from_file is not None:
        src = Path(config.initial.from_file)
        same = src.exists() and path.exists() and src.resolve() == path.resolve()
    if append:
        if config.initial.from_file is None:
            raise InputFileError(f"{where}: --append continues a run into its own file: give --restart FILE")
        if not same:
            raise InputFileError(f'{where}: --append writes into the restart file "{config.initial.from_file}"; '
                                 "drop --output (or give the same file)")
        if not os.access(path, os.W_OK):
            raise InputFileError(f"{where}: file is not writable")
        return path
    if same:
        raise InputFileError(f"{where}: is the restart file; continue into it with --append, or write the "
                             "continuation to another file (--output)")
    return output_file(path, where, overwrite=overwrite)


#: sections whose values must agree between a file and the config that continues in it
_SAME_PHYSICS = ("system", "particles", "collision")


def check_same_physics(config: RunConfig, path: Path) -> None:
    """A run continued into its own file (``--append``) keeps the physics of the file's
    config (``parameters/config``): same system (except the seed), particles and
    collision rule; one line naming the first key that differs."""
    stored = read_parameters(path).get("config")  # InputFileError names what is wrong with the file
    try:
        old = parse_config(stored, source=str(path)) if isinstance(stored, str) else None
    except ConfigError:
        old = None
    if old is None:
        raise InputFileError(f"{path}: parameters/config is missing or not a valid config; --append needs the "
                             "file's config")
    for name in ("driving", "gravity", "walls"):
        if (getattr(config, name) is None) != (getattr(old, name) is None):
            given = f"has no [{name}]" if getattr(config, name) is None else f"has [{name}]"
            raise ConfigError(f"{config.source}: {given}, but the file {path} was run "
                              f"{'with' if getattr(old, name) is not None else 'without'} it; --append continues the "
                              "same physics (write a new file with --output instead)")
    for name in ("gravity", "walls"):
        if getattr(config, name) != getattr(old, name):
            raise ConfigError(f"{config.source}: [{name}] differs from the one the file {path} was run with; --append "
                              "continues the same physics (write a new file with --output instead)")
    for section in _SAME_PHYSICS:
        new_s, old_s = getattr(config, section), getattr(old, section)
        for f in fields(new_s):
            if section == "system" and f.name == "seed":
                continue
            a, b = getattr(new_s, f.name), getattr(old_s, f.name)
            if a != b:
                key = f"{section}.{'from' if f.name == 'from_file' else f.name}"
                raise ConfigError(f"{config.source}: {key} = {_plain(a)}: the file {path} was run with {_plain(b)}; "
                                  "--append continues the same physics (write a new file with --output instead)")


def _plain(v):
    return f'"{v}"' if isinstance(v, str) else ("{...}" if hasattr(v, "__dataclass_fields__") else f"{v}")


def stored_fields(config: RunConfig, sim) -> tuple:
    """The per-frame fields of :data:`granulargas.state.PARTICLE_FIELDS` a run stores besides
    positions, velocities and images: the restart state its model needs
    (:class:`granulargas.io.h5md.H5MDWriter`)."""
    rough = ("angular_velocities",) if config.collision.rough else ()
    if config.run.method == "dsmc":
        return rough
    tc = config.collision.model == "constant" and config.collision.tc_time is not None
    return ((("last_collision",) if tc else ()) + (("contact_until", "contact_partner") if sim.rule.resolved else ())
            + rough)


def collapse_message(config: RunConfig, where: str) -> str:
    """The inelastic-collapse error of a config run: the cure named by the config's keys
    (the TC model's ``collision.tc_time``, with a value that changed T(t) by 0.03 % in the
    collapse demonstration of docs/choosing-a-model.md, or the viscoelastic model)."""
    tc = TC_TIME_FRACTION * mean_free_time(config)
    if config.gravity is not None or config.system.walls:
        speed = ELASTIC_BELOW_FRACTION * math.sqrt(config.initial.temperature / config.particles.mass) \
            if config.particles.mass else ELASTIC_BELOW_FRACTION
        return (f"inelastic collapse {where}: ever faster collisions (a grain coming to rest on a wall, or a "
                f"cluster on a shaken plate, bounces infinitely often in a finite time); set collision.elastic_below "
                f"in {config.source} (collisions below that normal speed are elastic, e.g. elastic_below = "
                f"{speed:.2g}: {ELASTIC_BELOW_FRACTION:g} of the initial thermal speed) or collision.tc_time "
                f"(the TC model)")
    return (f"inelastic collapse {where}: the collision rate diverges; set collision.tc_time in {config.source} "
            f"(the TC model, e.g. tc_time = {tc:.2g}: {TC_TIME_FRACTION:.0e} of the initial mean free time) "
            f"or use collision.model = \"viscoelastic\"")


#: tc_time the collapse error proposes, in mean free times at the initial temperature
TC_TIME_FRACTION = 1e-6
#: elastic_below the collapse error of a scene with walls or gravity proposes, in initial thermal speeds
ELASTIC_BELOW_FRACTION = 1e-3


def run_config(config: RunConfig, *, overwrite: bool = False, quiet: bool = True, progress=None,
               log=None, append: bool = False, stop: StopRequest | None = None) -> RunSummary:
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
    append : bool
        Continue into the restart file itself (``initial.from`` = ``output.file``):
        its datasets are extended, times stay absolute, the physics must be the
        file's (:func:`check_same_physics`).
    stop : StopRequest, optional
        Checked between compiled chunks: when set (by :func:`stop_on_signals`), the run
        stops there, writes the state reached as a final frame marked as interrupted,
        closes the file and raises :class:`RunInterrupted`.

    Returns
    -------
    RunSummary

    Raises
    ------
    UserError
        Bad input (nothing written, nothing changed), a run that cannot continue
        (:class:`SimulationError`; the file keeps the snapshots written so far), or
        :class:`RunInterrupted`.

    Start-up: everything before the first event (initial state, compiling the run's
    kernels the first time such a run is made or loading them from numba's cache, the
    event queue, the first frame) is ``RunSummary.startup_time``. The engine's first
    compilation is announced with one line on ``log`` before it starts (the initial
    placement's, before the config has passed every check, is not: bad input gets one
    line). A compilation during the run itself (a kernel first needed there) counts as
    start-up too, never as run time.
    """
    start = _time.perf_counter()
    what = [describe([v for v in variants_for(config) if v.announced])]
    with CompileWatch(announce=lambda: (log or _stderr)(announcement(what[0])), armed=False) as watch:
        return _run(config, overwrite, quiet, progress, log, append, stop, start, what, watch)


def _run(config, overwrite, quiet, progress, log, append, stop, start, what, watch) -> RunSummary:
    """:func:`run_config` within its :class:`~granulargas._numba.CompileWatch` (``what[0]``: what
    the run compiles, as the announcement names it)."""
    path = check_output(config, overwrite, append)
    if append:
        check_same_physics(config, path)
    setup = prepare(config)  # checks the memory before building anything
    for w in setup.warnings:
        (log or _stderr)(w)
    st = setup.state
    check_output_size(config, len(st.radii))
    schedule = output_schedule(config)
    _check_something_to_run(config, setup, st)

    dsmc = config.run.method == "dsmc"
    watch.armed = True  # from here on a compile is announced (bad input has had its one line)
    sim = _build_simulation(config, setup, st, what)

    start_key = st.time if schedule.clock == "time" else st.collisions
    keep = schedule.targets > start_key
    targets, is_snap, is_sample = schedule.targets[keep], schedule.snapshot[keep], schedule.sample[keep]
    budget = None
    if config.run.collisions_per_particle is not None:
        budget = collision_budget(config)

    resolved = not dsmc and sim.rule.resolved
    writer = _open_writer(config, setup, st, sim, path, append, overwrite, stop)
    bar, callback = _progress_display(quiet, progress, targets, schedule.clock, start_key, sim)

    def between_chunks(sim_):
        if stop:
            raise _Stop
        if callback is not None:
            callback(sim_)

    frame = [(st.events, st.time)]  # (step, time) of the file's last frame

    def snapshot():
        sim.synchronise()
        writer.write_state(sim.state)
        frame[0] = (sim.events, sim.time)

    c0 = sim.collisions
    stop_reason = "end_time" if schedule.clock == "time" else "collisions_per_particle"
    wall0, compiled0 = _time.perf_counter(), watch.seconds
    try:
        if not append:  # a continued file already holds the starting frame and its sample
            writer.write_observables(sim.events, sim.time, _observables(sim, False), flush=False)
            snapshot()
        # the first frame (its observables' and synchronisation's kernels) is start-up too
        wall0, compiled0 = _time.perf_counter(), watch.seconds
        last_sample = (sim.events, sim.time)
        for target, snap, sample in zip(targets, is_snap, is_sample):
            if stop:
                raise _Stop
            if schedule.clock == "time":
                left = None if budget is None else budget - sim.collisions
                sim.run(until=float(target), max_collisions=left, progress=between_chunks)
                hit_budget = budget is not None and sim.collisions >= budget and sim.time < target
            else:
                sim.run(until=math.inf, max_collisions=int(target) - sim.collisions, progress=between_chunks)
                hit_budget = False
            if not (sample or hit_budget):
                continue  # an engine pacing stop (run.schedule.pacing_stops): no output
            writer.write_observables(sim.events, sim.time, _observables(sim, True), flush=False)
            last_sample = (sim.events, sim.time)
            if snap or hit_budget:
                snapshot()
            if callback is not None:
                callback(sim)
            if hit_budget:
                stop_reason = "collisions_per_particle"
                break
    except _Stop:
        raise _close_stopped(stop, sim, writer, bar, path, last_sample, frame[0], snapshot) from None
    except BaseException as exc:
        err = _close_failed(exc, config, sim, writer, bar, path)
        if err is not None:
            raise err from None
        raise
    late = watch.seconds - compiled0  # compiled during the run: start-up, not run time
    wall = _time.perf_counter() - wall0 - late
    summary = RunSummary(
        output=path,
        collisions=int(sim.collisions),
        events=int(sim.events),
        time=float(sim.time),
        wall_time=wall,
        collisions_per_second=(sim.collisions - c0) / wall if wall > 0 else math.nan,
        final_temperature=float(sim.temperature),
        snapshots=writer.frames,
        stop_reason=stop_reason,
        particles=len(st.radii),
        warnings=tuple(setup.warnings),
        startup_time=wall0 - start + late,
        compile_time=watch.seconds,
        three_body_contacts=int(sim.three_body_contacts) if resolved else None,
        method=config.run.method,
        candidates=int(sim.candidates) if dsmc else None,
    )
    _close_finished(writer, bar, summary)
    return summary


def _check_something_to_run(config: RunConfig, setup, st) -> None:
    """A restart that is already at the run's end is bad input (nothing to run)."""
    run = config.run
    if run.end_time is not None and st.time >= run.end_time:
        raise ConfigError(f"{config.source}: run.end_time = {run.end_time:g}: the restart file "
                          f"{setup.source} is already at t = {st.time:g}; nothing to run")
    if run.collisions_per_particle is not None and st.collisions >= collision_budget(config):
        raise ConfigError(f"{config.source}: run.collisions_per_particle = {run.collisions_per_particle:g}: the "
                          f"restart file {setup.source} already has {st.collisions} collisions; nothing to run")


def _build_simulation(config: RunConfig, setup, st, what):
    """The engine or the DSMC of the run, compiled (or loaded) and with its queue built, before the
    file exists and outside the timed part (so that collisions/s measures the event loop; both
    paths of a restart do it, so restart equality is unaffected). ``what[0]`` becomes what the
    engine compiles for the neighbour mode it chose ("auto" at the state's packing)."""
    if config.run.method == "dsmc":
        sim = make_dsmc(config, setup)
    else:
        sim = Simulation(st, setup.rule, driving=setup.driving, neighbours=config.run.neighbours,
                         shear=setup.shear, stress=_stress(setup), gravity=setup.gravity, walls=setup.walls,
                         tangential=setup.tangential)
        what[0] = describe([v for v in variants_for(config, sim.neighbours) if v.announced])
    sim.run(until=sim.time)
    return sim


def _open_writer(config: RunConfig, setup, st, sim, path, append: bool, overwrite: bool, stop) -> H5MDWriter:
    """The run's H5MD file, new or continued; from here on a stop request keeps the state reached.
    A failure to arm the stop leaves no new file behind."""
    fields = stored_fields(config, sim)
    if append:
        writer = H5MDWriter.append(path, st, fields=fields)
        writer.set_parameters(_continuation_record(writer, config, setup, st))
    else:
        writer = H5MDWriter(path, st, fields=fields, parameters=setup.parameters, overwrite=overwrite,
                            driven=sim.driving is not None or (setup.shear is not None and setup.shear.thermostat),
                            gravity=setup.gravity is not None,
                            wall_kinds=setup.walls is not None and setup.walls.moving,
                            tensor=(config.run.method != "dsmc" and _stress(setup)) or setup.shear is not None,
                            species=setup.rule.species)
    try:
        if stop is not None:
            stop.arm()
    except BaseException:
        writer.close()
        if not append:
            path.unlink(missing_ok=True)
        raise
    return writer


def _progress_display(quiet: bool, progress, targets, clock: str, start_key, sim):
    """(bar or None, callback or None): what runs between compiled chunks to show progress."""
    if not _want_progress(quiet, progress):
        return None, None
    if callable(progress) and not isinstance(progress, bool):
        return None, progress
    bar = _Progress(targets[-1] if len(targets) else start_key, clock, start_key, sim)
    return bar, bar


def _close_stopped(stop, sim, writer, bar, path, last_sample, last_frame, snapshot) -> RunInterrupted:
    """A stop request: the state at the last chunk boundary (every event up to ``sim.time``
    processed) becomes the file's last sample and frame, marked as interrupted; the file is
    closed. Returns the :class:`RunInterrupted` to raise."""
    name = signal.Signals(stop.signum).name
    try:
        if (sim.events, sim.time) != last_sample:  # the stop may fall right after a sample
            writer.write_observables(sim.events, sim.time, _observables(sim, True), flush=False)
        if (sim.events, sim.time) != last_frame:  # ... or right after a scheduled frame
            snapshot()
        writer.mark_interrupted(f"stopped by {name} at t = {sim.time!r}")
        writer.set_parameters({"summary": {"stop_reason": f"interrupted by {name}", "time": float(sim.time),
                                           "collisions": int(sim.collisions), "events": int(sim.events)}})
    finally:
        writer.close()
        if bar is not None:
            bar.close()
    return RunInterrupted(
        f"{name} at t = {sim.time:.6g} ({sim.collisions} collisions); {path} keeps the state reached as its "
        "last frame", signum=stop.signum, time=float(sim.time), collisions=int(sim.collisions), output=path)


def _close_failed(exc: BaseException, config: RunConfig, sim, writer, bar, path) -> BaseException | None:
    """A run that cannot go on: the file records why and closes with the frames written so far.
    Returns the error to raise in place of ``exc`` (its message names what the file keeps), or
    None to re-raise ``exc`` itself."""
    reason = "interrupted" if isinstance(exc, KeyboardInterrupt) else f"error: {exc}"
    try:
        writer.set_parameters({"summary": {"stop_reason": reason, "time": float(sim.time),
                                           "collisions": int(sim.collisions)}})
        kept = writer.frames
    finally:
        writer.close()
        if bar is not None:
            bar.close()
    if isinstance(exc, InelasticCollapseError):
        return InelasticCollapseError(f"{collapse_message(config, exc.where)} ({path} keeps {kept} snapshots)",
                                      where=exc.where)
    if isinstance(exc, SimulationError) and type(exc).__init__ is Exception.__init__:
        return type(exc)(f"{exc} ({path} keeps {kept} snapshots)")
    if isinstance(exc, KeyboardInterrupt):  # a second signal: stopped at once
        signum = getattr(exc, "signum", signal.SIGINT)
        return RunInterrupted(
            f"{signal.Signals(signum).name} again: stopped at once at t = {sim.time:.6g}; {path} keeps the "
            f"{kept} frames flushed before", signum=signum, time=float(sim.time), collisions=int(sim.collisions),
            output=path)
    return None


def _close_finished(writer, bar, summary: RunSummary) -> None:
    """The run's summary into the file's parameters; the file and the progress bar closed."""
    writer.set_parameters({"summary": {
        "stop_reason": summary.stop_reason, "time": summary.time, "collisions": summary.collisions,
        "events": summary.events, "wall_time": summary.wall_time,
        "collisions_per_second": summary.collisions_per_second, "startup_time": summary.startup_time,
        "compile_time": summary.compile_time,
        **({"three_body_contacts": summary.three_body_contacts} if summary.three_body_contacts is not None else {}),
    }})
    writer.close()
    if bar is not None:
        bar.close()


def _stress(setup) -> bool:
    """Whether a config run keeps the pressure tensor's sums: smooth particles, no gravity and
    no thermal or vibrating walls (the engine's stress sums follow straight flights and hard
    walls only)."""
    return (setup.tangential is None and setup.gravity is None
            and not (setup.walls is not None and setup.walls.moving))


def _continuation_record(writer, config: RunConfig, setup, st) -> dict:
    """``parameters/`` entries of a run continued into its file: the new resolved config
    (``config``) and, under ``continuations/<k>``, where it started and the config it replaced."""
    g = writer.file["parameters"]
    k = len(g["continuations"]) if "continuations" in g else 0
    previous = read_text(g["config"]) if "config" in g else ""
    return {
        "config": setup.parameters["config"],
        "config_source": setup.parameters["config_source"],
        "continuations": {f"{k:04d}": {
            "time": float(st.time), "step": int(st.events), "collisions": int(st.collisions),
            "frame": writer.frames - 1, "version": setup.parameters["version"],
            "config_file": setup.parameters["config_file"], "previous_config": previous,
        }},
    }


def _stderr(msg: str):
    print(msg, file=sys.stderr)
