"""Sweeps: expansion, local pool, Dask, skipping finished runs, failures."""

import json
from concurrent.futures import ThreadPoolExecutor

import h5py
import numpy as np
import pytest

from granulargas.cli import main
from granulargas.errors import ConfigError, InputFileError
from granulargas.run.sweep import load_sweep, make_executor, read_index, run_sweep

BASE = """\
[system]
dimension = 2
particles = 64
packing_fraction = 0.2
seed = 1

[particles]
diameter = 1.0
mass = 1.0

[initial]
temperature = 1.0

[collision]
model = "constant"
restitution = 0.9

[run]
end_time = 3.0

[output]
file = "unused.h5"
snapshots = 3
observables_interval = 0.5
"""


def write_sweep(tmp_path, vary, extra=""):
    (tmp_path / "base.toml").write_text(BASE)
    text = f'base = "base.toml"\noutput_dir = "out"\n{extra}\n[vary]\n{vary}\n'
    path = tmp_path / "sweep.toml"
    path.write_text(text)
    return path


def final_state(file):
    with h5py.File(file, "r") as fh:
        pos = fh["particles/all/position/value"][-1]
        vel = fh["particles/all/velocity/value"][-1]
    return pos, vel


def test_expansion_product_and_generators(tmp_path):
    path = write_sweep(tmp_path, 'collision.restitution = [0.9, 0.8]\nsystem.seed = { range = [1, 3] }')
    sweep = load_sweep(path)
    assert len(sweep.runs) == 6
    assert {r.parameters["system.seed"] for r in sweep.runs} == {1, 2, 3}
    assert len({r.file for r in sweep.runs}) == 6
    assert all(r.overrides["output.file"] == r.file for r in sweep.runs)


@pytest.mark.parametrize("spec, values", [
    ("[1, 4]", [1, 2, 3, 4]),          # both ends included, as linspace's
    ("[1, 10, 4]", [1, 5, 9]),         # the last value when a step lands on it
    ("[1, 9, 4]", [1, 5, 9]),
    ("[4, 1, -1]", [4, 3, 2, 1]),
    ("[3, 3]", [3]),
])
def test_range_includes_both_ends(tmp_path, spec, values):
    path = write_sweep(tmp_path, f"system.seed = {{ range = {spec} }}")
    assert [r.parameters["system.seed"] for r in load_sweep(path).runs] == values


def test_expansion_zip_and_linspace(tmp_path):
    path = write_sweep(
        tmp_path,
        'collision.restitution = { linspace = [0.9, 0.7, 3] }\nsystem.seed = [1, 2, 3]',
        extra='mode = "zip"',
    )
    runs = load_sweep(path).runs
    assert [r.parameters["system.seed"] for r in runs] == [1, 2, 3]
    np.testing.assert_allclose([r.parameters["collision.restitution"] for r in runs], [0.9, 0.8, 0.7])


@pytest.mark.parametrize(
    "vary, message",
    [
        ("", "[vary] is empty"),
        ("system.seed = { range = [1.5, 3] }", "integers"),
        ("system.seed = { range = [5] }", "[first, last] or [first, last, step]"),
        ("system.seed = { range = [4, 1] }", "gives no values"),
        ("system.seed = []", "at least one value"),
    ],
)
def test_bad_sweep_files(tmp_path, vary, message):
    with pytest.raises(ConfigError, match=message.replace("[", r"\[").replace("]", r"\]")):
        load_sweep(write_sweep(tmp_path, vary))


def test_local_pool_skips_done_and_redoes_broken(tmp_path):
    path = write_sweep(tmp_path, "system.seed = [1, 2]")
    sweep = load_sweep(path)
    executor, close = make_executor(workers=2)
    try:
        entries = run_sweep(sweep, executor, log=lambda *a: None)
        assert [e["status"] for e in entries] == ["done", "done"]
        first = final_state(entries[0]["file"])
        # a half-written file is redone; a finished one is skipped
        with open(entries[1]["file"], "wb") as fh:
            fh.write(b"not hdf5")
        messages = []
        run_sweep(sweep, executor, log=messages.append)
    finally:
        close()
    assert any(m.startswith("skip run_000") for m in messages)
    assert any(m.startswith("done run_001") for m in messages)
    np.testing.assert_array_equal(final_state(entries[0]["file"])[0], first[0])
    index = read_index(tmp_path / "out")
    assert [e["parameters"]["system.seed"] for e in index["runs"]] == [1, 2]


def test_failed_run_is_reported_and_others_go_on(tmp_path):
    # 4 particles: a valid config whose box is too small for the engine (found when the run starts)
    path = write_sweep(tmp_path, "system.particles = [64, 2]")
    with ThreadPoolExecutor(1) as pool:
        entries = run_sweep(load_sweep(path), pool, log=lambda *a: None)
    assert entries[0]["status"] == "done"
    assert entries[1]["status"] == "failed"
    assert "system.particles = 2" in entries[1]["error"]


def test_every_run_config_is_validated_before_any_run(tmp_path, capsys):
    path = write_sweep(tmp_path, "collision.restitution = [0.9, 1.5]")
    with pytest.raises(ConfigError, match=r"run_001 \(collision.restitution=1.5\): override: collision.restitution = "
                                          r"1.5: must be a number in \(0, 1\]"):
        load_sweep(path)
    assert main(["sweep", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run_001" in err
    assert not (tmp_path / "out").exists()


def test_output_directory_parent_must_exist(tmp_path):
    path = write_sweep(tmp_path, "system.seed = [1]").read_text().replace('output_dir = "out"', 'output_dir = "no/out"')
    (tmp_path / "s2.toml").write_text(path)
    with pytest.raises(InputFileError, match="directory .*no does not exist"):
        load_sweep(tmp_path / "s2.toml")
    assert not (tmp_path / "no").exists()


def test_cli_exit_codes(tmp_path, capsys):
    path = write_sweep(tmp_path, "system.seed = [1]")
    assert main(["sweep", str(path), "--dry-run"]) == 0
    assert "run_000" in capsys.readouterr().out
    assert main(["sweep", str(tmp_path / "missing.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "missing.toml" in err


def test_dask_gives_identical_results(tmp_path):
    distributed = pytest.importorskip("dask.distributed", reason="dask is not installed (pip install 'granulargas[dask]')")
    path = write_sweep(tmp_path, "system.seed = [1, 2]")
    sweep = load_sweep(path)
    with ThreadPoolExecutor(1) as pool:
        local = run_sweep(sweep, pool, log=lambda *a: None)
    reference = [final_state(e["file"]) for e in local]
    (tmp_path / "out" / "index.json").unlink()
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            remote = run_sweep(sweep, client.get_executor(pure=False), log=lambda *a: None)
    assert [e["status"] for e in remote] == ["done", "done"]
    for entry, (pos, vel) in zip(remote, reference):
        p, v = final_state(entry["file"])
        np.testing.assert_array_equal(p, pos)
        np.testing.assert_array_equal(v, vel)
    assert json.loads((tmp_path / "out" / "index.json").read_text())["runs"][0]["status"] == "done"


MIXTURE_BASE = """\
[system]
dimension = 2
packing_fraction = 0.2
[[species]]
name = "big"
count = 30
diameter = 1.2
[[species]]
name = "small"
count = 34
diameter = 0.8
[collision]
model = "constant"
restitution = { "big-big" = 0.9, "big-small" = 0.8, "small-small" = 0.85 }
[run]
end_time = 0.5
"""


def test_a_sweep_varies_a_species_key_and_a_pair_law(tmp_path):
    from granulargas.io.config import load_config

    (tmp_path / "base.toml").write_text(MIXTURE_BASE)
    (tmp_path / "out").mkdir()
    (tmp_path / "s.toml").write_text('base = "base.toml"\noutput_dir = "out"\n[vary]\n'
                                     'species.big.mass = [2.0, 4.0]\n"collision.restitution.small-big" = [0.7, 0.75]\n')
    sweep = load_sweep(tmp_path / "s.toml")
    assert len(sweep.runs) == 4
    for spec in sweep.runs:
        cfg = load_config(tmp_path / "base.toml", spec.overrides)
        assert cfg.species[0].mass == spec.parameters["species.big.mass"]
        assert cfg.collision.restitution["big-small"] == spec.parameters["collision.restitution.small-big"]
    (tmp_path / "bad.toml").write_text('base = "base.toml"\noutput_dir = "out"\n[vary]\nspecies.huge.mass = [2.0]\n')
    with pytest.raises(ConfigError, match="no species named huge"):
        load_sweep(tmp_path / "bad.toml")
