"""``granulargas analyze`` of a mixture: the species' temperatures against kinetic theory."""

import json

import numpy as np
import pytest

from granulargas.analysis.species import analyze_species
from granulargas.cli import main
from granulargas.io.config import parse_config
from granulargas.run.runner import run_config
from granulargas.theory.mixture import hcs_temperature_ratios

MIXTURE = """
[system]
dimension = 3
particles = 6000
packing_fraction = 0.005
seed = 2

[[species]]
name = "heavy"
fraction = 0.5
mass = 4.0

[[species]]
name = "light"
fraction = 0.5

[collision]
model = "{model}"
{law}

[run]
collisions_per_particle = 40
method = "dsmc"

[output]
file = "{out}"
snapshots = 4
"""


@pytest.fixture(scope="module")
def dsmc_file(tmp_path_factory):
    out = tmp_path_factory.mktemp("species") / "mix.h5"
    text = MIXTURE.replace("{model}", "constant").replace("{law}", "restitution = 0.8").replace("{out}", str(out))
    run_config(parse_config(text, "mix.toml"))
    return out


def test_species_analysis_against_garzo_dufty(dsmc_file):
    from granulargas.io.h5md import load_snapshot

    snap = load_snapshot(dsmc_file, 0)
    sa = analyze_species(dsmc_file, snap.box, 3)
    assert sa.names == ("heavy", "light")
    want = hcs_temperature_ratios([4.0, 1.0], [1.0, 1.0], [0.5, 0.5], 0.8)
    assert sa.steady[0] / sa.steady[1] == pytest.approx(want[0] / want[1], rel=1e-3)  # chi_ij ~ 1.01: dilute
    (m, e), = sa.late()
    assert m == pytest.approx(want[0] / want[1], rel=0.02)
    # the prediction starts at the measured first sample and ends at the steady state
    assert sa.theory_ratios[0, 0] == pytest.approx(sa.ratios[0, 0], rel=1e-9)
    assert sa.theory_ratios[-1, 0] == pytest.approx(sa.steady[0] / sa.steady[1], rel=1e-3)
    assert np.triu(sa.collisions).sum() == 6000 * 40 // 2


def test_analyze_reports_and_draws_the_species(dsmc_file, tmp_path, capsys):
    png = tmp_path / "mix.png"
    assert main(["analyze", str(dsmc_file), "--plot", str(png), "--no-snapshots"]) == 0
    out = capsys.readouterr().out
    assert "T_heavy/T_light" in out and "Garzó & Dufty 1999" in out
    assert (tmp_path / "mix_species.png").stat().st_size > 10_000
    assert main(["analyze", str(dsmc_file), "--json", "--no-snapshots"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["species"]["names"] == ["heavy", "light"]
    assert summary["species"]["ratios_late"][0]["pair"] == "heavy/light"


def test_observables_table_names_the_species(dsmc_file):
    pytest.importorskip("pandas")
    import granulargas as gg

    df = gg.load_run(dsmc_file).observables()
    assert {"species_temperature_heavy", "species_temperature_light", "species_sonine_a2_heavy",
            "species_collisions_heavy_light"} <= set(df.columns)
    x = np.array([0.5, 0.5])
    mixed = df[["species_temperature_heavy", "species_temperature_light"]].to_numpy() @ x
    np.testing.assert_allclose(mixed, df["temperature"].to_numpy(), rtol=1e-12)
