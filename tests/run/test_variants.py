"""The compiled variants (run.variants), the start-up line that names them before the pause,
the start-up accounting of the runner, and ``granulargas compile``."""

import os
import subprocess
import sys
import time
from pathlib import Path

import numba
import pytest
from numba.core import event

from granulargas import _numba
from granulargas.cli import main
from granulargas.engine import Simulation
from granulargas.errors import ConfigError
from granulargas.io.config import load_config
from granulargas.run import runner
from granulargas.run.validity import raise_if_invalid
from granulargas.run.variants import (BY_NAME, VARIANTS, describe, run_neighbours, tiny_config, variants_for,
                                      walled_twin)

ROOT = Path(__file__).resolve().parents[2]

#: the variants each example config compiles on its first run
EXAMPLES = {
    "quickstart.toml": ["placement", "cells"],
    "haff_2d.toml": ["placement", "cells"],
    "haff_3d.toml": ["placement", "cells"],
    "driven_3d.toml": ["placement", "cells", "cells-driven"],
    "walls_3d.toml": ["placement", "cells"],
    "elastic_3d.toml": ["placement", "lists"],
    "hcs_dsmc_3d.toml": ["dsmc"],
    "clustering_2d_constant.toml": ["placement", "placement-large", "cells"],
    "vibrated_bed_2d.toml": ["placement", "cells-gravity-walls"],
    "vibrated_bed_3d.toml": ["placement", "cells-gravity-walls"],
    "shaken_cell_3d.toml": ["placement", "cells-walls"],
    "rough_hcs_3d.toml": ["placement", "cells-rough"],
    "rough_driven_2d.toml": ["placement", "cells-rough", "cells-rough-driven"],
    "rough_mpemba_hot.toml": ["placement", "cells-rough", "cells-rough-driven"],
    "mixture_hcs_3d.toml": ["dsmc-mixture"],
    "glass_steel_3d.toml": ["placement", "cells-mixture"],
    "shear_2d.toml": ["placement", "cells-shear"],
    "shear_3d.toml": ["placement", "cells-shear"],
    "shear_elastic_3d.toml": ["placement", "cells-shear"],
    "shear_dsmc_3d.toml": ["dsmc-shear"],
}


@pytest.mark.parametrize("name, expected", EXAMPLES.items())
def test_example_configs_name_the_variants_they_compile(name, expected):
    cfg = load_config(ROOT / "configs" / name)
    assert [v.name for v in variants_for(cfg)] == expected


def test_every_example_config_compiles_a_named_variant():
    for path in (ROOT / "configs").glob("*.toml"):
        names = [v.name for v in variants_for(load_config(path))]
        assert any(n in ("lists", "cells", "resolved", "dsmc", "lists-walls", "cells-walls", "lists-gravity",
                         "cells-gravity", "lists-gravity-walls", "cells-gravity-walls", "lists-rough", "cells-rough",
                         "dsmc-rough", "lists-mixture", "cells-mixture", "dsmc-mixture", "lists-shear",
                         "cells-shear", "dsmc-shear") for n in names), (path.name, names)


def test_each_variant_tiny_run_selects_it(tmp_path):
    """The tiny run that ``granulargas compile`` makes for a variant is a run of that variant."""
    for v in VARIANTS:
        if v.config is None:
            continue
        cfg = tiny_config(v, tmp_path)
        assert v in variants_for(cfg), v.name
        for dep in v.after:
            assert BY_NAME[dep] in VARIANTS


def test_each_variant_tiny_run_passes_the_checks_of_a_run(tmp_path):
    """``granulargas compile`` makes each tiny run by the steps of ``granulargas run``: its
    config passes the checks before the run (a refused one would compile nothing)."""
    for v in VARIANTS:
        if v.config is not None:
            raise_if_invalid(tiny_config(v, tmp_path))


def test_engine_variants_without_walls_also_build_walls_at_rest(tmp_path):
    """A box with walls compiles a loop of its own (the periodic one carries no walls' code):
    ``granulargas compile`` builds it beside each engine variant whose tiny run is periodic, by
    a run of the same variant with a wall axis."""
    walled = [v.name for v in VARIANTS if v.walled]
    assert {"lists", "cells", "lists-driven", "cells-driven", "lists-rough", "cells-mixture",
            "cells-shear"} <= set(walled)
    assert not {"placement", "dsmc", "resolved", "cells-walls", "lists-gravity"} & set(walled)
    for name in walled:
        twin = walled_twin(BY_NAME[name], tmp_path)
        assert "wall" in twin.system.boundary and BY_NAME[name] in variants_for(twin), name
        assert twin.source == f"<{name}-walled>" and twin.output.file.endswith(f"{name}-walled.h5")
        raise_if_invalid(twin)


def test_sheared_runs_compile_the_sheared_loops(tmp_path):
    """A run with ``[shear]`` compiles the Lees-Edwards loop of its neighbour mode (or the
    DSMC of uniform shear flow), not the loop of the same run without shear, and back."""
    for loop in ("lists", "cells", "dsmc"):
        plain = tiny_config(BY_NAME[loop], tmp_path)
        sheared = tiny_config(BY_NAME[f"{loop}-shear"], tmp_path)
        mode = None if loop == "dsmc" else loop
        assert [v.name for v in variants_for(sheared, mode)] == (["dsmc-shear"] if loop == "dsmc"
                                                                   else ["placement", f"{loop}-shear"])
        assert f"{loop}-shear" not in [v.name for v in variants_for(plain, mode)]


def test_auto_neighbours_follow_the_engine():
    cfg = load_config(ROOT / "configs" / "quickstart.toml")
    assert run_neighbours(cfg) == "cells"
    assert run_neighbours(cfg, packing=0.3) == "lists"


def test_describe_names_the_variants_in_order():
    assert describe([BY_NAME["placement"], BY_NAME["cells"]]) == "the initial placement and the cell-crossing engine"
    assert describe([BY_NAME["placement"], BY_NAME["lists"], BY_NAME["lists-driven"]]) == (
        "the initial placement, the neighbour-list engine and its driving step")


def _fake_compile(seconds):
    """A numba compile event lasting ``seconds`` (what numba sends around a real compilation)."""
    with event.trigger_event("numba:compile", data={"dispatcher": None, "args": (), "return_type": None}):
        time.sleep(seconds)


SMALL = """
[system]
dimension = 2
particles = 100
packing_fraction = 0.1
seed = 1
[collision]
model = "constant"
restitution = 0.9
[run]
collisions_per_particle = 2
[output]
file = "{out}"
snapshots = 2
"""


def test_compiling_is_announced_once_before_it_starts(tmp_path, monkeypatch):
    path = tmp_path / "c.toml"
    path.write_text(SMALL.format(out=tmp_path / "o.h5"))
    cfg = load_config(path)
    order = []
    run = Simulation.run

    def compiling_run(self, *args, **kwargs):
        if not order:
            _fake_compile(0.01)
            order.append("first compile done")
            _fake_compile(0.01)
        return run(self, *args, **kwargs)

    monkeypatch.setattr(Simulation, "run", compiling_run)
    summary = runner.run_config(cfg, log=order.append)
    lines = [x for x in order if x.startswith("compiling")]
    assert lines == [f"compiling the cell-crossing engine (once; cached in {_numba.cache_location()})"]
    assert order.index(lines[0]) < order.index("first compile done")
    assert summary.compile_time >= 0.02
    assert "of it compiling, once" in summary.lines()[2]


def test_bad_input_found_while_compiling_the_placement_stays_one_line(tmp_path, monkeypatch, capsys):
    """The initial placement compiles before it can find a config too dense for it: that
    compile is counted, not announced, so the error is the only line on stderr."""
    path = tmp_path / "c.toml"
    path.write_text(SMALL.format(out=tmp_path / "o.h5"))

    def compiling_then_refusing(config):
        _fake_compile(0.01)
        raise ConfigError(f"{config.source}: system.packing_fraction = 0.9: too dense")

    monkeypatch.setattr(runner, "prepare", compiling_then_refusing)
    assert main(["run", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ")
    assert not (tmp_path / "o.h5").exists()


def test_a_compile_during_the_run_counts_as_start_up(tmp_path, monkeypatch):
    """A kernel first needed after the start (here a compile event of 1 s in the second
    observables sample) is start-up time, not run time: the rate stays the engine's."""
    path = tmp_path / "c.toml"
    path.write_text(SMALL.format(out=tmp_path / "o.h5"))
    cfg = load_config(path)
    calls = []
    observables = runner._observables

    def slow_second_sample(sim, pressure):
        calls.append(1)
        if len(calls) == 2:
            _fake_compile(1.0)
        return observables(sim, pressure)

    monkeypatch.setattr(runner, "_observables", slow_second_sample)
    summary = runner.run_config(cfg, log=lambda line: None)
    assert len(calls) > 2
    assert summary.compile_time >= 1.0
    assert summary.startup_time >= 1.0
    assert summary.wall_time < 1.0


def test_a_cached_run_says_so(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text(SMALL.format(out=tmp_path / "o.h5"))
    cfg = load_config(path)
    runner.run_config(cfg, log=lambda line: None)  # compiles whatever is not cached yet
    logged = []
    summary = runner.run_config(cfg, overwrite=True, log=logged.append)
    assert summary.compile_time == 0.0 and not [x for x in logged if x.startswith("compiling")]
    assert "compiled code from the cache" in summary.lines()[2]


def test_compile_watch_counts_outermost_compilations_only():
    @numba.njit(cache=False)
    def inner(x):
        return x + 1

    @numba.njit(cache=False)
    def outer(x):
        return inner(x) * 2

    announced = []
    with _numba.CompileWatch(announce=lambda: announced.append(1)) as watch:
        assert outer(1) == 4
    assert announced == [1] and watch.count == 2 and watch.seconds > 0.0
    with _numba.CompileWatch() as again:
        outer(2)
    assert again.count == 0 and again.seconds == 0.0


@pytest.mark.parametrize("argv, message", [
    (["compile", "nonsense"], "compile nonsense: not a variant; one of placement, "),
    (["compile", "--jobs", "0"], "--jobs = 0: must be at least 1"),
])
def test_compile_refuses_bad_arguments(capsys, argv, message):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {message}")


def test_compile_builds_a_variant_and_says_what_and_how_long(capsys):
    assert main(["compile", "dsmc", "--jobs", "1"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"compiling 1 variant, 1 at a time, into {_numba.cache_location()}"
    assert out[1].split()[:2] in (["compiled", "dsmc"], ["cached", "dsmc"]) and out[1].endswith("the DSMC")
    assert out[2].startswith("done in ") and ("1 compiled" in out[2] or "1 already cached" in out[2])


@pytest.mark.slow
def test_after_compile_a_first_run_compiles_nothing(tmp_path):
    """In a fresh numba cache: a run announces its compile; after ``granulargas compile`` of its
    variants, a run of another config of the same kind compiles nothing."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    env.pop("GRANULARGAS_NO_CACHE", None)
    cfg = tmp_path / "c.toml"
    cfg.write_text(SMALL.format(out=tmp_path / "o.h5"))

    def granulargas(*args):
        return subprocess.run([sys.executable, "-m", "granulargas", *args], env=env, cwd=tmp_path,
                              capture_output=True, text=True, check=True)

    built = granulargas("compile", "placement", "lists")
    assert "compiled  placement" in built.stdout and "compiled  lists" in built.stdout
    for walls in ("periodic", "wall"):
        run = granulargas("run", str(cfg), "--overwrite", "--set", "collision.restitution=0.7",
                          "--set", "system.dimension=3", "--set", 'run.neighbours="lists"',
                          "--set", f'system.boundary=["periodic", "periodic", "{walls}"]')
        assert "compiling" not in run.stderr, run.stderr
        assert "compiled code from the cache" in run.stdout
