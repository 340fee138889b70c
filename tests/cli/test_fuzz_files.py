"""Damaged H5MD files through every command that reads one (property-based).

A small valid run file is damaged (truncated, an element removed, a dataset replaced by
one of another shape or type, the creator changed, a file of another program, not HDF5
at all) and given to ``analyze``, ``export gsd``, ``run --restart`` (into a new file) and
``run --restart --append``. Every example ends with exit 0, 2 (one line naming the file,
nothing created, nothing changed) or 3, never a traceback.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from granulargas.io.config import load_config
from granulargas.run.runner import run_config
from tests.cli.fuzzing import _snapshot_tree, check_outcome, invoke, to_toml

CONFIG = {
    "system": {"dimension": 3, "particles": 64, "packing_fraction": 0.1, "seed": 1},
    "collision": {"model": "constant", "restitution": 0.9},
    "run": {"end_time": 2.0},
    "output": {"file": "run.h5", "snapshot_interval": 0.5, "observables_interval": 0.25},
}
CONFIG_LATER = {**CONFIG, "run": {"end_time": 3.0}}

COMMANDS = {
    "analyze": ["analyze", "run.h5"],
    "analyze-plot": ["analyze", "run.h5", "--plot", "fig.png", "--no-snapshots"],
    "export-gsd": ["export", "gsd", "run.h5", "-o", "out.gsd"],
    "restart": ["run", "later.toml", "--restart", "run.h5", "--output", "new.h5", "--quiet"],
    "append": ["run", "later.toml", "--restart", "run.h5", "--append", "--quiet"],
}


@pytest.fixture(scope="module")
def good_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("good")
    (d / "c.toml").write_text(to_toml(CONFIG))
    run_config(load_config(d / "c.toml", {"output.file": str(d / "run.h5")}))
    return d / "run.h5"


def _elements(path):
    names = []
    with h5py.File(path, "r") as f:
        f.visit(names.append)
    return sorted(names)


DAMAGES = ["truncate", "remove", "reshape", "retype", "creator", "foreign", "text", "empty", "nan"]


@st.composite
def damage(draw):
    kind = draw(st.sampled_from(DAMAGES))
    return kind, draw(st.floats(0.0, 1.0)), draw(st.integers(0, 10**6))


def apply_damage(path: Path, kind: str, fraction: float, pick: int):
    if kind == "truncate":
        data = path.read_bytes()
        path.write_bytes(data[: int(len(data) * fraction)])
    elif kind in ("remove", "reshape", "retype"):
        names = _elements(path)
        name = pick if isinstance(pick, str) else names[pick % len(names)]
        with h5py.File(path, "a") as f:
            obj = f[name]
            is_dataset = isinstance(obj, h5py.Dataset)
            shape = obj.shape if is_dataset else None
            del f[name]
            if kind == "reshape" and is_dataset:
                new = tuple(s + 1 for s in shape) + ((2,) if fraction > 0.5 else ())
                f.create_dataset(name, data=np.zeros(new if new else (3,)))
            elif kind == "retype" and is_dataset:
                f.create_dataset(name, data=np.array([b"not a number"] * max(1, shape[0] if shape else 1)))
            elif kind != "remove":
                f.create_group(name)
    elif kind == "creator":
        with h5py.File(path, "a") as f:
            f["h5md/creator"].attrs["name"] = "another program"
    elif kind == "foreign":
        path.unlink()
        with h5py.File(path, "w") as f:
            f.create_group("h5md/creator").attrs["name"] = "granulargas" if fraction > 0.5 else "lammps"
            f.create_dataset("particles/all/position/value", data=np.zeros((2, 3)))
    elif kind == "text":
        path.write_text("time,temperature\n0,1\n")
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "nan":
        with h5py.File(path, "a") as f:
            v = f["particles/all/velocity/value"]
            v[-1] = np.nan
            f["particles/all/radius"][0] = -1.0 if fraction > 0.5 else np.inf


def _property(good_file, command, dmg):
    kind, fraction, pick = dmg
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        shutil.copy(good_file, d / "run.h5")
        (d / "later.toml").write_text(to_toml(CONFIG_LATER))
        apply_damage(d / "run.h5", kind, fraction, pick)
        before = _snapshot_tree(d)
        o = invoke(COMMANDS[command], d, bound=30.0)
        after = _snapshot_tree(d)
        check_outcome(o, before, after)
        if o.code == 2:
            assert "run.h5" in o.stderr or "later.toml" in o.stderr, o.stderr
        if command == "append" and o.code != 0:
            assert after.get("run.h5") == before.get("run.h5"), "a refused --append changed the file"


FAST = settings(max_examples=120, derandomize=True, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))


@FAST
@given(st.sampled_from(sorted(COMMANDS)), damage())
# found by this property before they were fixed
@example("analyze", ("retype", 0.0, "particles/all/mass"))  # strings where numbers belong: TypeError
@example("analyze", ("nan", 0.2, 0))  # an infinite radius: the theory's integration never ended
@example("analyze", ("reshape", 0.9, "observables/temperature/value"))  # IndexError in the analysis
@example("analyze", ("reshape", 0.2, "observables/temperature/value"))  # T = 0: ZeroDivisionError
@example("analyze", ("reshape", 0.9, "observables/collisions/value"))  # TypeError in the analysis
@example("append", ("remove", 0.2, "observables/events"))  # KeyError after the file was opened for writing
@example("analyze", ("truncate", 0.5, 0))  # "sblock" in HDF5's message was taken for a file lock
@example("append", ("text", 0.0, 0))  # --append hid why the file could not be read
@example("analyze", ("remove", 0.0, 30))
@example("restart", ("remove", 0.0, 30))
@example("export-gsd", ("truncate", 0.6, 0))
@example("append", ("truncate", 0.9, 0))
@example("restart", ("nan", 0.9, 0))
@example("analyze", ("reshape", 0.9, 40))
def test_damaged_files_through_every_reader(good_file, command, dmg):
    _property(good_file, command, dmg)


@pytest.mark.slow
@settings(parent=FAST, max_examples=1500, derandomize=False)
@given(st.sampled_from(sorted(COMMANDS)), damage())
def test_damaged_files_through_every_reader_long(good_file, command, dmg):
    _property(good_file, command, dmg)


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_undamaged_file_works(good_file, command):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        shutil.copy(good_file, d / "run.h5")
        (d / "later.toml").write_text(to_toml(CONFIG_LATER))
        o = invoke(COMMANDS[command], d, bound=60.0)
        assert o.code == 0 and o.exception is None, o.stderr


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted(COMMANDS))
@pytest.mark.parametrize("kind", ["remove", "reshape", "retype"])
def test_every_element_damaged(good_file, command, kind):
    """Systematically: each element of the file removed, reshaped, retyped, for every command."""
    for name in _elements(good_file):
        for fraction in (0.2, 0.9):
            _property(good_file, command, (kind, fraction, name))
