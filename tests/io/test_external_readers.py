"""Our files load in the readers people use: pyh5md (2D and 3D) and MDAnalysis (3D)."""

import numpy as np
import pytest

from granulargas.io.config import load_config
from granulargas.io.h5md import iter_snapshots, read_observables
from granulargas.run.runner import run_config


@pytest.fixture(scope="module")
def run_files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ext")
    text = """
[system]
dimension = {d}
particles = 200
packing_fraction = 0.1
[collision]
model = "constant"
restitution = 0.95
[run]
end_time = 2.0
[output]
file = "{out}"
snapshot_interval = 0.5
observables_interval = 0.5
"""
    files = {}
    for d in (2, 3):
        cfg = tmp / f"c{d}.toml"
        cfg.write_text(text.replace("{d}", str(d)).replace("{out}", str(tmp / f"run{d}.h5")))
        files[d] = run_config(load_config(cfg)).output
    return files


@pytest.mark.parametrize("d", [2, 3])
def test_pyh5md_reads_positions_velocities_box_time(run_files, d):
    pyh5md = pytest.importorskip("pyh5md")
    ours = list(iter_snapshots(run_files[d]))
    with pyh5md.File(str(run_files[d]), "r") as f:
        part = f.particles_group("all")
        assert part["box"].attrs["dimension"] == d
        pos = pyh5md.element(part, "position")
        vel = pyh5md.element(part, "velocity")
        edges = pyh5md.element(part["box"], "edges")
        assert pos.element_type == "TimeElement"
        assert list(pos.time[()]) == [s.time for s in ours]
        assert list(pos.step[()]) == [s.step for s in ours]
        for k, s in enumerate(ours):
            assert np.array_equal(pos.value[k], s.positions)
            assert np.array_equal(vel.value[k], s.velocities)
            assert np.array_equal(edges.value[k], s.box)
        temp = pyh5md.element(f["observables"], "temperature")
        assert np.array_equal(temp.value[()], read_observables(run_files[d])["temperature"][2])


def test_mdanalysis_reads_3d_run(run_files):
    mda = pytest.importorskip("MDAnalysis")
    ours = list(iter_snapshots(run_files[3]))
    u = mda.Universe.empty(len(ours[0].radii))
    u.load_new(str(run_files[3]), format="H5MD", convert_units=False)
    assert u.trajectory.n_frames == len(ours)
    for ts, s in zip(u.trajectory, ours):
        assert ts.time == pytest.approx(s.time)
        assert ts.data["step"] == s.step
        assert np.allclose(ts.positions, s.positions, rtol=1e-6, atol=1e-5)  # MDAnalysis keeps float32
        assert np.allclose(ts.velocities, s.velocities, rtol=1e-6, atol=1e-6)
        assert np.allclose(ts.dimensions, list(s.box) + [90, 90, 90])


def test_pyh5md_reads_a_dsmc_file(tmp_path):
    """A DSMC file (no positions): velocity is a time element of its own, observables as usual."""
    pyh5md = pytest.importorskip("pyh5md")
    cfg = tmp_path / "d.toml"
    cfg.write_text('[system]\nparticles = 300\npacking_fraction = 0.02\n[collision]\nmodel = "constant"\n'
                   f'restitution = 0.9\n[run]\nmethod = "dsmc"\nend_time = 5.0\n[output]\nfile = "{tmp_path / "d.h5"}"\n'
                   "snapshot_interval = 1.0\n")
    out = run_config(load_config(cfg)).output
    ours = list(iter_snapshots(out))
    with pyh5md.File(str(out), "r") as f:
        part = f.particles_group("all")
        assert "position" not in part
        vel = pyh5md.element(part, "velocity")
        assert vel.element_type == "TimeElement"
        assert list(vel.time[()]) == [s.time for s in ours] == [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
        for k, s in enumerate(ours):
            assert np.array_equal(vel.value[k], s.velocities)
        temp = pyh5md.element(f["observables"], "temperature")
        assert np.array_equal(temp.value[()], read_observables(out)["temperature"][2])
