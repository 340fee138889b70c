"""Runs with collisions that take time (`[collision] duration = "resolved"`): config checks,
restart equality with contacts under way in the file, the three-body observable."""

import numpy as np
import pytest

from granulargas.cli import main
from granulargas.io.config import load_config
from granulargas.io.h5md import load_snapshot, read_observables, read_parameters
from granulargas.run.runner import run_config
from tests.materials import RUBBER

#: a soft rubber-like material: t_c / t_free ~ 0.1 at packing 0.1
RESOLVED = """
[system]
dimension = 3
particles = 200
packing_fraction = 0.1
seed = 3

[collision]
model = "viscoelastic"
duration = "resolved"

""" + RUBBER + """
[run]
end_time = 4.0

[output]
file = "{out}"
snapshot_interval = 1.0
observables_interval = 0.5
"""


def test_restart_equals_uninterrupted_run(write_config, tmp_path):
    """run to 2t == run to t + restart to 2t, with the contacts under way stored in the file."""
    path = write_config(RESOLVED)
    full = run_config(load_config(path))
    half = run_config(load_config(path, {"run.end_time": 2.0, "output.file": str(tmp_path / "half.h5")}))
    mid = load_snapshot(half.output)
    assert mid.contact_until is not None and np.any(mid.contact_until > mid.time)  # a contact under way at t
    rest = run_config(load_config(path, {"initial.from": str(half.output), "output.file": str(tmp_path / "rest.h5")}))
    assert (rest.collisions, rest.events) == (full.collisions, full.events)
    assert rest.three_body_contacts == full.three_body_contacts > 0
    a, b = load_snapshot(full.output), load_snapshot(rest.output)
    for name in ("positions", "velocities", "images", "contact_until", "contact_partner"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    oa, ob = read_observables(full.output), read_observables(rest.output)
    assert np.array_equal(oa["three_body_contacts"][2][-1:], ob["three_body_contacts"][2][-1:])
    # energy balance with the resolved collisions' losses
    ke, diss = oa["kinetic_energy"][2], oa["dissipated_energy"][2]
    assert np.allclose(ke + diss, ke[0], rtol=1e-12)
    par = read_parameters(full.output)
    assert par["collision"]["duration"] == "resolved" and par["summary"]["three_body_contacts"] > 0
    assert par["collision"]["compression"] > 0


def test_append_continues_the_contacts(write_config, tmp_path):
    path = write_config(RESOLVED)
    full = run_config(load_config(path, {"output.file": str(tmp_path / "full.h5")}))
    part = tmp_path / "part.h5"
    run_config(load_config(path, {"run.end_time": 2.0, "output.file": str(part)}))
    cont = run_config(load_config(path, {"initial.from": str(part), "output.file": str(part)}), append=True)
    assert (cont.collisions, cont.events, cont.three_body_contacts) == (full.collisions, full.events,
                                                                       full.three_body_contacts)
    a, b = load_snapshot(full.output), load_snapshot(part)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.contact_until, b.contact_until)


@pytest.mark.parametrize("change, message", [
    ('young_modulus = 1e6', "needs the contact stiffness"),
    ('model = "viscoelastic"', 'needs model = "viscoelastic"'),
])
def test_resolved_without_stiffness_is_refused(write_config, capsys, change, message):
    text = RESOLVED
    if "young" in change:  # damping instead of the material
        text = text[:text.index("[collision.material]")] + "damping = 0.1\n\n" + text[text.index("[run]"):]
    else:
        text = text.replace(change, 'model = "constant"\nrestitution = 0.9')
        text = text[:text.index("[collision.material]")] + text[text.index("[run]"):]
    path = write_config(text)
    assert main(["run", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0] and "collision.duration" in err[0]


def test_resolved_with_walls_is_refused(write_config, capsys):
    text = RESOLVED.replace("seed = 3", 'seed = 3\nboundary = ["periodic", "periodic", "wall"]')
    assert main(["run", str(write_config(text))]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "periodic boundaries only" in err[0]


def test_advise_keeps_a_resolved_config_on_edmd(write_config):
    from granulargas.run.advise import advise

    adv = advise(load_config(write_config(RESOLVED)))
    text = "\n".join(adv.lines())
    assert 'EDMD (run.method = "edmd"): collisions that take time need positions' in text
    # the contact-time ratio (0.168 at T0) decides the duration; constant eps is never offered
    assert "duration     " in text and "t_c/t_free = 0.168" in text and 'model = "constant"' not in text


@pytest.mark.parametrize("three_body, says_dem", [(100, False), (300, True)])
def test_summary_says_dem_beyond_the_three_body_share_checked_against_lammps(three_body, says_dem):
    from pathlib import Path

    from granulargas.run.advise import RESOLVED_THREE_BODY_CHECKED
    from granulargas.run.runner import RunSummary

    summary = RunSummary(Path("x.h5"), 1000, 2000, 1.0, 1.0, 1000.0, 1.0, 2, "end time", particles=100,
                         three_body_contacts=three_body)
    assert (three_body / 1000 > RESOLVED_THREE_BODY_CHECKED) == says_dem
    line = next(ln for ln in summary.lines() if ln.startswith("three-body"))
    assert ("use DEM" in line) == says_dem


def test_resolved_with_cell_crossings_is_refused_and_auto_uses_lists(write_config, capsys):
    text = RESOLVED.replace("end_time = 4.0", 'end_time = 4.0\nneighbours = "cells"')
    assert main(["run", str(write_config(text))]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "run.neighbours" in err[0] and "neighbour lists" in err[0]
    # "auto" at this packing (0.1) keeps the resolved rule on lists
    from granulargas.run.prepare import prepare
    from granulargas.engine import Simulation

    setup = prepare(load_config(write_config(RESOLVED, name="auto.toml")))
    st = setup.state
    sim = Simulation(st, setup.rule, neighbours="auto")
    assert sim.neighbours == "lists"
