"""Cost of a rough collision against a smooth one, and the engine's memory per particle.

For each number of particles, packing fraction and neighbour mode, three simulations of
the same initial state run in one process: smooth elastic spheres (the reference), rough
spheres with eps = 1 and a constant beta_t = +1 (perfectly rough: no energy is lost, so the
gas keeps its temperature and the event mix), and rough spheres with Walton's model
(eps = 1, beta_0 = +1, mu = 0.5: only sliding contacts lose energy). After a warm-up (compile,
2 collisions per particle) chunks of ``--chunk`` collisions per particle alternate between
them, in an order that rotates every round, so that each round's chunks share the machine's
state; the figure per case is the median over rounds of the ratio of CPU time per collision
(rough / smooth). The engine's state is measured in bytes per particle
(``engine._state.nbytes``, every array of the compiled state).

    taskset -c 1 python scripts/benchmarks/rough.py [--sizes 1e4 1e5] [--packings 0.1 0.3]
        [--modes lists cells] [--rounds 15] [--chunk 0.5] [--record]

Prints one line per case: the medians (and the 25-75 % range) of the ratios, the smooth
collision rate, and the engine bytes per particle of the smooth and the rough state.
``--record`` writes each case into ``docs/performance/results.json`` (table ``rough``) and
rewrites the performance page.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

from granulargas.engine import CollisionRule, Simulation, TangentialRule
from granulargas.engine import _state
from granulargas.initial import random_state

VARIANTS = {
    "smooth": None,
    "rough": TangentialRule.constant(1.0),
    "coulomb": TangentialRule.coulomb(1.0, 0.5),
}


def case(n, packing, mode, rounds, chunk, seed=1):
    st = random_state(n, packing, 3, seed=seed)
    rng = np.random.default_rng(seed)
    st = st.replace(angular_velocities=rng.normal(size=(n, 3)) / math.sqrt(0.1), inertia=np.full(n, 0.4))
    sims = {name: Simulation(st, CollisionRule.elastic(), tangential=tg, neighbours=mode)
            for name, tg in VARIANTS.items()}
    for sim in sims.values():  # compile, build, settle
        sim.run(math.inf, max_collisions=2 * n)
    names = list(sims)
    per = {name: [] for name in names}
    step = max(1, int(chunk * n))
    for r in range(rounds):
        order = names[r % len(names):] + names[:r % len(names)]
        for name in order:
            sim = sims[name]
            c0, t0 = sim.collisions, time.process_time()
            sim.run(math.inf, max_collisions=step)
            per[name].append((time.process_time() - t0) / (sim.collisions - c0))
    smooth = np.array(per["smooth"])
    out = {"rate_smooth": 1.0 / float(np.median(smooth))}
    for name in names[1:]:
        ratio = np.array(per[name]) / smooth
        out[name] = (float(np.median(ratio)), float(np.percentile(ratio, 25)), float(np.percentile(ratio, 75)))
    out["bytes_smooth"] = _state.nbytes(sims["smooth"]._engine) / n
    out["bytes_rough"] = _state.nbytes(sims["rough"]._engine) / n
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", nargs="+", type=float, default=[1e4, 1e5])
    p.add_argument("--packings", nargs="+", type=float, default=[0.1, 0.3])
    p.add_argument("--modes", nargs="+", default=["lists", "cells"])
    p.add_argument("--rounds", type=int, default=15)
    p.add_argument("--chunk", type=float, default=0.5, help="collisions per particle per chunk")
    p.add_argument("--record", action="store_true", help="write the ratios into docs/performance/results.json and "
                   "rewrite the performance page (table of rough grains)")
    args = p.parse_args(argv)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import results

    load, commit, records = os.getloadavg()[0], results.this_commit(), []
    print(f"load {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")
    print(f"{'N':>8} {'packing':>7} {'mode':>6}  {'rough/smooth':>22}  {'coulomb/smooth':>22}  "
          f"{'smooth coll/s':>13}  {'B/particle smooth, rough':>25}")
    for n in args.sizes:
        for packing in args.packings:
            for mode in args.modes:
                r = case(int(n), packing, mode, args.rounds, args.chunk)
                fmt = lambda x: f"{x[0]:.3f} ({x[1]:.3f}-{x[2]:.3f})"  # noqa: E731
                print(f"{int(n):8d} {packing:7.3g} {mode:>6}  {fmt(r['rough']):>22}  {fmt(r['coulomb']):>22}  "
                      f"{r['rate_smooth']:13.3g}  {r['bytes_smooth']:11.1f}, {r['bytes_rough']:11.1f}", flush=True)
                records.append(dict(table="rough", id=f"3D {mode} packing {packing:g} N={int(n)}", dim=3, n=int(n),
                                    packing=packing, neighbours=mode, ratio=round(r["rough"][0], 3),
                                    ratio_coulomb=round(r["coulomb"][0], 3),
                                    bytes_per_particle=round(r["bytes_rough"]),
                                    bytes_per_particle_smooth=round(r["bytes_smooth"]), rounds=args.rounds))
    print(f"load {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")
    if args.record:
        words = argv if argv is not None else sys.argv[1:]
        results.record_and_render(records, " ".join(["python scripts/benchmarks/rough.py", *words]),
                                  load_average=max(load, os.getloadavg()[0]), commit=commit)


if __name__ == "__main__":
    main()
