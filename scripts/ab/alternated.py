"""Alternated A/B benchmark of two source trees of granulargas.

The machine's speed drifts (a shared host), so two versions of the engine are
compared by alternating them: each round runs, for each size, tree A and then
tree B, each in a fresh process of this tree's ``scripts/benchmarks/run.py
--case N packing dim rule`` with ``PYTHONPATH`` set to the tree and a numba
cache directory of its own (pinned to one core when ``taskset`` exists). It
prints every rate and, per size, the medians, B/A of the medians, and the spread
of the per-round ratios (each round's B over the same round's A: the pairs ran
back to back, so they share the machine's state).

Usage::

    git worktree add /tmp/base main              # the tree to compare with
    python scripts/ab/alternated.py /tmp/base . --sizes 1e4 1e5 1e6 --rounds 3
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def rate(tree, n, packing, dim, rule, cache):
    """(wall-clock, CPU-time) median collisions/s of one ``scripts/benchmarks/run.py --case`` process
    run against ``tree``."""
    cmd = [sys.executable, os.path.join(ROOT, "scripts", "benchmarks", "run.py"), "--case", str(n), str(packing),
           str(dim), rule]
    if shutil.which("taskset"):
        cmd = ["taskset", "-c", str(os.cpu_count() - 1)] + cmd
    env = dict(os.environ, PYTHONPATH=os.path.abspath(tree), NUMBA_CACHE_DIR=cache)
    out = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"scripts/ab/alternated.py: {tree}: N = {n}: {out.stderr.strip().splitlines()[-1:]}")
    r = json.loads(out.stdout.strip().splitlines()[-1])
    return r["rate_wall"], r["rate_cpu"]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("tree_a", help="source tree A (holds the granulargas package)")
    p.add_argument("tree_b", help="source tree B")
    p.add_argument("--sizes", type=float, nargs="+", default=[1e4, 1e5, 1e6])
    p.add_argument("--packing", type=float, default=0.3)
    p.add_argument("--dim", type=int, default=3, choices=[2, 3])
    p.add_argument("--rule", default="elastic")
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args(argv)
    for tree in (args.tree_a, args.tree_b):
        if not os.path.isfile(os.path.join(tree, "granulargas", "__init__.py")):
            p.error(f"{tree}: no granulargas package there")
    if args.rounds < 1 or any(n < 100 for n in args.sizes):
        p.error("--rounds must be >= 1 and --sizes >= 100")
    caches = {t: tempfile.mkdtemp(prefix="bench_ab_nc_") for t in (args.tree_a, args.tree_b)}
    rates = {(t, n): [] for t in caches for n in args.sizes}
    for r in range(args.rounds):
        for n in args.sizes:
            for tree in (args.tree_a, args.tree_b):
                x = rate(tree, int(n), args.packing, args.dim, args.rule, caches[tree])
                rates[tree, n].append(x)
                print(f"round {r + 1} N = {int(n):>8d} {tree}: {x[0] / 1e6:.3f} M collisions/s "
                      f"(CPU time: {x[1] / 1e6:.3f})", flush=True)
    for k, clock in enumerate(("wall clock", "CPU time of the process")):
        print(f"\nmedians (M collisions/s, {clock}), {args.dim}D, packing {args.packing}, {args.rule}:")
        for n in args.sizes:
            ra = [x[k] for x in rates[args.tree_a, n]]
            rb = [x[k] for x in rates[args.tree_b, n]]
            a, b = statistics.median(ra), statistics.median(rb)
            pairs = [y / x for x, y in zip(ra, rb)]
            print(f"N = {int(n):>8d}: A {a / 1e6:.3f}  B {b / 1e6:.3f}  B/A {b / a:.3f}  per-round B/A "
                  f"median {statistics.median(pairs):.3f}, range {min(pairs):.3f}..{max(pairs):.3f}")


if __name__ == "__main__":
    main()
