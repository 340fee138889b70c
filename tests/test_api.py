"""The front door ``import granulargas as gg``: a config run, its result as a table, its analysis."""

import math
import sys

import numpy as np
import pytest

import granulargas as gg
from granulargas.errors import ConfigError, InputFileError
from granulargas.io.h5md import read_observables, read_parameters
from granulargas.run.runner import RunSummary

pd = pytest.importorskip("pandas", reason="the [pandas] extra (installed by the [test] extra)")

CONFIG = """
[system]
dimension = 2
particles = 200
packing_fraction = 0.1
seed = 3

[collision]
model = "constant"
restitution = 0.9

[run]
end_time = 3.0

[output]
file = "{out}"
snapshots = 3
observables_interval = 0.5
"""


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    d = tmp_path_factory.mktemp("api")
    (d / "c.toml").write_text(CONFIG.replace("{out}", str(d / "run.h5")))
    return gg.simulate(d / "c.toml")


def test_simulate_runs_the_config_and_opens_its_file(result):
    assert isinstance(result, gg.Result)
    assert isinstance(result.summary, RunSummary) and result.summary.output == result.path
    assert result.summary.stop_reason == "end_time" and result.summary.time == 3.0
    assert result.snapshot_count() == result.summary.snapshots == 3
    assert result.parameters["particles"] == 200 and result.config.collision.restitution == 0.9
    assert result.snapshot().time == 3.0 and [s.index for s in result.snapshots()] == [0, 1, 2]
    assert "200" in repr(result) and "2D" in repr(result)


def test_observables_table_holds_the_files_numbers(result):
    df = result.observables()
    raw = read_observables(result.path)
    assert isinstance(df, pd.DataFrame) and df.index.name == "time"
    step, t, T = raw["temperature"]
    np.testing.assert_array_equal(df.index.to_numpy(), t)
    np.testing.assert_array_equal(df["temperature"].to_numpy(), T)
    np.testing.assert_array_equal(df["step"].to_numpy(), step)
    np.testing.assert_array_equal(df["collisions"].to_numpy(), raw["collisions"][2])
    # a vector observable: one column per axis
    np.testing.assert_array_equal(df[["momentum_x", "momentum_y"]].to_numpy(), raw["momentum"][2])
    assert "momentum" not in df.columns and "momentum_z" not in df.columns
    assert set(raw) - {"momentum", "pressure_tensor"} <= set(df.columns)
    # the pressure tensor: one column per independent component
    np.testing.assert_array_equal(df["pressure_tensor_xy"].to_numpy(), raw["pressure_tensor"][2][:, 0, 1])
    assert "pressure_tensor_yx" not in df.columns
    # the run's last sample is its end, with the summary's temperature
    assert df.index[-1] == 3.0 and math.isclose(df["temperature"].iloc[-1], result.summary.final_temperature)
    # the dict readers stay
    assert result.observables_dict().keys() == raw.keys()


def test_temperature_plots_from_the_table(result, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    df = result.observables()
    ax = df.plot(y="temperature", loglog=True)
    x, y = ax.get_lines()[0].get_data()
    np.testing.assert_array_equal(x, df.index)
    np.testing.assert_array_equal(y, df["temperature"])
    ax.figure.savefig(tmp_path / "T.png")
    assert (tmp_path / "T.png").stat().st_size > 0


def test_a_shorter_observable_is_nan_at_the_missing_times():
    from granulargas.api import observable_columns

    t = np.array([0.0, 1.0, 2.0])
    s = np.array([0, 10, 20])
    cols = observable_columns({"temperature": (s, t, np.array([1.0, 0.9, 0.8])),
                               "collisions": (s[:2], t[:2], np.array([0, 7]))})
    np.testing.assert_array_equal(cols["time"], t)
    assert cols["collisions"][:2].tolist() == [0, 7] and np.isnan(cols["collisions"][2])
    with pytest.raises(InputFileError, match="observables/collisions"):
        observable_columns({"temperature": (s, t, t), "collisions": (s[:2], t[:2] + 0.5, t[:2])})


def test_without_pandas_the_table_says_how_to_get_it(result, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ModuleNotFoundError, match=r"granulargas\[pandas\]"):
        result.observables()


def test_analyze_gives_the_analysis_of_the_run(result):
    a = result.analyze(with_sonine=False)
    assert a.kind == "cooling"
    assert a.summary()["T_ratio_final"] == gg.analyze(result.path, with_sonine=False).summary()["T_ratio_final"]


def test_load_run_refuses_what_is_not_a_run(tmp_path):
    with pytest.raises(InputFileError, match="not found"):
        gg.load_run(tmp_path / "missing.h5")
    (tmp_path / "x.h5").write_bytes(b"not hdf5")
    with pytest.raises(InputFileError):
        gg.load_run(tmp_path / "x.h5")


def test_simulate_with_overrides_and_a_bad_value_writes_nothing(tmp_path):
    (tmp_path / "c.toml").write_text(CONFIG.replace("{out}", str(tmp_path / "a.h5")))
    with pytest.raises(ConfigError, match="collision.restitution"):
        gg.simulate(tmp_path / "c.toml", overrides={"collision.restitution": 1.5})
    assert not (tmp_path / "a.h5").exists()
    cfg = gg.load_config(tmp_path / "c.toml")
    with pytest.raises(TypeError, match="load_config"):
        gg.simulate(cfg, overrides={"system.seed": 1})


def test_a_loaded_run_is_the_same_file(result):
    again = gg.load_run(result.path)
    assert again.summary is None
    assert again.parameters["summary"]["collisions"] == read_parameters(result.path)["summary"]["collisions"]


def test_the_getting_started_session_runs_as_shown(tmp_path, monkeypatch, capsys):
    """The Python blocks of docs/getting-started.md#from-python, run in order in a fresh
    directory holding the quickstart config: each works and prints what the page shows."""
    import re
    import shutil
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    root = Path(__file__).resolve().parents[1]
    page = (root / "docs" / "getting-started.md").read_text()
    section = page[page.index("## From Python"):]
    section = section[:section.index("\n## ", 1)] if "\n## " in section[1:] else section
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert len(blocks) == 3
    (tmp_path / "configs").mkdir()
    (tmp_path / "runs").mkdir()
    shutil.copy(root / "configs" / "quickstart.toml", tmp_path / "configs")
    monkeypatch.chdir(tmp_path)
    namespace = {}
    for block in blocks:
        exec(compile(block, "getting-started.md", "exec"), namespace)
    out = capsys.readouterr().out
    shown = re.search(r"print\(res\)\s+# (.*)", blocks[0]).group(1)
    assert shown in out
    assert namespace["df"].index.name == "time" and namespace["sim"].time == 5.0
    assert namespace["old"].path == namespace["res"].path
