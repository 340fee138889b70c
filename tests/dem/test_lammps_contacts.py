"""LAMMPS gas runs with the material stiffness, the pressure column and the contact dump.

The export's material stiffness is checked against the config's SI numbers; the contact
dump reader against a hand-made dump; with ``lmp`` installed, an elastic LAMMPS gas's
kinetic + contact elastic energy is conserved while its kinetic energy alone is not, its
collision count matches the engine's from the same initial state, and its pressure
column starts at the ideal-gas value.
"""

import math

import numpy as np
import pytest

from granulargas.cli import main
from granulargas.errors import ConfigError
from granulargas.dem.export import export_lammps
from granulargas.dem.lammps import DemContact, find_lmp, read_contacts, read_thermo, run_lammps
from granulargas.io.config import parse_config
from granulargas.run.prepare import reduced_prefactor
from tests.materials import RUBBER

needs_lmp = pytest.mark.skipif(find_lmp() is None, reason="LAMMPS executable `lmp` not installed (apt-get install lammps)")

MATERIAL = """
[system]
dimension = 3
particles = {n}
packing_fraction = 0.1
seed = 5

[collision]
model = "{model}"

{material}

[run]
end_time = {end}

[output]
observables_interval = {interval}
"""



def test_material_stiffness_is_the_configs_young_modulus_in_reduced_units(tmp_path):
    config = parse_config(MATERIAL.format(n=60, model="viscoelastic", material=RUBBER, end=1.0, interval=0.1))
    ex = export_lammps(config, tmp_path, contact_fraction=None, steps_per_contact=20)
    # Y d^3 / (m u^2), m = density pi d^3 / 6: 1e6 Pa (0.01 m)^3 / (5.236e-4 kg (0.5 m/s)^2)
    mass = 1000 * math.pi * 0.01**3 / 6
    assert ex.contact.young_modulus == pytest.approx(1e6 * 0.01**3 / (mass * 0.25), rel=1e-12)
    assert ex.contact.poisson_ratio == 0.3
    assert ex.contact.prefactor() == pytest.approx(reduced_prefactor(config), rel=1e-12)
    # the fraction the export reports is that of this stiffness
    t_c = ex.contact.hertz_contact_time(ex.thermal_speed, 0.25, 0.5)
    assert ex.contact_fraction == pytest.approx(t_c / ex.mean_free_time, rel=1e-12)
    assert ex.timestep <= t_c / 20 * (1 + 1e-12)


def test_material_stiffness_needs_a_material(tmp_path, capsys):
    text = MATERIAL.format(n=60, model="viscoelastic", material="", end=1.0, interval=0.1).replace(
        'model = "viscoelastic"', 'model = "viscoelastic"\ndamping = 0.1')
    with pytest.raises(ConfigError, match="collision.material"):
        export_lammps(parse_config(text), tmp_path, contact_fraction=None)
    p = tmp_path / "damping.toml"
    p.write_text(text)
    assert main(["export", "lammps", str(p), "-o", str(tmp_path / "out"), "--material-stiffness"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "collision.material" in err[0]


def _dump(path, frames):
    with open(path, "w") as fh:
        for step, rows in frames:
            fh.write(f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ENTRIES\n{len(rows)}\n"
                     "ITEM: BOX BOUNDS pp pp pp\n0 5\n0 5\n0 5\nITEM: ENTRIES c_a[1] c_a[2] c_b\n")
            for i, j, r in rows:
                fh.write(f"{i} {j} {r!r}\n")


def test_new_contacts_and_elastic_energy_of_a_dump(tmp_path):
    path = tmp_path / "contacts"
    # pair (1, 2) touches at step 1 and stays; (3, 1) at step 2 (listed in either order);
    # (1, 2) separates at step 3 and touches again at step 4
    _dump(path, [(0, []), (1, [(1, 2, 0.99)]), (2, [(2, 1, 0.98), (3, 1, 0.995)]),
                 (3, [(1, 3, 0.99)]), (4, [(1, 3, 0.999), (1, 2, 0.999)])])
    contact = DemContact(1000.0, 0.3, 0.0)
    radii = np.array([0.5, 0.5, 0.5])
    steps, new, elastic = read_contacts(path, radii, contact)
    assert steps.tolist() == [0, 1, 2, 3, 4]
    assert new.tolist() == [0, 1, 1, 0, 1]
    e_eff = 1000.0 / (2 * (1 - 0.09))

    def hertz(xi):  # (2/5) xi F(xi), F = (4/3) E_eff sqrt(R_eff) xi^(3/2), R_eff = 1/4
        return 0.4 * xi * (4 / 3) * e_eff * 0.5 * xi**1.5

    np.testing.assert_allclose(elastic, [0, hertz(0.01), hertz(0.02) + hertz(0.005), hertz(0.01),
                                         hertz(0.001) * 2], rtol=1e-9)
    assert read_contacts(path)[2] is None


@needs_lmp
def test_elastic_lammps_gas_conserves_kinetic_plus_contact_energy_and_counts_the_engines_collisions(tmp_path):
    from granulargas.io.h5md import read_observables
    from granulargas.run.prepare import initial_state
    from granulargas.run.runner import run_config

    # elastic spheres of a stiffness whose contact time is 1 % of the mean free time; thermo every 0.01
    text = MATERIAL.format(n=120, model="elastic", material="", end=5.0, interval=0.01)
    config = parse_config(text.replace("[output]\n", f'[output]\nfile = "{tmp_path / "edmd.h5"}"\n'))
    ex = export_lammps(config, tmp_path / "lammps", contact_fraction=0.01, steps_per_contact=40, pressure=True,
                       contact_pairs=True)
    run_lammps(ex.input_file)
    th = read_thermo(tmp_path / "lammps" / "log.lammps")
    state = initial_state(config)
    steps, new, elastic = read_contacts(tmp_path / "lammps" / "contacts.granulargas", state.radii, ex.contact)
    n = config.system.particles
    kinetic = 1.5 * n * th["c_granT"]
    stored = np.interp(th["Step"], steps, elastic)
    total = kinetic + stored
    assert np.ptp(kinetic) / kinetic[0] > 1e-3  # energy goes into the contacts and back
    assert np.ptp(total) / total[0] < 0.01 * np.ptp(kinetic) / kinetic[0]
    # collisions: the engine's hard-sphere count from the same initial state (fluctuations of a few %)
    summary = run_config(config, overwrite=True, quiet=True)
    assert new.sum() == pytest.approx(summary.collisions, rel=0.05)
    # pressure: averaged over each thermo interval; the first full window of a dilute gas is close to
    # n T (kinetic) + the Enskog collisional part; compare with the engine's window mean instead
    p_edmd = read_observables(summary.output)["pressure"][2][1:]
    assert np.mean(th["f_granP"][1:]) == pytest.approx(np.mean(p_edmd), rel=0.03)
