"""Names users rely on: the package root (the front door ``import granulargas as gg``) and the CLI table."""

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


#: the names a notebook starts with (``import granulargas as gg``) and where each is defined
FRONT_DOOR = {
    "load_config": "granulargas.io.config", "simulate": "granulargas.api", "load_run": "granulargas.api",
    "Result": "granulargas.api", "analyze": "granulargas.api",
    "Simulation": "granulargas.engine", "CollisionRule": "granulargas.engine", "WhiteNoise": "granulargas.engine",
    "TangentialRule": "granulargas.engine",
    "DSMC": "granulargas.dsmc", "random_state": "granulargas.initial", "State": "granulargas.state",
    "restitution": "granulargas.contact",
}


def test_dir_lists_the_front_door():
    """dir(gg) shows every public name (loaded or not) and nothing of the package's machinery."""
    out = subprocess.run([sys.executable, "-c", "import granulargas, sys; print(sorted(dir(granulargas))); "
                          "print(sorted(granulargas.__all__)); print('numba' in sys.modules)"],
                         capture_output=True, text=True, check=True)
    shown, listed, numba = out.stdout.splitlines()
    assert set(FRONT_DOOR) <= set(eval(shown)) and sorted(FRONT_DOOR) == eval(listed)
    assert numba == "False"  # listing the names imports none of them
    assert not [n for n in eval(shown) if "Moved" in n or n in ("sys", "importlib")]


@pytest.mark.parametrize("name", sorted(FRONT_DOOR))
def test_each_front_door_name_is_the_object_of_its_module(name):
    assert getattr(granulargas, name) is getattr(importlib.import_module(FRONT_DOOR[name]), name)
    assert getattr(granulargas, name).__doc__


def test_no_front_door_name_is_a_subpackage():
    """Importing granulargas.X sets the package attribute X: a public name X would be replaced."""
    import pkgutil

    modules = {m.name for m in pkgutil.iter_modules(granulargas.__path__)}
    assert "run" in modules and not modules & set(granulargas.__all__)
    importlib.import_module("granulargas.run.runner")
    assert callable(granulargas.simulate) and granulargas.Result.__module__ == "granulargas.api"


def test_opening_a_result_does_not_import_numba():
    code = ("import sys, granulargas as gg; gg.load_config, gg.load_run, gg.Result; "
            "print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_no_module_answers_for_a_retired_path():
    """Modules live at one path each: the old paths of moved modules are gone."""
    for old in ("granulargas.io.runner", "granulargas.engine.initial", "granulargas.advise"):
        sys.modules.pop(old, None)
        with pytest.raises(ModuleNotFoundError):
            importlib.import_module(old)


def test_config_and_readers_stay_in_io():
    from granulargas.io import config, h5md

    assert callable(config.load_config) and callable(h5md.read_observables) and callable(h5md.iter_snapshots)


def test_api_docs_list_every_front_door_name():
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "api" / "granulargas.md").read_text()
    assert [n for n in granulargas.__all__ if f"`gg.{n}" not in page] == []
    assert "::: granulargas.api" in page
