"""``[[species]]``: mixtures in the config -- counts and fractions, per-pair and per-species
tables, the material route per species, overrides, and one line naming the species and the key
for every bad input."""

import pytest

from granulargas.errors import ConfigError
from granulargas.io.config import parse_config

MIX = """
[system]
dimension = 3
particles = 1000
packing_fraction = 0.05

[[species]]
name = "glass"
fraction = 0.5
diameter = 1.0
mass = 1.0

[[species]]
name = "steel"
fraction = 0.5
diameter = 1.2
density = 3.0

[collision]
model = "constant"
restitution = { "glass-glass" = 0.9, "steel-glass" = 0.8, "steel-steel" = 0.85 }

[run]
collisions_per_particle = 10
"""

MATERIAL = """
[system]
particles = 300

[[species]]
name = "glass"
count = 200
young_modulus = 6.3e10
poisson_ratio = 0.24
dissipation_time = 2e-9

[[species]]
name = "steel"
count = 100
density = 3.1
young_modulus = 2.1e11
poisson_ratio = 0.29
dissipation_time = 1e-9

[collision]
model = "viscoelastic"
[collision.material]
diameter = 1e-3
density = 2500
speed_unit = 0.5

[run]
end_time = 1
"""


def test_a_mixture_config():
    cfg = parse_config(MIX, "mix.toml")
    assert cfg.species_names == ("glass", "steel") and cfg.mixture
    glass, steel = cfg.species
    assert (glass.count, steel.count, cfg.system.particles) == (500, 500, 1000)
    assert steel.particle_mass(3) == pytest.approx(3.0 * 3.141592653589793 / 6 * 1.2**3, rel=1e-15)
    # pair keys in either order, normalised to the species' order
    assert cfg.collision.restitution == {"glass-glass": 0.9, "glass-steel": 0.8, "steel-steel": 0.85}
    assert cfg.collision.pair_table(cfg.collision.restitution, cfg.species_names) == [[0.9, 0.8], [0.8, 0.85]]
    again = parse_config(cfg.to_toml(), "again.toml")
    assert again.species == cfg.species and again.collision == cfg.collision
    assert again.system == cfg.system


def test_fractions_are_rounded_by_largest_remainder():
    text = MIX.replace("particles = 1000", "particles = 7").replace("fraction = 0.5\ndiameter = 1.0",
                                                                    "fraction = 0.3\ndiameter = 1.0")
    text = text.replace("fraction = 0.5\ndiameter = 1.2", "fraction = 0.7\ndiameter = 1.2")
    cfg = parse_config(text, "m.toml")
    assert [sp.count for sp in cfg.species] == [2, 5]  # 2.1 and 4.9


def test_counts_give_the_particles():
    cfg = parse_config(MATERIAL, "m.toml")
    assert [sp.count for sp in cfg.species] == [200, 100] and cfg.system.particles == 300
    cfg = parse_config(MATERIAL.replace("particles = 300", "seed = 2"), "m.toml")
    assert cfg.system.particles == 300
    assert cfg.collision.material.young_modulus is None  # every species gives its own
    assert cfg.species[1].young_modulus == 2.1e11


def test_overrides_address_a_species_by_name():
    cfg = parse_config(MIX, "m.toml", overrides={"species.steel.diameter": 1.5,
                                                 "collision.restitution.glass-steel": 0.75})
    assert cfg.species[1].diameter == 1.5
    assert cfg.collision.restitution["glass-steel"] == 0.75


def test_one_law_for_all_pairs_and_walls_per_species():
    text = MIX.replace('restitution = { "glass-glass" = 0.9, "steel-glass" = 0.8, "steel-steel" = 0.85 }',
                       "restitution = 0.8\nwall_restitution = { steel = 0.6 }")
    text = text.replace("packing_fraction = 0.05", 'packing_fraction = 0.05\nboundary = ["periodic", "periodic", '
                                                   '"wall"]')
    cfg = parse_config(text, "m.toml")
    assert cfg.collision.restitution == 0.8
    assert cfg.collision.species_values(cfg.collision.wall_restitution, cfg.species_names, [0.8, 0.8]) == [0.8, 0.6]


BAD = [
    # fractions that do not add up
    (MIX.replace("fraction = 0.5\ndiameter = 1.2", "fraction = 0.3\ndiameter = 1.2"),
     "species.steel.fraction = 0.3: the fractions add up to 0.8 (glass 0.5, steel 0.3), not 1"),
    # a pair without a law
    (MIX.replace(', "steel-steel" = 0.85', ""),
     'collision.restitution = {...}: no law for the pair steel-steel: give every pair of species'),
    # a species with no particles
    (MIX.replace("fraction = 0.5\ndiameter = 1.0", "count = 0\ndiameter = 1.0").replace(
        "fraction = 0.5\ndiameter = 1.2", "count = 5\ndiameter = 1.2"),
     "species.glass.count = 0: must be an integer in [1, 2147483647]"),
    (MIX.replace("fraction = 0.5\ndiameter = 1.0", "fraction = 0.0001\ndiameter = 1.0").replace(
        "fraction = 0.5\ndiameter = 1.2", "fraction = 0.9999\ndiameter = 1.2"),
     "species.glass.fraction = 0.0001: gives no particle of system.particles = 1000"),
    # a missing material constant
    (MATERIAL.replace("poisson_ratio = 0.29\n", ""),
     "species.steel.poisson_ratio: missing; give it in this species or in [collision.material]"),
    # and the rest
    (MIX.replace('name = "steel"', 'name = "glass"'), "species.glass.name = \"glass\": two species are named glass"),
    (MIX.replace('name = "steel"', 'name = "st-eel"'), 'species[1].name = "st-eel": must be a name of letters'),
    (MIX.replace('name = "steel"\n', ""), "species[1].name: missing; every [[species]] needs a name"),
    (MIX.replace("diameter = 1.2", "diameter = -1.2"), "species.steel.diameter = -1.2: must be a number in [1e-50"),
    (MIX.replace("density = 3.0", "density = 3.0\nmass = 2.0"), "species.steel.density = 3: give either mass or "
                                                                 "density"),
    (MIX.replace("density = 3.0", "colour = 3"), "species.steel.colour = 3: unknown key"),
    (MIX.replace("fraction = 0.5\ndiameter = 1.2", "count = 500\ndiameter = 1.2"),
     "species.glass.fraction = 0.5: give count for every species or fraction for every species"),
    (MIX.replace("fraction = 0.5\ndiameter = 1.0", "diameter = 1.0"),
     "species.glass.count: missing; every species needs count"),
    (MIX.replace('"steel-glass" = 0.8', '"steel-iron" = 0.8'),
     'collision.restitution."steel-iron" = 0.8: no species named iron (species: glass, steel)'),
    (MIX.replace('"steel-glass" = 0.8', '"steel-glass" = 0.8, "glass-steel" = 0.8'),
     'collision.restitution."glass-steel" = 0.8: the pair glass-steel is given twice'),
    (MIX.replace('"steel-glass" = 0.8', '"steel-glass" = 1.8'),
     'collision.restitution."steel-glass" = 1.8: must be a number in (0, 1]'),
    (MIX.replace("[collision]", "[particles]\nmass = 2.0\n[collision]"),
     "particles.mass = 2: is not used with [[species]]"),
    (MATERIAL.replace("[collision.material]\n", "[collision.material]\nyoung_modulus = 1e9\n").replace(
        'model = "viscoelastic"', 'model = "viscoelastic"\nduration = "resolved"'),
     'collision.duration = "resolved": "resolved" takes one material'),
    (MATERIAL.replace('model = "viscoelastic"\n[collision.material]\ndiameter = 1e-3\ndensity = 2500\n'
                      'speed_unit = 0.5', 'model = "viscoelastic"\ndamping = 0.1'),
     "species.glass.young_modulus = 6.3e+10: is used with the material route"),
    ('[[species]]\nname = "a"\ncount = 3\n[collision]\nmodel = "constant"\nrestitution = { "a-a" = 0.9 }\n'
     '[run]\nend_time = 1\n' .replace("[[species]]", "species = 3\n[[species]]"),
     "TOML syntax error"),
    ("species = 3\n[run]\nend_time = 1\n", "species: must be an array of tables"),
    ('[collision]\nmodel = "constant"\nrestitution = { "a-a" = 0.9 }\n[run]\nend_time = 1\n',
     "collision.restitution = {...}: a table per pair or per species needs [[species]]"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_bad_input_gets_one_line_naming_the_species_and_key(text, message):
    with pytest.raises(ConfigError) as err:
        parse_config(text, "bad.toml")
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("bad.toml: "), msg
    assert message in msg, msg


@pytest.mark.parametrize("key, value, message", [
    ("species.iron.mass", 2.0, "override species.iron.mass = 2: no species named iron (species: glass, steel)"),
    ("species.glass", 2.0, "a species key is species.<name>.<key>"),
    ("species.glass.diameter", "big", 'override: species.glass.diameter = "big": must be a number'),
    ("collision.restitution.glass-steel", 2.0, 'override: collision.restitution."glass-steel" = 2: must be'),
])
def test_bad_overrides(key, value, message):
    with pytest.raises(ConfigError) as err:
        parse_config(MIX, "m.toml", overrides={key: value})
    assert message in str(err.value), str(err.value)
