"""A DSMC file (velocities, no positions) through the commands: analyze reads it, export
refuses it with one line, a sweep runs DSMC configs."""

import json
from concurrent.futures import ThreadPoolExecutor

import pytest

from granulargas import theory
from granulargas.cli import main
from granulargas.io.h5md import has_positions, read_observables
from granulargas.run.sweep import load_sweep, run_sweep

CONFIG = """
[system]
dimension = 3
particles = 2000
packing_fraction = 0.02
seed = 5

[collision]
model = "constant"
restitution = 0.8

[run]
method = "dsmc"
end_time = 60.0

[output]
file = "{out}"
snapshots = 12
"""


def _run(tmp_path, capsys, text=CONFIG):
    out = tmp_path / "d.h5"
    cfg = tmp_path / "d.toml"
    cfg.write_text(text.replace("{out}", str(out)))
    assert main(["run", str(cfg), "--quiet"]) == 0
    capsys.readouterr()
    return cfg, out


def test_analyze_reads_a_dsmc_file(tmp_path, capsys):
    """Temperature against Haff's law and a2 against the first-Sonine theory: the DSMC
    solves the Enskog-Boltzmann equation, so both agree within the sampling error."""
    _, out = _run(tmp_path, capsys)
    png = tmp_path / "d.png"
    assert main(["analyze", str(out), "--plot", str(png)]) == 0
    text = capsys.readouterr().out
    assert "method = dsmc" in text and png.stat().st_size > 0
    # the velocity distribution of the snapshots of the report's a2 mean: the same a2 with the
    # same error (one window, one error estimate), against the HCS reference
    vel = tmp_path / "v.png"
    assert main(["analyze", str(out), "--velocity", str(vel)]) == 0
    text = capsys.readouterr().out
    assert "velocity distribution:" in text and "high-energy tail" in text and vel.stat().st_size > 0
    report = [x for x in text.splitlines() if x.startswith("  a2 = ")][0]
    dist = [x for x in text.splitlines() if "velocity distribution:" in x][0]
    m_report, e_report = (float(x) for x in report.split("a2 = ")[1].split(":")[0].split(" +- "))
    m_dist, e_dist = (float(x) for x in dist.split("a2 = ")[1].split(",")[0].split(" +- "))
    assert m_report == pytest.approx(m_dist, abs=1e-5) and e_report == pytest.approx(e_dist, rel=0.05)
    assert f"mean of {report.split('mean of ')[1].split()[0]} snapshots" in report
    assert f"velocity distribution: {report.split('mean of ')[1].split()[0]} snapshots" in dist
    assert main(["analyze", str(out), "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["method"] == "dsmc" and js["kind"] == "cooling"
    # T(t) against Haff's law with the van Noije-Ernst a2 (first Sonine; off from the exact
    # Boltzmann a2 by a few per cent, a 1e-3 effect on the cooling rate at eps = 0.8)
    obs = read_observables(out)
    t, temp = obs["temperature"][1], obs["temperature"][2]
    n = theory.number_density(0.02, 3, 1.0)
    tau0 = theory.haff_tau0(0.8, n, 1.0, 3, 1.0, 1.0)
    haff = theory.haff_temperature(t, 1.0, tau0)
    assert abs(temp[-1] / haff[-1] - 1.0) < 0.03, (temp[-1], haff[-1])
    # a2 over the second half: the HCS value, within the sampling error of 2000 particles (~0.03 per sample)
    a2 = obs["sonine_a2"][2][t > 30.0].mean()
    assert abs(a2 - theory.sonine_a2(0.8, 3)) < 0.03


def test_export_refuses_a_dsmc_file_with_one_line(tmp_path, capsys):
    cfg, out = _run(tmp_path, capsys, CONFIG.replace("end_time = 60.0", "end_time = 2.0"))
    assert not has_positions(out)
    gsd = tmp_path / "d.gsd"
    assert main(["export", "gsd", str(out), "-o", str(gsd)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "DSMC file has no positions" in err and not gsd.exists()
    assert main(["export", "lammps", str(cfg), "-o", str(tmp_path / "lmp")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'run.method = "dsmc"' in err and "no positions" in err
    assert not (tmp_path / "lmp").exists()


def test_a_sweep_runs_dsmc_configs(tmp_path):
    base = CONFIG.replace("end_time = 60.0", "end_time = 5.0").replace('file = "{out}"', 'file = "unused.h5"')
    (tmp_path / "base.toml").write_text(base)
    (tmp_path / "sweep.toml").write_text('base = "base.toml"\noutput_dir = "out"\n\n[vary]\n'
                                         "collision.restitution = [0.9, 0.5]\n")
    with ThreadPoolExecutor(1) as pool:
        entries = run_sweep(load_sweep(tmp_path / "sweep.toml"), pool, log=lambda *a: None)
    assert [e["status"] for e in entries] == ["done", "done"]
    files = [e["file"] for e in entries]
    assert not any(has_positions(f) for f in files)
    t_final = [read_observables(f)["temperature"][2][-1] for f in files]
    assert t_final[1] < t_final[0] < 1.0  # the more inelastic gas cools faster


def test_velocity_distribution_of_an_engine_file(tmp_path, capsys):
    """--velocity reads velocities only, so it works for either method; an elastic gas is
    Maxwellian (a2 = 0 within its sampling error, ~ sqrt(8 / (d (d + 2) N)) per snapshot)."""
    text = CONFIG.replace('method = "dsmc"\n', "").replace('model = "constant"\nrestitution = 0.8',
                                                           'model = "elastic"').replace(
        "particles = 2000", "particles = 500").replace("end_time = 60.0", "end_time = 20.0")
    _, out = _run(tmp_path, capsys, text)
    assert has_positions(out)
    assert main(["analyze", str(out), "--velocity", str(tmp_path / "v.png")]) == 0
    line = [x for x in capsys.readouterr().out.splitlines() if "velocity distribution" in x][0]
    a2 = float(line.split("a2 = ")[1].split()[0])
    assert abs(a2) < 4 * (8.0 / (15 * 500 * 6)) ** 0.5 and "a2 of the Maxwellian: 0.00000" in line
    assert main(["analyze", str(out), "--velocity", str(tmp_path / "missing" / "v.png")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--velocity" in err
