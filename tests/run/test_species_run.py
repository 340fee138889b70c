"""Config runs of mixtures: identical species are the one-component run bit for bit (engine and
DSMC), restarts continue a mixture exactly, the file holds the species and their observables."""

import numpy as np
import pytest

from granulargas.io.config import load_config
from granulargas.io.h5md import load_snapshot, read_observables, read_parameters
from granulargas.run.runner import run_config

ONE = """
[system]
dimension = 2
particles = 240
packing_fraction = 0.12
seed = 3
boundary = ["periodic", "wall"]

[particles]
diameter = 1.0
mass = 2.0

[collision]
{collision}

[run]
end_time = 6.0
method = "{method}"

[output]
file = "{out}"
snapshot_interval = 1.0
observables_interval = 0.5
"""

SPECIES = """
[[species]]
name = "a"
count = 100
diameter = 1.0
mass = 2.0

[[species]]
name = "b"
count = 140
diameter = 1.0
mass = 2.0
"""

COLLISIONS = {
    "constant": ('model = "constant"\nrestitution = 0.8\nwall_restitution = 0.7',
                 'model = "constant"\nrestitution = { "a-a" = 0.8, "a-b" = 0.8, "b-b" = 0.8 }\n'
                 "wall_restitution = { a = 0.7, b = 0.7 }"),
    "viscoelastic": ('model = "viscoelastic"\ndamping = 0.1',
                     'model = "viscoelastic"\ndamping = { "a-a" = 0.1, "a-b" = 0.1, "b-b" = 0.1 }'),
}


def _text(collision, method, species):
    text = ONE.replace("{collision}", collision).replace("{method}", method)
    if method == "dsmc":  # no walls
        text = text.replace('boundary = ["periodic", "wall"]\n', "").replace("\nwall_restitution = 0.7", "")
        text = text.replace("\nwall_restitution = { a = 0.7, b = 0.7 }", "")
    if species:
        a = text.index("[particles]")
        b = text.index("[collision]")
        text = text[:a] + SPECIES + "\n" + text[b:]
    return text


@pytest.mark.parametrize("method", ["edmd", "dsmc"])
@pytest.mark.parametrize("model", sorted(COLLISIONS))
def test_identical_species_give_the_one_component_run_bit_for_bit(write_config, tmp_path, method, model):
    one, two = COLLISIONS[model]
    a = run_config(load_config(write_config(_text(one, method, False), out=str(tmp_path / "runs" / "one.h5"))))
    b = run_config(load_config(write_config(_text(two, method, True), name="two.toml",
                                            out=str(tmp_path / "runs" / "two.h5"))))
    assert a.collisions == b.collisions > 250
    sa, sb = load_snapshot(a.output), load_snapshot(b.output)
    assert np.array_equal(sa.velocities, sb.velocities)
    if method == "edmd":
        assert np.array_equal(sa.positions, sb.positions)
    oa, ob = read_observables(a.output), read_observables(b.output)
    for name in oa:
        assert np.array_equal(oa[name][2], ob[name][2], equal_nan=True), name
    # the mixture's file has its species, their observables and parameters
    assert sb.species.tolist() == [0] * 100 + [1] * 140
    t = ob["species_temperature"][2]
    x = np.array([100, 140]) / 240
    np.testing.assert_allclose(t @ x, ob["temperature"][2], rtol=1e-12)
    assert np.array_equal(np.triu(ob["species_collisions"][2][-1]).sum(), ob["collisions"][2][-1])
    par = read_parameters(b.output)["species"]
    assert par["names"] == ["a", "b"] and par["counts"].tolist() == [100, 140]


MIXTURE = """
[system]
dimension = 3
packing_fraction = 0.1
seed = 5

[[species]]
name = "heavy"
count = 120
diameter = 1.3
mass = 4.0

[[species]]
name = "light"
count = 180
diameter = 0.9

[collision]
model = "constant"
restitution = { "heavy-heavy" = 0.7, "heavy-light" = 0.8, "light-light" = 0.9 }

[run]
end_time = 4.0
method = "{method}"

[output]
file = "{out}"
snapshot_interval = 1.0
observables_interval = 0.5
"""


@pytest.mark.parametrize("method", ["edmd", "dsmc"])
def test_restart_of_a_mixture_equals_the_uninterrupted_run(write_config, tmp_path, method):
    path = write_config(MIXTURE.replace("{method}", method))
    full = run_config(load_config(path))
    half = run_config(load_config(path, {"run.end_time": 2.0, "output.file": str(tmp_path / "half.h5")}))
    rest = run_config(load_config(path, {"initial.from": str(half.output), "output.file": str(tmp_path / "r.h5")}))
    a, b = load_snapshot(full.output), load_snapshot(rest.output)
    assert np.array_equal(a.velocities, b.velocities) and a.time == b.time
    oa, ob = read_observables(full.output), read_observables(rest.output)
    assert np.array_equal(oa["species_collisions"][2][-1], ob["species_collisions"][2][-1])
    assert np.array_equal(oa["species_temperature"][2][-1], ob["species_temperature"][2][-1])


def test_restart_with_other_species_is_refused(write_config, tmp_path):
    from granulargas.errors import ConfigError

    path = write_config(MIXTURE.replace("{method}", "edmd"))
    half = run_config(load_config(path, {"run.end_time": 1.0, "output.file": str(tmp_path / "half.h5")}))
    with pytest.raises(ConfigError, match=r"restart file .* has species counts \[120, 180\], the config heavy 100"):
        run_config(load_config(path, {"initial.from": str(half.output), "species.heavy.count": 100,
                                      "species.light.count": 200, "output.file": str(tmp_path / "r.h5")}))
