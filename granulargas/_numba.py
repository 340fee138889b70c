"""The numba decorators the package uses.

``cache=True`` everywhere (compiled code is reused across processes); no
``fastmath`` (it breaks ``inf`` sentinels and event ordering). Set
``GRANULARGAS_NO_CACHE=1`` to disable the on-disk cache.

:func:`kernel` is :func:`jit` without numba's reference counting (``_nrt=False``),
for compiled code that allocates no arrays. Numba counts references to every
array argument of a compiled function (an atomic increment at entry and a
decrement at exit, through a call it cannot inline); the event loop passes a
few dozen arrays to each of its per-event calls, and these counts cost ~20 % of
its time (``scripts/profile_loop.py``). A kernel may not create arrays
(``np.empty`` etc. fail to compile in it); it may read and write the arrays it
is given and call other kernels or jit functions.
"""

import os

import numba

_CACHE = os.environ.get("GRANULARGAS_NO_CACHE", "") not in ("1", "true", "yes")


def jit(*args, **kwargs):
    """``numba.njit`` with the package defaults (cache=True, no fastmath)."""
    kwargs.setdefault("cache", _CACHE)
    return numba.njit(*args, **kwargs)


def kernel(*args, **kwargs):
    """:func:`jit` without reference counting (``_nrt=False``): for code that allocates nothing."""
    kwargs.setdefault("_nrt", False)
    return jit(*args, **kwargs)
