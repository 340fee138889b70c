"""MkDocs hook: pages generated from the code at build time.

A page that contains one of the markers below gets it replaced by generated
Markdown, so that the text cannot drift from the code it describes:

``<!-- generated: config-reference -->``
    Every section and key of the run configuration: type, default, allowed
    values, meaning (:func:`config_reference_markdown`).
``<!-- generated: cli-reference -->``
    The ``--help`` text of every command (:func:`cli_reference_markdown`).

The docstrings use Sphinx roles (``:func:`name```), which mkdocstrings shows
verbatim; :func:`on_page_content` drops the role prefix and keeps the code span.

Where the configuration reference comes from
--------------------------------------------
:func:`config_entries` returns one :class:`ConfigKey` per key. If
``granulargas.io.config`` provides ``config_schema()`` (an iterable of objects
with the attributes ``section``, ``key``, ``type``, ``default``, ``allowed`` and
``meaning``, all strings except that ``default`` may be any TOML value or None),
the reference is that schema, rendered as is. Otherwise the entries are derived
from the validator as it is written today: the keys, their order and their
dataclass defaults from the dataclasses of ``granulargas.io.config``; the type
and the allowed values from the validator's own error messages (each key is set
to a value of the wrong type and to an out-of-range value, and the one-line
``ConfigError`` says what is allowed); only the meaning, and defaults that the
validator computes (e.g. the output file name), come from :data:`MEANINGS` below.
A key of a config dataclass without an entry in :data:`MEANINGS` fails the
build, and so does an entry whose key the validator rejects as unknown.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import io
import os
import re
from dataclasses import dataclass
from typing import Any

CONFIG_MARKER = "<!-- generated: config-reference -->"
CLI_MARKER = "<!-- generated: cli-reference -->"


class Text(str):
    """A default described in words (computed by the validator), not a TOML value."""


@dataclass(frozen=True)
class ConfigKey:
    """One key of the run configuration, as the reference shows it."""

    section: str  # "system", "collision.material", ...
    key: str  # "packing_fraction", "diameter.min", ...
    type: str  # "integer", "number", "string", "number or table", ...
    default: Any  # a TOML value, None (no default) or Text (a default described in words)
    allowed: str  # what the validator accepts
    meaning: str

    @property
    def dotted(self) -> str:
        return f"{self.section}.{self.key}"


# ----------------------------------------------------------------------------------------
# What the code does not say (yet): the meaning of each key, defaults the validator
# computes, and the context in which a key can be set (for probing the validator).
# Keys are (section, TOML key). "context" is merged into a minimal valid document.

_VISCO = {"collision": {"model": "viscoelastic", "damping": 0.1}}
_CONSTANT = {"collision": {"model": "constant", "restitution": 0.9}}
_MATERIAL = {"collision": {"model": "viscoelastic", "material": {
    "young_modulus": 1.0e7, "poisson_ratio": 0.3, "dissipation_time": 1.0e-5,
    "diameter": 0.01, "density": 1000.0, "speed_unit": 1.0}}}

_WALLS_CONSTANT = {"system": {"boundary": ["periodic", "periodic", "wall"]},
                   "collision": {"model": "constant", "restitution": 0.9}}
_DRIVEN = {"collision": {"model": "constant", "restitution": 0.9}, "driving": {"heating_rate": 0.1}}

MEANINGS: dict[tuple[str, str], dict] = {
    ("system", "dimension"): dict(meaning="2 (disks) or 3 (spheres)."),
    ("system", "particles"): dict(
        meaning="Number of particles; the box must hold at least 3.05 largest diameters per side."),
    ("system", "packing_fraction"): dict(
        meaning="Fraction of the volume (area in 2D) covered by the particles; sets the box. "
                "Random placement works up to about 0.54 (3D) and 0.76 (2D).",
        also=[("in 2D", {"system": {"dimension": 2}})]),
    ("system", "seed"): dict(
        meaning="Seed of all randomness (diameters, positions, velocities, the driving's kicks); a "
                "seed gives the same initial state on every machine."),
    ("system", "boundary"): dict(
        meaning="One entry per axis (x, y, z): `\"periodic\"`, or `\"wall\"` for flat hard walls at 0 "
                "and L (no sphere may start overlapping them; sphere-wall collisions follow the "
                "collision model with R_eff = R, m_eff = m). A wall axis must be at least 4.15 largest "
                "diameters long; the packing fraction counts the whole box ([Walls and driving](walls-and-driving.md)).",
        type="list of strings", allowed='one entry per dimension, each "periodic" or "wall"',
        default=Text("all \"periodic\"")),
    ("particles", "diameter"): dict(
        meaning="Particle diameter, or `{ min = ..., max = ... }` for a uniform polydisperse mix "
                "(the reference diameter is then the mean)."),
    ("particles", "diameter.min"): dict(meaning="Smallest diameter of a polydisperse mix.",
                                        probe_table=True),
    ("particles", "diameter.max"): dict(meaning="Largest diameter of a polydisperse mix.",
                                        probe_table=True),
    ("particles", "mass"): dict(meaning="Mass of every particle (give `mass` or `density`, not both).",
                                default="1.0 when `density` is not given"),
    ("particles", "density"): dict(
        meaning="Instead of `mass`: mass = density × π d³/6 (3D) or π d²/4 (2D)."),
    ("initial", "temperature"): dict(
        meaning="Maxwell–Boltzmann velocities with zero total momentum and exactly this "
                "temperature T = m⟨c²⟩/d."),
    ("initial", "from"): dict(
        meaning="Start from the last snapshot of this granulargas H5MD file instead (time, event "
                "count, collisions and dissipated energy continue; box, radii and masses come "
                "from the file; `dimension` and `particles` must match). Same as `--restart`."),
    ("collision", "model"): dict(meaning="The coefficient of restitution: elastic, constant, or "
                                         "the viscoelastic ε(g) of the contact law."),
    ("collision", "restitution"): dict(
        meaning="`model = \"constant\"` only: the constant ε.", context=_CONSTANT),
    ("collision", "damping"): dict(
        meaning="`model = \"viscoelastic\"` only: β at normal impact speed 1 for two reference "
                "particles (diameter 1, mass 1); other pairs scale with R_eff and m_eff, "
                "β = k (R_eff g / m_eff²)^(1/5). Give `damping` or `[collision.material]`.",
        context=_VISCO),
    ("collision", "contact_end"): dict(
        meaning="`\"overlap\"`: the contact ends when the compression returns to zero "
                "(Schwager & Pöschel (1997), eq. (4)); `\"force\"`: when the repulsive force "
                "vanishes (Schwager & Pöschel 2008).", context=_VISCO),
    ("collision", "tc_time"): dict(
        meaning="`model = \"constant\"` only: TC model (Luding & McNamara 1998); a collision "
                "within `tc_time` of either particle's previous one is elastic, which guards "
                "against inelastic collapse.", context=_CONSTANT),
    ("collision", "wall_restitution"): dict(
        meaning="`model = \"constant\"` with walls only: the constant ε of sphere-wall collisions "
                "(default: `restitution`).", context=_WALLS_CONSTANT),
    ("driving", "model"): dict(
        meaning="`\"white_noise\"`: every particle gets independent Gaussian velocity kicks "
                "(their momentum removed at each kick) at the times (k + 1/2) × `interval`.",
        context=_DRIVEN),
    ("driving", "heating_rate"): dict(
        meaning="H: the driving alone raises the temperature as dT/dt = H; the gas settles where "
                "ζ(T) T = H. 0 means no driving.", context=_DRIVEN, default=Text("— (required)")),
    ("driving", "interval"): dict(
        meaning="Time between kicks; the steady state is independent of it for ζ × interval ≤ 0.05.",
        context=_DRIVEN,
        default=Text("0.02 / ζ (the shortest of the steady, initial cooling and heating times), "
                     "shortened to a whole fraction of `observables_interval`")),
    ("collision.material", "young_modulus"): dict(meaning="Young's modulus Y (Pa).", context=_MATERIAL),
    ("collision.material", "poisson_ratio"): dict(meaning="Poisson ratio ν.", context=_MATERIAL),
    ("collision.material", "dissipation_time"): dict(
        meaning="The dissipative constant A of Schwager & Pöschel (1997), eq. (2) (s).",
        context=_MATERIAL),
    ("collision.material", "diameter"): dict(meaning="Diameter of the reference particle (m).",
                                             context=_MATERIAL),
    ("collision.material", "density"): dict(meaning="Material density (kg/m³); the reference mass "
                                                    "is density × π d³/6 (also for disks).",
                                            context=_MATERIAL),
    ("collision.material", "speed_unit"): dict(
        meaning="The reduced velocity unit √(T0/m) in m/s; time is then in diameter / speed_unit.",
        context=_MATERIAL),
    ("run", "end_time"): dict(meaning="Stop at this time (give `end_time`, "
                                      "`collisions_per_particle` or both; the first reached stops)."),
    ("run", "collisions_per_particle"): dict(
        meaning="Stop after s = 2C/N collisions per particle (each pair collision counts for both "
                "partners)."),
    ("output", "file"): dict(meaning="The H5MD output file, relative to the working directory.",
                             default="runs/<config name>.h5"),
    ("output", "snapshots"): dict(
        meaning="Number of full snapshots, the initial and the final state included, log-spaced in "
                "time from `first_snapshot` to `end_time` (without `end_time`: log-spaced in "
                "collisions from one per particle to the budget).", default="20"),
    ("output", "snapshot_interval"): dict(
        meaning="Instead of `snapshots`: a snapshot every this much time."),
    ("output", "first_snapshot"): dict(
        meaning="Time of the first log-spaced snapshot after the start.",
        default="the Enskog mean free time at T0"),
    ("output", "observables_interval"): dict(
        meaning="Sampling interval of the observables (temperature, energies, counts, momentum, "
                "pressure); they are also sampled at every snapshot, at the start and at the end.",
        default="end_time / 200"),
}

SECTION_TEXT = {
    "system": "The system: dimension, size, density and the random seed.",
    "particles": "Particle sizes and masses (reduced units: the reference particle has "
                 "diameter 1 and mass 1).",
    "initial": "The initial state.",
    "collision": "The collision rule.",
    "collision.material": "Instead of `damping`: the viscoelastic contact from material constants "
                          "(SI; all keys required), converted once to the reduced pair prefactor "
                          "k = (3/2) A (2Y / (3(1 − ν²)))^(2/5) (σ u / m²)^(1/5).",
    "driving": "Optional: white-noise driving (a heated granular gas in a steady state).",
    "run": "When to stop (at least one key).",
    "output": "The output file and its schedule.",
}


def _dataclass_keys():
    """(section, TOML key, dataclass default) for every field of the config dataclasses."""
    from granulargas.io import config as c

    table = [
        ("system", c.SystemConfig), ("particles", c.ParticlesConfig), ("initial", c.InitialConfig),
        ("collision", c.CollisionConfig), ("collision.material", c.MaterialConfig),
        ("driving", c.DrivingConfig), ("run", c.RunSection), ("output", c.OutputConfig),
    ]
    rename = {("initial", "from_file"): "from", ("particles", "diameter_min"): "diameter.min",
              ("particles", "diameter_max"): "diameter.max"}
    out = []
    for section, cls in table:
        for f in dataclasses.fields(cls):
            if (section, f.name) == ("collision", "material"):
                continue  # the sub-table, documented as its own section
            default = f.default if f.default is not dataclasses.MISSING else None
            out.append((section, rename.get((section, f.name), f.name), default))
    return out


def _document(section: str, key: str, value, context: dict) -> dict:
    """A minimal valid config document with section.key set to value."""
    doc = {"run": {"end_time": 1.0}}
    for name, table in copy.deepcopy(_VISCO if not context else context).items():
        doc.setdefault(name, {}).update(table)
    node = doc
    path = section.split(".") + key.split(".")
    for part in path[:-1]:
        nxt = node.get(part)
        if not isinstance(nxt, dict):
            nxt = node[part] = {}
        node = nxt
    node[path[-1]] = value
    return doc


def _probe(section: str, key: str, value, context: dict) -> str | None:
    """What the validator says about section.key = value: None if accepted, else its message."""
    from granulargas.errors import ConfigError
    from granulargas.io.config import build_config

    doc = _document(section, key, value, context)
    if key.startswith("diameter.") and section == "particles":
        doc["particles"]["diameter"].setdefault("min", 0.9)
        doc["particles"]["diameter"].setdefault("max", 1.1)
    try:
        build_config(doc, source="probe")
    except ConfigError as exc:
        return str(exc)
    return None


def _must_be(message: str | None, dotted: str) -> str | None:
    if message is None:
        return None
    if "unknown key" in message or "unknown section" in message:
        raise RuntimeError(f"config reference: the validator does not accept {dotted}: {message}")
    m = re.search(r": (?:must be |is only used |needs )(.*)$", message)
    return m.group(1) if m else message.split(": ", 2)[-1]


def _derived_entry(section: str, key: str, default) -> ConfigKey:
    dotted = f"{section}.{key}"
    spec = MEANINGS.get((section, key))
    if spec is None:
        raise RuntimeError(f"config reference: no meaning for {dotted} in docs/hooks/generate.py MEANINGS")
    context = spec.get("context", {})
    if "type" in spec:  # the probes cannot tell (e.g. a list)
        return ConfigKey(section, key, spec["type"], spec.get("default", default), spec["allowed"],
                         spec["meaning"])
    kind = _must_be(_probe(section, key, "__not_a_value__", context), dotted)
    if kind is None:
        typ, allowed = "string", _must_be(_probe(section, key, "", context), dotted) or "any string"
    elif kind.startswith("one of"):
        typ, allowed = "string", kind
    elif kind.startswith("an integer"):
        typ, allowed = "integer", _must_be(_probe(section, key, -10**9, context), dotted)
    elif kind.startswith("a number"):
        typ, allowed = "number", _must_be(_probe(section, key, -1e300, context), dotted)
    else:
        raise RuntimeError(f"config reference: cannot tell the type of {dotted} from {kind!r}")
    if key == "diameter" and section == "particles":
        typ = "number or table"
    for label, extra in spec.get("also", []):
        ctx = copy.deepcopy(context or _VISCO)
        for name, table in extra.items():
            ctx.setdefault(name, {}).update(table)
        allowed += f"; {label}: " + _must_be(_probe(section, key, -1e300, ctx), dotted)
    if "default" in spec:
        default = Text(spec["default"])
    return ConfigKey(section, key, typ, default, allowed, spec["meaning"])


def config_entries() -> list[ConfigKey]:
    """Every configuration key, from the schema if there is one, else from the validator."""
    from granulargas.io import config as c

    schema = getattr(c, "config_schema", None)
    if schema is not None:
        return [ConfigKey(e.section, e.key, e.type, e.default, e.allowed, e.meaning) for e in schema()]
    keys = _dataclass_keys()
    known = {(s, k) for s, k, _ in keys}
    stale = sorted(f"{s}.{k}" for s, k in MEANINGS if (s, k) not in known)
    if stale:
        raise RuntimeError(f"config reference: MEANINGS has keys the config does not: {', '.join(stale)}")
    return [_derived_entry(s, k, d) for s, k, d in keys]


def _show_default(value) -> str:
    if value is None:
        return "—"
    if isinstance(value, Text):
        return str(value)
    if isinstance(value, str):
        return f'`"{value}"`'
    if isinstance(value, bool):
        return f"`{str(value).lower()}`"
    return f"`{value!r}`"


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def config_reference_markdown() -> str:
    """The configuration reference: one table per section."""
    entries = config_entries()
    lines = []
    for section in dict.fromkeys(e.section for e in entries):
        anchor = section.replace(".", "-")
        lines += [f"## `[{section}]` {{ #{anchor} }}", ""]
        if section in SECTION_TEXT:
            lines += [SECTION_TEXT[section], ""]
        lines += ["| key | type | default | allowed | meaning |", "|---|---|---|---|---|"]
        for e in (e for e in entries if e.section == section):
            lines.append(f"| `{e.key}` | {e.type} | {_cell(_show_default(e.default))} | "
                         f"{_cell(e.allowed)} | {_cell(e.meaning)} |")
        lines.append("")
    return "\n".join(lines)


def cli_reference_markdown() -> str:
    """The ``--help`` output of ``granulargas`` and of each command."""
    from granulargas.cli import COMMANDS, build_parser

    def help_text(argv):
        out = io.StringIO()
        old = os.environ.get("COLUMNS")
        os.environ["COLUMNS"] = "100"
        try:
            with contextlib.redirect_stdout(out), contextlib.suppress(SystemExit):
                build_parser(argv).parse_args(argv + ["--help"])
        finally:
            if old is None:
                del os.environ["COLUMNS"]
            else:
                os.environ["COLUMNS"] = old
        return out.getvalue().rstrip()

    lines = ["## `granulargas`", "", "```text", help_text([]), "```", ""]
    for name in COMMANDS:
        lines += [f"## `granulargas {name}`", "", "```text", help_text([name]), "```", ""]
    return "\n".join(lines)


def on_page_markdown(markdown, page, config, files):  # noqa: ARG001 (MkDocs hook signature)
    if CONFIG_MARKER in markdown:
        markdown = markdown.replace(CONFIG_MARKER, config_reference_markdown())
    if CLI_MARKER in markdown:
        markdown = markdown.replace(CLI_MARKER, cli_reference_markdown())
    return markdown


_ROLE = re.compile(r":(?:func|class|mod|meth|data|attr|exc|obj):(?=<code>)")


def on_page_content(html, page, config, files):  # noqa: ARG001 (MkDocs hook signature)
    return _ROLE.sub("", html)
