"""advise names the collision duration a material-route config needs: instantaneous where the
contact's duration is short enough, resolved where the resolved scheme's measured error against
LAMMPS is within the tolerance, a DEM beyond (thresholds from RESOLVED_LAMMPS_MEASURED)."""

import math

import numpy as np
import pytest

from granulargas.cli import main
from granulargas.contact.material import dissipation_time_from_prefactor, prefactor_from_damping
from granulargas.io.config import parse_config
from granulargas.run.advise import (DEFAULT_TOLERANCE, RESOLVED_COST, RESOLVED_LAMMPS_MEASURED, advise,
                                    choose_duration, dem_cost, duration_error, fastest_impact_bounds)
from granulargas.run.validity import contact_time_ratio

MATERIAL = """
[system]
dimension = 3
particles = 2000
packing_fraction = 0.05

[collision]
model = "viscoelastic"

[collision.material]
young_modulus = {young!r}
poisson_ratio = 0.3
dissipation_time = {dissipation!r}
diameter = 1.0
density = {density!r}
speed_unit = 1.0

[run]
end_time = 20.0
"""


def _text(young, damping=0.1):
    young = float(young)
    a = dissipation_time_from_prefactor(prefactor_from_damping(damping), young, 0.3)
    return MATERIAL.format(young=young, dissipation=a, density=6.0 / math.pi)


def _config(young, damping=0.1):
    return parse_config(_text(young, damping))


def _young_for_ratio(ratio):
    """Young modulus of the MATERIAL gas whose contact-time ratio at T0 is ``ratio``."""
    from scipy.optimize import brentq

    return math.exp(brentq(lambda y: math.log(contact_time_ratio(_config(math.exp(y))) / ratio),
                           math.log(1.0), math.log(1e12), xtol=1e-12))


def test_measured_points_are_reproduced_and_interpolated_as_power_laws():
    for r, e_inst, e_res, cost in RESOLVED_LAMMPS_MEASURED:
        assert duration_error(r, "instantaneous") == pytest.approx(e_inst)
        assert duration_error(r, "resolved") == pytest.approx(e_res)
        assert dem_cost(r) == pytest.approx(cost)
    (r0, a0, _, c0), (r1, a1, _, c1) = RESOLVED_LAMMPS_MEASURED[:2]
    mid = math.sqrt(r0 * r1)
    assert duration_error(mid, "instantaneous") == pytest.approx(math.sqrt(a0 * a1))
    assert dem_cost(mid) == pytest.approx(math.sqrt(c0 * c1))
    assert math.isnan(duration_error(2 * RESOLVED_LAMMPS_MEASURED[-1][0], "resolved"))
    # below the measurements: in proportion to the ratio
    assert duration_error(r0 / 10, "instantaneous") == pytest.approx(a0 / 10)


@pytest.mark.parametrize("row", RESOLVED_LAMMPS_MEASURED, ids=lambda row: f"ratio {row[0]:g}")
def test_at_the_measured_ratios_the_measured_errors_decide(row):
    ratio, e_inst, e_res, cost = row
    config = _config(_young_for_ratio(ratio * (1 - 1e-9)))  # on the measured side of the largest ratio
    assert contact_time_ratio(config) == pytest.approx(ratio, rel=1e-6)
    duration, reason = choose_duration(config)
    assert f"t_c/t_free = {ratio:.3g}" in reason
    expected = ("instantaneous" if e_inst <= DEFAULT_TOLERANCE else
                "resolved" if e_res <= DEFAULT_TOLERANCE and cost >= 1 else "dem")
    assert duration == expected


def test_longer_contacts_never_get_a_cheaper_answer():
    order = {"instantaneous": 0, "resolved": 1, "dem": 2}
    answers = [order[choose_duration(_config(y))[0]] for y in np.geomspace(1e8, 1e2, 25)]
    assert answers == sorted(answers)


def test_all_three_answers_occur_over_the_stiffness_range():
    answers = {choose_duration(_config(y))[0] for y in (1e2, 1e4, 1e8)}
    assert answers == {"instantaneous", "resolved", "dem"}


def test_resolved_advice_gives_cost_and_errors():
    # pick a stiffness between the instantaneous and resolved limits
    for young in (1e5, 3e4, 1e4, 3e3, 1e3):
        duration, reason = choose_duration(_config(young))
        if duration == "resolved":
            break
    else:
        pytest.fail("no stiffness gives the resolved advice")
    assert 'duration = "resolved"' in reason and f"x{RESOLVED_COST:g}" in reason
    adv = advise(_config(young))
    text = "\n".join(adv.lines())
    assert "duration     resolved:" in text
    assert 'model = "constant"' not in text  # constant eps is an instantaneous rule


def test_beyond_the_measured_range_the_advice_is_dem():
    config = _config(1e2)
    assert contact_time_ratio(config) > RESOLVED_LAMMPS_MEASURED[-1][0]
    duration, reason = choose_duration(config)
    assert duration == "dem" and "export lammps" in reason


def test_a_looser_tolerance_keeps_instantaneous_collisions_longer():
    config = _config(1e4)
    assert choose_duration(config, 0.5)[0] == "instantaneous"


def test_damping_route_and_constant_rule_get_no_duration_advice():
    damping = parse_config(_text(1e4).split("[collision.material]")[0].replace(
        'model = "viscoelastic"', 'model = "viscoelastic"\ndamping = 0.1') + "[run]\nend_time = 20.0\n")
    assert choose_duration(damping) is None and advise(damping).duration is None


def test_cli_advise_prints_the_duration(tmp_path, capsys):
    p = tmp_path / "c.toml"
    p.write_text(_text(1e2))
    assert main(["advise", str(p)]) == 0
    out = capsys.readouterr().out
    assert "duration     dem:" in out


@pytest.mark.parametrize("table, expected", [
    # instantaneous off by 5 %, resolved by 1 %, DEM 3x the resolved run's time -> resolved
    (((0.01, 0.05, 0.01, 3.0), (0.5, 0.05, 0.01, 3.0)), "resolved"),
    # the same, but DEM at half the resolved run's time -> DEM
    (((0.01, 0.05, 0.01, 0.5), (0.5, 0.05, 0.01, 0.5)), "dem"),
    # resolved off by 5 % -> DEM
    (((0.01, 0.05, 0.05, 3.0), (0.5, 0.05, 0.05, 3.0)), "dem"),
    # instantaneous within 1 % -> instantaneous, whatever else
    (((0.01, 0.01, 0.05, 0.5), (0.5, 0.01, 0.05, 0.5)), "instantaneous"),
])
def test_the_cheapest_accurate_method_is_chosen(monkeypatch, table, expected):
    import granulargas.run.advise as A

    monkeypatch.setattr(A, "RESOLVED_LAMMPS_MEASURED", table)
    config = _config(_young_for_ratio(0.05))
    assert choose_duration(config)[0] == expected


def test_dsmc_is_not_advised_where_the_contacts_last_long_enough_to_matter():
    stiff, soft = advise(_config(1e8)), advise(_config(1e4))  # dilute and homogeneous, both
    assert stiff.duration == "instantaneous" and stiff.method == "dsmc"
    assert soft.duration == "resolved" and soft.method == "edmd" and "last long enough" in soft.method_reason


def test_fastest_impact_prediction_brackets_real_initial_states():
    from granulargas.run.prepare import initial_state, oblique_bounds, reduced_compression, reduced_prefactor

    config = _config(_young_for_ratio(0.2))
    predicted = fastest_impact_bounds(config)[1]
    actual = []
    for seed in range(1, 7):
        c = parse_config(_text(config.collision.material.young_modulus).replace(
            "packing_fraction = 0.05", f"packing_fraction = 0.05\nseed = {seed}"))
        actual.append(oblique_bounds(reduced_prefactor(c), reduced_compression(c), initial_state(c))[1])
    # the 0.9 quantile of the largest of N speeds: above most of the states' fastest impacts
    assert sorted(actual)[2] < predicted < 1.2 * max(actual)


def test_a_gas_whose_fastest_impacts_leave_the_table_gets_dem():
    # at t_c/t_free = 0.15 a billion particles hold faster impacts than 2000 do
    small = _config(_young_for_ratio(0.15))
    large = parse_config(_text(small.collision.material.young_modulus).replace("particles = 2000",
                                                                                "particles = 1000000000"))
    assert choose_duration(small)[0] == "resolved"
    duration, reason = choose_duration(large)
    assert fastest_impact_bounds(large)[1] > 0.5
    assert duration == "dem" and "beyond the resolved scheme's table" in reason
