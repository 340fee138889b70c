"""Config runs with ``run.method = "dsmc"``: the DSMC the config describes, its H5MD file
(velocities and the DSMC random state, no positions), bit-exact restarts and continuation
into the same file, the keys DSMC cannot honour refused with one line."""

import h5py
import numpy as np
import pytest

from granulargas import theory
from granulargas.cli import main
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule
from granulargas.errors import ConfigError
from granulargas.io.config import load_config, parse_config
from granulargas.io.h5md import (has_positions, interrupted_frames, iter_snapshots, load_snapshot,
                                 read_observables, read_parameters, read_state)
from granulargas.observables import sonine_coefficients
from granulargas.run.prepare import prepare
from granulargas.run.runner import RunInterrupted, StopRequest, run_config
from granulargas.state import State

DSMC_3D = """
[system]
dimension = 3
particles = 400
packing_fraction = 0.05
seed = 7

[collision]
model = "viscoelastic"
damping = 0.1

[run]
method = "dsmc"
end_time = 20.0

[output]
file = "{out}"
snapshot_interval = 5.0
observables_interval = 1.0
"""

FRAME_DATASETS = ("particles/all/velocity/value", "particles/all/velocity/time", "particles/all/velocity/step",
                  "particles/all/box/edges/value") + tuple(
    f"particles/all/dsmc/{k}/value" for k in ("rng", "candidates", "pending_pair", "pending_time", "frame_velocity"))


def _datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        for name in FRAME_DATASETS:
            out[name] = f[name][()]
        for name, g in f["observables"].items():
            for part in ("step", "time", "value"):
                out[f"observables/{name}/{part}"] = g[part][()]
    return out


def _assert_same_datasets(a, b):
    da, db = _datasets(a), _datasets(b)
    assert sorted(da) == sorted(db)
    for name in da:
        assert da[name].shape == db[name].shape, name
        assert np.array_equal(da[name], db[name], equal_nan=da[name].dtype.kind == "f"), name


@pytest.fixture
def dsmc_config(write_config):
    def make(text=DSMC_3D, **kw):
        return write_config(text, **kw)
    return make


def test_the_file_has_velocities_and_the_dsmc_state_but_no_positions(dsmc_config):
    path = dsmc_config()
    s = run_config(load_config(path))
    assert s.time == 20.0 and s.snapshots == 5 and s.collisions > 0
    with h5py.File(s.output, "r") as f:
        part = f["particles/all"]
        assert "position" not in part and "image" not in part and "dsmc" in part
        assert "pressure" not in f["observables"]
        assert f["parameters"].attrs["method"] == "dsmc"
    assert not has_positions(s.output)
    snaps = list(iter_snapshots(s.output))
    assert [x.time for x in snaps] == [0.0, 5.0, 10.0, 15.0, 20.0]
    assert all(x.positions is None and x.images is None for x in snaps)
    with pytest.raises(Exception, match="DSMC file has no positions"):
        snaps[0].unwrapped_positions
    obs = read_observables(s.output)
    for name in ("temperature", "kinetic_energy", "collisions", "events", "dissipated_energy", "momentum",
                 "sonine_a2", "sonine_a3"):
        assert name in obs
    # the observables are those of the stored velocities (frames are sampled too)
    last = snaps[-1]
    k = np.nonzero(obs["temperature"][1] == last.time)[0][-1]
    a2, a3 = sonine_coefficients(last.velocities, last.masses)
    assert obs["sonine_a2"][2][k] == pytest.approx(a2, rel=1e-12)
    assert obs["sonine_a3"][2][k] == pytest.approx(a3, rel=1e-12)
    m, v = last.masses, last.velocities
    assert obs["temperature"][2][k] == pytest.approx(float((m[:, None] * v * v).sum()) / (3 * len(m)), rel=1e-12)
    # energy bookkeeping: kinetic energy lost = energy dissipated
    ke, diss = obs["kinetic_energy"][2], obs["dissipated_energy"][2]
    assert np.allclose(ke + diss, ke[0], rtol=1e-10)
    assert obs["collisions"][2][-1] == s.collisions and np.all(obs["events"][2] >= obs["collisions"][2])


def test_the_run_is_the_dsmc_the_config_describes(dsmc_config):
    """The config's DSMC equals one built by hand from the file's initial velocities, the
    box volume, the theory module's chi and the engine's viscoelastic rule: bit for bit."""
    path = dsmc_config()
    config = load_config(path)
    s = run_config(config)
    setup = prepare(config)
    first = load_snapshot(s.output, 0)
    box = first.box
    eta = float(len(first.radii) * np.pi / 6.0 / np.prod(box))
    chi = float(theory.contact_value(eta, 3))
    par = read_parameters(s.output)
    assert par["dsmc"]["chi"] == pytest.approx(chi, rel=1e-12)
    assert par["packing_fraction"] == pytest.approx(0.05, rel=1e-12)
    rule = CollisionRule.viscoelastic(prefactor=setup.prefactor, table=setup.table)
    ref = DSMC(State(None, setup.state.velocities, first.radii, first.masses, box), rule,
               chi=par["dsmc"]["chi"], seed=7)
    assert np.array_equal(ref.velocities, first.velocities)
    for t in (5.0, 10.0, 15.0, 20.0):
        ref.run(t)
    last = load_snapshot(s.output, -1)
    assert np.array_equal(ref.velocities, last.velocities)
    assert ref.collisions == s.collisions
    # no hard-sphere placement: the state has no positions
    assert setup.state.positions is None


def test_collisions_per_particle_stops_at_the_budget(dsmc_config, tmp_path):
    text = DSMC_3D.replace("end_time = 20.0", "collisions_per_particle = 3.0").replace(
        "snapshot_interval = 5.0\nobservables_interval = 1.0", "snapshots = 4")
    s = run_config(load_config(dsmc_config(text)))
    assert s.collisions == 600 and s.stop_reason == "collisions_per_particle"
    assert read_observables(s.output)["collisions"][2][-1] == 600


def test_restart_and_append_equal_the_uninterrupted_run(dsmc_config, tmp_path):
    """A run to 2t equals a run to t continued to 2t (--restart FILE --append), dataset by
    dataset, bit for bit; a restart into a new file ends in the same state."""
    path = dsmc_config()
    full = run_config(load_config(path, {"output.file": str(tmp_path / "full.h5")}))
    part = tmp_path / "part.h5"
    run_config(load_config(path, {"run.end_time": 10.0, "output.file": str(part)}))
    new = run_config(load_config(path, {"initial.from": str(part), "output.file": str(tmp_path / "new.h5")}))
    cont = run_config(load_config(path, {"initial.from": str(part), "output.file": str(part)}), append=True)
    assert cont.time == full.time == 20.0 and cont.collisions == full.collisions == new.collisions
    _assert_same_datasets(full.output, part)
    a, b = load_snapshot(full.output, -1), load_snapshot(new.output, -1)
    assert np.array_equal(a.velocities, b.velocities)
    assert read_state(full.output).dsmc.candidates == read_state(new.output).dsmc.candidates


def test_a_signal_keeps_the_state_and_the_continuation_is_exact(dsmc_config, tmp_path):
    path = dsmc_config()
    stopped = tmp_path / "stopped.h5"
    stop = StopRequest()

    def progress(sim):
        if sim.time >= 7.0 and not stop:
            stop.request(2)

    with pytest.raises(RunInterrupted) as err:
        run_config(load_config(path, {"output.file": str(stopped)}), stop=stop, progress=progress)
    t_s = err.value.time
    assert 7.0 <= t_s < 20.0 and interrupted_frames(stopped) == [len(list(iter_snapshots(stopped))) - 1]
    run_config(load_config(path, {"initial.from": str(stopped), "output.file": str(stopped)}), append=True)
    ref = tmp_path / "ref.h5"
    run_config(load_config(path, {"run.end_time": t_s, "output.file": str(ref)}))
    run_config(load_config(path, {"initial.from": str(ref), "output.file": str(ref)}), append=True)
    _assert_same_datasets(ref, stopped)


def test_2d_constant_and_mixtures_run(dsmc_config):
    text = DSMC_3D.replace("dimension = 3", "dimension = 2").replace(
        'model = "viscoelastic"\ndamping = 0.1', 'model = "constant"\nrestitution = 0.8').replace(
        "[collision]", "[particles]\ndiameter = { min = 0.8, max = 1.2 }\n\n[collision]")
    s = run_config(load_config(dsmc_config(text)))
    snap = load_snapshot(s.output, -1)
    assert snap.velocities.shape == (400, 2) and len(np.unique(snap.radii)) == 400
    assert s.final_temperature < 1.0


@pytest.mark.parametrize("extra, key", [
    ('[system]\nboundary = ["wall", "periodic", "periodic"]', "system.boundary"),
    ('[collision]\nmodel = "constant"\nrestitution = 0.9\ntc_time = 0.001', "collision.tc_time"),
])
def test_keys_dsmc_cannot_honour_are_refused(extra, key):
    base = {"system": "dimension = 3\nparticles = 100\npacking_fraction = 0.05",
            "collision": 'model = "elastic"', "run": 'method = "dsmc"\nend_time = 1.0'}
    section = extra.split("]")[0][1:]
    body = extra.split("\n", 1)[1]
    if section in base:
        base[section] = body if section == "collision" else base[section] + "\n" + body
    else:
        base[section] = body
    text = "\n".join(f"[{k}]\n{v}\n" for k, v in base.items())
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")) as err:
        parse_config(text)
    assert "dsmc" in str(err.value) and "\n" not in str(err.value)
    parse_config(text.replace('method = "dsmc"', 'method = "edmd"'))  # the engine takes them


def test_cli_refuses_with_one_line_and_writes_nothing(write_config, tmp_path, capsys):
    text = DSMC_3D.replace("[collision]", '[collision]\nwall_restitution = 0.5').replace(
        "dimension = 3", 'dimension = 3\nboundary = ["wall", "periodic", "periodic"]').replace(
        'model = "viscoelastic"\ndamping = 0.1', 'model = "constant"\nrestitution = 0.9')
    path = write_config(text)
    assert main(["run", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "system.boundary" in err and "dsmc" in err
    assert not (tmp_path / "runs" / "out.h5").exists()
    assert main(["run", str(write_config(DSMC_3D.replace('"dsmc"', '"monte-carlo"')))]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'run.method = "monte-carlo"' in err and '"edmd", "dsmc"' in err


def test_a_restart_keeps_its_method(dsmc_config, small_3d, write_config, tmp_path, capsys):
    path = dsmc_config()
    d = run_config(load_config(path, {"run.end_time": 5.0, "output.file": str(tmp_path / "d.h5")}))
    assert main(["run", str(path), "--restart", str(d.output), "--set", "run.method=edmd",
                 "--output", str(tmp_path / "x.h5")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "DSMC run" in err and not (tmp_path / "x.h5").exists()
    e = run_config(load_config(write_config(small_3d, name="e.toml"),
                               {"run.end_time": 0.5, "output.file": str(tmp_path / "e.h5")}))
    assert main(["run", str(path), "--restart", str(e.output), "--output", str(tmp_path / "y.h5")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "EDMD run" in err and not (tmp_path / "y.h5").exists()


def test_engine_runs_write_sonine_coefficients(small_3d, write_config):
    s = run_config(load_config(write_config(small_3d), {"run.end_time": 1.0}))
    obs = read_observables(s.output)
    snap = load_snapshot(s.output, -1)
    k = np.nonzero(obs["sonine_a2"][1] == snap.time)[0][-1]
    a2, a3 = sonine_coefficients(snap.velocities, snap.masses)
    assert obs["sonine_a2"][2][k] == pytest.approx(a2, rel=1e-12, abs=1e-15)
    assert obs["sonine_a3"][2][k] == pytest.approx(a3, rel=1e-12, abs=1e-15)
    assert has_positions(s.output) and "pressure" in obs


def test_driven_dsmc_config_restarts_exactly(dsmc_config, tmp_path):
    """[driving] with method = "dsmc": the engine's kicks; the file carries injected_energy and
    kick_step, and --append continues bit for bit."""
    text = DSMC_3D.replace('model = "viscoelastic"\ndamping = 0.1', 'model = "constant"\nrestitution = 0.8').replace(
        "[run]", "[driving]\nheating_rate = 0.05\n\n[run]")
    path = dsmc_config(text)
    full = run_config(load_config(path, {"output.file": str(tmp_path / "full.h5")}))
    part = tmp_path / "part.h5"
    run_config(load_config(path, {"run.end_time": 10.0, "output.file": str(part)}))
    run_config(load_config(path, {"initial.from": str(part), "output.file": str(part)}), append=True)
    _assert_same_datasets(full.output, part)
    obs = read_observables(full.output)
    assert obs["kick_step"][2][-1] > 0 and obs["injected_energy"][2][-1] > 0
    ke, diss, inj = obs["kinetic_energy"][2], obs["dissipated_energy"][2], obs["injected_energy"][2]
    assert np.allclose(ke + diss - inj, ke[0], rtol=1e-9)
    assert read_parameters(full.output)["driving"]["heating_rate"] == 0.05


def test_a_damaged_dsmc_file_is_refused_with_one_line(dsmc_config, tmp_path, capsys):
    path = dsmc_config()
    d = run_config(load_config(path, {"run.end_time": 5.0, "output.file": str(tmp_path / "d.h5")}))
    with h5py.File(d.output, "r+") as f:
        del f["particles/all/dsmc/rng"]
    with pytest.raises(Exception, match="particles/all/dsmc/rng/value is missing"):
        load_snapshot(d.output)
    assert main(["run", str(path), "--restart", str(d.output), "--output", str(tmp_path / "x.h5")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "dsmc/rng" in err and not (tmp_path / "x.h5").exists()


def test_append_to_a_file_without_sonine_observables(small_3d, write_config, tmp_path):
    """Files written before sonine_a2/a3 were sampled continue with --append (without them)."""
    path = write_config(small_3d)
    part = tmp_path / "part.h5"
    run_config(load_config(path, {"run.end_time": 1.0, "output.file": str(part)}))
    with h5py.File(part, "r+") as f:
        del f["observables/sonine_a2"], f["observables/sonine_a3"]
    s = run_config(load_config(path, {"run.end_time": 2.0, "initial.from": str(part), "output.file": str(part)}),
                   append=True)
    obs = read_observables(part)
    assert s.time == 2.0 and "sonine_a2" not in obs and obs["temperature"][1][-1] == 2.0


def test_sigint_in_a_real_dsmc_process(write_config, tmp_path):
    """A real SIGINT during a long DSMC run: exit 130, one line, the file keeps the state reached
    as its last frame (with the DSMC state), and --append continues it."""
    import signal
    import subprocess
    import sys
    import time

    text = DSMC_3D.replace("particles = 400", "particles = 200000").replace("end_time = 20.0", "end_time = 1e6")
    path = write_config(text.replace("snapshot_interval = 5.0\nobservables_interval = 1.0\n", ""))
    out = tmp_path / "runs" / "out.h5"
    proc = subprocess.Popen([sys.executable, "-m", "granulargas", "run", str(path), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        end = time.time() + 240.0
        while time.time() < end:
            time.sleep(0.3)
            if out.exists():
                try:
                    with h5py.File(out, "r", locking=False) as f:
                        if f["particles/all/velocity/time"].shape[0] >= 2:
                            break
                except (OSError, KeyError):
                    pass
            assert proc.poll() is None, proc.stderr.read()
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert len(err.strip().splitlines()) == 1 and err.startswith("interrupted: SIGINT at t = ")
    frames = list(iter_snapshots(out))
    assert interrupted_frames(out) == [len(frames) - 1] and frames[-1].time > frames[-2].time
    t_s = frames[-1].time
    assert read_state(out).dsmc.candidates > 0
    assert main(["run", str(path), "--restart", str(out), "--append", "--quiet",
                 "--set", f"run.end_time={t_s + 1.0!r}"]) == 0
    assert [s.time for s in iter_snapshots(out)][-1] == t_s + 1.0


def test_rough_driven_dsmc_config_restarts_exactly(dsmc_config, tmp_path):
    """Rough particles with method = "dsmc": angular velocities in every frame, the rough
    observables, the energy balance of translation and rotation, --append bit for bit."""
    text = DSMC_3D.replace('model = "viscoelastic"\ndamping = 0.1',
                           'model = "constant"\nrestitution = 0.8\n\n[collision.tangential]\nmodel = "coulomb"\n'
                           "restitution = 0.5\nfriction = 0.3").replace(
        "[run]", "[driving]\nheating_rate = 0.05\ninterval = 0.1\nrotational_fraction = 0.5\n\n[run]")
    path = dsmc_config(text)
    full = run_config(load_config(path, {"output.file": str(tmp_path / "full.h5")}))
    part = tmp_path / "part.h5"
    run_config(load_config(path, {"run.end_time": 10.0, "output.file": str(part)}))
    run_config(load_config(path, {"initial.from": str(part), "output.file": str(part)}), append=True)
    _assert_same_datasets(full.output, part)
    with h5py.File(full.output) as f, h5py.File(part) as g:
        assert np.array_equal(f["particles/all/angular_velocity/value"][()], g["particles/all/angular_velocity/value"][()])
        assert f["particles/all/angular_velocity/value"].shape == (5, 400, 3)
        assert np.all(f["particles/all/inertia"][()] == 0.4)
    obs = read_observables(full.output)
    ke, diss, inj = obs["kinetic_energy"][2], obs["dissipated_energy"][2], obs["injected_energy"][2]
    rot = 0.5 * 3 * 400 * obs["rotational_temperature"][2]
    assert np.allclose(ke + rot + diss - inj, ke[0] + rot[0], rtol=1e-9)
    assert obs["rotational_temperature"][2][0] == pytest.approx(1.0, rel=1e-12)  # the default: T0
    assert {"cumulant_a20", "cumulant_a02", "cumulant_a11"} <= set(obs)
    assert read_parameters(full.output)["tangential"]["friction"] == 0.3
