"""Elastic runs: energy drift, Z and collision frequency, on a synthetic file (exact numbers)
and on an engine run (against the Kolafa-Labik-Malijevsky equation of state and Enskog)."""

import json
import math

import numpy as np
import pytest

from granulargas import theory as th
from granulargas.analysis.elastic import analyze_elastic, block_mean
from granulargas.analysis.kinds import analyze_file
from granulargas.cli import main
from granulargas.io.h5md import H5MDWriter
from granulargas.state import State


def _write(path, n=400, eta=0.3, dim=3, z=(4.0, 3.9, 4.1, 4.0, 3.95, 4.05), rate=10.0):
    rng = np.random.default_rng(1)
    L = (n / th.number_density(eta, dim)) ** (1 / dim)
    nd = n / L**dim
    state = State(rng.uniform(0, L, (n, dim)), rng.normal(size=(n, dim)), 0.5, 1.0, np.full(dim, L))
    with H5MDWriter(path, state, parameters={"collision": {"model": "elastic"}}) as w:
        for k in range(len(z) + 1):
            t = float(k)
            ke = 0.5 * dim * n * (1.0 + 1e-15 * k)
            w.write_observables(k, t, {"temperature": 1.0, "kinetic_energy": ke, "collisions": int(0.5 * n * rate * t),
                                       "pressure": np.nan if k == 0 else z[k - 1] * nd})
        w.write_state(state)
    return path


def test_synthetic_elastic_file(tmp_path):
    path = _write(tmp_path / "e.h5")
    a = analyze_file(path)
    assert a.kind == "elastic"
    s = a.summary()
    # windows from t_eq = max(0.1 * 6, 5 t_free) on; t_free = 1/omega_Enskog(eta = 0.3) ~ 0.1
    assert a.t_equilibrated == pytest.approx(0.6)
    assert s["Z"] == pytest.approx(np.mean([3.9, 4.1, 4.0, 3.95, 4.05]), rel=1e-12)
    assert s["collision_frequency"] == pytest.approx(10.0, rel=1e-12)
    assert s["energy_drift_final"] == pytest.approx(6e-15, rel=1e-3)
    assert s["Z_theory"] == pytest.approx(th.compressibility_factor(0.3, 3)) and s["Z_theory_name"] == "Kolafa-Labík-Malijevský"
    assert s["tau0_fit"] is None and s["tau0_theory"] is None


def test_block_mean_error_follows_the_scatter_of_correlated_means():
    # AR(1) series (correlation 0.8 between neighbours): over 300 replicates the block
    # error matches the actual scatter of the means, which the naive std/sqrt(n) misses
    rng = np.random.default_rng(3)
    reps, n, rho = 300, 2000, 0.8
    noise = rng.normal(size=(reps, n))
    x = np.empty_like(noise)
    x[:, 0] = noise[:, 0] / math.sqrt(1 - rho**2)
    for i in range(1, n):
        x[:, i] = rho * x[:, i - 1] + noise[:, i]
    est = np.array([block_mean(r)[1] for r in x])
    actual = x.mean(axis=1).std()
    naive = (x.std(axis=1) / math.sqrt(n)).mean()
    assert 0.85 < est.mean() / actual < 1.1
    assert naive < 0.5 * actual
    assert math.isnan(block_mean([1.0])[1])


@pytest.fixture(scope="module")
def elastic_run(tmp_path_factory):
    from granulargas.io.config import parse_config
    from granulargas.run.runner import run_config

    path = tmp_path_factory.mktemp("elastic") / "e3.h5"
    text = (f'[system]\ndimension = 3\nparticles = 1000\npacking_fraction = 0.3\nseed = 4\n[collision]\nmodel = "elastic"\n'
            f'[run]\nend_time = 12.0\n[output]\nfile = "{path}"\nsnapshot_interval = 4.0\nobservables_interval = 0.5\n')
    run_config(parse_config(text, source="test"), overwrite=True)
    return path


def test_engine_elastic_run_matches_kolafa_labik_malijevsky(elastic_run, capsys, tmp_path):
    # N = 1000 at packing 0.3, ~120 collisions per particle: Z within 1 % of the equation of
    # state (Carnahan-Starling is 0.26 % below it), omega within 1 % of Enskog with the same chi
    assert main(["analyze", str(elastic_run), "--json", "--plot", str(tmp_path / "e.png")]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["kind"] == "elastic" and s["tau0_theory"] is None and s["tau0_fit"] is None
    assert abs(s["Z"] / s["Z_theory"] - 1) < 0.01
    assert abs(s["Z"] - s["Z_theory"]) < 4 * s["Z_error"] + 0.005
    assert abs(s["collision_frequency"] / s["collision_frequency_theory"] - 1) < 0.01
    assert s["energy_drift_max"] < 1e-12
    assert (tmp_path / "e.png").stat().st_size > 10_000


def test_elastic_report_prints_z(elastic_run, capsys):
    assert main(["analyze", str(elastic_run), "--no-snapshots"]) == 0
    out = capsys.readouterr().out
    assert "Z = P/(nT)" in out and "Kolafa-Labík-Malijevský" in out and "Carnahan-Starling" in out
    assert "energy drift" in out and "tau0" not in out
    a = analyze_elastic(elastic_run, with_sonine=False)
    assert a.sonine[0].size == 0
