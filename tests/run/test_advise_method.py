"""advise names the model: DSMC for a homogeneous dilute scene, EDMD otherwise, with the
predicted speed-up from the benchmark's measured collision rates."""

import math

import pytest

from granulargas import theory
from granulargas.cli import main
from granulargas.io.config import parse_config
from granulargas.run.advise import DSMC_MAX_PACKING, DSMC_SPEEDUP_MEASURED, advise, choose_method, dsmc_speedup

BASE = """
[system]
dimension = 3
particles = {n}
packing_fraction = {eta}
{extra_system}
[collision]
model = "constant"
restitution = 0.9
{extra_collision}
[run]
end_time = 10.0
"""


def _config(n=2000, eta=0.02, extra_system="", extra_collision="", driving=""):
    return parse_config(BASE.format(n=n, eta=eta, extra_system=extra_system, extra_collision=extra_collision)
                        + driving)


def _instability_length(eta):
    """Goldhirsch & Zanetti's L_c ~ 10 l / sqrt(1 - eps^2) with l the Enskog mean free path, eps = 0.9."""
    n = theory.number_density(eta, 3, 1.0)
    chi = theory.contact_value(eta, 3)
    mfp = 1.0 / (math.sqrt(2.0) * math.pi * n * chi)
    return 10.0 * mfp / math.sqrt(1.0 - 0.81)


def test_dilute_homogeneous_scene_gets_dsmc_with_the_measured_speedup():
    adv = advise(_config())
    assert adv.method == "dsmc" and "dilute" in adv.method_reason
    assert adv.speedup == pytest.approx(DSMC_SPEEDUP_MEASURED[0][1])
    text = "\n".join(adv.lines())
    assert 'run.method = "dsmc"' in text and "x252" in text and "the config has" in text


def test_speedup_interpolates_the_measured_ratios():
    (p0, r0), (p1, r1) = DSMC_SPEEDUP_MEASURED
    assert dsmc_speedup(p0) == pytest.approx(r0) and dsmc_speedup(p1) == pytest.approx(r1)
    mid = math.sqrt(p0 * p1)
    assert dsmc_speedup(mid) == pytest.approx(math.sqrt(r0 * r1))  # a power law between the two
    assert dsmc_speedup(1e-4) == pytest.approx(r0) and dsmc_speedup(0.5) == pytest.approx(r1)


@pytest.mark.parametrize("kwargs, why", [
    ({"extra_system": 'boundary = ["wall", "periodic", "periodic"]'}, "walls"),
    ({"extra_collision": "tc_time = 0.001"}, "TC model"),
    ({"eta": 0.2, "n": 50}, "packing fraction 0.2"),
    ({"n": 200000}, "instability length"),
])
def test_scenes_dsmc_cannot_simulate_get_edmd(kwargs, why):
    config = _config(**kwargs)
    method, reason = choose_method(config, _instability_length(config.system.packing_fraction))
    assert method == "edmd" and why in reason


def test_the_box_is_compared_with_the_instability_length():
    # N = 2000 at packing 0.02: box 37 < L_c ~ 117 (Goldhirsch & Zanetti); N = 2e5: box 174 > L_c
    assert choose_method(_config(n=2000), _instability_length(0.02))[0] == "dsmc"
    assert choose_method(_config(n=200000), _instability_length(0.02))[0] == "edmd"
    assert DSMC_MAX_PACKING == 0.1


def test_cli_advise_prints_the_method(tmp_path, capsys):
    p = tmp_path / "c.toml"
    p.write_text(BASE.format(n=2000, eta=0.02, extra_system="", extra_collision=""))
    assert main(["advise", str(p)]) == 0
    out = capsys.readouterr().out
    assert "method       DSMC" in out
    assert main(["advise", str(p), "--set", "system.packing_fraction=0.3"]) == 0
    assert "method       EDMD" in capsys.readouterr().out


def test_a_dsmc_run_of_a_scene_that_needs_positions_says_so(tmp_path, capsys):
    p = tmp_path / "c.toml"
    text = BASE.format(n=200, eta=0.3, extra_system="", extra_collision="").replace(
        "[run]", '[run]\nmethod = "dsmc"').replace("end_time = 10.0", "end_time = 1.0") + \
        f'[output]\nfile = "{tmp_path / "c.h5"}"\n'
    p.write_text(text)
    assert main(["run", str(p), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert 'warning      run.method = "dsmc": packing fraction 0.3 > 0.1' in out
    p.write_text(text.replace("packing_fraction = 0.3", "packing_fraction = 0.02"))
    assert main(["run", str(p), "--quiet", "--overwrite"]) == 0
    assert "warning" not in capsys.readouterr().out
