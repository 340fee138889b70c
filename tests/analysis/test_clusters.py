"""Clusters against known layouts."""

import numpy as np
import pytest

from granulargas.analysis import clusters as cl


def test_chains_across_the_periodic_boundary():
    box = np.array([20.0, 20.0])
    # chain of 5 touching disks crossing x = 0, a pair, three singles
    chain = np.array([[18.0 + i * 1.0, 5.0] for i in range(5)]) % box
    pair = np.array([[10.0, 10.0], [10.0, 11.05]])
    singles = np.array([[3.0, 15.0], [15.0, 15.0], [10.0, 18.0]])
    pos = np.vstack([chain, pair, singles])
    labels = cl.cluster_labels(pos, box)
    sizes = cl.cluster_sizes(labels)
    assert list(sizes) == [5, 2, 1, 1, 1]
    assert np.all(labels[:5] == 0) and np.all(labels[5:7] == 1)
    size, count = cl.cluster_size_distribution(sizes)
    assert list(size) == [1, 2, 5] and list(count) == [3, 1, 1]
    assert cl.largest_cluster_fraction(pos, box) == pytest.approx(0.5)


def test_contact_factor_and_polydisperse_radii():
    box = np.full(3, 10.0)
    pos = np.array([[1.0, 1.0, 1.0], [2.2, 1.0, 1.0], [9.5, 9.5, 9.5], [0.45, 9.5, 9.5]])
    # distance 1.2: bonded only if factor * (r_i + r_j) > 1.2
    assert cl.cluster_sizes(cl.cluster_labels(pos, box, factor=1.1))[0] == 2  # the wrapped pair (0.95 apart)
    assert list(cl.cluster_sizes(cl.cluster_labels(pos, box, factor=1.25))) == [2, 2]
    radii = np.array([0.5, 0.75, 0.5, 0.5])  # contact 1.25 > 1.2
    assert list(cl.cluster_sizes(cl.cluster_labels(pos, box, radii=radii, factor=1.0))) == [2, 2]
    assert list(cl.cluster_sizes(cl.cluster_labels(pos, box, cutoff=1.3))) == [2, 2]


def test_dense_block_is_one_cluster_dilute_gas_is_not():
    rng = np.random.default_rng(1)
    box = np.full(2, 100.0)
    g = np.arange(20) * 1.0
    block = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2) + 40
    assert cl.largest_cluster_fraction(block, box) == 1.0
    gas = rng.uniform(0, 100, (400, 2))
    assert cl.largest_cluster_fraction(gas, box) < 0.05
