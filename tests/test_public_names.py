"""Names users rely on keep working: the package root, the CLI table, and the
deprecated aliases at the paths modules moved from."""

import importlib
import subprocess
import sys

import pytest

import granulargas
from granulargas import cli


def test_root_exposes_the_engine_lazily():
    from granulargas.engine import CollisionRule, Simulation

    assert granulargas.Simulation is Simulation and granulargas.CollisionRule is CollisionRule


def test_help_does_not_import_numba():
    code = ("import sys; from granulargas.cli import main\n"
            "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
            "print('numba' in sys.modules, 'scipy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split()[-2:] == ["False", "False"]


@pytest.mark.parametrize("name", sorted(cli.COMMANDS))
def test_every_command_module_has_parser_and_run(name):
    module = importlib.import_module(cli.COMMANDS[name][0])
    assert module.__name__.startswith("granulargas.cli.")
    assert callable(module.configure_parser) and callable(module.run)


@pytest.mark.parametrize("old, new, names", [
    ("granulargas.io.runner", "granulargas.run.runner", ["run_config", "output_schedule", "mean_free_time"]),
    ("granulargas.io.setup", "granulargas.run.prepare", ["prepare", "fresh_state", "reduced_prefactor"]),
    ("granulargas.io.lammps", "granulargas.dem.lammps", ["DemContact", "write_lammps_gas", "find_lmp"]),
    ("granulargas.engine.initial", "granulargas.initial.lattice_gas", ["random_state", "random_positions"]),
    ("granulargas.advise", "granulargas.run.advise", ["advise", "summary_line"]),
    ("granulargas.validity", "granulargas.run.validity", ["check_run", "raise_if_invalid"]),
    ("granulargas.sweep", "granulargas.run.sweep", ["load_sweep", "run_sweep"]),
    ("granulargas.io.run_command", "granulargas.cli.run", ["configure_parser", "run"]),
    ("granulargas.analysis.cli", "granulargas.cli.analyze", ["report", "run"]),
    ("granulargas.contact.cli", "granulargas.cli.epsilon", ["configure_parser", "run"]),
    ("granulargas.contact.seed_route", "granulargas.contact.perturbation", ["perturbation_solution", "puiseux_x"]),
])
def test_moved_modules_keep_their_old_name(old, new, names):
    sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning, match=new.replace(".", r"\.")):
        module = importlib.import_module(old)
    moved = importlib.import_module(new)
    assert module is moved
    for name in names:
        assert getattr(module, name) is getattr(moved, name)


def test_export_names_keep_working():
    sys.modules.pop("granulargas.io.export", None)
    with pytest.warns(DeprecationWarning):
        from granulargas.io.export import GSD_TIME_KEY, export_gsd, export_lammps
    from granulargas.dem import export
    from granulargas.io import gsd

    assert export_lammps is export.export_lammps and export_gsd is gsd.export_gsd
    assert GSD_TIME_KEY == gsd.GSD_TIME_KEY


def test_old_paths_hold_no_file():
    """The old names are resolved by granulargas._moved, so no old file shadows a moved module."""
    from pathlib import Path

    from granulargas._moved import MOVED

    root = Path(granulargas.__file__).parent.parent
    for old in MOVED:
        path = root / Path(*old.split("."))
        assert not path.with_suffix(".py").exists() and not path.is_dir(), old


def test_config_and_readers_stay_in_io():
    from granulargas.io import config, h5md

    assert callable(config.load_config) and callable(h5md.read_observables) and callable(h5md.iter_snapshots)
