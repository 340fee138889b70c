"""Soft-sphere compression of large initial states: neighbour lists and FIRE forces against
brute-force references, and the compression route forced at small N."""

import numba
import numpy as np
import pytest

from granulargas.initial import _compression as fire
from granulargas.initial import _montecarlo as mc
from granulargas.initial import lattice_gas, random_state


def _sorted_overlapping_state(n, eta, d, seed, radii=None):
    """A fluid state (positions (n, 3), radii, box (3,)) grown 6 % beyond its radii (so
    that many pairs overlap), sorted by the cells of the compression's grid."""
    radii = np.full(n, 0.5) if radii is None else radii
    st = random_state(n, eta, d, seed=seed, radii=radii)
    r = np.zeros((n, 3))
    r[:, :d] = st.positions
    box = np.ones(3)
    box[:d] = st.box
    radius = 1.06 * st.radii
    grid = fire.compression_grid(st.box, 2.0 * radius.max() * (1.04 + 0.25))
    assert grid is not None
    start = np.empty(int(np.prod(grid)) + 1, dtype=np.int32)
    ids = np.arange(n)
    mc.sort_by_cell(r, radius, ids, box, grid, start, np.empty(n, dtype=np.int32), np.empty_like(r),
                    np.empty(n), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int32))
    return r, radius, box, grid, start


def _brute_pairs(r, radius, box, cut):
    """Pairs i < j (sorted order) with |r_ij| < cut(R_i + R_j), minimum image, and their
    separation vectors r_i - r_j."""
    dr = r[:, None, :] - r[None, :, :]
    dr -= box * np.round(dr / box)
    dist = np.linalg.norm(dr, axis=2)
    i, j = np.nonzero(np.triu(dist < cut(radius[:, None] + radius[None, :]), 1))
    return i, j, dr[i, j]


@pytest.mark.parametrize("d, eta, poly", [(3, 0.45, False), (2, 0.6, False), (3, 0.4, True)])
def test_neighbour_rows_hold_each_close_pair_once(d, eta, poly):
    n = 700
    radii = np.random.default_rng(1).uniform(0.35, 0.5, n) if poly else None
    r, radius, box, grid, start = _sorted_overlapping_state(n, eta, d, seed=2, radii=radii)
    swell, skin = 0.04, 0.2
    counts = np.empty(n, dtype=np.int64)
    fire.neighbour_counts(r, radius, box, grid, start, swell, skin, counts)
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    pairs = np.empty(int(offsets[-1]), dtype=np.int32)
    found = np.empty(n, dtype=np.int64)
    assert fire.neighbour_rows(r, radius, box, grid, start, swell, skin, offsets, pairs, found) == 0
    np.testing.assert_array_equal(found, counts)
    listed = {(k, int(j)) for k in range(n) for j in pairs[offsets[k]:offsets[k + 1]]}
    assert len(listed) == offsets[-1]  # no pair twice
    i, j, _ = _brute_pairs(r, radius, box, lambda s: (1 + swell) * s + skin)
    assert listed == set(zip(i.tolist(), j.tolist()))
    # rows too short: counted, reported, nothing written beyond them
    short = offsets.copy()
    short[1:] = np.cumsum(np.maximum(counts - 1, 0))
    guard = np.full(int(short[-1]) + 5, -7, dtype=np.int32)
    assert fire.neighbour_rows(r, radius, box, grid, start, swell, skin, short, guard, found) == np.sum(counts > 0)
    assert np.all(guard[short[-1]:] == -7)


def _listed_state(n, eta, d, seed, swell, skin, radii=None, odd_slabs=False):
    """A sorted overlapping state with its neighbour list and slabs: (r, radius, box, offsets,
    counts, pairs, slab_start), with an odd (``odd_slabs``) or even number of z slabs (y rows
    in 2D): one fewer than the grid's if needed, each thicker."""
    r, radius, box, grid, start = _sorted_overlapping_state(n, eta, d, seed, radii=radii)
    if grid[d - 1] % 2 != odd_slabs:
        grid = grid.copy()
        grid[d - 1] -= 1
        mc.sort_by_cell(r, radius, np.arange(n), box, grid, start, np.empty(n, dtype=np.int32), np.empty_like(r),
                        np.empty(n), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int32))
    counts = np.empty(n, dtype=np.int64)
    fire.neighbour_counts(r, radius, box, grid, start, swell, skin, counts)
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    pairs = np.empty(int(offsets[-1]), dtype=np.int32)
    assert fire.neighbour_rows(r, radius, box, grid, start, swell, skin, offsets, pairs, counts) == 0
    slabs = int(grid[d - 1])
    slab_start = start[np.arange(slabs + 1) * (int(np.prod(grid)) // slabs)].astype(np.int64)
    return r, radius, box, offsets, counts, pairs, slab_start


def _forces(r, radius, box, offsets, counts, pairs, swell, v, slab_start):
    f = np.full((len(r), 3), np.nan)
    sums = np.empty((len(slab_start) - 1, 6))
    return f, fire.fire_forces(r, radius, box, offsets, counts, pairs, swell, v, f, slab_start, sums)


@pytest.mark.parametrize("n, d, eta, odd", [(2500, 3, 0.45, False), (2500, 3, 0.45, True), (700, 2, 0.6, True)])
def test_fire_forces_are_the_swollen_harmonic_overlaps(n, d, eta, odd):
    swell = 0.04
    radii = np.random.default_rng(3).uniform(0.4, 0.5, n)
    r, radius, box, offsets, counts, pairs, slab_start = _listed_state(n, eta, d, 4, swell, 0.2, radii, odd)
    slabs = len(slab_start) - 1
    assert slabs % 2 == odd and slabs >= 3
    # pairs across the periodic boundary between the first and the last slab (written by slab 0)
    rows = np.repeat(np.arange(n), counts)
    listed = np.concatenate([pairs[offsets[k]:offsets[k] + counts[k]] for k in range(n)])
    assert np.sum((rows < slab_start[1]) & (listed >= slab_start[-2])) > 10
    v = np.random.default_rng(5).standard_normal((n, 3))
    v[:, 2] *= d == 3
    f, (power, vv, ff, hard, worst, stray) = _forces(r, radius, box, offsets, counts, pairs, swell, v, slab_start)
    # reference: every pair by brute force, F_i = sum_j (s'_ij - d_ij) n_ij
    i, j, dr = _brute_pairs(r, radius, box, lambda s: (1 + swell) * s)
    s = radius[i] + radius[j]
    dist = np.linalg.norm(dr, axis=1)
    push = ((1 + swell) * s - dist)[:, None] * dr / dist[:, None]
    ref = np.zeros((n, 3))
    np.add.at(ref, i, push)
    np.add.at(ref, j, -push)
    assert len(i) > n  # many overlaps: a real test
    np.testing.assert_allclose(f, ref, rtol=1e-12, atol=1e-12)
    assert power == pytest.approx(np.sum(ref * v), rel=1e-12)
    assert vv == pytest.approx(np.sum(v * v), rel=1e-12)
    assert ff == pytest.approx(np.sum(ref * ref), rel=1e-12)
    assert hard == np.sum(dist < s)
    assert worst == pytest.approx(np.max((1 + swell) * s - dist - 0.5 * swell * s), rel=1e-12)
    assert stray == 0


@pytest.mark.parametrize("odd", [False, True])
def test_fire_forces_are_the_same_for_any_thread_count(odd):
    n = 3000
    r, radius, box, offsets, counts, pairs, slab_start = _listed_state(n, 0.5, 3, 7, 0.04, 0.25, odd_slabs=odd)
    v = np.random.default_rng(8).standard_normal((n, 3))
    threads = numba.get_num_threads()
    try:
        out = []
        for t in sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)}):
            numba.set_num_threads(t)
            out.append(_forces(r, radius, box, offsets, counts, pairs, 0.04, v, slab_start))
    finally:
        numba.set_num_threads(threads)
    for f, sums in out[1:]:
        np.testing.assert_array_equal(f, out[0][0])
        assert sums == out[0][1]


def test_fire_forces_report_pairs_beyond_the_next_slab():
    """Slabs thinner than the list's reach (here: one slab counted as two) are reported."""
    n = 700
    r, radius, box, offsets, counts, pairs, slab_start = _listed_state(n, 0.45, 3, 4, 0.04, 0.2)
    halves = np.sort(np.concatenate([slab_start, (slab_start[1:] + slab_start[:-1]) // 2]))
    _, out = _forces(r, radius, box, offsets, counts, pairs, 0.04, np.zeros((n, 3)), halves)
    assert out[-1] > 0


def test_fire_move_is_a_fire_step():
    rng = np.random.default_rng(6)
    r, v, f = rng.random((9, 3)), rng.standard_normal((9, 3)), rng.standard_normal((9, 3))
    r0 = r - 0.01
    want_v = 0.9 * v + 0.3 * f + 0.2 * f
    want_r = r + 0.2 * want_v
    moved = np.empty((3, 2))
    fire.fire_move(r, v, f, r0, 0.9, 0.3, 0.2, 10.0, 4, moved)
    np.testing.assert_allclose(v, want_v, rtol=1e-14)
    np.testing.assert_allclose(r, want_r, rtol=1e-14)
    dist = np.linalg.norm(want_r - r0, axis=1)
    top = [np.sort(dist[0:4])[::-1][:2], np.sort(dist[4:8])[::-1][:2], [dist[8], 0.0]]
    np.testing.assert_allclose(moved, top, rtol=1e-14)


def test_fire_move_caps_each_move():
    rng = np.random.default_rng(7)
    r, v, f = rng.random((6, 3)), rng.standard_normal((6, 3)), rng.standard_normal((6, 3))
    f[2] *= 100.0  # a large force: this particle's move is capped
    want_v = 0.9 * v + 0.3 * f + 0.2 * f
    step = 0.2 * np.linalg.norm(want_v, axis=1)
    cap = 0.5 * step[2]
    assert np.sum(step > cap) == 1
    want_v[2] *= cap / step[2]  # the same direction, a move of length cap
    want_r = r + 0.2 * want_v
    fire.fire_move(r, v, f, r.copy(), 0.9, 0.3, 0.2, cap, 4, np.empty((2, 2)))
    np.testing.assert_allclose(v, want_v, rtol=1e-14)
    np.testing.assert_allclose(r, want_r, rtol=1e-14)
    assert np.linalg.norm(0.2 * v[2]) == pytest.approx(cap, rel=1e-14)


def test_large_dense_states_are_compressed_without_pushes(monkeypatch):
    """The sorted route grows dense states to full size by the compression alone."""
    monkeypatch.setattr(lattice_gas, "SORTED_MIN_PARTICLES", 0)

    def no_pushes(*args):
        raise AssertionError("pushes used")

    monkeypatch.setattr(mc, "sorted_push", no_pushes)
    monkeypatch.setattr(mc, "sorted_push_serial", no_pushes)
    monkeypatch.setattr(mc, "push_some", no_pushes)
    st = random_state(1500, 0.5, 3, seed=1)
    dr = st.positions[:, None, :] - st.positions[None, :, :]
    dr -= st.box * np.round(dr / st.box)
    dist = np.linalg.norm(dr, axis=2) + 10 * np.eye(1500)
    assert dist.min() >= 1.0


def test_compressed_states_keep_no_density_wave_of_the_lattice(monkeypatch):
    """S(G) at the lattice's nearest reciprocal vectors G ({111}, {200} of the FCC cell) is
    the fluid's (~2; here the mean over seven G), not a remnant of the start (melting sweeps
    before the compression leave a mean of 30-40 at this N, a perfect lattice N)."""
    monkeypatch.setattr(lattice_gas, "SORTED_MIN_PARTICLES", 0)
    n, eta = 5000, 0.5
    st = random_state(n, eta, 3, seed=1)
    sites = lattice_gas._lattice(max(n, round(n / (1 - lattice_gas.fluid_s0(eta, 3)))), st.box)[0]
    cell = st.box / (np.array([len(np.unique(np.round(sites[:, a], 9))) for a in range(3)]) // 2)
    hkl = np.array([(1, 1, 1), (1, 1, -1), (1, -1, 1), (-1, 1, 1), (2, 0, 0), (0, 2, 0), (0, 0, 2)])
    s_g = np.abs(np.exp(1j * st.positions @ (2 * np.pi * hkl / cell).T).sum(axis=0)) ** 2 / n
    assert np.mean(s_g) < 10.0


def test_separate_pairs_pushes_overlapping_pairs_to_the_swollen_distance():
    box = np.array([10.0, 10.0, 10.0])
    r = np.array([[0.2, 5.0, 5.0], [9.5, 5.0, 5.0], [3.0, 3.0, 3.0], [4.05, 3.0, 3.0]])  # pair 0-1 across x = 0
    radius = np.array([0.5, 0.5, 0.4, 0.6])
    offsets = np.array([0, 2, 3, 4, 4])
    counts = np.array([2, 0, 1, 0])
    pairs = np.array([1, 2, 3, -1], dtype=np.int32)  # 0-1 (overlap 0.3), 0-2 (apart), 2-3 (apart)
    assert fire.separate_pairs(r, radius, box, offsets, counts, pairs, 0.04) == 1
    gap = r[0, 0] + 10.0 - r[1, 0]
    assert gap == pytest.approx(1.02, rel=1e-14)
    assert r[0, 0] + r[1, 0] - 10.0 == pytest.approx(0.2 + 9.5 - 10.0, abs=1e-14)  # centre kept
    np.testing.assert_array_equal(r[2:], [[3.0, 3.0, 3.0], [4.05, 3.0, 3.0]])
