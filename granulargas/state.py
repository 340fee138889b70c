"""The physics state of a gas as one record: :class:`State`.

:class:`granulargas.engine.Simulation` and :class:`granulargas.dsmc.DSMC` take a
``State`` whole and give the current one back (``sim.state``: a synchronised copy,
particles in id order), the initial states (:func:`granulargas.initial.random_state`)
make one, and an H5MD frame stores one (:mod:`granulargas.io.h5md`: ``write_state``,
``read_state``). ``Simulation(sim.state, rule, ...)`` continues bit for bit where
``sim.synchronise()`` would, and so does a restart from a frame written at that time.

What a run *is* lives here (particles, box, clock, counters); how it is run (collision
rule, driving, neighbour search, the DSMC's density) stays a keyword argument of the
simulation.

Per-particle quantities are declared once, in :data:`PARTICLE_FIELDS`: name, dtype,
per-particle shape in d dimensions, default, H5MD element, whether the element is
written once or per frame, and whether it is an observable or kept for restarts only.
The record converts each field to its dtype, the simulations check its shape from the
table, the simulations keep the fields they do not use as given, and the H5MD writer
and reader store and read every field of the table, so a model that needs a new
per-particle quantity adds one entry there, which also makes it an attribute of
:class:`State` (ARCHITECTURE.md, "Adding a per-particle field").
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Callable

import numpy as np

from granulargas.errors import ConfigError


def _vector(d: int) -> tuple:
    return (d,)


def _scalar(d: int) -> tuple:
    return ()


def _spin(d: int) -> tuple:
    """Angular velocity: 3 components in 3D, the one about z in 2D."""
    return (3,) if d == 3 else (1,)


@dataclass(frozen=True)
class ParticleField:
    """One per-particle quantity of the state (a row of :data:`PARTICLE_FIELDS`)."""

    #: attribute of :class:`State`
    name: str
    dtype: type
    #: per-particle shape in d dimensions: ``shape(d)``
    shape: Callable[[int], tuple]
    #: value of every particle when the state does not carry the field (None: the field is required
    #: wherever it is used)
    default: float | int | None
    #: H5MD element under ``particles/all``
    element: str
    #: True: one value per frame (time-dependent); False: written once (time-independent)
    per_frame: bool
    #: True: kept for exact restarts only; False: an observable a reader analyses
    restart_only: bool
    #: what the values are (the H5MD element's description; error messages)
    description: str


#: Every per-particle quantity of the state, in particle-id order.
PARTICLE_FIELDS = (
    # name, dtype, per-particle shape(d), default, H5MD element, per frame, restart only, description
    ParticleField("positions", np.float64, _vector, None, "position", True, False,
                  "positions, wrapped into the box on periodic axes"),
    ParticleField("velocities", np.float64, _vector, None, "velocity", True, False,
                  "velocities (a DSMC run: peculiar velocities)"),
    ParticleField("images", np.int64, _vector, 0, "image", True, False,
                  "periodic image counts (0 on wall axes)"),
    ParticleField("radii", np.float64, _scalar, None, "radius", False, False, "radii"),
    ParticleField("masses", np.float64, _scalar, None, "mass", False, False, "masses"),
    ParticleField("species", np.int32, _scalar, 0, "species", False, False, "species indices"),
    ParticleField("last_collision", np.float64, _scalar, -np.inf, "last_collision", True, True,
                  "the TC model's last-collision times"),
    ParticleField("contact_until", np.float64, _scalar, -np.inf, "contact_until", True, True,
                  "the end times of contacts under way (collisions that take time; -inf: none)"),
    ParticleField("contact_partner", np.int64, _scalar, -1, "contact_partner", True, True,
                  "the partners of contacts under way (collisions that take time; -1: none)"),
    ParticleField("angular_velocities", np.float64, _spin, 0.0, "angular_velocity", True, False,
                  "angular velocities of rough particles (3D: 3 components; 2D: the one about z)"),
    ParticleField("inertia", np.float64, _scalar, None, "inertia", False, False,
                  "kappa = I / (m R^2) of rough particles, I the moment of inertia about a centre "
                  "axis (2/5: uniform sphere, 1/2: uniform disk)"),
)
FIELDS = {f.name: f for f in PARTICLE_FIELDS}

#: Counters of the state that an H5MD file keeps as observables of the same name (sampled
#: at every frame): name -> dtype. ``time`` and ``events`` are the frame's time and step.
COUNTERS = {"collisions": np.int64, "dissipated_energy": np.float64, "wall_collisions": np.int64,
            "wall_work": np.float64,
            "injected_energy": np.float64, "kick_step": np.int64, "three_body_contacts": np.int64}


@dataclass(frozen=True)
class DSMCContinuation:
    """What continues a DSMC run bit for bit besides its velocities, clock and counters.

    ``rng`` uint64 (5,): the random words; ``candidates``: candidate pairs drawn so far
    (the position in the pair stream); ``pending_pair`` (i, j) and ``pending_time``: the
    next collision, already drawn ((-1, -1) and nan when there is none);
    ``frame_velocity`` (d,): the mean velocity subtracted at the start (the DSMC works
    with peculiar velocities).
    """

    rng: np.ndarray
    candidates: int
    pending_pair: tuple
    pending_time: float
    frame_velocity: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "rng", np.array(self.rng, dtype=np.uint64))
        object.__setattr__(self, "candidates", int(self.candidates))
        object.__setattr__(self, "pending_pair", tuple(int(x) for x in self.pending_pair))
        object.__setattr__(self, "pending_time", float(self.pending_time))
        object.__setattr__(self, "frame_velocity", np.array(self.frame_velocity, dtype=np.float64))


def _with_particle_fields(cls):
    """Give the record an attribute, default None, for every entry of :data:`PARTICLE_FIELDS`
    that its class body does not declare: a new per-particle field is one line of the table."""
    for f in PARTICLE_FIELDS:
        if f.name not in cls.__annotations__:
            cls.__annotations__[f.name] = "np.ndarray | None"
            setattr(cls, f.name, None)
    return cls


@dataclass(frozen=True)
@_with_particle_fields
class State:
    """The physics state of a gas of N particles in d = 2 or 3 dimensions.

    Per-particle arrays are in particle-id order, C-contiguous, of the dtype of
    :data:`PARTICLE_FIELDS` (the record converts them; ``radii`` and ``masses`` may be
    given as one number for all). An optional field left as None means its default for
    every particle. Every entry of :data:`PARTICLE_FIELDS` is an attribute of the same
    name (those not listed below come after ``dsmc``, default None).

    Attributes
    ----------
    positions : array (N, d) or None
        Positions in units of the reference diameter (None: a DSMC state, a homogeneous
        gas without positions).
    velocities : array (N, d)
    radii, masses : arrays (N,)
    box : array (d,) or None
        Box sides L (a DSMC state may have none: its density is then a setting).
    boundary : tuple of str
        One entry per axis, "periodic" or "wall" (default: all periodic).
    images : int64 array (N, d), optional
        Periodic image counters (unwrapped position = position + images * box).
    species : int32 array (N,), optional
        Species index of each particle (default 0).
    last_collision : array (N,), optional
        Time of each particle's last collision (-inf: none; the TC model uses it).
    contact_until, contact_partner : arrays (N,), optional
        Collisions that take time: when each particle's contact under way ends (-inf:
        none) and the particle id of its partner (-1: none).
    angular_velocities : array (N, 3) in 3D, (N, 1) in 2D, optional
        Rough particles: the angular velocities (2D: about z; default 0).
    inertia : array (N,), optional
        Rough particles: kappa = I / (m R^2) (I the moment of inertia; no default: a rough
        simulation without it takes that of a uniform sphere or disk, 2/5 or 1/2).
    time : float
        The state's time.
    collisions, events, wall_collisions, three_body_contacts : int
        Pair collisions, events processed (every kind, a driving step counting as one;
        a DSMC counts its collisions), sphere-wall collisions, collisions of a particle
        still in contact with another (collisions that take time), all so far.
    dissipated_energy, injected_energy : float
        Kinetic energy dissipated in collisions and put in by the driving so far.
    wall_work : float
        Energy the thermal and vibrating walls have given the gas so far (net).
    kick_step : int or None
        Index k of the next driving step, at (k + 1/2) dt (None: the first after ``time``).
    species_collisions : int64 array (S, S) or None
        A mixture: pair collisions so far per pair of species, symmetric (entry (a, b)
        counts the collisions between species a and b); None: not counted (0).
    dsmc : DSMCContinuation or None
        The DSMC's random state and pending collision (None: a fresh DSMC start).
    """

    positions: np.ndarray | None
    velocities: np.ndarray
    radii: np.ndarray
    masses: np.ndarray
    box: np.ndarray | None
    boundary: tuple | None = None
    images: np.ndarray | None = None
    species: np.ndarray | None = None
    last_collision: np.ndarray | None = None
    contact_until: np.ndarray | None = None
    contact_partner: np.ndarray | None = None
    time: float = 0.0
    collisions: int = 0
    events: int = 0
    dissipated_energy: float = 0.0
    wall_collisions: int = 0
    injected_energy: float = 0.0
    kick_step: int | None = None
    three_body_contacts: int = 0
    species_collisions: np.ndarray | None = None
    dsmc: DSMCContinuation | None = None
    wall_work: float = 0.0

    def __post_init__(self):
        set_ = object.__setattr__
        if self.velocities is None:
            raise ConfigError("velocities: every state has velocities (N, d)")
        vel = np.ascontiguousarray(self.velocities, dtype=np.float64)
        if vel.ndim != 2 or vel.shape[1] not in (2, 3):
            raise ConfigError(f"velocities: shape {vel.shape}, expected (N, 2) or (N, 3)")
        n, d = vel.shape
        set_(self, "velocities", vel)
        for f in PARTICLE_FIELDS:
            value = getattr(self, f.name)
            if value is None or f.name == "velocities":
                continue
            arr = np.asarray(value, dtype=f.dtype)
            if f.name in ("radii", "masses") and arr.ndim == 0:
                arr = np.full(n, arr, dtype=f.dtype)
            set_(self, f.name, np.ascontiguousarray(arr))
        if self.box is not None:
            box = np.asarray(self.box, dtype=np.float64)
            set_(self, "box", np.full(d, box) if box.ndim == 0 else np.ascontiguousarray(box))
        if self.boundary is None:
            set_(self, "boundary", ("periodic",) * d)
        elif isinstance(self.boundary, str):
            raise ConfigError(f"boundary = {self.boundary!r}: give one entry per axis, e.g. "
                              f"{('periodic',) * (d - 1) + ('wall',)}")
        else:
            set_(self, "boundary", tuple(str(x) for x in self.boundary))
        for name in ("time", "dissipated_energy", "injected_energy", "wall_work"):
            set_(self, name, float(getattr(self, name)))
        for name in ("collisions", "events", "wall_collisions", "three_body_contacts"):
            set_(self, name, int(getattr(self, name)))
        if self.kick_step is not None:
            set_(self, "kick_step", int(self.kick_step))
        if self.species_collisions is not None:
            counts = np.array(self.species_collisions, dtype=np.int64)
            if counts.ndim != 2 or counts.shape[0] != counts.shape[1] or not np.array_equal(counts, counts.T):
                raise ConfigError(f"species_collisions: a symmetric (S, S) table of counts, got shape {counts.shape}")
            set_(self, "species_collisions", counts)

    @property
    def n(self) -> int:
        """Number of particles."""
        return self.velocities.shape[0]

    @property
    def dimension(self) -> int:
        return self.velocities.shape[1]

    def array(self, name: str) -> np.ndarray:
        """The per-particle field ``name``, or its default for every particle when the state
        does not carry it (a new array)."""
        f = FIELDS[name]
        value = getattr(self, name)
        if value is not None:
            return value.copy()
        if f.default is None:
            raise ConfigError(f"{name}: this state has none")
        return np.full((self.n,) + f.shape(self.dimension), f.default, dtype=f.dtype)

    def check_shapes(self):
        """Every per-particle field the state carries has the shape (N,) + shape(d) of
        :data:`PARTICLE_FIELDS` (ConfigError otherwise), the box d sides."""
        n, d = self.n, self.dimension
        for f in PARTICLE_FIELDS:
            value = getattr(self, f.name)
            want = (n,) + f.shape(d)
            if value is not None and value.shape != want:
                raise ConfigError(f"{f.name}: shape {value.shape}, expected {want}")
        if self.box is not None and self.box.shape != (d,):
            raise ConfigError(f"box: shape {self.box.shape}, expected ({d},)")

    def replace(self, **changes) -> "State":
        """A copy with some fields changed (:func:`dataclasses.replace`)."""
        return dataclasses.replace(self, **changes)


#: names of the fields of :class:`State`
STATE_FIELDS = tuple(f.name for f in dataclasses.fields(State))
