"""The config schema: one entry per key, the validator driven by it, the rules across keys."""

import dataclasses
import math

import pytest

from granulargas.errors import ConfigError
from granulargas.io import config as c
from granulargas.io.config import SCHEMA, config_rules, config_schema, parse_config

TOML_NAME = {"from_file": "from", "diameter_min": "diameter.min", "diameter_max": "diameter.max"}


def test_every_dataclass_field_has_one_schema_entry():
    schema = {(k.section, k.key) for k in SCHEMA}
    assert len(schema) == len(SCHEMA)
    fields = set()
    for section, cls in c.SECTION_CLASSES.items():
        for f in dataclasses.fields(cls):
            fields.add((section, TOML_NAME.get(f.name, f.name)))
    assert fields == schema


def test_schema_defaults_are_the_dataclass_defaults():
    for key in SCHEMA:
        if key.default is None or key.section in c.SUBTABLES:
            continue
        f = {x.name: x for x in dataclasses.fields(c.SECTION_CLASSES[key.section])}[key.attribute]
        assert f.default == key.default, key.dotted


def test_every_entry_is_documented():
    for key in config_schema():
        assert key.meaning.strip().endswith(".") and key.allowed, key.dotted
        bounded = key.type in ("number", "integer") and key.choices is None
        if bounded and key.high is not None and key.high >= 1e9:
            assert key.reason, f"{key.dotted}: a bound beyond the physics of the key needs its reason"
    assert all(r.text.strip() for r in config_rules())


def test_table_limit_is_the_contact_tables():
    from granulargas.contact.table import TABLE_BETA_MAX

    assert c.TABLE_BETA_MAX == TABLE_BETA_MAX


BASE = '[collision]\nmodel = "elastic"\n[run]\nend_time = 1.0\n'

#: (document, message fragment): each bound and each rule of the schema
REFUSED = [
    ("[particles]\nmass = 1e-101\n" + BASE, "particles.mass = 1e-101: must be a number in [1e-100, 1e100] (speeds"),
    ("[particles]\nmass = 1e101\n" + BASE, "particles.mass = 1e+101: must be a number in [1e-100, 1e100]"),
    ("[initial]\ntemperature = 1e-300\n" + BASE, "initial.temperature = 1e-300: must be a number in [1e-100, 1e100]"),
    ("[particles]\ndiameter = 1e60\n" + BASE, "particles.diameter = 1e+60: must be a number in [1e-50, 1e50]"),
    ("[particles]\ndiameter = 2.0\ndensity = 1e-120\n" + BASE, "particles.density = 1e-120: gives masses"),
    ("[system]\nparticles = 2147483648\n" + BASE, "system.particles = 2147483648: must be an integer in [2, 2147483647] "
                                                    "(the engine indexes particles with int32)"),
    ("[system]\nparticles = 1000\n[collision]\nmodel = \"elastic\"\n[run]\ncollisions_per_particle = 1e14\n",
     "run.collisions_per_particle = 1e+14: gives 5e+16 pair collisions for 1000 particles; at most 2^53"),
    ('[collision]\nmodel = "elastic"\n[run]\nend_time = 1e101\n', "run.end_time = 1e+101: must be a number in (0, 1e100]"),
    ('[collision]\nmodel = "viscoelastic"\ndamping = 41\n[run]\nend_time = 1.0\n',
     "collision.damping = 41: must be a number in [0, 40] (the restitution table covers beta <= 40"),
    ('[collision]\nmodel = "constant"\nrestitution = 0.5\ndamping = 0.1\n[run]\nend_time = 1.0\n',
     'collision.damping = 0.1: is only used with model = "viscoelastic" (model = "constant")'),
    ('[collision]\nmodel = "elastic"\ntc_time = 1.0\n[run]\nend_time = 1.0\n',
     'collision.tc_time = 1: is only used with model = "constant"'),
    ('[collision]\ndamping = 0.1\n[collision.material]\nyoung_modulus = 1e7\npoisson_ratio = 0.3\n'
     'dissipation_time = 1e-6\ndiameter = 0.01\ndensity = 1000.0\nspeed_unit = 1.0\n[run]\nend_time = 1.0\n',
     "collision.material = {...}: give either damping or material, not both"),
    ("[run]\ncollisions_per_particle = 1\n[output]\nobservables_interval = 1.0\n[collision]\nmodel = \"elastic\"\n",
     "output.observables_interval = 1: needs run.end_time"),
    ("[output]\nfirst_snapshot = 2.0\n" + BASE, "output.first_snapshot = 2: must be below run.end_time = 1"),
    ("[output]\nsnapshot_interval = 0.1\nfirst_snapshot = 0.5\n" + BASE,
     "output.first_snapshot = 0.5: is only used for log-spaced snapshots"),
    ("[output]\nsnapshots = 3\nsnapshot_interval = 0.1\n" + BASE,
     "output.snapshot_interval = 0.1: give either snapshots or snapshot_interval, not both"),
    ("[output]\nfile = \" \"\n" + BASE, 'output.file = " ": must be a non-empty string'),
    ("[particles]\ndiameter = { min = 1.0, max = 1.2, mean = 1.1 }\n" + BASE,
     "particles.diameter.mean = 1.1: unknown key"),
    ("[particles]\ndiameter = { min = 1.0 }\n" + BASE, "particles.diameter = { min = 1 }: needs both min and max"),
    ("[system]\ntemperature = 2.0\n" + BASE, "system.temperature = 2: unknown key; did you mean `initial.temperature`?"),
    ("[collision.materal]\nyoung_modulus = 1\n" + BASE.replace("[collision]\n", "[collision]\n"),
     "unknown key; did you mean `material`?"),
]


@pytest.mark.parametrize("text, fragment", REFUSED)
def test_bounds_and_rules_refuse_with_one_line(text, fragment):
    with pytest.raises(ConfigError) as err:
        parse_config(text, "c.toml")
    msg = str(err.value)
    assert fragment in msg and "\n" not in msg and msg.startswith("c.toml: ")


def test_values_at_the_bounds_are_accepted():
    text = ("[system]\nparticles = 2147483647\n[particles]\nmass = 1e-100\ndiameter = 1e50\n[initial]\n"
            "temperature = 1e100\n" + BASE.replace("end_time = 1.0", "end_time = 1e100"))
    cfg = parse_config(text, "c.toml")
    assert (cfg.system.particles, cfg.particles.mass, cfg.particles.diameter, cfg.run.end_time) == (
        2**31 - 1, 1e-100, 1e50, 1e100)


def test_every_key_round_trips_through_to_toml():
    text = """[system]\ndimension = 2\nparticles = 100\npacking_fraction = 0.1\nseed = 3
[particles]\ndiameter = { min = 0.8, max = 1.2 }\ndensity = 2.0
[initial]\ntemperature = 2.0\nfrom = "x.h5"
[collision]\nmodel = "constant"\nrestitution = 0.9\ntc_time = 1e-4
[run]\nend_time = 10.0\ncollisions_per_particle = 5
[output]\nfile = "a.h5"\nsnapshots = 5\nfirst_snapshot = 0.5\nobservables_interval = 0.1\n"""
    cfg = parse_config(text, "c.toml")
    again = parse_config(cfg.to_toml(), "c.toml")
    assert dataclasses.astuple(again)[:6] == dataclasses.astuple(cfg)[:6]
    written = cfg.to_toml()
    for key in SCHEMA:
        if key.template:  # walls.<side>: test_gravity_and_walls_round_trip
            continue
        if key.per_species:  # [[species]]: tests/io/test_config_species.py
            continue
        value = None if key.section in c.SUBTABLES else getattr(getattr(cfg, key.section), key.attribute, None)
        if value is not None and "." not in key.key and key.dotted not in c.SUBTABLES:
            assert f"{key.key} = " in written, key.dotted
    assert math.isclose(cfg.particles.diameter, 1.0)


GRAVITY_BASE = """[system]\ndimension = 3\nparticles = 100\npacking_fraction = 0.05\nboundary = ["periodic", "wall", "wall"]
[collision]\nmodel = "constant"\nrestitution = 0.9\nelastic_below = 0.001
[gravity]\nacceleration = [0.0, 0.0, -1.0]
[walls]
z_low = { kind = "vibrating", amplitude = 0.2, frequency = 1.5, waveform = "biparabolic", phase = 0.5 }
z_high = { kind = "hard" }
y_low = { kind = "thermal", temperature = 2.0 }
[run]\nend_time = 1.0\n"""


def test_gravity_and_walls_round_trip():
    cfg = parse_config(GRAVITY_BASE, "c.toml")
    assert cfg.gravity.vector == (0.0, 0.0, -1.0)
    assert cfg.walls.side(2, 0) == c.WallConfig("vibrating", 0.2, 1.5, "biparabolic", 0.5, None)
    assert cfg.walls.side(1, 0) == c.WallConfig("thermal", temperature=2.0, waveform=None, phase=None)
    assert cfg.walls.side(0, 1) == c.WallConfig()  # not given: hard
    assert cfg.walls.moving and cfg.collision.elastic_below == 0.001
    again = parse_config(cfg.to_toml(), "c.toml")
    assert (again.gravity, again.walls, again.collision) == (cfg.gravity, cfg.walls, cfg.collision)
    # without the optional sections: None
    plain = parse_config(BASE, "c.toml")
    assert plain.gravity is None and plain.walls is None


@pytest.mark.parametrize("edit, fragment", [
    (("[0.0, 0.0, -1.0]", "[0.0, -1.0]"), "gravity.acceleration = [0, -1]: 2 entries for a 3D system"),
    (("[0.0, 0.0, -1.0]", "[0.0, 0.0, nan]"), "gravity.acceleration = [0, 0, nan]: must be a list of 3 numbers"),
    (("[0.0, 0.0, -1.0]", "-1.0"), "gravity.acceleration = -1: must be a list of 3 numbers"),
    (("acceleration = [0.0, 0.0, -1.0]", ""), "gravity.acceleration: missing"),
    (('"wall", "wall"]', '"wall", "periodic"]'), 'walls.z_low = {...}: the z axis is "periodic"'),
    (("amplitude = 0.2", "amplitude = 0.0"), "walls.z_low.amplitude = 0: must be a number in (0, 1e50]"),
    (("frequency = 1.5", "frequency = -1.5"), "walls.z_low.frequency = -1.5: must be a number in (0, 1e50]"),
    (("frequency = 1.5, ", ""), 'walls.z_low.frequency: missing; kind = "vibrating" needs amplitude and frequency'),
    (('"biparabolic"', '"square"'), 'walls.z_low.waveform = "square": must be one of "sine", "triangle"'),
    (("temperature = 2.0", "temperature = 0.0"), "walls.y_low.temperature = 0: must be a number in [1e-100"),
    (('{ kind = "thermal", temperature = 2.0 }', '{ kind = "thermal" }'), "walls.y_low.temperature: missing"),
    (('{ kind = "hard" }', '{ kind = "hard", amplitude = 1.0 }'),
     'walls.z_high.amplitude = 1: is only used with kind = "vibrating" (kind = "hard")'),
    (('{ kind = "hard" }', '{ kind = "hard", ampltude = 1.0 }'), "walls.z_high.ampltude = 1: unknown key; did you mean"),
    (('z_high = { kind = "hard" }', 'z_high = "hard"'), 'walls.z_high = "hard": must be a table'),
    (('z_high = { kind = "hard" }', 'x_high = { kind = "hard" }'), 'walls.x_high = {...}: the x axis is "periodic"'),
    (('z_high = { kind = "hard" }', 'w_high = { kind = "hard" }'), 'walls.w_high = { kind = "hard" }: unknown key; did you mean `z_high`?'),
    (("[run]\n", '[run]\nmethod = "dsmc"\n'), '[gravity]: needs positions: method = "dsmc"'),
    (('model = "constant"\nrestitution = 0.9', 'model = "elastic"'),
     'collision.elastic_below = 0.001: is only used with model = "constant" or "viscoelastic"'),
])
def test_gravity_and_walls_refuse_with_one_line(edit, fragment):
    text = GRAVITY_BASE.replace(*edit)
    assert text != GRAVITY_BASE
    with pytest.raises(ConfigError) as err:
        parse_config(text, "c.toml")
    msg = str(err.value)
    assert fragment in msg and "\n" not in msg and msg.startswith("c.toml: "), msg


def test_dsmc_refuses_walls_and_elastic_below():
    base = '[collision]\nmodel = "constant"\nrestitution = 0.9\n[run]\nend_time = 1.0\nmethod = "dsmc"\n'
    with pytest.raises(ConfigError, match=r"\[walls\]: needs positions"):
        parse_config("[walls]\n" + base, "c.toml")
    with pytest.raises(ConfigError, match="collision.elastic_below = 0.1: guards against"):
        parse_config(base.replace("restitution = 0.9", "restitution = 0.9\nelastic_below = 0.1"), "c.toml")
