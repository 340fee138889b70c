"""`granulargas advise`: the best constant eps and its predicted error, checked against
the closed-form laws (Haff t^-2 vs viscoelastic t^-5/3) fitted by brute force."""

import math
from pathlib import Path

import numpy as np
import pytest

from granulargas.run import advise as A
from granulargas.run import validity as V
from granulargas import theory
from granulargas.cli import main
from granulargas.io.config import parse_config

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


def config(collision, run="end_time = 100.0"):
    return parse_config(f"[system]\ndimension = 3\nparticles = 2000\npacking_fraction = 0.1\n"
                        f"[collision]\n{collision}\n[run]\n{run}\n", source="test.toml")


def brute_force_minimax(b, n, t_end):
    """Best Haff law against T = (1 + t/tau_v)^(-5/3), both in closed form (a2 = 0)."""
    tau_v = theory.viscoelastic_tau0(b, n, 1.0, 3)
    t = np.linspace(0, t_end, 2001)
    Tv = theory.viscoelastic_temperature(t, 1.0, tau_v)
    taus = tau_v * np.geomspace(0.3, 3, 4001)
    err = np.max(np.abs((1 + t[None, :] / taus[:, None]) ** -2 / Tv[None, :] - 1), axis=1)
    return float(err.min())


@pytest.mark.parametrize("t_end", [5.0, 50.0])
def test_predicted_error_matches_closed_forms_at_small_damping(t_end):
    b = 0.003
    adv = A.advise(config(f'model = "viscoelastic"\ndamping = {b}', f"end_time = {t_end}"))
    n = theory.number_density(0.1, 3)
    ref = brute_force_minimax(b, n, t_end)
    # corrections: beta ~ 0.003 in the law, a2(eps) in Haff's rate
    assert adv.error == pytest.approx(ref, rel=0.1, abs=2e-4)


def test_verdict_follows_tolerance():
    short = A.advise(config('model = "viscoelastic"\ndamping = 0.01', "end_time = 10.0"))
    assert short.constant_ok and short.error < 0.02
    long = A.advise(config('model = "viscoelastic"\ndamping = 0.1', "end_time = 1000.0"))
    assert not long.constant_ok and long.error > 0.02
    # same numbers, looser tolerance
    assert A.advise(config('model = "viscoelastic"\ndamping = 0.1', "end_time = 1000.0"),
                    tolerance=long.error * 1.01).constant_ok


def test_best_constant_lies_inside_the_spread():
    adv = A.advise(config('model = "viscoelastic"\ndamping = 0.1'))
    assert adv.spread["eps_min"] < adv.eps_best < adv.spread["eps_max"]
    # any other constant eps is worse
    gas = A.V.gas_from_config(config('model = "viscoelastic"\ndamping = 0.1'))
    curve = A.V.viscoelastic_cooling(gas)
    for de in (-0.005, 0.005):
        assert A.constant_error(gas, adv.eps_best + de, curve, adv.t_end) > adv.error


@pytest.mark.parametrize("eps, beta_limit", [(0.95, 0.5), (0.6, 4.0), (0.1, 40.0)])
def test_equivalent_damping_needs_the_restitution_table_only_near_its_root(monkeypatch, eps, beta_limit):
    """The root search asks for the table up to a beta of the order of the root's, not up to the
    end of the search range (building the table to beta ~ 30 takes seconds), and finds the same
    root as a search over the whole range."""
    import granulargas.theory.gas as gas_theory
    from scipy.optimize import brentq

    gas = V.gas_from_config(config(f'model = "constant"\nrestitution = {eps}'))
    asked = []
    table = gas_theory.restitution_table

    def recording(beta_max, *args, **kwargs):
        asked.append(beta_max)
        return table(beta_max, *args, **kwargs)

    monkeypatch.setattr(gas_theory, "restitution_table", recording)
    k = A._equivalent_prefactor(gas, eps)
    assert max(asked) < beta_limit

    def f(log_k):  # the search over the whole range, independently
        g = A.replace(gas, model="viscoelastic", prefactor=math.exp(log_k))
        return V.effective_inelasticity(g, gas.temperature) - (1 - eps**2)

    unit = A.replace(gas, model="viscoelastic", prefactor=1.0)
    scale = unit.pair_constant * math.sqrt(2 * gas.temperature / gas.mass) ** 0.2
    assert k == pytest.approx(math.exp(brentq(f, math.log(1e-8 / scale), math.log(20 / scale), xtol=1e-12)),
                              rel=1e-9)


def test_constant_config_equivalent_damping():
    adv = A.advise(config('model = "constant"\nrestitution = 0.9'))
    # leading order: 1 - eps^2 = 2 C1 b Gamma(21/10) 4^(1/10) at T0 = 1
    b_lo = (1 - 0.81) / (2 * theory.C1 * math.gamma(2.1) * 4**0.1)
    assert adv.damping_equivalent == pytest.approx(b_lo, rel=0.15)
    assert adv.error > 0
    adv = A.advise(config('model = "constant"\nrestitution = 0.6'))
    assert any("tc_time" in n for n in adv.notes)


def test_summary_line():
    line = A.summary_line(config('model = "viscoelastic"\ndamping = 0.1'))
    assert "\n" not in line and "best constant" in line
    assert A.summary_line(config('model = "elastic"')) is None
    assert "damping" in A.summary_line(config('model = "constant"\nrestitution = 0.9'))


def test_a_run_solves_its_cooling_curve_once(monkeypatch):
    """The run's checks, the advice and the summary line share one solution of the cooling
    law (each for a run of a different length: the curve does not depend on it)."""
    solved = []
    solve = V.viscoelastic_cooling
    monkeypatch.setattr(V, "viscoelastic_cooling", lambda gas: solved.append(gas) or solve(gas))
    V._cooling.cache_clear()
    for t_end in (40.0, 80.0):
        cfg = config('model = "viscoelastic"\ndamping = 0.0123', f"end_time = {t_end}")
        V.raise_if_invalid(cfg)
        A.advise(cfg)
        assert A.summary_line(cfg).startswith("advice       eps")
    assert len(solved) == 1


def test_cli(capsys):
    assert main(["advise", str(CONFIGS / "quickstart.toml")]) == 0
    out = capsys.readouterr().out
    assert "best const." in out and "eps spread" in out
    assert main(["advise", str(CONFIGS / "quickstart.toml"), "--tolerance", "2"]) == 2
    assert "tolerance" in capsys.readouterr().err
    assert main(["advise", str(CONFIGS / "quickstart.toml"), "--set", "collision.damping=-1"]) == 2


def test_equivalent_damping_is_the_config_damping_for_any_particles():
    """The reported damping means the config's ``damping`` (two reference particles), also
    when the gas's particles are not the reference ones: pasting it into a viscoelastic
    config gives the constant config's 1 - eps^2 as the initial effective inelasticity."""
    particles = "[particles]\ndiameter = 1.5\nmass = 2.0\n"

    def cfg(collision):
        return parse_config(f"[system]\ndimension = 3\nparticles = 2000\npacking_fraction = 0.1\n{particles}"
                            f"[collision]\n{collision}\n[run]\nend_time = 100.0\n", source="test.toml")

    adv = A.advise(cfg('model = "constant"\nrestitution = 0.9'))
    gas = V.gas_from_config(cfg(f'model = "viscoelastic"\ndamping = {adv.damping_equivalent!r}'))
    assert V.effective_inelasticity(gas, gas.temperature) == pytest.approx(1 - 0.81, rel=1e-8)
    # ... while the pair constant b of these particles differs from the damping
    assert gas.pair_constant == pytest.approx(adv.damping_equivalent * (0.375 / 1.0) ** 0.2, rel=1e-12)


def test_advise_and_analyze_report_one_instability_length(tmp_path):
    """`advise` (from the config) and `analyze` (from the run's file) give the same L_c."""
    from granulargas.analysis.run import RunInfo
    from granulargas.run.runner import run_config

    for collision in ('model = "viscoelastic"\ndamping = 0.1', 'model = "constant"\nrestitution = 0.9'):
        cfg = parse_config(f"[system]\ndimension = 3\nparticles = 300\npacking_fraction = 0.1\n"
                           f"[collision]\n{collision}\n[run]\nend_time = 0.2\n"
                           f"[output]\nfile = \"{tmp_path / 'r.h5'}\"\n", source="test.toml")
        advised = A.advise(cfg).instability_length
        run_config(cfg, overwrite=True)
        analysed = RunInfo.from_file(tmp_path / "r.h5").prediction(1.0).instability_length
        assert math.isfinite(advised) and analysed == pytest.approx(advised, rel=1e-9)


def test_viscoelastic_instability_length_at_small_damping():
    """Exact-eps L_c at T0 against the closed form with the leading-order (1 - eps^2)_eff."""
    b, n = 0.002, theory.number_density(0.1, 3)
    gas = V.gas_from_config(config(f'model = "viscoelastic"\ndamping = {b}'))
    q = float(theory.effective_inelasticity(b, 1.0, order=2))
    assert gas.instability_length() == pytest.approx(theory.instability_length(math.sqrt(1 - q), n, 3, a2=0.0),
                                                     rel=1e-4)
    # it grows as the gas cools: (1 - eps^2)_eff ~ T^(1/10), so L_c ~ T^(-1/20)
    assert gas.instability_length(1e-3) / gas.instability_length() == pytest.approx(1e-3 ** -0.05, rel=2e-3)
