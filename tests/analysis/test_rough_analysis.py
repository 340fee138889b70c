"""Runs of rough particles through the user's tools: analyze (report, JSON, figure), advise and
the run summary, the scene, and a run built in Python (RunWriter)."""

import json
import math

import numpy as np
import pytest

from granulargas.analysis.kinds import analyze_file
from granulargas.cli import main
from granulargas.engine import CollisionRule, Simulation, TangentialRule
from granulargas.initial import random_state
from granulargas.io.config import load_config
from granulargas.io.scene import Scene
from granulargas.run.advise import advise, summary_line
from granulargas.run.record import RunWriter
from granulargas.run.runner import run_config
from granulargas.theory import rough as R

ROUGH = """
[system]
dimension = 3
particles = 400
packing_fraction = 0.05
seed = 2

[initial]
rotational_temperature = 0.0

[collision]
model = "constant"
restitution = 0.9

[collision.tangential]
restitution = 0.0

[run]
collisions_per_particle = 30

[output]
file = "{out}"
snapshots = 4
"""


@pytest.fixture(scope="module")
def rough_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("rough")
    path = d / "c.toml"
    path.write_text(ROUGH.replace("{out}", str(d / "r.h5")))
    cfg = load_config(path)
    return cfg, run_config(cfg).output


def test_analyze_compares_two_temperatures_with_the_theory(rough_run, tmp_path):
    cfg, out = rough_run
    a = analyze_file(out)
    assert a.kind == "rough" and not a.driven
    s = a.summary()
    assert s["theta_theory"] == pytest.approx(R.hcs_temperature_ratio(0.9, 0.0, 0.4, 3), rel=1e-12)
    # relaxed theta (400 spheres, from spins at rest): near the Maxwellian theta_HCS, which is known
    # to be a few per cent high
    assert 0.85 < s["theta"] / s["theta_theory"] < 1.05
    assert 0.8 < s["theta_theory_samples"] / s["theta_theory"] <= 1.0
    assert s["T_tr_final"] == pytest.approx(s["T_tr_final_theory"], rel=0.1)
    assert a.history.rotational[0] == 0.0 and a.history.rotational[-1] > 0.0
    assert all(math.isfinite(s[f"cumulant_{k}"]) for k in ("a20", "a02", "a11"))
    png = tmp_path / "r.png"
    assert main(["analyze", str(out), "--plot", str(png)]) == 0
    assert png.stat().st_size > 10_000


def test_analyze_json_and_report(rough_run, capsys):
    _, out = rough_run
    assert main(["analyze", str(out), "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["kind"] == "rough" and s["tangential"] == "constant" and s["inertia"] == 0.4
    assert main(["analyze", str(out)]) == 0
    text = capsys.readouterr().out
    assert "theta = T_rot/T_tr" in text and "homogeneous cooling state (Maxwellian) 0.57379" in text


def test_scene_advice_and_summary(rough_run):
    cfg, out = rough_run
    assert Scene.from_config(cfg).rough and Scene.from_file(out).rough
    assert "rough particles" in Scene.from_config(cfg).describe()
    adv = advise(cfg)
    assert adv.rough_deviation > 0.5 and not adv.smooth_ok  # beta_t = 0 changes the cooling a lot
    assert "two-temperature theory" in adv.lines()[0]
    assert "smooth particles (beta_t = -1) would not do" in summary_line(cfg)
    assert not any("best const" in x or "equivalent" in x for x in adv.lines())  # smooth comparisons left out


def test_a_smooth_enough_rough_gas_is_told_so(rough_run):
    cfg, _ = rough_run
    from dataclasses import replace

    nearly = replace(cfg, collision=replace(cfg.collision, tangential=replace(cfg.collision.tangential,
                                                                              restitution=-0.999)))
    adv = advise(nearly)
    assert adv.smooth_ok and adv.rough_deviation < 0.02


def test_runwriter_of_a_python_run_is_analysed_as_rough(tmp_path):
    st = random_state(300, 0.05, 2, seed=4)
    st = st.replace(angular_velocities=np.zeros((300, 1)))
    sim = Simulation(st, CollisionRule.constant(0.9), tangential=TangentialRule.coulomb(0.5, 0.3))
    path = tmp_path / "py.h5"
    with RunWriter(path, sim) as out:
        for t in np.linspace(2.0, 60.0, 30):
            sim.run(t)
            out.sample()
        out.snapshot()
    a = analyze_file(path)
    assert a.kind == "rough" and a.gas.tangential == "coulomb" and a.gas.friction == 0.3
    assert a.gas.inertia == 0.5
    assert a.history.rotational[-1] > 0
