"""First JIT compile of the event loop, per neighbour mode, and the cached load.

Each measurement is a fresh process that builds a 64-sphere random state and runs
it briefly with ``Simulation(..., neighbours=MODE)`` (elastic rule, periodic box):
"first" with an empty numba cache directory of its own (everything the run needs
is compiled), "cached" with a cache that the first run filled (import and a tiny
run, everything loaded from the cache). The time counted starts after the import
and the initial state (whose kernels are compiled during them): CPU time of the
process and wall clock. Printed per mode and source tree: every round and the
medians. With several ``--trees`` (source trees holding the granulargas package)
the rounds alternate between them, in alternating order, so that the machine's
drift falls on both alike.

Usage::

    python scripts/bench_compile.py                        # lists and cells, this tree, 3 rounds
    python scripts/bench_compile.py --trees /tmp/main . --rounds 3 --core 1
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

_CHILD = """
import sys, time
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
st = random_state(64, 0.05, 3, seed=0)
# a tree whose initial state is a set of keyword arguments (as_kwargs) or a state record
args = ((), st.as_kwargs()) if hasattr(st, "as_kwargs") else ((st,), {})
cpu, wall = time.process_time(), time.perf_counter()
Simulation(*args[0], rule=CollisionRule.elastic(), neighbours=sys.argv[1], **args[1]).run(0.5)
print(time.process_time() - cpu, time.perf_counter() - wall)
"""


def measure(tree, mode, cache, core=None):
    """(CPU s, wall s) of one fresh process's first run against ``tree`` with numba cache ``cache``."""
    cmd = [sys.executable, "-c", _CHILD, mode]
    if core is not None and shutil.which("taskset"):
        cmd = ["taskset", "-c", str(core)] + cmd
    env = dict(os.environ, PYTHONPATH=os.path.abspath(tree), NUMBA_CACHE_DIR=cache)
    env.pop("GRANULARGAS_NO_CACHE", None)
    out = subprocess.run(cmd, env=env, cwd=tree, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{tree}: run failed:\n{out.stderr[-2000:]}")
    cpu, wall = (float(x) for x in out.stdout.split())
    return cpu, wall


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--trees", nargs="+", default=[os.path.dirname(HERE)],
                   help="source trees to compare (default: this one)")
    p.add_argument("--modes", nargs="+", default=["lists", "cells"], choices=["lists", "cells"])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--core", type=int, default=None, help="pin the runs to this core (taskset)")
    args = p.parse_args(argv)
    for tree in args.trees:
        if not os.path.isdir(os.path.join(tree, "granulargas")):
            p.error(f"--trees {tree}: no granulargas package there")
    print(f"# first JIT compile (empty numba cache) and cached load, fresh processes, "
          f"{args.rounds} rounds, load average {os.getloadavg()[0]:.2f} at start")
    first, cached = {}, {}
    for r in range(args.rounds):
        order = args.trees if r % 2 == 0 else args.trees[::-1]
        for mode in args.modes:
            for tree in order:
                cache = tempfile.mkdtemp(prefix="numba-cache-")
                try:
                    f = measure(tree, mode, cache, args.core)
                    c = measure(tree, mode, cache, args.core)
                finally:
                    shutil.rmtree(cache, ignore_errors=True)
                first.setdefault((tree, mode), []).append(f)
                cached.setdefault((tree, mode), []).append(c)
                print(f"round {r} {mode:5s} {tree}: first CPU {f[0]:.1f} s, wall {f[1]:.1f} s; "
                      f"cached CPU {c[0]:.2f} s, wall {c[1]:.2f} s", flush=True)
    print("# medians")
    for mode in args.modes:
        for tree in args.trees:
            f, c = first[(tree, mode)], cached[(tree, mode)]
            print(f"{mode:5s} {tree}: first compile CPU {statistics.median(x[0] for x in f):.1f} s, "
                  f"wall {statistics.median(x[1] for x in f):.1f} s; cached load CPU "
                  f"{statistics.median(x[0] for x in c):.2f} s, wall {statistics.median(x[1] for x in c):.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
