"""``granulargas epsilon``: both forms print every method; bad input is one clear line."""

import pytest

from granulargas.cli import main
from granulargas.contact import duration, restitution


def test_beta_form_prints_each_method(capsys, cache_dir):
    assert main(["epsilon", "--beta", "0.1"]) == 0
    out = capsys.readouterr().out
    for word in ("ode", "table", "series(2)", "series(10)", "pade", "overlap", "force"):
        assert word in out
    assert f"{restitution(0.1):.14f}" in out
    assert f"{duration(0.1, end='force'):.14f}" in out


def test_beyond_radius_and_validity_are_reported(capsys, cache_dir):
    assert main(["epsilon", "--beta", "2", "--end", "overlap"]) == 0
    out = capsys.readouterr().out
    assert "diverges" in out and "warning: beta = 2" in out


def test_material_form(capsys, cache_dir):
    args = ["epsilon", "--young", "1e7", "--poisson", "0.3", "-A", "1e-5", "--radius", "0.01",
            "--density", "1000", "--speed", "0.1", "--end", "overlap"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "beta = 0.0215481" in out and "t_c [s]" in out


@pytest.mark.parametrize("argv,msg", [
    (["epsilon"], "give --beta"),
    (["epsilon", "--beta", "-1"], "--beta"),
    (["epsilon", "--young", "1e7"], "--poisson"),
    (["epsilon", "--young", "1e7", "--poisson", "0.7", "-A", "1e-5", "--radius", "0.01", "--mass", "1",
      "--speed", "1"], "--poisson 0.7"),
])
def test_bad_input_is_one_line(argv, msg, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert msg in err and err.count("\n") == 1


def test_beta_form_names_the_value_to_use_first(capsys, cache_dir):
    # the engine's table value, before the comparison of the methods, for each end
    from granulargas.contact import restitution_table

    assert main(["epsilon", "--beta", "0.3"]) == 0
    out = capsys.readouterr().out
    for end in ("overlap", "force"):
        block = out[out.index(f"end = {end}"):]
        use = block.index("use: eps = ")
        assert use < block.index("comparison") < block.index("ode")
        table = restitution_table(0.3, end=end)
        assert f"use: eps = {float(table.restitution(0.3)):.14f}" in block
        assert f"tau_c = {float(table.duration(0.3)):.14f}" in block
    assert "end = overlap (the engine's default)" in out


def test_beta_beyond_the_table_is_one_line(capsys):
    assert main(["epsilon", "--beta", "50"]) == 2
    err = capsys.readouterr().err
    assert "40" in err and err.count("\n") == 1
