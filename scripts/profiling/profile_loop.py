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
    python scripts/profiling/profile_loop.py 1e4 --packing 0.1 --shear   # Lees-Edwards vs periodic

``--shear``: the gas of ``scripts/benchmarks/shear.py`` (constant eps = 0.8, the steady
shear rate of the packing) under Lees-Edwards boundaries, and the same gas in a periodic
box with the stress sums on, profiled one after the other; the "global events" part is
the slides of the sliding rows (cell mode). Each table also gives the events per
collision by kind and the pair predictions per collision (list mode: list entries
scanned by the predictions).
"""

from __future__ import annotations

import argparse
import time


def _make(n, packing, walls, seed, neighbours, shear, shell):
    import numpy as np

    from granulargas.engine import CollisionRule, Simulation
    from granulargas.initial import random_state

    kw = {} if shell is None else {"shell": shell}
    if shear is not None:
        from granulargas.engine.shear import Shear

        boundary = ("periodic", "lees-edwards", "periodic")
        rule = CollisionRule.constant(0.8)
        if shear > 0:
            return Simulation(random_state(n, packing, 3, seed=seed, boundary=boundary, shear=shear), rule,
                              neighbours=neighbours, shear=Shear(shear), **kw)
        return Simulation(random_state(n, packing, 3, seed=seed), rule, neighbours=neighbours, stress=True, **kw)
    st = random_state(n, packing, 3, seed=seed)
    if walls:  # the same gas between walls at z = 0 and L: the spheres touching them are moved in
        pos = st.positions.copy()
        pos[:, 2] = np.clip(pos[:, 2], st.radii, st.box[2] - st.radii)
        st = st.replace(positions=pos, boundary=("periodic", "periodic", "wall"))
    return Simulation(st, CollisionRule.elastic(), neighbours=neighbours, **kw)


def profile(n, packing, walls=False, seed=1, neighbours="lists", shear=None, shell=None):
    """Profile one gas; ``shear``: None (elastic, the default gas), a rate > 0 (sheared) or 0
    (the sheared benchmark's gas in a periodic box)."""
    import numpy as np

    from granulargas.engine import _loop, _probe
    from granulargas.engine._calendar import cal_width
    from granulargas.engine._cells import CELL_OVERFLOW, OVERFLOW

    sim = _make(n, packing, walls, seed, neighbours, shear, shell)
    sim.run(np.inf, max_collisions=2 * n)
    prm = sim._params()
    probe = np.zeros(_probe.PROBE_SIZE, np.int64)
    sheared = sim.shear is not None

    def go(ncoll):
        # chunks of N collisions, between which the calendar's window is matched to the
        # event rate as Simulation.run does (a cooling gas slows down); a full list or
        # cell table is widened as there
        c0 = sim.collisions
        w = time.perf_counter()
        while sim.collisions < c0 + ncoll:
            cal = sim._engine.calendar
            if not 0.5 <= cal_width(sim.time, cal.qt) / float(cal.state[0]["width"]) <= 2.0:
                sim._place_events(sim.time)
            e = sim._engine
            target = min(c0 + ncoll, sim.collisions + n)
            if sheared:
                status = _loop.advance_sheared(e, *_loop.mode_flags(e.cells), prm, np.inf, 10**12, target, probe,
                                               prm.space.shear, e.stress, sim._walls_arg(e))
            else:
                status = _loop.advance(e, *_loop.mode_flags(e.cells), prm, np.inf, 10**12, target, probe, None,
                                       e.stress, sim._walls_arg(e))
            if status == OVERFLOW:
                sim._grow_lists()
            elif status == CELL_OVERFLOW:
                sim._grow_cells()
            else:
                assert status == _loop.MAX_COLLISIONS, status
        return time.perf_counter() - w, sim.collisions - c0

    t = time.perf_counter()
    go(1000)
    compile_s = time.perf_counter() - t
    probe[:] = 0
    fields = ("events", "expiries", "crossings", "stale")
    c = sim._engine.counters[0]
    before = {k: int(c[k]) for k in fields}
    slides = int(prm.space.shear.slide[0]) if sheared and sim.neighbours == "cells" else 0
    dt, nc = go(max(300_000, n))
    counts = {k: (int(c[k]) - before[k]) / nc for k in fields}
    if sheared and sim.neighbours == "cells":
        slides = int(prm.space.shear.slide[0]) - slides
    parts = _probe.PARTS
    total = probe[:parts].sum()
    kind = "" if shear is None else (f", eps 0.8, sheared at a = {shear:.4g}" if sheared else
                                     ", eps 0.8, periodic (stress sums on)")
    print(f"N = {n}, packing {packing}{', walls on z' if walls else ''}{kind}, {sim.neighbours} "
          f"(shell {sim.shell:.3f}): {nc / dt / 1e6:.3f} M "
          f"collisions/s instrumented, {total / nc:.0f} cycles per collision ({dt / nc * 1e9:.0f} ns); "
          f"compile or cache load {compile_s:.1f} s")
    line = "  per collision: " + ", ".join(f"{k} {v:.3f}" for k, v in counts.items())
    if sim.neighbours == "lists":
        line += f"; mean list length {sim._engine.lists.nbn.mean():.2f}"
    if sheared and sim.neighbours == "cells":
        line += f"; slides {slides} ({slides * n / nc:.3f} particle scans per collision)"
    print(line)
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
    p.add_argument("--shear", action="store_true",
                   help="the sheared gas of scripts/benchmarks/shear.py and the same gas periodic")
    p.add_argument("--shell", type=float, default=None, help="list shell in diameters (default: the engine's)")
    args = p.parse_args(argv)
    if any(n < 100 for n in args.sizes) or not 0.0 < args.packing <= 0.5:
        p.error("sizes must be >= 100 and 0 < --packing <= 0.5")
    if args.shear and args.walls:
        p.error("--shear and --walls exclude each other")
    for n in args.sizes:
        if args.shear:
            from granulargas import theory

            dens = float(theory.number_density(args.packing, 3))
            rate = theory.shear.grad_usf(0.8, 3, args.packing).a_star * float(
                theory.shear.reference_frequency(dens, 1.0, 3))
            for a in (0.0, rate):
                profile(int(n), args.packing, neighbours=args.neighbours, shear=a, shell=args.shell)
        else:
            profile(int(n), args.packing, args.walls, neighbours=args.neighbours, shell=args.shell)


if __name__ == "__main__":
    main()
