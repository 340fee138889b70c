"""Run-level validity checks against independent numbers: Monte Carlo impact speeds,
closed-form cooling laws (theory), Hertz's contact duration, Haff in collisions."""

import math

import numpy as np
import pytest
from scipy.special import gamma

from granulargas import theory
from granulargas.run import validity as V
from granulargas.errors import ConfigError
from granulargas.io.config import parse_config
from granulargas.theory.hcs import hcs_reference

HERTZ_TAU = 3.2180654  # (4/5)(5/4)^(2/5) B(2/5, 1/2), the Hertz duration


def config(collision, run="end_time = 100.0", system="dimension = 3\nparticles = 2000\npacking_fraction = 0.1"):
    return parse_config(f"[system]\n{system}\n[collision]\n{collision}\n[run]\n{run}\n", source="test.toml")


def test_impact_speed_quantiles_match_monte_carlo():
    # collisions sample the normal relative speed g with weight g (collision kernel)
    rng = np.random.default_rng(3)
    T, m = 0.7, 2.0
    v1, v2 = rng.normal(0, math.sqrt(T / m), (2, 400_000, 3))
    g = v1[:, 0] - v2[:, 0]  # normal component along a fixed direction
    g, w = g[g > 0], g[g > 0]
    order = np.argsort(g)
    cdf = np.cumsum(w[order]) / w.sum()
    for q in (0.05, 0.5, 0.95):
        mc = g[order][np.searchsorted(cdf, q)]
        assert V.impact_speed_quantile(q, T, m) == pytest.approx(mc, rel=0.01)


def test_effective_inelasticity_matches_series_average():
    # theory.effective_inelasticity(order=2) is the analytic kernel average of the
    # two-term series; the difference is O(b^3)
    for b in (1e-3, 1e-2):
        gas = V.gas_from_config(config(f'model = "viscoelastic"\ndamping = {b}'))
        for T in (1.0, 1e-3):
            ours = V.effective_inelasticity(gas, T)
            ref = theory.effective_inelasticity(b, T, order=2)
            beta = b * (4 * T) ** 0.1
            assert abs(ours / ref - 1) < 3 * beta**2


def test_viscoelastic_cooling_reduces_to_five_thirds_law():
    b = 1e-3
    gas = V.gas_from_config(config(f'model = "viscoelastic"\ndamping = {b}'))
    curve = V.viscoelastic_cooling(gas, t_min_ratio=1e-6)
    tau0 = theory.viscoelastic_tau0(b, gas.density, 1.0, 3)
    t = np.geomspace(0.1, 0.9, 20) * curve.time[-1]
    ref = theory.viscoelastic_temperature(t, 1.0, tau0)
    # relative corrections are O(beta) at thermal speed
    assert np.max(np.abs(curve.temperature_at(t) / ref - 1)) < 0.01
    # and the collision count follows theory.viscoelastic_collisions
    s_ref = theory.viscoelastic_collisions(t, tau0, gas.collision_frequency)
    s = np.interp(t, curve.time, curve.collisions)
    assert np.max(np.abs(s / s_ref - 1)) < 0.01


def test_restitution_spread_brackets_thermal_eps():
    from granulargas.contact import restitution

    gas = V.gas_from_config(config('model = "viscoelastic"\ndamping = 0.1'))
    sp = V.restitution_spread(gas, 1.0, 0.01)
    g_typ = math.sqrt(math.pi * 1.0)  # mean collision impact speed at T = 1, m = 1
    assert sp["eps_min"] < restitution(0.1 * g_typ**0.2) < sp["eps_max"]
    assert sp["eps_max"] == pytest.approx(float(restitution(sp["beta_min"])), abs=1e-9)
    assert sp["spread"] > 0


def test_haff_run_end_matches_theory():
    cfg = config('model = "constant"\nrestitution = 0.8', run="end_time = 50.0")
    gas = V.gas_from_config(cfg)
    # Haff's law with the cooling rate and collision frequency of the HCS reference (theory.hcs)
    ref = hcs_reference(0.8, 3)
    tau0 = 2.0 / (theory.enskog_cooling_rate(0.8, gas.density, 1.0, 3, chi=gas.chi, a2=0.0) * ref.zeta_factor)
    t_end, T_end = V.run_temperature_range(gas)
    assert t_end == 50.0
    assert T_end == pytest.approx(theory.haff_temperature(50.0, 1.0, tau0), rel=1e-12)
    cfg = config('model = "constant"\nrestitution = 0.8', run="collisions_per_particle = 30")
    _, T_end = V.run_temperature_range(V.gas_from_config(cfg))
    assert T_end == pytest.approx(math.exp(-ref.cooling_per_collision * 30), rel=1e-9)


def test_contact_time_ratio_elastic_limit_is_hertz():
    # A -> 0: t_c = tau_Hertz rho^(-2/5) g^(-1/5), averaged over the Rayleigh law of g:
    # <g^(-1/5)> = (2 s^2)^(-1/10) Gamma(9/10), s^2 = 2T/m
    Y, nu, d, dens, u = 1e8, 0.3, 0.01, 2000.0, 2.0
    cfg = config(f'model = "viscoelastic"\n[collision.material]\nyoung_modulus = {Y}\npoisson_ratio = {nu}\n'
                 f"dissipation_time = 1e-15\ndiameter = {d}\ndensity = {dens}\nspeed_unit = {u}")
    gas = V.gas_from_config(cfg)
    M = dens * math.pi * d**3 / 6
    rho = 2 * Y * math.sqrt(d / 4) / (3 * (M / 2) * (1 - nu**2))
    mean_g = (2 * 2.0) ** -0.1 * gamma(0.9) * u**-0.2  # T = m = 1 reduced, g in m/s
    t_c = HERTZ_TAU * rho**-0.4 * mean_g / (d / u)
    assert V.contact_time_ratio(cfg) == pytest.approx(t_c * gas.collision_frequency, rel=1e-6)
    # the ratio grows as T^(2/5)
    assert V.contact_time_ratio(cfg, 1e-5) == pytest.approx(V.contact_time_ratio(cfg) * 1e-2, rel=1e-4)


def test_contact_time_ratio_warning_threshold():
    base = 'model = "constant"\nrestitution = 0.9\ntc_time = {}'
    gas = V.gas_from_config(config(base.format(1.0)))
    tc_warn = V.TC_RATIO_WARN / gas.collision_frequency
    low = V.check_run(config(base.format(0.5 * tc_warn)))
    high = V.check_run(config(base.format(2.0 * tc_warn)))
    assert low.tc_ratio == pytest.approx(0.5 * V.TC_RATIO_WARN)
    assert not low.warnings
    assert len(high.warnings) == 1 and "mean free time" in high.warnings[0]
    # damping route: not determined, no warning, said so
    rv = V.check_run(config('model = "viscoelastic"\ndamping = 0.1'))
    assert rv.tc_ratio is None and any("not determined" in ln for ln in rv.lines())


def test_large_beta_is_flagged():
    rv = V.check_run(config('model = "viscoelastic"\ndamping = 2.0'))
    assert rv.spread["beta_max"] > 1
    assert any("beta" in w for w in rv.warnings)
    assert not V.check_run(config('model = "viscoelastic"\ndamping = 0.1')).warnings


def test_velocity_underflow_is_refused():
    ok = config('model = "constant"\nrestitution = 0.5', run="collisions_per_particle = 100")
    assert not V.raise_if_invalid(ok).errors
    # (1 - eps^2)(1 + 3 a2/16) s / d ~ 0.25 s: 1e-250 after ~2300 collisions per particle
    bad = config('model = "constant"\nrestitution = 0.5', run="collisions_per_particle = 5000")
    with pytest.raises(ConfigError, match="run.collisions_per_particle.*underflow"):
        V.raise_if_invalid(bad)
    # viscoelastic gases slow their cooling: no underflow even for absurd lengths
    assert not V.check_run(config('model = "viscoelastic"\ndamping = 0.1', run="end_time = 1e12")).errors


def test_summary_lines_are_single_lines():
    for coll in ('model = "elastic"', 'model = "constant"\nrestitution = 0.9',
                 'model = "viscoelastic"\ndamping = 0.05'):
        lines = V.summary_lines(config(coll))
        assert lines and all("\n" not in ln for ln in lines)


CONFIGS = __import__("pathlib").Path(__file__).resolve().parents[2] / "configs"


def test_a_cooling_engine_run_in_a_box_above_the_instability_length_is_warned(tmp_path, capsys):
    from granulargas.cli import main

    # 1000 disks at packing 0.05: box sqrt(1000 (pi/4) / 0.05) = 125.3; eps = 0.8 clusters (L_c ~ 91),
    # eps = 0.95 (the config's) stays homogeneous (L_c ~ 174)
    box = math.sqrt(1000 * math.pi / 4 / 0.05)
    args = ["run", str(CONFIGS / "haff_2d.toml"), "--quiet", "--set", "run.collisions_per_particle=2"]
    assert main(args + ["-o", str(tmp_path / "a.h5"), "--set", "collision.restitution=0.8"]) == 0
    (line,) = [ln for ln in capsys.readouterr().out.splitlines() if "instability length" in ln]
    assert line.startswith("warning: ") and f"box length {box:.4g} is above" in line
    assert main(args + ["-o", str(tmp_path / "b.h5")]) == 0
    assert "instability length" not in capsys.readouterr().out


def test_a_dsmc_run_gets_no_space_or_drift_warning():
    from granulargas.io.config import load_config
    from granulargas.run.advise import advise, method_line

    # the full example: 10^5 velocities, whose notional box (137.8) exceeds L_c (127.9)
    cfg = load_config(CONFIGS / "hcs_dsmc_3d.toml")
    rv = V.check_run(cfg)
    assert rv.warnings == [] and method_line(cfg) is None
    assert V.box_length(cfg) == pytest.approx((1e5 * math.pi / 6 / 0.02) ** (1 / 3))
    assert V.box_length(cfg) > V.gas_from_config(cfg).instability_length()
    lines = advise(cfg).lines()
    assert not any(ln.startswith("clustering") for ln in lines)
    assert any(ln.startswith("homogeneous  DSMC has no space") for ln in lines)
    # a constant eps = 0.5 cooling by 40 decades: no centre-of-mass warning (DSMC and the engine remove
    # the round-off drift themselves)
    for method in ("dsmc", "edmd"):
        cold = config('model = "constant"\nrestitution = 0.5',
                      run=f'collisions_per_particle = 400\nmethod = "{method}"',
                      system="dimension = 3\nparticles = 2000\npacking_fraction = 0.02")
        rv = V.check_run(cold)
        assert rv.T_end < 1e-35 and not rv.errors
        assert not any("centre-of-mass" in w for w in rv.warnings)


def test_rough_theory_beyond_the_restitution_table_is_one_config_error():
    """At T0 the smooth theory's fastest impacts stay inside the table, but the two-temperature
    theory of rough grains (energy fed back from the spins) reaches beyond it: refused with the
    damping named, by the run's checks and by advise alike (not a run-time error)."""
    from granulargas.run.advise import advise

    cfg = config('model = "viscoelastic"\ndamping = 20.0\n[collision.tangential]\nmodel = "coulomb"\n'
                 'restitution = 0.4\nfriction = 0.3', run="end_time = 0.5",
                 system="dimension = 3\nparticles = 64\npacking_fraction = 0.1")
    gas = V.gas_from_config(cfg)
    assert V.table_range_error(gas) is None
    with pytest.raises(ConfigError, match=r"collision.damping = 20.*two-temperature theory"):
        V.raise_if_invalid(cfg)
    with pytest.raises(ConfigError, match=r"collision.damping = 20.*two-temperature theory"):
        advise(cfg)
