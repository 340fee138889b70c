"""``granulargas export lammps``: the files say what the config says.

The data file and input are parsed here with a small independent reader of
the LAMMPS formats (always); when ``lmp`` is installed, LAMMPS itself reads
them and reports the initial granular temperature.
"""

import json
import math

import numpy as np
import pytest

from granulargas.cli import main
from granulargas.errors import UserError
from granulargas.io.config import parse_config
from granulargas.dem.export import export_lammps
from granulargas.dem.lammps import HERTZ_DURATION, enskog_mean_free_time, find_lmp, read_thermo, run_lammps
from granulargas.run.prepare import fresh_state, reduced_prefactor

needs_lmp = pytest.mark.skipif(find_lmp() is None, reason="LAMMPS executable `lmp` not installed (apt-get install lammps)")


def config_text(dimension=3, particles=120, end="force", extra="", boundary=None):
    walls = "" if boundary is None else "boundary = [" + ", ".join(f'"{b}"' for b in boundary) + "]"
    return f"""
[system]
dimension = {dimension}
particles = {particles}
packing_fraction = 0.1
seed = 11
{walls}

[collision]
model = "viscoelastic"
damping = 0.2
contact_end = "{end}"

[run]
end_time = 0.5
{extra}
"""


def read_data_file(path):
    """Minimal reader of a LAMMPS data file (atom_style sphere, Velocities)."""
    lines = path.read_text().splitlines()
    out = {"box": {}}
    k = 1
    while k < len(lines):
        words = lines[k].split()
        if len(words) == 2 and words[1] == "atoms":
            out["atoms"] = int(words[0])
        elif len(words) == 3 and words[1:] == ["atom", "types"]:
            out["types"] = int(words[0])
        elif len(words) == 4 and words[2].endswith("lo"):
            out["box"][words[2][0]] = (float(words[0]), float(words[1]))
        elif words and words[0] in ("Atoms", "Velocities"):
            name = words[0]
            rows = [ln.split() for ln in lines[k + 2:k + 2 + out["atoms"]]]
            out[name] = np.array(rows, dtype=float)
            k += 1 + out["atoms"]
        k += 1
    return out


def read_input(path):
    """Commands of a LAMMPS input: {command: [argument lists]}."""
    cmds = {}
    for line in path.read_text().splitlines():
        words = line.split("#")[0].split()
        if words:
            cmds.setdefault(words[0], []).append(words[1:])
    return cmds


@pytest.mark.parametrize("dimension", [2, 3])
def test_export_matches_config(tmp_path, dimension):
    config = parse_config(config_text(dimension))
    ex = export_lammps(config, tmp_path, contact_fraction=0.02, steps_per_contact=40)
    state = fresh_state(config)  # what `granulargas run` starts from
    n = config.system.particles

    data = read_data_file(ex.data_file)
    assert data["atoms"] == n and data["types"] == 1
    atoms, vel = data["Atoms"], data["Velocities"]
    np.testing.assert_array_equal(atoms[:, 0], np.arange(1, n + 1))
    np.testing.assert_allclose(atoms[:, 2], 2 * state.radii, rtol=1e-15)
    np.testing.assert_allclose(atoms[:, 4:4 + dimension], state.positions, rtol=1e-15)
    np.testing.assert_allclose(vel[:, 1:1 + dimension], state.velocities, rtol=1e-15)
    if dimension == 2:
        assert np.all(atoms[:, 6] == 0) and np.all(vel[:, 3:] == 0)
        assert data["box"]["z"][0] < 0 < data["box"]["z"][1]
    for axis, edge in zip("xyz", state.box):
        assert data["box"][axis] == (0.0, pytest.approx(edge, rel=1e-15))

    cmds = read_input(ex.input_file)
    assert cmds["dimension"] == [[str(dimension)]]
    assert cmds["read_data"] == [[ex.data_file.name]]
    assert cmds["set"] == [["type", "1", "mass", "1"]]
    assert ("enforce2d" in " ".join(sum(cmds["fix"], []))) == (dimension == 2)
    (pc,) = cmds["pair_coeff"]
    Y, eta_n0, nu = float(pc[3]), float(pc[4]), float(pc[5])
    assert pc[2] == "hertz/material" and pc[6:8] == ["damping", "viscoelastic"] and pc[-1] == "limit_damping"
    # mapping (docs/interoperability.md): E = Y, eta_n0 = 3 A rho / (2 sqrt(R_eff)), and the
    # damping of the config: beta(g = 1, reference pair) = (3/2) A rho^{2/5} = 0.2
    r_eff, m_eff = 0.25, 0.5
    rho = 2 * Y * math.sqrt(r_eff) / (3 * m_eff * (1 - nu**2))
    A = eta_n0 * 2 * math.sqrt(r_eff) / (3 * rho)
    assert 1.5 * A * rho**0.4 == pytest.approx(0.2, rel=1e-12)
    assert ex.contact.prefactor() == pytest.approx(reduced_prefactor(config), rel=1e-12)
    # stiffness: Hertz contact time at g_T = sqrt(2 T0 / m_eff) = 2 is 2 % of the mean free time
    t_c = HERTZ_DURATION * rho**-0.4 * 2.0**-0.2
    assert t_c == pytest.approx(0.02 * enskog_mean_free_time(dimension, 0.1), rel=1e-9)
    dt = float(cmds["timestep"][0][0])
    steps = int(cmds["run"][0][0])
    assert dt <= t_c / 40 * (1 + 1e-12) and dt > t_c / 41
    assert steps * dt == pytest.approx(0.5, rel=1e-12)
    assert cmds["compute"] == [["granT", "all", "temp/com"]]
    summary = json.loads((tmp_path / "granulargas_lammps.json").read_text())
    assert summary["young_modulus"] == pytest.approx(Y, rel=1e-15)


@pytest.mark.parametrize("dimension, boundary", [(3, ("periodic", "periodic", "wall")),
                                                 (2, ("wall", "wall"))])
def test_walls_become_fixed_boundaries_with_a_wall_fix_of_the_same_contact(tmp_path, dimension, boundary):
    config = parse_config(config_text(dimension, boundary=boundary))
    ex = export_lammps(config, tmp_path)
    cmds = read_input(ex.input_file)
    want = ["f" if b == "wall" else "p" for b in boundary] + (["p"] if dimension == 2 else [])
    assert cmds["boundary"] == [want]
    state = fresh_state(config)
    (pc,) = cmds["pair_coeff"]
    walls = [f for f in cmds["fix"] if f[2] == "wall/gran"]
    assert len(walls) == boundary.count("wall")
    for f in walls:
        axis = "xyz".index(f[-3][0])
        assert f[1] == "type1" and f[3] == "granular" and f[-3] == f"{'xyz'[axis]}plane"
        assert float(f[-2]) == 0.0 and float(f[-1]) == pytest.approx(state.box[axis], rel=1e-15)
        # the pair's model with eta_n0 for m_eff = m (sphere-plane) instead of m/2
        model = f[4:-3]
        assert model[0] == "hertz/material" and model[4:] == pc[6:]
        assert float(model[2]) == pytest.approx(0.5 * float(pc[4]), rel=1e-15)
        assert model[1] == pc[3] and model[3] == pc[5]
    data = read_data_file(ex.data_file)
    for a, b in enumerate(boundary):
        if b == "wall":  # every sphere within [R, L - R]
            z = data["Atoms"][:, 4 + a]
            r = data["Atoms"][:, 2] / 2
            assert np.all(z >= r) and np.all(z <= state.box[a] - r)


def test_driven_config_is_refused(tmp_path):
    config = parse_config(config_text(extra="\n[driving]\nheating_rate = 0.1\n"))
    with pytest.raises(UserError, match="driving"):
        export_lammps(config, tmp_path)


def test_rough_config_is_refused(tmp_path):
    config = parse_config(config_text(extra="\n[collision.tangential]\nrestitution = 0.0\n"))
    with pytest.raises(UserError, match="collision.tangential"):
        export_lammps(config, tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_overlap_end_has_no_limit_damping(tmp_path):
    ex = export_lammps(parse_config(config_text(end="overlap")), tmp_path)
    (pc,) = read_input(ex.input_file)["pair_coeff"]
    assert "limit_damping" not in pc


def test_unequal_masses_get_one_eta_per_type_pair(tmp_path):
    from granulargas.dem.lammps import write_lammps_gas

    rng = np.random.default_rng(0)
    n, L = 40, 12.0
    masses = np.where(np.arange(n) % 2 == 0, 1.0, 3.0)
    ex = write_lammps_gas(tmp_path, rng.uniform(0, L, (n, 3)), rng.normal(size=(n, 3)), np.full(n, 0.5), masses,
                          np.full(3, L), 0.15, end_time=0.1)
    cmds = read_input(ex.input_file)
    assert cmds["set"] == [["type", "1", "mass", "1"], ["type", "2", "mass", "3"]]
    eta = {(int(a[0]), int(a[1])): float(a[4]) for a in cmds["pair_coeff"]}
    A, Yr = ex.contact.dissipation_time, ex.contact.reduced_modulus
    for (i, j), m_eff in {(1, 1): 0.5, (1, 2): 0.75, (2, 2): 1.5}.items():
        assert eta[(i, j)] == pytest.approx(A * Yr / m_eff, rel=1e-15)
    types = read_data_file(ex.data_file)["Atoms"][:, 1]
    np.testing.assert_array_equal(types, np.where(masses == 1.0, 1, 2))


def test_too_many_masses_is_refused(tmp_path):
    config = parse_config(config_text(extra="\n[particles]\ndiameter = { min = 0.8, max = 1.2 }\ndensity = 1.9\n"))
    with pytest.raises(UserError, match="distinct particle masses"):
        export_lammps(config, tmp_path)


def test_cli(tmp_path, capsys):
    cfg = tmp_path / "gas.toml"
    cfg.write_text(config_text())
    out = tmp_path / "lmp"
    assert main(["export", "lammps", str(cfg), "-o", str(out), "--contact-fraction", "0.05"]) == 0
    assert (out / "in.granulargas").exists() and (out / "data.granulargas").exists()
    assert "0.05 x mean free time" in capsys.readouterr().out
    bad = tmp_path / "const.toml"
    bad.write_text(config_text().replace('model = "viscoelastic"', 'model = "constant"\nrestitution = 0.9')
                   .replace("damping = 0.2\n", "").replace('contact_end = "force"\n', ""))
    assert main(["export", "lammps", str(bad), "-o", str(out)]) == 2
    assert "constant" in capsys.readouterr().err
    assert main(["export", "lammps", str(cfg), "-o", str(out), "--contact-fraction", "2"]) == 2


@needs_lmp
@pytest.mark.parametrize("dimension", [2, 3])
def test_lammps_reads_export(tmp_path, dimension):
    """LAMMPS parses the files; its initial temperature is ours (mass, velocities, dof)."""
    config = parse_config(config_text(dimension))
    ex = export_lammps(config, tmp_path, end_time=0.02)
    text = run_lammps(ex.input_file)
    assert f"{config.system.particles} atoms" in text
    th = read_thermo(tmp_path / "log.lammps")
    assert th["c_granT"][0] == pytest.approx(config.initial.temperature, rel=1e-9)
    assert th["Time"][-1] == pytest.approx(0.02, rel=1e-9)
    assert th["c_granT"][-1] <= th["c_granT"][0]


@needs_lmp
@pytest.mark.parametrize("dimension, end_time, boundary", [
    (3, 3.0, None), (2, 8.0, None), (3, 3.0, ("periodic", "periodic", "wall"))])
def test_lammps_cools_like_granulargas(tmp_path, dimension, end_time, boundary):
    """Same initial state, same contact law: T(t) of LAMMPS (t_c = 1 % of the mean free
    time) and of our event-driven run agree within the run-to-run fluctuation.

    N = 1000, packing 0.1, damping 0.1, until T has dropped to ~0.65-0.7. Two
    runs from one initial state decorrelate after a few collisions, so they
    differ by the spread between independent runs: max over time of
    |T_LAMMPS / T_ours - 1| is about 0.5-2 % (single runs; over 8 seeds at N = 2000
    in 3D the mean difference is +0.5 +- 0.4 %, scripts/lammps/cooling_gas.py --ensemble). A factor
    1.5 error in the damping mapping moves T(t_end) by 10-20 %; the tolerance is 4 %.
    With walls on z (LAMMPS ``fix wall/gran``, the engine's sphere-plane contact) too.
    """
    from granulargas.io.h5md import read_observables
    from granulargas.run.runner import run_config

    text = config_text(dimension, particles=1000, boundary=boundary).replace("damping = 0.2", "damping = 0.1")
    text = text.replace("end_time = 0.5", f"end_time = {end_time}")
    text += f'\n[output]\nfile = "{tmp_path / "ed.h5"}"\nsnapshots = 2\nobservables_interval = 0.1\n'
    config = parse_config(text)
    run_config(config, quiet=True)
    _, t, T = read_observables(tmp_path / "ed.h5")["temperature"]
    ex = export_lammps(config, tmp_path / "lmp", contact_fraction=0.01)
    run_lammps(ex.input_file)
    th = read_thermo(tmp_path / "lmp" / "log.lammps")
    assert th["Time"][-1] == pytest.approx(end_time)
    assert T[-1] < 0.75  # it did cool
    T_lammps = np.interp(t, th["Time"], th["c_granT"])
    assert np.max(np.abs(T_lammps / T - 1.0)) < 0.04


def test_export_from_a_restart_file(tmp_path):
    """initial.from: LAMMPS starts from the file's last snapshot and runs the remaining time."""
    from granulargas.io.h5md import load_snapshot
    from granulargas.run.runner import run_config

    h5 = tmp_path / "first.h5"
    run_config(parse_config(config_text() + f'\n[output]\nfile = "{h5}"\nsnapshots = 2\n'), quiet=True)
    snap = load_snapshot(h5)
    config = parse_config(config_text().replace("end_time = 0.5", "end_time = 1.25")
                          + f'\n[initial]\nfrom = "{h5}"\n')
    ex = export_lammps(config, tmp_path / "lmp")
    data = read_data_file(ex.data_file)
    np.testing.assert_allclose(data["Atoms"][:, 4:7], snap.positions, rtol=1e-15)
    np.testing.assert_allclose(data["Velocities"][:, 1:4], snap.velocities, rtol=1e-15)
    assert ex.steps * ex.timestep == pytest.approx(1.25 - snap.time, rel=1e-12)
    assert f"granulargas time {snap.time:.17g}" in ex.input_file.read_text()


def test_polydisperse_equal_masses_is_one_type(tmp_path):
    """eta_n0 depends on m_eff only, so per-atom diameters with a common mass need one type."""
    config = parse_config(config_text(extra="\n[particles]\ndiameter = { min = 0.8, max = 1.2 }\nmass = 1.0\n"))
    ex = export_lammps(config, tmp_path)
    data = read_data_file(ex.data_file)
    assert data["types"] == 1
    np.testing.assert_allclose(data["Atoms"][:, 2], 2 * fresh_state(config).radii, rtol=1e-15)
    assert data["Atoms"][:, 2].std() > 0.05


GLASS_STEEL = """
[system]
dimension = 3
packing_fraction = 0.1
seed = 5

[[species]]
name = "glass"
count = 70
young_modulus = 6.3e10
poisson_ratio = 0.24
dissipation_time = 1e-7

[[species]]
name = "steel"
count = 50
diameter = 0.8
material_density = 7800
young_modulus = 2.1e11
poisson_ratio = 0.29
dissipation_time = 5e-8

[collision]
model = "viscoelastic"

[collision.material]
diameter = 1e-3
density = 2500
speed_unit = 1.0

[run]
end_time = 0.2
"""


@pytest.mark.parametrize("stiffness", ["contact_fraction", "material"])
def test_export_of_a_mixture_has_a_type_and_a_contact_per_species(tmp_path, stiffness):
    """Species are atom types; each pair of types has its own contact: the pair's prefactor k_ij
    (read back from E, eta_n0, nu of its pair_coeff line), and on the material route the pair's
    effective modulus 1/Y* = (1 - nu_i^2)/Y_i + (1 - nu_j^2)/Y_j (E / (1 - nu^2) = 2 Y*)."""
    from granulargas.contact.material import effective_modulus
    from granulargas.run.prepare import pair_prefactors, reference_mass_si

    config = parse_config(GLASS_STEEL)
    fraction = 0.02 if stiffness == "contact_fraction" else None
    ex = export_lammps(config, tmp_path, contact_fraction=fraction)
    data = read_data_file(ex.data_file)
    assert data["types"] == 2
    np.testing.assert_array_equal(data["Atoms"][:, 1], [1] * 70 + [2] * 50)
    cmds = read_input(ex.input_file)
    steel_mass = 7800 / 2500 * 0.8**3
    assert cmds["set"] == [["type", "1", "mass", "1"], ["type", "2", "mass", repr(steel_mass)]]
    masses = {1: 1.0, 2: steel_mass}
    k = pair_prefactors(config)
    m = config.collision.material
    unit = m.diameter**3 / (reference_mass_si(m) * m.speed_unit**2)
    consts = {1: (6.3e10, 0.24), 2: (2.1e11, 0.29)}
    for pc in cmds["pair_coeff"]:
        i, j = int(pc[0]), int(pc[1])
        Y, eta_n0, nu = float(pc[3]), float(pc[4]), float(pc[5])
        m_eff = masses[i] * masses[j] / (masses[i] + masses[j])
        A = eta_n0 * m_eff * (1 - nu**2) / Y  # eta_n0 = A Y / ((1 - nu^2) m_eff)
        k_back = 1.5 * A * (2 * Y / (3 * (1 - nu**2))) ** 0.4
        assert k_back == pytest.approx(k[i - 1, j - 1], rel=1e-12)
        if stiffness == "material":
            y_star = effective_modulus(*consts[i], *consts[j]) * unit
            assert Y / (1 - nu**2) == pytest.approx(2 * y_star, rel=1e-12)
    assert len(cmds["pair_coeff"]) == 3
