"""Damaged and foreign files: every reader gives one line naming the file and what is missing."""

import h5py
import numpy as np
import pytest

from granulargas.errors import InputFileError
from granulargas.io.h5md import (
    H5MDWriter,
    iter_snapshots,
    load_snapshot,
    read_observables,
    read_parameters,
    read_state,
    snapshot_count,
)
from granulargas.state import State
from tests.io.test_h5md import _write

READERS = {
    "iter_snapshots": lambda p: list(iter_snapshots(p)),
    "load_snapshot": load_snapshot,
    "read_observables": read_observables,
    "read_parameters": read_parameters,
    "read_state": read_state,
    "snapshot_count": snapshot_count,
}


def _state(n, **fields):
    """A 3D state of n particles at rest (the continuation's particle count, step and time)."""
    return State(np.zeros((n, 3)), np.zeros((n, 3)), 0.5, 1.0, np.full(3, 4.0), **fields)


@pytest.fixture
def good(tmp_path):
    p = tmp_path / "a.h5"
    _write(p, frames=3)
    return p


def _one_line(err):
    msg = str(err.value)
    assert "\n" not in msg
    return msg


@pytest.mark.parametrize("reader", sorted(READERS))
def test_truncated_file(good, reader):
    data = good.read_bytes()
    good.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputFileError) as err:
        READERS[reader](good)
    assert _one_line(err) == f"{good}: truncated HDF5 file: {len(data) // 2} of its {len(data)} bytes (the file was cut short)"


@pytest.mark.parametrize("element", ["particles/all/velocity/value", "particles/all/radius", "particles/all/box",
                                     "particles/all/position/time", "observables", "parameters"])
@pytest.mark.parametrize("reader", ["iter_snapshots", "load_snapshot", "read_parameters"])
def test_element_removed(good, element, reader):
    with h5py.File(good, "a") as f:
        del f[element]
    with pytest.raises(InputFileError) as err:
        READERS[reader](good)
    msg = _one_line(err)
    assert msg.startswith(f"{good}: damaged H5MD file: ") and element.split("/")[-1] in msg


@pytest.mark.parametrize("element, shape", [("particles/all/velocity/value", (3, 20, 2)),
                                            ("particles/all/radius", (19,)),
                                            ("particles/all/box/edges/value", (3, 2)),
                                            ("particles/all/position/value", (3, 20))])
def test_wrong_shapes(good, element, shape):
    with h5py.File(good, "a") as f:
        del f[element]
        f.create_dataset(element, data=np.zeros(shape))
    with pytest.raises(InputFileError) as err:
        load_snapshot(good)
    msg = _one_line(err)
    assert msg.startswith(f"{good}: damaged H5MD file: {element} has shape {shape}")


def test_observable_damaged(good):
    with h5py.File(good, "a") as f:
        del f["observables/temperature/time"]
    with pytest.raises(InputFileError, match=r"observables/temperature/time is missing"):
        read_observables(good)
    with h5py.File(good, "a") as f:
        del f["observables/collisions/value"]
        f["observables/collisions/value"] = np.array([b"x", b"y", b"z"])
    with pytest.raises(InputFileError, match="observables/collisions holds values that are not numbers"):
        read_observables(good)


def test_files_of_other_programs(tmp_path):
    lammps = tmp_path / "lammps.h5"
    with h5py.File(lammps, "w") as f:  # an H5MD file of another program
        f.create_group("h5md/creator").attrs["name"] = "lammps"
        f["particles/all/position/value"] = np.zeros((1, 4, 3))
    with pytest.raises(InputFileError, match='not an H5MD file written by granulargas'):
        load_snapshot(lammps)
    empty = tmp_path / "empty.h5"
    empty.write_bytes(b"")
    with pytest.raises(InputFileError, match="not an HDF5 file or unreadable"):
        read_observables(empty)


def test_append_checks_before_changing_anything(good, tmp_path):
    before = good.read_bytes()
    with pytest.raises(InputFileError, match="holds 20 particles in 3D, the continuation 21 in 3D"):
        H5MDWriter.append(good, _state(21, events=20, time=1.0))
    with pytest.raises(InputFileError, match="its last frame is not the state the continuation starts from"):
        H5MDWriter.append(good, _state(20, events=10, time=0.5))
    with pytest.raises(InputFileError, match="lacks the TC model's last-collision times"):
        H5MDWriter.append(good, _state(20, events=20, time=1.0), fields=("last_collision",))
    assert good.read_bytes() == before
