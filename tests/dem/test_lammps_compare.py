"""Smoke test of scripts/lammps/cooling_gas.py on a tiny gas (keeps the script from rotting)."""

import importlib.util
import json
from pathlib import Path

import pytest

from granulargas.dem.lammps import find_lmp

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "lammps" / "cooling_gas.py"


def load_script():
    spec = importlib.util.spec_from_file_location("compare_lammps", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow  # ~15 s, mostly matplotlib
def test_compare_script_tiny(tmp_path):
    script = load_script()
    figure = tmp_path / "cooling.png"
    script.main([str(SCRIPT.parents[2] / "configs" / "viscoelastic_3d.toml"), "--end-time", "0.5",
                 "--set", "system.particles=300", "--fractions", "0.05", "--repeats", "1", "--seeds", "2",
                 "--workdir", str(tmp_path / "work"), "--figure", str(figure)])
    assert figure.stat().st_size > 10_000
    results = json.loads((tmp_path / "work" / "results.json").read_text())
    assert results["particles"] == 300 and results["granulargas"]["T_end"] < 1.0
    if find_lmp() is None:
        assert results["lammps"] == []
    else:
        (dem,) = results["lammps"]
        assert dem["contact_fraction"] == 0.05 and dem["max_rel_dev"] < 0.05
