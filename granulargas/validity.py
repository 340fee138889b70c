"""Deprecated location: this module moved to :mod:`granulargas.run.validity`.

``import granulargas.validity`` still works (it is the same module object) and emits a
DeprecationWarning; import :mod:`granulargas.run.validity` instead.
"""

import sys
import warnings

from granulargas.run import validity as _moved

warnings.warn("granulargas.validity moved to granulargas.run.validity", DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
