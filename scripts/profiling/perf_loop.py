"""Where the production event loop spends its time, by source line: ``perf`` samples mapped
onto numba's compiled code.

``scripts/profiling/profile_loop.py`` times the parts of an event with counters compiled into a
second build of the loop; this script samples the production build instead. It runs
itself under ``perf record -e cpu-clock`` (a software clock: it needs no hardware
counters, which virtual machines often lack) with an empty numba cache and
``NUMBA_DEBUGINFO=1``, so that every kernel is compiled in the process and carries a
line table. After the timed run the child writes each engine kernel's object code
(numba keeps it for its cache) and a ``/tmp/perf-PID.map`` of their symbols, so that
``perf`` names the samples; the parent then maps each sample's address to a source
line with ``objdump -dl`` and prints the share of the samples in compiled code per
source function and per line (inlined code counts where its own source is). The
debug information may change the generated code a little: read shares, not rates.
The first compile takes as long as without cache (~20 s).

Usage::

    python scripts/profiling/perf_loop.py 10976 --packing 0.05 --neighbours cells
    python scripts/profiling/perf_loop.py 1e5 --collisions 2e6 --lines 40
    python scripts/profiling/perf_loop.py 1e5 --packing 0.1 --eps 0.8 --shear 0.5905
"""

from __future__ import annotations

import argparse
import ast
import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def child(args, out):
    """The timed run; then the engine kernels' object code and the perf map."""
    import warnings

    import numpy as np
    from numba.core.errors import NumbaDebugInfoWarning
    from numba.core.registry import CPUDispatcher

    warnings.simplefilter("ignore", NumbaDebugInfoWarning)

    from granulargas.engine import CollisionRule, Simulation
    from granulargas.initial import random_state

    n = int(float(args.n))
    rule = CollisionRule.elastic() if args.eps is None else CollisionRule.constant(args.eps)
    if args.shear:
        from granulargas.engine.shear import Shear

        st = random_state(n, args.packing, 3, seed=1, boundary=("periodic", "lees-edwards", "periodic"),
                          shear=args.shear)
        sim = Simulation(st, rule, neighbours=args.neighbours, shear=Shear(args.shear))
    else:
        sim = Simulation(random_state(n, args.packing, 3, seed=1), rule, neighbours=args.neighbours,
                         stress=args.eps is not None)
    sim.run(np.inf, max_collisions=2 * sim.n)
    t0 = time.process_time()
    sim.run(np.inf, max_collisions=int(float(args.collisions)))
    print(f"{int(float(args.collisions)) / (time.process_time() - t0) / 1e6:.4f} M collisions/s "
          f"(with the sampling and the debug information)", flush=True)
    entries = []
    seen = set()
    for name, mod in list(sys.modules.items()):
        if not name.startswith("granulargas.engine"):
            continue
        for attr, disp in vars(mod).items():
            if not isinstance(disp, CPUDispatcher) or id(disp) in seen:
                continue
            seen.add(id(disp))
            for k, cres in enumerate(disp.overloads.values()):
                try:
                    addr = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)
                    obj = cres.library.serialize_using_object_code()[2][0]
                except Exception:  # noqa: BLE001 - a kernel without object code is left out
                    continue
                path = out / f"{attr}.{k}.o"
                path.write_bytes(obj)
                syms = {}
                for line in subprocess.run(["nm", "-S", "--defined-only", str(path)], capture_output=True,
                                           text=True).stdout.splitlines():
                    parts = line.split()
                    if len(parts) == 4 and parts[2] in "tT":
                        syms[parts[3]] = (int(parts[0], 16), int(parts[1], 16))
                base = addr - syms[cres.fndesc.llvm_func_name][0]
                (out / f"{attr}.{k}.base").write_text(f"{base}\n")
                entries += [(base + o, size, f"{attr}.{k}") for o, size in syms.values()]
    (out / "pid").write_text(f"{os.getpid()}\n")
    with open(f"/tmp/perf-{os.getpid()}.map", "w") as fh:
        for a, size, nm in sorted(entries):
            fh.write(f"{a:x} {size:x} {nm}\n")


def functions_by_line(root):
    """(file name, line) -> name of the innermost function there, for the engine's sources."""
    names = {}
    for path in Path(root).glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for line in range(node.lineno, node.end_lineno + 1):
                    names[(path.name, line)] = node.name
    return names


def report(out, lines):
    """Samples per source function and per source line of the kernels in ``out``."""
    samples = collections.defaultdict(collections.Counter)
    script = subprocess.run(["perf", "script", "-i", str(out / "perf.data"), "-F", "ip,sym"],
                            capture_output=True, text=True).stdout
    total = 0
    for line in script.splitlines():
        parts = line.split(None, 1)
        if len(parts) == 2:
            total += 1
            samples[parts[1].strip()][int(parts[0], 16)] += 1
    by_line = collections.Counter()
    for obj in sorted(out.glob("*.o")):
        kernel = obj.stem
        if kernel not in samples:
            continue
        base = int((out / f"{kernel}.base").read_text())
        here = "?"
        for text in subprocess.run(["objdump", "-dl", "--no-show-raw-insn", str(obj)], capture_output=True,
                                   text=True).stdout.splitlines():
            m = re.match(r"^(/\S+\.py):(\d+)", text)
            if m:
                here = f"{Path(m.group(1)).name}:{m.group(2)}"
                continue
            m = re.match(r"\s*([0-9a-f]+):\s", text)
            if m:
                c = samples[kernel].get(base + int(m.group(1), 16), 0)
                if c:
                    by_line[(kernel, here)] += c
    compiled = sum(by_line.values())
    if compiled == 0:
        print("no samples in compiled code (is perf allowed to sample this process?)")
        return
    import granulargas.engine

    names = functions_by_line(Path(granulargas.engine.__file__).parent)
    by_function = collections.Counter()
    for (kernel, here), c in by_line.items():
        file, _, num = here.partition(":")
        by_function[names.get((file, int(num)), file) if num else here] += c
    print(f"{compiled} samples in compiled code ({100 * compiled / max(total, 1):.0f} % of all, "
          f"the rest is set-up and compilation)")
    print("per source function (inlined code counted where its source is):")
    for name, c in by_function.most_common(lines):
        print(f"  {100 * c / compiled:5.1f} %  {name}")
    print("per source line (kernel, file:line):")
    for (kernel, here), c in by_line.most_common(lines):
        print(f"  {100 * c / compiled:5.1f} %  {kernel:28s} {here}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("n", help="number of spheres (3D, elastic, random state, seed 1)")
    p.add_argument("--packing", type=float, default=0.3)
    p.add_argument("--neighbours", choices=("lists", "cells"), default="lists")
    p.add_argument("--eps", type=float, help="constant coefficient of restitution (default: elastic); "
                   "an inelastic periodic gas keeps the stress sums on, as a sheared one")
    p.add_argument("--shear", type=float, default=0.0,
                   help="Lees-Edwards shear rate (flow x, gradient y; with --eps 0.8 and packing 0.1 the "
                        "steady rate is 0.5905, the gas of scripts/benchmarks/shear.py)")
    p.add_argument("--collisions", default="2e6", help="collisions of the sampled run")
    p.add_argument("--lines", type=int, default=30, help="rows of each table")
    p.add_argument("--child", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.child:
        child(args, Path(args.child))
        return 0
    for tool in ("perf", "nm", "objdump"):
        if shutil.which(tool) is None:
            print(f"scripts/profiling/perf_loop.py: '{tool}' not found on PATH (needs perf and binutils)", file=sys.stderr)
            return 2
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        env = dict(os.environ, NUMBA_CACHE_DIR=str(out / "cache"), NUMBA_DEBUGINFO="1")
        cmd = ["perf", "record", "-q", "-e", "cpu-clock", "-F", "4000", "-o", str(out / "perf.data"),
               sys.executable, __file__, *(argv if argv is not None else sys.argv[1:]), "--child", str(out)]
        run = subprocess.run(cmd, env=env)
        if run.returncode != 0:
            print(f"scripts/profiling/perf_loop.py: the sampled run failed (exit {run.returncode})", file=sys.stderr)
            return 2
        report(out, args.lines)
        pid = out / "pid"
        if pid.exists():
            Path(f"/tmp/perf-{pid.read_text().strip()}.map").unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
