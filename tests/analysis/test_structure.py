"""S(k), g(r) and density field against independent truths."""

import math

import numpy as np
import pytest

from granulargas.analysis import structure as st


def _naive_S(pos, kvec):
    rho = np.exp(1j * pos @ kvec.T).sum(axis=0)
    return np.abs(rho) ** 2 / len(pos)


@pytest.mark.parametrize("dim", [2, 3])
def test_structure_factor_vectors_match_naive_sum(dim):
    rng = np.random.default_rng(dim)
    box = np.array([7.0, 9.0, 8.0][:dim])
    pos = rng.uniform(0, 1, (300, dim)) * box
    kvec, S = st.structure_factor_vectors(pos, box, k_max=3.0, chunk=64)
    np.testing.assert_allclose(S, _naive_S(pos, kvec), rtol=1e-9, atol=1e-9)
    # half space, no k = 0, every vector within k_max, no +-k duplicates
    assert np.all(np.linalg.norm(kvec, axis=1) <= 3.0 + 1e-12) and np.all(np.linalg.norm(kvec, axis=1) > 0)
    keys = {tuple(np.round(k * box / (2 * np.pi)).astype(int)) for k in kvec}
    assert len(keys) == len(kvec)
    assert not any(tuple(-np.array(k)) in keys for k in keys)
    # complete: number of lattice vectors in the half ball
    n = np.arange(-10, 11)
    grid = np.stack(np.meshgrid(*[n] * dim, indexing="ij"), -1).reshape(-1, dim)
    kk = np.linalg.norm(2 * np.pi * grid / box, axis=1)
    assert len(kvec) == (np.count_nonzero(kk <= 3.0) - 1) // 2


@pytest.mark.parametrize("dim", [2, 3])
def test_ideal_gas_structure_factor_is_one_on_average(dim):
    rng = np.random.default_rng(10 + dim)
    box = np.full(dim, 20.0)
    n = 4000
    vals = []
    for _ in range(3):
        k, S, c = st.structure_factor(rng.uniform(0, 20.0, (n, dim)), box, k_max=4.0)
        vals.append(np.sum(S * c) / np.sum(c))
    # each |rho_k|^2/N is exponential with mean 1 - (k = 0 excluded): mean over many k ~ 1
    nk = np.sum(c) * 3
    assert np.mean(vals) == pytest.approx(1.0, abs=5 / math.sqrt(nk))


@pytest.mark.parametrize("dim", [2, 3])
def test_lattice_bragg_peaks(dim):
    a, cells = 1.25, 8
    L = a * cells
    g = np.arange(cells) * a
    pos = np.stack(np.meshgrid(*[g] * dim, indexing="ij"), -1).reshape(-1, dim) + 0.1
    kvec, S = st.structure_factor_vectors(pos, np.full(dim, L), k_max=2 * math.pi / a * 1.01)
    n = np.round(kvec * L / (2 * np.pi)).astype(int)
    bragg = np.all(n % cells == 0, axis=1)
    assert bragg.sum() == dim  # (8,0[,0]), (0,8[,0]), ... in the half space
    np.testing.assert_allclose(S[bragg], len(pos), rtol=1e-9)
    assert np.max(S[~bragg]) < 1e-18 * len(pos) + 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_rdf_of_uniform_random_points_is_one(dim):
    rng = np.random.default_rng(20 + dim)
    box = np.full(dim, 12.0)
    pos = rng.uniform(0, 12.0, (3000, dim))
    r, g = st.radial_distribution(pos, box, r_max=5.0, bins=10)
    # Poisson error per bin ~ 1/sqrt(pairs): generous 5 sigma
    pairs = 3000 * 2999 / 12.0**dim * (math.pi if dim == 2 else 4 * math.pi / 3) * np.diff(np.linspace(0, 5, 11) ** dim)
    assert np.all(np.abs(g - 1) < 5 / np.sqrt(pairs))


def test_rdf_of_square_lattice_peaks_at_neighbour_shells():
    a, cells = 1.0, 10
    g0 = np.arange(cells) * a
    pos = np.stack(np.meshgrid(g0, g0, indexing="ij"), -1).reshape(-1, 2)
    r, g = st.radial_distribution(pos, np.full(2, 10.0), r_max=1.65, bins=11)
    # 4 neighbours at 1 and 4 at sqrt(2): only the bins (0.9, 1.05] and (1.35, 1.5]
    assert np.allclose(r[g > 0], [0.975, 1.425])
    n = 100 / 100.0
    for rr in (0.975, 1.425):
        i = np.argmin(abs(r - rr))
        shell = np.pi * ((r[i] + 0.075) ** 2 - (r[i] - 0.075) ** 2)
        assert g[i] == pytest.approx(4 / (shell * n) * 100 / 99)


def test_rdf_rejects_too_large_r_max():
    with pytest.raises(ValueError):
        st.radial_distribution(np.zeros((3, 2)), np.full(2, 4.0), r_max=2.5)


def test_density_field_conserves_mass_and_locates_particles():
    box = np.array([10.0, 5.0])
    pos = np.array([[0.5, 0.5], [9.9, 4.9], [10.0, 2.0], [-0.1, 1.0]])  # last two wrap
    counts = st.density_field(pos, box, (10, 5), quantity="count")
    assert counts.sum() == 4 and counts[0, 0] == 1 and counts[9, 4] == 1 and counts[0, 2] == 1 and counts[9, 1] == 1
    phi = st.density_field(pos, box, (10, 5))
    assert phi.sum() * 1.0 == pytest.approx(4 * math.pi * 0.25)
