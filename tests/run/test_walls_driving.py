"""Config runs with walls and with white-noise driving: input errors, the file, the analysis."""

import json

import numpy as np
import pytest

from granulargas.cli import main
from granulargas.io.config import load_config
from granulargas.io.h5md import load_snapshot, open_run, read_observables, read_parameters
from granulargas.run.runner import run_config

WALLS = """
[system]
dimension = 3
particles = 400
packing_fraction = 0.1
seed = 2
boundary = ["periodic", "periodic", "wall"]

[collision]
model = "constant"
restitution = 0.9
wall_restitution = 0.7

[run]
end_time = 5.0

[output]
file = "{out}"
observables_interval = 0.5
"""

DRIVEN = """
[system]
dimension = 2
particles = 400
packing_fraction = 0.1
seed = 2

[collision]
model = "constant"
restitution = 0.9

[driving]
model = "white_noise"
heating_rate = 0.05

[run]
end_time = 400.0

[output]
file = "{out}"
snapshot_interval = 40.0
observables_interval = 2.0
"""


@pytest.mark.parametrize("text, override, match", [
    (WALLS, {"system.boundary": ["periodic", "wall"]}, "2 entries for a 3D system"),
    (WALLS, {"system.boundary": ["periodic", "periodic", "mirror"]}, '"mirror" is not one of'),
    (WALLS, {"system.boundary": "wall"}, "a list of 3 strings"),
    (WALLS, {"system.particles": 30, "system.packing_fraction": 0.3}, "wall axis z is .* too short for the"),
    (WALLS, {"system.boundary": ["periodic"] * 3}, "wall_restitution .* only used with walls"),
    (DRIVEN, {"driving.heating_rate": -0.1}, r"driving.heating_rate = -0.1: must be a number in \[0, "),
    (DRIVEN, {"driving.model": "shaker"}, "driving.model"),
    (DRIVEN, {"driving.interval": 0.0}, "driving.interval"),
], ids=["boundary-length", "boundary-value", "boundary-type", "wall-axis-short", "wall-eps-no-walls",
        "heating-negative", "driving-model", "driving-interval"])
def test_bad_input_is_one_line_exit_2_and_no_file(write_config, tmp_path, capsys, text, override, match):
    out = tmp_path / "runs" / "x.h5"
    cfg = write_config(text, out=str(out))
    args = ["run", str(cfg), "--quiet"]
    for k, v in override.items():
        args += ["--set", f"{k}={json.dumps(v)}"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ")
    import re
    assert re.search(match, err), err
    assert not out.exists()


def test_walled_run_file_and_analysis(write_config, tmp_path, capsys):
    cfg = write_config(WALLS)
    summary = run_config(load_config(cfg))
    with open_run(summary.output) as f:
        assert [b.decode() if isinstance(b, bytes) else b
                for b in f["particles/all/box"].attrs["boundary"]] == ["periodic", "periodic", "none"]
    snap = load_snapshot(summary.output)
    assert snap.boundary == ("periodic", "periodic", "wall")
    assert np.all(snap.images[:, 2] == 0)
    assert np.all(snap.positions[:, 2] >= 0.5 * (1 - 1e-9))
    assert np.all(snap.positions[:, 2] <= snap.box[2] - 0.5 * (1 - 1e-9))
    obs = read_observables(summary.output)
    wc, wp = obs["wall_collisions"][2], obs["wall_pressure"][2]
    assert wc[-1] > 100 and np.all(np.diff(wc) >= 0)
    assert np.isnan(wp[0]) and np.all(wp[1:] >= 0) and np.mean(wp[1:]) > 0  # short windows may see none
    assert read_parameters(summary.output)["collision"]["wall_restitution"] == 0.7
    assert main(["analyze", str(summary.output), "--json"]) == 0
    walls = json.loads(capsys.readouterr().out)["walls"]
    assert walls["axes"] == [2] and walls["wall_pressure"] > 0 and 0.05 < walls["bulk_packing"] < 0.2


def test_driven_run_is_analysed_against_its_steady_state(write_config, tmp_path, capsys):
    cfg = write_config(DRIVEN)
    summary = run_config(load_config(cfg))
    params = read_parameters(summary.output)["driving"]
    # the kick interval divides the observables interval: samples half-way between kicks
    assert params["heating_rate"] == 0.05
    assert 2.0 / params["interval"] == pytest.approx(round(2.0 / params["interval"]), abs=1e-9)
    obs = read_observables(summary.output)
    assert obs["kick_step"][2][-1] == round(400.0 / params["interval"])
    e = obs["kinetic_energy"][2][-1]
    assert e == pytest.approx(obs["kinetic_energy"][2][0] + obs["injected_energy"][2][-1]
                              - obs["dissipated_energy"][2][-1], rel=1e-9)
    assert main(["analyze", str(summary.output), "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["kind"] == "driven" and s["theory"].startswith("Enskog")
    # 400 disks, ~30 cooling times after the relaxation: T_ss within 3 % (error ~1 %)
    assert s["T_ratio"] == pytest.approx(1.0, abs=max(0.03, 3 * s["T_ratio_error"]))
    assert main(["analyze", str(summary.output)]) == 0
    out = capsys.readouterr().out
    assert "T_ss =" in out and "heating rate H = 0.05" in out
