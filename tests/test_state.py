"""The state record (granulargas.state): conversions, shape checks, defaults, and a new line of
the per-particle field table becoming a field of the record, the engine's state and the H5MD
frame without further code."""

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from granulargas.errors import ConfigError
from granulargas.state import FIELDS, PARTICLE_FIELDS, STATE_FIELDS, DSMCContinuation, State

ROOT = Path(__file__).resolve().parents[1]


def test_every_table_entry_is_a_field_of_the_record():
    assert set(FIELDS) <= set(STATE_FIELDS)
    assert [f.name for f in PARTICLE_FIELDS][:5] == ["positions", "velocities", "images", "radii", "masses"]


def test_the_record_converts_to_the_table_dtypes():
    st = State([[0, 1, 2], [3, 4, 5]], [[1, 0, 0], [0, 1, 0]], 0.5, 2, [10, 10, 10],
               images=[[0, 0, 1], [0, -1, 0]], species=[0, 3], last_collision=[0, 1],
               time=1, collisions=2.0, kick_step=3.0)
    for f in PARTICLE_FIELDS:
        value = getattr(st, f.name)
        if value is not None:
            assert value.dtype == f.dtype and value.flags.c_contiguous, f.name
            assert value.shape == (2,) + f.shape(3), f.name
    assert st.radii.tolist() == [0.5, 0.5] and st.masses.tolist() == [2.0, 2.0]
    assert st.boundary == ("periodic",) * 3 and st.n == 2 and st.dimension == 3
    assert type(st.time) is float and type(st.collisions) is int and type(st.kick_step) is int
    assert st.contact_until is None and st.dsmc is None


def test_defaults_fill_absent_fields():
    st = State(None, np.zeros((4, 2)), 0.5, 1.0, None)
    assert st.array("species").dtype == np.int32 and not st.array("species").any()
    assert np.all(st.array("last_collision") == -np.inf)
    assert st.array("images").shape == (4, 2) and st.array("contact_partner").tolist() == [-1] * 4
    with pytest.raises(ConfigError, match="positions: this state has none"):
        st.array("positions")


@pytest.mark.parametrize("change, match", [
    (dict(images=np.zeros((3, 3))), r"images: shape \(3, 3\), expected \(2, 3\)"),
    (dict(radii=[0.5, 0.5, 0.5]), r"radii: shape \(3,\), expected \(2,\)"),
    (dict(positions=np.zeros((2, 2))), r"positions: shape \(2, 2\), expected \(2, 3\)"),
    (dict(box=[4.0, 4.0]), r"box: shape \(2,\), expected \(3,\)"),
])
def test_check_shapes_names_the_field(change, match):
    st = State(np.zeros((2, 3)), np.zeros((2, 3)), 0.5, 1.0, 4.0).replace(**change)
    with pytest.raises(ConfigError, match=match):
        st.check_shapes()


@pytest.mark.parametrize("velocities, match", [(np.zeros((3, 4)), "expected"), (None, "every state has velocities")])
def test_velocities_are_required_and_2d_or_3d(velocities, match):
    with pytest.raises(ConfigError, match=match):
        State(None, velocities, 0.5, 1.0, None)


def test_replace_keeps_the_rest_and_the_original():
    st = State(np.zeros((2, 3)), np.ones((2, 3)), 0.5, 1.0, 4.0, time=2.0, collisions=5)
    new = st.replace(time=3.0)
    assert (new.time, new.collisions, st.time) == (3.0, 5, 2.0)
    assert new.velocities is st.velocities


def test_dsmc_continuation_converts():
    c = DSMCContinuation(rng=[1, 2, 3, 4, 5], candidates=7.0, pending_pair=np.array([1, 2]), pending_time=3,
                         frame_velocity=[0, 0, 0])
    assert c.rng.dtype == np.uint64 and c.pending_pair == (1, 2) and type(c.candidates) is int


# a new line of the table, in a copy of the package: a per-frame vector field and a static one
_NEW_LINES = '''
    ParticleField("spins", np.float64, lambda d: (3,) if d == 3 else (1,), 0.0, "spin", True, False, "spins"),
    ParticleField("charges", np.float64, _scalar, 0.0, "charge", False, False, "charges"),
'''

_CHECK = textwrap.dedent('''
    import sys
    import numpy as np
    from granulargas.engine import CollisionRule, Simulation
    from granulargas.errors import ConfigError
    from granulargas.initial import random_state
    from granulargas.io.h5md import H5MDWriter, read_state

    st = random_state(20, 0.1, 2, seed=1)
    assert st.spins is None and st.charges is None
    spins, charges = np.arange(20.0)[:, None], np.linspace(-1.0, 1.0, 20)
    st = st.replace(spins=spins, charges=charges)
    sim = Simulation(st, CollisionRule.elastic())
    assert np.array_equal(sim.state.spins, spins) and np.array_equal(sim.state.charges, charges)
    try:
        Simulation(st.replace(spins=np.zeros((20, 3))), CollisionRule.elastic())
        raise SystemExit("a wrong shape was taken")
    except ConfigError as exc:
        assert "spins: shape (20, 3), expected (20, 1)" in str(exc), exc
    for fields, stored in ((("spins",), spins), ((), None)):
        path = sys.argv[1] + f"/f{len(fields)}.h5"
        with H5MDWriter(path, sim.state, fields=fields) as w:
            w.write_observables(0, 0.0, {"collisions": 0, "dissipated_energy": 0.0})
            w.write_state(sim.state)
        back = read_state(path)
        assert np.array_equal(back.charges, charges)
        assert (back.spins is None) if stored is None else np.array_equal(back.spins, stored)
        assert np.array_equal(back.positions, sim.state.positions)
    print("ok")
''')


def test_a_new_line_of_the_table_is_a_field_of_record_engine_and_file(tmp_path):
    """One line added to PARTICLE_FIELDS (in a copy of the package) makes a field of State that
    the engine checks and carries through and that H5MD writes and reads back."""
    shutil.copytree(ROOT / "granulargas", tmp_path / "granulargas",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    path = tmp_path / "granulargas" / "state.py"
    text = path.read_text()
    anchor = '                  "the partners of contacts under way (collisions that take time; -1: none)"),\n'
    assert anchor in text
    path.write_text(text.replace(anchor, anchor + _NEW_LINES))
    env = dict(os.environ, PYTHONPATH=str(tmp_path), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    out = subprocess.run([sys.executable, "-c", _CHECK, str(tmp_path)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stdout + out.stderr
