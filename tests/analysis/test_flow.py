"""Velocity field, vorticity and energy spectrum against analytic flows."""

import math

import numpy as np
import pytest

from granulargas.analysis import flow as fl


def _grid_particles(L, n, dim):
    g = (np.arange(n) + 0.5) * L / n
    return np.stack(np.meshgrid(*[g] * dim, indexing="ij"), -1).reshape(-1, dim)


def test_shear_wave_vorticity_and_spectrum_2d():
    L, n = 30.0, 32
    pos = _grid_particles(L, n, 2)
    k = 2 * math.pi / L
    U = 0.3
    v = np.zeros_like(pos)
    v[:, 0] = U * np.sin(k * pos[:, 1])  # shear mode u_x(y)
    u, mass = fl.velocity_field(pos, v, [L, L], n)
    np.testing.assert_allclose(u[..., 0], np.broadcast_to(U * np.sin(k * ((np.arange(n) + 0.5) * L / n)), (n, n)), atol=1e-12)
    w = fl.vorticity(u, [L, L])
    y = (np.arange(n) + 0.5) * L / n
    np.testing.assert_allclose(w, -U * k * np.cos(k * y)[None, :] * np.ones((n, 1)), atol=1e-10)
    kk, E = fl.energy_spectrum(u, [L, L])
    assert kk[np.argmax(E)] == pytest.approx(k)
    assert E.sum() == pytest.approx(0.5 * np.mean(np.sum(u**2, axis=-1)))
    assert E[0] == pytest.approx(U**2 / 4)


def test_vorticity_3d_rigid_rotation_like_mode():
    L, n = 10.0, 16
    pos = _grid_particles(L, n, 3)
    k = 2 * math.pi / L
    v = np.zeros_like(pos)
    v[:, 1] = np.sin(k * pos[:, 2])  # u_y(z): curl = (-d_z u_y, 0, 0)
    u, _ = fl.velocity_field(pos, v, [L] * 3, n)
    w = fl.vorticity(u, [L] * 3)
    z = (np.arange(n) + 0.5) * L / n
    np.testing.assert_allclose(w[..., 0], -k * np.cos(k * z)[None, None, :] * np.ones((n, n, 1)), atol=1e-10)
    np.testing.assert_allclose(w[..., 1:], 0, atol=1e-10)


def test_velocity_field_is_mass_weighted_and_removes_drift():
    pos = np.array([[0.1, 0.1], [0.2, 0.2], [1.5, 1.5]])
    v = np.array([[1.0, 0.0], [4.0, 0.0], [0.0, 0.0]])
    m = np.array([3.0, 1.0, 1.0])
    u, mass = fl.velocity_field(pos, v, [2.0, 2.0], 2, masses=m, remove_mean=False)
    assert u[0, 0, 0] == pytest.approx(7.0 / 4.0) and mass[0, 0] == 4.0 and u[0, 1, 0] == 0.0
    u2, _ = fl.velocity_field(pos, v, [2.0, 2.0], 2, masses=m)
    assert u2[0, 0, 0] == pytest.approx(7.0 / 4.0 - 7.0 / 5.0)
