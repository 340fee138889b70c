"""Velocity-distribution analysis: normalisation, Sonine forms, tail fits, theory constants."""

import math

import numpy as np
import pytest
from scipy import integrate

from granulargas import theory
from granulargas.analysis import velocity as vd


def _sphere(dim):
    return 2 * math.pi ** (dim / 2) / math.gamma(dim / 2)


@pytest.mark.parametrize("dim", [2, 3])
def test_histogram_of_a_maxwellian(dim):
    rng = np.random.default_rng(0)
    hist = vd.SpeedHistogram(dim, c_max=5.0, bins=50)
    for _ in range(5):
        hist.add(rng.standard_normal((200_000, dim)) * 3.0 + 1.0)
    c, f, err = hist.density()
    # normalised: sum over shells of f dV = fraction below c_max
    assert np.sum(f * hist.shell_volumes) == pytest.approx(1 - hist.overflow / hist.samples, rel=1e-12)
    # the d-dimensional density of scaled velocities is the Maxwellian pi^(-d/2) exp(-c^2)
    # (shell averages: compare with the shell average of the Maxwellian)
    edges = hist.edges
    exact = np.array([integrate.quad(lambda x: _sphere(dim) * x ** (dim - 1) * vd.maxwellian(x, dim), a, b)[0]
                      for a, b in zip(edges[:-1], edges[1:])]) / hist.shell_volumes
    ok = hist.counts > 400
    z = (f[ok] - exact[ok]) / err[ok]
    assert np.max(np.abs(z)) < 5 and abs(z.mean()) < 1
    a2, a2e, a3, a3e = hist.sonine()
    assert abs(a2) < 5 * a2e and abs(a3) < 5 * a3e


@pytest.mark.parametrize("dim", [2, 3])
def test_sonine_density_normalised_with_the_right_moments(dim):
    a2, a3 = 0.12, -0.05

    def moment(p):
        return integrate.quad(lambda c: _sphere(dim) * c ** (dim - 1 + p) * vd.sonine_density(c, dim, a2, a3),
                              0, 12)[0]

    def maxwell_moment(p):
        return integrate.quad(lambda c: _sphere(dim) * c ** (dim - 1 + p) * vd.maxwellian(c, dim), 0, 12)[0]

    assert moment(0) == pytest.approx(1.0, abs=1e-10)
    assert moment(2) == pytest.approx(dim / 2, rel=1e-10)
    assert moment(4) / maxwell_moment(4) == pytest.approx(1 + a2, rel=1e-10)
    assert moment(6) / maxwell_moment(6) == pytest.approx(1 + 3 * a2 - a3, rel=1e-10)


@pytest.mark.parametrize("dim", [2, 3])
def test_tail_fit_recovers_an_exponential(dim):
    """Speeds with the d-dimensional density exp(-A c) follow a Gamma(d, 1/A) law."""
    a_true = 3.7
    estimates, errors = [], []
    for seed in range(6):
        rng = np.random.default_rng(seed)
        hist = vd.SpeedHistogram(dim, c_max=8.0, bins=160)
        speeds = rng.gamma(dim, 1.0 / a_true, 400_000)
        hist.counts += np.histogram(speeds, bins=hist.edges)[0]
        hist.samples += speeds.size
        fit = vd.fit_exponential_tail(hist, 1.0, 4.0)
        estimates.append(fit.A)
        errors.append(fit.A_err)
        assert fit.deviance_per_bin < 2.0
        assert fit(2.0) == pytest.approx(fit.B * math.exp(-2 * fit.A))
    estimates, errors = np.array(estimates), np.array(errors)
    assert np.all(np.abs(estimates - a_true) < 4 * errors)
    # the error bar is the scatter between samples
    assert 0.4 < estimates.std(ddof=1) / errors.mean() < 2.5
    cl, slope, err = vd.local_slope(hist)
    sel = (cl > 1.0) & (cl < 3.0)
    assert np.all(np.abs(slope[sel] - a_true) < 5 * err[sel])


def test_tail_fit_refuses_an_empty_window():
    hist = vd.SpeedHistogram(3)
    with pytest.raises(ValueError, match="too few"):
        vd.fit_exponential_tail(hist, 5.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_reduced_cooling_rate_and_tail_constant(dim):
    eps, n, chi, a2 = 0.6, 0.2, 1.3, 0.05
    zeta_star = vd.sonine_cooling_rate(eps, dim, a2)
    # zeta* chi n v_T is the Enskog cooling rate of the theory module
    temp = 2.0
    zeta = theory.enskog_cooling_rate(eps, n, temp, dim, chi=chi, a2=a2)
    assert zeta_star * chi * n * math.sqrt(2 * temp) == pytest.approx(zeta, rel=1e-12)
    assert vd.omega_reduced(dim) * chi * n * math.sqrt(2 * temp) == pytest.approx(
        theory.collision_frequency(n, temp, dim, chi=chi), rel=1e-12)
    # Haff's law with this zeta* gives it back
    tau0 = theory.haff_tau0(eps, n, temp, dim, chi=chi, a2=a2)
    t = np.linspace(0, 10 * tau0, 30)
    measured, err = vd.reduced_cooling_rate(t, theory.haff_temperature(t, temp, tau0), n, chi, dim)
    assert measured == pytest.approx(zeta_star, rel=1e-9)
    b_d = math.pi if dim == 3 else 2.0
    assert vd.tail_constant(zeta_star, dim) == pytest.approx(2 * b_d / zeta_star)


def test_plot_writes_a_figure(tmp_path):
    rng = np.random.default_rng(1)
    panels = []
    for dim in (2, 3):
        hist = vd.SpeedHistogram(dim, c_max=6.0, bins=120)
        for _ in range(3):
            hist.add(rng.standard_normal((20000, dim)))
        panels.append(dict(hist=hist, fit=vd.fit_exponential_tail(hist, 1.5, 3.0), a2_theory=0.01,
                           A_theory={"test": 3.0}, label=f"{dim}D"))
    path = tmp_path / "f.png"
    vd.plot_velocity_distribution(panels, path, title="test")
    assert path.stat().st_size > 10_000
