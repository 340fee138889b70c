"""Deprecated location: this module moved to :mod:`granulargas.run.sweep`.

``import granulargas.sweep`` still works (it is the same module object) and emits a
DeprecationWarning; import :mod:`granulargas.run.sweep` instead.
"""

import sys
import warnings

from granulargas.run import sweep as _moved

warnings.warn("granulargas.sweep moved to granulargas.run.sweep", DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
