"""File-level analysis on synthetic H5MD files (written with io's H5MDWriter)."""

import numpy as np
import pytest

from granulargas import theory as th
from granulargas.analysis.run import RunInfo, analyze_cooling, cooling_history, snapshot_series, sonine_history
from granulargas.cli import main
from granulargas.io.h5md import H5MDWriter
from granulargas.state import State
from granulargas.theory.hcs import DSMC_TABLE, hcs_reference


def _haff_tau0(eps, n, dim):
    """Haff's tau0 with the cooling rate of the HCS reference (theory.hcs)."""
    return 2.0 / (th.enskog_cooling_rate(eps, n, 1.0, dim, a2=0.0) * hcs_reference(eps, dim).zeta_factor)


def _write(path, dim=3, n=500, eta=0.1, eps=0.9, frames=5, tau0=None):
    rng = np.random.default_rng(0)
    L = (n / th.number_density(eta, dim)) ** (1 / dim)
    box = np.full(dim, L)
    tau0 = tau0 or _haff_tau0(eps, th.number_density(eta, dim), dim)
    with H5MDWriter(path, State(np.zeros((n, dim)), np.zeros((n, dim)), 0.5, 1.0, box),
                    parameters={"collision": {"model": "constant", "restitution": eps}}) as w:
        t = np.concatenate([[0.0], np.geomspace(0.1, 100 * tau0, 80)])
        T = th.haff_temperature(t, 1.0, tau0)
        for k, (tk, Tk) in enumerate(zip(t, T)):
            w.write_observables(k, tk, {"temperature": Tk, "collisions": int(k * 100)})
        for k, tk in enumerate(np.geomspace(1.0, 100 * tau0, frames)):
            Tk = th.haff_temperature(tk, 1.0, tau0)
            w.write_state(State(rng.uniform(0, L, (n, dim)), rng.normal(0, np.sqrt(Tk), (n, dim)), 0.5, 1.0, box,
                                time=tk, events=k))
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


REQUIRED_JSON = ("model", "dimension", "t_final", "T_final", "theory", "T_theory_final", "T_ratio_final", "tau0_fit",
                 "tau0_theory", "exponent_fit", "exponent_theory", "a2_mean", "Z", "Z_theory")


def test_cooling_analysis_uses_the_kinetic_theory(tmp_path):
    # the file holds Haff's law with the HCS reference's cooling rate from t = 0; the kinetic
    # theory starts Maxwellian (a2 = 0), relaxes to the same state and then runs parallel to it
    path, tau0 = _write(tmp_path / "a.h5")
    a = analyze_cooling(path)
    assert a.theory is not None and DSMC_TABLE in a.theory_name
    late = a.time > 10 * tau0
    r = a.ratio[late]
    assert np.ptp(r) < 2e-3 and abs(r.mean() - 1) < 0.01
    # the same fixed-exponent fit of run and theory curve
    assert a.theory_fit.tau0 == pytest.approx(tau0, rel=0.01)
    assert a.T_ratio_final == pytest.approx(r[-1], rel=1e-3)


def test_analyze_json_has_the_documented_keys(tmp_path, capsys):
    import json

    path, tau0 = _write(tmp_path / "a.h5")
    assert main(["analyze", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in REQUIRED_JSON:
        assert key in out, key
    assert out["model"] == "constant" and out["dimension"] == 3 and out["kind"] == "cooling"
    assert out["tau0_fit"] == pytest.approx(tau0, rel=1e-6) and out["exponent_fit"] == pytest.approx(-2.0, rel=1e-6)
    assert 0.98 < out["T_ratio_final"] < 1.02
    assert out["Z"] is None  # the synthetic file has no pressure


def test_analyze_directory_without_index_is_one_line(tmp_path, capsys):
    assert main(["analyze", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "index.json" in err and err.count("\n") == 1


def test_pressure_windows_use_the_mean_temperature(tmp_path):
    from granulargas.analysis.run import CoolingHistory, pressure_samples

    t = np.linspace(0.0, 4.0, 5)
    T = np.exp(-t)  # log-linear: the mean of T over [a, b] is (T(a) - T(b)) / (b - a)
    p = np.array([np.nan, 1.0, np.nan, 2.0, 3.0])
    h = CoolingHistory(t, T, np.zeros(5, int), np.zeros(5), np.full(5, np.nan), p)
    s = pressure_samples(h, density=0.5)
    np.testing.assert_allclose(s.start, [0.0, 1.0, 3.0])
    np.testing.assert_allclose(s.end, [1.0, 3.0, 4.0])
    Tm = (np.exp(-s.start) - np.exp(-s.end)) / (s.end - s.start)
    np.testing.assert_allclose(s.temperature, Tm, rtol=1e-12)
    np.testing.assert_allclose(s.Z, [1.0, 2.0, 3.0] / (0.5 * Tm), rtol=1e-12)
