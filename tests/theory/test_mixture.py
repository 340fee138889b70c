"""Granular mixtures in the Maxwellian approximation (Garzó & Dufty 1999) against independent numbers:
the one-component closed forms, a Monte Carlo average of the collision rule itself, and the
contact values of one-size mixtures."""

import math

import numpy as np
import pytest

from granulargas import theory
from granulargas.theory.mixture import (
    driven_temperature_ratios,
    hcs_temperature_ratios,
    mixture_contact_values,
    mixture_cooling_rates,
    temperature_history,
)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("eps", [0.5, 0.9, 1.0])
def test_one_species_is_the_one_component_maxwellian_cooling_rate(d, eps):
    z = mixture_cooling_rates([1.7], [2.0], [1.3], [0.04], eps, dim=d)
    want = theory.enskog_cooling_rate(eps, 0.04, 1.7, dim=d, sigma=1.3, m=2.0, chi=1.0, a2=0.0)
    assert z[0] == pytest.approx(float(want), rel=1e-13)


@pytest.mark.parametrize("d", [2, 3])
def test_identical_species_cool_as_one(d):
    # two labels for one kind of particle: each cools at the rate of the whole gas
    z = mixture_cooling_rates([1.0, 1.0], [1.0, 1.0], [1.0, 1.0], [0.03, 0.01], 0.8, dim=d)
    one = mixture_cooling_rates([1.0], [1.0], [1.0], [0.04], 0.8, dim=d)
    assert z == pytest.approx([one[0], one[0]], rel=1e-13)


def _monte_carlo_cooling(d, temp, m, sigma, n, alpha, samples, rng, chunk=250_000):
    """zeta_i by sampling the collision rule: Maxwellian velocities, unit normals uniform on the
    sphere, each pair weighted by the collision kernel Theta(-g.k)|g.k| (k from j to i); the
    energy species i loses per unit volume and time is n_i n_j chi sigma_ij^(d-1) Omega_d
    E[Theta |g.k| (-Delta E_i)] (Omega_d the sphere's solid angle). ``alpha(i, j, u)`` gives
    the restitution at normal speeds u."""
    S = len(m)
    omega_d = 2.0 * math.pi ** (d / 2.0) / math.gamma(d / 2.0)
    zeta = np.zeros(S)
    for i in range(S):
        for j in range(S):
            total = 0.0
            for _ in range(samples // chunk):
                vi = rng.normal(0.0, math.sqrt(temp[i] / m[i]), (chunk, d))
                vj = rng.normal(0.0, math.sqrt(temp[j] / m[j]), (chunk, d))
                k = rng.normal(size=(chunk, d))
                k /= np.linalg.norm(k, axis=1)[:, None]
                gn = np.einsum("ij,ij->i", vi - vj, k)
                a = alpha(i, j, np.abs(gn))
                # the collision rule (2) of engine._collide, applied to particle i
                vi_new = vi - ((1.0 + a) * m[j] / (m[i] + m[j]) * gn)[:, None] * k
                de = 0.5 * m[i] * (np.sum(vi_new**2, axis=1) - np.sum(vi**2, axis=1))
                total += float(np.sum(np.where(gn < 0.0, -gn * de, 0.0)))
            sij = 0.5 * (sigma[i] + sigma[j])
            zeta[i] += -n[j] * sij ** (d - 1) * omega_d * total / samples * 2.0 / (d * temp[i])
    return zeta


# Monte Carlo: 2e6 pairs per species pair give a standard error of about 0.5 % of the larger
# |zeta_i| (measured over 30 seeds); the tolerance is four times that.
MC_SAMPLES, MC_TOLERANCE = 2_000_000, 0.02


@pytest.mark.parametrize("d", [2, 3])
def test_cooling_rates_are_the_collision_rule_averaged_over_maxwellians(d):
    """(M1) against a direct Monte Carlo average of the collision rule (no formula shared):
    unequal masses, sizes, temperatures and a restitution per pair."""
    rng = np.random.default_rng(7)
    temp, m, sigma, n = [1.6, 0.5], [3.0, 1.0], [1.4, 0.8], [0.05, 0.02]
    alpha = np.array([[0.7, 0.85], [0.85, 0.95]])
    mc = _monte_carlo_cooling(d, temp, m, sigma, n, lambda i, j, u: alpha[i, j], MC_SAMPLES, rng)
    z = mixture_cooling_rates(temp, m, sigma, n, alpha, dim=d)
    # species 2 is heated by the hot heavy one (zeta_2 < 0): both signs are checked
    assert z[1] < 0.0 < z[0]
    assert np.abs(mc - z).max() < MC_TOLERANCE * np.abs(z).max()


def test_impact_speed_dependent_restitution_by_quadrature():
    temp, m, sigma, n = [1.2, 0.9], [2.0, 1.0], [1.0, 1.5], [0.02, 0.03]
    alpha = np.array([[0.8, 0.7], [0.7, 0.9]])
    closed = mixture_cooling_rates(temp, m, sigma, n, alpha)
    quad = mixture_cooling_rates(temp, m, sigma, n, lambda i, j, u: np.full_like(u, alpha[i, j]))
    assert quad == pytest.approx(closed, rel=1e-12)
    # a restitution falling with the impact speed: the Monte Carlo average of the rule agrees
    law = lambda i, j, u: 1.0 - 0.3 * np.minimum(u, 2.0) / 2.0  # noqa: E731
    q = mixture_cooling_rates(temp, m, sigma, n, law)
    mc = _monte_carlo_cooling(3, temp, m, sigma, n, law, MC_SAMPLES, np.random.default_rng(3))
    assert np.abs(mc - q).max() < MC_TOLERANCE * np.abs(q).max()


@pytest.mark.parametrize("mass_ratio, size_ratio, eps, x1, ratio", [
    # Garzó & Dufty (1999), dilute 3D, from their eqs. (3.3) and (A5) with a2 = 0
    (2.0, 1.0, 0.9, 0.5, 1.060), (4.0, 1.0, 0.8, 0.5, 1.341), (10.0, 1.0, 0.8, 0.5, 2.059),
    (8.0, 2.0, 0.8, 0.5, 1.382), (1.0, 2.0, 0.8, 0.5, 0.870), (5.0, 1.0, 0.7, 0.2, 1.902),
])
def test_hcs_temperature_ratios(mass_ratio, size_ratio, eps, x1, ratio):
    r = hcs_temperature_ratios([mass_ratio, 1.0], [size_ratio, 1.0], [x1, 1.0 - x1], eps)
    assert r[0] / r[1] == pytest.approx(ratio, abs=6e-4)
    assert x1 * r[0] + (1.0 - x1) * r[1] == pytest.approx(1.0, rel=1e-12)
    # and the species then cool at one rate
    z = mixture_cooling_rates(r, [mass_ratio, 1.0], [size_ratio, 1.0], [x1, 1.0 - x1], eps)
    assert z[0] == pytest.approx(z[1], rel=1e-12)


def test_hcs_equipartition_limits():
    # elastic collisions: equipartition whatever the masses; identical species: equal temperatures
    r = hcs_temperature_ratios([5.0, 1.0], [2.0, 1.0], [0.3, 0.7], 1.0 - 1e-12)
    assert r[0] / r[1] == pytest.approx(1.0, abs=1e-9)
    r = hcs_temperature_ratios([1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.2, 0.3, 0.5], 0.6)
    assert r == pytest.approx([1.0, 1.0, 1.0], rel=1e-10)


def test_three_species_cool_at_one_rate():
    m, s, x = [4.0, 2.0, 1.0], [1.2, 1.0, 0.9], [0.3, 0.3, 0.4]
    alpha = np.array([[0.7, 0.8, 0.9], [0.8, 0.85, 0.8], [0.9, 0.8, 0.75]])
    r = hcs_temperature_ratios(m, s, x, alpha)
    z = mixture_cooling_rates(r, m, s, x, alpha)
    assert z == pytest.approx(np.full(3, z[0]), rel=1e-9)


def test_enskog_ratios_use_the_mixture_contact_values():
    m, s, x = [4.0, 1.0], [2.0, 1.0], [0.5, 0.5]
    dilute = hcs_temperature_ratios(m, s, x, 0.8)
    dense = hcs_temperature_ratios(m, s, x, 0.8, packing=0.3)
    n = np.array(x) * 0.3 / float(np.sum(np.array(x) * theory.particle_volume(np.array(s), 3)))
    chi = mixture_contact_values(s, n, 3)
    z = mixture_cooling_rates(dense, m, s, n, 0.8, chi=chi)
    assert z[0] == pytest.approx(z[1], rel=1e-10)
    assert abs(dense[0] / dense[1] - dilute[0] / dilute[1]) > 1e-3


@pytest.mark.parametrize("d, form", [(3, "closed"), (2, "closed")])
def test_one_size_contact_values_are_the_one_component_ones(d, form):
    s = [1.0, 1.0]
    n = np.array([0.2, 0.35]) * (6.0 / math.pi if d == 3 else 4.0 / math.pi)
    chi = mixture_contact_values(s, n, d)
    want = theory.contact_value(0.55, d, form=form)
    assert chi == pytest.approx(np.full((2, 2), want), rel=1e-13)


def test_bghlm_small_sphere_limit():
    # a vanishing amount of big spheres in small ones: chi of two small spheres is that of the
    # pure small-sphere fluid (Carnahan-Starling); the big-small pair grows with the size ratio
    eta = 0.3
    n_small = eta / theory.particle_volume(1.0, 3)
    chi = mixture_contact_values([1.0, 3.0], [n_small, 1e-12], 3)
    assert chi[0, 0] == pytest.approx(theory.contact_value(eta, 3, form="closed"), rel=1e-9)
    assert chi[0, 1] > chi[0, 0] and chi[1, 1] > chi[0, 1]


def test_driven_ratios_follow_the_noise():
    m, s, x = [4.0, 1.0], [1.0, 1.0], [0.5, 0.5]
    for noise in ("equal_heating", "equal_acceleration", "equal_force"):
        r = driven_temperature_ratios(m, s, x, 0.8, noise=noise)
        z = mixture_cooling_rates(r, m, s, x, 0.8)
        q = {"equal_acceleration": 0.0, "equal_heating": 1.0, "equal_force": 2.0}[noise]
        balance = z * r / np.asarray(m) ** (1.0 - q)
        assert balance[0] == pytest.approx(balance[1], rel=1e-10)
    acc = driven_temperature_ratios(m, s, x, 0.8, noise="equal_acceleration")
    heat = driven_temperature_ratios(m, s, x, 0.8, noise="equal_heating")
    force = driven_temperature_ratios(m, s, x, 0.8, noise="equal_force")
    # the heavy species gets more of the power the more the noise favours mass
    assert acc[0] / acc[1] > heat[0] / heat[1] > force[0] / force[1]
    with pytest.raises(ValueError, match="equal_heating"):
        driven_temperature_ratios(m, s, x, 0.8, noise="pink")


def test_temperature_history_relaxes_to_the_hcs_ratio():
    m, s, x = [4.0, 1.0], [1.0, 1.0], [0.5, 0.5]
    n = np.array(x) * 0.05
    t = np.array([0.0, 1.0, 10.0, 1e3, 1e5])
    T = temperature_history(t, [1.0, 1.0], m, s, n, 0.8)
    assert T[0] == pytest.approx([1.0, 1.0], rel=1e-12)
    r = hcs_temperature_ratios(m, s, x, 0.8)
    assert T[-1, 0] / T[-1, 1] == pytest.approx(r[0] / r[1], rel=1e-6)
    # late times: Haff's law of the mixture temperature with the HCS cooling rate
    tmix = x[0] * T[:, 0] + x[1] * T[:, 1]
    z_hcs = mixture_cooling_rates(r, m, s, n, 0.8)[0]
    assert tmix[-1] / tmix[-2] == pytest.approx(((1 + z_hcs * 1e3 / 2) / (1 + z_hcs * 1e5 / 2)) ** 2, rel=2e-2)


def test_bad_input():
    with pytest.raises(ValueError, match="add up to 1"):
        hcs_temperature_ratios([1.0, 2.0], [1.0, 1.0], [0.5, 0.6], 0.9)
    with pytest.raises(ValueError, match="symmetric"):
        mixture_cooling_rates([1, 1], [1, 2], [1, 1], [1, 1], np.array([[0.9, 0.8], [0.7, 0.9]]))
    with pytest.raises(ValueError, match="one entry per species"):
        mixture_cooling_rates([1, 1], [1, 2], [1], [1, 1], 0.9)


def test_mixture_record_and_viscoelastic_pairs():
    from granulargas.contact import restitution
    from granulargas.contact.material import pair_constant
    from granulargas.theory.mixture import Mixture

    mix = Mixture(("a", "b"), (4.0, 1.0), (1.0, 1.0), (50, 50), 3, 0.1, restitution=((0.8, 0.8), (0.8, 0.8)))
    assert mix.hcs_ratios() == pytest.approx(hcs_temperature_ratios([4.0, 1.0], [1.0, 1.0], [0.5, 0.5], 0.8),
                                             rel=1e-10)
    assert mix.driven_ratios("equal_force") == pytest.approx(
        driven_temperature_ratios([4.0, 1.0], [1.0, 1.0], [0.5, 0.5], 0.8, noise="equal_force"), rel=1e-10)
    k = ((0.2, 0.3), (0.3, 0.1))
    visco = Mixture(("a", "b"), (4.0, 1.0), (1.2, 0.8), (30, 70), 3, 0.1, prefactor=k)
    law = visco.restitution_law()
    u = np.array([0.1, 1.0, 3.0])
    b = float(pair_constant(0.3, 0.6, 0.4, 4.0, 1.0))
    assert law(0, 1, u) == pytest.approx(restitution(b * u**0.2), rel=1e-7)
    # hotter gas, faster impacts, more inelastic: the ratios move with the temperature
    assert abs(visco.hcs_ratios(1.0)[0] - visco.hcs_ratios(1e-4)[0]) > 1e-3


def test_collision_frequencies_and_predicted_end():
    from granulargas.theory.mixture import Mixture

    # one kind of particle under two names: the Enskog collision frequency and Haff's law
    mix = Mixture(("a", "b"), (1.0, 1.0), (1.0, 1.0), (30, 70), 3, 0.05, restitution=((0.8, 0.8), (0.8, 0.8)))
    nu = mix.collision_frequencies([1.0, 1.0])
    assert nu == pytest.approx([float(theory.collision_frequency(0.05, 1.0, 3, chi=1.0))] * 2, rel=1e-13)
    zeta = float(theory.enskog_cooling_rate(0.8, 0.05, 1.0, 3, chi=1.0, a2=0.0))
    t, T = mix.predicted_end(1.0, end_time=50.0)
    assert t == pytest.approx(50.0, rel=1e-9)
    assert T == pytest.approx([1.0 / (1 + zeta * 50 / 2) ** 2] * 2, rel=1e-6)
    # Haff in collisions: T = exp(-(1 - eps^2) s / d) at a2 = 0
    t, T = mix.predicted_end(1.0, collisions_per_particle=20.0)
    assert T[0] == pytest.approx(math.exp(-(1 - 0.8**2) * 20 / 3), rel=1e-6)
