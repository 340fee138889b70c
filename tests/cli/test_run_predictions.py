"""``granulargas run`` keeps its predictions (validity and advice lines) for the next run of the
same gas (:mod:`granulargas.run.predictions`), and its second run loads neither scipy's solvers
nor matplotlib."""

import json
import os
import subprocess
import sys
import warnings

import pytest

from granulargas.cli import main
from granulargas.cli import run as cli_run
from granulargas.io.config import load_config
from granulargas.run import predictions

CONFIG = """
[system]
dimension = 3
particles = 200
packing_fraction = 0.1
seed = 1

[collision]
{collision}

[run]
end_time = 1.0

[output]
file = "{out}"
snapshots = 3
"""
CONSTANT = 'model = "constant"\nrestitution = 0.9'
VISCOELASTIC = 'model = "viscoelastic"\ndamping = 0.05'


@pytest.fixture
def setup(tmp_path, cache_dir, monkeypatch):
    """write(collision, seed=1) -> config path; the table cache is private to the test."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("GRANULARGAS_NO_CACHE", raising=False)

    def write(collision=CONSTANT, seed=1, name="c.toml"):
        path = tmp_path / name
        path.write_text(CONFIG.format(collision=collision, out=tmp_path / "out.h5").replace("seed = 1", f"seed = {seed}"))
        return path

    return write


def _run(capsys, path, *extra):
    capsys.readouterr()
    assert main(["run", str(path), "--overwrite", "--quiet", *extra]) == 0
    out, err = capsys.readouterr()
    return [ln for ln in out.splitlines() if not ln.startswith("wall time")], err


def _kept(cache_dir):
    return sorted(cache_dir.glob("predictions-*.json"))


@pytest.mark.parametrize("collision", [CONSTANT, VISCOELASTIC])
def test_second_run_prints_the_kept_lines_without_solving(setup, capsys, cache_dir, monkeypatch, collision):
    path = setup(collision)
    first, _ = _run(capsys, path)
    assert any(ln.startswith("validity") for ln in first) and any(ln.startswith("advice") for ln in first)
    assert len(_kept(cache_dir)) == 1

    def solved(*args, **kwargs):
        raise AssertionError("the predictions were solved again")

    monkeypatch.setattr(cli_run, "raise_if_invalid", solved)
    monkeypatch.setattr(cli_run, "summary_line", solved)
    second, _ = _run(capsys, path)
    assert second == first


def test_the_key_leaves_out_seed_and_output_file_only(setup, tmp_path):
    base = predictions.cache_file(load_config(setup()))
    assert predictions.cache_file(load_config(setup(seed=7))) == base
    assert predictions.cache_file(load_config(setup(), {"output.file": str(tmp_path / "other.h5")})) == base
    assert predictions.cache_file(load_config(setup(), {"collision.restitution": 0.8})) != base
    assert predictions.cache_file(load_config(setup(), {"run.end_time": 2.0})) != base
    assert predictions.cache_file(load_config(setup(name="d.toml"))) != base  # the lines name the file


def test_no_cache_and_warnings_keep_nothing(setup, capsys, cache_dir, monkeypatch):
    path = setup()
    monkeypatch.setenv("GRANULARGAS_NO_CACHE", "1")
    _run(capsys, path)
    assert _kept(cache_dir) == []
    monkeypatch.delenv("GRANULARGAS_NO_CACHE")
    checks = cli_run.raise_if_invalid

    def warning_check(config):
        warnings.warn("a warning of the checks", RuntimeWarning)
        return checks(config)

    monkeypatch.setattr(cli_run, "raise_if_invalid", warning_check)
    with pytest.warns(RuntimeWarning, match="a warning of the checks"):  # shown as before
        _run(capsys, path)
    assert _kept(cache_dir) == []  # and shown again next time: nothing kept


def test_an_unreadable_file_is_solved_again(setup, capsys, cache_dir):
    path = setup()
    first, _ = _run(capsys, path)
    (kept,) = _kept(cache_dir)
    kept.write_text("{not json")
    assert _run(capsys, path)[0] == first
    assert json.loads(kept.read_text())["validity"]
    kept.write_text(json.dumps({"format": predictions.FORMAT, "validity": "x"}))  # a field missing
    assert _run(capsys, path)[0] == first


_MODULES = """
import json, sys
from granulargas.cli import main
rc = main(sys.argv[1:])
print(json.dumps([rc, sorted(m for m in sys.modules if m.split(".")[0] in ("scipy", "matplotlib"))]))
"""


@pytest.mark.parametrize("collision", [CONSTANT, VISCOELASTIC])
def test_second_run_loads_no_scipy_solver_nor_matplotlib(setup, tmp_path, collision):
    # numba imports scipy's top level (a version check): whatever that loads is allowed, no more
    env = dict(os.environ)
    env.pop("GRANULARGAS_NO_CACHE", None)
    bare = subprocess.run([sys.executable, "-c", "import sys, json, scipy; print(json.dumps(sorted(sys.modules)))"],
                          capture_output=True, text=True, env=env, check=True)
    allowed = set(json.loads(bare.stdout))
    path = setup(collision)
    argv = ["run", str(path), "--overwrite", "--quiet"]
    loaded = []
    for _ in range(2):
        proc = subprocess.run([sys.executable, "-c", _MODULES, *argv], capture_output=True, text=True, env=env,
                              cwd=tmp_path)
        rc, modules = json.loads(proc.stdout.splitlines()[-1])
        assert rc == 0, proc.stderr
        loaded.append(set(modules))
    assert "scipy.integrate" in loaded[0]  # the first run solves the theory (so the check can fail)
    assert loaded[1] <= allowed, sorted(loaded[1] - allowed)
