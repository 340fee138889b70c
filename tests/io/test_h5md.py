"""H5MD writer and readers on synthetic arrays (no engine)."""

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
from granulargas.state import STATE_FIELDS, DSMCContinuation, State


def _write(path, frames=3, n=20, d=3, seed=0, **kw):
    rng = np.random.default_rng(seed)
    box = np.full(d, 4.0)
    radii = rng.uniform(0.4, 0.6, n)
    masses = rng.uniform(0.5, 2.0, n)
    params = {"config": "[system]\nseed = 1\n", "seed": 1, "collision": {"model": "constant", "restitution": 0.9},
              "table": np.arange(8.0).reshape(2, 4)}
    state = State(np.zeros((n, d)), np.zeros((n, d)), radii, masses, box)
    w = H5MDWriter(path, state, parameters=params, **kw)
    data = []
    for k in range(frames):
        pos = rng.uniform(0, 4.0, (n, d))
        vel = rng.normal(size=(n, d))
        img = rng.integers(-2, 3, (n, d))
        w.write_observables(10 * k, 0.5 * k, {"temperature": 1.0 / (k + 1), "collisions": 7 * k,
                                             "momentum": np.zeros(d)})
        w.write_state(state.replace(positions=pos, velocities=vel, images=img, events=10 * k, time=0.5 * k))
        data.append((pos, vel, img))
    w.close()
    return box, radii, masses, data


def test_layout_is_h5md_1_1(tmp_path):
    p = tmp_path / "a.h5"
    _write(p)
    with h5py.File(p, "r") as f:
        assert list(f["h5md"].attrs["version"]) == [1, 1]
        assert f["h5md/creator"].attrs["name"] == "granulargas"
        assert "name" in f["h5md/author"].attrs
        box = f["particles/all/box"]
        assert box.attrs["dimension"] == 3
        assert [b.decode() if isinstance(b, bytes) else b for b in box.attrs["boundary"]] == ["periodic"] * 3
        for name in ("position", "velocity", "image", "box/edges"):
            g = f["particles/all/" + name]
            assert g["step"].dtype.kind == "i" and g["time"].dtype.kind == "f"
            assert g["value"].shape[0] == g["step"].shape[0] == 3
        assert f["particles/all/position/value"].shape == (3, 20, 3)
        for name in ("mass", "radius", "species"):
            assert f["particles/all/" + name].shape == (20,)
        for name in ("temperature", "kinetic_energy", "collisions", "pressure", "dissipated_energy"):
            g = f["observables/" + name]
            assert g["value"].shape[0] == g["step"].shape[0] == g["time"].shape[0] == 3


def test_readers_round_trip_exactly(tmp_path):
    p = tmp_path / "a.h5"
    box, radii, masses, data = _write(p, d=2)
    snaps = list(iter_snapshots(p))
    assert [s.time for s in snaps] == [0.0, 0.5, 1.0] and [s.step for s in snaps] == [0, 10, 20]
    for s, (pos, vel, img) in zip(snaps, data):
        assert np.array_equal(s.positions, pos) and np.array_equal(s.velocities, vel)
        assert np.array_equal(s.images, img) and np.array_equal(s.box, box)
        assert np.array_equal(s.radii, radii) and np.array_equal(s.masses, masses)
        assert np.array_equal(s.unwrapped_positions, pos + img * box)
    assert np.array_equal(load_snapshot(p).positions, data[-1][0])
    assert np.array_equal(load_snapshot(p, 1).velocities, data[1][1])
    with pytest.raises(InputFileError, match="out of range"):
        load_snapshot(p, 3)
    obs = read_observables(p)
    step, time, value = obs["temperature"]
    assert list(step) == [0, 10, 20] and list(time) == [0.0, 0.5, 1.0] and list(value) == [1.0, 0.5, 1 / 3]
    assert list(obs["collisions"][2]) == [0, 7, 14]
    assert np.isnan(obs["pressure"][2]).all()  # not given -> NaN
    par = read_parameters(p)
    assert par["config"] == "[system]\nseed = 1\n" and par["seed"] == 1
    assert par["collision"] == {"model": "constant", "restitution": 0.9}
    assert np.array_equal(par["table"], np.arange(8.0).reshape(2, 4))
    assert par["creator_version"]


def test_iter_snapshots_reads_one_frame_at_a_time(tmp_path, monkeypatch):
    p = tmp_path / "a.h5"
    _write(p, frames=4)
    reads = []
    orig = h5py.Dataset.__getitem__

    def spy(self, key):
        out = orig(self, key)
        if self.name.endswith("position/value"):
            reads.append(np.shape(out))
        return out

    monkeypatch.setattr(h5py.Dataset, "__getitem__", spy)
    assert len(list(iter_snapshots(p))) == 4
    assert reads == [(20, 3)] * 4


def test_never_overwrites_without_permission(tmp_path):
    p = tmp_path / "a.h5"
    _write(p)
    before = p.read_bytes()
    with pytest.raises(InputFileError, match="exists"):
        _write(p)
    assert p.read_bytes() == before
    _write(p, frames=1, overwrite=True)
    assert snapshot_count(p) == 1


def test_half_written_frame_is_ignored(tmp_path):
    """A frame whose values were resized but whose step/time were not (killed mid-write)."""
    p = tmp_path / "a.h5"
    _write(p)
    with h5py.File(p, "a") as f:
        v = f["particles/all/position/value"]
        v.resize(4, axis=0)
    assert snapshot_count(p) == 3 and load_snapshot(p).time == 1.0


def test_foreign_files_are_rejected(tmp_path):
    p = tmp_path / "other.h5"
    with h5py.File(p, "w") as f:
        f.create_group("h5md/creator").attrs["name"] = "someone else"
    with pytest.raises(InputFileError, match="not an H5MD file written by granulargas"):
        load_snapshot(p)
    q = tmp_path / "text.h5"
    q.write_text("hello")
    with pytest.raises(InputFileError, match="not an HDF5 file"):
        read_observables(q)
    with pytest.raises(InputFileError, match="file not found"):
        read_parameters(tmp_path / "missing.h5")


def _full_state(rng, n=12, d=3, **extra):
    return State(rng.uniform(0, 4.0, (n, d)), rng.normal(size=(n, d)), rng.uniform(0.3, 0.5, n),
                 rng.uniform(0.5, 2.0, n), np.full(d, 4.0), boundary=("periodic",) * (d - 1) + ("wall",),
                 images=rng.integers(-2, 3, (n, d)) * np.array([1] * (d - 1) + [0]),
                 species=np.arange(n) % 2, last_collision=rng.uniform(0, 1, n),
                 contact_until=rng.uniform(0, 1, n), contact_partner=rng.integers(-1, n, n), time=2.5,
                 collisions=40, events=97, dissipated_energy=1.25, wall_collisions=6, injected_energy=0.5,
                 kick_step=11, three_body_contacts=3, **extra)


def _counters(st, d):
    return {"temperature": 1.0, "collisions": st.collisions, "dissipated_energy": st.dissipated_energy,
            "momentum": np.zeros(d), "wall_collisions": st.wall_collisions, "injected_energy": st.injected_energy,
            "kick_step": st.kick_step, "three_body_contacts": st.three_body_contacts}


@pytest.mark.parametrize("d", [2, 3])
def test_write_state_and_read_state_round_trip_every_field(tmp_path, d):
    """write_state / read_state: each per-particle field the run stores, box, boundary, time,
    step and every counter (from the observables sample at the frame) come back exactly."""
    rng = np.random.default_rng(d)
    first, other = _full_state(rng, d=d), _full_state(rng, d=d)
    last = other.replace(radii=first.radii, masses=first.masses, species=first.species, time=3.5, events=150,
                         collisions=70)  # time-independent fields as in the first frame
    fields = ("last_collision", "contact_until", "contact_partner")
    p = tmp_path / "s.h5"
    with H5MDWriter(p, first, fields=fields, driven=True) as w:
        for st in (first, last):
            w.write_observables(st.events, st.time, _counters(st, d))
            w.write_state(st)
    for index, st in ((0, first), (-1, last)):
        back = read_state(p, index)
        for name in STATE_FIELDS:
            if name in ("dsmc",):
                continue
            want, got = getattr(st, name), getattr(back, name)
            if isinstance(want, np.ndarray):
                assert got.dtype == want.dtype and np.array_equal(got, want), name
            else:
                assert got == want, name
    with h5py.File(p, "r") as f:  # each element says what it holds, and which are restart state only
        part = f["particles/all"]
        assert part["last_collision"].attrs["description"].endswith("(kept for exact restarts)")
        assert part["position"].attrs["description"] == "positions, wrapped into the box on periodic axes"
        assert part["species"].attrs["description"] == "species indices"
    # a frame without an observables sample at its time is no restart state
    with H5MDWriter(tmp_path / "t.h5", first) as w:
        w.write_observables(0, 0.0, {"collisions": 0, "dissipated_energy": 0.0})
        w.write_state(first)
    with pytest.raises(InputFileError, match=r"no observables sample at snapshot 0 \(t = 2.5\)"):
        read_state(tmp_path / "t.h5")


def test_dsmc_frames_store_the_continuation(tmp_path):
    rng = np.random.default_rng(5)
    cont = DSMCContinuation(rng=rng.integers(0, 2**63, 5, dtype=np.uint64), candidates=1234, pending_pair=(3, 7),
                            pending_time=2.75, frame_velocity=[0.1, -0.2, 0.3])
    st = State(None, rng.normal(size=(10, 3)), 0.5, 1.0, np.full(3, 8.0), time=2.5, collisions=900, events=900,
               dissipated_energy=3.0, dsmc=cont)
    p = tmp_path / "d.h5"
    with H5MDWriter(p, st) as w:
        w.write_observables(900, 2.5, {"temperature": 1.0, "collisions": 900, "dissipated_energy": 3.0,
                                       "momentum": np.zeros(3)})
        w.write_state(st)
    back = read_state(p)
    assert back.positions is None and back.images is None
    assert np.array_equal(back.velocities, st.velocities) and (back.time, back.events) == (2.5, 900)
    assert np.array_equal(back.dsmc.rng, cont.rng) and back.dsmc.pending_pair == (3, 7)
    assert (back.dsmc.candidates, back.dsmc.pending_time) == (1234, 2.75)
    with pytest.raises(ValueError, match="DSMC continuation"):
        with H5MDWriter(tmp_path / "e.h5", st) as w:
            w.write_state(st.replace(dsmc=None))
