"""Compiled Monte Carlo kernels of the initial states: random numbers, sorted sweeps, threads."""

import numba
import numpy as np
import pytest

from granulargas.initial import _montecarlo as mc
from granulargas.initial import random_state
from granulargas.initial import lattice_gas
from granulargas.initial.lattice_gas import _sorted_grid


def _splitmix64(seed, count):
    """Reference SplitMix64 (Steele, Lea & Flood 2014) in Python integers: top 53 bits / 2^53."""
    mask = (1 << 64) - 1
    x, out = seed, []
    for _ in range(count):
        x = (x + 0x9E3779B97F4A7C15) & mask
        z = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & mask
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
        out.append((z ^ (z >> 31)) >> 11)
    return np.array(out, dtype=np.float64) / 2.0**53


@pytest.mark.parametrize("key, dim", [(0, 3), (1234567890123456789, 3), (2**63 - 1, 2)])
def test_sweep_uniforms_are_splitmix64(key, dim):
    u = mc.sweep_uniforms(np.uint64(key), 7, dim)
    np.testing.assert_array_equal(u.ravel(), _splitmix64(key, 7 * dim))


def test_sweep_uniforms_are_uniform():
    u = mc.sweep_uniforms(np.uint64(42), 200_000, 3)
    assert u.min() >= 0.0 and u.max() < 1.0
    assert u.mean() == pytest.approx(0.5, abs=3 * 0.29 / np.sqrt(u.size))
    assert u.var() == pytest.approx(1 / 12, rel=0.01)
    # neighbouring draws (the axes of one particle) uncorrelated
    assert abs(np.corrcoef(u[:, 0], u[:, 1])[0, 1]) < 3 / np.sqrt(len(u))


@pytest.mark.parametrize("d, eta, step", [(3, 0.3, 0.2), (3, 0.45, 0.05), (2, 0.6, 0.1)])
def test_sorted_sweeps_create_no_overlap(d, eta, step):
    """Many sweeps over cell-sorted particles, each checked by brute force for overlaps."""
    st = random_state(600, eta, d, seed=3, sweeps=0 if eta < 0.4 else None)
    n = len(st.radii)
    r = np.zeros((n, 3))
    r[:, :d] = st.positions
    box = np.ones(3)
    box[:d] = st.box
    radius, ids = st.radii.copy(), np.arange(n)
    grid = _sorted_grid(st.box, 1.0, step)
    assert grid is not None
    start = np.empty(int(np.prod(grid)) + 1, dtype=np.int32)
    scratch = (np.empty(n, dtype=np.int32), np.empty_like(r), np.empty(n), np.empty(n, dtype=np.int64),
               np.empty(n, dtype=np.int32))
    moved = 0
    for sweep in range(30):
        mc.sort_by_cell(r, radius, ids, box, grid, start, *scratch)
        moved += mc.sorted_sweep(r, radius, box, grid, start, step, np.uint64(sweep + 11), d)
        dr = r[:, None, :d] - r[None, :, :d]
        dr -= box[:d] * np.round(dr / box[:d])
        dist = np.linalg.norm(dr, axis=2) + 10 * np.eye(n)
        assert dist.min() >= 1.0, sweep
        assert np.all(r[:, :d] >= 0) and np.all(r[:, :d] < box[:d])
    assert moved > 0.1 * 30 * n
    np.testing.assert_array_equal(np.sort(ids), np.arange(n))


def _overlapping_pairs(st):
    """Pairs closer than R_i + R_j, by brute force over all pairs (minimum image)."""
    d = st.positions.shape[1]
    dr = st.positions[:, None, :] - st.positions[None, :, :]
    dr -= st.box[:d] * np.round(dr / st.box[:d])
    dist = np.linalg.norm(dr, axis=2) + 10 * np.eye(len(st.radii))
    return int(np.sum(np.triu(dist < st.radii[:, None] + st.radii[None, :], 1)))


@pytest.mark.parametrize("d, eta, seed", [(3, 0.54, 0), (3, 0.54, 1), (3, 0.5, 2), (2, 0.76, 0), (2, 0.76, 1)])
def test_dense_states_over_sorted_particles_have_no_overlap(monkeypatch, d, eta, seed):
    """The growth steps of large systems (census and pushes over cell-sorted particles,
    forced here for 600 particles) leave no overlap, at the densest packings allowed."""
    monkeypatch.setattr(lattice_gas, "SORTED_MIN_PARTICLES", 0)
    st = random_state(600, eta, d, seed=seed, sweeps=0)
    assert _overlapping_pairs(st) == 0
    assert np.all(st.positions >= 0) and np.all(st.positions < st.box)


def test_polydisperse_dense_state_over_sorted_particles_has_no_overlap(monkeypatch):
    monkeypatch.setattr(lattice_gas, "SORTED_MIN_PARTICLES", 0)
    radii = np.random.default_rng(5).uniform(0.35, 0.5, 800)
    st = random_state(800, 0.5, 3, seed=4, radii=radii, sweeps=0)
    assert _overlapping_pairs(st) == 0


@pytest.mark.parametrize("n, d, eta", [(64, 3, 0.5), (12, 2, 0.7)])
def test_dense_states_of_large_systems_in_small_boxes_have_no_overlap(monkeypatch, n, d, eta):
    """A box too small for the scans over sorted particles (fewer than two rows of cells):
    the growth steps of a large system push over cell lists there, and leave no overlap."""
    monkeypatch.setattr(lattice_gas, "SORTED_MIN_PARTICLES", 0)
    for seed in range(4):
        st = random_state(n, eta, d, seed=seed, sweeps=0)
        assert _sorted_grid(st.box, 1.0, lattice_gas.PUSH_CAP) is None
        assert _overlapping_pairs(st) == 0


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_state_does_not_depend_on_the_thread_count(monkeypatch):
    monkeypatch.setattr(lattice_gas, "SORTED_MIN_PARTICLES", 0)  # the sorted, parallel sweeps
    monkeypatch.setattr(lattice_gas, "PARALLEL_MIN_PUSHES", 0)  # and pushes
    states = []
    for threads in (1, 2):
        numba.set_num_threads(threads)
        try:
            states.append(random_state(3000, 0.5, 3, seed=2).positions)
        finally:
            numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    monkeypatch.setattr(lattice_gas, "PARALLEL_MIN_PUSHES", 10**9)  # pushes on one thread
    states.append(random_state(3000, 0.5, 3, seed=2).positions)
    np.testing.assert_array_equal(states[0], states[1])
    np.testing.assert_array_equal(states[0], states[2])
