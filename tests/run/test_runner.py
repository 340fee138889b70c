"""Config runs end to end on small systems: schedule, restart equality, crash safety."""

import math
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from granulargas.io.config import load_config, parse_config
from granulargas.io.h5md import iter_snapshots, load_snapshot, read_observables, read_parameters, snapshot_count
from granulargas.run.runner import mean_free_time, output_schedule, run_config


def test_schedule_log_spaced_from_mean_free_time(small_3d):
    c = parse_config(small_3d.replace("snapshot_interval = 1.0", "snapshots = 6").replace("{out}", "x.h5"), "x.toml")
    s = output_schedule(c)
    snaps = s.targets[s.snapshot]
    t_mf = mean_free_time(c)
    assert snaps[0] == pytest.approx(t_mf) and snaps[-1] == 4.0 and len(snaps) == 5  # + the start frame
    ratios = snaps[1:] / snaps[:-1]
    assert np.allclose(ratios, ratios[0])
    assert set(np.round(np.arange(1, 17) * 0.25, 12)) <= set(np.round(s.targets, 12))


@pytest.mark.parametrize("end", [27.5, 4.0, 0.3, 1e-3 * 7, 123.456])
def test_schedule_never_passes_the_end_time(small_3d, end):
    """27.5 / 200 * 200 = 27.500000000000004: the last target must be end_time itself."""
    text = small_3d.replace("end_time = 4.0", f"end_time = {end!r}").replace(
        "observables_interval = 0.25", "").replace("{out}", "x.h5")
    s = output_schedule(parse_config(text, "x.toml"))
    assert s.targets[-1] == end and np.all(s.targets[:-1] < end)
    assert np.all(np.diff(s.targets) > 0)


def test_mean_free_time_is_enskog():
    # 3D, eta = 0.1: omega = 4 sqrt(pi) chi n sigma^2 sqrt(T/m), n = 6 eta / pi, chi = (1 - eta/2)/(1 - eta)^3
    # (the schedule keeps the closed-form chi so that output times do not move with the theory)
    c = parse_config('[system]\npacking_fraction = 0.1\n[collision]\nmodel = "elastic"\n[run]\nend_time = 1.0', "x")
    chi = 0.95 / 0.9**3
    assert mean_free_time(c) == pytest.approx(1 / (4 * math.sqrt(math.pi) * chi * 0.6 / math.pi))


def test_run_writes_schedule_and_summary(write_config):
    cfg = load_config(write_config())
    summary = run_config(cfg)
    assert summary.output.exists() and summary.snapshots == 5 and summary.stop_reason == "end_time"
    assert summary.time == 4.0 and summary.collisions > 0 and summary.events >= summary.collisions
    snaps = list(iter_snapshots(summary.output))
    assert [s.time for s in snaps] == [0.0, 1.0, 2.0, 3.0, 4.0]
    obs = read_observables(summary.output)
    step, t, temp = obs["temperature"]
    assert np.allclose(t, np.arange(17) * 0.25) and temp[0] == pytest.approx(1.0, rel=1e-12)
    assert temp[-1] == pytest.approx(summary.final_temperature, rel=1e-14)
    assert np.all(np.diff(obs["collisions"][2]) >= 0) and obs["collisions"][2][-1] == summary.collisions
    # energy bookkeeping: kinetic energy + dissipated energy is conserved
    ke, diss = obs["kinetic_energy"][2], obs["dissipated_energy"][2]
    assert np.allclose(ke + diss, ke[0], rtol=1e-9)
    # T = m <c^2> / d from the snapshot equals the observable
    last = snaps[-1]
    c2 = ((last.velocities - (last.masses[:, None] * last.velocities).sum(0) / last.masses.sum()) ** 2)
    assert (last.masses[:, None] * c2).sum() / (3 * len(last.masses)) == pytest.approx(temp[-1], rel=1e-10)
    assert np.isnan(obs["pressure"][2][0]) and np.all(obs["pressure"][2][1:] > 0)
    par = read_parameters(summary.output)
    assert par["seed"] == 4 and par["summary"]["collisions"] == summary.collisions
    assert load_config(write_config(par["config"], name="resolved.toml")).collision == cfg.collision
    table = par["collision"]["restitution_table"]
    assert table["coeffs"].shape[1] == 4 and table["end"] == "overlap"


RESTART_CASES = {
    "viscoelastic-3d": {},
    "tc-model-2d": {"system.dimension": 2, "collision.model": "constant", "collision.damping": None,
                    "collision.restitution": 0.5, "collision.tc_time": 1e-3},
    "walls-driven-viscoelastic-3d": {"system.boundary": ["periodic", "periodic", "wall"],
                                     "driving.heating_rate": 0.3},
    "walls-constant-2d": {"system.dimension": 2, "system.boundary": ["wall", "wall"],
                          "collision.model": "constant", "collision.damping": None,
                          "collision.restitution": 0.8, "collision.wall_restitution": 0.6},
    "cells-viscoelastic-3d": {"run.neighbours": "cells"},
    "cells-walls-driven-tc-2d": {"system.dimension": 2, "system.boundary": ["periodic", "wall"],
                                 "collision.model": "constant", "collision.damping": None,
                                 "collision.restitution": 0.7, "collision.tc_time": 1e-3,
                                 "driving.heating_rate": 0.3, "run.neighbours": "cells"},
}


@pytest.mark.parametrize("case", sorted(RESTART_CASES))
def test_restart_equals_uninterrupted_run(small_3d, write_config, tmp_path, case):
    """run to 2t == run to t + restart to 2t: same event count, bit-identical state."""
    text = small_3d
    over = {}
    for key, value in RESTART_CASES[case].items():
        if value is None:
            text = text.replace(f"{key.split('.')[1]} = ", f"# {key.split('.')[1]} = ")
        else:
            over[key] = value
    path = write_config(text)
    full = run_config(load_config(path, over))
    half = run_config(load_config(path, {**over, "run.end_time": 2.0, "output.file": str(tmp_path / "half.h5")}))
    rest = run_config(load_config(path, {**over, "initial.from": str(half.output),
                                         "output.file": str(tmp_path / "rest.h5")}))
    assert (rest.collisions, rest.events) == (full.collisions, full.events)
    a, b = load_snapshot(full.output), load_snapshot(rest.output)
    assert a.time == b.time == 4.0 and a.step == b.step
    for name in ("positions", "velocities", "images", "last_collision"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None and y is None) or np.array_equal(x, y), name
    if case.startswith("tc"):
        assert a.last_collision is not None
    oa, ob = read_observables(full.output), read_observables(rest.output)
    assert set(oa) == set(ob)
    assert ("wall_pressure" in oa) == ("walls" in case) and ("kick_step" in oa) == ("driven" in case)
    for name in sorted(set(oa) - {"momentum"}):
        n = len(ob[name][1]) - 1  # the restart's first sample is its start (pressure NaN there)
        assert np.array_equal(oa[name][1][-n:], ob[name][1][-n:])
        assert np.array_equal(oa[name][2][-n:], ob[name][2][-n:]), name
    assert read_parameters(rest.output)["restart"]["time"] == 2.0


def test_collapse_exits_with_3_and_keeps_snapshots(write_config, tmp_path):
    from granulargas.errors import InelasticCollapseError

    text = """
[system]
dimension = 2
particles = 300
packing_fraction = 0.4
[collision]
model = "constant"
restitution = 0.2
[run]
collisions_per_particle = 20000
[output]
file = "{out}"
snapshots = 30
"""
    cfg = load_config(write_config(text))
    with pytest.raises(InelasticCollapseError) as err:
        run_config(cfg)
    assert err.value.exit_code == 3 and "snapshots" in str(err.value)
    out = tmp_path / "runs" / "out.h5"
    assert snapshot_count(out) >= 2
    assert read_parameters(out)["summary"]["stop_reason"].startswith("error: inelastic collapse")


def test_progress_bar_and_callback(write_config, capsys):
    cfg = load_config(write_config())
    seen = []
    run_config(cfg, progress=lambda sim: seen.append(sim.time))
    assert seen and seen[-1] == 4.0 and seen == sorted(seen)
    run_config(cfg, overwrite=True, progress=True)
    err = capsys.readouterr().err
    assert "coll/s" in err and "%" in err
    run_config(cfg, overwrite=True, quiet=False)  # stderr is not a terminal here: no bar
    assert capsys.readouterr().err == ""


def test_collision_budget_stops_the_run(small_3d, write_config):
    text = small_3d.replace("end_time = 4.0", "collisions_per_particle = 3").replace(
        "snapshot_interval = 1.0", "snapshots = 4").replace("observables_interval = 0.25\n", "")
    s = run_config(load_config(write_config(text)))
    assert s.collisions == 450 and s.stop_reason == "collisions_per_particle"
    assert snapshot_count(s.output) == 4
    # both limits: the earlier one wins
    text2 = small_3d.replace("end_time = 4.0", "end_time = 100.0\ncollisions_per_particle = 2")
    s2 = run_config(load_config(write_config(text2, name="b.toml")), overwrite=True)
    assert s2.collisions == 300 and s2.time < 100.0 and s2.stop_reason == "collisions_per_particle"
    assert load_snapshot(s2.output).time == s2.time


def test_two_dimensional_polydisperse_run(small_3d, write_config):
    text = small_3d.replace("dimension = 3", "dimension = 2").replace(
        "[collision]", "[particles]\ndiameter = { min = 0.8, max = 1.2 }\ndensity = 1.0\n\n[collision]")
    s = run_config(load_config(write_config(text)))
    snap = load_snapshot(s.output)
    assert snap.positions.shape == (300, 2) and 0.4 <= snap.radii.min() < snap.radii.max() <= 0.6
    assert np.allclose(snap.masses, math.pi * (2 * snap.radii) ** 2 / 4)
    eta = (math.pi * snap.radii**2).sum() / np.prod(snap.box)
    assert eta == pytest.approx(0.15, rel=1e-12)


def test_material_route_converts_to_reduced_prefactor(small_3d, write_config):
    """k = k_SI (sigma u / M^2)^(1/5), checked against beta computed directly in SI units."""
    from granulargas.contact.material import beta_from_material
    from granulargas.run.prepare import reduced_prefactor

    mat = dict(young_modulus=1e7, poisson_ratio=0.4, dissipation_time=1e-5, diameter=0.01, density=1100.0,
               speed_unit=2.0)
    text = small_3d.replace("damping = 0.1", "[collision.material]\n" + "\n".join(f"{k} = {v!r}" for k, v in mat.items()))
    cfg = load_config(write_config(text))
    k = reduced_prefactor(cfg)
    mass = 1100.0 * math.pi * 0.01**3 / 6
    g_red = 0.7  # reduced impact speed of two reference particles
    beta_si = beta_from_material(1e7, 0.4, 1e-5, 0.01 / 4, mass / 2, g_red * 2.0)
    assert k * (0.25 * g_red / 0.5**2) ** 0.2 == pytest.approx(float(beta_si), rel=1e-12)


def test_killed_run_leaves_valid_file(small_3d, write_config, tmp_path):
    text = small_3d.replace("end_time = 4.0", "end_time = 100000.0").replace(
        "snapshot_interval = 1.0", "snapshot_interval = 0.5").replace("observables_interval = 0.25", "")
    path = write_config(text)
    out = tmp_path / "runs" / "out.h5"
    proc = subprocess.Popen([sys.executable, "-m", "granulargas", "run", str(path), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.time() + 240  # a fresh numba cache compiles the engine first
        while time.time() < deadline:
            time.sleep(0.3)
            if out.exists():
                try:  # the writer holds the HDF5 file lock: peek without locking
                    with h5py.File(out, "r", locking=False) as f:
                        if f["particles/all/position/time"].shape[0] >= 4:
                            break
                except OSError:
                    pass
            assert proc.poll() is None, proc.stderr.read().decode()
        time.sleep(0.2)  # the peek may see metadata the writer has not finished flushing
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    n = snapshot_count(out)
    assert n >= 3
    times = [s.time for s in iter_snapshots(out)]
    assert times == [0.5 * k for k in range(n)]
    # and it can be continued
    cont = run_config(load_config(path, {"initial.from": str(out), "output.file": str(tmp_path / "c.h5"),
                                         "run.end_time": times[-1] + 1.0}))
    assert cont.time == times[-1] + 1.0 and load_snapshot(cont.output).step > load_snapshot(out).step


def test_validity_warning_is_one_line(write_config):
    from granulargas.run.prepare import expected_beta, fresh_state

    cfg = load_config(write_config(), {"collision.damping": 2.0, "run.end_time": 0.5})
    typical, high = expected_beta(2.0, fresh_state(cfg))  # k = damping for reference particles
    # independent check: beta = k (R_eff g / m_eff^2)^(1/5) at g = sqrt(pi T / (2 m_eff)) = sqrt(pi)
    assert typical == pytest.approx(2.0 * (0.25 * math.sqrt(math.pi) / 0.25) ** 0.2, rel=1e-12)
    assert high == pytest.approx(2.0 * (0.25 * 3 * math.sqrt(2.0) / 0.25) ** 0.2, rel=1e-12)
    lines = []
    run_config(cfg, log=lines.append)
    assert len(lines) == 1 and "\n" not in lines[0] and "beta = " in lines[0]
    lines.clear()
    run_config(load_config(write_config(), {"collision.damping": 0.05, "run.end_time": 0.5}), overwrite=True,
               log=lines.append)
    assert lines == []
