"""Bad shear configs through ``granulargas run``: one line naming the file, key and value on
stderr, exit 2, nothing written (the config rules of ``[shear]`` and the run checks of a sheared
run's reach of its steady state)."""

import pytest

from tests.cli.test_run import _check_rejected, case  # noqa: F401  (the fixture)

SHEARED = """
[system]
dimension = 3
particles = 200
packing_fraction = 0.02
seed = 1
boundary = ["periodic", "lees-edwards", "periodic"]

[collision]
model = "constant"
restitution = 0.8

[shear]
rate = 0.114

[run]
end_time = 200.0

[output]
file = "{out}"
snapshots = 3
"""


def _with(old, new):
    assert old in SHEARED
    return SHEARED.replace(old, new)


BAD = {
    "lees-edwards without shear": (_with("[shear]\nrate = 0.114\n", ""),
                                   'system.boundary = ["periodic", "lees-edwards", "periodic"]: "lees-edwards" needs [shear]'),
    "shear without rate": (_with("rate = 0.114", "thermostat_temperature = 1.0"), "shear.rate: missing"),
    "shear without lees-edwards": (_with('"periodic", "lees-edwards", "periodic"', '"periodic", "periodic", "periodic"'),
                                   'a shear flow needs "lees-edwards" on y'),
    "walls on the sheared axis": (_with('"periodic", "lees-edwards", "periodic"', '"periodic", "wall", "periodic"'),
                                  'a shear flow needs "lees-edwards" on y'),
    "lees-edwards on x": (_with('"periodic", "lees-edwards", "periodic"', '"lees-edwards", "periodic", "periodic"'),
                          'a shear flow needs "lees-edwards" on y'),
    "negative rate": (_with("rate = 0.114", "rate = -0.1"), "shear.rate = -0.1: must be"),
    "nan rate": (_with("rate = 0.114", "rate = nan"), "shear.rate = nan: must be"),
    "elastic without thermostat": (_with('model = "constant"\nrestitution = 0.8', 'model = "elastic"'),
                                   "an elastic gas only heats under shear"),
    "restitution 1 without thermostat": (_with("restitution = 0.8", "restitution = 1.0"),
                                         "an elastic gas only heats under shear"),
    "interval without temperature": (_with("rate = 0.114", "rate = 0.114\nthermostat_interval = 0.1"),
                                     "shear.thermostat_interval = 0.1: needs shear.thermostat_temperature"),
    "driving": (SHEARED + "\n[driving]\nheating_rate = 0.1\n", "[driving] is not available with [shear]"),
    "rough grains": (_with("[shear]", '[collision.tangential]\nmodel = "constant"\nrestitution = 0.0\n\n[shear]'),
                     "rough particles are not available with [shear]"),
    "gravity": (SHEARED + "\n[gravity]\nacceleration = [0.0, 0.0, -1.0]\n",
                "gravity.acceleration = [0, 0, -1]: [gravity] is not available with [shear]"),
    "vibrating wall": (_with('"periodic", "lees-edwards", "periodic"', '"periodic", "lees-edwards", "wall"')
                       + '\n[walls.z_low]\nkind = "vibrating"\namplitude = 0.1\nfrequency = 1.0\n',
                       'walls.z_low = {...}: kind = "vibrating" is not available with [shear]'),
    "thermal wall": (_with('"periodic", "lees-edwards", "periodic"', '"periodic", "lees-edwards", "wall"')
                     + '\n[walls.z_high]\nkind = "thermal"\ntemperature = 1.0\n',
                     'walls.z_high = {...}: kind = "thermal" is not available with [shear]'),
    "species": (SHEARED + '\n[[species]]\nname = "a"\ncount = 100\ndiameter = 1.0\nmass = 1.0\n'
                '\n[[species]]\nname = "b"\ncount = 100\ndiameter = 1.0\nmass = 2.0\n',
                "[shear] is not available with [[species]]"),
    "dsmc polydisperse": (_with("[run]\n", '[particles]\ndiameter = { min = 0.8, max = 1.2 }\n\n[run]\nmethod = "dsmc"\n'),
                          "the DSMC of uniform shear flow takes identical particles"),
    "rate far from steady in the run time": (_with("rate = 0.114", "rate = 0.001"),
                                             "shear.rate = 0.001: the gas would move from T0 = 1 to its steady T"),
    "thermostat too sparse for the shear": (_with("rate = 0.114", "rate = 0.114\nthermostat_temperature = 1.0\n"
                                                                   "thermostat_interval = 5.0"),
                                            "shear.thermostat_interval = 5: rate x interval = 0.57 > 0.5"),
    "run too short to reach the steady state": (_with("rate = 0.114", "rate = 0.03"), "beyond run.end_time = 200"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_shear_config(case, name):  # noqa: F811
    text, message = BAD[name]
    rc, out, err, _, new = case(text)
    _check_rejected(rc, out, err, new, message)


def test_the_good_config_runs(case):  # noqa: F811
    rc, out, err, path, _ = case(SHEARED, "--quiet")
    assert rc == 0, err
    assert path.exists()
