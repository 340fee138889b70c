"""TOML run configuration -> frozen dataclasses, with validation.

A config file has the sections ``[system]``, ``[particles]``, ``[initial]``,
``[collision]`` (with the optional sub-table ``[collision.material]``),
``[driving]`` (optional), ``[run]`` and ``[output]``; :func:`load_config` reads it with :mod:`tomllib`, applies
optional dotted-key overrides, and returns a :class:`RunConfig`. Every value is
checked once, here: unknown keys, wrong types and out-of-range values raise
:class:`granulargas.errors.ConfigError` with one line naming the file, the key,
the value and what is allowed.

Units (reduced): lengths in the reference particle diameter, masses in the
reference particle mass, energies in the initial temperature T0 (k_B = 1), so
time in sigma sqrt(m/T0). The material route (``[collision.material]``) gives
the reference particle's SI diameter and density and the SI velocity unit
``speed_unit`` (= sqrt(T0/m) for temperature 1); :mod:`granulargas.run.prepare`
converts it once to the reduced pair prefactor k (ARCHITECTURE.md).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from granulargas.errors import ConfigError

#: Densest packings: FCC spheres pi/(3 sqrt 2), hexagonal disks pi/(2 sqrt 3).
MAX_PACKING = {3: math.pi / (3.0 * math.sqrt(2.0)), 2: math.pi / (2.0 * math.sqrt(3.0))}
MODELS = ("elastic", "constant", "viscoelastic")
CONTACT_ENDS = ("overlap", "force")
BOUNDARIES = ("periodic", "wall")
DRIVING_MODELS = ("white_noise",)
DEFAULT_SNAPSHOTS = 20


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
class ParticlesConfig:
    """``[particles]``: diameters (uniform in [diameter_min, diameter_max] when
    polydisperse) and either a common ``mass`` or a ``density`` (mass = density
    x volume, volume pi d^3/6 in 3D and pi d^2/4 in 2D)."""

    diameter: float = 1.0
    diameter_min: float | None = None
    diameter_max: float | None = None
    mass: float | None = 1.0
    density: float | None = None

    @property
    def polydisperse(self) -> bool:
        return self.diameter_min is not None


@dataclass(frozen=True)
class InitialConfig:
    """``[initial]``: Maxwell-Boltzmann temperature, or a file to continue from."""

    temperature: float = 1.0
    from_file: str | None = None  # TOML key "from"


@dataclass(frozen=True)
class MaterialConfig:
    """``[collision.material]`` (SI): the viscoelastic contact of Schwager & Pöschel (1997), eq. (2).

    young_modulus (Pa), poisson_ratio, dissipation_time A (s), diameter (m) and
    density (kg/m^3) of the reference particle, speed_unit (m/s): the reduced
    velocity unit sqrt(T0/m)."""

    young_modulus: float
    poisson_ratio: float
    dissipation_time: float
    diameter: float
    density: float
    speed_unit: float


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
    walls, viscoelastic runs the sphere-plane contact of the same material."""

    model: str = "viscoelastic"
    restitution: float | None = None
    damping: float | None = None
    material: MaterialConfig | None = None
    contact_end: str = "overlap"
    tc_time: float | None = None
    wall_restitution: float | None = None


@dataclass(frozen=True)
class DrivingConfig:
    """``[driving]`` (optional): white-noise driving, every particle kicked by independent
    Gaussian velocity kicks (momentum-conserving) that raise the temperature at
    ``heating_rate`` (dT/dt of the driving alone, T0 per time unit); ``interval``
    between kicks (default: 0.02 of the theoretical steady state's cooling time,
    :func:`granulargas.theory.driving_interval`)."""

    model: str = "white_noise"
    heating_rate: float = 0.0
    interval: float | None = None


@dataclass(frozen=True)
class RunSection:
    """``[run]``: stop at ``end_time`` or after ``collisions_per_particle``,
    whichever comes first (at least one is required). Collisions per particle
    count each pair collision for both partners: s = 2 C / N (kinetic theory)."""

    end_time: float | None = None
    collisions_per_particle: float | None = None


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

    def to_toml(self) -> str:
        """The resolved configuration (defaults filled in) as TOML text."""
        return dump_toml(self)


# --------------------------------------------------------------------------- parsing


class _Reader:
    """Pulls typed, range-checked values out of one TOML table."""

    def __init__(self, source: str, section: str, table: Any, overridden: set[str]):
        self.source = source
        self.section = section
        self.overridden = overridden
        if not isinstance(table, dict):
            self.fail_key(None, table, "a table")
        self.table = dict(table)

    def where(self, key: str | None) -> str:
        dotted = f"{self.section}.{key}" if key else self.section
        origin = "override" if dotted in self.overridden else self.source
        return f"{origin}: {dotted}"

    def fail(self, key: str | None, value: Any, allowed: str):
        raise ConfigError(f"{self.where(key)} = {_show(value)}: {allowed}")

    def fail_key(self, key, value, allowed):
        self.fail(key, value, f"must be {allowed}")

    def pop(self, key, default=None):
        return self.table.pop(key, default)

    def integer(self, key, default, *, minimum=None, allowed=None):
        if key not in self.table:
            return default
        v = self.table.pop(key)
        if isinstance(v, float) and v.is_integer() and abs(v) < 2**53:
            v = int(v)
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail_key(key, v, "an integer")
        if allowed is not None and v not in allowed:
            self.fail_key(key, v, " or ".join(str(a) for a in allowed))
        if minimum is not None and v < minimum:
            self.fail_key(key, v, f"an integer >= {minimum}")
        return v

    def number(self, key, default, *, low=None, high=None, low_open=True, high_open=False, what=None):
        if key not in self.table:
            return default
        v = self.table.pop(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self.fail_key(key, v, "a number")
        v = float(v)
        bad = not math.isfinite(v)
        if low is not None:
            bad |= v <= low if low_open else v < low
        if high is not None:
            bad |= v >= high if high_open else v > high
        if bad:
            self.fail_key(key, v, what or _interval(low, high, low_open, high_open))
        return v

    def string(self, key, default, *, allowed=None):
        if key not in self.table:
            return default
        v = self.table.pop(key)
        if not isinstance(v, str):
            self.fail_key(key, v, "a string")
        if allowed is not None and v not in allowed:
            self.fail_key(key, v, "one of " + ", ".join(f'"{a}"' for a in allowed))
        return v

    def done(self):
        for key, value in self.table.items():
            self.fail(key, value, "unknown key")


def _interval(low, high, low_open, high_open):
    if high is None:
        return f"a number {'>' if low_open else '>='} {low:g}"
    if low is None:
        return f"a number {'<' if high_open else '<='} {high:g}"
    return f"in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"


def _show(value: Any) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_show(v)}" for k, v in value.items()) + " }"
    if isinstance(value, list):
        return "[" + ", ".join(_show(v) for v in value) + "]"
    return repr(value) if not isinstance(value, float) else f"{value:g}"


SECTIONS = ("system", "particles", "initial", "collision", "driving", "run", "output")


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


def apply_overrides(data: dict, overrides: dict[str, Any], source: str = "<config>") -> set[str]:
    """Set dotted keys in a nested dict in place; return the set of keys set."""
    done = set()
    for dotted, value in overrides.items():
        parts = str(dotted).split(".")
        if len(parts) < 2 or not all(parts) or parts[0] not in SECTIONS:
            raise ConfigError(
                f"override {dotted} = {_show(value)}: key must be section.key with section one of {', '.join(SECTIONS)}"
            )
        node = data
        for part in parts[:-1]:
            nxt = node.setdefault(part, {})
            if not isinstance(nxt, dict):
                raise ConfigError(f"override {dotted}: {part} is not a table")
            node = nxt
        node[parts[-1]] = value
        done.add(".".join(parts))
    return done


def build_config(data: dict, *, source: str = "<config>", text: str = "", overridden=frozenset()) -> RunConfig:
    """Validate a parsed TOML document (nested dict) into a :class:`RunConfig`."""
    overridden = set(overridden)
    for key, value in data.items():
        if key not in SECTIONS:
            origin = "override" if any(o.startswith(key + ".") for o in overridden) else source
            raise ConfigError(
                f"{origin}: [{key}]: unknown section (allowed: {', '.join(f'[{s}]' for s in SECTIONS)})"
            )

    def reader(section):
        return _Reader(source, section, data.get(section, {}), overridden)

    # [system]
    r = reader("system")
    dimension = r.integer("dimension", 3, allowed=(2, 3))
    particles = r.integer("particles", SystemConfig.particles, minimum=2)
    eta_max = MAX_PACKING[dimension]
    packing = r.number(
        "packing_fraction",
        SystemConfig.packing_fraction,
        low=0.0,
        high=eta_max,
        high_open=True,
        what=f"in (0, {eta_max:.4f}) (densest packing of {'spheres' if dimension == 3 else 'disks'} in {dimension}D)",
    )
    seed = r.integer("seed", 1, minimum=0)
    boundary = ("periodic",) * dimension
    if "boundary" in r.table:
        raw = r.pop("boundary")
        if not isinstance(raw, list) or not all(isinstance(b, str) for b in raw):
            r.fail_key("boundary", raw, f"a list of {dimension} strings, each one of "
                       + ", ".join(f'"{b}"' for b in BOUNDARIES))
        if len(raw) != dimension:
            r.fail("boundary", raw, f"{len(raw)} entries for a {dimension}D system: give one per axis "
                   f"(x, y{', z' if dimension == 3 else ''}), each one of "
                   + ", ".join(f'"{b}"' for b in BOUNDARIES))
        bad = [b for b in raw if b not in BOUNDARIES]
        if bad:
            r.fail("boundary", raw, f'"{bad[0]}" is not one of ' + ", ".join(f'"{b}"' for b in BOUNDARIES))
        boundary = tuple(raw)
    r.done()
    system = SystemConfig(dimension, particles, packing, seed, boundary)

    # [particles]
    r = reader("particles")
    diameter, dmin, dmax = 1.0, None, None
    if "diameter" in r.table:
        raw = r.table["diameter"]
        if isinstance(raw, dict):
            r.pop("diameter")
            sub = _Reader(source, "particles.diameter", raw, overridden)
            dmin = sub.number("min", None, low=0.0)
            dmax = sub.number("max", None, low=0.0)
            sub.done()
            if dmin is None or dmax is None:
                r.fail("diameter", raw, "needs both min and max, e.g. { min = 0.8, max = 1.2 }")
            if dmin > dmax:
                r.fail("diameter", raw, "needs min <= max")
            diameter = 0.5 * (dmin + dmax)
            if dmin == dmax:
                dmin = dmax = None
        else:
            diameter = r.number("diameter", 1.0, low=0.0, what="a number > 0 or { min = ..., max = ... }")
    mass = r.number("mass", None, low=0.0)
    density = r.number("density", None, low=0.0)
    if mass is not None and density is not None:
        r.fail("density", density, "give either mass or density, not both")
    if mass is None and density is None:
        mass = 1.0
    r.done()
    particles_cfg = ParticlesConfig(diameter, dmin, dmax, mass, density)

    # [initial]
    r = reader("initial")
    temperature = r.number("temperature", 1.0, low=0.0)
    from_file = r.string("from", None)
    if from_file is not None and not from_file:
        r.fail("from", from_file, "must be a file name")
    r.done()
    initial = InitialConfig(temperature, from_file)

    # [collision]
    r = reader("collision")
    model = r.string("model", "viscoelastic", allowed=MODELS)
    restitution = r.number("restitution", None, low=0.0, high=1.0, what="in (0, 1]")
    damping = r.number("damping", None, low=0.0, low_open=False, what="a number >= 0")
    contact_end = r.string("contact_end", "overlap", allowed=CONTACT_ENDS)
    # > 0, as CollisionRule.constant asserts: tc_time = 0 would make no collision elastic (the
    # TC model off) while still tracking and writing last-collision times; leave the key out instead
    tc_time = r.number("tc_time", None, low=0.0, low_open=True,
                       what="a number > 0 (TC-model time; leave tc_time out for no TC model)")
    wall_restitution = r.number("wall_restitution", None, low=0.0, high=1.0, what="in (0, 1]")
    material = None
    if "material" in r.table:
        m = _Reader(source, "collision.material", r.pop("material"), overridden)
        vals = {}
        specs = {
            "young_modulus": dict(low=0.0, what="a number > 0 (Pa)"),
            "poisson_ratio": dict(low=-1.0, high=0.5, high_open=True, what="in (-1, 0.5)"),
            "dissipation_time": dict(low=0.0, low_open=False, what="a number >= 0 (s)"),
            "diameter": dict(low=0.0, what="a number > 0 (m)"),
            "density": dict(low=0.0, what="a number > 0 (kg/m^3)"),
            "speed_unit": dict(low=0.0, what="a number > 0 (m/s)"),
        }
        for key, spec in specs.items():
            vals[key] = m.number(key, None, **spec)
        m.done()
        missing = [k for k, v in vals.items() if v is None]
        if missing:
            raise ConfigError(f"{m.where(None)}: missing key(s) {', '.join(missing)} (all of {', '.join(specs)} are needed)")
        material = MaterialConfig(**vals)
    r.done()
    if model == "constant":
        if restitution is None:
            raise ConfigError(f"{r.where('restitution')}: missing; model = \"constant\" needs restitution in (0, 1]")
        for key, val in (("damping", damping), ("material", material)):
            if val is not None:
                r.fail(key, val if key != "material" else "{...}", 'is only used with model = "viscoelastic"')
    elif model == "viscoelastic":
        if restitution is not None:
            r.fail("restitution", restitution, 'is only used with model = "constant"')
        if tc_time is not None:
            r.fail("tc_time", tc_time, 'is only used with model = "constant"')
        if damping is None and material is None:
            raise ConfigError(
                f"{r.where('damping')}: missing; model = \"viscoelastic\" needs damping >= 0 or a [collision.material] table"
            )
        if damping is not None and material is not None:
            r.fail("damping", damping, "give either damping or [collision.material], not both")
    else:  # elastic
        for key, val in (("restitution", restitution), ("damping", damping), ("material", material), ("tc_time", tc_time)):
            if val is not None:
                r.fail(key, val if key != "material" else "{...}", 'is not used with model = "elastic"')
    if wall_restitution is not None:
        if model != "constant":
            r.fail("wall_restitution", wall_restitution, 'is only used with model = "constant" (elastic '
                   "runs have elastic walls, viscoelastic ones the sphere-plane contact)")
        if not system.walls:
            r.fail("wall_restitution", wall_restitution, 'is only used with walls (system.boundary with '
                   'a "wall" entry)')
    collision = CollisionConfig(model, restitution, damping, material, contact_end, tc_time,
                                wall_restitution)

    # [driving]
    driving = None
    if "driving" in data:
        r = reader("driving")
        dmodel = r.string("model", "white_noise", allowed=DRIVING_MODELS)
        if "heating_rate" not in r.table:
            raise ConfigError(f"{r.where('heating_rate')}: missing; [driving] needs heating_rate >= 0 "
                              "(dT/dt of the driving alone)")
        heating = r.number("heating_rate", None, low=0.0, low_open=False,
                           what="a number >= 0 (dT/dt of the driving alone)")
        interval = r.number("interval", None, low=0.0, what="a number > 0 (time between kicks)")
        r.done()
        driving = DrivingConfig(dmodel, heating, interval)

    # [run]
    r = reader("run")
    end_time = r.number("end_time", None, low=0.0)
    cpp = r.number("collisions_per_particle", None, low=0.0)
    r.done()
    if end_time is None and cpp is None:
        raise ConfigError(f"{source}: run: needs end_time and/or collisions_per_particle (both > 0)")
    run = RunSection(end_time, cpp)

    # [output]
    r = reader("output")
    default_file = f"runs/{Path(source).stem}.h5" if source and not source.startswith("<") else "runs/run.h5"
    file = r.string("file", default_file)
    if not file.strip():
        r.fail("file", file, "must be a file name")
    snapshots = r.integer("snapshots", None, minimum=2)
    snap_dt = r.number("snapshot_interval", None, low=0.0)
    if snapshots is not None and snap_dt is not None:
        r.fail("snapshot_interval", snap_dt, "give either snapshots (log-spaced) or snapshot_interval, not both")
    first = r.number("first_snapshot", None, low=0.0)
    obs_dt = r.number("observables_interval", None, low=0.0)
    if snap_dt is not None and first is not None:
        r.fail("first_snapshot", first, "is only used for log-spaced snapshots (without snapshot_interval)")
    if end_time is None:
        for key, val in (("snapshot_interval", snap_dt), ("first_snapshot", first), ("observables_interval", obs_dt)):
            if val is not None:
                r.fail(key, val, "needs run.end_time (without it, output is scheduled in collisions per particle)")
    if end_time is not None and first is not None and first >= end_time:
        r.fail("first_snapshot", first, f"must be below run.end_time = {end_time:g}")
    r.done()
    output = OutputConfig(file, snapshots, snap_dt, first, obs_dt)

    return RunConfig(system, particles_cfg, initial, collision, run, output, source=source, text=text,
                     driving=driving)


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
    """Resolved config as TOML (round-trips through :func:`parse_config`)."""
    lines = [f"# resolved from {config.source}"]

    def section(name, pairs):
        lines.append(f"\n[{name}]")
        for k, v in pairs:
            if v is not None:
                lines.append(f"{k} = {v if isinstance(v, _Raw) else _toml_value(v)}")

    s, p, i, c, r, o = (config.system, config.particles, config.initial, config.collision, config.run, config.output)
    boundary = _Raw("[" + ", ".join(_toml_value(b) for b in s.boundary) + "]")
    section("system", [(f.name, boundary if f.name == "boundary" else getattr(s, f.name))
                       for f in fields(s)])
    diam = _Raw(f"{{ min = {p.diameter_min!r}, max = {p.diameter_max!r} }}") if p.polydisperse else p.diameter
    section("particles", [("diameter", diam), ("mass", p.mass), ("density", p.density)])
    section("initial", [("temperature", i.temperature), ("from", i.from_file)])
    section(
        "collision",
        [("model", c.model), ("restitution", c.restitution), ("damping", c.damping),
         ("contact_end", c.contact_end), ("tc_time", c.tc_time), ("wall_restitution", c.wall_restitution)],
    )
    if c.material is not None:
        section("collision.material", [(f.name, getattr(c.material, f.name)) for f in fields(c.material)])
    if config.driving is not None:
        section("driving", [(f.name, getattr(config.driving, f.name)) for f in fields(config.driving)])
    section("run", [(f.name, getattr(r, f.name)) for f in fields(r)])
    section("output", [(f.name, getattr(o, f.name)) for f in fields(o)])
    return "\n".join(lines) + "\n"


class _Raw(str):
    """A pre-formatted TOML value."""
