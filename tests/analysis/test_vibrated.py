"""Profiles along an axis, the centre of mass and the energy balance of a vibrated gas, on
synthetic samples with known answers."""

import math

import numpy as np
import pytest

from granulargas.analysis.vibrated import (GAUSSIAN_TAIL_2, LayerAccumulator, LayerDistributionAccumulator,
                                          barometric_height, centre_of_mass, centre_of_mass_height,
                                          distribution_edges, energy_balance)


def test_layer_profiles_of_a_known_gas():
    """Uniform density in a 4 x 6 x 10 box, T(z) = 1 + z / 10 along z with the mean velocity 0.3
    in x (not counted in T), Gaussian velocities: density, T, the anisotropy and zero excess
    kurtosis within their errors."""
    rng = np.random.default_rng(0)
    box = np.array([4.0, 6.0, 10.0])
    acc = LayerAccumulator(2, np.linspace(0, 10, 6), box)
    frames, n, m = 40, 3000, 2.0
    for _ in range(frames):
        r = rng.uniform(0, 1, size=(n, 3)) * box
        temp = 1.0 + r[:, 2] / 10.0
        v = rng.normal(size=(n, 3)) * np.sqrt(temp / m)[:, None]
        v[:, 0] += 0.3
        acc.add(r, v, m)
    p = acc.profile()
    np.testing.assert_allclose(p.density, n / box.prod(), rtol=0.03)
    expected = 1.0 + p.centres / 10.0
    np.testing.assert_allclose(p.temperature, expected, rtol=0.03)
    np.testing.assert_allclose(p.t_along, expected, rtol=0.05)
    np.testing.assert_allclose(p.t_across, expected, rtol=0.05)
    # a mixture of temperatures within a layer is slightly non-Gaussian; the layers are thin
    assert np.all(np.abs(p.kurtosis) < 5 * p.kurtosis_error[:, None] + 0.02)
    assert p.frames == frames and p.counts.sum() == frames * n


def test_kurtosis_sees_a_non_maxwellian_layer():
    rng = np.random.default_rng(1)
    acc = LayerAccumulator(1, [0.0, 1.0], np.array([1.0, 1.0]))
    v = rng.laplace(size=(400_000, 2))  # excess kurtosis 3
    acc.add(rng.uniform(size=(400_000, 2)), v, 1.0)
    assert acc.profile().kurtosis[0] == pytest.approx([3.0, 3.0], abs=0.3)


def test_centre_of_mass():
    pos = np.array([[0.0, 1.0], [0.0, 3.0]])
    assert centre_of_mass(pos, [1.0, 3.0], 1) == pytest.approx(2.5)


def test_energy_balance_of_a_steady_state():
    t = np.linspace(0, 100, 1001)
    rng = np.random.default_rng(2)
    work = 0.7 * t + rng.normal(scale=0.05, size=t.size)
    lost = 0.7 * t - 3.0 + rng.normal(scale=0.05, size=t.size)
    b = energy_balance(t, work, lost)
    assert b.power_in == pytest.approx(0.7, rel=0.01) and b.dissipation == pytest.approx(0.7, rel=0.01)
    assert abs(b.ratio - 1.0) < 4 * b.ratio_error
    assert b.t_from == 50.0
    b2 = energy_balance(t, work, 0.5 * lost)
    assert abs(b2.ratio - 0.5) < 4 * b2.ratio_error and abs(b2.ratio - 1.0) > 10 * b2.ratio_error
    assert math.isnan(energy_balance(t[:2], work[:2], lost[:2]).power_in)


def _layered_gas(rng, frames, n, box, axis, t_along, t_across, mass=1.0, drift=0.0, laplace_layer=None):
    """Snapshots of a gas in layers of equal thickness along ``axis``, Maxwellian in each with
    the layer's temperature along (t_along[i]) and across (t_across[i]) the axis."""
    layers = len(t_along)
    d = box.size
    for _ in range(frames):
        r = rng.uniform(0, 1, size=(n, d)) * box
        k = np.minimum((r[:, axis] / box[axis] * layers).astype(int), layers - 1)
        scale = np.empty((n, d))
        scale[:] = np.sqrt(np.asarray(t_across)[k] / mass)[:, None]
        scale[:, axis] = np.sqrt(np.asarray(t_along)[k] / mass)
        v = rng.normal(size=(n, d)) * scale
        if laplace_layer is not None:
            sel = k == laplace_layer
            v[sel] = rng.laplace(size=(sel.sum(), d)) * scale[sel] / math.sqrt(2.0)
        v[:, 0 if axis else 1] += drift
        yield r, v


def _distributions(gas, axis, edges, box, mass):
    frames = list(gas)
    acc = LayerAccumulator(axis, edges, box)
    for r, v in frames:
        acc.add(r, v, mass)
    groups = [np.arange(i, i + 1) for i in range(len(edges) - 1)]
    dacc = LayerDistributionAccumulator(axis, edges, *acc.moments(groups))
    for r, v in frames:
        dacc.add(r, v, mass)
    return dacc.distributions()


def test_velocity_distribution_of_maxwellian_layers():
    """Three layers along y in 3D, each Maxwellian at its own temperatures along and across
    (anisotropic, a drift across): the scaled histograms follow the unit Gaussian (chi^2 with
    the counts' Poisson errors), the excess kurtosis is 0 within its error, its block error
    is that of independent samples, sqrt(24 / n), and the tail weight P(|c| > 2) is the
    Gaussian's."""
    rng = np.random.default_rng(3)
    box = np.array([5.0, 9.0, 4.0])
    t_al, t_ac, mass = [3.0, 1.5, 0.5], [2.0, 1.0, 0.8], 2.0
    dist = _distributions(_layered_gas(rng, 40, 6000, box, 1, t_al, t_ac, mass, drift=0.7), 1,
                          [0.0, 3.0, 6.0, 9.0], box, mass)
    np.testing.assert_allclose(dist.temperature, np.stack([t_al, t_ac], axis=1), rtol=0.02)
    assert dist.counts[:, 1].sum() == 2 * dist.counts[:, 0].sum() == 2 * 40 * 6000
    assert np.all(np.abs(dist.kurtosis) < 4 * dist.kurtosis_error)
    np.testing.assert_allclose(dist.kurtosis_error, np.sqrt(24.0 / dist.counts), rtol=0.6)
    np.testing.assert_allclose(dist.a2, dist.kurtosis / 3.0)
    width = np.diff(dist.bins)
    for i in range(3):
        for j, hist in enumerate((dist.along, dist.across)):
            n = dist.counts[i, j]
            counts = hist[i] * n * width
            # the unit Gaussian's probability per bin, exactly
            cdf = np.array([0.5 * math.erfc(-x / math.sqrt(2.0)) for x in dist.bins])
            expected = n * np.diff(cdf)
            use = expected > 20
            chi2 = float(np.sum((counts[use] - expected[use]) ** 2 / expected[use]))
            dof = int(use.sum())
            assert chi2 < dof + 5 * math.sqrt(2 * dof), (i, j, chi2, dof)
            assert abs(dist.tail[i, j] - GAUSSIAN_TAIL_2) < 4 * math.sqrt(GAUSSIAN_TAIL_2 / n)
    np.testing.assert_allclose(dist.gaussian, np.exp(-0.5 * dist.centres**2) / math.sqrt(2 * math.pi))


def test_velocity_distribution_sees_a_non_maxwellian_layer():
    """The middle layer has Laplace velocities (excess kurtosis 3 per component, a2 = 1): its
    kurtosis and its histogram say so; the other layers stay Gaussian."""
    rng = np.random.default_rng(4)
    box = np.array([6.0, 3.0])
    dist = _distributions(_layered_gas(rng, 20, 6000, box, 1, [1.0] * 3, [1.0] * 3, laplace_layer=1), 1,
                          [0.0, 1.0, 2.0, 3.0], box, 1.0)
    assert dist.kurtosis[1] == pytest.approx([3.0, 3.0], abs=0.4)
    assert dist.a2[1] == pytest.approx([1.0, 1.0], abs=0.15)
    assert np.all(np.abs(dist.kurtosis[[0, 2]]) < 4 * dist.kurtosis_error[[0, 2]])
    centre = np.argmin(np.abs(dist.centres))
    assert dist.along[1][centre] > 1.3 * dist.gaussian[centre]  # the Laplace peak: 1/sqrt(2) = 0.71 against 0.40


def test_distribution_layers_hold_equal_shares_of_the_samples():
    rng = np.random.default_rng(5)
    box = np.array([2.0, 20.0])
    acc = LayerAccumulator(1, np.linspace(0.0, 20.0, 41), box)
    z = rng.exponential(3.0, size=200_000)
    z = z[z < 15.0]  # the layers above 15 stay empty
    acc.add(np.stack([rng.uniform(0, 2, z.size), z], axis=1), rng.normal(size=(z.size, 2)), 1.0)
    edges = distribution_edges(acc.profile(), 4)
    assert edges[0] == 0.0 and edges[-1] == 15.0 and edges.size == 5
    shares = np.histogram(z, edges)[0] / z.size
    np.testing.assert_allclose(shares, 0.25, atol=0.04)  # cut at the fine edges (0.5 apart)


def test_centre_of_mass_height_of_a_barometric_column():
    """Heights exponential with scale T/(m g) above sigma/2 over a floor at rest position A
    (a vibrating floor): the steady time mean of the centre of mass is A + sigma/2 + T/(m g)
    within its block error; a floor above the gas (gravity up) measures down from it."""
    rng = np.random.default_rng(6)
    T, g, m, sigma, A = 2.5, 0.5, 2.0, 1.0, 0.05
    times = np.arange(400.0)
    coms = [centre_of_mass(np.stack([np.zeros(500), A + sigma / 2 + rng.exponential(T / (m * g), 500)], axis=1),
                           m, 1) for _ in times]
    h, err = centre_of_mass_height(times, coms, floor=A, t_from=0.0)
    expect = barometric_height(T, g, m, sigma)
    assert expect == pytest.approx(sigma / 2 + 2.5)
    assert abs(h - expect) < 4 * err and err < 0.02
    h_down, err_down = centre_of_mass_height(times, 30.0 - np.asarray(coms), floor=30.0 - A, t_from=0.0, up=-1)
    assert h_down == pytest.approx(h) and err_down == pytest.approx(err)
    # the second half by default
    coms2 = np.where(times < 200, 100.0, np.asarray(coms))
    assert centre_of_mass_height(times, coms2, floor=A)[0] == pytest.approx(float(np.mean(coms2[200:])) - A)
