"""Paired in-process A/B benchmark of two source trees of granulargas.

Small differences in speed (a few per cent) drown in the drift of a shared host
when two versions run in separate processes one after the other
(``scripts/ab/alternated.py``). Here both versions run in one process: each tree's
package is copied under a name of its own (``gg_a``, ``gg_b``; imports
renamed), both simulations are built from the same initial state and warmed up
(2 collisions per particle), and then chunks of ``--chunk`` collisions
alternate between them, A B B A A B ..., so that each pair of chunks shares the
machine's state. The figure per packing is the median over rounds of the
per-round ratio of CPU time per collision.

The version run second in a round comes out a few per cent slower (code and data
placement; an A/A comparison shows it), so the whole measurement is made twice,
in two fresh processes, with the trees listed in both orders; the result is the
geometric mean of the two, in which the position bias cancels.

Usage::

    git worktree add /tmp/base main
    taskset -c 1 python scripts/ab/paired.py /tmp/base . --mode cells --n 10976 \\
        --packings 0.05 0.1 --rounds 40
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

NAMES = ("gg_a", "gg_b")


def copy_package(tree, name, dest):
    """Copy ``tree/granulargas`` to ``dest/name`` with every import renamed."""
    target = os.path.join(dest, name)
    shutil.copytree(os.path.join(tree, "granulargas"), target,
                    ignore=shutil.ignore_patterns("__pycache__"))
    for root, _, files in os.walk(target):
        for f in files:
            if f.endswith(".py"):
                path = os.path.join(root, f)
                with open(path, encoding="utf-8") as fh:
                    text = fh.read()
                text = re.sub(r"granulargas(?=[._a-z])", name, text)
                text = re.sub(r"\bgranulargas\b", name, text)
                with open(path, "w", encoding="utf-8") as fh:
                    fh.write(text)


def worker(args):
    """One process: the packages in ``args.order``; prints per packing the median over
    rounds of (CPU time per collision of the first) / (that of the second), i.e. the
    speed of the second relative to the first, as JSON."""
    import numpy as np

    sys.path.insert(0, args.pkgdir)
    mods = [(importlib.import_module(nm + ".engine"), importlib.import_module(nm + ".initial"))
            for nm in args.order]
    out = {}
    for packing in args.packings:
        sims = []
        for nm, (eng, ini) in zip(args.order, mods):
            if args.mode == "dsmc":  # the DSMC of a constant eps = 0.9 gas, Maxwellian start
                dsmc, state_mod = importlib.import_module(nm + ".dsmc"), importlib.import_module(nm + ".state")
                v = np.random.default_rng(args.seed).normal(size=(args.n, args.dim))
                st = state_mod.State(None, v, 0.5, 1.0, None)
                sim = dsmc.DSMC(st, eng.CollisionRule.constant(0.9), packing_fraction=packing, seed=args.seed)
                sim.run(math.inf, max_collisions=args.n)
                sims.append(sim)
                continue
            if args.shear > 0.0:  # Lees-Edwards (flow x, gradient y), eps = 0.8 as scripts/benchmarks/shear.py
                shear_mod = importlib.import_module(nm + ".engine.shear")
                st = ini.random_state(args.n, packing, args.dim, seed=args.seed,
                                      boundary=("periodic", "lees-edwards", "periodic")[:args.dim], shear=args.shear)
                sim = eng.Simulation(st, eng.CollisionRule.constant(0.8), neighbours=args.mode,
                                     shear=shear_mod.Shear(args.shear))
                sim.run(math.inf, max_collisions=args.n)
                sims.append(sim)
                continue
            st = ini.random_state(args.n, packing, args.dim, seed=args.seed)
            # a tree whose initial state is a set of keyword arguments (as_kwargs) or a state record
            state = ((), st.as_kwargs()) if hasattr(st, "as_kwargs") else ((st,), {})
            sim = eng.Simulation(*state[0], rule=eng.CollisionRule.elastic(), neighbours=args.mode, **state[1])
            sim.run(math.inf, max_collisions=args.n)
            sims.append(sim)
        times = [[], []]
        for r in range(args.rounds):
            for k in ((0, 1) if r % 2 == 0 else (1, 0)):
                sim = sims[k]
                c0 = sim.collisions
                t0 = time.process_time()
                sim.run(math.inf, max_collisions=args.chunk)
                times[k].append((time.process_time() - t0) / (sim.collisions - c0))
        t = np.array(times)
        out[str(packing)] = dict(ratio=float(np.median(t[0] / t[1])),
                                 rate=[float(np.median(1.0 / t[k])) for k in (0, 1)])
    print(json.dumps(out))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("tree_a")
    ap.add_argument("tree_b")
    ap.add_argument("--mode", choices=("lists", "cells", "dsmc"), default="lists",
                    help="the engine's neighbour mode, or dsmc (the DSMC of a constant eps = 0.9 gas)")
    ap.add_argument("--n", type=lambda s: int(float(s)), default=10976)
    ap.add_argument("--packings", type=float, nargs="+", default=[0.3])
    ap.add_argument("--dim", type=int, choices=(2, 3), default=3)
    ap.add_argument("--rounds", type=int, default=40)
    ap.add_argument("--chunk", type=int, default=20000, help="collisions per timed chunk")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--shear", type=float, default=0.0,
                    help="Lees-Edwards shear rate (0: the periodic box); sheared gases have eps = 0.8")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--pkgdir", help=argparse.SUPPRESS)
    ap.add_argument("--order", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(args)
        return 0
    for tree in (args.tree_a, args.tree_b):
        if not os.path.isfile(os.path.join(tree, "granulargas", "__init__.py")):
            print(f"error: {tree}: no granulargas package in this tree", file=sys.stderr)
            return 2
    with tempfile.TemporaryDirectory() as tmp:
        pkgdir = os.path.join(tmp, "pk")
        os.makedirs(pkgdir)
        copy_package(args.tree_a, NAMES[0], pkgdir)
        copy_package(args.tree_b, NAMES[1], pkgdir)
        env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(tmp, "numba"))
        passes = []
        for order in (NAMES, NAMES[::-1]):
            cmd = [sys.executable, os.path.abspath(__file__), args.tree_a, args.tree_b, "--worker",
                   "--pkgdir", pkgdir, "--order", *order, "--mode", args.mode, "--n", str(args.n),
                   "--dim", str(args.dim), "--rounds", str(args.rounds), "--chunk", str(args.chunk),
                   "--seed", str(args.seed), "--shear", str(args.shear), "--packings", *map(str, args.packings)]
            run = subprocess.run(cmd, env=env, capture_output=True, text=True)
            if run.returncode != 0:
                lines = run.stderr.strip().splitlines() or ["(no output)"]
                print(f"error: worker ({' '.join(order)}) failed: {lines[-1]}", file=sys.stderr)
                return 1
            passes.append(json.loads(run.stdout.strip().splitlines()[-1]))
    sheared = f", sheared at a = {args.shear}" if args.shear > 0.0 else ""
    print(f"# {args.mode}{sheared}, {args.dim}D, N = {args.n}, {args.rounds} rounds of {args.chunk} collisions, "
          f"CPU time; B/A = speed of B over A")
    print(f"# A = {args.tree_a}, B = {args.tree_b}")
    print(f"{'packing':>8} {'A M/s':>8} {'B M/s':>8} {'B/A (A first)':>14} {'B/A (B first)':>14} "
          f"{'B/A geo. mean':>14}")
    for p in map(str, args.packings):
        first, second = passes[0][p], passes[1][p]
        ab = first["ratio"]              # B listed second
        ba = 1.0 / second["ratio"]       # B listed first
        rate_a = math.sqrt(first["rate"][0] * second["rate"][1])
        rate_b = math.sqrt(first["rate"][1] * second["rate"][0])
        print(f"{p:>8} {rate_a / 1e6:>8.4f} {rate_b / 1e6:>8.4f} {ab:>14.3f} {ba:>14.3f} "
              f"{math.sqrt(ab * ba):>14.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
