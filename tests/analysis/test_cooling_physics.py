"""Physics tests: simulated cooling against kinetic theory (granulargas.theory).

Default-run versions are sized for CI (N = 1000, a few seconds each after the
numba compile); the ``slow`` versions use more particles and several seeds.
The box is always below the shear-instability length ``theory.instability_length``
(asserted), so the gas stays homogeneous.
"""

import math

import numpy as np
import pytest

from granulargas import theory as th
from granulargas.analysis.run import analyze_cooling
from granulargas.theory.hcs import hcs_reference

CONFIG = """
[system]
dimension = {dim}
particles = {n}
packing_fraction = {eta}
seed = {seed}

[collision]
{collision}

[run]
end_time = {end}
neighbours = "{neighbours}"

[output]
file = "{file}"
snapshots = 6
observables_interval = {dt}
"""


def _run(tmp_path, dim, n, eta, seed, collision, end, dt, neighbours="auto"):
    from granulargas.io.config import parse_config
    from granulargas.run.runner import run_config

    path = tmp_path / f"run_{dim}_{n}_{seed}.h5"
    text = CONFIG.format(dim=dim, n=n, eta=eta, seed=seed, collision=collision, end=end, dt=dt, file=path,
                         neighbours=neighbours)
    run_config(parse_config(text, source="test"), overwrite=True)
    return analyze_cooling(path, with_sonine=False)


def _check_homogeneous_box(a, eps):
    n = a.info.number_density
    assert a.info.box.max() < th.instability_length(eps, n, a.info.dimension)


def _haff(tmp_path, dim, n, eta, seeds, eps=0.9, span=60.0):
    # Haff's tau0 with the cooling rate of the HCS reference (theory.hcs)
    tau0 = 2.0 / (th.enskog_cooling_rate(eps, th.number_density(eta, dim), 1.0, dim, a2=0.0)
                  * hcs_reference(eps, dim).zeta_factor)
    out = []
    for seed in seeds:
        a = _run(tmp_path, dim, n, eta, seed, f'model = "constant"\nrestitution = {eps}', span * tau0, tau0 / 10)
        _check_homogeneous_box(a, eps)
        assert a.prediction.tau0 == pytest.approx(tau0, rel=1e-9)  # the run's own density
        out.append((a.fit.tau0 / tau0 - 1.0, a.fit_free.exponent))
    return np.array(out)


def test_haff_law_3d_constant_restitution(tmp_path):
    # eps = 0.9, packing 0.05, N = 1000: L = 21.9 = 0.39 L_c. The fitted tau0 of the
    # two-seed ensemble within 2 % of Enskog with a2 (single seeds scatter by ~1 %).
    dev, expo = _haff(tmp_path, 3, 1000, 0.05, seeds=[1, 2]).T
    assert abs(dev.mean()) < 0.02, dev
    assert np.all(np.abs(expo - 2.0) < 0.05), expo


def test_haff_law_2d_constant_restitution(tmp_path):
    # 2D boxes are long for a given N (N at fixed L/L_c grows as 1/density): a dilute
    # gas, packing 0.02, N = 600 gives L = 0.48 L_c. (Close to L_c, e.g. packing 0.1 with
    # N = 300 at L = 0.79 L_c, weakly damped shear modes keep T up to 10 % above Haff.)
    dev, expo = _haff(tmp_path, 2, 600, 0.02, seeds=[1])[0]
    assert abs(dev) < 0.02 and abs(expo - 2.0) < 0.05


def _visco(tmp_path, n, eta, damping, seeds, span=30.0):
    tau0 = th.viscoelastic_tau0(damping, th.number_density(eta, 3))
    out = []
    for seed in seeds:
        a = _run(tmp_path, 3, n, eta, seed, f'model = "viscoelastic"\ndamping = {damping}', span * tau0, tau0 / 20)
        eps_eff = math.sqrt(1 - th.effective_inelasticity(damping, 1.0))
        _check_homogeneous_box(a, eps_eff)
        assert a.prediction.law == "viscoelastic" and a.prediction.tau0 == pytest.approx(tau0, rel=1e-9)
        out.append((a.fit.tau0 / tau0 - 1.0, a.fit_free.exponent))
    return np.array(out)


def test_viscoelastic_cooling_3d_small_damping(tmp_path):
    # damping 0.02 (beta ~ 0.02 at thermal speed): T ~ (1 + t/tau0)^(-5/3), tau0 from
    # theory.viscoelastic_tau0 (leading order in beta; the beta^2 term shifts it by ~ +3 %).
    dev, expo = _visco(tmp_path, 1000, 0.1, 0.02, seeds=[3])[0]
    assert abs(dev) < 0.05, dev
    assert abs(expo - 5.0 / 3.0) < 0.05, expo


@pytest.mark.slow
def test_haff_law_3d_large_several_seeds(tmp_path):
    # packing 0.05: N = 8000, L = 0.77 L_c; packing 0.1: N = 1000, L = 0.61 L_c, where the
    # measured tau0 sits 1-2 % above Enskog + a2 (docs/validation.md, denser gases), hence 6 seeds.
    for eta, n, seeds in ((0.05, 8000, [11, 12, 13]), (0.1, 1000, [11, 12, 13, 14, 15, 16])):
        dev, expo = _haff(tmp_path, 3, n, eta, seeds=seeds, span=100.0).T
        assert abs(dev.mean()) < 0.02, (eta, dev)
        assert np.all(np.abs(expo - 2.0) < 0.05), (eta, expo)


@pytest.mark.slow
def test_viscoelastic_cooling_3d_large_several_seeds(tmp_path):
    dev, expo = _visco(tmp_path, 8000, 0.1, 0.01, seeds=[21, 22], span=100.0).T
    assert np.all(np.abs(dev) < 0.05), dev
    assert np.all(np.abs(expo - 5.0 / 3.0) < 0.05), expo


@pytest.mark.slow
def test_sonine_a2_of_the_hcs_matches_van_noije_ernst(tmp_path):
    # eps = 0.9, 3D, packing 0.05, L = 0.5 L_c (N = 2182), 12 seeds; a2 averaged over
    # the snapshots after 2 tau0 (the Maxwellian start relaxes within a few collisions).
    # The error comes from the scatter of the seeds' means: successive snapshots are
    # correlated (slow hydrodynamic modes), and seeds 1-36 scatter 1.5-1.8 times more
    # than the snapshots' own scatter / sqrt(snapshots) says.
    from granulargas.analysis.run import sonine_history
    from granulargas.io.config import parse_config
    from granulargas.run.runner import run_config

    eps, eta = 0.9, 0.05
    n = th.number_density(eta, 3)
    N = int(n * (0.5 * th.instability_length(eps, n)) ** 3)
    tau0 = th.haff_tau0(eps, n)
    vals = []
    for seed in range(1, 13):
        path = tmp_path / f"a2_{seed}.h5"
        text = CONFIG.format(dim=3, n=N, eta=eta, seed=seed, collision=f'model = "constant"\nrestitution = {eps}',
                             end=30 * tau0, dt=tau0, file=path, neighbours="auto").replace("snapshots = 6", f"snapshot_interval = {30 * tau0 / 39}")
        run_config(parse_config(text, source="test"), overwrite=True)
        t, a2, _ = sonine_history(path)
        vals.append(a2[t > 2 * tau0].mean())
    v = np.array(vals)
    se = v.std(ddof=1) / math.sqrt(v.size)
    expected = th.sonine_a2(eps, 3)  # -0.0146
    assert abs(v.mean() - expected) < 4 * se, (v.mean(), se)
    assert v.mean() < -5 * se  # the sign: a2 < 0 for 1/sqrt(2) < eps < 1


def test_viscoelastic_cooling_at_damping_0_1_follows_the_kinetic_theory(tmp_path):
    # damping 0.1 (beta ~ 0.1 at thermal speed): the leading-order law is 10-20 % off by
    # the end, the kinetic theory with the exact eps(g) and a2(t) within 3 % (it agrees with
    # DSMC of the Enskog-Boltzmann equation to 0.15 %). Packing 0.05, N = 1000, four seeds:
    # single seeds scatter by 1.1 % (seeds 1-12: T/T_theory 0.998 +- 0.003 over the last
    # decade). At packing 0.1 the simulated gas cools 2 % slower than Enskog's theory at
    # every N (1000: 1.018 +- 0.004, 4000: 1.021 +- 0.002), the velocity correlations
    # that the Enskog closure leaves out.
    ratios, closed = [], []
    for seed in (1, 2, 3, 4):
        a = _run(tmp_path, 3, 1000, 0.05, seed, 'model = "viscoelastic"\ndamping = 0.1', 120.0, 1.0)
        eps_eff = math.sqrt(1 - th.effective_inelasticity(0.1, 1.0))
        _check_homogeneous_box(a, eps_eff)
        ratios.append(a.T_ratio_last_decade)
        closed.append(a.history.temperature[-1] / a.prediction.temperature(a.time[-1]))
    assert abs(np.mean(ratios) - 1) < 0.03, ratios
    assert min(closed) > 1.1, closed
