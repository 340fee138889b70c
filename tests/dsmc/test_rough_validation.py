"""Rough grains against independent numbers: the DSMC against published driven steady states
(Megías & Santos 2022) and the Maxwellian theory; EDMD against DSMC in the homogeneous
cooling state and the Mpemba crossing time (slow). ``scripts/validation/rough_validation.py`` runs the
full set (docs page "Rough grains")."""

import math

import numpy as np
import pytest

from granulargas import theory
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, Simulation, TangentialRule, WhiteNoise
from granulargas.initial import maxwell_spins, random_state
from granulargas.state import State
from granulargas.theory import rough as R
from granulargas.theory.gas import Gas

PACKING = {3: 0.01, 2: 0.01}  # EDMD boxes below the shear-instability length


def _gas(d, eps, T=1.0):
    n = theory.number_density(PACKING[d], d)
    return Gas(dimension=d, packing_fraction=PACKING[d], density=n, sigma=1.0, mass=1.0, temperature=T,
               model="constant", restitution=eps)


def _state(method, d, n, seed, T_tr, T_rot):
    kappa = R.DEFAULT_INERTIA[d]
    if method == "edmd":
        st = random_state(n, PACKING[d], d, temperature=T_tr, seed=seed)
    else:
        rng = np.random.default_rng(seed)
        box = np.full(d, (n * float(theory.particle_volume(1.0, d)) / PACKING[d]) ** (1.0 / d))
        st = State(None, rng.normal(size=(n, d)) * math.sqrt(T_tr), 0.5, 1.0, box)
    spins = maxwell_spins(np.full(n, kappa / 4), d, T_rot, rng=np.random.default_rng([seed, 1]))
    return st.replace(angular_velocities=spins, inertia=np.full(n, kappa))


def _sim(method, state, eps, tangential, driving=None, seed=1):
    if method == "edmd":
        return Simulation(state, CollisionRule.constant(eps), tangential=tangential, driving=driving,
                          neighbours="cells")
    return DSMC(state, CollisionRule.constant(eps), seed=seed, tangential=tangential, driving=driving)


def hcs_theta(method, d, eps, beta, n, seed, s_from=10.0, s_to=40.0):
    """theta over s in [s_from, s_to] of a cooling run started at the Maxwellian theta_HCS."""
    rough = R.RoughGas(_gas(d, eps), R.DEFAULT_INERTIA[d], tangential_restitution=beta)
    sim = _sim(method, _state(method, d, n, seed, 1.0, R.hcs_ratio(rough)), eps, TangentialRule.constant(beta),
               seed=seed)
    out = []
    for s in np.arange(s_from, s_to + 0.5, 1.0):
        sim.run(math.inf, max_collisions=max(int(round(s * n / 2)) - sim.collisions, 1))
        out.append(sim.rotational_temperature / sim.temperature)
    return float(np.mean(out))


def driven_theta(method, eps, beta, lam, n, seed, s_to=80.0):
    """theta_st of driven disks (kappa = 1/2) over s in [10, s_to], started at the theory's state."""
    base = R.RoughGas(_gas(2, eps), 0.5, tangential_restitution=beta, heating_rate=1.0, rotational_fraction=lam)
    h = R.driven_state(base)[0] ** -1.5  # T_st = 1
    rough = R.RoughGas(_gas(2, eps), 0.5, tangential_restitution=beta, heating_rate=h, rotational_fraction=lam)
    T, Tr = R.driven_state(rough)
    drv = WhiteNoise(h, theory.driving_interval(h / T), seed=seed, rotational_fraction=lam)
    sim = _sim(method, _state(method, 2, n, seed, T, Tr), eps, TangentialRule.constant(beta), drv, seed)
    out = []
    for s in np.arange(10.0, s_to + 0.5, 2.0):
        sim.run(math.inf, max_collisions=max(int(s * n / 2) - sim.collisions, 1))
        out.append(sim.rotational_temperature / sim.temperature)
    return float(np.mean(out))


#: Megías & Santos (2022), EDMD and DSMC theta_st of driven rough disks (kappa = 1/2):
#: (eps, beta_t, fraction of the power on the spins) -> (EDMD, DSMC, error of the DSMC)
PUBLISHED = {(0.9, 0.0, 0.0): (0.24242, 0.24244, 0.00006), (0.9, 0.0, 0.5): (1.03038, 1.02863, 0.00027)}


@pytest.mark.parametrize("case", sorted(PUBLISHED))
def test_dsmc_driven_steady_state_against_published_simulations(case):
    """The DSMC's theta_st within 1.5 % of the published EDMD and DSMC (our run: 4 x 10^4 disks,
    70 collisions per particle; its own spread about 0.5 %); the Maxwellian theory misses both by
    1-3 % (0.2500 and 1.0420)."""
    eps, beta, lam = case
    pub_edmd, pub_dsmc, _ = PUBLISHED[case]
    ours = np.mean([driven_theta("dsmc", eps, beta, lam, 20000, seed) for seed in (1, 2)])
    assert ours == pytest.approx(pub_dsmc, rel=0.015)
    assert ours == pytest.approx(pub_edmd, rel=0.015)
    maxwell = R.steady_temperature_ratio(beta, 0.5) if lam == 0 else 1.042
    assert abs(ours / maxwell - 1) > abs(ours / pub_dsmc - 1)  # the simulations agree better with each other


@pytest.mark.parametrize("d, eps, beta", [(3, 0.9, 0.0), (2, 0.9, 0.0)])
def test_dsmc_hcs_ratio_against_the_maxwellian_theory(d, eps, beta):
    """The DSMC's theta_HCS lies a few per cent below the Maxwellian value (4-6 % here: the
    approximation's known miss), not farther."""
    theta = hcs_theta("dsmc", d, eps, beta, 20000, seed=1)
    th = R.hcs_temperature_ratio(eps, beta, R.DEFAULT_INERTIA[d], d)
    assert 0.92 < theta / th < 0.99


@pytest.mark.slow
@pytest.mark.parametrize("d, eps, beta, n, seeds", [(3, 0.9, 0.0, 8000, 4), (3, 0.9, 0.6, 8000, 4),
                                                    (2, 0.9, 0.0, 1000, 12)])
def test_edmd_against_dsmc_in_the_homogeneous_cooling_state(d, eps, beta, n, seeds):
    """At low density EDMD and DSMC solve the same Boltzmann dynamics: their theta_HCS agree within
    4 standard errors (EDMD boxes below the shear-instability length)."""
    edmd = [hcs_theta("edmd", d, eps, beta, n, seed) for seed in range(1, seeds + 1)]
    dsmc = [hcs_theta("dsmc", d, eps, beta, 20000, seed) for seed in range(1, 5)]
    err = math.hypot(np.std(edmd, ddof=1) / math.sqrt(seeds), np.std(dsmc, ddof=1) / 2)
    assert abs(np.mean(edmd) - np.mean(dsmc)) < 4 * err + 1e-3


@pytest.mark.slow
def test_edmd_driven_steady_state_against_published_simulations():
    """EDMD disks, translation driven: theta_st within 2 % of the published 0.2424 (EDMD and DSMC)."""
    ours = np.mean([driven_theta("edmd", 0.9, 0.0, 0.0, 1000, seed) for seed in range(1, 10)])
    assert ours == pytest.approx(0.2424, rel=0.02)


@pytest.mark.slow
def test_mpemba_crossing_time_against_theory():
    """The rough-sphere Mpemba scene: a hot gas without spin (T_tr = 12) and a cold one with much
    spin (T_tr = 1.1, T_rot = 22), both driven on translation towards T_st = 1; their T_tr cross
    near the Maxwellian theory's crossing time (within 10 %, the DSMC and EDMD spreads being a few
    per cent), and the hot one is the colder afterwards."""
    d, eps, beta = 3, 0.9, 0.0
    base = R.RoughGas(_gas(d, eps), 0.4, tangential_restitution=beta, heating_rate=1.0)
    h = R.driven_state(base)[0] ** -1.5
    gases = {name: R.RoughGas(_gas(d, eps, T), 0.4, tangential_restitution=beta, heating_rate=h,
                              rotational_temperature=Tr) for name, (T, Tr) in {"hot": (12.0, 0.0),
                                                                               "cold": (1.1, 22.0)}.items()}
    t_th = R.mpemba_crossing_time(*(R.two_temperature_curve(g, 60.0) for g in gases.values()))
    times = np.arange(0.0, 60.0, 0.25)
    for method, n in (("dsmc", 20000), ("edmd", 8000)):
        T = {}
        for name, g in gases.items():
            zeta = R.cooling_rates(gases["hot"], 12.0, 12.0)[0]
            drv = WhiteNoise(h, theory.driving_interval(zeta), seed=3)
            sim = _sim(method, _state(method, d, n, 3, g.translational_temperature, g.initial_rotational_temperature),
                       eps, TangentialRule.constant(beta), drv, seed=3)
            T[name] = np.array([(sim.run(t), sim.temperature)[1] for t in times])
        diff = np.log(T["hot"]) - np.log(T["cold"])
        k = int(np.flatnonzero(diff < 0)[0])
        t_cross = times[k - 1] - diff[k - 1] * (times[k] - times[k - 1]) / (diff[k] - diff[k - 1])
        assert t_cross == pytest.approx(t_th, rel=0.1), method
        assert np.all(diff[k + 4:k + 40] < 0)
