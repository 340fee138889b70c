"""Fletcher-32 checksums on every dataset the writers create: bytes changed inside a dataset's
stored data after writing give one line naming the element (exit 2), never numbers."""

import h5py
import numpy as np
import pytest

from granulargas.cli import main
from granulargas.errors import InputFileError
from granulargas.io.config import parse_config
from granulargas.io.h5md import H5MDWriter, read_observables, read_parameters
from granulargas.run.runner import run_config
from granulargas.state import DSMCContinuation, State

CONFIG = """
[system]
dimension = 3
particles = 300
packing_fraction = 0.1
seed = 3
[collision]
model = "viscoelastic"
damping = 0.1
[run]
end_time = 4.0
[output]
file = "{file}"
snapshots = 6
"""


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("checksums") / "run.h5"
    run_config(parse_config(CONFIG.format(file=path), source="c.toml"), quiet=True)
    return path


def _datasets(path):
    out = {}

    def visit(name, obj):  # returns None: h5py goes on visiting
        if isinstance(obj, h5py.Dataset):
            out[name] = obj.fletcher32

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return out


def test_every_dataset_of_a_run_carries_a_checksum(run_file):
    sets = _datasets(run_file)
    assert {"particles/all/velocity/value", "particles/all/radius", "observables/temperature/value",
            "parameters/config", "parameters/collision/restitution_table/coeffs"} <= set(sets)
    assert all(sets.values()), [k for k, v in sets.items() if not v]
    text = read_parameters(run_file)["config"]  # the text reads back whole
    assert text == parse_config(CONFIG.format(file=run_file), source="c.toml").to_toml()


def test_every_optional_element_carries_a_checksum(tmp_path):
    n, d = 20, 3
    rng = np.random.default_rng(1)
    velocities, radii, masses = rng.normal(size=(n, d)), np.full(n, 0.5), np.ones(n)
    engine = State(rng.uniform(1, 5, (n, d)), velocities, radii, masses, np.full(d, 6.0),
                   boundary=("periodic", "periodic", "wall"), last_collision=np.zeros(n),
                   contact_until=np.full(n, -np.inf), contact_partner=np.full(n, -1), kick_step=0)
    dsmc = State(None, velocities, radii, masses, np.full(d, 6.0), dsmc=DSMCContinuation(
        rng=np.zeros(5, np.uint64), candidates=0, pending_pair=(0, 0), pending_time=0.0,
        frame_velocity=np.zeros(d)))
    for name, state, fields in (("engine", engine, ("last_collision", "contact_until", "contact_partner")),
                                ("dsmc", dsmc, ())):
        path = tmp_path / f"{name}.h5"
        with H5MDWriter(path, state, fields=fields, parameters={"table": np.zeros(3)}, driven=True) as w:
            w.write_observables(0, 0.0, {"temperature": 1.0})
            w.write_state(state)
            w.mark_interrupted("test")
        sets = _datasets(path)
        assert len(sets) > 15 and all(sets.values()), [k for k, v in sets.items() if not v]


def _corrupt(path, element, coord, seed, count=3):
    """Flip ``count`` random bytes of the stored data of the chunk of ``element`` at ``coord`` (not its
    four checksum bytes at the end); returns the chunk's byte range."""
    with h5py.File(path, "r") as f:
        info = f[element].id.get_chunk_info_by_coord(coord)
    rng = np.random.default_rng(seed)
    raw = bytearray(path.read_bytes())
    for at in info.byte_offset + rng.choice(info.size - 4, count, replace=False):
        raw[at] ^= int(rng.integers(1, 256))
    path.write_bytes(bytes(raw))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_changed_bytes_in_a_snapshot_give_one_line_naming_it(run_file, tmp_path, capsys, seed):
    path = tmp_path / "bad.h5"
    path.write_bytes(run_file.read_bytes())
    frame = 1 + seed  # chunks of one frame each
    _corrupt(path, "particles/all/velocity/value", (frame, 0, 0), seed)
    assert main(["analyze", str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.strip() == (f"error: {path}: damaged H5MD file: particles/all/velocity/value, frame {frame}: "
                           "checksum mismatch (Fletcher-32): the stored data changed after they were written")
    assert main(["analyze", str(path), "--no-snapshots"]) == 0  # the observables alone are intact
    capsys.readouterr()


def test_changed_bytes_in_the_observables_or_the_config_name_them(run_file, tmp_path):
    obs = tmp_path / "obs.h5"
    obs.write_bytes(run_file.read_bytes())
    _corrupt(obs, "observables/temperature/value", (0,), 5)
    with pytest.raises(InputFileError, match=r"observables/temperature/value: checksum mismatch"):
        read_observables(obs)
    par = tmp_path / "par.h5"
    par.write_bytes(run_file.read_bytes())
    _corrupt(par, "parameters/config", (0,), 6)
    with pytest.raises(InputFileError, match=r"parameters/config: checksum mismatch"):
        read_parameters(par)
