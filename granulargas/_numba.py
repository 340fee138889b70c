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

:func:`inlined` is a kernel that every compiled caller inlines: it is compiled
and optimised once, as a function of its own, and LLVM inlines the optimised
code at each call site (the ``alwaysinline`` attribute: numba's
``forceinline``). The event loop's hot kernels are of this kind. Numba's own
``inline="always"`` inlines at the level of numba's IR instead: the callee's IR
is rebuilt, deep-copied (once per block, with the whole variable scope) and
typed again at every call site, and nested inlining repeats that at every
level, so that a loop built of nested inline kernels compiles several seconds
slower. An inlined kernel has no Python entry point (``python=True`` keeps one,
for the few that tests call directly): calling one from Python crashes the
interpreter.

Every function here is compiled with ``forceinline`` set explicitly (False
unless :func:`inlined`): numba otherwise inherits the flag from the function
whose compilation triggered the callee's, so that a kernel first compiled from
within an inlined kernel would be inlined into all its callers.
"""

import os

import numba

_CACHE = os.environ.get("GRANULARGAS_NO_CACHE", "") not in ("1", "true", "yes")


def jit(*args, **kwargs):
    """``numba.njit`` with the package defaults (cache=True, no fastmath)."""
    kwargs.setdefault("cache", _CACHE)
    kwargs.setdefault("forceinline", False)
    return numba.njit(*args, **kwargs)


def kernel(*args, python=True, **kwargs):
    """:func:`jit` without reference counting (``_nrt=False``): for code that allocates nothing.

    ``python=False``: no Python entry point (numba's CPython and C wrappers, which
    unbox every argument, are not built; calling the kernel from Python crashes),
    for a kernel that only compiled code calls.
    """
    kwargs.setdefault("_nrt", False)
    if not python:
        kwargs["no_cpython_wrapper"] = True
        kwargs["no_cfunc_wrapper"] = True
    return jit(*args, **kwargs)


def inlined(*args, python=False, **kwargs):
    """:func:`kernel` inlined by LLVM into every compiled caller (``forceinline``).

    ``python=False`` (default): no Python entry point (numba's CPython and C
    wrappers are not built; calling it from Python crashes). ``python=True``
    keeps them, for a kernel that tests call from Python.
    """
    kwargs["forceinline"] = True
    return kernel(*args, python=python, **kwargs)
