"""Deprecated location: this module moved to :mod:`granulargas.run.runner`.

``import granulargas.io.runner`` still works (it is the same module object) and emits a
DeprecationWarning; import :mod:`granulargas.run.runner` instead.
"""

import sys
import warnings

from granulargas.run import runner as _moved

warnings.warn("granulargas.io.runner moved to granulargas.run.runner", DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
