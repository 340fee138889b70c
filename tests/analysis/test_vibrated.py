"""Profiles along an axis, the centre of mass and the energy balance of a vibrated gas, on
synthetic samples with known answers."""

import math

import numpy as np
import pytest

from granulargas.analysis.vibrated import LayerAccumulator, centre_of_mass, energy_balance


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
