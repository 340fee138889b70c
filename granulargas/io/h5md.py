"""H5MD 1.1 output (de Buyl, Colberg & Höfling, Comput. Phys. Commun. 185, 1546 (2014)).

Layout written by :class:`H5MDWriter` (N particles, d dimensions, F frames)::

    h5md/                      attrs version = [1, 1]
        author/                attrs name
        creator/               attrs name = "granulargas", version
    particles/all/
        box/                   attrs dimension = d, boundary = "periodic" or "none" per axis
                               (H5MD), kind = "periodic", "wall" or "lees-edwards" per axis
                               ("none": flat walls at 0 and the edge, H5MD 1.1)
            edges/             step, time -> hard links to position/step, time
                value          (F, d) float64 box edge lengths
        position/  step (F,) int64 (event count), time (F,) float64, value (F, N, d) in [0, L)
        velocity/  step, time (links), value (F, N, d)
        image/     step, time (links), value (F, N, d) int64 periodic image counts (0 on wall axes)
        last_collision/        (TC model only) value (F, N): time of each particle's last collision
        contact_until/         (collisions that take time only) value (F, N) float64: when each
                               particle's contact under way ends (-inf: none)
        contact_partner/       (collisions that take time only) value (F, N) int64: particle id of
                               that contact's partner (-1: none)
        dsmc/                  (DSMC runs only) the random state that continues the run bit for
                               bit: rng (F, 5) uint64, candidates (F,), pending_pair (F, 2),
                               pending_time (F,), frame_velocity (F, d); step, time linked
        mass       (N,) float64         time-independent
        radius     (N,) float64         time-independent, non-standard element
        species    (N,) int32           time-independent
    observables/
        temperature, kinetic_energy, collisions, dissipated_energy, events,
        momentum (d,), pressure:        step (S,), time (S,) shared, value (S, ...)
        pressure_tensor (d, d)          (event-driven runs of smooth particles without gravity or
                                        thermal or vibrating walls, and sheared DSMC runs: kinetic +
                                        collisional transfer, peculiar velocities)
        wall_collisions, wall_pressure  (runs with walls)
        potential_energy                (runs with gravity: -sum m g . r, unwrapped positions)
        wall_work, wall_impulse (d, 2)  (runs with thermal or vibrating walls, or gravity and walls: energy
                                        the walls gave the gas, cumulative; normal momentum delivered to
                                        the lower / upper wall of each axis over the interval ending at time)
        injected_energy, kick_step      (driven runs: energy put in, index of the next kick)
        three_body_contacts             (collisions that take time: collisions of a particle still
                                        in contact with another one, cumulative)
    parameters/
        config (resolved TOML text), config_source (file text), attrs
        version, seed, model, units, prefactor, ...; restitution_table/ (the
        exact table the engine used: inv_h, coeffs, duration_coeffs, beta_max, end)

A DSMC run (``parameters/`` attribute ``method = "dsmc"``) simulates a homogeneous
gas without positions: it has no ``position`` and ``image`` elements (``velocity``
then owns the frames' ``step`` and ``time``; the velocities are peculiar velocities),
no ``pressure`` observable, and the ``dsmc/`` elements above; ``step`` counts pair
collisions, ``events`` the candidate pairs drawn. The readers return snapshots with
``positions = images = None`` (:func:`has_positions`).

All elements with an explicit ``step`` and ``time``. ``pressure`` is the mean
over the sampling interval that ends at ``time`` (kinetic plus collisional
virial), NaN at the first sample of a run; ``wall_pressure`` likewise the
normal momentum delivered to the walls per unit wall area and time. All observables share one clock
(hard-linked ``step``/``time``) and are sampled at every snapshot time too, so
frame-indexed readers (MDAnalysis ``ts.data``) never run past their end; use
:func:`read_observables` for the right times. The unwrapped position is
``position + image * edges``.

Crash safety: the writer flushes the file after each snapshot (observables
are buffered for at most ``flush_seconds`` of wall time and always written
before a snapshot), so a run killed in the compiled loop leaves a file that
holds every frame written before, readable by any HDF5 reader (no SWMR flag to
clear); the readers ignore a last frame whose time was not yet written.

The per-particle elements are those of the table
:data:`granulargas.state.PARTICLE_FIELDS`: a run's state (:class:`granulargas.state.State`)
goes into a frame whole (:meth:`H5MDWriter.write_state`; the time-independent fields once,
when the file is created; the restart-only per-frame fields a run lists in ``fields``) and
comes back whole (:func:`read_state`: the frame's fields, box, boundary, time and step, the
counters of :data:`granulargas.state.COUNTERS` from the observables sample at the frame,
a DSMC file's random state), which is what a restart reads.

Continuing a run into the same file (:meth:`H5MDWriter.append`): the file is
opened for writing, cut back to the state the continuation starts from (its last
complete frame and the observables sample at that frame: a run killed after it
may have written a few samples more) and its datasets are extended; every time
stays absolute. The frame at which a signal stopped a run (the state reached,
written off the output schedule unless the stop fell on a scheduled frame) is
listed in ``parameters/interrupted_frames`` (:func:`interrupted_frames`).

The readers (:func:`read_observables`, :func:`iter_snapshots`,
:func:`load_snapshot`, :func:`read_parameters`) read one frame at a time. A file
that is not ours, or one that is truncated or lacks an element the readers need
(a dataset removed, shapes that do not fit together), raises
:class:`granulargas.errors.InputFileError` with one line naming the file and
what is missing or unreadable.
"""

from __future__ import annotations

import dataclasses
import os
import re
import time as _time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import h5py
import numpy as np

from granulargas import __version__
from granulargas.errors import InputFileError
from granulargas.state import COUNTERS, FIELDS, PARTICLE_FIELDS, DSMCContinuation, State

CREATOR = "granulargas"
_wall = _time.monotonic
SCALAR_OBSERVABLES = ("temperature", "kinetic_energy", "collisions", "events", "dissipated_energy", "pressure",
                      "sonine_a2", "sonine_a3")
#: observables a file may lack: Sonine coefficients (files written before they were sampled), pressure (DSMC),
#: the pressure tensor (unsheared DSMC, files written before it was sampled)
OPTIONAL_OBSERVABLES = ("sonine_a2", "sonine_a3", "pressure", "pressure_tensor")
#: the DSMC random state stored with every frame of a DSMC run: name -> (trailing shape, dtype)
DSMC_STATE = {"rng": ((5,), np.uint64), "candidates": ((), np.int64), "pending_pair": ((2,), np.int64),
              "pending_time": ((), np.float64), "frame_velocity": (("d",), np.float64)}
#: observables of runs with walls / with driving (written only by such runs)
WALL_OBSERVABLES = ("wall_collisions", "wall_pressure")
#: the pressure tensor (d, d): event-driven runs of smooth particles without gravity or thermal or
#: vibrating walls, and DSMC runs under shear
TENSOR_OBSERVABLES = ("pressure_tensor",)
DRIVING_OBSERVABLES = ("injected_energy", "kick_step")
GRAVITY_OBSERVABLES = ("potential_energy",)
#: observables of runs with thermal or vibrating walls, or with gravity and walls
WALL_KIND_OBSERVABLES = ("wall_work", "wall_impulse")
RESOLVED_OBSERVABLES = ("three_body_contacts",)
#: observables of runs of rough particles (those that store angular velocities)
ROUGH_OBSERVABLES = ("rotational_temperature", "cumulant_a20", "cumulant_a02", "cumulant_a11")
#: observables of a mixture of S species: one value per species, the collisions (S, S) per pair
SPECIES_OBSERVABLES = ("species_temperature", "species_sonine_a2", "species_collisions")
_SPECIES_DESCRIPTIONS = {
    "species_temperature": "temperature T_s = <m c^2>_s / d of each species (index = particles/all/species; "
                           "c the peculiar velocity of the whole gas)",
    "species_sonine_a2": "second Sonine coefficient d/(d+2) <e^2>_s/<e>_s^2 - 1, e = m c^2, of each species",
    "species_collisions": "pair collisions so far per pair of species (S, S), symmetric: (a, b) counts the "
                          "collisions between species a and b",
}
#: per-frame fields every frame of an EDMD / a DSMC file holds; the other per-frame fields of
#: granulargas.state.PARTICLE_FIELDS are stored when a run asks for them (``fields``)
CORE_FIELDS = ("positions", "velocities", "images")
CORE_FIELDS_DSMC = ("velocities",)
#: per-frame fields a run may store besides the core ones (restart state of its model)
OPTIONAL_FIELDS = tuple(x for x in PARTICLE_FIELDS if x.per_frame and x.name not in CORE_FIELDS)
_INT_OBSERVABLES = ("collisions", "events", "wall_collisions", "kick_step", "three_body_contacts",
                    "species_collisions")
#: H5MD box boundary of each axis kind (Lees-Edwards images are periodic with a shift: ``kind``
#: keeps the axis kinds themselves)
_H5MD_BOUNDARY = {"periodic": "periodic", "wall": "none", "lees-edwards": "periodic"}


def _frame_chunks(n: int, tail: tuple) -> tuple:
    # one frame per chunk (frame-by-frame readers), split beyond ~8 MB
    per = max(1, min(n, (1 << 20) // max(int(np.prod(tail)), 1)))
    return (1, per) + tuple(tail)


def _frame_fields(positions: bool, fields) -> tuple:
    """The per-frame fields a file stores: the core ones of its method and ``fields``, in the
    order of :data:`granulargas.state.PARTICLE_FIELDS`."""
    optional = {x.name for x in OPTIONAL_FIELDS}
    unknown = [x for x in fields if x not in optional]
    if unknown:
        raise ValueError(f"fields: {unknown[0]!r} is not one of {', '.join(sorted(optional))}")
    core = CORE_FIELDS if positions else CORE_FIELDS_DSMC
    return tuple(x.name for x in PARTICLE_FIELDS if x.name in core or x.name in fields)


def _describe(fld) -> str:
    """The ``description`` attribute of a per-particle element."""
    return fld.description + (" (kept for exact restarts)" if fld.restart_only else "")


#: every dataset the writer creates carries HDF5's Fletcher-32 checksum (verified on each read)
CHECKSUMS = True


def _dataset(group, name, **kwargs):
    """``group.create_dataset(name, **kwargs)`` with the Fletcher-32 checksum filter (chunked
    storage; HDF5 checks every chunk when it is read, :func:`_read`)."""
    return group.create_dataset(name, fletcher32=CHECKSUMS, **kwargs)


def write_text(group, name, text: str):
    """A text as a one-element dataset of fixed-length UTF-8 bytes (checksummed like every
    dataset; a variable-length string cannot carry the filter). :func:`read_text` reads it."""
    data = text.encode("utf-8")
    return _dataset(group, name, data=np.array([data], dtype=f"S{max(len(data), 1)}"), chunks=(1,))


def read_text(ds) -> str:
    """The text of a dataset written by :func:`write_text` (or a variable-length string of an
    older file)."""
    value = _read(ds)
    if isinstance(value, np.ndarray) and value.shape == (1,):
        value = value[0]
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


class H5MDWriter:
    """Append-only H5MD writer for one run.

    Parameters
    ----------
    path : str or Path
        Output file; created (an existing file is replaced only with ``overwrite``).
    state : granulargas.state.State
        The run's state: its box, boundary and time-independent per-particle fields
        (radii, masses, species) are written here; no positions (a DSMC state) makes a
        DSMC file (no positions and images; each frame stores the DSMC continuation).
    fields : sequence of str
        Per-frame fields of :data:`granulargas.state.PARTICLE_FIELDS` stored besides the
        positions, velocities and images: the restart state of the run's model
        (``last_collision``: TC model; ``contact_until``, ``contact_partner``: collisions
        that take time, which also get the ``three_body_contacts`` observable).
    parameters : dict, optional
        Attributes of ``parameters/`` (scalars or strings); nested dicts become groups,
        numpy arrays become datasets.
    overwrite : bool
    driven : bool
        Also the driving's observables (``injected_energy``, ``kick_step``).
    gravity, wall_kinds : bool
        A run under gravity (``potential_energy``) / with thermal or vibrating walls
        (``wall_work``, ``wall_impulse``; with gravity and walls too).
    species : int
        A mixture of that many species: also :data:`SPECIES_OBSERVABLES` (0: none).
    """

    def __init__(self, path, state: State, *, fields=(), parameters=None, overwrite=False, author=None,
                 driven=False, gravity=False, wall_kinds=False, tensor=None, species: int = 0):
        self.path = Path(path)
        self.d, self.n = state.dimension, state.n
        self.positions = state.positions is not None
        self.fields = _frame_fields(self.positions, fields)
        if self.path.exists() and not overwrite:
            raise InputFileError(f"{self.path}: output file exists (use --overwrite to replace it)")
        try:
            f = h5py.File(self.path, "w")
        except (OSError, ValueError) as exc:
            raise InputFileError(f"{self.path}: cannot create output file ({_short(exc)})") from None
        self.file = f
        self.boundary = state.boundary
        extra = ((WALL_OBSERVABLES if "wall" in self.boundary else ()) + (DRIVING_OBSERVABLES if driven else ())
                 + (RESOLVED_OBSERVABLES if "contact_partner" in self.fields else ())
                 + (GRAVITY_OBSERVABLES if gravity else ())
                 + (WALL_KIND_OBSERVABLES if wall_kinds or (gravity and "wall" in self.boundary) else ())
                 + (ROUGH_OBSERVABLES if "angular_velocities" in self.fields else ())
                 + (SPECIES_OBSERVABLES if species else ()))
        self.species = int(species)
        names = SCALAR_OBSERVABLES + ("momentum",) + extra
        if not self.positions:  # DSMC: no pair virial, no pressure
            names = tuple(x for x in names if x != "pressure")
        if (self.positions if tensor is None else tensor):
            names += TENSOR_OBSERVABLES
        try:
            self._create(state, parameters or {}, author, names)
        except BaseException:
            self.file.close()
            self.path.unlink(missing_ok=True)
            raise
        self._pending = []
        self._last_flush = _wall()
        self.file.flush()

    #: longest wall time (s) observables samples stay buffered in memory
    flush_seconds = 2.0

    @classmethod
    def append(cls, path, state: State, *, fields=()):
        """Open one of our files to continue its run in it (module docstring).

        The file must hold the ``state``'s particles in its dimensions, store the same
        per-frame ``fields`` (:class:`H5MDWriter`) and end with a complete frame at the
        state's step (``events``) and ``time`` with an observables sample there (the
        state the continuation starts from); frames and samples after it (a half-written
        frame, samples of a killed run) are cut off. Everything is checked with the file
        open read-only: a file that does not fit raises :class:`InputFileError` and stays
        unchanged.
        """
        path = Path(path)
        positions = state.positions is not None
        wanted = _frame_fields(positions, fields)
        with open_run(path) as f, _damaged(path, "the run to continue"):
            frames, samples = _continuation_point(f, path, state, wanted)
        f = open_run(path, "r+")
        try:
            with _damaged(path, "the run to continue"):
                self = cls.__new__(cls)
                self.path, self.file, self.n, self.d = path, f, state.n, state.dimension
                part = f["particles/all"]
                self.positions = has_positions(f)
                self.fields = wanted
                self.box = np.ascontiguousarray(_read(part["box/edges/value"], frames - 1), dtype=np.float64)
                self.boundary = read_boundary(f)
                names = [FIELDS[x].element for x in self.fields] + ["box/edges"]
                names += [] if self.positions else [f"dsmc/{k}" for k in DSMC_STATE]
                self._frame_groups = [part[name] for name in names]
                for g in self._frame_groups:
                    g["value"].resize(frames, axis=0)
                for key in ("step", "time"):
                    part[_clock_name(f)][key].resize(frames, axis=0)
                self._obs = {name: g for name, g in f["observables"].items()}
                self._obs_clock = (f["observables/temperature/step"], f["observables/temperature/time"])
                for g in self._obs.values():
                    g["value"].resize(samples, axis=0)
                for ds in self._obs_clock:
                    ds.resize(samples, axis=0)
                self._pending = []
                self._last_flush = _wall()
                f.flush()
        except BaseException:
            f.close()
            raise
        return self

    def mark_interrupted(self, reason: str):
        """Record the last frame as the state at which a signal stopped the run (written off the
        schedule, unless the stop fell on a scheduled frame)."""
        g = self.file["parameters"]
        old = list(_read(g["interrupted_frames"])) if "interrupted_frames" in g else []
        if "interrupted_frames" in g:
            del g["interrupted_frames"]
        _dataset(g, "interrupted_frames", data=np.asarray(old + [self.frames - 1], dtype=np.int64))
        g["interrupted_frames"].attrs["description"] = (
            "frames at which a signal stopped the run (the state reached; off the output schedule unless "
            "the stop fell on a scheduled frame)")
        g["interrupted_frames"].attrs["last_reason"] = reason
        self.file.flush()

    # ----------------------------------------------------------------- layout
    def _create(self, state, parameters, author, names):
        f, n, d = self.file, self.n, self.d
        h = f.create_group("h5md")
        h.attrs["version"] = np.array([1, 1], dtype=np.int32)
        h.create_group("author").attrs["name"] = author or os.environ.get("USER", "unknown")
        c = h.create_group("creator")
        c.attrs["name"] = CREATOR
        c.attrs["version"] = __version__

        part = f.create_group("particles/all")
        b = part.create_group("box")
        b.attrs["dimension"] = np.int32(d)
        b.attrs["boundary"] = np.array([_H5MD_BOUNDARY[x] for x in self.boundary],
                                       dtype=h5py.string_dtype("ascii", 8))
        if "lees-edwards" in self.boundary:
            b.attrs["kind"] = np.array(list(self.boundary), dtype=h5py.string_dtype("ascii", 16))
        if state.box is None:
            raise ValueError("H5MDWriter: the state has no box")
        self.box = state.box.copy()

        groups = []
        step = time = None
        for name in self.fields:
            fld = FIELDS[name]
            g = part.create_group(fld.element)
            if step is None:  # the first element owns the frames' clock
                step = _dataset(g, "step", shape=(0,), maxshape=(None,), dtype=np.int64, chunks=(256,))
                time = _dataset(g, "time", shape=(0,), maxshape=(None,), dtype=np.float64, chunks=(256,))
            else:
                g["step"], g["time"] = step, time  # hard links: one clock for all frames
            tail = fld.shape(d)
            _dataset(g, "value", shape=(0, n) + tail, maxshape=(None, n) + tail, dtype=fld.dtype,
                             chunks=_frame_chunks(n, tail))
            g.attrs["description"] = _describe(fld)
            groups.append(g)
        if not self.positions:
            part["velocity"].attrs["description"] = (
                "peculiar velocities of a DSMC run (homogeneous gas, no positions)")
            dg = part.create_group("dsmc")
            dg.attrs["description"] = ("DSMC random state at each frame (granulargas.dsmc.DSMC.continuation): "
                                       "continues the run bit for bit")
            for name, (tail, dtype) in DSMC_STATE.items():
                tail = tuple(d if x == "d" else x for x in tail)
                g = dg.create_group(name)
                g["step"], g["time"] = step, time
                _dataset(g, "value", shape=(0,) + tail, maxshape=(None,) + tail, dtype=dtype,
                                 chunks=(256,) + tail)
                groups.append(g)
        e = b.create_group("edges")
        e["step"], e["time"] = step, time
        _dataset(e, "value", shape=(0, d), maxshape=(None, d), dtype=np.float64, chunks=(256, d))
        groups.append(e)
        self._frame_groups = groups
        for fld in PARTICLE_FIELDS:
            # time-independent: written once (a field without a default only when the state has it)
            if not fld.per_frame and (fld.default is not None or getattr(state, fld.name) is not None):
                _dataset(part, fld.element, data=state.array(fld.name))
                part[fld.element].attrs["description"] = _describe(fld)

        obs = f.create_group("observables")
        self._obs = {}
        step = time = None
        for name in names:
            shape = ((d,) if name == "momentum" else (d, d) if name == "pressure_tensor"
                     else (d, 2) if name == "wall_impulse" else ())
            if name in SPECIES_OBSERVABLES:
                shape = (self.species,) * (2 if name == "species_collisions" else 1)
            dtype = np.int64 if name in _INT_OBSERVABLES else np.float64
            g = obs.create_group(name)
            if step is None:
                step = _dataset(g, "step", shape=(0,), maxshape=(None,), dtype=np.int64, chunks=(1024,))
                time = _dataset(g, "time", shape=(0,), maxshape=(None,), dtype=np.float64, chunks=(1024,))
            else:
                g["step"], g["time"] = step, time  # hard links: one clock for all observables
            _dataset(g, "value", shape=(0,) + shape, maxshape=(None,) + shape, dtype=dtype,
                             chunks=(1024,) + shape)
            self._obs[name] = g
        self._obs_clock = (step, time)
        if "pressure_tensor" in obs:
            obs["pressure_tensor"].attrs["description"] = (
                "mean pressure tensor P_ab (kinetic sum m c_a c_b with the peculiar velocities, relative to "
                "the shear flow if any, plus collisional transfer r_ij,a Delta p_i,b) per volume over the "
                "sampling interval ending at time; NaN at the first sample of a run")
        if "pressure" in obs:
            obs["pressure"].attrs["description"] = (
                "mean pressure (kinetic + collisional virial) over the sampling interval ending at time; "
                "NaN at the first sample of a run"
            )
        obs["sonine_a2"].attrs["description"] = (
            "second Sonine coefficient d/(d+2) <c^4>/<c^2>^2 - 1 of the peculiar velocities "
            "(mass-weighted; granulargas.observables)")
        obs["sonine_a3"].attrs["description"] = (
            "third Sonine coefficient of the peculiar velocities (granulargas.observables)")
        if "rotational_temperature" in obs:
            obs["rotational_temperature"].attrs["description"] = (
                "rotational temperature sum I |w|^2 / (d_r N) of rough particles (d_r = 3 for spheres, 1 for "
                "disks); temperature is the translational one")
            for name, what in (("cumulant_a20", "d_t/(d_t+2) <c^4>/<c^2>^2 - 1 of the peculiar velocities"),
                               ("cumulant_a02", "d_r/(d_r+2) <w^4>/<w^2>^2 - 1 of the spins"),
                               ("cumulant_a11", "<c^2 w^2>/(<c^2><w^2>) - 1")):
                obs[name].attrs["description"] = (
                    f"{what} (c weighted by m, w by I: granulargas.observables.rough_moments)")
        described = {
            "potential_energy": "potential energy -sum m g . r in the uniform field (unwrapped positions)",
            "wall_work": "energy the thermal and vibrating walls have given the gas (cumulative, net)",
            "wall_impulse": "normal momentum delivered to the lower / upper wall of each axis over the sampling "
                            "interval ending at time (d, 2); NaN at the first sample",
            **_SPECIES_DESCRIPTIONS}
        for name, text in described.items():
            if name in obs:
                obs[name].attrs["description"] = text
        if "wall_pressure" in obs:
            obs["wall_pressure"].attrs["description"] = (
                "normal momentum delivered to the walls per unit wall area per unit time over the sampling "
                "interval ending at time; NaN at the first sample of a run"
            )
        _write_parameters(f.create_group("parameters"), parameters)

    # ----------------------------------------------------------------- frames
    @property
    def frames(self) -> int:
        return int(self.file[f"particles/all/{_clock_name(self.file)}/step"].shape[0])

    def write_state(self, state: State):
        """Append one frame: the per-frame fields of a (synchronised) state at its step
        (``state.events``) and ``time`` (a DSMC file: also ``state.dsmc``), then flush.

        The frame's values are written before its step/time, so a reader of a
        killed run never sees a time without data."""
        if self.positions != (state.positions is not None) or (not self.positions and state.dsmc is None):
            raise ValueError("write_state: a state with positions for an EDMD file, with a DSMC continuation "
                             "for a DSMC file")
        self.flush_observables()
        k = self.frames
        data = {FIELDS[name].element: state.array(name) for name in self.fields}
        data["edges"] = self.box if state.box is None else state.box
        if state.dsmc is not None:
            data.update({name: np.asarray(getattr(state.dsmc, name)) for name in DSMC_STATE})
        for g in self._frame_groups:
            name = g.name.rsplit("/", 1)[-1]
            v = g["value"]
            v.resize(k + 1, axis=0)
            v[k] = data[name]
        pos = self.file[f"particles/all/{_clock_name(self.file)}"]
        for key, val in (("step", state.events), ("time", state.time)):
            pos[key].resize(k + 1, axis=0)
            pos[key][k] = val
        self.file.flush()

    def write_observables(self, step, time, values: dict, flush=True):
        """Append one sample of every observable (``values``: name -> value;
        a missing one is stored as NaN, or -1 for the integer counters).

        Samples are buffered in memory and written in one block (h5py's cost
        per call dominates small writes) when ``flush`` is true, before each
        snapshot, at :meth:`close`, and at least every ``flush_seconds`` of
        wall time."""
        values = {k: v for k, v in values.items() if k in self._obs or k not in OPTIONAL_OBSERVABLES}
        unknown = set(values) - set(self._obs)
        if unknown:
            raise KeyError(f"unknown observables {sorted(unknown)}")
        self._pending.append((int(step), float(time), values))
        if flush or _wall() - self._last_flush > self.flush_seconds:
            self.flush_observables()

    def flush_observables(self):
        """Write the buffered observables samples and flush the file."""
        if self._pending:
            step_ds, time_ds = self._obs_clock
            k, m = step_ds.shape[0], len(self._pending)
            for name, g in self._obs.items():
                v = g["value"]
                fill = -1 if name in _INT_OBSERVABLES else np.full(v.shape[1:], np.nan)
                block = np.array([p[2].get(name, fill) for p in self._pending], dtype=v.dtype)
                v.resize(k + m, axis=0)
                v[k:k + m] = block
            for ds, col in ((step_ds, 0), (time_ds, 1)):
                ds.resize(k + m, axis=0)
                ds[k:k + m] = [p[col] for p in self._pending]
            self._pending = []
        self.file.flush()
        self._last_flush = _wall()

    def set_parameters(self, parameters: dict):
        """Add entries to ``parameters/`` (e.g. the final summary)."""
        _write_parameters(self.file["parameters"], parameters)
        self.flush_observables()

    def close(self):
        if self.file.id.valid:
            try:
                self.flush_observables()
            finally:
                self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _continuation_point(f, path, state: State, fields) -> tuple[int, int]:
    """(frames, samples) to keep of a file a run continues in (:meth:`H5MDWriter.append`)."""
    part = f["particles/all"]
    particles, dimension, step, time = state.n, state.dimension, state.events, state.time
    n, d = (int(x) for x in part[f"{_clock_name(f)}/value"].shape[1:])
    if (n, d) != (particles, dimension):
        raise InputFileError(f"{path}: holds {n} particles in {d}D, the continuation {particles} in {dimension}D")
    for fld in OPTIONAL_FIELDS:
        if (fld.element in part) != (fld.name in fields):
            raise InputFileError(f"{path}: {'has' if fld.element in part else 'lacks'} {fld.description}; "
                                 "continue it with the same collision model")
    frames = _frame_count(f)
    clock = _clock_name(f)
    if frames == 0 or int(_read(part[f"{clock}/step"], frames - 1)) != step or float(
            _read(part[f"{clock}/time"], frames - 1)) != time:
        raise InputFileError(f"{path}: its last frame is not the state the continuation starts from")
    names = list(f["observables"])
    for name in tuple(x for x in SCALAR_OBSERVABLES if x not in OPTIONAL_OBSERVABLES) + ("momentum",):
        g = f["observables"].get(name)
        if not isinstance(g, h5py.Group) or any(not isinstance(g.get(p), h5py.Dataset) for p in ("step", "time", "value")):
            raise InputFileError(f"{path}: damaged H5MD file: observables/{name} is missing or incomplete")
    obs_step, obs_time = _read(f["observables/temperature/step"]), _read(f["observables/temperature/time"])
    hits = np.nonzero((obs_step == step) & (obs_time == time))[0]
    if len(hits) == 0:
        raise InputFileError(f"{path}: no observables sample at its last frame (t = {time:g})")
    samples = int(hits[-1]) + 1
    for name in names:
        if f[f"observables/{name}/value"].shape[0] < samples:
            raise InputFileError(f"{path}: damaged H5MD file: observables/{name} ends before its last frame")
    return frames, samples


def _short(exc) -> str:
    """The useful part of an HDF5 error message."""
    text = str(exc).strip()
    m = re.search(r"error message = '([^']*)'", text)
    if m:
        return m.group(1)
    text = text.splitlines()[0] if text else type(exc).__name__
    m = re.search(r"\(([^()]*)\)\s*$", text)
    return m.group(1) if m else text


def _write_parameters(group, params: dict):
    for key, value in params.items():
        if value is None:
            continue
        if isinstance(value, dict):
            _write_parameters(group.require_group(key), value)
        elif isinstance(value, np.ndarray) and value.ndim > 0:
            if key in group:
                del group[key]
            _dataset(group, key, data=value)
        elif isinstance(value, str) and (len(value) > 200 or "\n" in value):
            if key in group:
                del group[key]
            write_text(group, key, value)
        elif isinstance(value, np.ndarray):
            group.attrs[key] = value.item()
        elif isinstance(value, (list, tuple)) and value and all(isinstance(x, str) for x in value):
            group.attrs.create(key, [str(x) for x in value], dtype=h5py.string_dtype())
        elif isinstance(value, (list, tuple)):
            group.attrs[key] = np.asarray(value)
        else:
            group.attrs[key] = value


# --------------------------------------------------------------------- readers


@dataclass(frozen=True)
class Snapshot:
    """One frame: synchronised state at ``time`` (arrays in particle-id order)."""

    index: int
    time: float
    step: int
    positions: np.ndarray | None  # (N, d) in [0, box); None in a DSMC file
    velocities: np.ndarray  # (N, d)
    images: np.ndarray | None  # (N, d) int64; None in a DSMC file
    box: np.ndarray  # (d,)
    radii: np.ndarray  # (N,)
    masses: np.ndarray  # (N,)
    species: np.ndarray  # (N,)
    last_collision: np.ndarray | None = None  # (N,) TC model only
    contact_until: np.ndarray | None = None  # (N,) collisions that take time only
    contact_partner: np.ndarray | None = None  # (N,) int64, collisions that take time only
    boundary: tuple = ()  # "periodic" or "wall" per axis
    angular_velocities: np.ndarray | None = None  # (N, 3) / (N, 1) in 2D, rough particles only
    inertia: np.ndarray | None = None  # (N,) kappa = I / (m R^2), rough particles only

    @property
    def unwrapped_positions(self) -> np.ndarray:
        if self.positions is None:
            raise InputFileError("DSMC file has no positions (a homogeneous gas: velocities only)")
        return self.positions + self.images * self.box


def open_run(path, mode="r") -> h5py.File:
    """Open one of our H5MD files; :class:`InputFileError` if missing, not ours or damaged
    (a truncated file, an element the readers need missing, shapes that do not fit)."""
    path = Path(path)
    if not path.exists():
        raise InputFileError(f"{path}: file not found")
    if path.is_dir():
        raise InputFileError(f"{path}: is a directory, not an H5MD file")
    try:
        f = h5py.File(path, mode)
    except OSError as exc:
        text = str(exc).lower()
        locked = "unable to lock file" in text
        if not locked or mode != "r":
            why = _short(exc)
            if "truncated file" in text:
                m = re.search(r"eof = (\d+).*stored_eof = (\d+)", text)
                size = f": {m.group(1)} of its {m.group(2)} bytes" if m else f" ({why})"
                raise InputFileError(f"{path}: truncated HDF5 file{size} (the file was cut short)") from None
            if locked:
                raise InputFileError(f"{path}: locked by a running simulation; wait until it has finished") from None
            raise InputFileError(f"{path}: not an HDF5 file or unreadable ({why})") from None
        # a running simulation holds the HDF5 lock; it flushes after every snapshot,
        # so reading without the lock sees the frames written so far
        try:
            f = h5py.File(path, mode, locking=False)
        except OSError:
            raise InputFileError(f"{path}: locked by a running simulation; try again when it has finished") from None
    try:
        try:
            creator = f["h5md/creator"].attrs.get("name", None)
            if isinstance(creator, bytes):
                creator = creator.decode()
            ours = creator == CREATOR
        except (KeyError, OSError, RuntimeError):
            ours = False
        if not ours:
            raise InputFileError(f"{path}: not an H5MD file written by granulargas (no h5md/creator "
                                 f'name "{CREATOR}")')
        with _damaged(path, "its layout"):
            _check_layout(f, path)
    except BaseException:
        f.close()
        raise
    return f


#: datasets every reader needs, relative to particles/all
_REQUIRED = ("position/step", "position/time", "position/value", "velocity/value", "image/value",
             "box/edges/value", "radius", "mass", "species")
#: ... in a DSMC file (no positions; ``velocity`` owns the frames' clock)
_REQUIRED_DSMC = ("velocity/step", "velocity/time", "velocity/value", "box/edges/value", "radius", "mass",
                  "species") + tuple(f"dsmc/{k}/value" for k in DSMC_STATE)


def has_positions(f) -> bool:
    """False for a DSMC run's file (open file or path): no positions, only velocities."""
    if not isinstance(f, h5py.File):
        with open_run(f) as g:
            return has_positions(g)
    return "position" in f["particles/all"] or "dsmc" not in f["particles/all"]


def _clock_name(f) -> str:
    """The particles/all element that owns the frames' step and time."""
    return "position" if has_positions(f) else "velocity"


def _check_layout(f, path):
    """Every element the readers need exists, with shapes that fit together (metadata only)."""
    part = f.get("particles/all")
    if not isinstance(part, h5py.Group):
        raise InputFileError(f"{path}: damaged H5MD file: particles/all is missing")
    positions = has_positions(f)
    clock = "position" if positions else "velocity"
    for name in _REQUIRED if positions else _REQUIRED_DSMC:
        if not isinstance(part.get(name), h5py.Dataset):
            raise InputFileError(f"{path}: damaged H5MD file: particles/all/{name} is missing")
    pos = part[f"{clock}/value"].shape
    if len(pos) != 3 or pos[2] not in (2, 3):
        raise InputFileError(f"{path}: damaged H5MD file: particles/all/{clock}/value has shape {pos}, "
                             "expected (frames, particles, 2 or 3)")
    n, d = pos[1], pos[2]
    expect = {"velocity/value": (n, d), "box/edges/value": (d,), "radius": None,
              "mass": None, "species": None, f"{clock}/step": (), f"{clock}/time": ()}
    if positions:
        expect["image/value"] = (n, d)
    else:
        expect.update({f"dsmc/{k}/value": tuple(d if x == "d" else x for x in tail)
                       for k, (tail, _) in DSMC_STATE.items()})
    for name, tail in expect.items():
        shape = part[name].shape
        ok = shape == (n,) if tail is None else (len(shape) == len(tail) + 1 and shape[1:] == tail)
        if not ok:
            want = "(particles,)" if tail is None else "(frames" + "".join(f", {x}" for x in tail) + ")"
            raise InputFileError(f"{path}: damaged H5MD file: particles/all/{name} has shape {shape}, "
                                 f"expected {want} with {n} particles in {d}D")
    for name in _REQUIRED if positions else _REQUIRED_DSMC:
        if part[name].dtype.kind not in "fiu":
            raise InputFileError(f"{path}: damaged H5MD file: particles/all/{name} holds {part[name].dtype} "
                                 "values, not numbers")
    for fld in OPTIONAL_FIELDS:
        if fld.element in part:
            value, want = part.get(f"{fld.element}/value"), (n,) + fld.shape(d)
            if not isinstance(value, h5py.Dataset) or value.shape[1:] != want:
                raise InputFileError(f"{path}: damaged H5MD file: particles/all/{fld.element}/value is missing "
                                     f"or not (frames{''.join(f', {x}' for x in want)})")
    for fld in PARTICLE_FIELDS:  # time-independent fields a file may hold (e.g. inertia)
        if not fld.per_frame and fld.element in part and fld.element not in expect:
            value = part[fld.element]
            if not isinstance(value, h5py.Dataset) or value.shape != (n,) + fld.shape(d):
                raise InputFileError(f"{path}: damaged H5MD file: particles/all/{fld.element} is not an array "
                                     f"of shape ({n},)")
    if not isinstance(f.get("observables"), h5py.Group):
        raise InputFileError(f"{path}: damaged H5MD file: observables/ is missing")
    if not isinstance(f.get("parameters"), h5py.Group):
        raise InputFileError(f"{path}: damaged H5MD file: parameters/ is missing")


def _read(ds, selection=()):
    """``ds[selection]``; a read that fails (a Fletcher-32 checksum mismatch, damaged storage)
    raises :class:`InputFileError` with one line naming the file and the element (and the
    frame, for an integer selection)."""
    try:
        return ds[selection]
    except (OSError, RuntimeError) as exc:
        where = ds.name.lstrip("/")
        if isinstance(selection, (int, np.integer)):
            where += f", frame {int(selection)}" if where.startswith("particles/") else f", row {int(selection)}"
        checksum = ds.fletcher32 and "filter" in str(exc).lower()
        why = ("checksum mismatch (Fletcher-32): the stored data changed after they were written" if checksum
               else f"unreadable ({_short(exc)})")
        raise InputFileError(f"{ds.file.filename}: damaged H5MD file: {where}: {why}") from None


@contextmanager
def _damaged(path, what: str):
    """Turn what h5py raises on damaged content into one line naming the file and the element."""
    try:
        yield
    except InputFileError:
        raise
    except (OSError, KeyError, ValueError, TypeError, IndexError, RuntimeError) as exc:
        raise InputFileError(f"{path}: damaged H5MD file: cannot read {what} ({_short(exc)})") from None


def _frame_count(f) -> int:
    part = f["particles/all"]
    pos = part[_clock_name(f)]
    lengths = [pos["step"].shape[0], pos["time"].shape[0], pos["value"].shape[0]]
    others = ("velocity/value", "image/value") if has_positions(f) else tuple(f"dsmc/{k}/value" for k in DSMC_STATE)
    lengths += [part[name].shape[0] for name in others + ("box/edges/value",)]
    for fld in OPTIONAL_FIELDS:
        if fld.element in part:
            lengths.append(part[f"{fld.element}/value"].shape[0])
    return int(min(lengths))


def _snapshot(f, k, static) -> Snapshot:
    part = f["particles/all"]
    radii, masses, species, boundary = static
    lc = _read(part["last_collision/value"], k) if "last_collision" in part else None
    snap = _read_snapshot(part, k, radii, masses, species, lc, boundary)
    if "contact_until" in part and "contact_partner" in part:
        snap = dataclasses.replace(snap, contact_until=_read(part["contact_until/value"], k),
                                   contact_partner=_read(part["contact_partner/value"], k))
    if "angular_velocity" in part:
        snap = dataclasses.replace(snap, angular_velocities=_read(part["angular_velocity/value"], k),
                                   inertia=part["inertia"][()] if "inertia" in part else None)
    for name in ("positions", "velocities", "box") if snap.positions is not None else ("velocities", "box"):
        if not np.all(np.isfinite(getattr(snap, name))) or (name == "box" and not np.all(snap.box > 0)):
            raise InputFileError(f"{f.filename}: damaged H5MD file: frame {k} holds non-finite {name}")
    if not np.isfinite(snap.time):
        raise InputFileError(f"{f.filename}: damaged H5MD file: frame {k} has time {snap.time}")
    return snap


def _read_snapshot(part, k, radii, masses, species, lc, boundary) -> Snapshot:
    positions = "position" in part
    clock = part["position" if positions else "velocity"]
    return Snapshot(
        index=k,
        time=float(_read(clock["time"], k)),
        step=int(_read(clock["step"], k)),
        positions=_read(part["position/value"], k) if positions else None,
        velocities=_read(part["velocity/value"], k),
        images=_read(part["image/value"], k) if positions else None,
        box=_read(part["box/edges/value"], k),
        radii=radii,
        masses=masses,
        species=species,
        last_collision=lc,
        boundary=boundary,
    )


def _static(f):
    part = f["particles/all"]
    radii, masses = _read(part["radius"]), _read(part["mass"])
    for name, values in (("radius", radii), ("mass", masses)):
        if not np.all(np.isfinite(values) & (values > 0)):
            raise InputFileError(f"{f.filename}: damaged H5MD file: particles/all/{name} holds non-finite or "
                                 "non-positive values")
    return radii, masses, _read(part["species"]), read_boundary(f)


def read_boundary(f) -> tuple:
    """The boundary of each axis ("periodic" or "wall") from an open file's box attributes."""
    box = f["particles/all/box"]
    d = int(box.attrs.get("dimension", f["particles/all/velocity/value"].shape[-1]))
    raw = box.attrs.get("boundary", None)
    if raw is None:
        return ("periodic",) * d
    names = [x.decode() if isinstance(x, bytes) else str(x) for x in np.atleast_1d(raw)]
    kind = box.attrs.get("kind", None)
    if kind is not None:  # our own axis kinds (Lees-Edwards)
        kinds = tuple(x.decode() if isinstance(x, bytes) else str(x) for x in np.atleast_1d(kind))
        if len(kinds) == len(names) and all(k in _H5MD_BOUNDARY for k in kinds):
            return kinds
    return tuple("wall" if x == "none" else "periodic" for x in names)


def iter_snapshots(path) -> Iterator[Snapshot]:
    """Yield the snapshots of a run in time order, one frame at a time."""
    with open_run(path) as f:
        with _damaged(path, "particles/all (radius, mass, species)"):
            static = _static(f)
            count = _frame_count(f)
        for k in range(count):
            with _damaged(path, f"frame {k}"):
                snap = _snapshot(f, k, static)
            yield snap


def snapshot_count(path) -> int:
    """Number of complete snapshots in a file."""
    with open_run(path) as f:
        return _frame_count(f)


def load_snapshot(path, index: int = -1) -> Snapshot:
    """One snapshot by index (negative counts from the end; default the last)."""
    with open_run(path) as f:
        n = _frame_count(f)
        if n == 0:
            raise InputFileError(f"{path}: holds no snapshot")
        k = index + n if index < 0 else index
        if not 0 <= k < n:
            raise InputFileError(f"{path}: snapshot index {index} out of range ({n} snapshots)")
        with _damaged(path, f"frame {k}"):
            return _snapshot(f, k, _static(f))


def read_state(path, index: int = -1) -> State:
    """One frame as a :class:`granulargas.state.State` (negative index: from the end): every
    per-particle field of :data:`granulargas.state.PARTICLE_FIELDS` the file holds, the box
    and boundary, the frame's time and step (``events``), the counters of
    :data:`granulargas.state.COUNTERS` from the observables sample at the frame, and a DSMC
    file's continuation. What a run restarts from (:func:`granulargas.run.prepare.restart_state`)."""
    with open_run(path) as f:
        count = _frame_count(f)
        if count == 0:
            raise InputFileError(f"{path}: holds no snapshot")
        k = index + count if index < 0 else index
        if not 0 <= k < count:
            raise InputFileError(f"{path}: snapshot index {index} out of range ({count} snapshots)")
        with _damaged(path, f"the state at frame {k}"):
            part = f["particles/all"]
            values = {}
            for fld in PARTICLE_FIELDS:
                if fld.element in part:
                    values[fld.name] = (_read(part[f"{fld.element}/value"], k) if fld.per_frame
                                        else _read(part[fld.element]))
            clock = part[_clock_name(f)]
            time, step = float(_read(clock["time"], k)), int(_read(clock["step"], k))
            counters = _counters_at(f, path, step, time, k)
            dsmc = None
            if "dsmc" in part:
                g = part["dsmc"]
                dsmc = DSMCContinuation(**{name: _read(g[name]["value"], k) for name in DSMC_STATE})
            return State(box=_read(part["box/edges/value"], k), boundary=read_boundary(f), time=time, events=step,
                         dsmc=dsmc, **{"positions": None, **values}, **counters)


def _counters_at(f, path, step: int, time: float, k: int) -> dict:
    """The counters of :data:`granulargas.state.COUNTERS` from the observables sample at frame k."""
    obs = f["observables"]
    for name in ("collisions", "dissipated_energy"):
        if not isinstance(obs.get(name), h5py.Group):
            raise InputFileError(f"{path}: damaged H5MD file: observables/{name} is missing")
    g = obs["collisions"]
    m = min(g["step"].shape[0], g["time"].shape[0], g["value"].shape[0])
    hits = np.nonzero((_read(g["step"], slice(0, m)) == step) & (_read(g["time"], slice(0, m)) == time))[0]
    if len(hits) == 0:
        raise InputFileError(f"{path}: no observables sample at snapshot {k} (t = {time:g})")
    sample = int(hits[-1])
    out = {}
    for name, dtype in COUNTERS.items():
        if name in obs:
            value = obs[name]["value"]
            if sample >= value.shape[0]:
                raise InputFileError(f"{path}: damaged H5MD file: observables/{name} ends before snapshot {k}")
            out[name] = dtype(_read(value, sample)).item()
    if "species_collisions" in obs:
        value = obs["species_collisions"]["value"]
        if sample >= value.shape[0]:
            raise InputFileError(f"{path}: damaged H5MD file: observables/species_collisions ends before snapshot {k}")
        out["species_collisions"] = np.asarray(_read(value, sample), dtype=np.int64)
    return out


def interrupted_frames(path) -> list[int]:
    """Indices of the frames at which a signal stopped the run (:meth:`H5MDWriter.mark_interrupted`)."""
    with open_run(path) as f, _damaged(path, "parameters/interrupted_frames"):
        g = f["parameters"]
        return [int(k) for k in _read(g["interrupted_frames"])] if "interrupted_frames" in g else []


def read_observables(path) -> dict:
    """All observables: ``{name: (step, time, value)}`` as numpy arrays."""
    out = {}
    with open_run(path) as f:
        for name in list(f["observables"]):
            with _damaged(path, f"observables/{name}"):
                g = f["observables"][name]
                for part in ("step", "time", "value"):
                    if not isinstance(g.get(part), h5py.Dataset):
                        raise InputFileError(f"{path}: damaged H5MD file: observables/{name}/{part} is missing")
                if any(g[p].dtype.kind not in "fiu" for p in ("step", "time", "value")):
                    raise InputFileError(f"{path}: damaged H5MD file: observables/{name} holds values that are "
                                         "not numbers")
                want = (1 if name in SCALAR_OBSERVABLES else 2 if name == "momentum" else 3 if name == "pressure_tensor"
                        else g["value"].ndim)
                if g["step"].ndim != 1 or g["time"].ndim != 1 or g["value"].ndim != max(want, 1):
                    raise InputFileError(f"{path}: damaged H5MD file: observables/{name} has step/time/value "
                                         f"of shapes {g['step'].shape}, {g['time'].shape}, {g['value'].shape}")
                n = min(g["step"].shape[0], g["time"].shape[0], g["value"].shape[0])
                out[name] = (_read(g["step"], slice(0, n)), _read(g["time"], slice(0, n)),
                             _read(g["value"], slice(0, n)))
                values = out[name][2]
                if not np.all(np.isfinite(out[name][1])) or (  # NaN: a sample the writer was not given
                        name in ("temperature", "kinetic_energy") and np.any((values < 0) | np.isinf(values))):
                    raise InputFileError(f"{path}: damaged H5MD file: observables/{name} holds infinite or "
                                         "negative values")
    return out


def read_parameters(path) -> dict:
    """The ``parameters/`` group as a nested dict (attributes and datasets), plus
    ``creator_version``; strings decoded, ``config`` the resolved TOML text."""
    with open_run(path) as f, _damaged(path, "parameters/"):
        out = _read_group(f["parameters"])
        out["creator_version"] = _decode(f["h5md/creator"].attrs.get("version", "unknown"))
    return out


def _decode(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.ndarray) and v.dtype.kind in "SO":
        return [_decode(x) for x in v.tolist()]
    if isinstance(v, np.generic):
        return v.item()
    return v


def _read_group(g) -> dict:
    out = {k: _decode(v) for k, v in g.attrs.items()}
    for k, v in g.items():
        if isinstance(v, h5py.Group):
            out[k] = _read_group(v)
        elif v.dtype.kind in "SO" and v.shape in ((), (1,)):
            out[k] = read_text(v)
        elif v.dtype.kind in "SO":
            out[k] = _decode(_read(v))
        else:
            out[k] = _read(v)
    return out
