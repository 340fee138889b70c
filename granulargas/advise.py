"""Deprecated location: this module moved to :mod:`granulargas.run.advise`.

``import granulargas.advise`` still works (it is the same module object) and emits a
DeprecationWarning; import :mod:`granulargas.run.advise` instead.
"""

import sys
import warnings

from granulargas.run import advise as _moved

warnings.warn("granulargas.advise moved to granulargas.run.advise", DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
