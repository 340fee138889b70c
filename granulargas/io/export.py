"""Deprecated location: the exports moved to :mod:`granulargas.io.gsd` (GSD),
:mod:`granulargas.dem.export` (LAMMPS) and :mod:`granulargas.cli.export` (the command).

The names below keep working and importing this module emits a DeprecationWarning.
"""

import warnings

from granulargas.dem.export import export_lammps  # noqa: F401
from granulargas.io.gsd import GSD_TIME_KEY, export_gsd  # noqa: F401

warnings.warn("granulargas.io.export moved to granulargas.io.gsd (export_gsd) and granulargas.dem.export "
              "(export_lammps)", DeprecationWarning, stacklevel=2)
