"""First-run start-up: the quickstart on a fresh install, each further kind of run, a warm run.

Every measurement is a fresh process (``python -m granulargas run ...``); the figure is
the CPU time of that process (user + sys, from ``os.wait4``), which the machine's load
changes far less than the wall clock, with the run's own start-up and compile figures
(its summary line) beside it:

* ``quickstart``: ``granulargas run configs/quickstart.toml`` with an empty numba cache
  and an empty table cache (``NUMBA_CACHE_DIR``, ``GRANULARGAS_CACHE_DIR`` fresh
  folders): what the README's first command costs on a fresh install;
* ``variants``: from a copy of the cache the quickstart left, one short run of each
  further kind (2D, driven, walls, DSMC, constant eps, dense 3D with neighbour lists, 2D with
  neighbour lists),
  each from its own copy: what the first run of that kind adds;
* ``warm``: a small 2D run (400 disks, 5 collisions per particle) with everything
  cached (compiled code, tables, the run's predictions, :mod:`granulargas.run.predictions`),
  the per-run overhead of a sweep of small runs made as separate commands;
* ``engine`` (not in the default set): the first compile of the event loop alone per
  neighbour mode (``--modes``), a 64-sphere run timed after the import and the initial
  state, for source trees side by side (``--trees``, alternated rounds).

Python's bytecode cache is on in every process (``_bytecode_cache``), as on an install.

Prints every round and the medians, with the load average at the start.

Usage::

    python scripts/benchmarks/startup.py                          # quickstart, variants, warm; 3 rounds
    python scripts/benchmarks/startup.py --what quickstart --rounds 5
    python scripts/benchmarks/startup.py --what variants --trees /tmp/main . --rounds 2
    python scripts/benchmarks/startup.py --what engine --trees /tmp/main . --modes lists cells --core 1
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

#: the further kinds of run, each after the quickstart: (name, config, overrides)
SHORT = ["--set", "system.particles=500", "--set", "run.collisions_per_particle=5"]
VARIANT_RUNS = [
    ("2D", "haff_2d.toml", SHORT),
    ("driven", "driven_3d.toml", SHORT),
    ("walls", "walls_3d.toml", SHORT),
    ("DSMC", "hcs_dsmc_3d.toml", SHORT),
    ("constant eps", "haff_3d.toml", SHORT),
    ("lists 3D", "elastic_3d.toml", SHORT),
    ("lists 2D", "haff_2d.toml", SHORT + ["--set", 'run.neighbours="lists"']),
]
#: the rows of the performance page's start-up table: (id in the results file, text) per row name
PAGE_ROWS = {
    "quickstart (fresh install)": ("0", "quickstart on a fresh install (empty numba and table caches)"),
    "after the quickstart: 2D": ("1", "then a 2D run (cell crossings)"),
    "after the quickstart: driven": ("2", "then a driven run (the driving step)"),
    "after the quickstart: walls": ("3", "then a run with walls"),
    "after the quickstart: DSMC": ("4", "then a DSMC run"),
    "after the quickstart: constant eps": ("5", "then a constant-ε run"),
    "after the quickstart: lists 3D": ("6", "then dense 3D (neighbour lists, placement with pushes)"),
    "after the quickstart: lists 2D": ("6a", "then a 2D run with neighbour lists (no pushes)"),
    "warm small 2D run (400 disks)": ("7", "a warm run (everything cached), 400 disks"),
}
WARM = ("haff_2d.toml", ["--set", "system.particles=400", "--set", "run.collisions_per_particle=5"])

_STARTUP = re.compile(r"\+ ([0-9.e+-]+) s start-up \((?:([0-9.e+-]+) s of it compiling)?")

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


def run_cli(args, numba_cache, table_cache, tree=ROOT, core=None):
    """(CPU s of the process, wall s, start-up s, compile s) of ``granulargas ARGS`` in a fresh process."""
    cmd = [sys.executable, "-m", "granulargas", *args]
    if core is not None and shutil.which("taskset"):
        cmd = ["taskset", "-c", str(core)] + cmd
    env = dict(os.environ, PYTHONPATH=os.path.abspath(tree), NUMBA_CACHE_DIR=numba_cache,
               GRANULARGAS_CACHE_DIR=table_cache)
    env.pop("GRANULARGAS_NO_CACHE", None)
    _bytecode_cache(env)
    wall = time.perf_counter()
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(cmd, env=env, cwd=tree, stdout=out, stderr=err, text=True)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - wall
        out.seek(0)
        err.seek(0)
        text, errors = out.read(), err.read()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"granulargas {' '.join(args)} failed:\n{errors[-2000:]}")
    m = _STARTUP.search(text)
    startup = float(m.group(1)) if m else float("nan")
    compiled = float(m.group(2)) if m and m.group(2) else 0.0
    return usage.ru_utime + usage.ru_stime, wall, startup, compiled


def _bytecode_cache(env):
    """Python's bytecode cache on (``__pycache__`` beside the sources, git ignores it), as on an
    installed package, whose ``.pyc`` files pip writes. An environment may turn it off
    (PYTHONDONTWRITEBYTECODE); each process then compiles every module of the package again,
    ~0.15 s of CPU of a warm run."""
    env.pop("PYTHONDONTWRITEBYTECODE", None)


def engine_compile(tree, mode, cache, core=None):
    """(CPU s, wall s) of one fresh process's first engine run against ``tree`` with numba cache ``cache``."""
    cmd = [sys.executable, "-c", _CHILD, mode]
    if core is not None and shutil.which("taskset"):
        cmd = ["taskset", "-c", str(core)] + cmd
    env = dict(os.environ, PYTHONPATH=os.path.abspath(tree), NUMBA_CACHE_DIR=cache)
    env.pop("GRANULARGAS_NO_CACHE", None)
    _bytecode_cache(env)
    out = subprocess.run(cmd, env=env, cwd=tree, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{tree}: run failed:\n{out.stderr[-2000:]}")
    cpu, wall = (float(x) for x in out.stdout.split())
    return cpu, wall


def _line(name, r):
    cpu, wall, startup, compiled = r
    return f"{name}: CPU {cpu:.1f} s, wall {wall:.1f} s; summary start-up {startup:.3g} s, compiling {compiled:.3g} s"


def first_runs(args, rows, tree=ROOT):
    """One round of quickstart / variants / warm (module docstring) with the package of
    ``tree``, appended to ``rows`` (keys prefixed with the tree when several are compared)."""
    tag = f"[{tree}] " if len(args.trees) > 1 else ""
    work = tempfile.mkdtemp(prefix="bench-compile-")
    try:
        numba_cache, table_cache = os.path.join(work, "numba"), os.path.join(work, "tables")
        out = os.path.join(work, "out.h5")
        qs = run_cli(["run", "configs/quickstart.toml", "--output", out, "--quiet"], numba_cache, table_cache,
                     tree=tree, core=args.core)
        if "quickstart" in args.what:
            rows.setdefault(tag + "quickstart (fresh install)", []).append(qs)
            print(_line(tag + "quickstart (fresh install)", qs), flush=True)
        if "variants" in args.what:
            for name, config, extra in VARIANT_RUNS:
                copy = os.path.join(work, f"numba-{len(rows)}-{name}")
                shutil.copytree(numba_cache, copy)
                r = run_cli(["run", f"configs/{config}", "--output", out, "--overwrite", "--quiet", *extra], copy,
                            table_cache, tree=tree, core=args.core)
                shutil.rmtree(copy, ignore_errors=True)
                rows.setdefault(f"{tag}after the quickstart: {name}", []).append(r)
                print(_line(f"{tag}after the quickstart: {name}", r), flush=True)
        if "warm" in args.what:
            config, extra = WARM
            run_cli(["run", f"configs/{config}", "--output", out, "--overwrite", "--quiet", *extra], numba_cache,
                    table_cache, tree=tree, core=args.core)  # compiles the 2D run's kernels
            r = run_cli(["run", f"configs/{config}", "--output", out, "--overwrite", "--quiet", *extra], numba_cache,
                        table_cache, tree=tree, core=args.core)
            rows.setdefault(tag + "warm small 2D run (400 disks)", []).append(r)
            print(_line(tag + "warm small 2D run (400 disks)", r), flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--what", nargs="+", default=["quickstart", "variants", "warm"],
                   choices=["quickstart", "variants", "warm", "engine"])
    p.add_argument("--trees", nargs="+", default=[ROOT],
                   help="source trees to compare, alternated (default: this one; the configs are this tree's)")
    p.add_argument("--modes", nargs="+", default=["lists", "cells"], choices=["lists", "cells"])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--core", type=int, default=None, help="pin the runs to this core (taskset)")
    p.add_argument("--record", action="store_true", help="write the medians into docs/performance/results.json "
                   "and rewrite the performance page (one tree only)")
    args = p.parse_args(argv)
    if args.record and len(args.trees) > 1:
        p.error("--record: measures one source tree; give one --trees entry")
    load = os.getloadavg()[0]
    commit = _commit()
    for tree in args.trees:
        if not os.path.isdir(os.path.join(tree, "granulargas")):
            p.error(f"--trees {tree}: no granulargas package there")
    print(f"# fresh processes, {args.rounds} rounds, load average {os.getloadavg()[0]:.2f} at start; CPU = user + sys",
          flush=True)
    rows = {}
    first, cached = {}, {}
    for r in range(args.rounds):
        order = args.trees if r % 2 == 0 else args.trees[::-1]
        if set(args.what) - {"engine"}:
            for tree in order:
                first_runs(args, rows, tree)
        if "engine" not in args.what:
            continue
        for mode in args.modes:
            for tree in order:
                cache = tempfile.mkdtemp(prefix="numba-cache-")
                try:
                    f = engine_compile(tree, mode, cache, args.core)
                    c = engine_compile(tree, mode, cache, args.core)
                finally:
                    shutil.rmtree(cache, ignore_errors=True)
                first.setdefault((tree, mode), []).append(f)
                cached.setdefault((tree, mode), []).append(c)
                print(f"round {r} {mode:5s} {tree}: first CPU {f[0]:.1f} s, wall {f[1]:.1f} s; "
                      f"cached CPU {c[0]:.2f} s, wall {c[1]:.2f} s", flush=True)
    print(f"# medians of {args.rounds} rounds (load average {os.getloadavg()[0]:.2f} at the end)")
    for name, rs in rows.items():
        med = [statistics.median(x[k] for x in rs) for k in range(4)]
        print(_line(name, med) + f" (CPU {min(x[0] for x in rs):.1f}-{max(x[0] for x in rs):.1f})")
    for mode in args.modes if "engine" in args.what else []:
        for tree in args.trees:
            f, c = first[(tree, mode)], cached[(tree, mode)]
            print(f"engine {mode:5s} {tree}: first compile CPU {statistics.median(x[0] for x in f):.1f} s, "
                  f"wall {statistics.median(x[1] for x in f):.1f} s; cached load CPU "
                  f"{statistics.median(x[0] for x in c):.2f} s, wall {statistics.median(x[1] for x in c):.2f} s")
    if args.record:
        record(args, rows, first, cached, argv if argv is not None else sys.argv[1:], max(load, os.getloadavg()[0]),
               commit)
    return 0


def record(args, rows, first, cached, argv, load, commit):
    """The medians as records of the results file (tables ``startup`` and ``compile``); rewrite the page."""
    sys.path.insert(0, HERE)
    import results

    records = []
    for name, rs in rows.items():
        key, what = PAGE_ROWS[name]
        cpu = [x[0] for x in rs]
        digits = 2 if max(cpu) < 5.0 else 1
        # no compile column: a run's summary gives its compile time on the wall clock, which a
        # loaded machine stretches beyond the process's CPU time
        records.append(dict(table="startup", id=f"{key} {what}", what=what,
                            cpu_seconds=round(statistics.median(cpu), digits),
                            cpu_range=[round(min(cpu), digits), round(max(cpu), digits)],
                            compile_seconds=None, rounds=len(rs)))
    for (tree, mode), f in first.items():
        records.append(dict(table="compile", id=f"3D {mode}", neighbours=mode,
                            first_seconds=round(statistics.median(x[0] for x in f), 1),
                            cached_seconds=round(statistics.median(x[0] for x in cached[(tree, mode)]), 2)))
    results.record_and_render(records, "python scripts/benchmarks/startup.py " + " ".join(argv), load_average=load,
                              commit=commit)


def _commit():
    """The source tree's commit when the measurement starts (``scripts/benchmarks/results.py``)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import results

    return results.this_commit()


if __name__ == "__main__":
    sys.exit(main())
