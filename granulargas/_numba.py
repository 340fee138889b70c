"""The one numba decorator the package uses.

``cache=True`` everywhere (compiled code is reused across processes); no
``fastmath`` (it breaks ``inf`` sentinels and event ordering). Set
``GRANULARGAS_NO_CACHE=1`` to disable the on-disk cache.
"""

import os

import numba

_CACHE = os.environ.get("GRANULARGAS_NO_CACHE", "") not in ("1", "true", "yes")


def jit(*args, **kwargs):
    """``numba.njit`` with the package defaults (cache=True, no fastmath)."""
    kwargs.setdefault("cache", _CACHE)
    return numba.njit(*args, **kwargs)
