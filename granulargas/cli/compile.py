"""Compile every kind of run once, ahead of the first runs.

``granulargas compile [VARIANT ...] [--jobs N]``: builds each compiled variant
(:data:`granulargas.run.variants.VARIANTS`; default: all) in a process of its own, at
most N at once (default: the number of CPUs), by a tiny run of that kind, so that
the first real run of each kind loads its kernels from numba's cache instead of
compiling them. Prints one line per variant as it finishes (compiled or already
cached, with its time) and a total.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass

from granulargas import _numba
from granulargas._numba import cache_location
from granulargas.errors import ConfigError, SimulationError
from granulargas.run.advise import method_line, summary_line
from granulargas.run.runner import run_config
from granulargas.run.validity import raise_if_invalid
from granulargas.run.variants import BY_NAME, tiny_config, walled_twin


def build(name: str) -> None:
    """Compile (or load from the cache) the kernels of variant ``name`` in this process: a
    tiny run of that kind by the steps of ``granulargas run`` (the checks before the run,
    the run, the advice after it), and for an engine variant without walls the same run in
    a box with walls at rest (its second build)."""
    variant = BY_NAME[name]
    if variant.build is not None:
        variant.build()
        return
    with tempfile.TemporaryDirectory(prefix="granulargas-compile-") as tmp:
        configs = [tiny_config(variant, tmp)] + ([walled_twin(variant, tmp)] if variant.walled else [])
        for config in configs:
            raise_if_invalid(config)
            run_config(config, quiet=True, log=lambda line: None)
            summary_line(config)
            method_line(config)


@dataclass
class Built:
    """What building one variant took: ``compiled`` functions (0: all loaded from the cache),
    ``compile_seconds`` (wall clock), ``cpu_seconds`` and ``wall_seconds`` of its process."""

    name: str
    compiled: int
    compile_seconds: float
    cpu_seconds: float
    wall_seconds: float
    error: str = ""


_CHILD = "import sys; from granulargas.cli.compile import _child; _child(sys.argv[1])"


def _child(name: str) -> None:
    """Entry point of a build process: build ``name``, print a :class:`Built` as JSON."""
    wall = time.perf_counter()
    with _numba.CompileWatch() as watch:
        build(name)
    times = os.times()
    print(json.dumps({"name": name, "compiled": watch.count, "compile_seconds": watch.seconds,
                      "cpu_seconds": times.user + times.system, "wall_seconds": time.perf_counter() - wall}))


def build_all(names=None, jobs: int | None = None, report=None) -> list[Built]:
    """Build the variants ``names`` (default: all), each in a process of its own, at most
    ``jobs`` at once (default: the number of CPUs), a variant after those it builds on.
    ``report(built)`` is called as each one finishes. Returns them in order of completion."""
    names = list(BY_NAME) if not names else list(names)
    jobs = max(1, jobs or os.cpu_count() or 1)
    pending = [n for n in BY_NAME if n in names]
    running: dict[str, tuple[subprocess.Popen, float]] = {}
    done: list[Built] = []
    finished: set[str] = set()
    while pending or running:
        for n in list(pending):
            if len(running) >= jobs:
                break
            if all(dep in finished or dep not in names for dep in BY_NAME[n].after):
                cmd = [sys.executable, "-c", _CHILD, n]
                running[n] = (subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True),
                              time.perf_counter())
                pending.remove(n)
        time.sleep(0.05)
        for n, (proc, start) in list(running.items()):
            if proc.poll() is None:
                continue
            out, err = proc.communicate()
            del running[n]
            finished.add(n)
            try:
                b = Built(**json.loads(out.strip().splitlines()[-1]))
            except (ValueError, IndexError, TypeError):
                b = Built(n, 0, 0.0, 0.0, time.perf_counter() - start,
                          error=(err.strip().splitlines() or ["failed"])[-1])
            done.append(b)
            if report is not None:
                report(b)
    return done


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
