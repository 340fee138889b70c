"""Sweep aggregation: seed averages against a direct read, tau0 against theory."""

import json
import math
from concurrent.futures import ThreadPoolExecutor

import h5py
import numpy as np
import pytest

from granulargas import theory
from granulargas.analysis.ensemble import SweepResults
from granulargas.analysis.kinds import analyze_file
from granulargas.cli import main
from granulargas.run.sweep import load_sweep, run_sweep

BASE = """\
[system]
dimension = 2
particles = 400
packing_fraction = 0.1
seed = 1

[initial]
temperature = 1.0

[collision]
model = "constant"
restitution = 0.9

[run]
end_time = 20.0

[output]
file = "unused.h5"
snapshots = 2
observables_interval = 0.5
"""


@pytest.fixture(scope="module")
def sweep_dir(tmp_path_factory):
    tmp_path = tmp_path_factory.mktemp("sweep")
    (tmp_path / "base.toml").write_text(BASE)
    (tmp_path / "sweep.toml").write_text(
        'base = "base.toml"\noutput_dir = "out"\n[vary]\n'
        "collision.restitution = [0.95, 0.8]\nsystem.seed = [1, 2, 3]\n"
    )
    with ThreadPoolExecutor(1) as pool:
        entries = run_sweep(load_sweep(tmp_path / "sweep.toml"), pool, log=lambda *a: None)
    assert all(e["status"] == "done" for e in entries)
    return tmp_path / "out"


def test_seed_average_and_tau0_scan(sweep_dir):
    results = SweepResults(sweep_dir)
    assert results.varied == ["collision.restitution"]
    histories = {h.parameters["collision.restitution"]: h for h in results.temperature()}
    assert set(histories) == {0.95, 0.8}

    # the ensemble mean is the plain mean of the files' temperature series
    h = histories[0.8]
    direct = []
    for file in h.files:
        with h5py.File(file, "r") as fh:
            direct.append(fh["observables/temperature/value"][:])
    np.testing.assert_allclose(h.mean, np.mean(direct, axis=0), rtol=1e-12)
    assert h.temperatures.shape[0] == 3 and np.all(np.isfinite(h.stderr[1:]))

    # tau0 against restitution: ordered, and near Enskog (small 2D systems: 10 %; measured 5 % and 0.1 %)
    scan = results.tau0_scan("collision.restitution", exponent=2.0)
    np.testing.assert_array_equal(scan.values, [0.8, 0.95])
    n = theory.number_density(0.1, dim=2)
    predicted = np.array([theory.haff_tau0(e, n, T0=1.0, dim=2) for e in scan.values])
    assert scan.mean[0] < scan.mean[1]
    np.testing.assert_allclose(scan.mean, predicted, rtol=0.10)


def test_sweep_summaries_repr_and_cli(sweep_dir, capsys, tmp_path):
    results = SweepResults(sweep_dir)
    text = repr(results)
    assert "6 runs done" in text and "2 parameter sets" in text and "3 seeds" in text
    groups = results.summaries()
    assert [g.parameters["collision.restitution"] for g in groups] == [0.8, 0.95]
    for g in groups:
        # mean and standard error over the seeds of the per-file analyses
        tau = [analyze_file(f, with_sonine=False).fit.tau0 for f in g.files]
        assert g.quantity == "tau0" and g.seeds == 3
        assert g.value == pytest.approx(np.mean(tau), rel=1e-12)
        assert g.error == pytest.approx(np.std(tau, ddof=1) / math.sqrt(3), rel=1e-9)
        assert abs(g.value / g.theory - 1) < 0.1 and abs(g.T_ratio_final - 1) < 0.1
        assert g.ratio_mean.shape == g.ratio_time.shape and g.ratio_time.size > 10
    assert main(["analyze", str(sweep_dir), "--json", "--plot", str(tmp_path / "s.png")]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["varied"] == ["collision.restitution"] and len(out["groups"]) == 2
    g = out["groups"][0]
    assert g["seeds"] == 3 and g["quantity"] == "tau0" and "DSMC table" in g["theory"]
    assert g["value"] == pytest.approx(groups[0].value) and g["theory_value"] == pytest.approx(groups[0].theory)
    assert (tmp_path / "s.png").stat().st_size > 10_000
    assert main(["analyze", str(sweep_dir), "--plot"]) == 0  # without a path: inside the sweep's directory
    assert f"wrote {sweep_dir / 'sweep.png'}" in capsys.readouterr().out
    assert (sweep_dir / "sweep.png").stat().st_size > 10_000
    assert main(["analyze", str(sweep_dir)]) == 0
    table = capsys.readouterr().out
    assert "seeds" in table and "T_theory" in table and "0.95" in table
