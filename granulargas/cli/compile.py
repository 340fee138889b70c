"""Compile every kind of run once, ahead of the first runs.

``granulargas compile [VARIANT ...] [--jobs N]``: builds each compiled variant
(:data:`granulargas.run.variants.VARIANTS`; default: all) in a process of its own, at
most N at once (default: the number of CPUs), by a tiny run of that kind, so that
the first real run of each kind loads its kernels from numba's cache instead of
compiling them. Prints one line per variant as it finishes (compiled or already
cached, with its time) and a total.
"""

from __future__ import annotations

import os
import time

from granulargas._numba import cache_location
from granulargas.errors import ConfigError, SimulationError
from granulargas.run.variants import BY_NAME, build_all


def configure_parser(parser):
    parser.add_argument("variants", nargs="*", metavar="VARIANT",
                        help=f"what to compile (default: all): {', '.join(BY_NAME)}")
    parser.add_argument("--jobs", "-j", type=int, default=None, metavar="N",
                        help="build at most N variants at once (default: the number of CPUs)")


def run(args) -> int:
    for name in args.variants:
        if name not in BY_NAME:
            raise ConfigError(f"compile {name}: not a variant; one of {', '.join(BY_NAME)}")
    if args.jobs is not None and args.jobs < 1:
        raise ConfigError(f"--jobs = {args.jobs}: must be at least 1")
    jobs = args.jobs or os.cpu_count() or 1
    names = args.variants or list(BY_NAME)
    print(f"compiling {len(names)} variant{'s' if len(names) != 1 else ''}, {jobs} at a time, into "
          f"{cache_location()}", flush=True)
    wall = time.perf_counter()
    failed = []

    def report(b):
        what = BY_NAME[b.name].what
        if b.error:
            failed.append(b.name)
            print(f"failed    {b.name:16s} {what}: {b.error}", flush=True)
        elif b.compiled:
            print(f"compiled  {b.name:16s} {b.compile_seconds:6.1f} s ({b.cpu_seconds:.1f} s CPU in all)  {what}",
                  flush=True)
        else:
            print(f"cached    {b.name:16s} {b.wall_seconds:6.1f} s  {what}", flush=True)

    built = build_all(names, jobs=jobs, report=report)
    cpu = sum(b.cpu_seconds for b in built)
    compiled = sum(1 for b in built if b.compiled and not b.error)
    print(f"done in {time.perf_counter() - wall:.1f} s ({cpu:.1f} s CPU): {compiled} compiled, "
          f"{len(built) - compiled - len(failed)} already cached, {len(failed)} failed", flush=True)
    if failed:
        raise SimulationError(f"compile: {', '.join(failed)} failed (the lines above say why)")
    return 0
