"""Deprecated location: this module moved to :mod:`granulargas.run.prepare`.

``import granulargas.io.setup`` still works (it is the same module object) and emits a
DeprecationWarning; import :mod:`granulargas.run.prepare` instead.
"""

import sys
import warnings

from granulargas.run import prepare as _moved

warnings.warn("granulargas.io.setup moved to granulargas.run.prepare", DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
