"""``granulargas run``: bad input gives one line on stderr, a non-zero exit, no traceback and no file."""

import os
import subprocess
import sys

import h5py
import pytest

from granulargas.cli import main

GOOD = """
[system]
dimension = 3
particles = 200
packing_fraction = 0.1
seed = 1

[collision]
model = "constant"
restitution = 0.9

[run]
end_time = 1.0

[output]
file = "{out}"
snapshots = 3
"""


@pytest.fixture
def case(tmp_path, capsys, monkeypatch):
    """case(text or None, *extra args, real=False) -> (exit code, stdout, stderr, output path, new paths).

    Runs ``granulargas run`` through ``cli.main`` in this process, or as a real
    subprocess with ``real=True``."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "runs").mkdir()  # the runner never creates output directories

    def run(text, *extra, real=False):
        out = tmp_path / "runs" / "out.h5"
        cfg = tmp_path / "c.toml"
        if text is not None:
            cfg.write_text(text.replace("{out}", str(out)))
        before = set(tmp_path.rglob("*"))
        argv = ["run", str(cfg), *extra]
        if real:
            proc = subprocess.run([sys.executable, "-m", "granulargas", *argv], capture_output=True, text=True)
            rc, stdout, stderr = proc.returncode, proc.stdout, proc.stderr
        else:
            capsys.readouterr()
            rc = main(argv)
            stdout, stderr = capsys.readouterr()
        new = set(tmp_path.rglob("*")) - before
        return rc, stdout, stderr, out, new

    return run


def _replace(old, new):
    return GOOD.replace(old, new)


BAD = {
    "toml syntax": (_replace("[run]", "[run"), "TOML syntax error"),
    "unknown key": (_replace("seed = 1", "seed = 1\ntemprature = 2"), "system.temprature = 2: unknown key; did you mean `initial.temperature`?"),
    "wrong type": (_replace("particles = 200", 'particles = "many"'), 'system.particles = "many": must be an integer in [2, 2147483647]'),
    "negative count": (_replace("particles = 200", "particles = -200"), "system.particles = -200: must be an integer in [2, 2147483647]"),
    "dimension": (_replace("dimension = 3", "dimension = 4"), "system.dimension = 4: must be 2 or 3"),
    "packing": (_replace("packing_fraction = 0.1", "packing_fraction = 0.8"), "system.packing_fraction = 0.8: must be a number in (0, 0.7405)"),
    "restitution high": (_replace("restitution = 0.9", "restitution = 1.5"), "collision.restitution = 1.5: must be a number in (0, 1]"),
    "restitution zero": (_replace("restitution = 0.9", "restitution = 0.0"), "collision.restitution = 0: must be a number in (0, 1]"),
    "negative damping": (_replace('model = "constant"\nrestitution = 0.9', 'model = "viscoelastic"\ndamping = -0.1'),
                         "collision.damping = -0.1: must be a number in [0, 40]"),
    "unknown model": (_replace('model = "constant"', 'model = "hertz"'), 'collision.model = "hertz": must be one of'),
    "too few particles": (_replace("particles = 200", "particles = 4"), "below 3.15 largest diameters"),
}


def _check_rejected(rc, out, err, new, message):
    assert rc == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: ") and message in lines[0]
    assert "Traceback" not in err and out == ""
    assert not [p for p in new if p.is_file()], new


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_config(case, name):
    text, message = BAD[name]
    rc, out, err, _, new = case(text)
    _check_rejected(rc, out, err, new, message)


@pytest.mark.parametrize("name", ["toml syntax", "packing"])
def test_bad_config_in_a_real_process(case, name):
    text, message = BAD[name]
    rc, out, err, _, new = case(text, real=True)
    _check_rejected(rc, out, err, new, message)


def test_missing_config_file(case):
    rc, out, err, _, new = case(None, real=True)
    _check_rejected(rc, out, err, new, "config file not found")


def test_output_directory_not_writable(case, tmp_path):
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    rc, out, err, _, new = case(GOOD, "--output", str(blocker / "sub" / "out.h5"))
    _check_rejected(rc, out, err, new, "is not a directory")


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write into read-only directories")
def test_output_directory_read_only(case, tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        rc, out, err, _, new = case(GOOD, "--output", str(ro / "out.h5"))
    finally:
        ro.chmod(0o755)
    _check_rejected(rc, out, err, new, "not writable")


def test_restart_from_foreign_files(case, tmp_path):
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = [1, 2, 3]
    rc, out, err, _, new = case(GOOD, "--restart", str(foreign))
    _check_rejected(rc, out, err, new, "not an H5MD file written by granulargas")
    text = tmp_path / "notes.h5"
    text.write_text("not hdf5")
    rc, out, err, _, new = case(GOOD, "--restart", str(text))
    _check_rejected(rc, out, err, new, "not an HDF5 file")
    rc, out, err, _, new = case(GOOD, "--restart", str(tmp_path / "missing.h5"))
    _check_rejected(rc, out, err, new, "file not found")


def test_existing_output_needs_overwrite_and_run_summary(case):
    rc, out, err, path, _ = case(GOOD, real=True)
    assert rc == 0, err
    assert "collisions" in out and "collisions/s" in out and "temperature" in out and str(path) in out
    # no progress bar when stderr is not a terminal; a first run on a fresh
    # cache announces what it compiles, and nothing else
    assert all(line.startswith("compiling ") for line in err.splitlines()), err
    before = path.read_bytes()
    rc, out, err, _, new = case(GOOD)
    _check_rejected(rc, out, err, new, "file exists (use --overwrite")
    assert path.read_bytes() == before
    # restarting into the file it continues from is refused too
    rc, out, err, _, new = case(GOOD.replace("end_time = 1.0", "end_time = 2.0"), "--restart", str(path), "--overwrite")
    _check_rejected(rc, out, err, new, "is the restart file")
    rc, out, err, _, _ = case(GOOD, "--overwrite", "--set", "collision.restitution=0.8")
    assert rc == 0, err


def test_restart_must_match_the_system(case, tmp_path):
    rc, _, err, path, _ = case(GOOD, "--quiet")
    assert rc == 0, err
    rc, out, err, _, new = case(GOOD, "--restart", str(path), "--output", str(tmp_path / "b.h5"),
                                "--set", "system.particles=300")
    _check_rejected(rc, out, err, new, "system.particles = 300: restart file")
    rc, out, err, _, new = case(GOOD, "--restart", str(path), "--output", str(tmp_path / "b.h5"))
    _check_rejected(rc, out, err, new, "run.end_time = 1: the restart file")


def test_bad_set_override_in_process(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text(GOOD.replace("{out}", str(tmp_path / "o.h5")))
    assert main(["run", str(cfg), "--set", "collision.restitution=2"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == "error: override: collision.restitution = 2: must be a number in (0, 1]"
    assert main(["run", str(cfg), "--set", "nonsense"]) == 2
    assert "expected section.key=value" in capsys.readouterr().err
    assert not (tmp_path / "o.h5").exists()


def test_summary_reports_validity_and_advice(case):
    """The run summary says whether a constant eps would do and reports the model range."""
    visco = GOOD.replace('model = "constant"\nrestitution = 0.9', 'model = "viscoelastic"\ndamping = 0.1')
    rc, out, err, _, _ = case(visco, "--overwrite")
    assert rc == 0, err
    assert "advice" in out and "best constant eps" in out
    assert "t_c/t_free" in out


COLLAPSING = """
[system]
dimension = 2
particles = 300
packing_fraction = 0.4
seed = 1
[collision]
model = "constant"
restitution = 0.2
[run]
end_time = 50.0
[output]
file = "{out}"
snapshots = 30
"""


def test_collapse_names_the_config_key_not_the_python_call(case):
    """A config run's user is told which key cures the collapse (the engine's own error names
    the Python call, for Python callers: tests/engine/test_physics.py)."""
    rc, out, err, path, _ = case(COLLAPSING)
    assert rc == 3 and path.exists()
    line, = [x for x in err.strip().splitlines() if not x.startswith("compiling ")]  # (a cold numba cache)
    assert line.startswith("error: inelastic collapse at t = ")
    assert "set collision.tc_time in " in line and "c.toml" in line and 'collision.model = "viscoelastic"' in line
    assert "CollisionRule" not in line and "keeps" in line
    tc = float(line.split("tc_time = ")[1].split(":")[0])
    assert 1e-8 < tc < 1e-5  # 1e-6 of the initial mean free time (about 0.3 here)
