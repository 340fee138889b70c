"""Velocity moments: temperature and Sonine coefficients of a particle sample."""

import numpy as np
import pytest

from granulargas.analysis.cooling import temperature as numpy_temperature
from granulargas.observables import (
    energy_moments,
    finite_sample_sonine,
    sonine_a2,
    sonine_a3,
    sonine_coefficients,
)


def numpy_sonine(v, m=None):
    """The estimator written out with numpy: x = m c^2 / (2T), a2 = 4<x^2>/(d(d+2)) - 1,
    a3 = 1 + 3 a2 - 8<x^3>/(d(d+2)(d+4))."""
    v = np.asarray(v, dtype=float)
    n, d = v.shape
    m = np.ones(n) if m is None else np.asarray(m, dtype=float)
    c = v - (m[:, None] * v).sum(axis=0) / m.sum()
    e = m * (c * c).sum(axis=1)
    x = e / (2 * e.mean() / d)
    a2 = 4 * np.mean(x**2) / (d * (d + 2)) - 1
    return a2, 1 + 3 * a2 - 8 * np.mean(x**3) / (d * (d + 2) * (d + 4))


@pytest.mark.parametrize("dim", [2, 3])
def test_matches_the_numpy_estimators(dim):
    rng = np.random.default_rng(0)
    v = rng.standard_exponential((1000, dim)) * rng.choice([-1, 1], (1000, dim)) + 0.3
    m = rng.uniform(0.5, 2.0, 1000)
    a2, a3 = sonine_coefficients(v, m)
    b2, b3 = numpy_sonine(v, m)
    assert a2 == pytest.approx(b2, rel=1e-12) and a3 == pytest.approx(b3, rel=1e-12)
    t, c2, c3 = energy_moments(np.ascontiguousarray(v), dim, m)
    assert t == pytest.approx(numpy_temperature(v, m), rel=1e-12)
    # padded rows: only the first d columns count
    padded = np.zeros((1000, 4))
    padded[:, :dim] = v
    padded[:, dim:] = 99.0
    assert energy_moments(padded, dim, m)[1] == pytest.approx(a2, rel=1e-12)
    assert sonine_a2(v) == pytest.approx(numpy_sonine(v)[0], rel=1e-12)
    assert sonine_a3(v) == pytest.approx(numpy_sonine(v)[1], rel=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_equal_speeds(dim):
    """All peculiar speeds equal: <c^4> = <c^2>^2, so a2 = -2/(d+2), a3 = 1 + 3 a2 - d^2/((d+2)(d+4))."""
    v = np.concatenate([np.eye(dim), -np.eye(dim)]) * 2.5 + 7.0
    a2, a3 = sonine_coefficients(v)
    assert a2 == pytest.approx(-2 / (dim + 2), abs=1e-14)
    assert a3 == pytest.approx(1 + 3 * a2 - dim**2 / ((dim + 2) * (dim + 4)), abs=1e-14)


@pytest.mark.parametrize("dim", [2, 3])
def test_finite_sample_values(dim):
    """Gaussian samples normalised onto their energy-momentum shell are uniform on it:
    their mean a2, a3 equal the exact finite-N values."""
    rng = np.random.default_rng(1)
    n, reps = 20, 40000
    a2 = np.empty(reps)
    a3 = np.empty(reps)
    for r in range(reps):
        v = rng.standard_normal((n, dim))
        a2[r], a3[r] = sonine_coefficients(v)
    e2, e3 = finite_sample_sonine(n, dim)
    assert abs(a2.mean() - e2) < 4 * a2.std() / np.sqrt(reps)
    assert abs(a3.mean() - e3) < 4 * a3.std() / np.sqrt(reps)
    assert e2 < -8 * a2.std() / np.sqrt(reps)  # the bias is resolved


def test_bad_shapes():
    with pytest.raises(ValueError):
        sonine_coefficients(np.zeros((5, 4)))
    with pytest.raises(ValueError):
        sonine_coefficients(np.zeros((5, 3)), np.ones(4))
    assert np.isnan(sonine_a2(np.zeros((5, 3))))


def test_scale_invariance_far_from_unit_speeds():
    rng = np.random.default_rng(4)
    v = rng.standard_normal((500, 3)) + 0.2
    a2, a3 = sonine_coefficients(v)
    t = energy_moments(np.ascontiguousarray(v), 3, np.ones(1))[0]
    for scale in (1e-150, 1e-100, 1e100, 1e140):
        t_s, b2, b3 = energy_moments(np.ascontiguousarray(v * scale), 3, np.ones(1))
        assert t_s == pytest.approx(t * scale**2, rel=1e-12)
        assert b2 == pytest.approx(a2, rel=1e-12) and b3 == pytest.approx(a3, rel=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_kinetic_energy_and_momentum(dim):
    from granulargas.observables import kinetic_energy_momentum

    rng = np.random.default_rng(5)
    v = rng.standard_normal((300, dim))
    m = rng.uniform(0.5, 2, 300)
    e, *p = kinetic_energy_momentum(v, dim, m)
    assert e == pytest.approx(0.5 * np.sum(m[:, None] * v * v), rel=1e-12)
    assert np.allclose(p[:dim], (m[:, None] * v).sum(axis=0), rtol=1e-12, atol=1e-12)
    e1 = kinetic_energy_momentum(v, dim, np.array([2.0]))[0]
    assert e1 == pytest.approx(np.sum(v * v), rel=1e-12)


def test_sample_history_runs_and_samples_either_method():
    from granulargas.dsmc import DSMC
    from granulargas.engine import CollisionRule, Simulation
    from granulargas.initial import random_state
    from granulargas.observables import sample_history

    st = random_state(200, 0.1, 3, seed=4)
    rule = CollisionRule.constant(0.8)
    times = np.array([0.5, 1.0, 2.0])
    for sim in (Simulation(st, rule),
                DSMC(st, rule, seed=1)):
        h = sample_history(sim, times)
        assert sim.time == 2.0 and h[-1, 2] == sim.collisions
        c = sim.velocities - sim.velocities.mean(axis=0)
        assert h[-1, 0] == pytest.approx(np.mean(np.sum(c * c, axis=1)) / 3, rel=1e-12)
        assert h[-1, 1] == pytest.approx(sonine_coefficients(sim.velocities)[0], rel=1e-12)
        assert np.all(np.diff(h[:, 0]) < 0) and np.all(np.diff(h[:, 2]) > 0)  # a cooling gas


# ---------------------------------------------------------------- rough particles


def _direct_rough(v, w, m, inertia, dim):
    c = v - (m[:, None] * v).sum(0) / m.sum()
    x = m * np.sum(c**2, 1)
    y = inertia * np.sum(w**2, 1)
    dr = 3 if dim == 3 else 1
    return (x.mean() / dim, y.mean() / dr, dim / (dim + 2) * np.mean(x**2) / x.mean() ** 2 - 1,
            dr / (dr + 2) * np.mean(y**2) / y.mean() ** 2 - 1, np.mean(x * y) / (x.mean() * y.mean()) - 1)


@pytest.mark.parametrize("dim", [2, 3])
def test_rough_moments_are_the_definitions(dim):
    from granulargas.observables import rotational_observables, sonine_a2

    rng = np.random.default_rng(4)
    n = 500
    v = rng.normal(size=(n, dim)) * rng.uniform(0.5, 2.0, (n, 1))  # correlated with the spins below
    w = rng.normal(size=(n, 3 if dim == 3 else 1)) * np.linalg.norm(v, axis=1)[:, None]
    m = rng.uniform(0.5, 2.0, n)
    inertia = 0.4 * m * rng.uniform(0.3, 0.6, n) ** 2
    out = rotational_observables(v, w, m, inertia)
    expected = _direct_rough(v, w, m, inertia, dim)
    names = ("temperature", "rotational_temperature", "cumulant_a20", "cumulant_a02", "cumulant_a11")
    for name, e in zip(names, expected):
        assert out[name] == pytest.approx(e, rel=1e-12, abs=1e-14)
    assert out["cumulant_a11"] > 0.1  # the spins grow with the speeds
    assert out["cumulant_a20"] == pytest.approx(sonine_a2(v, m), rel=1e-12)
    # 2D spins may come as (N, 3) with the z spin last
    if dim == 2:
        w3 = np.zeros((n, 3))
        w3[:, 2] = w[:, 0]
        assert rotational_observables(v, w3, m, inertia) == out
    # scale-free: units of velocity and spin drop out of the cumulants
    scaled = rotational_observables(v * 1e-80, w * 1e90, m, inertia)
    for name in names[2:]:
        assert scaled[name] == pytest.approx(out[name], rel=1e-10)
    assert scaled["rotational_temperature"] == pytest.approx(out["rotational_temperature"] * 1e180, rel=1e-12)


def test_rough_moments_of_a_maxwellian_vanish():
    from granulargas.observables import rotational_observables

    rng = np.random.default_rng(5)
    n = 200_000
    out = rotational_observables(rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) * 3.0, None, 0.1)
    assert out["temperature"] == pytest.approx(1.0, rel=0.01)
    assert out["rotational_temperature"] == pytest.approx(0.9, rel=0.01)
    for name in ("cumulant_a20", "cumulant_a02", "cumulant_a11"):
        assert abs(out[name]) < 0.02
    still = rotational_observables(rng.normal(size=(10, 3)), np.zeros((10, 3)), None, 0.1)
    assert still["rotational_temperature"] == 0.0 and np.isnan(still["cumulant_a02"])
