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


SECTIONS_ALLOWED = "(allowed: system, particles, initial, collision, driving, gravity, walls, shear, run, output, species)"


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
               "initial, collision, driving, gravity, walls, shear, run, output, species"),
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
    ("[sytem]\nseed = 1", "[sytem]: unknown section (allowed: [system], [particles], [initial], [collision], [driving], [gravity], [walls], [shear], [run], [output], [[species]]); did you mean [system]?"),
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


# ------------------------------------------------------------------ rough particles

ROUGH = CONSTANT + "\n[collision.tangential]\nrestitution = 0.2\n"


def test_rough_defaults_and_round_trip():
    c = parse_config(ROUGH, "r.toml")
    assert c.collision.rough and c.collision.tangential.model == "constant"
    assert c.collision.tangential.restitution == 0.2
    assert c.particles.inertia == 0.4 and c.initial.rotational_temperature == 1.0  # sphere, T_tr
    c2 = parse_config(ROUGH.replace("dimension = 3", "dimension = 2").replace("temperature = 1.0",
                                                                              "temperature = 2.5"), "r.toml")
    assert c2.particles.inertia == 0.5 and c2.initial.rotational_temperature == 2.5  # disk
    again = parse_config(c.to_toml(), "r.toml")
    assert (again.collision, again.particles, again.initial) == (c.collision, c.particles, c.initial)
    smooth = parse_config(CONSTANT, "s.toml")
    assert not smooth.collision.rough and smooth.particles.inertia is None
    assert smooth.initial.rotational_temperature is None
    driven = parse_config(CONSTANT + "\n[driving]\nheating_rate = 0.1\n", "d.toml")
    assert driven.driving.spin_fraction == 0.0
    assert "rotational_fraction" not in driven.to_toml()
    parse_config(driven.to_toml(), "d.toml")


def test_coulomb_and_walls_round_trip():
    text = ROUGH.replace("restitution = 0.2\n", 'model = "coulomb"\nrestitution = 0.4\nfriction = 0.3\n'
                                               "wall_restitution = -0.5\nwall_friction = 0.1\n")
    text = text.replace("seed = 1", 'seed = 1\nboundary = ["wall", "periodic", "periodic"]')
    c = parse_config(text + "\n[driving]\nheating_rate = 0.1\nrotational_fraction = 0.25\n", "c.toml")
    t = c.collision.tangential
    assert (t.model, t.restitution, t.friction, t.wall_restitution, t.wall_friction) == ("coulomb", 0.4, 0.3, -0.5, 0.1)
    assert c.driving.spin_fraction == 0.25
    assert parse_config(c.to_toml(), "c.toml").collision == c.collision


ROUGH_BAD = [
    ("collision.tangential.restitution", 1.5, "must be a number in [-1, 1]"),
    ("collision.tangential.restitution", -1.0001, "must be a number in [-1, 1]"),
    ("collision.tangential.model", "stick", 'must be one of "constant", "coulomb"'),
    ("collision.tangential.friction", 0.3, 'is only used with model = "coulomb"'),
    ("collision.tangential.wall_restitution", 0.3, "is only used with walls"),
    ("particles.inertia", 0.7, "must be a number in (0, 0.6667] (no mass outside the surface"),
    ("particles.inertia", 0.0, "must be a number in (0, 0.6667]"),
    ("initial.rotational_temperature", -1.0, "must be a number in [0, 1e100]"),
    ("collision.duration", "resolved", "collision.duration"),
]


@pytest.mark.parametrize("key, value, message", ROUGH_BAD)
def test_rough_bad_values(key, value, message):
    with pytest.raises(ConfigError) as err:
        parse_config(ROUGH, "r.toml", overrides={key: value})
    msg = str(err.value)
    assert "\n" not in msg and message in msg


def test_coulomb_needs_a_nonnegative_friction():
    text = ROUGH.replace("restitution = 0.2\n", 'model = "coulomb"\nrestitution = 0.4\n')
    with pytest.raises(ConfigError, match=r"collision\.tangential\.friction: missing; model = \"coulomb\""):
        parse_config(text, "c.toml")
    with pytest.raises(ConfigError, match=r"collision\.tangential\.friction = -0\.1: must be a number in \[0, 1e100\]"):
        parse_config(text + "friction = -0.1\n", "c.toml")
    with pytest.raises(ConfigError, match=r"collision\.tangential: missing key\(s\) restitution"):
        parse_config(CONSTANT + '\n[collision.tangential]\nmodel = "constant"\n', "c.toml")


def test_disks_take_a_ring_and_spheres_a_shell():
    disks = ROUGH.replace("dimension = 3", "dimension = 2")
    assert parse_config(disks, "d.toml", overrides={"particles.inertia": 1.0}).particles.inertia == 1.0
    with pytest.raises(ConfigError, match=r"must be a number in \(0, 1\]"):
        parse_config(disks, "d.toml", overrides={"particles.inertia": 1.01})
    assert parse_config(ROUGH, "s.toml", overrides={"particles.inertia": 2.0 / 3.0}).particles.inertia == 2.0 / 3.0


@pytest.mark.parametrize("key, value", [("particles.inertia", 0.4), ("initial.rotational_temperature", 1.0),
                                        ("driving.rotational_fraction", 0.0)])
def test_rough_keys_need_the_tangential_table(key, value):
    text = CONSTANT + "\n[driving]\nheating_rate = 0.1\n"
    with pytest.raises(ConfigError, match=rf"^override: {key.replace('.', chr(92) + '.')} = .*: is for rough particles"):
        parse_config(text, "x.toml", overrides={key: value})
    if key == "driving.rotational_fraction":
        with pytest.raises(ConfigError, match="must be a number in"):
            parse_config(text + "\n[collision.tangential]\nrestitution = 0.0\n", "x.toml", overrides={key: 1.5})


def test_inertia_bounds_are_the_theorys():
    from granulargas.io import config
    from granulargas.theory import rough

    assert config.MAX_INERTIA == rough.MAX_INERTIA and config.DEFAULT_INERTIA == rough.DEFAULT_INERTIA


def test_rough_mixture_is_refused_in_one_line():
    """[collision.tangential] with [[species]]: one line naming the table (rough mixtures run
    from Python only)."""
    text = ROUGH.replace("[particles]\ndiameter = 1.0\nmass = 1.0\n", "") + (
        '\n[[species]]\nname = "a"\nfraction = 0.5\n\n[[species]]\nname = "b"\nfraction = 0.5\nmass = 2.0\n')
    parse_config(text.replace("[collision.tangential]\nrestitution = 0.2\n", ""), "m.toml")  # smooth: fine
    with pytest.raises(ConfigError) as err:
        parse_config(text, "m.toml")
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("m.toml: collision.tangential = {...}: ") and "[[species]]" in msg
