"""Where the event loop spends its time: cycle counters around each part of ``advance``.

The loop ``granulargas.engine._loop.advance`` takes a ``probe`` argument: ``None``
in production, an int64 array here. Its type selects a second build of the same
source with cycle counters (``llvm.readcyclecounter``, :mod:`granulargas.engine._probe`)
between the parts of one event: pop and validation, the collision, the partner's
prediction and calendar update, the list rebuild, a wall collision, the
stale-event path, a driving step, the particle's own prediction and calendar
update, the prefetch hints and the peek at the next event. That build is
compiled once (numba cache) and run on a random state after a warm-up of two
collisions per particle; the table gives cycles per collision and per call of
each part, and how often the prefetch's guess of the event after next was
right. The counters perturb the timing a little (the instrumented rate is
printed beside the cycle totals); compare parts and sizes, not absolute rates
with ``scripts/benchmarks/run.py``.

Usage::

    python scripts/profiling/profile_loop.py 1e4 1e6          # N values, packing 0.3, 3D, elastic
    python scripts/profiling/profile_loop.py 1e5 --packing 0.1
    python scripts/profiling/profile_loop.py 1e4 --walls      # walls on the z axis
    python scripts/profiling/profile_loop.py 1e4 --packing 0.05 --neighbours cells
"""

from __future__ import annotations

import argparse
import time


def profile(n, packing, walls=False, seed=1, neighbours="lists"):
    import numpy as np

    from granulargas.engine import CollisionRule, Simulation, _loop, _probe
    from granulargas.initial import random_state

    st = random_state(n, packing, 3, seed=seed)
    if walls:  # the same gas between walls at z = 0 and L: the spheres touching them are moved in
        pos = st.positions.copy()
        pos[:, 2] = np.clip(pos[:, 2], st.radii, st.box[2] - st.radii)
        st = st.replace(positions=pos, boundary=("periodic", "periodic", "wall"))
    sim = Simulation(st, CollisionRule.elastic(), neighbours=neighbours)
    sim.run(np.inf, max_collisions=2 * n)
    prm = sim._params()
    probe = np.zeros(_probe.PROBE_SIZE, np.int64)

    def go(ncoll):
        c0 = sim.collisions
        w = time.perf_counter()
        e = sim._engine
        status = _loop.advance(e, *_loop.mode_flags(e.cells), prm, np.inf, 10**12, c0 + ncoll, probe)
        assert status == _loop.MAX_COLLISIONS, status
        return time.perf_counter() - w, sim.collisions - c0

    t = time.perf_counter()
    go(1000)
    compile_s = time.perf_counter() - t
    probe[:] = 0
    dt, nc = go(max(300_000, n))
    parts = _probe.PARTS
    total = probe[:parts].sum()
    print(f"N = {n}, packing {packing}{', walls on z' if walls else ''}, {sim.neighbours}: {nc / dt / 1e6:.3f} M "
          f"collisions/s instrumented, {total / nc:.0f} cycles per collision ({dt / nc * 1e9:.0f} ns); "
          f"compile or cache load {compile_s:.1f} s")
    for k, name in enumerate(_probe.PART_NAMES):
        calls = probe[parts + k]
        if calls == 0:
            continue
        print(f"  {name:16s} {probe[k] / nc:7.0f} cycles/collision {100 * probe[k] / total:5.1f} %"
              f"  calls/collision {calls / nc:.2f}  cycles/call {probe[k] / calls:.0f}")
    print(f"  the event after next, guessed for the prefetch: right for "
          f"{100 * probe[_probe.GUESSED] / max(1, probe[_probe.GUESSES]):.1f} % of events")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("sizes", type=float, nargs="+", help="numbers of spheres")
    p.add_argument("--packing", type=float, default=0.3)
    p.add_argument("--walls", action="store_true", help="flat walls at z = 0 and L")
    p.add_argument("--neighbours", choices=["lists", "cells"], default="lists",
                   help="neighbour search (cells: the 'list rebuild' part is the cell crossing)")
    args = p.parse_args(argv)
    if any(n < 100 for n in args.sizes) or not 0.0 < args.packing <= 0.5:
        p.error("sizes must be >= 100 and 0 < --packing <= 0.5")
    for n in args.sizes:
        profile(int(n), args.packing, args.walls, neighbours=args.neighbours)


if __name__ == "__main__":
    main()
