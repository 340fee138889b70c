"""granulargas.analysis.cooling against independent truths."""

import math

import numpy as np
import pytest

from granulargas.analysis import cooling as ac
from granulargas import theory as th


@pytest.mark.parametrize("dim", [2, 3])
def test_temperature_of_maxwellian_with_drift(dim):
    rng = np.random.default_rng(0)
    m = rng.uniform(0.5, 2.0, 50_000)
    T = 1.7
    v = rng.normal(size=(m.size, dim)) * np.sqrt(T / m)[:, None] + 3.0  # drift removed
    assert ac.temperature(v, m) == pytest.approx(T, rel=0.02)


@pytest.mark.parametrize("dim", [2, 3])
def test_maxwellian_sonine_coefficients_vanish_within_sampling_error(dim):
    rng = np.random.default_rng(dim)
    n = 200_000
    a2s, a3s = zip(*(ac.sonine_coefficients(rng.normal(size=(n, dim))) for _ in range(4)))
    se2 = math.sqrt(8.0 / (dim * (dim + 2) * n))  # standard error of a2 for a Maxwellian
    assert abs(np.mean(a2s)) < 4 * se2 / 2
    assert abs(np.mean(a3s)) < 10 * se2  # a3 has a larger variance


def _sample_sonine(dim, a2, a3, n, rng):
    # rejection sampling of x = m c^2 / 2T from Gamma(d/2) weighted by 1 + a2 S2 + a3 S3
    # (x truncated at 25: the Gamma tail beyond carries e^-25 of the mass)
    def weight(x):
        return 1 + a2 * ac.sonine_polynomial(2, x, dim) + a3 * ac.sonine_polynomial(3, x, dim)

    grid = np.linspace(0, 25, 10001)
    assert weight(grid).min() > 0
    w_max = weight(grid).max()
    out = []
    while sum(len(o) for o in out) < n:
        x = rng.gamma(dim / 2, size=4 * n)
        x = x[x < 25]
        keep = rng.uniform(0, w_max, x.size) < weight(x)
        out.append(x[keep])
    x = np.concatenate(out)[:n]
    direction = rng.normal(size=(n, dim))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    return direction * np.sqrt(2 * x)[:, None] / np.sqrt(2)  # T = 1/2 * ... any scale


@pytest.mark.parametrize("dim", [2, 3])
def test_sonine_coefficients_recover_a_known_distribution(dim):
    rng = np.random.default_rng(7)
    a2, a3 = 0.08, -0.03
    v = _sample_sonine(dim, a2, a3, 150_000, rng)
    m2, m3 = ac.sonine_coefficients(v)
    assert m2 == pytest.approx(a2, abs=0.012)
    assert m3 == pytest.approx(a3, abs=0.03)


@pytest.mark.parametrize("dim", [2, 3])
def test_speed_histogram_matches_maxwell(dim):
    rng = np.random.default_rng(3)
    v = rng.normal(size=(200_000, dim))
    u, dens = ac.velocity_distribution(v, bins=40)
    ref = ac.maxwell_sonine_pdf(u, dim, kind="speed")
    assert np.max(np.abs(dens - ref)) < 0.03
    uc, dc = ac.velocity_distribution(v, bins=40, kind="component")
    assert np.max(np.abs(dc - ac.maxwell_sonine_pdf(uc, dim))) < 0.03


def test_speed_pdf_is_normalised_with_sonine_terms():
    from scipy import integrate
    for dim in (2, 3):
        val = integrate.quad(lambda u: ac.maxwell_sonine_pdf(u, dim, 0.1, -0.05, kind="speed"), 0, 12)[0]
        assert val == pytest.approx(1.0, abs=1e-10)


def test_fit_recovers_haff_parameters_from_noisy_data():
    rng = np.random.default_rng(11)
    t = np.concatenate([[0.0], np.geomspace(0.1, 2000, 60)])
    T = th.haff_temperature(t, 1.0, 37.0) * np.exp(rng.normal(0, 0.01, t.size))
    T[0] = 1.0
    fit = ac.fit_cooling_law(t, T)
    assert fit.tau0 == pytest.approx(37.0, rel=0.01)
    assert fit.exponent == 2.0
    free = ac.fit_cooling_law(t, T, exponent=None)
    assert free.exponent == pytest.approx(2.0, abs=0.02)
    assert abs(free.exponent - 2.0) < 4 * free.exponent_err + 1e-3


def test_fit_viscoelastic_law_and_local_exponent():
    t = np.concatenate([[0.0], np.geomspace(1, 1e5, 40)])
    T = th.viscoelastic_temperature(t, 2.0, 120.0)
    fit = ac.fit_cooling_law(t, T, exponent=None)
    assert fit.tau0 == pytest.approx(120.0, rel=1e-6)
    assert fit.exponent == pytest.approx(5 / 3, rel=1e-6)
    tm, slope = ac.local_exponent(t, T, fit.tau0)
    np.testing.assert_allclose(slope, -5 / 3, rtol=1e-6)
    tm, slope0 = ac.local_exponent(t, T)
    assert slope0[-1] == pytest.approx(-5 / 3, abs=0.01) and slope0[2] > -1.0


def test_collisions_per_particle():
    assert ac.collisions_per_particle(500, 1000) == 1.0
