"""File-level analysis on synthetic H5MD files (written with io's H5MDWriter)."""

import numpy as np
import pytest

from granulargas import theory as th
from granulargas.analysis.run import RunInfo, analyze_cooling, cooling_history, snapshot_series, sonine_history
from granulargas.cli import main
from granulargas.io.h5md import H5MDWriter


def _write(path, dim=3, n=500, eta=0.1, eps=0.9, frames=5, tau0=None):
    rng = np.random.default_rng(0)
    L = (n / th.number_density(eta, dim)) ** (1 / dim)
    box = np.full(dim, L)
    tau0 = tau0 or th.haff_tau0(eps, th.number_density(eta, dim), dim=dim)
    with H5MDWriter(path, box, np.full(n, 0.5), np.ones(n),
                    parameters={"collision": {"model": "constant", "restitution": eps}}) as w:
        t = np.concatenate([[0.0], np.geomspace(0.1, 100 * tau0, 80)])
        T = th.haff_temperature(t, 1.0, tau0)
        for k, (tk, Tk) in enumerate(zip(t, T)):
            w.write_observables(k, tk, {"temperature": Tk, "collisions": int(k * 100)})
        for k, tk in enumerate(np.geomspace(1.0, 100 * tau0, frames)):
            Tk = th.haff_temperature(tk, 1.0, tau0)
            w.write_snapshot(k, tk, rng.uniform(0, L, (n, dim)), rng.normal(0, np.sqrt(Tk), (n, dim)),
                             np.zeros((n, dim), np.int64))
    return path, tau0


def test_run_info_and_prediction(tmp_path):
    path, tau0 = _write(tmp_path / "a.h5")
    info = RunInfo.from_file(path)
    assert info.dimension == 3 and info.particles == 500 and info.monodisperse
    assert info.packing_fraction == pytest.approx(0.1)
    p = info.prediction(1.0)
    assert p.law == "haff" and p.tau0 == pytest.approx(tau0) and p.exponent == 2.0
    assert p.instability_length == pytest.approx(th.instability_length(0.9, info.number_density))


def test_analyze_cooling_recovers_the_law(tmp_path):
    path, tau0 = _write(tmp_path / "a.h5")
    a = analyze_cooling(path)
    assert a.fit.tau0 == pytest.approx(tau0, rel=1e-6)
    assert a.fit_free.exponent == pytest.approx(2.0, rel=1e-6)
    assert abs(a.tau0_deviation) < 1e-6
    t, a2, a3 = a.sonine
    assert t.size == 5 and np.all(np.abs(a2) < 0.15)
    h = cooling_history(path)
    assert h.collisions_per_particle[2] == pytest.approx(2 * 200 / 500)


def test_snapshot_series_is_lazy_and_selectable(tmp_path):
    path, _ = _write(tmp_path / "a.h5", frames=4)
    times = [t for t, _ in snapshot_series(path, lambda s: s.positions.shape, every=2)]
    assert len(times) == 2
    assert [r for _, r in snapshot_series(path, lambda s: s.index, indices=[3, 1])] == [3, 1]
    assert sonine_history(path, every=3)[0].size == 2


def test_cli_report_and_plot(tmp_path, capsys):
    path, tau0 = _write(tmp_path / "a.h5")
    png = tmp_path / "c.png"
    assert main(["analyze", str(path), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "tau0" in out and "+0.00 %" in out and "below L_c" in out
    assert png.stat().st_size > 10_000


def test_cli_missing_file_is_one_line_error(tmp_path, capsys):
    assert main(["analyze", str(tmp_path / "nope.h5")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1
