"""Stopping on a signal and continuing: the state reached is kept, --append extends the same
file, times stay absolute, and the continued files equal the runs they stand for bit for bit."""

import hashlib
import os
import shlex
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from granulargas.cli import main
from granulargas.errors import ConfigError
from granulargas.io.config import load_config
from granulargas.io.h5md import interrupted_frames, iter_snapshots, read_observables, read_parameters, snapshot_count
from granulargas.run.runner import Interrupted, RunInterrupted, StopRequest, run_config

DATASETS = ("particles/all/position/value", "particles/all/position/time", "particles/all/position/step",
            "particles/all/velocity/value", "particles/all/image/value", "particles/all/box/edges/value")


def _datasets(path):
    """Every frame and observables dataset of a file, as arrays."""
    out = {}
    with h5py.File(path, "r") as f:
        for name in DATASETS:
            out[name] = f[name][()]
        for name, g in f["observables"].items():
            for part in ("step", "time", "value"):
                out[f"observables/{name}/{part}"] = g[part][()]
        for element in ("last_collision", "angular_velocity"):
            if element in f["particles/all"]:
                out[element] = f[f"particles/all/{element}/value"][()]
    return out


def _assert_same_datasets(a, b):
    da, db = _datasets(a), _datasets(b)
    assert sorted(da) == sorted(db)
    for name in da:
        x, y = da[name], db[name]
        assert x.shape == y.shape, (name, x.shape, y.shape)
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name


def _stop_at(time_reached, signum=signal.SIGINT):
    """A StopRequest (armed by the runner) and a progress callback that sets it once the
    simulation has reached ``time_reached`` (as a signal handler would)."""
    stop = StopRequest()

    def progress(sim):
        if sim.time >= time_reached and not stop:
            stop.request(signum)

    return stop, progress


CASES = {
    "viscoelastic-3d": {},
    "tc-model-2d": {"system.dimension": 2, "collision.model": "constant", "collision.restitution": 0.5,
                    "collision.tc_time": 1e-3},
    "rough-coulomb-driven-3d": {"collision.tangential.model": "coulomb", "collision.tangential.restitution": 0.4,
                                "collision.tangential.friction": 0.2, "initial.rotational_temperature": 0.3,
                                "driving.heating_rate": 0.05, "driving.interval": 0.05,
                                "driving.rotational_fraction": 0.4},
}


def _config_text(small_3d, case):
    return small_3d if case != "tc-model-2d" else small_3d.replace("damping = 0.1", "")


@pytest.mark.parametrize("case", sorted(CASES))
def test_append_equals_the_uninterrupted_run(small_3d, write_config, tmp_path, case):
    """run to t, then --restart FILE --append to 2t: the file equals a run to 2t, dataset by dataset."""
    path = write_config(_config_text(small_3d, case))
    over = CASES[case]
    full = run_config(load_config(path, {**over, "output.file": str(tmp_path / "full.h5")}))
    part = tmp_path / "part.h5"
    run_config(load_config(path, {**over, "run.end_time": 2.0, "output.file": str(part)}))
    cont = run_config(load_config(path, {**over, "initial.from": str(part), "output.file": str(part)}), append=True)
    assert cont.time == full.time == 4.0 and (cont.collisions, cont.events) == (full.collisions, full.events)
    _assert_same_datasets(full.output, part)
    par = read_parameters(part)
    assert "end_time = 4.0" in par["config"] and "end_time = 2.0" in par["continuations"]["0000"]["previous_config"]
    assert par["continuations"]["0000"]["time"] == 2.0 and par["summary"]["time"] == 4.0
    assert interrupted_frames(part) == []


def test_interrupt_keeps_the_state_and_continues_bit_for_bit(small_3d, write_config, tmp_path):
    """A stop at t_s writes the state reached as a marked frame; --append continues to the
    absolute end. The result equals a run to t_s continued with --append (the same
    synchronisation times) bit for bit; the uninterrupted run's frames before t_s are the same."""
    path = write_config()
    stopped = tmp_path / "stopped.h5"
    stop, progress = _stop_at(2.2)
    with pytest.raises(RunInterrupted) as err:
        run_config(load_config(path, {"output.file": str(stopped)}), stop=stop, progress=progress)
    t_s = err.value.time
    assert err.value.exit_code == 130 and 2.2 <= t_s < 4.0 and err.value.output == stopped
    frames = list(iter_snapshots(stopped))
    assert [f.time for f in frames[:-1]] == [0.0, 1.0, 2.0] and frames[-1].time == t_s
    assert interrupted_frames(stopped) == [len(frames) - 1]
    assert read_parameters(stopped)["summary"]["stop_reason"] == "interrupted by SIGINT"
    obs = read_observables(stopped)
    assert obs["temperature"][1][-1] == t_s and np.all(np.diff(obs["temperature"][1]) > 0)

    # the uninterrupted run: the same frames up to the stop
    full = run_config(load_config(path, {"output.file": str(tmp_path / "full.h5")}))
    for a, b in zip(frames[:-1], iter_snapshots(full.output)):
        assert a.time == b.time and np.array_equal(a.positions, b.positions)

    # continue into the file: to the config's absolute end
    cont = run_config(load_config(path, {"initial.from": str(stopped), "output.file": str(stopped)}), append=True)
    assert cont.time == 4.0
    times = [s.time for s in iter_snapshots(stopped)]
    assert times == [0.0, 1.0, 2.0, t_s, 3.0, 4.0]
    assert interrupted_frames(stopped) == [3]

    # the same synchronisation times without a signal: a run to t_s, then --append to 4
    ref = tmp_path / "ref.h5"
    run_config(load_config(path, {"run.end_time": t_s, "output.file": str(ref)}))
    run_config(load_config(path, {"initial.from": str(ref), "output.file": str(ref)}), append=True)
    _assert_same_datasets(ref, stopped)


def test_restart_into_a_new_file_keeps_the_absolute_clock(small_3d, write_config, tmp_path):
    from granulargas.analysis.run import analyze_cooling

    path = write_config()
    stopped = tmp_path / "stopped.h5"
    stop, progress = _stop_at(1.6)
    with pytest.raises(RunInterrupted):
        run_config(load_config(path, {"output.file": str(stopped)}), stop=stop, progress=progress)
    t_s = snapshot_count(stopped) and list(iter_snapshots(stopped))[-1].time
    new = tmp_path / "new.h5"
    run_config(load_config(path, {"initial.from": str(stopped), "output.file": str(new)}))
    times = [s.time for s in iter_snapshots(new)]
    assert times[0] == t_s and times[-1] == 4.0
    a = analyze_cooling(new, with_sonine=False, with_theory=False)
    assert a.history.time[0] == t_s and a.t_offset == t_s  # analysis reads the file's clock
    assert a.summary()["t_start"] == t_s


def test_append_refuses_other_physics_and_changes_nothing(small_3d, write_config, tmp_path, capsys):
    path = write_config()
    out = tmp_path / "runs" / "out.h5"
    run_config(load_config(path, {"run.end_time": 1.0}))
    before = hashlib.sha256(out.read_bytes()).hexdigest()
    assert main(["run", str(path), "--restart", str(out), "--append", "--set", "collision.damping=0.2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "collision.damping = 0.2: the file" in err and "--append" in err
    # --append without --restart, and with another output
    assert main(["run", str(path), "--append"]) == 2
    assert "give --restart FILE" in capsys.readouterr().err
    assert main(["run", str(path), "--restart", str(out), "--append", "--output", str(tmp_path / "x.h5")]) == 2
    assert "drop --output" in capsys.readouterr().err
    # nothing to run: the file is already at the end
    assert main(["run", str(path), "--restart", str(out), "--append", "--set", "run.end_time=1.0"]) == 2
    assert "nothing to run" in capsys.readouterr().err
    assert hashlib.sha256(out.read_bytes()).hexdigest() == before
    assert not (tmp_path / "x.h5").exists()


def test_stop_request_before_and_after_arming():
    stop = StopRequest()
    with pytest.raises(Interrupted) as err:  # nothing to keep yet: stop at once
        stop.request(signal.SIGTERM)
    assert err.value.signum == signal.SIGTERM
    stop = StopRequest()
    stop.arm()
    stop.request(signal.SIGINT)  # armed: only a request
    assert stop and stop.signum == signal.SIGINT
    with pytest.raises(Interrupted):  # a second signal: at once
        stop.request(signal.SIGINT)


def test_signal_during_the_compile_is_an_interruption(small_3d, write_config, monkeypatch, capsys):
    """A signal before the output file exists raises at once; inside numba's compiler it
    surfaces as the compiler's own error. The command line names the signal (exit 130), no
    traceback."""
    import granulargas.cli.run as cli_run

    def compiling(config, *, stop, **kwargs):
        try:
            stop.request(signal.SIGINT)
        except Interrupted:
            raise RuntimeError("no compiled object yet for <Library 'advance'>") from None

    monkeypatch.setattr(cli_run, "run_config", compiling)
    assert main(["run", str(write_config(small_3d)), "--quiet"]) == 130
    assert capsys.readouterr().err.strip().splitlines()[-1] == "interrupted: SIGINT"


def _long_config(write_config, small_3d, end=100000.0):
    text = small_3d.replace("end_time = 4.0", f"end_time = {end!r}").replace(
        "snapshot_interval = 1.0", "snapshot_interval = 0.5").replace("observables_interval = 0.25",
                                                                     "observables_interval = 0.25")
    text = text.replace('model = "viscoelastic"\ndamping = 0.1', 'model = "elastic"')
    return write_config(text)


def _wait_for_frames(proc, out, frames, deadline=240.0):
    end = time.time() + deadline  # a fresh numba cache compiles the engine first
    while time.time() < end:
        time.sleep(0.3)
        if out.exists():
            try:  # the writer holds the HDF5 file lock: peek without locking
                with h5py.File(out, "r", locking=False) as f:
                    if f["particles/all/position/time"].shape[0] >= frames:
                        return
            except (OSError, KeyError):
                pass
        assert proc.poll() is None, proc.stderr.read()
    raise AssertionError("the run wrote no frames in time")


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_signal_in_a_real_process(small_3d, write_config, tmp_path, signum):
    """A real signal: exit 128 + signum, one line with the time and the command that continues,
    a valid file ending with the state reached; the printed command continues it."""
    path = _long_config(write_config, small_3d)
    out = tmp_path / "runs" / "out.h5"
    proc = subprocess.Popen([sys.executable, "-m", "granulargas", "run", str(path), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _wait_for_frames(proc, out, 3)
        proc.send_signal(signum)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 128 + signum, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"interrupted: {signal.Signals(signum).name} at t = "), err
    command = lines[0].split("continue with: ", 1)[1]
    assert command == shlex.join(["granulargas", "run", str(path), "--restart", str(out), "--append", "--quiet"])
    n = snapshot_count(out)
    frames = list(iter_snapshots(out))
    assert interrupted_frames(out) == [n - 1]
    assert [f.time for f in frames[:-1]] == [0.5 * k for k in range(n - 1)] and frames[-1].time > frames[-2].time
    # the printed command, shortened with --set (the config's end is far away), continues it
    argv = shlex.split(command)[1:] + ["--set", f"run.end_time={frames[-1].time + 1.0!r}"]
    assert main(argv) == 0
    times = [s.time for s in iter_snapshots(out)]
    assert times[:n] == [f.time for f in frames] and times[-1] == frames[-1].time + 1.0
    assert np.all(np.diff(times) > 0)


def test_killed_run_continues_into_its_file_bit_for_bit(small_3d, write_config, tmp_path):
    """SIGKILL leaves every frame flushed before (and maybe samples after the last frame);
    --append cuts those off and the file then equals an uninterrupted run."""
    path = _long_config(write_config, small_3d)
    out = tmp_path / "runs" / "out.h5"
    proc = subprocess.Popen([sys.executable, "-m", "granulargas", "run", str(path), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _wait_for_frames(proc, out, 4)
        time.sleep(0.2)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    last = list(iter_snapshots(out))[-1].time
    end = last + 1.0
    assert main(["run", str(path), "--restart", str(out), "--append", "--quiet", "--set", f"run.end_time={end!r}"]) == 0
    ref = run_config(load_config(path, {"run.end_time": end, "output.file": str(tmp_path / "ref.h5")}))
    assert ref.time == end
    _assert_same_datasets(ref.output, out)


def test_continuing_a_finished_run_needs_a_later_end(small_3d, write_config):
    path = write_config()
    run_config(load_config(path))
    with pytest.raises(ConfigError, match="nothing to run"):
        run_config(load_config(path, {"initial.from": str(path.parent / "runs" / "out.h5"),
                                      "output.file": str(path.parent / "runs" / "out.h5")}), append=True)
