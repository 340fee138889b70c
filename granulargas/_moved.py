"""Deprecated module paths: modules that moved keep working under their old names.

``import granulargas.io.runner`` (or ``from granulargas.io.runner import run_config``)
gives the module at its new place, :mod:`granulargas.run.runner` -- the same module
object -- and emits a DeprecationWarning naming the new path. No file stays at the
old path, so the old name adds no import to the package's dependency graph.
:data:`MOVED` lists every old name.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import warnings

#: old module name -> new module name
MOVED = {
    "granulargas.advise": "granulargas.run.advise",
    "granulargas.validity": "granulargas.run.validity",
    "granulargas.sweep": "granulargas.run.sweep",
    "granulargas.io.runner": "granulargas.run.runner",
    "granulargas.io.setup": "granulargas.run.prepare",
    "granulargas.io.lammps": "granulargas.dem.lammps",
    "granulargas.io.run_command": "granulargas.cli.run",
    # export_lammps, export_gsd, GSD_TIME_KEY, configure_parser, run
    "granulargas.io.export": "granulargas.cli.export",
    "granulargas.engine.initial": "granulargas.initial.lattice_gas",
    "granulargas.analysis.cli": "granulargas.cli.analyze",
    "granulargas.contact.cli": "granulargas.cli.epsilon",
    "granulargas.contact.seed_route": "granulargas.contact.perturbation",
}


class MovedModuleFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds the old names of :data:`MOVED` (and nothing else) and loads the new module."""

    def find_spec(self, name, path=None, target=None):
        if name not in MOVED:
            return None
        return importlib.util.spec_from_loader(name, self)

    def create_module(self, spec):
        new = MOVED[spec.name]
        warnings.warn(f"{spec.name} moved to {new}; import it from there", DeprecationWarning, stacklevel=2)
        return importlib.import_module(new)

    def exec_module(self, module):
        pass  # the new module is already executed
