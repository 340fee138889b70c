"""A run built in Python and written with :class:`granulargas.run.record.RunWriter` is a file like
those of ``granulargas run``: analyze compares it with the theory of its model, restarts continue
it, export converts it; a file that does not record its model is refused with one line."""

import json

import numpy as np
import pytest

from granulargas import theory
from granulargas.cli import main
from granulargas.contact import restitution_table
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.io.h5md import H5MDWriter, read_parameters, snapshot_count
from granulargas.state import State

N, PACKING = 500, 0.1


def _rule(model):
    if model == "constant":
        return CollisionRule.constant(0.8)
    return CollisionRule.viscoelastic(prefactor=0.2, table=restitution_table(1.0))


def _simulation(model):
    st = random_state(n=N, packing=PACKING, dimension=3, seed=4)
    if model == "dsmc":  # velocities only, the density a setting
        return DSMC(State(None, st.velocities, st.radii, st.masses, None), _rule("constant"),
                    packing_fraction=PACKING, seed=4)
    return Simulation(st, _rule(model))


def _write(path, sim, t_end=10.0):
    from granulargas.run.record import RunWriter

    with RunWriter(path, sim) as out:
        for k, t in enumerate(np.linspace(t_end / 40, t_end, 40)):
            sim.run(until=t)
            out.sample()
            if k % 10 == 9:
                out.snapshot()
    return path


def _analyze(path, capsys):
    assert main(["analyze", str(path), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("model", ["constant", "viscoelastic", "dsmc"])
def test_a_python_run_is_analysed_against_the_theory_of_its_model(model, tmp_path, capsys):
    path = _write(tmp_path / "py.h5", _simulation(model))
    par = read_parameters(path)
    assert par["method"] == ("dsmc" if model == "dsmc" else "edmd")
    assert par["collision"]["model"] == ("constant" if model == "dsmc" else model)
    assert snapshot_count(path) == 5  # the starting state and 4 frames
    s = _analyze(path, capsys)
    assert s["kind"] == "cooling" and s["scene"]["method"] == par["method"]
    assert abs(s["T_ratio_final"] - 1.0) < 0.05
    if model != "viscoelastic":  # against Haff's law in closed form (Enskog rate, van Noije-Ernst a2)
        n = N / float(np.prod(random_state(n=N, packing=PACKING, dimension=3, seed=4).box))
        tau0 = theory.haff_tau0(0.8, n, 1.0, 3)
        assert s["T_final"] == pytest.approx(theory.haff_temperature(10.0, 1.0, tau0), rel=0.05)


def test_a_python_run_continues_from_a_config_and_exports(tmp_path, capsys):
    path = _write(tmp_path / "py.h5", _simulation("constant"))
    cfg = tmp_path / "c.toml"
    cfg.write_text(f'[system]\ndimension = 3\nparticles = {N}\npacking_fraction = {PACKING}\n'
                   '[collision]\nmodel = "constant"\nrestitution = 0.8\n[run]\nend_time = 12.0\n'
                   f'[output]\nfile = "{tmp_path / "more.h5"}"\n')
    assert main(["run", str(cfg), "--restart", str(path), "--quiet"]) == 0
    capsys.readouterr()
    s = _analyze(tmp_path / "more.h5", capsys)
    assert s["t_start"] == pytest.approx(10.0) and s["t_final"] == pytest.approx(12.0)
    pytest.importorskip("gsd")
    assert main(["export", "gsd", str(path)]) == 0
    assert "5 frames" in capsys.readouterr().out


def test_a_file_without_its_model_is_refused_with_one_line(tmp_path, capsys):
    # what H5MDWriter alone writes: a cooling gas, but no parameters/collision
    sim = _simulation("constant")
    path = tmp_path / "bare.h5"
    with H5MDWriter(path, sim.state) as w:
        for k in range(3):
            sim.run(until=5.0 * k)
            sim.synchronise()
            w.write_observables(sim.events, sim.time, {"temperature": sim.temperature,
                                                       "kinetic_energy": sim.kinetic_energy,
                                                       "collisions": sim.collisions})
            w.write_state(sim.state)
    assert sim.temperature < 0.5  # it cooled: an elastic analysis would report an energy drift
    for args in (["analyze", str(path)], ["analyze", str(path), "--json"]):
        assert main(args) == 2
        out, err = capsys.readouterr()
        assert out == "" and len(err.strip().splitlines()) == 1
        assert "records no collision model" in err and "RunWriter" in err and "drift" not in err
