"""What gravity and a vibrating wall cost per collision: paired in-process comparisons.

Two simulations from the same initial state run in one process, in alternating chunks of
``--chunk`` pair collisions (A B B A A B ...), so that each pair of chunks shares the
machine's state; the figure is the median over rounds of the ratio of CPU time per
collision (pair and wall collisions) of B over A, with the first two chunks of each left
out as warm-up (compiling is not timed). Scenes:

* ``gravity``: an elastic gas in a periodic box, A without gravity, B falling freely under
  g along z. Uniform gravity changes no pair collision (the same sequence, shifted by
  g t^2 / 2), so B does the work of A plus what the flight costs: parabolic streaming, the
  partners streamed on their flight, the list-expiry bound (lists) or the quadratic face
  times (cells). g is chosen so that the fall adds ``--fall`` thermal speeds over the
  timed chunks.
* ``wall``: an elastic gas between walls on z (thickness ``--slab`` diameters, so that wall
  collisions are a good share), A with hard walls at rest, B with the lower wall vibrating
  as a sine (A omega = 0.3 thermal speeds): the ratio per event of any kind, and what B
  spends more per wall collision: (t_B - t_A) / (wall collisions of B) over the time of A
  per collision of any kind. This charges to the wall collisions everything the vibrating
  wall costs, also the contact search of the two partners after every pair collision.
* ``wallcost``: the cost of one wall collision, vibrating against hard. The same gas in both
  arms, dilute enough (``--knudsen-packing``) in a thin slab (``--knudsen-slab``) that pair
  collisions are a few per cent of the collisions and each wall collision's work is the
  whole run's: the contact prediction of the particle leaving the wall, the collision at the
  wall's velocity, the cells or lists it moves through on the way to the other wall. The
  engine counts pair and wall collisions apart (``collisions``, ``wall_collisions``); each
  chunk runs for the time of about ``--chunk`` wall collisions (re-estimated each chunk: the
  vibrated slab heats up) and the figure is the median over rounds of the CPU time per wall
  collision of the vibrating slab over that of the hard one (in alternating order). What
  the vibrating wall adds to the pair collisions of a dense gas is the ``wall`` scene's.
  With cells the wall collisions and the cell crossings between them are the run's work;
  with lists a dilute gas spends most of its time on list expiries (several per wall
  collision, the same for both kinds), which hide the wall's cost: read the cells figure.

  A hard-wall collision of a dense gas cannot be timed apart by subtraction: fitting the
  time per event against the wall share over slabs of several thicknesses, or subtracting
  the pair collisions at the cost of a periodic box of the same gas, gives negative costs
  for it, since a pair collision in a thin slab (fewer neighbours near a wall) costs less
  than in the bulk by more than a hard-wall collision costs. Hence the Knudsen slab.

Usage::

    python scripts/benchmarks/gravity.py --n 1e4 1e5 --modes lists cells
    python scripts/benchmarks/gravity.py --scenes wall wallcost --n 1e4 --rounds 10

``--record`` writes each figure into ``docs/performance/results.json`` (table of scene costs)
and rewrites the performance page.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

from granulargas.engine import CollisionRule, Simulation, Wall, Walls
from granulargas.initial import random_state


def _pair(scene, n, mode, packing, fall, slab, seed):
    rule = CollisionRule.elastic()
    if scene == "gravity":
        st = random_state(n, packing, 3, seed=seed)
        a = Simulation(st, rule, neighbours=mode, remove_drift=False)
        return a, None, st
    d = 3
    side = math.sqrt(n * (math.pi / 6.0) / (packing * slab))
    st = random_state(n, packing, d, seed=seed, aspect=[side, side, slab],
                      boundary=("periodic", "periodic", "wall"), margins=[[0, 0], [0, 0], [0.1, 0]])
    a = Simulation(st, rule, neighbours=mode)
    b = Simulation(st, rule, neighbours=mode, walls=Walls(z_low=Wall.vibrating(0.05, 0.3 / (2 * math.pi * 0.05))))
    return a, b, st


def measure(scene, n, mode, packing, rounds, chunk, fall, slab, seed):
    a, b, st = _pair(scene, n, mode, packing, fall, slab, seed)
    if scene == "gravity":
        # the time the timed chunks take, from a warm-up of A: g adds ``fall`` thermal speeds over it
        a.run(math.inf, max_collisions=chunk)
        span = a.time * (rounds + 1)
        g = fall * math.sqrt(a.temperature) / span
        b = Simulation(st, CollisionRule.elastic(), neighbours=mode, remove_drift=False, gravity=[0.0, 0.0, -g])
        b.run(math.inf, max_collisions=chunk)
    else:
        a.run(math.inf, max_collisions=chunk)
        b.run(math.inf, max_collisions=chunk)
    sims = (a, b)
    per = [[], []]
    walls = [[], []]
    for r in range(rounds):
        for k in ((0, 1) if r % 2 == 0 else (1, 0)):
            s = sims[k]
            c0, w0 = s.collisions, s.wall_collisions
            t0 = time.process_time()
            s.run(math.inf, max_collisions=chunk)
            dt = time.process_time() - t0
            per[k].append(dt / (s.collisions - c0 + s.wall_collisions - w0))
            walls[k].append((s.wall_collisions - w0, dt, s.collisions - c0 + s.wall_collisions - w0))
    pa, pb = np.array(per[0]), np.array(per[1])
    ratio = float(np.median(pb / pa))
    extra = math.nan
    if scene == "wall":
        # what one wall collision of B costs more than a collision of A, in collisions of A
        ext = [(wb[1] - pa_i * wb[2]) / max(wb[0], 1) / pa_i for wb, pa_i in zip(walls[1], pa)]
        extra = float(np.median(ext))
    share = float(np.mean([w[0] / w[2] for w in walls[1]]))
    return ratio, 1.0 / float(np.median(pa)), 1.0 / float(np.median(pb)), share, extra


def _slab(n, mode, packing, slab, seed, wall, amplitude=0.05):
    side = math.sqrt(n * (math.pi / 6.0) / (packing * slab))
    st = random_state(n, packing, 3, seed=seed, aspect=[side, side, slab],
                      boundary=("periodic", "periodic", "wall"), margins=[[0, 0], [0, 0], [0.1, 0]])
    walls = Walls(z_low=Wall.vibrating(amplitude, 0.3 / (2 * math.pi * amplitude))) if wall == "vibrating" else None
    return Simulation(st, CollisionRule.elastic(), neighbours=mode, walls=walls)


def measure_wall_collisions(n, mode, rounds, chunk, seed, packing, slab, amplitude=0.05):
    """CPU time per wall collision of a vibrating floor over that of a hard floor, in a Knudsen
    slab (see the module docstring): (median ratio, its IQR, time per wall collision of the hard
    and the vibrating slab (s), their shares of pair collisions among the collisions)."""
    kinds = ("hard", "vibrating")
    sims = {k: _slab(n, mode, packing, slab, seed, k, amplitude) for k in kinds}
    span = {}
    for k, sim in sims.items():  # warm-up (compiling, not timed) and the duration of ``chunk`` wall collisions
        sim.run(1.0)
        span[k] = sim.time * chunk / max(sim.wall_collisions, 1)
    per, pairs = {k: [] for k in kinds}, {k: [] for k in kinds}
    for r in range(rounds):
        for k in (kinds if r % 2 == 0 else kinds[::-1]):
            sim = sims[k]
            c0, w0 = sim.collisions, sim.wall_collisions
            t0 = time.process_time()
            sim.run(sim.time + span[k])
            dt = time.process_time() - t0
            p, w = sim.collisions - c0, sim.wall_collisions - w0
            per[k].append(dt / max(w, 1))
            pairs[k].append(p / max(p + w, 1))
            span[k] *= chunk / max(w, 1)  # the vibrated slab heats up: keep ``chunk`` wall collisions
    ratio = np.array(per["vibrating"]) / np.array(per["hard"])
    return (float(np.median(ratio)), tuple(np.percentile(ratio, [25, 75])), float(np.median(per["hard"])),
            float(np.median(per["vibrating"])), float(np.mean(pairs["hard"])), float(np.mean(pairs["vibrating"])))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", default=["gravity", "wall", "wallcost"], choices=("gravity", "wall", "wallcost"))
    ap.add_argument("--n", type=lambda s: int(float(s)), nargs="+", default=[10000, 100000])
    ap.add_argument("--modes", nargs="+", default=["lists", "cells"], choices=("lists", "cells"))
    ap.add_argument("--packing", type=float, default=None, help="default: 0.3 (lists), 0.05 (cells)")
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--chunk", type=int, default=20000)
    ap.add_argument("--fall", type=float, default=0.3, help="thermal speeds gravity adds over the timed chunks")
    ap.add_argument("--slab", type=float, default=6.0, help="the wall scene's thickness in diameters")
    ap.add_argument("--knudsen-packing", type=float, default=0.002, help="the wallcost scene's packing fraction")
    ap.add_argument("--knudsen-slab", type=float, default=5.0, help="the wallcost scene's thickness in diameters")
    ap.add_argument("--wall-amplitude", type=float, default=0.05,
                    help="the wallcost scene's amplitude A (A omega = 0.3 whatever A): a tiny A leaves the contact "
                         "search a step or two, the rest of what a vibrating wall costs stays")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--record", action="store_true", help="write the ratios into docs/performance/results.json and "
                    "rewrite the performance page (table of scene costs)")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import results

    load, commit, records = os.getloadavg()[0], results.this_commit(), []

    def add(scene, reference, n, mode, packing, ratio, **extra):
        records.append(dict(table="scene_cost", id=f"{scene} 3D {mode} packing {packing:g} N={n}", scene=scene,
                            reference=reference, dim=3, n=n, packing=packing, neighbours=mode,
                            ratio=round(ratio, 3), rounds=args.rounds, **extra))
    print(f"# load {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}; {args.rounds} rounds "
          f"of {args.chunk} pair collisions; ratio = CPU time per collision of B / of A (median)")
    print(f"{'scene':>8} {'mode':>6} {'N':>7} {'packing':>8} {'A M/s':>8} {'B M/s':>8} {'B/A':>7} {'wall share':>10} "
          f"{'+ per wall coll.':>16}")
    for scene in args.scenes:
        for mode in args.modes:
            for n in args.n:
                packing = args.packing or (0.3 if mode == "lists" else 0.05)
                if scene == "wallcost":
                    r, iqr, th, tv, ph, pv = measure_wall_collisions(n, mode, args.rounds, args.chunk, args.seed,
                                                                     args.knudsen_packing, args.knudsen_slab,
                                                                     args.wall_amplitude)
                    print(f"wallcost {mode:>6} {n:>7d} {args.knudsen_packing:>8.3g}  Knudsen slab {args.knudsen_slab:g} "
                          f"diameters, A = {args.wall_amplitude:g}, pair collisions {100 * ph:.1f} % / {100 * pv:.1f} % of the collisions; CPU "
                          f"time per wall collision hard {th * 1e6:.3f} us, vibrating {tv * 1e6:.3f} us: vibrating / "
                          f"hard = {r:.3f} (IQR {iqr[0]:.3f}-{iqr[1]:.3f})", flush=True)
                    amplitude = "," if args.wall_amplitude == 0.05 else f" A = {args.wall_amplitude:g},"
                    add(f"vibrating floor{amplitude} per wall collision (Knudsen slab {args.knudsen_slab:g} diameters)",
                        "hard floor", n, mode, args.knudsen_packing, r,
                        quartiles=[round(float(iqr[0]), 3), round(float(iqr[1]), 3)])
                    continue
                ratio, ra, rb, share, extra = measure(scene, n, mode, packing, args.rounds, args.chunk, args.fall,
                                                      args.slab, args.seed)
                print(f"{scene:>8} {mode:>6} {n:>7d} {packing:>8.3g} {ra / 1e6:>8.4f} {rb / 1e6:>8.4f} {ratio:>7.3f} "
                      f"{share:>10.3f} {extra:>16.3g}", flush=True)
                if scene == "gravity":
                    add("gravity (elastic gas falling freely)", "the same gas without gravity", n, mode, packing, ratio)
                else:
                    add(f"vibrating floor, per collision (slab {args.slab:g} diameters)", "hard floor", n, mode,
                        packing, ratio)
    print(f"# load {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")
    if args.record:
        words = argv if argv is not None else sys.argv[1:]
        results.record_and_render(records, " ".join(["python scripts/benchmarks/gravity.py", *words]),
                                  load_average=max(load, os.getloadavg()[0]), commit=commit)
    return 0


if __name__ == "__main__":
    sys.exit(main())
