"""Where a first run's compile time goes: per compiled function, per compiler pass, LLVM.

Runs ``granulargas run CONFIG`` in a fresh process with an empty numba cache, or with
the cache that a run of ``--after`` left (e.g. the quickstart: what a further kind of
run adds), and listens to numba's events in that process: ``numba:compile`` (one per
function compiled, none for a function loaded from the cache), ``numba:run_pass`` (the
compiler's passes) and ``numba:llvm_lock`` (LLVM's work: parsing, optimisation, machine
code). Times are CPU seconds (``time.process_time``), *exclusive*: a function's time
excludes that of the functions compiled while compiling it (its callees), a pass's time
excludes the compilations it triggers (type inference compiles the callees), so the rows
add up to the compile time. Prints the process's CPU time, the compile total, the
functions by exclusive time (with their passes' split: type inference, lowering to LLVM
IR + LLVM, IR inlining), the passes in total, the functions compiled with several
signatures, and those compiled again with a signature ``--after`` had already compiled.

Usage::

    python scripts/profiling/compile_profile.py configs/haff_2d.toml --after configs/quickstart.toml \\
        --set system.particles=500 --set run.collisions_per_particle=5
    python scripts/profiling/compile_profile.py configs/quickstart.toml --top 30
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def _child(argv, out_json):
    """Run ``granulargas run ARGV`` in this process with numba's events recorded into ``out_json``."""
    from numba.core import event

    compiles = []  # [name, signature, CPU s inclusive, exclusive, {pass: exclusive s}, llvm s]
    stack = []  # open compilations: [name, signature, start, CPU s of callees, passes, llvm]
    passes = []  # open passes: [name, start, CPU s of nested compilations and passes, compile depth]
    llvm = []  # open LLVM sections: [start]

    class Compiles(event.Listener):
        def on_start(self, ev):
            f = ev.data["dispatcher"].py_func
            stack.append([f"{f.__module__}.{f.__qualname__}", str(ev.data["args"]), time.process_time(), 0.0,
                          collections.Counter(), 0.0])

        def on_end(self, ev):
            name, sig, start, callees, by_pass, ll = stack.pop()
            inclusive = time.process_time() - start
            if stack:
                stack[-1][3] += inclusive
            if passes and passes[-1][3] == len(stack):  # the caller's pass that compiled it
                passes[-1][2] += inclusive
            compiles.append([name, sig, inclusive, inclusive - callees, dict(by_pass), ll])

    class Passes(event.Listener):
        def on_start(self, ev):
            passes.append([ev.data["name"].split(" [")[0], time.process_time(), 0.0, len(stack)])

        def on_end(self, ev):
            name, start, nested, depth = passes.pop()
            inclusive = time.process_time() - start
            if passes and passes[-1][3] == depth:  # a pass within a pass of the same function
                passes[-1][2] += inclusive
            if stack:
                stack[-1][4][name] += inclusive - nested

    class Llvm(event.Listener):
        def on_start(self, ev):
            llvm.append(time.process_time())

        def on_end(self, ev):
            spent = time.process_time() - llvm.pop()
            if stack and not llvm:
                stack[-1][5] += spent

    event.register("numba:compile", Compiles())
    event.register("numba:run_pass", Passes())
    event.register("numba:llvm_lock", Llvm())
    from granulargas.cli import main

    try:
        main(["run", *argv])
    except SystemExit:
        pass
    with open(out_json, "w") as f:
        json.dump(compiles, f)


def _run(args, numba_cache, table_cache, record=None):
    """CPU s (user + sys) of a fresh process running ``granulargas run ARGS`` (recorded into ``record``)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=numba_cache, GRANULARGAS_CACHE_DIR=table_cache, PYTHONPATH=ROOT)
    env.pop("GRANULARGAS_NO_CACHE", None)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    if record:
        cmd = [sys.executable, os.path.abspath(__file__), "--child", record, *args]
    else:
        cmd = [sys.executable, "-m", "granulargas", "run", *args]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"granulargas run {' '.join(args)} failed:\n{proc.stderr[-2000:]}")
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def _short(name):
    return name.replace("granulargas.", "").replace("numba.cpython.", "")


def main(argv=None):
    if argv is None:
        argv = sys.argv[1:]
    if argv and argv[0] == "--child":
        return _child(argv[2:], argv[1])
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("config")
    p.add_argument("--after", help="a config run first (its compiled code is in the cache, not counted)")
    p.add_argument("--set", action="append", default=[], help="key=value for the profiled run (granulargas run --set)")
    p.add_argument("--top", type=int, default=25, help="functions listed")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="compile-profile-") as work:
        numba_cache, tables = os.path.join(work, "numba"), os.path.join(work, "tables")
        out = ["--output", os.path.join(work, "out.h5"), "--overwrite", "--quiet"]
        before = []
        if args.after:
            before_json = os.path.join(work, "after.json")
            cpu = _run([args.after, *out], numba_cache, tables, record=before_json)
            with open(before_json) as f:
                before = json.load(f)
            print(f"# {args.after}: {cpu:.2f} s of CPU, {sum(r[3] for r in before):.2f} s compiling "
                  f"({len(before)} functions)")
        rows_json = os.path.join(work, "rows.json")
        extra = [x for kv in args.set for x in ("--set", kv)]
        load = os.getloadavg()[0]
        cpu = _run([args.config, *out, *extra], numba_cache, tables, record=rows_json)
        with open(rows_json) as f:
            rows = json.load(f)
    total = sum(r[3] for r in rows)
    by_pass = collections.Counter()
    for r in rows:
        by_pass.update(r[4])
    print(f"# {args.config}{' after ' + args.after if args.after else ''}: {cpu:.2f} s of CPU "
          f"(load {load:.2f}), {total:.2f} s compiling in {len(rows)} functions, "
          f"{sum(r[5] for r in rows):.2f} s of it in LLVM")
    print(f"{'excl s':>7} {'incl s':>7} {'types':>6} {'lower':>6} {'llvm':>6} {'inline':>6}  function")
    for name, sig, incl, excl, passes, ll in sorted(rows, key=lambda r: -r[3])[:args.top]:
        inline = passes.get("inline_inlinables", 0.0) + passes.get("inline_closure_likes", 0.0)
        print(f"{excl:7.3f} {incl:7.3f} {passes.get('nopython_type_inference', 0.0):6.3f} "
              f"{passes.get('native_lowering', 0.0):6.3f} {ll:6.3f} {inline:6.3f}  {_short(name)}")
    print("passes (exclusive s):", ", ".join(f"{n} {t:.2f}" for n, t in by_pass.most_common(8)))
    counts = collections.Counter(r[0] for r in rows)
    several = [f"{_short(n)} x{c}" for n, c in counts.items() if c > 1]
    print("compiled with several signatures:", ", ".join(several) or "none")
    seen = {(r[0], r[1]) for r in before}
    again = [r for r in rows if (r[0], r[1]) in seen]
    if args.after:
        print(f"compiled again with a signature {args.after} compiled: {len(again)} functions, "
              f"{sum(r[3] for r in again):.2f} s", (", ".join(sorted({_short(r[0]) for r in again}))))


if __name__ == "__main__":
    main()
