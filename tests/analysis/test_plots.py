"""What the figures and the text report of ``granulargas analyze`` show a reader."""

import json

import matplotlib
import numpy as np
import pytest

from granulargas import theory as th
from granulargas.analysis import plots
from granulargas.analysis.run import RunInfo, analyze_cooling
from granulargas.cli import analyze as analyze_cli
from granulargas.cli import main
from tests.analysis.test_run_file import _write

matplotlib.use("Agg")


def _captured_figures(monkeypatch):
    """Figures the plot functions close, kept open for the test to read their axes."""
    import matplotlib.pyplot as plt

    kept = []
    monkeypatch.setattr(plt, "close", lambda fig=None: kept.append(fig))
    return kept


@pytest.mark.parametrize("ratio, scale", [
    ([0.99, 1.0, 1.01], "linear"),
    ([1.0, 1.2, 1.45], "linear"),
    ([1.0, 2.0, 6.3], "log"),          # a clustered gas runs hot
    ([1.0, 0.5, 0.05], "log"),         # ... or one collapsing runs cold
])
def test_ratio_axis_holds_the_ratio_and_never_goes_negative(ratio, scale):
    s, low, high = plots.ratio_limits(ratio)
    assert s == scale and 0 < low < min(ratio) and max(ratio) < high
    assert low < 1 < high
    if scale == "linear":
        assert low + high == pytest.approx(2.0) and high - 1 >= 0.03


def test_cooling_figure_of_a_gas_far_above_theory_has_a_positive_ratio_axis(tmp_path, monkeypatch):
    eps, n = 0.9, th.number_density(0.1, 3)
    path, _ = _write(tmp_path / "hot.h5", tau0=5 * th.haff_tau0(eps, n, dim=3))  # T/T_theory grows to ~20
    a = analyze_cooling(path)
    assert np.nanmax(a.ratio) > 5
    kept = _captured_figures(monkeypatch)
    plots.plot_cooling(a, tmp_path / "hot.png")
    low, high = kept[0].axes[1].get_ylim()
    assert 0 < low < np.nanmin(a.ratio[a.time > 0]) and high > np.nanmax(a.ratio)


def _viscoelastic_info(prefactor=0.1):
    return RunInfo(path="runs/x.h5", dimension=3, particles=100, box=np.full(3, 10.0), diameter=1.0, mass=1.0,
                   monodisperse=True, model="viscoelastic", restitution=None, prefactor=prefactor)


def test_the_viscoelastic_parameter_is_called_damping_everywhere():
    """The config's damping is named `damping` in the report, the figure and the JSON."""
    info = _viscoelastic_info(0.1)
    assert info.damping == pytest.approx(0.1)  # reduced units: the reference pair's beta at g = 1 is k
    header = "\n".join(analyze_cli._header(info))
    title = plots._title(info, "Cooling")
    for text in (header, title):
        assert "damping 0.1" in text
        assert "prefactor" not in text and "k =" not in text
    assert RunInfo(**{**info.__dict__, "model": "constant", "restitution": 0.9}).damping is None


def test_report_prints_the_figures_fitted_tau0(tmp_path, monkeypatch, capsys):
    """The figure's fit (T0 (1 + t/tau0)^-p, p free) is printed in the text report too."""
    path, _ = _write(tmp_path / "a.h5")
    a = analyze_cooling(path)
    assert main(["analyze", str(path), "--no-snapshots"]) == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if "free exponent" in ln)
    assert f"tau0 = {a.fit_free.tau0:.5g}" in line and f"p = {a.fit_free.exponent:.4f}" in line
    kept = _captured_figures(monkeypatch)
    plots.plot_cooling(a, tmp_path / "a.png")
    labels = [t.get_text() for t in kept[0].axes[0].get_legend().get_texts()]
    assert any(f"{a.fit_free.tau0:.4g}" in t for t in labels)
    assert main(["analyze", str(path), "--no-snapshots", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["tau0_fit_free"] == pytest.approx(a.fit_free.tau0) and "prefactor" not in out
