"""Oblique two-sphere collisions in LAMMPS against the resolved-contact table (granulargas.contact.oblique).

LAMMPS ``pair_style granular`` (hertz/material + damping viscoelastic, no
tangential force) integrates the same central force with velocity Verlet, so
its velocities, contact duration and outgoing line must converge to the
table's at first order in the time step. The instantaneous collision at first
touch is far off at these parameters, so agreement is not an accident of the
geometry. The LAMMPS tests need ``lmp`` and skip with a reason otherwise.
"""

import importlib.util
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from granulargas.dem.lammps import DemContact, find_lmp, oblique_input, stiffness_for_compression

needs_lmp = pytest.mark.skipif(find_lmp() is None,
                               reason="LAMMPS executable `lmp` not installed (apt-get install lammps)")
SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "lammps" / "oblique_collisions.py"


def load_script():
    spec = importlib.util.spec_from_file_location("oblique_lammps", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_stiffness_for_compression_gives_delta():
    cases = [(0.05, 1.0, 0.25, 0.5, 1.0), (0.2, 0.3, 0.21, 0.345, 1.0), (1e-3, 4.0, 1, 2, 4)]
    for delta, g, r_eff, m_eff, dist in cases:
        young = stiffness_for_compression(delta, g, r_eff, m_eff, dist)
        rho = DemContact(young, 0.3, 0.0).rho(r_eff, m_eff)
        assert (g * g / rho) ** 0.4 / dist == pytest.approx(delta, rel=1e-13)


def test_oblique_input_sets_the_relative_velocity():
    contact = DemContact.from_beta(0.5, 1.0, 1e4, 0.21, 0.4 * 2.5 / 2.9)
    text = oblique_input(contact, 1.3, 0.7, 1e-4, 10, radii=(0.3, 0.7), masses=(0.4, 2.5))
    values = {}
    for line in text.splitlines():
        w = line.split()
        if w[:2] == ["set", "atom"] and w[3] in ("vx", "vy"):
            values[(int(w[2]), w[3])] = float(w[4])
    assert values[(1, "vx")] - values[(2, "vx")] == pytest.approx(1.3, rel=1e-15)
    assert values[(1, "vy")] - values[(2, "vy")] == pytest.approx(0.7, rel=1e-15)
    assert 0.4 * values[(1, "vx")] + 2.5 * values[(2, "vx")] == pytest.approx(0.0, abs=1e-15)
    assert "boundary m m m" in text and "thermo 1" in text
    assert contact.pair_coeff(1, 2, 0.4 * 2.5 / 2.9) in text


def test_script_refuses_without_lammps(tmp_path):
    env = {"GRANULARGAS_LMP": "no-such-lmp-executable", "PATH": "/usr/bin:/bin",
           "PYTHONPATH": str(SCRIPT.parents[2])}
    proc = subprocess.run([sys.executable, str(SCRIPT), "--workdir", str(tmp_path)], capture_output=True, text=True,
                          env=env, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "lmp" in proc.stderr
    proc = subprocess.run([sys.executable, str(SCRIPT), "--angles", "95"], capture_output=True, text=True, env=env,
                          timeout=120)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "angles" in proc.stderr


@needs_lmp
@pytest.mark.parametrize("end", ["overlap", "force"])
def test_lammps_converges_to_the_table(end, tmp_path, cache_dir):
    script = load_script()
    case = {"name": f"t-{end}", "end": end, "theta": 60.0, "beta": 0.5, "delta": 0.05, "radii": [0.5, 0.5],
            "masses": [1.0, 1.0], "all_betas": [0.5], "all_deltas": [0.05]}
    r = script.run_case(case, [200, 400, 800], tmp_path, {})
    err = {key: np.array([r["steps"][n][key] for n in (200, 400, 800)])
           for key in ("velocity_error", "duration_error", "intercept_error")}
    for key, e in err.items():
        ratios = e[:-1] / e[1:]
        assert np.all((ratios > 1.5) & (ratios < 2.6)), (key, e)  # first order in the time step
    assert err["velocity_error"][-1] < 2e-4
    assert err["duration_error"][-1] < 1e-3
    assert err["intercept_error"][-1] < 3e-3
    # Richardson extrapolation removes most of the first-order error
    assert r["richardson"]["velocity_error"] < 0.3 * err["velocity_error"][-1]
    # the instantaneous collision is hundreds of times further off
    assert r["instantaneous"]["velocity_error"] > 100 * err["velocity_error"][-1]
    assert r["instantaneous"]["intercept_error"] > 100 * err["intercept_error"][-1]


@needs_lmp
def test_unequal_spheres_grazing(tmp_path, cache_dir):
    """Radii 0.3 / 0.7, masses 0.4 / 2.5 (D != 4 R_eff), nearly grazing: c > 1, the spheres pass through
    each other's overlap along a chord; LAMMPS must still agree."""
    script = load_script()
    case = {"name": "grazing", "end": "overlap", "theta": 85.0, "beta": 0.3, "delta": 0.1, "radii": [0.3, 0.7],
            "masses": [0.4, 2.5], "all_betas": [0.3], "all_deltas": [0.1]}
    r = script.run_case(case, [200, 400], tmp_path, {})
    assert r["table"]["c"] > 1.0
    fine = r["steps"][400]
    assert fine["velocity_error"] < 1e-4 and fine["duration_error"] < 1e-3 and fine["intercept_error"] < 3e-3
    assert r["instantaneous"]["velocity_error"] > 0.05
    assert math.isfinite(r["richardson"]["velocity_error"])
