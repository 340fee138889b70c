"""``granulargas export gsd``: every H5MD snapshot reads back from GSD with the gsd package."""

import sys

import numpy as np
import pytest

from granulargas.cli import main
from granulargas.errors import InputFileError, UserError
from granulargas.io.gsd import GSD_TIME_KEY, export_gsd
from granulargas.io.h5md import H5MDWriter, iter_snapshots
from granulargas.state import State

# gsd is in the `test` extra: a missing gsd fails here rather than skipping the export tests
import gsd.hoomd as gsd_hoomd  # noqa: E402


def write_h5md(path, dimension, n=37, frames=4, seed=0):
    """A small H5MD file written with our writer (no engine needed)."""
    rng = np.random.default_rng(seed)
    box = np.array([7.0, 9.5, 8.25][:dimension])
    radii = rng.uniform(0.3, 0.6, n)
    masses = rng.uniform(0.5, 2.0, n)
    species = (np.arange(n) % 3 == 0).astype(np.int32) * 2  # species 0 and 2
    state = State(np.zeros((n, dimension)), np.zeros((n, dimension)), radii, masses, box, species=species)
    with H5MDWriter(path, state) as w:
        for k in range(frames):
            pos = rng.uniform(0, 1, (n, dimension)) * box
            vel = rng.normal(size=(n, dimension))
            img = rng.integers(-3, 4, (n, dimension))
            w.write_state(state.replace(positions=pos, velocities=vel, images=img, events=17 * k, time=0.25 * k + 0.1))
    return path


@pytest.mark.parametrize("dimension", [2, 3])
def test_gsd_reads_back_and_matches_h5md(tmp_path, dimension):
    h5 = write_h5md(tmp_path / "run.h5", dimension)
    path, frames = export_gsd(h5)
    assert path == tmp_path / "run.gsd" and frames == 4
    snaps = list(iter_snapshots(h5))
    with gsd_hoomd.open(str(path), mode="r") as traj:
        assert len(traj) == len(snaps)
        for snap, frame in zip(snaps, traj):
            n, d = snap.positions.shape
            L = snap.box
            assert frame.configuration.dimensions == d
            assert frame.configuration.step == snap.step
            np.testing.assert_allclose(frame.configuration.box[:d], L, rtol=1e-7)
            if d == 2:
                assert frame.configuration.box[2] == 0.0
            assert np.all(frame.configuration.box[3:] == 0.0)
            assert frame.particles.N == n
            # GSD boxes are centred on the origin; single precision (HOOMD schema)
            np.testing.assert_allclose(frame.particles.position[:, :d] + 0.5 * L, snap.positions,
                                       atol=4 * np.finfo(np.float32).eps * L.max())
            assert np.all(np.abs(frame.particles.position[:, :d]) <= 0.5 * L * (1 + 1e-6))
            np.testing.assert_allclose(frame.particles.velocity[:, :d], snap.velocities, rtol=1e-6, atol=1e-6)
            np.testing.assert_array_equal(frame.particles.image[:, :d], snap.images)
            if d == 2:
                assert np.all(frame.particles.position[:, 2] == 0) and np.all(frame.particles.velocity[:, 2] == 0)
            np.testing.assert_allclose(frame.particles.diameter, 2 * snap.radii, rtol=1e-7)
            np.testing.assert_allclose(frame.particles.mass, snap.masses, rtol=1e-7)
            assert frame.particles.types == ["S0", "S2"]
            np.testing.assert_array_equal(frame.particles.typeid, np.where(snap.species == 2, 1, 0))
            assert frame.log[GSD_TIME_KEY][0] == snap.time


def test_cli_output_and_overwrite(tmp_path, capsys):
    h5 = write_h5md(tmp_path / "a.h5", 3, frames=2)
    out = tmp_path / "movie.gsd"
    assert main(["export", "gsd", str(h5), "-o", str(out)]) == 0
    assert "2 frames" in capsys.readouterr().out
    assert main(["export", "gsd", str(h5), "-o", str(out)]) == 2  # exists
    assert "--overwrite" in capsys.readouterr().err
    assert main(["export", "gsd", str(h5), "-o", str(out), "--overwrite"]) == 0
    assert not list(tmp_path.glob("*.part"))


def test_bad_inputs(tmp_path):
    with pytest.raises(InputFileError, match="not found"):
        export_gsd(tmp_path / "missing.h5")
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    with pytest.raises(InputFileError, match="not an HDF5"):
        export_gsd(junk)


def test_missing_gsd_package_is_one_clear_line(tmp_path, monkeypatch):
    h5 = write_h5md(tmp_path / "a.h5", 2, frames=1)
    monkeypatch.setitem(sys.modules, "gsd.hoomd", None)  # makes `import gsd.hoomd` raise ImportError
    with pytest.raises(UserError, match=r"pip install 'granulargas\[export\]'"):
        export_gsd(h5)


def test_export_of_a_real_run(tmp_path):
    """End to end: granulargas run -> export gsd, unwrapped positions preserved."""
    cfg = tmp_path / "gas.toml"
    cfg.write_text(f"""
[system]
dimension = 2
particles = 60
packing_fraction = 0.2
seed = 3

[collision]
model = "viscoelastic"
damping = 0.1

[run]
end_time = 1.0

[output]
file = "{tmp_path / 'gas.h5'}"
snapshots = 3
""")
    assert main(["run", str(cfg), "--quiet"]) == 0
    path, frames = export_gsd(tmp_path / "gas.h5")
    snaps = list(iter_snapshots(tmp_path / "gas.h5"))
    assert frames == len(snaps) == 3
    with gsd_hoomd.open(str(path)) as traj:
        for snap, frame in zip(snaps, traj):
            L = snap.box
            unwrapped = frame.particles.position[:, :2] + frame.particles.image[:, :2] * L + 0.5 * L
            np.testing.assert_allclose(unwrapped, snap.unwrapped_positions, atol=1e-5 * L.max() * 4)
