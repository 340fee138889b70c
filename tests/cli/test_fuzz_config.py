"""Any config, any value: mutated configs through the real commands (property-based).

A valid small config (:data:`tests.cli.fuzzing.BASES`) gets 1 to 3 mutations (any
key to any TOML value, the ends of float64/int64 and of every range the schema
declares, keys and sections dropped, unknown keys and sections added, some of them
as ``--set`` overrides) and goes through ``granulargas run``, ``advise``, ``export
lammps`` and the sweep file loader, in this process through ``granulargas.cli.main``.
Every example must end with exit 0, 2 (one line on stderr naming the key or the
file, nothing created, nothing changed) or 3 (a run that cannot continue), within a
wall-clock bound (after it SIGINT stops a legal long run at a chunk boundary: exit
130, the state kept); never a traceback. The default run checks a few hundred
examples (derandomised); ``-m slow`` checks thousands.

Each bug the property found has an ``@example`` beside it.
"""

from __future__ import annotations

import copy
import math
import tempfile
from pathlib import Path

import h5py
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from tests.cli.fuzzing import (
    BASES,
    EXTREMES,
    GENERAL_BASES,
    SHEAR_BASES,
    MutatedConfig,
    Mutation,
    _apply,
    _snapshot_tree,
    _toml_values,
    _value,
    check_outcome,
    invoke,
    mutated_config,
    to_toml,
)

#: wall-clock bound of one in-process example (s): SIGINT after it
BOUND = 20.0
FAST = settings(max_examples=150, derandomize=True, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))
LONG = settings(max_examples=2000, derandomize=False, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))


def case(base: str, *mutations: tuple) -> MutatedConfig:
    """A fixed mutated config: ``case("constant-3d", ("system.particles", 2**63 - 1))``; a value
    of ``...`` drops the key; a key ending in ``!`` goes through ``--set``."""
    doc = copy.deepcopy(BASES[base])
    done, overrides = [], []
    for dotted, value in mutations:
        override = dotted.endswith("!")
        path = tuple(dotted.rstrip("!").split("."))
        m = Mutation("drop" if value is ... else "set", path, None if value is ... else value, override)
        if override:
            overrides.append(f"{'.'.join(path)}={_value(value)}")
        else:
            _apply(doc, m)
        done.append(m)
    return MutatedConfig(base, doc, overrides, done)


def _run_command(mc: MutatedConfig, command: list[str], *, output_made=True, bound=BOUND):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "c.toml").write_text(to_toml(mc.document))
        argv = command + [a for o in mc.overrides for a in ("--set", o)]
        before = _snapshot_tree(d)
        o = invoke(argv, d, bound=bound)
        after = _snapshot_tree(d)
        check_outcome(o, before, after, output_made=output_made)
        return o, d, after


def check_run(mc: MutatedConfig):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "c.toml").write_text(to_toml(mc.document))
        argv = ["run", "c.toml", "--quiet"] + [a for o in mc.overrides for a in ("--set", o)]
        before = _snapshot_tree(d)
        o = invoke(argv, d, bound=BOUND)
        after = _snapshot_tree(d)
        check_outcome(o, before, after, long_runs=True)
        # a first run on a fresh compile cache announces what it compiles ("compiling ..."), then
        # the bound's SIGINT may land while it compiles, before the file exists
        stderr = "\n".join(line for line in o.stderr.splitlines() if not line.startswith("compiling "))
        stopped_early = o.code == 130 and stderr.strip() == "interrupted: SIGINT"  # before the file existed
        if o.code == 0 or (o.code == 130 and not stopped_early):
            # the run's one new file (its name is the config's, which need not end in .h5)
            outputs = [d / p for p in set(after) - set(before)]
            assert len(outputs) == 1, (after, o.stdout)
            with h5py.File(outputs[0], "r") as f:  # a valid file: at least the first frame
                assert f["particles/all/velocity/time"].shape[0] >= 1  # the DSMC writes no positions
        if o.code == 130 and not stopped_early:
            assert stderr.strip().startswith("interrupted: SIGINT at t = "), o.stderr


# The issue's five cases (and 10^11 particles): one line and exit 2, or a legal run to its end
ISSUE_CASES = {
    "particles 2^63-1": (case("constant-3d", ("system.particles", 2**63 - 1)), (2,)),
    "snapshots 2^63-1": (case("constant-3d", ("output.snapshots", 2**63 - 1)), (2,)),
    "end_time 2^63-1": (case("constant-3d", ("run.end_time", 2**63 - 1)), (0, 2)),
    "mass 1e-300": (case("constant-3d", ("particles.mass", 1e-300)), (2,)),
    "packing 1e-300": (case("constant-3d", ("system.packing_fraction", 1e-300)), (2,)),
    "particles 1e11": (case("constant-3d", ("system.particles", 100000000000)), (2,)),
}


# a vibrated scene's bad input: one line naming the key, exit 2, nothing written
SCENE_CASES = {
    "walls meet": (case("vibrated-2d", ("walls.y_low.amplitude", 9.0), ("walls.y_high", {"kind": "vibrating",
                                                                                       "amplitude": 9.0,
                                                                                       "frequency": 1.0})),
                   "walls.y_low.amplitude = 9"),
    "no room": (case("vibrated-2d", ("walls.y_low.amplitude", 17.5)), "walls.y_low.amplitude = 17.5"),
    "frequency 0": (case("vibrated-2d", ("walls.y_low.frequency", 0.0)), "walls.y_low.frequency = 0"),
    "frequency < 0": (case("vibrated-2d", ("walls.y_low.frequency!", -2.0)), "walls.y_low.frequency = -2"),
    "vibrating on a periodic axis": (case("vibrated-2d", ("system.boundary", ["wall", "periodic"])), "walls.y_low"),
    "gravity axes": (case("vibrated-2d", ("gravity.acceleration", [0.0, -1.0, 0.0])), "gravity.acceleration"),
    "dsmc": (case("vibrated-2d", ("run.method", "dsmc")), "[gravity]"),
}


@pytest.mark.parametrize("name", sorted(SCENE_CASES))
def test_scene_bad_input_gives_one_line_and_writes_nothing(name):
    mc, key = SCENE_CASES[name]
    o, d, after = _run_command(mc, ["run", "c.toml", "--quiet"], output_made=False)
    assert o.code == 2 and key in o.stderr and o.stderr.count("\n") == 1, o.stderr


@pytest.mark.parametrize("name", sorted(ISSUE_CASES))
def test_issue_cases_give_one_line_or_run_to_the_end(name):
    mc, codes = ISSUE_CASES[name]
    o, d, after = _run_command(mc, ["run", "c.toml", "--quiet"])
    assert o.code in codes, o.stderr
    if o.code == 2:
        assert ".".join(mc.mutations[0].path) in o.stderr, o.stderr
    else:
        assert "stopped by end_time" in o.stdout


def _property_run(mc):
    check_run(mc)


@FAST
@given(mutated_config())
# found by this property before they were fixed (unfixed: traceback, hang or two lines)
@example(case("polydisperse-elastic", ("system.particles!", 2**63 - 1)))  # ValueError: array is too big
@example(case("polydisperse-elastic", ("run.collisions_per_particle!", 2**63 - 1)))  # TypeError in log10
@example(case("viscoelastic-2d", ("output.file", ...), ("run.collisions_per_particle!", 2**63 - 1)))  # OverflowError
@example(case("tc-2d", ("system.packing_fraction", 5e-324)))  # ValueError: zero-size array
@example(case("constant-3d", ("particles.diameter!", 227), ("system.packing_fraction", 1e-100)))  # hang (placement)
@example(case("polydisperse-elastic", ("system.particles", 2147483648)))  # hang (allocation)
@example(case("viscoelastic-2d", ("output.snapshot_interval", 1e-100)))  # ValueError: maximum size exceeded
@example(case("viscoelastic-2d", ("output.observables_interval", 1e-100)))  # ValueError: maximum size exceeded
@example(case("viscoelastic-2d", ("run.end_time", 208982728734088)))  # _ArrayMemoryError (schedule)
@example(case("constant-3d", ("particles.mass", 5e-324), ("system.dimension", 0), ("system", ...)))  # ZeroDivision
@example(case("constant-3d", ("system", "\x1e")))  # a record separator in the value split the line
@example(case("constant-3d", ("particles.mass!", 1e-50)))  # hang in the engine's calendar (pacing stops)
@example(case("constant-3d", ("particles.mass", 6.666666666666668e49)))  # ValueError in advise's bracket
@example(case("material-3d", ("collision.material.young_modulus", 2**63 - 1)))  # table range: exit 3, not 2
@example(case("constant-3d", ("sytem.particle!", 0)))  # misspelt section and key: suggested only `system`
@example(case("constant-3d", ("extra.particle!", 0)))  # an unknown section nothing is near: the key as given
# the issue's cases
@example(case("constant-3d", ("particles.mass", 1e-300)))
@example(case("constant-3d", ("system.packing_fraction", 1e-300)))
@example(case("constant-3d", ("run.end_time", 2**63 - 1)))
@example(case("constant-3d", ("output.snapshots", 2**63 - 1)))
def test_run_any_config(kernels_compiled, mc):
    _property_run(mc)


@pytest.mark.slow
@LONG
@given(mutated_config())
@example(case("constant-3d", ("run.end_time", 1e21)))  # hang in the engine's calendar; now a long run, SIGINT
def test_run_any_config_long(mc):
    _property_run(mc)


def _compile_variants(variants):
    """Run each (base, --set overrides) once without a bound: its kernels compiled (or loaded)
    before the bounded examples. A first compile can take longer than :data:`BOUND` on a loaded
    machine, and the bound's SIGINT would then land inside numba's compiler."""
    for base, sets in variants:
        with tempfile.TemporaryDirectory() as tmp:
            d = Path(tmp)
            (d / "c.toml").write_text(to_toml(BASES[base]))
            argv = ["run", "c.toml", "--quiet"] + [a for o in sets for a in ("--set", o)]
            invoke(argv, d, bound=3600.0)


@pytest.fixture(scope="module")
def kernels_compiled():
    """The kernels of every general base (:func:`_compile_variants`), and both neighbour modes
    and dimensions of the vibrated one (the wall-kind variants)."""
    flips = [("vibrated-2d", ['run.neighbours="lists"']), ("vibrated-2d", ['run.neighbours="cells"'])]
    _compile_variants([(base, []) for base in GENERAL_BASES] + flips)


@pytest.fixture(scope="module")
def sheared_kernels_compiled():
    """The sheared engine and DSMC compiled (or loaded) before the bounded examples
    (:func:`_compile_variants`)."""
    _compile_variants([("shear-3d", []), ("shear-3d", ["run.neighbours=\"lists\""]),
                       ("shear-3d", ["run.neighbours=\"cells\""]), ("shear-3d", ["system.dimension=2"]),
                       ("shear-3d", ["system.dimension=2", "run.neighbours=\"lists\""]),
                       ("shear-thermostat-2d", []), ("shear-thermostat-2d", ["system.dimension=3"])])


@settings(parent=FAST, max_examples=60)
@given(mc=mutated_config(bases=SHEAR_BASES))
@example(mc=case("shear-3d", ("collision.restitution", 1.0)))  # elastic without thermostat: ValueError in theory
@example(mc=case("shear-thermostat-2d", ("shear.rate", 2147483647)))  # hang: windows of 1e-10, no chunk boundary
def test_run_any_sheared_config(sheared_kernels_compiled, mc):
    _property_run(mc)


def _property_advise(mc):
    o, _, _ = _run_command(mc, ["advise", "c.toml"], output_made=False)
    assert o.code in (0, 2), o.stderr


@settings(parent=FAST, max_examples=40)
@given(mutated_config())
@example(case("material-3d", ("system", ...), ("collision.material.young_modulus", 2**63 - 1)))  # exit 3
@example(case("constant-3d", ("particles.mass", 6.666666666666668e49)))  # ValueError in the bracket
@example(case("viscoelastic-2d", ("collision.damping!", 26.484131033112767)))  # the theory's nodes beyond the table
@example(case("material-3d", ("system.packing_fraction", 1e-300)))  # cooling curve's clock beyond float64: nan beta
def test_advise_any_config(mc):
    _property_advise(mc)


@settings(parent=FAST, max_examples=40)
@given(mutated_config(bases=SHEAR_BASES))
def test_advise_any_sheared_config(mc):
    _property_advise(mc)


@pytest.mark.slow
@settings(parent=LONG, max_examples=500)
@given(mutated_config())
def test_advise_any_config_long(mc):
    _property_advise(mc)


def _property_export(mc):
    o, d, after = _run_command(mc, ["export", "lammps", "c.toml", "-o", "lmp"])
    if o.code == 0:
        assert {"lmp/", "lmp/data.granulargas", "lmp/in.granulargas"} <= set(after), after


@settings(parent=FAST, max_examples=30)
@given(mutated_config(bases=("viscoelastic-2d", "material-3d", "polydisperse-elastic")))
@example(case("viscoelastic-2d", ("run.end_time", 1e-300)))  # ZeroDivisionError: no whole time step
def test_export_lammps_any_config(mc):
    _property_export(mc)


@pytest.mark.slow
@settings(parent=LONG, max_examples=300)
@given(mutated_config(bases=("viscoelastic-2d", "material-3d", "polydisperse-elastic")))
def test_export_lammps_any_config_long(mc):
    _property_export(mc)


# ------------------------------------------------------------------ sweep files

_VARY_KEYS = ["collision.restitution", "system.seed", "system.particles", "run.end_time", "output.snapshots",
              "system.packing_fraction", "particles.mass", "system.temprature", "nosection.key", "collision"]


@st.composite
def sweep_file(draw):
    """A sweep file around the valid base config "constant-3d", with mutated entries."""
    values = st.one_of(st.sampled_from(EXTREMES), _toml_values(0))
    generators = st.one_of(
        st.lists(values, max_size=4),
        st.builds(lambda a: {"range": a}, st.lists(st.one_of(st.integers(-5, 2**63 - 1), values), max_size=4)),
        st.builds(lambda a: {"linspace": a}, st.lists(st.one_of(st.integers(0, 2**63 - 1), values), max_size=4)),
        st.builds(lambda a: {"logspace": a}, st.lists(st.one_of(st.integers(-400, 400), values), max_size=4)),
        values,
    )
    doc = {"base": "c.toml", "output_dir": "out", "mode": "product",
           "set": {"run": {"end_time": 0.5}}, "vary": {"system": {"seed": [1, 2]}}}
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["vary", "vary", "set", "top", "drop"]))
        if kind in ("vary", "set"):
            section, _, key = draw(st.sampled_from(_VARY_KEYS)).partition(".")
            value = draw(generators if kind == "vary" else values)
            table = doc.setdefault(kind, {})
            if not isinstance(table, dict):
                continue
            if key and isinstance(table.setdefault(section, {}), dict):
                table[section][key] = value
            else:
                table[section] = value
        elif kind == "top":
            doc[draw(st.sampled_from(["base", "output_dir", "mode", "name", "set", "vary", "bse"]))] = draw(
                _toml_values(1))
        else:
            doc.pop(draw(st.sampled_from(list(doc) or ["base"])), None)
    return doc


def _property_sweep(doc):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "c.toml").write_text(to_toml(BASES["constant-3d"]))
        (d / "s.toml").write_text(to_toml(doc))
        before = _snapshot_tree(d)
        o = invoke(["sweep", "s.toml", "--dry-run"], d, bound=BOUND)
        after = _snapshot_tree(d)
        check_outcome(o, before, after, output_made=False)
        assert o.code in (0, 2), o.stderr
        assert set(after) == set(before), "a dry run writes nothing"


@settings(parent=FAST, max_examples=60)
@given(sweep_file())
@example({"base": "c.toml", "output_dir": "out", "vary": {"system": {"seed": {"range": [0, 2**63 - 1]}}}})
@example({"base": "c.toml", "output_dir": "out", "vary": {"collision": {"restitution": {"logspace": [0, 400, 3]}}}})
@example({"base": "c.toml", "output_dir": "no/out", "vary": {"system": {"seed": [1]}}})
@example({"base": "c.toml", "vary": {"system": {"seed": [1]}}, "set": 3})
@example({"base": "c.toml", "output_dir": "out", "vary": {"system": {"seed": [1, 2]},
                                                         "collision": {"restitution": {"range": [294231]}}}})
def test_sweep_file_any_content(doc):
    _property_sweep(doc)


@pytest.mark.slow
@settings(parent=LONG, max_examples=1000)
@given(sweep_file())
def test_sweep_file_any_content_long(doc):
    _property_sweep(doc)


# ------------------------------------------------------------------ in a real process


@pytest.mark.parametrize("name", ["packing 1e-300", "particles 1e11"])
def test_refusals_in_a_real_process(name):
    mc = ISSUE_CASES[name][0]
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "c.toml").write_text(to_toml(mc.document))
        before = _snapshot_tree(d)
        o = invoke(["run", "c.toml", "--quiet"], d, bound=120, subprocess_run=True)
        after = _snapshot_tree(d)
    check_outcome(o, before, after)
    assert o.code == 2 and o.stderr.count("\n") == 1, o.stderr
    assert math.isfinite(o.seconds)
