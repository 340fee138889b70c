"""TOML run configuration -> frozen dataclasses, validated by one declarative schema.

A config file has the sections ``[system]``, ``[particles]``, ``[initial]``,
``[collision]`` (with the optional sub-table ``[collision.material]``),
``[driving]``, ``[gravity]`` and ``[walls]`` (optional), ``[run]`` and ``[output]``, and for a
mixture an array of tables ``[[species]]`` in place of ``[particles]``; :func:`load_config` reads it with :mod:`tomllib`, applies
optional dotted-key overrides, and returns a :class:`RunConfig`.

The schema
----------
Every key is described once, in :data:`SCHEMA`: a :class:`Key` gives its section,
name, type, default, allowed range (and why the range is what it is), unit and
meaning. Rules that involve several keys are :data:`RULES` (:class:`Rule`: a
sentence for the documentation and a check). The validator (:func:`build_config`)
is driven by the two:

1. the document's structure: unknown sections and keys are refused, with the
   nearest valid name suggested (:mod:`difflib`);
2. each key of :data:`SCHEMA` in order: type, then range (a key that is absent
   takes its default);
3. each rule of :data:`RULES` in order;
4. the values are assembled into the dataclasses (field ``Key.field`` of the
   section's dataclass).

Every failure raises :class:`granulargas.errors.ConfigError` with one line naming
the file (or ``override``), the key, the value and what is allowed, and the reason
of the bound when the value has the right type. :func:`config_schema` and
:func:`config_rules` are what the documentation's configuration reference is
generated from, so the reference cannot drift from the validator.

Adding a key: one :class:`Key` entry in :data:`SCHEMA` (and a field of that name in
the section's dataclass); a rule across keys, one entry in :data:`RULES`
(ARCHITECTURE.md, "Adding a config key").

Bounds that follow from float64 and from the engine (reduced units, below): masses
and temperatures lie in [1e-100, 1e100] so that thermal speeds sqrt(T/m) lie in
[1e-100, 1e100] and their squares far inside float64 (the engine refuses speeds
outside (1e-150, 1e150)); diameters lie in [1e-50, 1e50] so that volumes
(diameter^3) and squared distances stay finite; times lie below 1e100 so that
time x speed stays finite; particle ids are int32 in the engine. Bounds that need
the machine or the whole run (memory, disk, the float64 clock over the run, the
restitution table's range) are checked when a run starts, before anything is
allocated or written (:mod:`granulargas.run.resources`,
:mod:`granulargas.run.validity`); the reference states them too.

Units (reduced): lengths in the reference particle diameter, masses in the
reference particle mass, energies in the initial temperature T0 (k_B = 1), so
time in sigma sqrt(m/T0). The material route (``[collision.material]``) gives
the reference particle's SI diameter and density and the SI velocity unit
``speed_unit`` (= sqrt(T0/m) for temperature 1); :mod:`granulargas.run.prepare`
converts it once to the reduced pair prefactor k (ARCHITECTURE.md).
"""

from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Callable

from granulargas.errors import ConfigError

#: Densest packings: FCC spheres pi/(3 sqrt 2), hexagonal disks pi/(2 sqrt 3).
MAX_PACKING = {3: math.pi / (3.0 * math.sqrt(2.0)), 2: math.pi / (2.0 * math.sqrt(3.0))}
MODELS = ("elastic", "constant", "viscoelastic")
CONTACT_ENDS = ("overlap", "force")
DURATIONS = ("instantaneous", "resolved")
BOUNDARIES = ("periodic", "wall", "lees-edwards")
DRIVING_MODELS = ("white_noise",)
#: ``[walls]``: the sides of the wall axes, the kinds of wall and the waveforms of a vibrating one
WALL_SIDES = ("x_low", "x_high", "y_low", "y_high", "z_low", "z_high")
WALL_KINDS = ("hard", "thermal", "vibrating")
WAVEFORMS = ("sine", "triangle", "biparabolic")
#: largest |g| component (reduced): g t^2 and the speeds g t stay finite for times up to TIME_MAX**0.5
GRAVITY_MAX = 1e50
#: ``[collision.tangential] model``: a constant tangential restitution, or Walton's Coulomb model
TANGENTIAL_MODELS = ("constant", "coulomb")
#: ``particles.inertia`` kappa = 4 I / (m sigma^2): uniform sphere 2/5, uniform disk 1/2 (also
#: ``granulargas.theory.rough.DEFAULT_INERTIA``)
DEFAULT_INERTIA = {3: 0.4, 2: 0.5}
#: largest kappa: all the mass on the surface, a thin shell 2/3 or a ring 1
#: (``granulargas.theory.rough.MAX_INERTIA``)
MAX_INERTIA = {3: 2.0 / 3.0, 2: 1.0}
#: ``run.method``: event-driven molecular dynamics, or DSMC of the homogeneous Enskog-Boltzmann equation
METHODS = ("edmd", "dsmc")
#: ``run.neighbours``: the engine's neighbour search (``engine.simulation.NEIGHBOURS``)
NEIGHBOURS = ("auto", "lists", "cells")
DEFAULT_SNAPSHOTS = 20

#: largest particle count: the engine indexes particles (neighbour lists, cells) with int32
MAX_PARTICLES = 2**31 - 1
#: masses and temperatures (reduced): thermal speeds sqrt(T/m) within [1e-100, 1e100]
SCALE_RANGE = (1e-100, 1e100)
#: diameters (reduced): volumes diameter^3 and squared distances within float64
LENGTH_RANGE = (1e-50, 1e50)
#: longest time (reduced): time x speed (<= 1e100) stays finite
TIME_MAX = 1e100
#: largest pair collision count of a run, C = collisions_per_particle x N / 2: exact in float64
MAX_COLLISIONS = 2**53
#: the restitution table covers beta <= 40 (granulargas.contact.table.TABLE_BETA_MAX)
TABLE_BETA_MAX = 40.0
#: SI material constants: within 1e+-100 so that the reduced prefactor stays finite
SI_RANGE = (1e-100, 1e100)


@dataclass(frozen=True)
class SystemConfig:
    """``[system]``: dimension, particle count, packing fraction, RNG seed, and the
    boundary of each axis: "periodic" or "wall" (flat hard walls at 0 and L; the
    packing fraction counts the whole box)."""

    dimension: int = 3
    particles: int = 1000
    packing_fraction: float = 0.1
    seed: int = 1
    boundary: tuple = ("periodic", "periodic", "periodic")

    @property
    def walls(self) -> bool:
        """Whether any axis has walls."""
        return "wall" in self.boundary


@dataclass(frozen=True)
class ShearConfig:
    """``[shear]`` (optional): uniform shear flow, the flow a (y - L_y/2) along x with
    Lees-Edwards boundaries on y (``system.boundary`` marks y ``"lees-edwards"``);
    optionally a thermostat that rescales the peculiar velocities to
    ``thermostat_temperature`` every ``thermostat_interval``."""

    rate: float = 0.0
    thermostat_temperature: float | None = None
    thermostat_interval: float | None = None


@dataclass(frozen=True)
class ParticlesConfig:
    """``[particles]``: diameters (uniform in [diameter_min, diameter_max] when
    polydisperse) and either a common ``mass`` or a ``density`` (mass = density
    x volume, volume pi d^3/6 in 3D and pi d^2/4 in 2D)."""

    diameter: float = 1.0
    diameter_min: float | None = None
    diameter_max: float | None = None
    mass: float | None = 1.0
    density: float | None = None
    inertia: float | None = None  # kappa of rough particles (None: smooth, no spins)

    @property
    def polydisperse(self) -> bool:
        return self.diameter_min is not None


@dataclass(frozen=True)
class SpeciesConfig:
    """One ``[[species]]`` table of a mixture: its ``name``, its number of particles
    ``count`` (given, or from ``fraction`` of ``system.particles``), ``diameter``, and
    ``mass`` or ``density`` (reduced, as in ``[particles]``); for the material route
    (``[collision.material]``) its Young modulus, Poisson ratio and dissipative constant
    (SI; None: those of ``[collision.material]``), and instead of a mass its material density
    ``material_density`` (SI; the mass is then set from it when the config is read)."""

    name: str
    count: int
    fraction: float | None = field(default=None, compare=False)  # as given; ``count`` is what a run uses
    diameter: float = 1.0
    mass: float | None = None
    density: float | None = None
    material_density: float | None = None
    young_modulus: float | None = None
    poisson_ratio: float | None = None
    dissipation_time: float | None = None

    def particle_mass(self, dimension: int) -> float:
        """The mass of one particle: ``mass``, or ``density`` times its volume."""
        if self.density is None:
            return 1.0 if self.mass is None else self.mass
        unit = math.pi / 6.0 if dimension == 3 else math.pi / 4.0
        return self.density * unit * self.diameter**dimension


@dataclass(frozen=True)
class InitialConfig:
    """``[initial]``: Maxwell-Boltzmann temperature, or a file to continue from;
    ``rotational_temperature`` of the spins of rough particles (None: smooth particles)."""

    temperature: float = 1.0
    from_file: str | None = None  # TOML key "from"
    rotational_temperature: float | None = None


@dataclass(frozen=True)
class MaterialConfig:
    """``[collision.material]`` (SI): the viscoelastic contact of Schwager & Pöschel
    (1997), eq. (2).

    young_modulus (Pa), poisson_ratio, dissipation_time A (s), diameter (m) and
    density (kg/m^3) of the reference particle, speed_unit (m/s): the reduced
    velocity unit sqrt(T0/m). A mixture may give the first three per species
    (``[[species]]``); here they are then the values of the species that give none
    (None: every species gives its own)."""

    young_modulus: float | None
    poisson_ratio: float | None
    dissipation_time: float | None
    diameter: float
    density: float
    speed_unit: float


@dataclass(frozen=True)
class TangentialConfig:
    """``[collision.tangential]``: rough particles. ``model = "constant"``: the tangential
    restitution beta_t = ``restitution`` (-1 smooth, +1 perfectly rough); ``"coulomb"``:
    Walton's model, sticking contacts get beta_0 = ``restitution``, sliding ones the Coulomb
    limit of ``friction`` mu. ``wall_restitution``, ``wall_friction``: the same for
    particle-wall contacts (default: the pair values)."""

    model: str = "constant"
    restitution: float = -1.0
    friction: float | None = None
    wall_restitution: float | None = None
    wall_friction: float | None = None


@dataclass(frozen=True)
class CollisionConfig:
    """``[collision]``: the coefficient of restitution model.

    ``tc_time`` (constant model only): TC model of Luding & McNamara (1998), a
    collision within ``tc_time`` of either particle's previous one is elastic.
    It is a positive time; without the key (None) the TC model is off.
    ``damping``: beta at normal impact speed g = 1 for two reference particles
    (diameter 1, mass 1); :func:`granulargas.run.prepare.reduced_prefactor`
    turns it (or ``[collision.material]``) into the pair prefactor k.
    ``wall_restitution`` (constant model, with walls): the constant eps of
    sphere-wall collisions (default: ``restitution``); elastic runs have elastic
    walls, viscoelastic runs the sphere-plane contact of the same material.
    ``duration``: "instantaneous" collisions, or "resolved" (viscoelastic with
    ``[collision.material]``): collisions that take time. ``elastic_below``: collisions at a
    normal speed below it are elastic (None: never).
    A mixture (``[[species]]``): ``restitution`` and ``damping`` may be tables
    ``{"a-b": value}`` with one entry per pair of species (keys in the species' order,
    "a-b" with a at or before b; :meth:`pair_table`), ``wall_restitution`` a table
    ``{"a": value}`` per species."""

    model: str = "viscoelastic"
    restitution: float | dict | None = None
    damping: float | dict | None = None
    material: MaterialConfig | None = None
    contact_end: str = "overlap"
    tc_time: float | None = None
    wall_restitution: float | dict | None = None
    duration: str = "instantaneous"
    elastic_below: float | None = None
    tangential: TangentialConfig | None = None

    @property
    def rough(self) -> bool:
        """Rough particles (spins and a tangential restitution)."""
        return self.tangential is not None

    @staticmethod
    def pair_table(value, names) -> list:
        """A per-pair value (a number for every pair, or a ``{"a-b": x}`` table) as an (S, S)
        list of lists for the species ``names``."""
        size = len(names)
        if not isinstance(value, dict):
            return [[float(value)] * size for _ in range(size)]
        out = [[0.0] * size for _ in range(size)]
        for i, a in enumerate(names):
            for j, b in enumerate(names[i:], i):
                out[i][j] = out[j][i] = float(value[pair_key(a, b)])
        return out

    @staticmethod
    def species_values(value, names, default) -> list:
        """A per-species value (a number, a ``{"a": x}`` table, or None) as a list, the entries
        not given from ``default`` (a list)."""
        if value is None:
            return list(default)
        if not isinstance(value, dict):
            return [float(value)] * len(names)
        return [float(value.get(a, default[i])) for i, a in enumerate(names)]


def pair_key(a: str, b: str) -> str:
    """The key of the pair of species a, b in a per-pair table: ``"a-b"``."""
    return f"{a}-{b}"


@dataclass(frozen=True)
class DrivingConfig:
    """``[driving]`` (optional): white-noise driving, every particle kicked by independent
    Gaussian velocity kicks (momentum-conserving) that raise the temperature at
    ``heating_rate`` (dT/dt of the driving alone, T0 per time unit); ``interval``
    between kicks (default: 0.02 of the theoretical steady state's cooling time,
    :func:`granulargas.theory.driving_interval`). Rough particles: ``rotational_fraction``
    of the power (``d/2 heating_rate`` per particle) goes to the spins (the splitting
    thermostat of Megías & Santos 2022)."""

    model: str = "white_noise"
    heating_rate: float = 0.0
    interval: float | None = None
    rotational_fraction: float | None = None  # None: 0, the translation alone

    @property
    def spin_fraction(self) -> float:
        """The fraction of the power that goes to the spins (0 when ``rotational_fraction`` is absent)."""
        return 0.0 if self.rotational_fraction is None else self.rotational_fraction


@dataclass(frozen=True)
class GravityConfig:
    """``[gravity]`` (optional): a uniform acceleration ``acceleration`` (one component per
    axis), periodic axes or walls alike; particles fly on parabolas between events."""

    acceleration: tuple = (0.0, 0.0, -1.0)

    @property
    def vector(self) -> tuple:
        return tuple(float(x) for x in self.acceleration)


@dataclass(frozen=True)
class WallConfig:
    """One side of a wall axis in ``[walls]``: ``kind`` "hard" (at rest, the run's restitution),
    "thermal" (diffuse at ``temperature``) or "vibrating" (``amplitude``, ``frequency``,
    ``waveform``, ``phase`` in radians; it rests ``amplitude`` inside the box)."""

    kind: str = "hard"
    amplitude: float | None = None
    frequency: float | None = None
    waveform: str = "sine"
    phase: float = 0.0
    temperature: float | None = None


@dataclass(frozen=True)
class WallsConfig:
    """``[walls]`` (optional): the kind of each side of the wall axes (a side left out is hard)."""

    x_low: WallConfig | None = None
    x_high: WallConfig | None = None
    y_low: WallConfig | None = None
    y_high: WallConfig | None = None
    z_low: WallConfig | None = None
    z_high: WallConfig | None = None

    def side(self, axis: int, side: int) -> WallConfig:
        """The wall of an axis and side (0 lower, 1 upper); a hard one if not given."""
        return getattr(self, WALL_SIDES[2 * axis + side]) or WallConfig()

    @property
    def moving(self) -> bool:
        """Whether any side is thermal or vibrating (not all hard walls at rest)."""
        return any(getattr(self, s) is not None and getattr(self, s).kind != "hard" for s in WALL_SIDES)


@dataclass(frozen=True)
class RunSection:
    """``[run]``: stop at ``end_time`` or after ``collisions_per_particle``,
    whichever comes first (at least one is required). Collisions per particle
    count each pair collision for both partners: s = 2 C / N (kinetic theory)."""

    end_time: float | None = None
    collisions_per_particle: float | None = None
    method: str = "edmd"
    neighbours: str = "auto"


@dataclass(frozen=True)
class OutputConfig:
    """``[output]``: H5MD file and the output schedule.

    ``snapshots`` full snapshots (including the initial and the final state;
    default :data:`DEFAULT_SNAPSHOTS`), log-spaced in time from ``first_snapshot``
    to the end, or evenly spaced every ``snapshot_interval``; observables every
    ``observables_interval`` and at every snapshot."""

    @property
    def snapshot_count(self) -> int:
        return DEFAULT_SNAPSHOTS if self.snapshots is None else self.snapshots

    file: str = "runs/run.h5"
    snapshots: int | None = None  # None: DEFAULT_SNAPSHOTS (log-spaced) unless snapshot_interval
    snapshot_interval: float | None = None
    first_snapshot: float | None = None
    observables_interval: float | None = None


@dataclass(frozen=True)
class RunConfig:
    """The whole validated run configuration."""

    system: SystemConfig
    particles: ParticlesConfig
    initial: InitialConfig
    collision: CollisionConfig
    run: RunSection
    output: OutputConfig
    source: str = "<config>"
    text: str = ""
    driving: DrivingConfig | None = None
    gravity: GravityConfig | None = None
    walls: WallsConfig | None = None
    shear: ShearConfig | None = None
    species: tuple = ()

    @property
    def mixture(self) -> bool:
        """Whether the config has ``[[species]]``."""
        return bool(self.species)

    @property
    def species_names(self) -> tuple:
        return tuple(sp.name for sp in self.species)

    def to_toml(self) -> str:
        """The resolved configuration (defaults filled in) as TOML text."""
        return dump_toml(self)


# --------------------------------------------------------------------------- the schema


class DefaultText(str):
    """A default the validator computes, described in words (not a TOML value)."""


@dataclass(frozen=True)
class Key:
    """One config key: what it is, what it may be, and why.

    Attributes
    ----------
    section : str
        ``"system"``, ..., ``"collision.material"`` (sub-tables dotted).
    key : str
        The TOML key; a key of an inline table is dotted (``"diameter.min"``).
    type : str
        ``"integer"``, ``"number"``, ``"string"``, ``"table"``, ``"number or table"`` or
        ``"list of strings"`` (one entry per axis; ``choices`` apply to each entry).
    meaning : str
        One or two sentences (Markdown code spans allowed).
    default : TOML value or None
        The value an absent key takes (None: no value; see ``default_text``).
    default_text : str or None
        A default the validator computes (e.g. ``"runs/<config name>.h5"``).
    unit : str
        Unit of a number ("" for dimensionless or not a number).
    low, high : float or None
        Numeric range; ``low_open``/``high_open`` exclude the bound itself.
    high_by_dimension : dict or None
        An upper bound that depends on ``system.dimension`` (overrides ``high``).
    choices : tuple or None
        Allowed values (strings, or integers).
    reason : str
        Why the range is what it is (float64, memory, the engine, physics).
    run_check : str
        Bounds checked when a run starts (machine or whole-run bounds), in words.
    field : str or None
        The dataclass field (default: ``key``).
    required_in_table : bool
        A key of a sub-table that must be given whenever the table is.
    template : bool
        A key of each of several tables (section ``"walls.<side>"``: every side's table),
        checked once for each table given, under its real name (``walls.z_low.amplitude``).
    per_species : bool
        A key of each ``[[species]]`` table (section ``"species"``), checked once for each
        species under its name (``species.glass.diameter``).
    """

    section: str
    key: str
    type: str
    meaning: str
    default: Any = None
    default_text: str | None = None
    unit: str = ""
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    high_by_dimension: dict | None = None
    choices: tuple | None = None
    reason: str = ""
    run_check: str = ""
    field: str | None = None
    required_in_table: bool = False
    template: bool = False
    per_species: bool = False

    @property
    def dotted(self) -> str:
        return f"{self.section}.{self.key}"

    @property
    def attribute(self) -> str:
        return self.field or self.key

    @property
    def shown_default(self):
        """The default as the reference shows it: a TOML value, a :class:`DefaultText` or None."""
        return DefaultText(self.default_text) if self.default_text is not None else self.default

    def range_text(self, dimension: int | None = None) -> str:
        """What the validator accepts, as one phrase (the error messages use it)."""
        if self.type == "list of strings":
            n = f"{dimension} " if dimension is not None else ""
            return f"a list of {n}strings (one per axis), each one of " + ", ".join(f'"{c}"' for c in self.choices)
        if self.type == "list of numbers":
            n = f"{dimension} " if dimension is not None else ""
            return f"a list of {n}numbers (one per axis), " + _range_phrase("each", self.low, self.high,
                                                                           self.low_open, self.high_open)
        if self.choices is not None:
            if all(isinstance(c, str) for c in self.choices):
                return "one of " + ", ".join(f'"{c}"' for c in self.choices)
            return " or ".join(str(c) for c in self.choices)
        if self.type in ("string", "table"):
            return "a non-empty string" if self.type == "string" else "a table"
        high = self.high
        if self.high_by_dimension is not None and dimension is not None:
            high = self.high_by_dimension[dimension]
        kind = "an integer" if self.type == "integer" else "a number"
        return _range_phrase(kind, self.low, high, self.low_open, self.high_open)

    @property
    def allowed(self) -> str:
        """Everything the validator and the run-start checks accept, for the reference."""
        if self.high_by_dimension is not None:
            text = "; ".join(f"{d}D: {self.range_text(d)}" for d in sorted(self.high_by_dimension, reverse=True))
        else:
            text = self.range_text()
        if self.reason:
            text += f" ({self.reason})"
        if self.key == "diameter" and self.section == "particles":
            text += "; or a table { min, max } (below)"
        if self.required_in_table:
            text += "; required in the table"
        if self.run_check:
            text += f"; when the run starts: {self.run_check}"
        return text


def _num(x: float) -> str:
    if isinstance(x, int) or (isinstance(x, float) and x.is_integer() and abs(x) < 1e16):
        return str(int(x))
    return f"{x:.4g}".replace("e+", "e")


def _range_phrase(kind, low, high, low_open, high_open) -> str:
    if low is None and high is None:
        return kind
    if high is None:
        return f"{kind} {'>' if low_open else '>='} {_num(low)}"
    if low is None:
        return f"{kind} {'<' if high_open else '<='} {_num(high)}"
    where = f"{'(' if low_open else '['}{_num(low)}, {_num(high)}{')' if high_open else ']'}"
    return f"{kind} in {where}"


_SPEED = "speeds sqrt(T/m) within [1e-100, 1e100], their squares far inside float64"
_LENGTH = "volumes and squared distances stay finite in float64"
_TIME = "time x speed stays finite in float64"
_MEMORY = "the engine state, the initial placement and the output must fit the memory and disk available"

SCHEMA: tuple[Key, ...] = (
    # [system]
    Key("system", "dimension", "integer", "2 (disks) or 3 (spheres).", default=3, choices=(2, 3)),
    Key("system", "particles", "integer",
        "Number of particles; the box must hold at least 3.15 largest diameters per side.",
        default=1000, low=2, high=MAX_PARTICLES, reason="the engine indexes particles with int32",
        run_check=f"{_MEMORY} (about 1 kB per particle; estimated before allocating)"),
    Key("system", "packing_fraction", "number",
        "Fraction of the volume (area in 2D) covered by the particles; sets the box. Random placement "
        "works up to about 0.54 (3D) and 0.76 (2D).",
        default=0.1, low=0.0, low_open=True, high_by_dimension=MAX_PACKING, high_open=True,
        reason="below the densest packing of spheres / disks",
        run_check="the engine's cell grid (one cell per ~2 diameters of box edge, 68 bytes each) must "
                  "fit in memory, which bounds very dilute packings; the box edge must be at least "
                  "3.15 largest diameters"),
    Key("system", "seed", "integer",
        "Seed of all randomness (diameters, positions, velocities); a seed gives the same initial "
        "state on every machine.", default=1, low=0, high=2**63 - 1, reason="any TOML integer >= 0"),
    Key("system", "boundary", "list of strings",
        'One entry per axis (x, y, z): `"periodic"`, or `"wall"` for flat hard walls at 0 and L on '
        'that axis (the packing fraction counts the whole box), or `"lees-edwards"` on y with `[shear]` '
        "(sliding images: uniform shear flow).",
        default_text='"periodic" on every axis', choices=BOUNDARIES,
        run_check="a wall axis must be at least 4.15 largest diameters long"),
    # [particles]
    Key("particles", "diameter", "number or table",
        "Particle diameter, or `{ min = ..., max = ... }` for a uniform polydisperse mix (the "
        "reference diameter is then the mean).", default=1.0, unit="reference diameter",
        low=LENGTH_RANGE[0], high=LENGTH_RANGE[1], reason=_LENGTH),
    Key("particles", "diameter.min", "number", "Smallest diameter of a polydisperse mix.",
        unit="reference diameter", low=LENGTH_RANGE[0], high=LENGTH_RANGE[1], reason=_LENGTH,
        field="diameter_min", required_in_table=True),
    Key("particles", "diameter.max", "number", "Largest diameter of a polydisperse mix (>= `min`).",
        unit="reference diameter", low=LENGTH_RANGE[0], high=LENGTH_RANGE[1], reason=_LENGTH,
        field="diameter_max", required_in_table=True),
    Key("particles", "mass", "number", "Mass of every particle (give `mass` or `density`, not both).",
        default_text="1.0 when `density` is not given", unit="reference mass",
        low=SCALE_RANGE[0], high=SCALE_RANGE[1], reason=_SPEED),
    Key("particles", "density", "number",
        "Instead of `mass`: mass = density × π d³/6 (3D) or π d²/4 (2D); the masses it gives must "
        "lie in the range of `mass`.", unit="reference mass per reference volume",
        low=0.0, low_open=True, high=1e250, reason="finite; the masses it gives are checked like `mass`"),
    Key("particles", "inertia", "number",
        "Rough particles (`[collision.tangential]`): κ = 4I/(mσ²), the moment of inertia I in units "
        "of m σ²/4; a uniform sphere has 2/5, a uniform disk 1/2, and all particles share it.",
        default_text="2/5 (spheres), 1/2 (disks)", low=0.0, low_open=True, high_by_dimension=MAX_INERTIA,
        reason="no mass outside the surface: at most a thin shell (2/3) or a ring (1)"),
    # [initial]
    Key("initial", "temperature", "number",
        "Maxwell–Boltzmann velocities with zero total momentum and exactly this temperature "
        "T = m⟨c²⟩/d.", default=1.0, unit="T0", low=SCALE_RANGE[0], high=SCALE_RANGE[1], reason=_SPEED),
    Key("initial", "from", "string",
        "Start from the last snapshot of this granulargas H5MD file instead (time, event count, "
        "collisions and dissipated energy continue; box, radii and masses come from the file; "
        "`dimension` and `particles` must match). Same as `--restart`.",
        field="from_file", run_check="the file must exist and hold a complete snapshot"),
    Key("initial", "rotational_temperature", "number",
        "Rough particles (`[collision.tangential]`): Maxwell–Boltzmann spins with zero total angular "
        "momentum and exactly this rotational temperature T_rot = I⟨ω²⟩/d_r (d_r = 3 for spheres, 1 "
        "for disks); 0 starts without spin.", default_text="`temperature`", unit="T0",
        low=0.0, high=SCALE_RANGE[1], reason="spin speeds within float64 as for `temperature`"),
    # [collision]
    Key("collision", "model", "string",
        "The coefficient of restitution: elastic, constant, or the viscoelastic ε(g) of the contact law.",
        default="viscoelastic", choices=MODELS),
    Key("collision", "restitution", "number or table of pairs",
        '`model = "constant"` only: the constant ε; a mixture may give one per pair of species, '
        '`{ "glass-glass" = 0.9, "glass-steel" = 0.8, "steel-steel" = 0.85 }` (every pair once, in '
        "either order).", low=0.0, low_open=True, high=1.0),
    Key("collision", "damping", "number or table of pairs",
        '`model = "viscoelastic"` only: the [damping](contact.md#damping), β of an impact at normal '
        "speed 1 between two reference particles (diameter 1, mass 1); an impact at speed g between "
        "particles i, j has β = damping (R_eff g / m_eff²)^(1/5). Give `damping` or `[collision.material]`. "
        'A mixture may give one per pair of species, `{ "a-a" = 0.1, "a-b" = 0.2, "b-b" = 0.15 }`.',
        low=0.0, high=TABLE_BETA_MAX, reason="the restitution table covers beta <= 40; the model holds "
                                             "for beta well below 3",
        run_check="beta of the fastest impact the run's energy allows must stay <= 40"),
    Key("collision", "contact_end", "string",
        '`"overlap"`: the contact ends when the compression returns to zero (Schwager & Pöschel '
        '(1997), eq. (4)); `"force"`: when the repulsive force vanishes (Schwager & Pöschel 2008).',
        default="overlap", choices=CONTACT_ENDS),
    Key("collision", "duration", "string",
        '`"instantaneous"`: a collision changes the velocities at the moment of touch. `"resolved"` '
        "(viscoelastic with `[collision.material]`, periodic boundaries): collisions take time; the pair "
        "leaves the contact with the velocity, at the time and on the line that the contact force gives "
        "for its impact angle (the oblique-contact table), as Müller & Pöschel (2013); meant for dilute "
        "gases, collisions with a pair still in contact are counted (`three_body_contacts`).",
        default="instantaneous", choices=DURATIONS,
        run_check="the impacts' compression over the contact distance stays below 0.5 and beta below 2"),
    Key("collision", "tc_time", "number",
        '`model = "constant"` only: TC model (Luding & McNamara 1998); a collision within `tc_time` '
        "of either particle's previous one is elastic, which guards against inelastic collapse. "
        "Leave the key out for no TC model.",
        unit="reduced time", low=0.0, low_open=True, high=TIME_MAX, reason=_TIME),
    Key("collision", "wall_restitution", "number or table of species",
        '`model = "constant"` with walls only: the constant ε of particle–wall collisions (default: '
        "`restitution`). Elastic runs have elastic walls; viscoelastic runs the sphere–plane contact "
        "of the same material. A mixture may give one per species, `{ glass = 0.9, steel = 0.7 }` "
        "(a species left out: its own pair's ε).", low=0.0, low_open=True, high=1.0),
    Key("collision", "elastic_below", "number",
        '`model = "constant"` or `"viscoelastic"`: a collision (pair or wall) whose normal relative speed '
        "is below this is elastic (the restitution floor of DynamO's ElasticV, Bannerman, Sargant & Lue "
        "2011). It keeps a grain coming to rest on a floor under gravity, or a cluster on a shaken plate, "
        "out of an endless run of ever-smaller bounces (inelastic collapse): such a grain bounces on at "
        "about this speed. Leave the key out for none.",
        unit="reduced speed", low=0.0, low_open=True, high=SCALE_RANGE[1], reason=_SPEED),
    Key("collision", "material", "table",
        "Instead of `damping`: the viscoelastic contact from material constants "
        "(`[collision.material]`, below)."),
    Key("collision", "tangential", "table",
        "Rough particles: spins and a tangential restitution (`[collision.tangential]`, below); "
        "without it the particles are smooth and do not spin."),
    # [collision.material]
    Key("collision.material", "young_modulus", "number",
        "Young's modulus Y (a mixture: of the species that give none).", unit="Pa",
        low=SI_RANGE[0], high=SI_RANGE[1], reason="the reduced prefactor stays finite",
        required_in_table=True, run_check="beta of the fastest impact must stay <= 40"),
    Key("collision.material", "poisson_ratio", "number", "Poisson ratio ν (a mixture: of the species that give none).",
        low=-1.0, high=0.5, low_open=True, high_open=True, reason="elastic stability",
        required_in_table=True),
    Key("collision.material", "dissipation_time", "number",
        "The dissipative constant A of Schwager & Pöschel (1997), eq. (2) (a mixture: of the species "
        "that give none).", unit="s",
        low=0.0, high=SI_RANGE[1], reason="the reduced prefactor stays finite", required_in_table=True),
    Key("collision.material", "diameter", "number", "Diameter of the reference particle.", unit="m",
        low=SI_RANGE[0], high=SI_RANGE[1], reason="the reduced prefactor stays finite", required_in_table=True),
    Key("collision.material", "density", "number",
        "Material density; the reference mass is density × π d³/6 (also for disks).", unit="kg/m³",
        low=SI_RANGE[0], high=SI_RANGE[1], reason="the reduced prefactor stays finite", required_in_table=True),
    Key("collision.material", "speed_unit", "number",
        "The reduced velocity unit √(T0/m); time is then in diameter / speed_unit.", unit="m/s",
        low=SI_RANGE[0], high=SI_RANGE[1], reason="the reduced prefactor stays finite", required_in_table=True),
    # [collision.tangential]
    Key("collision.tangential", "model", "string",
        '`"constant"`: the tangential restitution β_t = `restitution` reverses the tangential velocity '
        'of the contact points, g_t → −β_t g_t; `"coulomb"`: Walton\'s model, a contact sticks with '
        "β_t = `restitution` unless the tangential impulse would exceed `friction` × the normal one, "
        "and then slides (β_t then depends on the impact angle).", default="constant",
        choices=TANGENTIAL_MODELS),
    Key("collision.tangential", "restitution", "number",
        "The tangential restitution β_t (`model = \"coulomb\"`: of sticking contacts): −1 smooth "
        "(no spin exchange), 0 the tangential contact velocity stopped, +1 perfectly rough "
        "(reversed, no loss). Not the viscoelastic `damping`.", low=-1.0, high=1.0,
        reason="|beta_t| <= 1: a collision cannot create energy", required_in_table=True),
    Key("collision.tangential", "friction", "number",
        '`model = "coulomb"` only: the friction coefficient μ of the Coulomb limit.',
        low=0.0, high=SI_RANGE[1], reason="a friction coefficient is >= 0"),
    Key("collision.tangential", "wall_restitution", "number",
        "With walls: β_t of particle–wall contacts (default: `restitution`).", low=-1.0, high=1.0,
        reason="|beta_t| <= 1: a collision cannot create energy"),
    Key("collision.tangential", "wall_friction", "number",
        '`model = "coulomb"` with walls: μ of particle–wall contacts (default: `friction`).',
        low=0.0, high=SI_RANGE[1], reason="a friction coefficient is >= 0"),
    # [[species]]
    Key("species", "name", "string",
        "The species' name (letters, digits and `_`): it names the species in the per-pair tables "
        "(`\"glass-steel\"`), the output and the analysis.", default_text="required", per_species=True),
    Key("species", "count", "integer",
        "Number of particles of this species (give `count` for every species or `fraction` for every "
        "species); their sum is `system.particles`.", low=1, high=MAX_PARTICLES,
        reason="a species has particles; the engine indexes particles with int32", per_species=True),
    Key("species", "fraction", "number",
        "Instead of `count`: the species' share of `system.particles` (the fractions add up to 1; counts "
        "rounded by largest remainder).", low=0.0, high=1.0, low_open=True, reason="a share of the particles",
        per_species=True),
    Key("species", "diameter", "number", "Diameter of the species' particles.", default=1.0,
        unit="reference diameter", low=LENGTH_RANGE[0], high=LENGTH_RANGE[1], reason=_LENGTH, per_species=True),
    Key("species", "mass", "number", "Mass of one particle (give `mass` or `density`, not both).",
        default_text="1.0 when `density` is not given", unit="reference mass", low=SCALE_RANGE[0],
        high=SCALE_RANGE[1], reason=_SPEED, per_species=True),
    Key("species", "density", "number",
        "Instead of `mass`: mass = density × π d³/6 (3D) or π d²/4 (2D), as `particles.density`.",
        unit="reference mass per reference volume", low=0.0, low_open=True, high=1e250,
        reason="finite; the mass it gives is checked like `mass`", per_species=True),
    Key("species", "material_density", "number",
        "The material route, instead of `mass` or `density`: the species' material density; a particle "
        "of diameter d (reduced) has mass (material_density / `collision.material.density`) d³ (spheres, "
        "also in 2D, as the reference mass).", unit="kg/m³", low=SI_RANGE[0], high=SI_RANGE[1],
        reason="the reduced mass stays finite", per_species=True),
    Key("species", "young_modulus", "number",
        "The material route: the species' Young modulus (default: that of `[collision.material]`).",
        unit="Pa", low=SI_RANGE[0], high=SI_RANGE[1], reason="the reduced prefactor stays finite",
        per_species=True),
    Key("species", "poisson_ratio", "number",
        "The material route: the species' Poisson ratio (default: that of `[collision.material]`).",
        low=-1.0, high=0.5, low_open=True, high_open=True, reason="elastic stability", per_species=True),
    Key("species", "dissipation_time", "number",
        "The material route: the species' dissipative constant A (default: that of "
        "`[collision.material]`); a pair of species gets the effective modulus and the "
        "compliance-weighted A of the [mixtures page](mixtures.md#viscoelastic-pairs).",
        unit="s", low=0.0, high=SI_RANGE[1], reason="the reduced prefactor stays finite", per_species=True),
    # [driving]
    Key("driving", "model", "string",
        "White-noise driving: every particle receives independent Gaussian velocity kicks "
        "(total momentum conserved) at regular intervals.", default="white_noise", choices=DRIVING_MODELS),
    Key("driving", "heating_rate", "number",
        "dT/dt of the driving alone; the gas settles where it equals the collisional cooling. Required "
        "whenever `[driving]` is given.", unit="T0 per reduced time", low=0.0, high=SCALE_RANGE[1],
        reason="a heating rate; 0 switches the kicks off"),
    Key("driving", "interval", "number",
        "Time between kicks; observables are sampled half-way between kicks.",
        default_text="0.02 of the cooling time of the theoretical steady state", unit="reduced time",
        low=0.0, low_open=True, high=TIME_MAX, reason=_TIME),
    # [gravity]
    Key("gravity", "acceleration", "list of numbers",
        "Uniform acceleration g, one component per axis (x, y, z), on wall and periodic axes alike (a "
        "periodic axis falls freely); particles fly on parabolas between events. A gas at temperature T "
        "fills a height of about T / (m |g|) above a floor.",
        default_text="required in `[gravity]`", unit="reference diameter per reduced time²",
        low=-GRAVITY_MAX, high=GRAVITY_MAX, reason="g t² and the speeds g t stay finite in float64"),
    # [walls]
    *(Key("walls", side, "table",
          f"The {'lower' if side.endswith('low') else 'upper'} wall of the {side[0]} axis (a \"wall\" entry "
          "of `system.boundary`): an inline table of the keys of `[walls.<side>]` below, e.g. "
          '`{ kind = "vibrating", amplitude = 0.1, frequency = 2.0 }`.',
          default_text='a hard wall at rest') for side in WALL_SIDES),
    # [walls.<side>]
    Key("walls.<side>", "kind", "string",
        '`"hard"`: at rest, the run\'s restitution (`wall_restitution`); `"thermal"`: at rest, diffuse: '
        "the outgoing velocity drawn from the flux of a Maxwellian at `temperature`; `\"vibrating\"`: "
        "infinitely heavy, moving along its normal as `amplitude` × waveform(2π `frequency` t + `phase`) "
        "about a rest position `amplitude` inside the box, the run's restitution at the speed relative to "
        "the wall.", default="hard", choices=WALL_KINDS, template=True),
    Key("walls.<side>", "amplitude", "number", '`kind = "vibrating"`: the amplitude A (required).',
        unit="reference diameter", low=0.0, low_open=True, high=LENGTH_RANGE[1], reason=_LENGTH, template=True,
        run_check="the walls of an axis leave room at their closest: L - 2 A_low - 2 A_high above the box's "
                  "smallest side for the cell grid"),
    Key("walls.<side>", "frequency", "number", '`kind = "vibrating"`: the frequency ν = ω / 2π (required).',
        unit="per reduced time", low=0.0, low_open=True, high=1e50, reason="ν t stays finite in float64",
        template=True),
    Key("walls.<side>", "waveform", "string",
        '`kind = "vibrating"`: `"sine"`; `"triangle"` (the symmetric sawtooth: constant speed (2/π) A ω, '
        'turning at ±A); `"biparabolic"` (parabolic arcs through the sine\'s zeros and extremes, '
        "acceleration ∓(8/π²) A ω² on each half cycle).", default="sine", choices=WAVEFORMS, template=True),
    Key("walls.<side>", "phase", "number", '`kind = "vibrating"`: the phase φ at t = 0.', default=0.0,
        unit="radians", low=-1e6, high=1e6, reason="its fraction of a cycle keeps 1e-10 in float64",
        template=True),
    Key("walls.<side>", "temperature", "number", '`kind = "thermal"`: the wall temperature T_w (required).',
        unit="T0", low=SCALE_RANGE[0], high=SCALE_RANGE[1], reason=_SPEED, template=True),
    Key("driving", "rotational_fraction", "number",
        "Rough particles (`[collision.tangential]`): the fraction of the driving's power that goes to "
        "the spins as random angular-velocity kicks (the splitting thermostat of Megías & Santos 2022); "
        "the power per particle is d/2 × `heating_rate`, so 0 heats the translation alone at "
        "`heating_rate`.", default_text="0", low=0.0, high=1.0, reason="a fraction of the power"),
    # [shear]
    Key("shear", "rate", "number",
        "Uniform shear flow: the shear rate a of the flow a (y − L_y/2) along x, with Lees–Edwards "
        'boundaries on y (`system.boundary = ["periodic", "lees-edwards", ...]`; x periodic, z periodic '
        "or walls). Viscous heating balances the collisional loss of an inelastic gas; an elastic gas "
        "needs the thermostat. Required whenever `[shear]` is given.",
        unit="1 / reduced time", low=0.0, low_open=True, high=SCALE_RANGE[1], reason="a rate",
        run_check="the gas must reach its steady state (theory: the Grad solution) within the run: "
                  "a rate that drives it there more slowly, or past the clock's resolution, is refused"),
    Key("shear", "thermostat_temperature", "number",
        "A thermostat: the peculiar velocities (relative to the flow) are rescaled to this temperature "
        "at regular intervals (a Gaussian thermostat applied at discrete times, as in the elastic "
        "uniform shear flow of the literature). Leave it out for none.",
        unit="T0", low=SCALE_RANGE[0], high=SCALE_RANGE[1], reason=_SPEED),
    Key("shear", "thermostat_interval", "number",
        "Time between the thermostat's rescalings (with `thermostat_temperature`).",
        default_text="0.1 of the shorter of the mean free time at the thermostat temperature and "
                     "1 / rate", unit="reduced time",
        low=0.0, low_open=True, high=TIME_MAX, reason=_TIME,
        run_check="rate × interval must not exceed 0.5 (the viscous heating would change the "
                  "temperature by order one between two rescalings)"),
    # [run]
    Key("run", "end_time", "number",
        "Stop at this time (give `end_time`, `collisions_per_particle` or both; the first reached stops).",
        unit="reduced time", low=0.0, low_open=True, high=TIME_MAX, reason=_TIME,
        run_check="the float64 clock at end_time must resolve a millionth of the time between a "
                  "particle's events (mean free time or diameter crossing time at the predicted "
                  "final temperature), e.g. end_time below about 4e9 mean free times of an elastic gas"),
    Key("run", "collisions_per_particle", "number",
        "Stop after s = 2C/N collisions per particle (each pair collision counts for both partners).",
        low=0.0, low_open=True, high=float(MAX_COLLISIONS),
        reason="C = s N / 2 pair collisions must stay <= 2^53 (exact in float64; room in the int64 "
               "event counter)"),
    Key("run", "method", "string",
        '`"edmd"`: event-driven molecular dynamics (positions, walls, structure); `"dsmc"`: Direct '
        "Simulation Monte Carlo of the homogeneous Enskog–Boltzmann equation with the same collision rule "
        "(no positions: `particles` is the sample size, `packing_fraction` sets n and χ; no walls, "
        "no TC model).",
        default="edmd", choices=METHODS),
    Key("run", "neighbours", "string",
        'How the event-driven engine finds collision partners: `"lists"` neighbour lists with a shell '
        '(list expiries are events), `"cells"` cell crossings without lists (each particle is predicted '
        "against the particles of its own and the neighbouring cells; a cell crossing is an event), "
        '`"auto"` cells below packing 0.2 in 3D and 0.35 in 2D, where they were measured faster (see the '
        "performance page), lists otherwise. The choice changes which events run, so trajectories of the "
        "two agree only up to round-off; both are exact event-driven dynamics.",
        default="auto", choices=NEIGHBOURS),
    # [output]
    Key("output", "file", "string", "The H5MD output file, relative to the working directory.",
        default_text="runs/<config name>.h5",
        run_check="its directory must exist (it is not created); an existing file needs --overwrite"),
    Key("output", "snapshots", "integer",
        "Number of full snapshots, the initial and the final state included, log-spaced in time "
        "from `first_snapshot` to `end_time` (without `end_time`: log-spaced in collisions from one "
        "per particle to the budget).", default_text=str(DEFAULT_SNAPSHOTS), low=2,
        run_check="the schedule must fit in memory and the snapshots on the disk"),
    Key("output", "snapshot_interval", "number", "Instead of `snapshots`: a snapshot every this much time.",
        unit="reduced time", low=0.0, low_open=True, high=TIME_MAX, reason=_TIME,
        run_check="end_time / snapshot_interval snapshots must fit in memory and on the disk"),
    Key("output", "first_snapshot", "number", "Time of the first log-spaced snapshot after the start.",
        default_text="the Enskog mean free time at T0", unit="reduced time", low=0.0, low_open=True,
        high=TIME_MAX, reason=_TIME),
    Key("output", "observables_interval", "number",
        "Sampling interval of the observables (temperature, energies, counts, momentum, pressure); "
        "they are also sampled at every snapshot, at the start and at the end.",
        default_text="end_time / 200", unit="reduced time", low=0.0, low_open=True, high=TIME_MAX,
        reason=_TIME, run_check="end_time / observables_interval samples must fit in memory and on the disk"),
)

#: section -> its dataclass (sub-tables: the dataclass of the table)
SECTION_CLASSES = {
    "system": SystemConfig, "particles": ParticlesConfig, "initial": InitialConfig,
    "collision": CollisionConfig, "collision.material": MaterialConfig,
    "collision.tangential": TangentialConfig, "driving": DrivingConfig,
    "gravity": GravityConfig, "walls": WallsConfig, "walls.<side>": WallConfig, "shear": ShearConfig,
    "run": RunSection, "output": OutputConfig, "species": SpeciesConfig,
}
SECTIONS = ("system", "particles", "initial", "collision", "driving", "gravity", "walls", "shear", "run", "output",
            "species")
#: the array of tables of a mixture, one table per species
ARRAY_SECTIONS = ("species",)
#: the material constants a species may give (``[[species]]``) or take from ``[collision.material]``
MATERIAL_CONSTANTS = ("young_modulus", "poisson_ratio", "dissipation_time")
#: characters of a species name
_NAME_CHARACTERS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_")
#: sections that may be left out as a whole (absent: None in RunConfig)
OPTIONAL_SECTIONS = ("driving", "gravity", "walls", "shear")
#: the tables of ``[walls]``: each side's keys are the template keys of ``walls.<side>``
SIDE_TABLES = {f"walls.{side}": "walls.<side>" for side in WALL_SIDES}
#: keys whose value is a sub-table with its own section in SCHEMA
SUBTABLES = {"collision.material": "collision.material", "collision.tangential": "collision.tangential"}
#: keys that take a number or an inline table of sub-keys (dotted in SCHEMA)
INLINE_TABLES = {"particles.diameter": ("min", "max")}

_BY_DOTTED = {k.dotted: k for k in SCHEMA}


def config_schema() -> tuple[Key, ...]:
    """Every key, in the order of the reference (and of validation)."""
    return SCHEMA


# --------------------------------------------------------------------------- values and errors


def quote(text: str) -> str:
    """A string as a TOML basic string, control and line-break characters escaped, so that
    an error message naming it stays on one line."""
    out = []
    for ch in str(text):
        if ch in '"\\':
            out.append("\\" + ch)
        elif ch.isprintable() and ch not in "\x1c\x1d\x1e\x85\u2028\u2029":
            out.append(ch)
        else:
            code = ord(ch)
            out.append(f"\\u{code:04X}" if code <= 0xFFFF else f"\\U{code:08X}")
    return '"' + "".join(out) + '"'


class _Shown(str):
    """A value shown in a message as it is (e.g. ``{...}`` for a table)."""


def _show(value: Any) -> str:
    if isinstance(value, _Shown):
        return str(value)
    if isinstance(value, str):
        return quote(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_show(v)}" for k, v in value.items()) + " }"
    if isinstance(value, list):
        return "[" + ", ".join(_show(v) for v in value) + "]"
    if isinstance(value, float):
        short = f"{value:g}"
        return short if math.isnan(value) or float(short) == value else repr(value)
    return repr(value)


class Values:
    """The values of one document during validation: given or default, and where each came from."""

    def __init__(self, source: str, overridden: set[str]):
        self.source = source
        self.overridden = overridden
        self.value: dict[str, Any] = {}
        self.given: set[str] = set()
        self.raw: dict[str, Any] = {}
        self.sections: set[str] = set()
        #: the names of the ``[[species]]`` tables, in order (empty: one kind of particle)
        self.species: list[str] = []

    def origin(self, dotted: str) -> str:
        return "override" if dotted in self.overridden else self.source

    def where(self, dotted: str) -> str:
        return f"{self.origin(dotted)}: {dotted}"

    def fail(self, dotted: str, message: str, value: Any = ..., ) -> None:
        if value is ...:
            value = self.raw.get(dotted, ...)
        shown = "" if value is ... else f" = {_show(value)}"
        raise ConfigError(f"{self.where(dotted)}{shown}: {message}")

    def get(self, dotted: str):
        return self.value.get(dotted)

    def has(self, dotted: str) -> bool:
        return dotted in self.given

    def section_given(self, section: str) -> bool:
        return section in self.sections


def _check_type(key: Key, v: Any, values: Values, dimension: int):
    """The value converted to its type (int for integers, float for numbers) or a ConfigError."""
    d = key.dotted
    if key.type == "integer":
        if isinstance(v, float) and v.is_integer() and abs(v) < 2**53:
            v = int(v)
        if isinstance(v, bool) or not isinstance(v, int):
            values.fail(d, f"must be {key.range_text(dimension) if key.choices is None else 'an integer: ' + key.range_text()}")
        return v
    if key.type in TABLE_TYPES and isinstance(v, dict):
        return dict(v)  # checked entry by entry against the species (_check_species_tables)
    if key.type in ("number", "number or table") + tuple(TABLE_TYPES):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            extra = " or { min = ..., max = ... }" if key.type == "number or table" else \
                f" or {TABLE_TYPES[key.type]}" if key.type in TABLE_TYPES else ""
            values.fail(d, f"must be {key.range_text(dimension)}{extra}")
        return float(v)
    if key.type == "string":
        if not isinstance(v, str):
            values.fail(d, "must be a string")
        return v
    if key.type == "table":
        if not isinstance(v, dict):
            values.fail(d, "must be a table")
        return v
    if key.type == "list of strings":
        if not isinstance(v, list) or not all(isinstance(b, str) for b in v):
            values.fail(d, f"must be {key.range_text(dimension)}")
        return tuple(v)
    if key.type == "list of numbers":
        if not isinstance(v, list) or not all(isinstance(b, (int, float)) and not isinstance(b, bool) for b in v):
            values.fail(d, f"must be {key.range_text(dimension)}")
        return tuple(float(b) for b in v)
    raise AssertionError(key.type)


def _check_range(key: Key, v: Any, values: Values, dimension: int):
    d = key.dotted
    ok = True
    if key.type == "list of strings":
        axes = "x, y, z" if dimension == 3 else "x, y"
        allowed = ", ".join(f'"{c}"' for c in key.choices)
        if len(v) != dimension:
            values.fail(d, f"{len(v)} entries for a {dimension}D system: give one per axis ({axes}), "
                           f"each one of {allowed}")
        bad = [b for b in v if b not in key.choices]
        if bad:
            values.fail(d, f'"{bad[0]}" is not one of {allowed}')
        return
    if key.type == "list of numbers":
        axes = "x, y, z" if dimension == 3 else "x, y"
        if len(v) != dimension:
            values.fail(d, f"{len(v)} entries for a {dimension}D system: give one per axis ({axes})")
        for x in v:
            if not (math.isfinite(x) and key.low <= x <= key.high):
                values.fail(d, f"must be {key.range_text(dimension)} ({key.reason})")
        return
    if key.choices is not None:
        ok = v in key.choices
    elif key.type == "string":
        ok = bool(v.strip())
    elif key.type in TABLE_TYPES and isinstance(v, dict):
        return
    elif key.type in ("number", "integer", "number or table") + tuple(TABLE_TYPES):
        x = float(v)
        high = key.high_by_dimension[dimension] if key.high_by_dimension is not None else key.high
        ok = math.isfinite(x)
        if key.low is not None:
            ok &= x > key.low if key.low_open else x >= key.low
        if high is not None:
            ok &= x < high if key.high_open else x <= high
    if not ok:
        reason = ""
        if key.reason and key.type != "string" and key.choices is None:
            reason = f" ({key.reason})"
        if key.high_by_dimension is not None:
            reason = f" ({key.reason} in {dimension}D)"
        text = key.range_text(dimension)
        if key.type == "number or table":
            text += " or { min = ..., max = ... }"
        values.fail(d, f"must be {text}{reason}")


#: key types that take a number or, in a mixture, a table (what the table is keyed by)
TABLE_TYPES = {"number or table of pairs": 'a table { "a-b" = ..., ... } with one entry per pair of species',
               "number or table of species": 'a table { a = ..., ... } with one entry per species'}


# --------------------------------------------------------------------------- rules across keys


@dataclass(frozen=True)
class Rule:
    """A rule across keys: ``text`` for the reference, ``check(values)`` raises ConfigError."""

    text: str
    check: Callable[[Values], None]


def _model_is(*models):
    return lambda v: v.get("collision.model") in models


def _only_with(dotted: str, models: tuple[str, ...]) -> Rule:
    shown = " or ".join(f'"{m}"' for m in models)

    def check(v: Values):
        if v.has(dotted) and v.get("collision.model") not in models:
            value = _Shown("{...}") if dotted == "collision.material" else ...
            v.fail(dotted, f"is only used with model = {shown} (model = \"{v.get('collision.model')}\")", value)

    key = dotted.split(".", 1)[1]
    return Rule(f"`{key}` is used only with `model = {shown}`.", check)


def _exclusive(a: str, b: str, why: str = "") -> Rule:
    def check(v: Values):
        if v.has(a) and v.has(b):
            value = _Shown("{...}") if b == "collision.material" else ...
            v.fail(b, f"give either {a.split('.')[-1]} or {b.split('.')[-1]}, not both{why}", value)

    return Rule(f"`{a}` and `{b}` exclude each other.", check)


def _check_constant_needs_restitution(v: Values):
    if v.get("collision.model") == "constant" and not v.has("collision.restitution"):
        v.fail("collision.restitution", 'missing; model = "constant" needs restitution in (0, 1]')


def _check_viscoelastic_needs_contact(v: Values):
    if v.get("collision.model") == "viscoelastic" and not (v.has("collision.damping") or v.has("collision.material")):
        v.fail("collision.damping", 'missing; model = "viscoelastic" needs damping in [0, 40] or a '
                                    "[collision.material] table")


def _check_resolved_needs_material(v: Values):
    if v.get("collision.duration") != "resolved":
        return
    if v.get("collision.model") != "viscoelastic":
        v.fail("collision.duration", f'"resolved" needs model = "viscoelastic" (model = '
                                     f'"{v.get("collision.model")}" has no contact force to resolve)')
    if not v.has("collision.material"):
        v.fail("collision.duration", '"resolved" needs the contact stiffness: give [collision.material] '
                                     "(young_modulus, poisson_ratio, dissipation_time, ...) instead of damping, "
                                     "which fixes beta but not the contact time")
    boundary = v.get("system.boundary")
    if boundary is not None and "wall" in boundary:
        v.fail("collision.duration", '"resolved" is available with periodic boundaries only '
                                     "(system.boundary has a wall)")
    if v.get("run.method") == "dsmc":
        v.fail("collision.duration", '"resolved" needs positions: it is for run.method = "edmd" (DSMC has '
                                     "instantaneous collisions only)")
    if v.get("run.neighbours") == "cells":
        v.fail("run.neighbours", '"cells" does not take collisions that take time (collision.duration = '
                                 '"resolved" needs neighbour lists: use "lists" or "auto")')


def _check_run_has_an_end(v: Values):
    if not (v.has("run.end_time") or v.has("run.collisions_per_particle")):
        raise ConfigError(f"{v.source}: run: needs end_time and/or collisions_per_particle (both > 0)")


def _check_needs_end_time(v: Values):
    if v.has("run.end_time"):
        return
    for key in ("output.snapshot_interval", "output.first_snapshot", "output.observables_interval"):
        if v.has(key):
            v.fail(key, "needs run.end_time (without it, output is scheduled in collisions per particle)")


def _check_first_snapshot_below_end(v: Values):
    first, end = v.get("output.first_snapshot"), v.get("run.end_time")
    if first is not None and end is not None and first >= end:
        v.fail("output.first_snapshot", f"must be below run.end_time = {end:g}")


def _check_first_snapshot_log_spaced(v: Values):
    if v.has("output.snapshot_interval") and v.has("output.first_snapshot"):
        v.fail("output.first_snapshot", "is only used for log-spaced snapshots (without snapshot_interval)")


def _check_diameter_range(v: Values):
    lo, hi = v.get("particles.diameter.min"), v.get("particles.diameter.max")
    if lo is not None and hi is not None and lo > hi:
        v.fail("particles.diameter", "needs min <= max", v.raw.get("particles.diameter"))


def _check_masses_from_density(v: Values):
    rho = v.get("particles.density")
    if rho is None:
        return
    dim = v.get("system.dimension")
    lo = v.get("particles.diameter.min") or v.get("particles.diameter")
    hi = v.get("particles.diameter.max") or v.get("particles.diameter")
    unit = math.pi / 6.0 if dim == 3 else math.pi / 4.0
    m_lo, m_hi = rho * unit * lo**dim, rho * unit * hi**dim
    if not (SCALE_RANGE[0] <= m_lo and m_hi <= SCALE_RANGE[1]):
        v.fail("particles.density", f"gives masses {m_lo:.3g} to {m_hi:.3g}, outside [1e-100, 1e100] "
                                    f"({_SPEED})")


def _check_collision_count(v: Values):
    s, n = v.get("run.collisions_per_particle"), v.get("system.particles")
    if s is not None and 0.5 * s * n > MAX_COLLISIONS:
        v.fail("run.collisions_per_particle",
               f"gives {0.5 * s * n:.3g} pair collisions for {n} particles; at most 2^53 = {MAX_COLLISIONS:.4g} "
               f"(exact in float64)")


def _check_wall_restitution_needs_walls(v: Values):
    boundary = v.get("system.boundary")
    if v.has("collision.wall_restitution") and (boundary is None or "wall" not in boundary):
        v.fail("collision.wall_restitution", 'is only used with walls (system.boundary with a "wall" entry)')


def _check_driving_needs_heating_rate(v: Values):
    if v.section_given("driving") and not v.has("driving.heating_rate"):
        v.fail("driving.heating_rate", "missing; [driving] needs heating_rate >= 0 (dT/dt of the driving alone)")


def _check_gravity_needs_acceleration(v: Values):
    if v.section_given("gravity") and not v.has("gravity.acceleration"):
        v.fail("gravity.acceleration", "missing; [gravity] needs acceleration = [gx, gy(, gz)], one entry per axis")


def _check_walls_on_wall_axes(v: Values):
    boundary = v.get("system.boundary") or ("periodic",) * v.get("system.dimension")
    for side in WALL_SIDES:
        table = f"walls.{side}"
        if not v.has(table):
            continue
        a = "xyz".index(side[0])
        if a >= v.get("system.dimension"):
            v.fail(table, f"a {v.get('system.dimension')}D system has no {side[0]} axis", _Shown("{...}"))
        if boundary[a] != "wall":
            v.fail(table, f'the {side[0]} axis is "{boundary[a]}" (system.boundary = '
                          f'[{", ".join(chr(34) + b + chr(34) for b in boundary)}]): a wall of any kind needs a '
                          '"wall" axis', _Shown("{...}"))


#: the keys each wall kind takes besides ``kind`` (required first, then optional)
_WALL_KEYS = {"hard": ((), ()), "thermal": (("temperature",), ()),
              "vibrating": (("amplitude", "frequency"), ("waveform", "phase"))}


def _check_wall_kind_keys(v: Values):
    for side in WALL_SIDES:
        table = f"walls.{side}"
        if not v.has(table):
            continue
        kind = v.get(f"{table}.kind")
        required, optional = _WALL_KEYS[kind]
        for key in required:
            if not v.has(f"{table}.{key}"):
                v.fail(f"{table}.{key}", f'missing; kind = "{kind}" needs {" and ".join(required)}')
        for key in ("amplitude", "frequency", "waveform", "phase", "temperature"):
            if v.has(f"{table}.{key}") and key not in required + optional:
                users = [k for k, (r, o) in _WALL_KEYS.items() if key in r + o]
                v.fail(f"{table}.{key}", f'is only used with kind = "{users[0]}" (kind = "{kind}")')


def _check_elastic_below(v: Values):
    if v.has("collision.elastic_below") and v.get("collision.duration") == "resolved":
        v.fail("collision.elastic_below", 'collisions that take time (duration = "resolved") have no '
                                          "restitution to set to 1")


def _check_species_scene(v: Values):
    if not v.species:
        return
    if v.section_given("gravity"):
        raise ConfigError(f"{v.source}: [gravity]: not available with [[species]] (a mixture runs without gravity; "
                          "gravity takes one kind of particle, [particles])")
    for side in WALL_SIDES:
        if v.has(f"walls.{side}") and v.get(f"walls.{side}.kind") != "hard":
            v.fail(f"walls.{side}", f'kind = "{v.get(f"walls.{side}.kind")}" is not available with [[species]] (a '
                                    'mixture takes hard walls at rest only)', _Shown("{...}"))


def _check_dsmc_supported(v: Values):
    if v.get("run.method") != "dsmc":
        return
    for section in ("gravity", "walls"):
        if v.section_given(section):
            raise ConfigError(f"{v.source}: [{section}]: needs positions: method = \"dsmc\" simulates a "
                              f"homogeneous gas (use method = \"edmd\")")
    if v.has("collision.elastic_below"):
        v.fail("collision.elastic_below", 'guards against the inelastic collapse of a spatial gas: not '
                                          'available with method = "dsmc"')
    boundary = v.get("system.boundary")
    if boundary is not None and "wall" in boundary:
        v.fail("system.boundary", 'walls need positions: method = "dsmc" simulates a homogeneous gas '
                                  '(use method = "edmd" or an all-"periodic" boundary)')
    if v.has("collision.tc_time"):
        v.fail("collision.tc_time", 'the TC model needs pair histories of a spatial gas: not available with '
                                    'method = "dsmc" (a homogeneous DSMC gas shows no inelastic collapse)')


def _check_shear(v: Values):
    boundary = v.get("system.boundary")
    marked = [a for a, b in enumerate(boundary or ()) if b == "lees-edwards"]
    if not v.section_given("shear"):
        if marked:
            v.fail("system.boundary", '"lees-edwards" needs [shear] (the rate of the flow along x)')
        return
    if not v.has("shear.rate"):
        v.fail("shear.rate", "missing; [shear] needs rate > 0 (the flow a (y - L_y/2) along x)")
    if marked != [1] or boundary[0] != "periodic":
        shown = boundary if boundary is not None else ("periodic",) * int(v.get("system.dimension"))
        v.fail("system.boundary", 'a shear flow needs "lees-edwards" on y and a periodic x, e.g. '
                                  f'{_show(["periodic", "lees-edwards"] + ["periodic"] * (len(shown) - 2))} '
                                  "(walls only on z)", list(shown))
    if v.get("collision.duration") == "resolved":
        v.fail("collision.duration", '"resolved" is not available with [shear] (Lees-Edwards boundaries)')
    if v.has("shear.thermostat_interval") and not v.has("shear.thermostat_temperature"):
        v.fail("shear.thermostat_interval", "needs shear.thermostat_temperature")
    if getattr(v, "species", None):
        v.fail("shear.rate", "[shear] is not available with [[species]] (uniform shear flow of one kind of "
                             "particle only)")
    if v.has("collision.tangential"):
        v.fail("collision.tangential", "rough particles are not available with [shear] (uniform shear flow of "
                                       "smooth particles only)", _Shown("{...}"))
    if v.section_given("driving"):
        v.fail("driving.heating_rate", "[driving] is not available with [shear] (the shear's thermostat holds "
                                       "the temperature of a sheared gas)")
    if v.section_given("gravity"):
        v.fail("gravity.acceleration", "[gravity] is not available with [shear] (uniform shear flow without an "
                                       "external field)")
    for side in WALL_SIDES:
        if v.has(f"walls.{side}") and v.get(f"walls.{side}.kind") != "hard":
            v.fail(f"walls.{side}", f'kind = "{v.get(f"walls.{side}.kind")}" is not available with [shear]: '
                                    "Lees-Edwards boundaries take hard walls at rest only (on z)", _Shown("{...}"))
    lo, hi = v.get("particles.diameter.min"), v.get("particles.diameter.max")
    if v.get("run.method") == "dsmc" and lo is not None and hi is not None and lo < hi:
        v.fail("particles.diameter", 'the DSMC of uniform shear flow takes identical particles: one diameter '
                                     '(or method = "edmd")', v.raw.get("particles.diameter"))
    eps = v.get("collision.restitution")
    elastic = v.get("collision.model") == "elastic" or (
        v.get("collision.model") == "constant" and isinstance(eps, (int, float)) and eps == 1.0)
    if elastic and not v.has("shear.thermostat_temperature"):
        v.fail("shear.rate", 'an elastic gas only heats under shear and never reaches a steady state: give '
                             "shear.thermostat_temperature or an inelastic collision model")


_ROUGH_KEYS = ("particles.inertia", "initial.rotational_temperature", "driving.rotational_fraction")


def _check_rough_keys_need_tangential(v: Values):
    if v.has("collision.tangential"):
        return
    for dotted in _ROUGH_KEYS:
        if v.has(dotted):
            v.fail(dotted, "is for rough particles: give a [collision.tangential] table (model, restitution) "
                           "to let the particles spin")


def _check_tangential(v: Values):
    if not v.has("collision.tangential"):
        return
    model = v.get("collision.tangential.model")
    if model == "coulomb" and not v.has("collision.tangential.friction"):
        v.fail("collision.tangential.friction", 'missing; model = "coulomb" needs friction >= 0 (the Coulomb '
                                                "limit of the tangential impulse)")
    for key in ("friction", "wall_friction"):
        if model != "coulomb" and v.has(f"collision.tangential.{key}"):
            v.fail(f"collision.tangential.{key}", f'is only used with model = "coulomb" (model = "{model}": '
                                                  "a constant tangential restitution has no friction)")
    boundary = v.get("system.boundary")
    for key in ("wall_restitution", "wall_friction"):
        if v.has(f"collision.tangential.{key}") and (boundary is None or "wall" not in boundary):
            v.fail(f"collision.tangential.{key}", 'is only used with walls (system.boundary with a "wall" entry)')
    if v.get("collision.duration") == "resolved":
        v.fail("collision.tangential", 'rough particles need instantaneous collisions: the resolved contact '
                                       '(collision.duration = "resolved") is frictionless', _Shown("{...}"))
    if v.species:
        v.fail("collision.tangential", "a config takes rough particles of one kind, not a mixture ([[species]]): "
                                       "rough mixtures run from Python (docs/rough.md)", _Shown("{...}"))
    if v.section_given("gravity"):
        raise ConfigError(f"{v.source}: [gravity]: not available with rough particles ([collision.tangential]) in "
                          "a config: rough grains under gravity run from Python (docs/gravity-and-vibrating-walls.md)")
    for side in WALL_SIDES:
        if v.has(f"walls.{side}") and v.get(f"walls.{side}.kind") != "hard":
            v.fail(f"walls.{side}", f'kind = "{v.get(f"walls.{side}.kind")}" is not available with rough particles '
                                    "([collision.tangential]): they take hard walls at rest only", _Shown("{...}"))
# ------------------------------------------------------------------ [[species]]


def _species_label(table: dict, index: int) -> str:
    name = table.get("name") if isinstance(table, dict) else None
    ok = isinstance(name, str) and name and set(name) <= _NAME_CHARACTERS
    return f"species.{name}" if ok else f"species[{index}]"


def _check_species_structure(tables: Any, values: Values):
    """``[[species]]`` is a non-empty array of tables of known keys."""
    if not isinstance(tables, list) or not tables or not all(isinstance(t, dict) for t in tables):
        raise ConfigError(f"{values.source}: species: must be an array of tables, one [[species]] table per "
                          "species (name, count or fraction, diameter, mass or density)")
    known = _section_keys("species")
    for k, table in enumerate(tables):
        label = _species_label(table, k)
        for key, value in table.items():
            if key not in known:
                values.fail(f"{label}.{key}", f"unknown key{_suggest(key, known)} (a species has "
                                             f"{', '.join(known)})", value)


def _check_species_keys(tables: Any, values: Values, dimension: int):
    """Each species' keys by the ``per_species`` keys of :data:`SCHEMA` (as
    ``species.<name>.<key>``), unique names, and the counts: given, or from the fractions."""
    from dataclasses import replace

    values.species = []
    if tables is None:
        return
    for k, table in enumerate(tables):
        name = table.get("name")
        if name is None:
            raise ConfigError(f"{values.source}: species[{k}].name: missing; every [[species]] needs a name")
        if not (isinstance(name, str) and name and set(name) <= _NAME_CHARACTERS):
            values.fail(f"species[{k}].name", 'must be a name of letters, digits and _ (a pair of species is '
                                              'named "a-b")', name)
        if name in values.species:
            values.fail(f"species.{name}.name", f"two species are named {name}: names must be unique", name)
        values.species.append(name)
        for template in (key for key in SCHEMA if key.per_species and key.key != "name"):
            key = replace(template, key=f"{name}.{template.key}", per_species=False)
            dotted = key.dotted
            if template.key not in table:
                values.value[dotted] = key.default
                continue
            values.raw[dotted] = table[template.key]
            values.given.add(dotted)
            v = _check_type(key, table[template.key], values, dimension)
            _check_range(key, v, values, dimension)
            values.value[dotted] = v


def _resolve_species_counts(values: Values):
    """``species.<name>.count`` for every species: given, or the fractions of ``system.particles``
    rounded by largest remainder; ``system.particles`` their sum."""
    names = values.species
    if not names:
        return
    counted = [n for n in names if values.has(f"species.{n}.count")]
    shared = [n for n in names if values.has(f"species.{n}.fraction")]
    for n in names:
        if values.has(f"species.{n}.count") and values.has(f"species.{n}.fraction"):
            values.fail(f"species.{n}.fraction", "give either count or fraction, not both")
        if not (values.has(f"species.{n}.count") or values.has(f"species.{n}.fraction")):
            values.fail(f"species.{n}.count", "missing; every species needs count (an integer >= 1) or fraction")
    if counted and shared:
        values.fail(f"species.{shared[0]}.fraction", f"give count for every species or fraction for every species "
                                                     f"(species.{counted[0]} gives count)")
    if counted:
        total = sum(values.get(f"species.{n}.count") for n in names)
        if values.has("system.particles") and values.get("system.particles") != total:
            listed = ", ".join(f"{n} {values.get('species.' + n + '.count')}" for n in names)
            values.fail("system.particles", f"the species' counts add up to {total} ({listed})")
        if total > MAX_PARTICLES:
            values.fail(f"species.{names[-1]}.count", f"the counts add up to {total}, beyond {MAX_PARTICLES} "
                                                      "(the engine indexes particles with int32)")
        values.value["system.particles"] = total
        return
    fractions = [values.get(f"species.{n}.fraction") for n in names]
    total = math.fsum(fractions)
    if abs(total - 1.0) > 1e-9:
        listed = ", ".join(f"{n} {f:g}" for n, f in zip(names, fractions))
        values.fail(f"species.{names[-1]}.fraction", f"the fractions add up to {total:.12g} ({listed}), not 1")
    n_total = values.get("system.particles")
    exact = [f / total * n_total for f in fractions]
    counts = [math.floor(x) for x in exact]
    for k in sorted(range(len(names)), key=lambda k: (counts[k] - exact[k], k))[:n_total - sum(counts)]:
        counts[k] += 1
    for name, count, f in zip(names, counts, fractions):
        if count == 0:
            values.fail(f"species.{name}.fraction", f"gives no particle of system.particles = {n_total}: a species "
                                                    "needs particles (a larger fraction or more particles)")
        values.value[f"species.{name}.count"] = count


def _pair_entries(v: Values, dotted: str):
    """The entries of a per-pair table keyed by the species' names (checked: known names, each
    pair once, every pair given, values in the key's range); {(i, j): value} with i <= j."""
    key = _BY_DOTTED[dotted]
    table = v.get(dotted)
    names = v.species
    out = {}
    for pair, value in table.items():
        parts = str(pair).split("-")
        shown = f"{dotted}.{quote(str(pair))}"
        if f"{dotted}.{pair}" in v.overridden:
            v.overridden.add(shown)
        if len(parts) != 2 or not all(parts):
            v.fail(shown, f'a pair of species is "a-b" with a, b among {", ".join(names)}', value)
        for part in parts:
            if part not in names:
                v.fail(shown, f"no species named {part} (species: {', '.join(names)}){_suggest(part, names)}", value)
        i, j = sorted(names.index(p) for p in parts)
        if (i, j) in out:
            v.fail(shown, f"the pair {names[i]}-{names[j]} is given twice (a-b and b-a are the same pair)", value)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(float(value)) or not (
                (float(value) > key.low if key.low_open else float(value) >= key.low) and float(value) <= key.high):
            v.fail(shown, f"must be {key.range_text()}" + (f" ({key.reason})" if key.reason else ""), value)
        out[(i, j)] = float(value)
    for i, a in enumerate(names):
        for j, b in enumerate(names[i:], i):
            if (i, j) not in out:
                v.fail(dotted, f'no law for the pair {a}-{b}: give every pair of species, e.g. "{a}-{b}" = ...',
                       _Shown("{...}"))
    return out


def _check_species_tables(v: Values):
    """Per-pair and per-species tables: only with [[species]], keyed by its names, complete."""
    for dotted in ("collision.restitution", "collision.damping", "collision.wall_restitution"):
        if not isinstance(v.get(dotted), dict):
            continue
        if not v.species:
            v.fail(dotted, "a table per pair or per species needs [[species]] (with one kind of particle give a "
                           "number)", _Shown("{...}"))
        if dotted != "collision.wall_restitution":
            normal = _pair_entries(v, dotted)
            names = v.species
            v.value[dotted] = {pair_key(names[i], names[j]): x for (i, j), x in sorted(normal.items())}
            continue
        key = _BY_DOTTED[dotted]
        for name, value in v.get(dotted).items():
            shown = f"{dotted}.{name}"
            if name not in v.species:
                v.fail(shown, f"no species named {name} (species: {', '.join(v.species)})"
                              f"{_suggest(str(name), v.species)}", value)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (0.0 < float(value) <= 1.0):
                v.fail(shown, f"must be {key.range_text()}", value)


def _check_species_particles(v: Values):
    """[[species]] replaces [particles]; each species has mass or density, not both, in range."""
    if not v.species:
        return
    for key in ("particles.diameter", "particles.mass", "particles.density"):
        if v.has(key):
            v.fail(key, "is not used with [[species]] (each species gives its own diameter and mass or density)")
    dim = v.get("system.dimension")
    unit = math.pi / 6.0 if dim == 3 else math.pi / 4.0
    for name in v.species:
        if v.has(f"species.{name}.mass") and v.has(f"species.{name}.density"):
            v.fail(f"species.{name}.density", "give either mass or density, not both")
        rho = v.get(f"species.{name}.density")
        if rho is not None:
            mass = rho * unit * v.get(f"species.{name}.diameter") ** dim
            if not SCALE_RANGE[0] <= mass <= SCALE_RANGE[1]:
                v.fail(f"species.{name}.density", f"gives the mass {mass:.3g}, outside [1e-100, 1e100] ({_SPEED})")
        if v.has(f"species.{name}.material_density"):
            for other in ("mass", "density"):
                if v.has(f"species.{name}.{other}"):
                    v.fail(f"species.{name}.material_density", f"give one of mass, density, material_density "
                                                               f"(the species gives {other})")
            if not v.has("collision.material"):
                v.fail(f"species.{name}.material_density", "is used with the material route: give "
                                                           "[collision.material] (its density is the reference)")
            mass = (v.get(f"species.{name}.material_density") / v.get("collision.material.density")
                    * v.get(f"species.{name}.diameter") ** 3)
            if not SCALE_RANGE[0] <= mass <= SCALE_RANGE[1]:
                v.fail(f"species.{name}.material_density", f"gives the mass {mass:.3g}, outside [1e-100, 1e100] "
                                                           f"({_SPEED})")


def _check_species_material(v: Values):
    """The material route of a mixture: every species has Y, nu and A (its own or those of
    [collision.material]); material constants of a species need [collision.material] (the units)."""
    if not v.species:
        return
    material = v.has("collision.material")
    for name in v.species:
        for const in MATERIAL_CONSTANTS:
            own = v.has(f"species.{name}.{const}")
            if own and not material:
                v.fail(f"species.{name}.{const}", "is used with the material route: give [collision.material] "
                                                  '(diameter, density, speed_unit) and model = "viscoelastic"')
            if material and not own and v.get(f"collision.material.{const}") is None:
                v.fail(f"species.{name}.{const}", f"missing; give it in this species or in [collision.material] "
                                                  f"(the value of the species that give none)")
    if v.get("collision.duration") == "resolved":
        v.fail("collision.duration", '"resolved" takes one material: a mixture ([[species]]) needs instantaneous '
                                     "collisions")


RULES: tuple[Rule, ...] = (
    Rule("`[[species]]`: every species has a unique `name` and `count` (an integer >= 1) or `fraction`, the "
         "same form for all; the fractions add up to 1 and give every species a particle; counts add up to "
         "`system.particles` when it is given.", _resolve_species_counts),
    Rule("Tables per pair of species (`restitution`, `damping`) need `[[species]]` and give every pair once "
         '(`"a-b"` or `"b-a"`); `wall_restitution` per species names known species.', _check_species_tables),
    Rule("`[[species]]` replaces `[particles]`; each species gives `mass` or `density`, not both.",
         _check_species_particles),
    Rule("The material route of a mixture: every species has `young_modulus`, `poisson_ratio` and "
         "`dissipation_time`, its own or those of `[collision.material]`; a mixture's collisions are "
         "instantaneous.", _check_species_material),
    Rule('`model = "constant"` needs `restitution`.', _check_constant_needs_restitution),
    _only_with("collision.restitution", ("constant",)),
    _only_with("collision.tc_time", ("constant",)),
    _only_with("collision.damping", ("viscoelastic",)),
    _only_with("collision.material", ("viscoelastic",)),
    Rule('`model = "viscoelastic"` needs `damping` or `[collision.material]`.', _check_viscoelastic_needs_contact),
    _exclusive("collision.damping", "collision.material"),
    Rule('`duration = "resolved"` needs `model = "viscoelastic"` with `[collision.material]`, periodic '
         'boundaries, `method = "edmd"` and neighbour lists (`neighbours` not `"cells"`; `"auto"` then '
         'uses lists).', _check_resolved_needs_material),
    Rule("`diameter = { min, max }` needs both keys and min <= max (min = max is monodisperse).",
         _check_diameter_range),
    _exclusive("particles.mass", "particles.density"),
    Rule("The masses `density` gives (for the smallest and largest diameter) lie in the range of `mass`.",
         _check_masses_from_density),
    Rule("`[run]` needs `end_time`, `collisions_per_particle` or both.", _check_run_has_an_end),
    Rule("`collisions_per_particle` × `particles` / 2 pair collisions at most 2^53.", _check_collision_count),
    _exclusive("output.snapshots", "output.snapshot_interval", " (snapshots: log-spaced)"),
    Rule("`first_snapshot` is for log-spaced snapshots only (not with `snapshot_interval`).",
         _check_first_snapshot_log_spaced),
    Rule("Without `end_time` the output is scheduled in collisions: `snapshot_interval`, `first_snapshot` "
         "and `observables_interval` need `end_time`.", _check_needs_end_time),
    Rule("`first_snapshot` lies below `end_time`.", _check_first_snapshot_below_end),
    _only_with("collision.wall_restitution", ("constant",)),
    Rule('`wall_restitution` is used only with walls (a `"wall"` entry in `boundary`).',
         _check_wall_restitution_needs_walls),
    Rule("`[driving]` needs `heating_rate`.", _check_driving_needs_heating_rate),
    _only_with("collision.elastic_below", ("constant", "viscoelastic")),
    Rule('`elastic_below` is not used with `duration = "resolved"`.', _check_elastic_below),
    Rule("`[[species]]` (a mixture) takes no `[gravity]` and only hard walls in `[walls]`.", _check_species_scene),
    Rule("`[gravity]` needs `acceleration`.", _check_gravity_needs_acceleration),
    Rule('A side of `[walls]` belongs to an axis of the system whose `boundary` entry is `"wall"` (a '
         "vibrating or thermal wall on a periodic axis is refused).", _check_walls_on_wall_axes),
    Rule('A vibrating wall needs `amplitude` and `frequency` (and may take `waveform`, `phase`), a thermal '
         "one `temperature`; a key of another kind is refused.", _check_wall_kind_keys),
    Rule('`method = "dsmc"` (homogeneous, no positions) takes no walls, no `[gravity]`, no `[walls]`, no '
         "`tc_time` and no `elastic_below`.", _check_dsmc_supported),
    Rule("`inertia`, `rotational_temperature` and `rotational_fraction` are for rough particles: they need "
         "`[collision.tangential]`.", _check_rough_keys_need_tangential),
    Rule('`[collision.tangential]`: `model = "coulomb"` needs `friction`; `friction` and `wall_friction` '
         'are only used with `"coulomb"`, `wall_restitution` and `wall_friction` only with walls; rough '
         'particles need `duration = "instantaneous"` and one kind of particle (no `[[species]]`), and take no '
         '`[gravity]` and only hard walls in `[walls]`.',
         _check_tangential),
    Rule('`[shear]` needs `rate` and `boundary` with `"lees-edwards"` on y and a periodic x (walls only on '
         'z), and `"lees-edwards"` needs `[shear]`; not with `duration = "resolved"`, `[driving]`, '
         '`[gravity]`, thermal or vibrating `[walls]`, `[[species]]` nor `[collision.tangential]`; with '
         '`method = "dsmc"` one diameter; an elastic gas needs the thermostat; `thermostat_interval` needs '
         "`thermostat_temperature`.", _check_shear),
)


def config_rules() -> tuple[Rule, ...]:
    """The rules across keys, in the order they are checked."""
    return RULES


# --------------------------------------------------------------------------- parsing


def load_config(path, overrides: dict[str, Any] | None = None) -> RunConfig:
    """Read, override and validate a TOML run configuration.

    Parameters
    ----------
    path : str or Path
        The TOML file.
    overrides : dict, optional
        Dotted keys to set before validation, e.g.
        ``{"collision.restitution": 0.8, "system.seed": 3, "output.file": "x.h5"}``;
        validated exactly like values from the file.

    Returns
    -------
    RunConfig

    Raises
    ------
    ConfigError
        Missing/unreadable file, TOML syntax error, unknown key, wrong type or
        out-of-range value (one line naming file, key, value and what is allowed).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: config file not found") from None
    except IsADirectoryError:
        raise ConfigError(f"{path}: is a directory, not a config file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read config file ({exc})") from None
    return parse_config(text, source=str(path), overrides=overrides)


def parse_config(text: str, source: str = "<config>", overrides: dict[str, Any] | None = None) -> RunConfig:
    """Validate TOML text (see :func:`load_config`)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: TOML syntax error: {exc}") from None
    overridden = apply_overrides(data, overrides or {}, source)
    return build_config(data, source=source, text=text, overridden=overridden)


def _suggest(name: str, candidates) -> str:
    close = difflib.get_close_matches(name, list(candidates), n=1, cutoff=0.6)
    return f"; did you mean `{close[0]}`?" if close else ""


def _section_keys(section: str) -> list[str]:
    """TOML keys of a section (inline-table sub-keys and sub-tables by their first part)."""
    return list(dict.fromkeys(k.key.split(".")[0] for k in SCHEMA if k.section == section))


def _nearest_key(parts: list[str]) -> str | None:
    """The schema key nearest a dotted key whose section is misspelt: the nearest section,
    then the nearest key in it (``sytem.particle``: ``system.particles``), else a key of that
    name in any section, else the section alone."""
    close = difflib.get_close_matches(parts[0], SECTIONS, n=1, cutoff=0.6)
    if not close:
        return None
    section = close[0]
    in_section = [k.dotted[len(section) + 1:] for k in SCHEMA if k.section.split(".")[0] == section and not k.template]
    key = difflib.get_close_matches(".".join(parts[1:]), in_section, n=1, cutoff=0.6)
    if key:
        return f"{section}.{key[0]}"
    by_name = {k.dotted.split(".")[-1]: k.dotted for k in SCHEMA if not k.template}  # not walls.<side>.*
    name = difflib.get_close_matches(parts[-1], list(by_name), n=1, cutoff=0.75)
    return by_name[name[0]] if name else section


def apply_overrides(data: dict, overrides: dict[str, Any], source: str = "<config>") -> set[str]:
    """Set dotted keys in a nested dict in place; return the set of keys set."""
    done = set()
    for dotted, value in overrides.items():
        parts = str(dotted).split(".")
        if len(parts) < 2 or not all(parts):
            raise ConfigError(f"override: {dotted} = {_show(value)}: key must be section.key with section "
                              f"one of {', '.join(SECTIONS)}")
        if parts[0] not in SECTIONS:
            near = _nearest_key(parts)
            hint = f"; did you mean `{near}`?" if near else ""
            raise ConfigError(f"override: {dotted} = {_show(value)}: unknown section {parts[0]} (allowed: "
                              f"{', '.join(SECTIONS)}){hint}")
        node = data
        if parts[0] in ARRAY_SECTIONS:
            node = _species_override(data, parts, dotted, value)
            parts = parts[2:]
        for part in parts[:-1]:
            nxt = node.setdefault(part, {})
            if not isinstance(nxt, dict):
                raise ConfigError(f"override: {dotted} = {_show(value)}: {part} is not a table")
            node = nxt
        if len(parts) == 3 and parts[0] == "collision" and parts[1] in ("restitution", "damping"):
            a, _, b = parts[2].partition("-")
            node.pop(f"{b}-{a}", None)  # a pair's override replaces it in either order
        node[parts[-1]] = value
        done.add(str(dotted))
    return done


def _species_override(data: dict, parts: list, dotted: str, value) -> dict:
    """The ``[[species]]`` table an override ``species.<name>.<key>`` addresses."""
    tables = data.get("species")
    names = [t.get("name") for t in tables] if isinstance(tables, list) and all(
        isinstance(t, dict) for t in tables) else []
    if len(parts) != 3:
        raise ConfigError(f"override {dotted} = {_show(value)}: a species key is species.<name>.<key>, e.g. "
                          f"species.{names[0] if names else 'glass'}.diameter")
    if parts[1] not in names:
        hint = _suggest(parts[1], [n for n in names if isinstance(n, str)])
        listed = ", ".join(str(n) for n in names) or "none"
        raise ConfigError(f"override {dotted} = {_show(value)}: no species named {parts[1]} (species: {listed}){hint}")
    return tables[names.index(parts[1])]


def _check_structure(data: dict, values: Values):
    """Unknown sections and keys (with the nearest valid name), non-table sections."""
    all_keys = {k.dotted.split(".")[-1]: k.dotted for k in SCHEMA if not k.template}
    for name, table in data.items():
        if name in ARRAY_SECTIONS and name in SECTIONS:
            _check_species_structure(table, values)
            continue
        if name not in SECTIONS:
            origin = "override" if any(o.startswith(name + ".") for o in values.overridden) else values.source
            close = difflib.get_close_matches(name, SECTIONS, n=1, cutoff=0.6)
            hint = f"; did you mean [{close[0]}]?" if close else ""
            raise ConfigError(f"{origin}: [{name}]: unknown section (allowed: "
                              f"{', '.join(f'[[{s}]]' if s in ARRAY_SECTIONS else f'[{s}]' for s in SECTIONS)}){hint}")
        _check_table(name, table, values, all_keys)


def _check_table(section: str, table: Any, values: Values, all_keys: dict):
    if not isinstance(table, dict):
        values.fail(section, "must be a table", table)
    known = _section_keys(section)
    for key, value in table.items():
        dotted = f"{section}.{key}"
        if key not in known:
            hint = _suggest(key, known)
            if not hint:  # a key of another section, maybe misspelt too
                close = difflib.get_close_matches(key, list(all_keys), n=1, cutoff=0.75)
                if close and all_keys[close[0]] != dotted:
                    hint = f"; did you mean `{all_keys[close[0]]}`?"
            values.fail(dotted, f"unknown key{hint}", value)
        if dotted in SUBTABLES:
            if not isinstance(value, dict):
                values.fail(dotted, "must be a table", value)
            _check_table(SUBTABLES[dotted], value, values, all_keys)
        elif dotted in SIDE_TABLES:
            if not isinstance(value, dict):
                values.fail(dotted, 'must be a table, e.g. { kind = "vibrating", amplitude = 0.1, frequency = 2.0 }',
                            value)
            subs = _section_keys(SIDE_TABLES[dotted])
            for sub, subvalue in value.items():
                if sub not in subs:
                    values.fail(f"{dotted}.{sub}", f"unknown key{_suggest(sub, subs)}", subvalue)
        elif dotted in INLINE_TABLES and isinstance(value, dict):
            subs = INLINE_TABLES[dotted]
            for sub, subvalue in value.items():
                if sub not in subs:
                    values.fail(f"{dotted}.{sub}", f"unknown key{_suggest(sub, subs)}", subvalue)


def _lookup(data: dict, key: Key):
    """(present, value) of a schema key in the document."""
    node = data
    for part in key.section.split(".") + key.key.split("."):
        if not isinstance(node, dict) or part not in node:
            return False, None
        node = node[part]
    return True, node


def build_config(data: dict, *, source: str = "<config>", text: str = "", overridden=frozenset()) -> RunConfig:
    """Validate a parsed TOML document (nested dict) into a :class:`RunConfig` (module docstring)."""
    values = Values(source, set(overridden))
    _check_structure(data, values)
    values.sections = set(data)
    dimension = 3
    for key in SCHEMA:
        if key.template or key.per_species:
            continue
        dotted = key.dotted
        present, raw = _lookup(data, key)
        if dotted in INLINE_TABLES and present and isinstance(raw, dict):
            values.raw[dotted] = raw
            values.given.add(dotted)
            sub_keys = [f"{dotted}.{s}" for s in INLINE_TABLES[dotted]]
            missing = [s for s in sub_keys if s.split(".")[-1] not in raw]
            if missing:
                values.fail(dotted, f"needs both {' and '.join(s.split('.')[-1] for s in sub_keys)}, "
                                    "e.g. { min = 0.8, max = 1.2 }", raw)
            continue  # the sub-keys are checked as their own entries
        if dotted in SUBTABLES:
            if present:
                values.given.add(dotted)
                values.raw[dotted] = raw
            continue
        if not present:
            parent = key.section if key.section in SUBTABLES else None
            optional = MATERIAL_CONSTANTS if "species" in data else ()  # a mixture's species may give them
            if key.required_in_table and parent and parent in values.given and key.key not in optional:
                required = [k.key for k in SCHEMA if k.section == key.section and k.required_in_table
                            and k.key not in optional]
                missing = [k for k in required if k not in values.raw[parent]]
                raise ConfigError(f"{values.where(parent)}: missing key(s) {', '.join(missing)} "
                                  f"(all of {', '.join(required)} are needed)")
            values.value[dotted] = key.default
            continue
        values.raw[dotted] = raw
        values.given.add(dotted)
        v = _check_type(key, raw, values, dimension)
        _check_range(key, v, values, dimension)
        if dotted == "system.dimension":
            dimension = v
        values.value[dotted] = v
    _check_side_tables(values, dimension)
    _check_species_keys(data.get("species"), values, dimension)
    for rule in RULES:
        rule.check(values)
    return _assemble(values, source, text)


def _check_side_tables(values: Values, dimension: int):
    """The keys of each ``[walls]`` side table given, as ``walls.<side>.<key>``: type and range
    by the template keys of ``walls.<side>`` (absent keys take their defaults)."""
    from dataclasses import replace

    for table in SIDE_TABLES:
        if table not in values.given:
            continue
        raw = values.raw[table]
        for template in (k for k in SCHEMA if k.template):
            key = replace(template, section="walls", key=f"{table.split('.')[1]}.{template.key}", template=False)
            dotted = key.dotted
            if template.key not in raw:
                values.value[dotted] = key.default
                continue
            values.raw[dotted] = raw[template.key]
            values.given.add(dotted)
            v = _check_type(key, raw[template.key], values, dimension)
            _check_range(key, v, values, dimension)
            values.value[dotted] = v


def _assemble(values: Values, source: str, text: str) -> RunConfig:
    """The dataclasses from the checked values (plus the few values derived from others)."""
    v = dict(values.value)
    # derived values: the mean diameter of a polydisperse mix, the default mass, the default file
    lo, hi = v.get("particles.diameter.min"), v.get("particles.diameter.max")
    if lo is not None:
        v["particles.diameter"] = 0.5 * (lo + hi)
        if lo == hi:
            v["particles.diameter.min"] = v["particles.diameter.max"] = None
    if v.get("particles.mass") is None and v.get("particles.density") is None:
        v["particles.mass"] = 1.0
    if v.get("output.file") is None:
        v["output.file"] = default_output(source)
    if v.get("system.boundary") is None:
        v["system.boundary"] = ("periodic",) * v["system.dimension"]
    material = tangential = None
    if values.has("collision.material"):
        material = MaterialConfig(**{k.attribute: v[k.dotted] for k in SCHEMA if k.section == "collision.material"})
    if values.has("collision.tangential"):
        tangential = TangentialConfig(**{k.attribute: v[k.dotted] for k in SCHEMA
                                         if k.section == "collision.tangential"})
        # rough particles: the defaults that depend on other keys
        if v.get("particles.inertia") is None:
            v["particles.inertia"] = DEFAULT_INERTIA[v["system.dimension"]]
        if v.get("initial.rotational_temperature") is None:
            v["initial.rotational_temperature"] = v["initial.temperature"]

    def section(name):
        kwargs = {k.attribute: v[k.dotted] for k in SCHEMA if k.section == name and k.dotted not in SUBTABLES}
        if name == "gravity" and kwargs.get("acceleration") is None:
            kwargs.pop("acceleration")
        if name == "collision":
            kwargs["material"] = material
            kwargs["tangential"] = tangential
        return SECTION_CLASSES[name](**kwargs)

    def walls():
        sides = {}
        for side in WALL_SIDES:
            if f"walls.{side}" in values.given:
                kind = v[f"walls.{side}.kind"]
                used = ("kind",) + _WALL_KEYS[kind][0] + _WALL_KEYS[kind][1]
                sides[side] = WallConfig(**{k.key: v[f"walls.{side}.{k.key}"] if k.key in used else None
                                            for k in SCHEMA if k.template})
        return WallsConfig(**sides)

    parts = {s: (walls() if s == "walls" else section(s)) if s not in OPTIONAL_SECTIONS or s in values.sections
             else None for s in SECTIONS if s not in ARRAY_SECTIONS}
    for name in values.species:
        if v[f"species.{name}.material_density"] is not None:  # the reduced mass of the material route
            v[f"species.{name}.mass"] = (v[f"species.{name}.material_density"] / v["collision.material.density"]
                                         * v[f"species.{name}.diameter"] ** 3)
        elif v[f"species.{name}.mass"] is None and v[f"species.{name}.density"] is None:
            v[f"species.{name}.mass"] = 1.0
    species = tuple(SpeciesConfig(name=name, **{k.attribute: v[f"species.{name}.{k.key}"] for k in SCHEMA
                                                if k.per_species and k.key != "name"})
                    for name in values.species)
    return RunConfig(**parts, source=source, text=text, species=species)


def default_output(source: str) -> str:
    """``runs/<config name>.h5`` for a config file, ``runs/run.h5`` for text without a file."""
    return f"runs/{Path(source).stem}.h5" if source and not source.startswith("<") else "runs/run.h5"


# --------------------------------------------------------------------------- writing


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    raise TypeError(v)


def dump_toml(config: RunConfig) -> str:
    """Resolved config as TOML (round-trips through :func:`parse_config`), key order of :data:`SCHEMA`."""
    lines = [f"# resolved from {config.source}"]
    objects = {s: getattr(config, s) for s in SECTIONS if s not in ARRAY_SECTIONS}
    objects["collision.material"] = config.collision.material
    objects["collision.tangential"] = config.collision.tangential
    # [[species]] in place of [particles], which then holds at most the rough particles' inertia
    mixed = {"particles": ("inertia",)} if config.species else {}
    if config.species and config.particles.inertia is None:
        objects["particles"] = None
    for name in tuple(objects):
        obj = objects[name]
        if obj is None:
            continue
        lines.append(f"\n[{name}]")
        if name == "walls":
            for side in WALL_SIDES:
                wall = getattr(obj, side)
                if wall is not None:
                    subs = ", ".join(f"{k.key} = {_toml_value(getattr(wall, k.key))}" for k in SCHEMA
                                     if k.template and getattr(wall, k.key) is not None)
                    lines.append(f"{side} = {{ {subs} }}")
            continue
        for key in SCHEMA:
            if key.section != name or key.dotted in SUBTABLES or key.dotted.startswith(tuple(f"{t}." for t in INLINE_TABLES)):
                continue
            if name in mixed and key.key not in mixed[name]:
                continue
            if key.dotted in INLINE_TABLES and getattr(obj, "polydisperse", False):
                subs = ", ".join(f"{s} = {getattr(obj, f'{key.key}_{s}')!r}" for s in INLINE_TABLES[key.dotted])
                lines.append(f"{key.key} = {{ {subs} }}")
                continue
            value = getattr(obj, key.attribute)
            if isinstance(value, tuple) and key.type == "list of numbers":
                lines.append(f"{key.key} = [{', '.join(_toml_value(float(x)) for x in value)}]")
            elif isinstance(value, tuple):
                lines.append(f"{key.key} = [{', '.join(_toml_value(x) for x in value)}]")
            elif isinstance(value, dict):
                entries = ", ".join(f"{quote(k)} = {_toml_value(x)}" for k, x in value.items())
                lines.append(f"{key.key} = {{ {entries} }}")
            elif value is not None:
                lines.append(f"{key.key} = {_toml_value(value)}")
    for sp in config.species:
        lines.append("\n[[species]]")
        lines.append(f"name = {_toml_value(sp.name)}")
        lines.append(f"count = {sp.count}")  # resolved: the counts the run uses
        for key in SCHEMA:
            if key.per_species and key.key not in ("name", "count", "fraction"):
                if key.key == "mass" and sp.material_density is not None:
                    continue  # set from material_density
                value = getattr(sp, key.attribute)
                if value is not None:
                    lines.append(f"{key.key} = {_toml_value(value)}")
    return "\n".join(lines) + "\n"
