"""Deprecated location: this module moved to :mod:`granulargas.initial.lattice_gas`.

``import granulargas.engine.initial`` still works (it is the same module object) and emits a
DeprecationWarning; import :mod:`granulargas.initial.lattice_gas` instead.
"""

import sys
import warnings

from granulargas.initial import lattice_gas as _moved

warnings.warn("granulargas.engine.initial moved to granulargas.initial.lattice_gas", DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
