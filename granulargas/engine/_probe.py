"""Cycle counters compiled into the event loop on request (numba leaf module).

The loop takes an argument ``probe``: ``None`` in production, or an int64 array
(:data:`PROBE_SIZE`) in the profiler (``scripts/profiling/profile_loop.py``). The
functions here branch on ``probe is None``, which numba resolves by the argument's
*type* before it types the function: for ``None`` they compile to nothing, so the production build of the
loop is the loop without counters; for an array they read the CPU cycle counter
(``llvm.readcyclecounter``) and add the cycles since the previous probe to the
part of the event that just ended. The same source thus gives two builds, and
the profiler measures the loop without editing it.

Parts of one event (indices into the probe array; ``probe[PARTS + k]`` counts
the calls of part k):
"""

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from granulargas._numba import inlined

#: int64, not Python ints: numba types a Python int constant as its literal and would compile
#: :func:`probe` once per part
POP, COLLIDE, REBUILD, WALL, STALE, PREDICT, UPDATE, PREFETCH, PEEK, GLOBAL = (np.int64(k) for k in range(10))
PART_NAMES = ["pop + validate", "collide (+ partner)", "list rebuild", "wall", "stale",
              "predict i", "update i", "prefetch", "peek next", "global events"]
PARTS = len(PART_NAMES)
#: probe[GUESSES]: events whose successor was guessed for the prefetch; probe[GUESSED]: right
GUESSES = 2 * PARTS
GUESSED = GUESSES + 1
PROBE_SIZE = GUESSED + 1

__doc__ += "".join(f"{k} {name}; " for k, name in enumerate(PART_NAMES)) + "\n"


@intrinsic
def _cycles(typingctx):
    def codegen(context, builder, signature, args):
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(64), []),
                                            "llvm.readcyclecounter")
        return builder.call(fn, [])

    return types.int64(), codegen


@inlined
def probe_start(probe):
    """Cycle counter now (0 without a probe array)."""
    if probe is None:
        return 0
    return _cycles()


@inlined
def probe(probe, part, clock):
    """Add the cycles since ``clock`` to ``part``; returns the new clock (no-op without probe)."""
    if probe is None:
        return clock
    now = _cycles()
    probe[part] += now - clock
    probe[PARTS + part] += 1
    return now


@inlined
def probe_guess(probe, right):
    """Count one guess of the event after next, and whether it was ``right``."""
    if probe is None:
        return
    probe[GUESSES] += 1
    if right:
        probe[GUESSED] += 1
