"""Where the event loop spends its time: cycle counters around each part of ``advance``.

A copy of ``granulargas/engine/_loop.py`` is patched (as text) with reads of the
CPU cycle counter (``llvm.readcyclecounter``) between the parts of one event:
pop and validation, collision execution, the partner's prediction and calendar
update, the list rebuild, the stale-event path, the particle's own prediction
and calendar update, the prefetch block and the peek at the next event. The
patched copy is compiled (numba, ~15 s, not cached) and run on a random state
after a warm-up of two collisions per particle; the table gives cycles per
collision and per call of each part, and how often the prefetch block's guess
of the event after next was right. The counters perturb the timing a little
(the instrumented rate is printed beside the cycle totals); compare parts and
sizes, not absolute rates with ``bench_engine.py``.

If ``_loop.py`` changed so that a marker is not found, the script says which.

Usage::

    python scripts/profile_loop.py 1e4 1e6          # N values, packing 0.3, 3D, elastic
    python scripts/profile_loop.py 1e5 --packing 0.1
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import os
import re
import sys
import tempfile
import time

PARTS = ["pop + validate", "collide", "predict partner", "update partner", "list rebuild",
         "stale", "predict i", "update i", "prefetch", "peek next"]

_HEADER = '''
from numba import types as _types
from numba.core import cgutils as _cgutils
from numba.extending import intrinsic as _intrinsic
from llvmlite import ir as _ir


@_intrinsic
def rdtsc(typingctx):
    def codegen(context, builder, signature, args):
        fn = _cgutils.get_or_insert_function(builder.module, _ir.FunctionType(_ir.IntType(64), []),
                                             "llvm.readcyclecounter")
        return builder.call(fn, [])
    return _types.int64(), codegen
'''


def _tick(k, indent):
    return (" " * indent + f"c1 = rdtsc(); prof[{k}] += c1 - c0; prof[{k + 10}] += 1; c0 = c1\n")


def patched_source(src):
    """The loop's source with cycle counters; raises ValueError naming a missing marker."""
    src = src.replace("import numpy as np\n", "import numpy as np\n" + _HEADER, 1)
    src, k = re.subn(r"(max_collisions,\s*scal, iscal)\):", r"\1, prof):", src)
    if k != 1:
        raise ValueError("the signature of advance(...) changed")
    after = [
        ("    status = DONE\n", "    c0 = rdtsc()\n    guess = -1\n    pending = -1\n"),
        ("        j = np.int64(partner[i])  # one signature for the callees (partner is int32)\n",
         _tick(0, 8)),
        ("            iscal[I_EXPIRIES] += 1\n", _tick(4, 12)),
        ("            iscal[I_STALE] += 1\n", _tick(5, 12)),
        ("        ti = predict(i, te, rec, centre, count, nbl, nbn, partner, pcount, box, "
         "half_shell)\n", _tick(6, 8)),
        ("        iscal[I_EVENTS] += 1\n        # ---- prefetch hints", None),
        ("        i1 = cal_peek(qt, chunks, qwhere, small, buckets, qi, qf)\n",
         _tick(9, 8) + "        pending = guess\n        guess = -1\n"),
        # the guess of the event after next, made in the prefetch block, checked when
        # that event comes (prof[20]: events, prof[21]: guessed right)
        ("                i2 = int(small[c2, 1])\n", "                guess = i2\n"),
    ]
    before = [
        ("        j = np.int64(partner[i])",
         "        prof[20] += 1\n        if i == pending:\n            prof[21] += 1\n"),
        ("                tj = predict(j, te,", _tick(1, 16)),
        ("                if not cal_update(j, tj,", _tick(2, 16)),
        ("                if rapid[i] >= collapse_count or", _tick(3, 16)),
        ("        if iscal[I_COLLISIONS] >= max_collisions:\n            status = MAX_COLLISIONS",
         _tick(8, 8)),
    ]
    for marker, text in after:
        if src.count(marker) != 1:
            raise ValueError(f"marker not found once in _loop.py: {marker.strip()!r}")
        if text is None:  # the update of i ends where the prefetch block starts
            text = _tick(7, 8)
            src = src.replace(marker, "        iscal[I_EVENTS] += 1\n" + text +
                              "        # ---- prefetch hints")
        else:
            src = src.replace(marker, marker + text)
    for marker, text in before:
        if src.count(marker) != 1:
            raise ValueError(f"marker not found once in _loop.py: {marker.strip()!r}")
        src = src.replace(marker, text + marker)
    return src


def profile(n, packing, seed=1):
    import numpy as np

    import granulargas.engine._loop as loop
    from granulargas.engine import CollisionRule, Simulation
    from granulargas.initial import random_state

    tmp = tempfile.mkdtemp(prefix="profile_loop_")
    with open(os.path.join(tmp, "_loop_profiled.py"), "w") as f:
        f.write(patched_source(inspect.getsource(loop)))
    sys.path.insert(0, tmp)
    prof_loop = importlib.import_module("_loop_profiled")
    sim = Simulation(**random_state(n, packing, 3, seed=seed).as_kwargs(),
                     rule=CollisionRule.elastic())
    sim.run(np.inf, max_collisions=2 * n)
    s = sim._s
    kind, eps, tc, pref, inv_h, coeffs = sim.rule.kernel_arguments()
    fpar = np.array([eps, tc, pref, inv_h, sim.shell, 1e-20, float(sim._radii.max())])
    prof = np.zeros(22, np.int64)
    names = list(inspect.signature(prof_loop.advance.py_func).parameters)

    def go(ncoll):
        c0 = int(s["iscal"][0])
        extra = dict(box=sim._box3, ncell=sim._ncell, kind=kind, fpar=fpar, coeffs=coeffs,
                     collapse_count=100, until=np.inf, max_events=10**12,
                     max_collisions=c0 + ncoll, prof=prof)
        args = [extra[k] if k in extra else s[k] for k in names]
        w = time.perf_counter()
        prof_loop.advance(*args)
        return time.perf_counter() - w, int(s["iscal"][0]) - c0

    t = time.perf_counter()
    go(1000)
    compile_s = time.perf_counter() - t
    prof[:] = 0
    dt, nc = go(max(300_000, n))
    total = prof[:10].sum()
    print(f"N = {n}, packing {packing}: {nc / dt / 1e6:.3f} M collisions/s instrumented, "
          f"{total / nc:.0f} cycles per collision ({dt / nc * 1e9:.0f} ns); compile {compile_s:.1f} s")
    for k, name in enumerate(PARTS):
        print(f"  {name:16s} {prof[k] / nc:7.0f} cycles/collision {100 * prof[k] / total:5.1f} %"
              f"  calls/collision {prof[10 + k] / nc:.2f}  cycles/call "
              f"{prof[k] / max(1, prof[10 + k]):.0f}")
    print(f"  the event after next, guessed for the prefetch: right for "
          f"{100 * prof[21] / max(1, prof[20]):.1f} % of events")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("sizes", type=float, nargs="+", help="numbers of spheres")
    p.add_argument("--packing", type=float, default=0.3)
    args = p.parse_args(argv)
    if any(n < 100 for n in args.sizes) or not 0.0 < args.packing <= 0.5:
        p.error("sizes must be >= 100 and 0 < --packing <= 0.5")
    for n in args.sizes:
        try:
            profile(int(n), args.packing)
        except ValueError as e:
            sys.exit(f"profile_loop.py: {e}")


if __name__ == "__main__":
    main()
