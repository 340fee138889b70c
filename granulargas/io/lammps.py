"""Deprecated location: this module moved to :mod:`granulargas.dem.lammps`.

``import granulargas.io.lammps`` still works (it is the same module object) and emits a
DeprecationWarning; import :mod:`granulargas.dem.lammps` instead.
"""

import sys
import warnings

from granulargas.dem import lammps as _moved

warnings.warn("granulargas.io.lammps moved to granulargas.dem.lammps", DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
