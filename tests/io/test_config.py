"""Config parsing and validation: every documented key, defaults, overrides, errors."""

import math
from pathlib import Path

import pytest

from granulargas.errors import ConfigError
from granulargas.io.config import MAX_PACKING, RunConfig, load_config, parse_config

CONFIGS = Path(__file__).resolve().parents[2] / "configs"

FULL = """
[system]
dimension = 3
particles = 10000
packing_fraction = 0.1
seed = 1

[particles]
diameter = 1.0
mass = 1.0

[initial]
temperature = 1.0

[collision]
model = "viscoelastic"
damping = 0.05
contact_end = "overlap"

[run]
end_time = 200.0
collisions_per_particle = 500

[output]
file = "runs/hcs.h5"
snapshots = 40
observables_interval = 1.0
"""


def test_documented_example_parses():
    c = parse_config(FULL, "hcs.toml")
    assert isinstance(c, RunConfig)
    assert (c.system.dimension, c.system.particles, c.system.packing_fraction, c.system.seed) == (3, 10000, 0.1, 1)
    assert c.collision.model == "viscoelastic" and c.collision.damping == 0.05
    assert c.run.end_time == 200.0 and c.run.collisions_per_particle == 500
    assert c.output.file == "runs/hcs.h5" and c.output.snapshots == 40 and c.output.observables_interval == 1.0


def test_dataclasses_are_frozen():
    c = parse_config(FULL, "x.toml")
    with pytest.raises(Exception):
        c.system.particles = 3


def test_resolved_toml_round_trips():
    text = FULL.replace("diameter = 1.0", "diameter = { min = 0.8, max = 1.2 }").replace("mass = 1.0", "density = 2.0")
    c = parse_config(text, "x.toml")
    again = parse_config(c.to_toml(), "x.toml")
    for section in ("system", "particles", "initial", "collision", "run", "output"):
        assert getattr(again, section) == getattr(c, section)


def test_material_route_round_trips():
    text = FULL.replace("damping = 0.05", "").replace(
        'contact_end = "overlap"',
        'contact_end = "force"\n[collision.material]\nyoung_modulus = 1e7\npoisson_ratio = 0.3\n'
        "dissipation_time = 1e-6\ndiameter = 0.01\ndensity = 1100.0\nspeed_unit = 1.0\n",
    )
    c = parse_config(text, "x.toml")
    assert c.collision.material.young_modulus == 1e7 and c.collision.contact_end == "force"
    assert parse_config(c.to_toml(), "x.toml").collision == c.collision


def test_defaults_and_output_name_from_config_file(tmp_path):
    p = tmp_path / "myrun.toml"
    p.write_text('[collision]\nmodel = "elastic"\n[run]\nend_time = 1.0\n')
    c = load_config(p)
    assert c.output.file == "runs/myrun.h5"
    assert c.system.dimension == 3 and c.initial.temperature == 1.0 and c.particles.mass == 1.0


def test_overrides_are_validated_like_file_values():
    c = parse_config(FULL, "x.toml", overrides={"system.seed": 3, "output.file": "o.h5", "collision.damping": 0.1})
    assert (c.system.seed, c.output.file, c.collision.damping) == (3, "o.h5", 0.1)
    with pytest.raises(ConfigError, match=r"override: collision\.damping = -0\.1: must be a number in \[0, 40\] \(the restitution table"):
        parse_config(FULL, "x.toml", overrides={"collision.damping": -0.1})
    with pytest.raises(ConfigError, match="unknown key"):
        parse_config(FULL, "x.toml", overrides={"system.temperature": 3})


SECTIONS_ALLOWED = "(allowed: system, particles, initial, collision, driving, run, output, species)"


@pytest.mark.parametrize("dotted, nearest", [
    ("sytem.particle", "; did you mean `system.particles`?"),  # section and key misspelt
    ("runs.end_time", "; did you mean `run.end_time`?"),
    ("collison.material.youngs", "; did you mean `collision.material.young_modulus`?"),  # a sub-table's key
    ("sytem.temprature", "; did you mean `initial.temperature`?"),  # a key of another section
    ("sytem.xyz", "; did you mean `system`?"),  # no key near: the section
    ("extra.particle", ""),  # nothing near
])
def test_override_of_an_unknown_section_names_the_key_and_the_nearest(dotted, nearest):
    message = f"override: {dotted} = 0: unknown section {dotted.split('.')[0]} {SECTIONS_ALLOWED}{nearest}"
    with pytest.raises(ConfigError) as info:
        parse_config(FULL, "x.toml", overrides={dotted: 0})
    assert str(info.value) == message


@pytest.mark.parametrize("dotted, message", [
    ("system", "override: system = 0: key must be section.key with section one of system, particles, "
               "initial, collision, driving, run, output, species"),
    ("system.particles.x", "override: system.particles.x = 0: particles is not a table"),
])
def test_override_that_is_no_section_key(dotted, message):
    with pytest.raises(ConfigError) as info:
        parse_config(FULL, "x.toml", overrides={dotted: 0})
    assert str(info.value) == message


def test_integer_valued_float_accepted_for_counts():
    c = parse_config(FULL.replace("particles = 10000", "particles = 1e4"), "x.toml")
    assert c.system.particles == 10000 and isinstance(c.system.particles, int)


BAD = [
    ("[system]\nparticles = -5", "system.particles = -5: must be an integer in [2, 2147483647] (the engine indexes particles with int32)"),
    ("[system]\nparticles = 2.5", "system.particles = 2.5: must be an integer in [2, 2147483647]"),
    ("[system]\ndimension = 4", "system.dimension = 4: must be 2 or 3"),
    ("[system]\ndimension = \"3\"", 'system.dimension = "3": must be an integer: 2 or 3'),
    ("[system]\npacking_fraction = 0.75", "system.packing_fraction = 0.75: must be a number in (0, 0.7405) (below the densest packing of spheres / disks in 3D)"),
    ("[system]\ndimension = 2\npacking_fraction = 0.95", "system.packing_fraction = 0.95: must be a number in (0, 0.9069) (below the densest packing of spheres / disks in 2D)"),
    ("[system]\npacking_fraction = 0", "system.packing_fraction = 0: must be a number in (0,"),
    ("[system]\nsede = 1", "system.sede = 1: unknown key; did you mean `seed`?"),
    ("[sytem]\nseed = 1", "[sytem]: unknown section (allowed: [system], [particles], [initial], [collision], [driving], [run], [output], [[species]]); did you mean [system]?"),
    ('[collision]\nmodel = "hertz"', 'collision.model = "hertz": must be one of "elastic", "constant", "viscoelastic"'),
    ('[collision]\nmodel = "constant"\nrestitution = 1.2', "collision.restitution = 1.2: must be a number in (0, 1]"),
    ('[collision]\nmodel = "constant"\nrestitution = 0', "collision.restitution = 0: must be a number in (0, 1]"),
    ('[collision]\nmodel = "constant"', "collision.restitution: missing"),
    ('[collision]\nmodel = "viscoelastic"\ndamping = -0.1', "collision.damping = -0.1: must be a number in [0, 40]"),
    ('[collision]\nmodel = "viscoelastic"', "collision.damping: missing"),
    ('[collision]\nmodel = "elastic"\nrestitution = 0.9', 'collision.restitution = 0.9: is only used with model = "constant" (model = "elastic")'),
    ('[collision]\ndamping = 0.1\ncontact_end = "sometimes"', 'collision.contact_end = "sometimes": must be one of'),
    ("[particles]\nmass = 1.0\ndensity = 2.0", "particles.density = 2: give either mass or density"),
    ("[particles]\ndiameter = { min = 1.2, max = 0.8 }", "needs min <= max"),
    ("[particles]\ndiameter = -1", "particles.diameter = -1: must be a number in [1e-50, 1e50] or { min = ..., max = ... } (volumes and squared distances stay finite in float64)"),
    ("[initial]\ntemperature = nan", "initial.temperature = nan: must be a number in [1e-100, 1e100] (speeds sqrt(T/m)"),
    ("[output]\nsnapshots = 1", "output.snapshots = 1: must be an integer >= 2"),
    ("[output]\nsnapshots = 5\nsnapshot_interval = 1.0", "output.snapshot_interval = 1: give either snapshots"),
    ("[output]\nsnapshot_interval = true", "output.snapshot_interval = true: must be a number in (0, 1e100]"),
    ("[collision.material]\nyoung_modulus = 1e7", "collision.material: missing key(s)"),
]


@pytest.mark.parametrize("fragment, message", BAD)
def test_bad_values_name_file_key_value_and_range(fragment, message):
    base = {"system": "", "collision": 'model = "elastic"', "run": "end_time = 1.0"}
    # put the fragment's section first so its keys land in it
    text = fragment + "\n"
    for section, body in base.items():
        if f"[{section}]" not in fragment:
            text += f"\n[{section}]\n{body}\n"
    with pytest.raises(ConfigError) as err:
        parse_config(text, "bad.toml")
    msg = str(err.value)
    assert msg.startswith("bad.toml: ") and "\n" not in msg
    assert message in msg


def test_run_needs_an_end():
    with pytest.raises(ConfigError, match="run: needs end_time and/or collisions_per_particle"):
        parse_config('[collision]\nmodel = "elastic"\n', "x.toml")


def test_syntax_error_and_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="bad.toml: TOML syntax error"):
        parse_config("[system\n", "bad.toml")
    with pytest.raises(ConfigError, match="config file not found"):
        load_config(tmp_path / "nope.toml")


def test_packing_limits_are_the_densest_packings():
    assert MAX_PACKING[3] == pytest.approx(math.pi / math.sqrt(18))
    assert MAX_PACKING[2] == pytest.approx(math.pi / math.sqrt(12))


def test_example_configs_validate():
    files = sorted(CONFIGS.glob("*.toml"))
    assert files, "no example configs"
    for f in files:
        c = load_config(f)
        first = f.read_text().lstrip().splitlines()[0]
        assert first.startswith("#"), f"{f.name} lacks a header comment"
        assert c.output.file.startswith("runs/")


CONSTANT = FULL.replace('damping = 0.05\ncontact_end = "overlap"', 'model = "constant"\nrestitution = 0.8').replace(
    'model = "viscoelastic"\n', "")


@pytest.mark.parametrize("tc_time", [0.0, -1.0])
def test_tc_time_must_be_positive(tc_time):
    # one meaning: a positive TC-model time; without the key the TC model is off
    with pytest.raises(ConfigError, match=rf"^override: collision\.tc_time = {tc_time:g}: must be a number in \(0, 1e100\]"):
        parse_config(CONSTANT, overrides={"collision.tc_time": tc_time})


def test_smallest_positive_tc_time_is_accepted_by_config_and_engine():
    from granulargas.engine import CollisionRule

    tiny = 5e-324
    cfg = parse_config(CONSTANT, overrides={"collision.tc_time": tiny})
    assert cfg.collision.tc_time == tiny
    assert CollisionRule.constant(0.8, tc_time=tiny).tc_time == tiny
    assert parse_config(CONSTANT).collision.tc_time is None
    with pytest.raises(ConfigError, match="must be > 0"):
        CollisionRule.constant(0.8, tc_time=0.0)
