"""Smoke tests of the study scripts on a tiny synthetic run (they must not rot)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from granulargas.io.h5md import H5MDWriter
from granulargas.state import State

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def _load(name):
    spec = importlib.util.spec_from_file_location(Path(name).name, SCRIPTS / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture
def tiny_run(tmp_path):
    rng = np.random.default_rng(0)
    n, L = 400, 40.0
    path = tmp_path / "tiny.h5"
    with H5MDWriter(path, State(np.zeros((n, 2)), np.zeros((n, 2)), 0.5, 1.0, np.full(2, L)),
                    parameters={"collision": {"model": "constant", "restitution": 0.8}}) as w:
        for k, t in enumerate([0.0, 1.0, 2.0]):
            T = 1.0 / (1 + t) ** 2
            w.write_observables(k, t, {"temperature": T, "collisions": 100 * k})
            w.write_state(State(rng.uniform(0, L, (n, 2)), rng.normal(0, np.sqrt(T), (n, 2)), 0.5, 1.0, np.full(2, L),
                                time=t, events=k))
    return path


def test_clustering_analysis_script(tiny_run, tmp_path, capsys):
    mod = _load("figures/clustering_analysis")
    assert mod.main([str(tiny_run), "--prefix", str(tmp_path / "c"), "--frames", "0", "2"]) == 0
    for name in ("c_series.png", "c_t000.png", "c_t002.png"):
        assert (tmp_path / name).stat().st_size > 5000
    out = capsys.readouterr().out
    assert "S_max" in out and len([l for l in out.splitlines() if l.strip().startswith(("0 ", "1 ", "2 "))]) == 3


def test_movie_script_writes_gif(tiny_run, tmp_path):
    mod = _load("figures/movie")
    out = tmp_path / "m.gif"
    assert mod.main([str(tiny_run), "--out", str(out), "--pixels", "50"]) == 0
    assert out.stat().st_size > 1000


def test_kinetic_theory_check_script(capsys):
    mod = _load("validation/kinetic_theory_check")
    assert mod.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "engine/theory-1" in out and "a2 theory" in out


def test_models_speed_accuracy_script(tmp_path, capsys):
    mod = _load("validation/models_speed_accuracy")
    assert mod.main(["--quick", "--prefix", str(tmp_path / "m")]) == 0
    for name in ("m_speed_accuracy.png", "m_where_dsmc_fails.png"):
        assert (tmp_path / name).stat().st_size > 5000
    out = capsys.readouterr().out
    # every sample size of both methods reports a finite error; the clustered gas is warmer than DSMC's
    rows = [l for l in out.splitlines() if "rms(T/T_ref - 1)" in l]
    assert len(rows) == 4 and all("nan" not in r for r in rows)
    last = [l for l in out.splitlines() if "T_engine/T_DSMC =" in l][-1]
    assert float(last.split("=")[-1]) > 1.05


def test_headline_figure_draws_the_theory_of_analyze(tmp_path):
    # scripts/validation/haff_comparison.py (docs/figures/cooling_haff.png): T/T_theory is taken against
    # the theory granulargas analyze uses (theory.gas.cooling_curve, exact eps(g) for the
    # viscoelastic gas), not against the leading-order law, which is several per cent off
    from granulargas.analysis.run import analyze_cooling
    from granulargas.io.config import parse_config
    from granulargas.run.runner import run_config

    mod = _load("validation/haff_comparison")
    path = tmp_path / "v.h5"
    text = ('[system]\ndimension = 3\nparticles = 5000\npacking_fraction = 0.05\nseed = 1\n\n[collision]\n'
            'model = "viscoelastic"\ndamping = 0.1\n\n[run]\nmethod = "dsmc"\nend_time = 200.0\n\n'
            f'[output]\nfile = "{path}"\nsnapshots = 8\n')
    run_config(parse_config(text, source="v"), overwrite=True, quiet=True, log=lambda *_: None)
    a = analyze_cooling(path)
    grid = np.geomspace(0.1, a.time[-1] / a.prediction.tau0, 30)
    mean, _ = mod.seed_band([a], grid)
    np.testing.assert_allclose(mean, np.interp(grid, a.time / a.prediction.tau0, a.ratio), rtol=1e-12)
    closed = np.interp(grid, a.time / a.prediction.tau0, a.history.temperature / a.prediction.temperature(a.time))
    assert np.max(np.abs(closed / mean - 1)) > 0.02
    png = tmp_path / "c.png"
    mod.figure_cooling({"const": ("a", [a]), "visco": ("b", [a])}, png)
    assert png.stat().st_size > 20_000
