"""What a mixture costs per collision against a polydisperse gas of the same particles.

Both gases are built from one initial state of N particles of two sizes and masses (half of
diameter 1 and mass 1, half of diameter ``--ratio`` and mass ``--ratio``^3): the polydisperse
gas has one collision law for every pair (``CollisionRule.constant(eps)``), the mixture the
same particles as two species with a law per pair of species. ``--law identical`` gives the
mixture every pair's eps the same value as the polydisperse gas, so both follow the same
trajectory to the last bit and the difference is what the law's lookup and the counts per pair
of species cost; ``--law mixture`` gives the pairs different eps (0.9, 0.8, 0.85), a real
mixture, whose dynamics then differ slightly.

Both simulations run in this process, after a warm-up of 2 collisions per particle (and the
compilation of both loops), in chunks of ``--chunk`` collisions alternated A B B A A B ...;
the figure is the median over rounds of the ratio of CPU time per collision (mixture /
polydisperse), with the range of the middle half of the rounds. The machine's load is printed
beside it: on a shared host run it more than once and read the spread.

Usage::

    python scripts/benchmarks/species.py --n 10976 --packing 0.1 --mode cells --rounds 30
    python scripts/benchmarks/species.py --n 10976 --packing 0.3 --mode lists --law mixture
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np

from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state


def build(n, packing, dim, ratio, seed, mode, law):
    half = n // 2
    of = np.repeat([0, 1], [half, n - half]).astype(np.int32)
    np.random.default_rng(seed).shuffle(of)
    radii = np.where(of == 0, 0.5, 0.5 * ratio)
    masses = np.where(of == 0, 1.0, ratio**3)
    st = random_state(n, packing, dim, seed=seed, radii=radii, masses=masses)
    table = np.full((2, 2), 0.9) if law == "identical" else np.array([[0.9, 0.8], [0.8, 0.85]])
    poly = Simulation(st, CollisionRule.constant(0.9), neighbours=mode)
    mix = Simulation(st.replace(species=of), CollisionRule.constant(table), neighbours=mode)
    return poly, mix


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=10976)
    ap.add_argument("--packing", type=float, default=0.1)
    ap.add_argument("--dim", type=int, default=3)
    ap.add_argument("--ratio", type=float, default=0.8, help="diameter of the second kind (first: 1)")
    ap.add_argument("--mode", choices=("lists", "cells"), default="cells")
    ap.add_argument("--law", choices=("identical", "mixture"), default="identical")
    ap.add_argument("--chunk", type=int, default=200_000, help="collisions per chunk")
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--record", action="store_true", help="write the ratio into docs/performance/results.json and "
                    "rewrite the performance page (table of scene costs)")
    args = ap.parse_args()
    load = os.getloadavg()[0]

    t0 = time.perf_counter()
    poly, mix = build(args.n, args.packing, args.dim, args.ratio, args.seed, args.mode, args.law)
    for sim in (poly, mix):  # compile (or load) both loops and warm up
        sim.run(math.inf, max_collisions=2 * args.n)
    setup = time.perf_counter() - t0
    cost = {"poly": [], "mix": []}
    sims = {"poly": poly, "mix": mix}
    for r in range(args.rounds):
        for name in (("poly", "mix") if r % 2 == 0 else ("mix", "poly")):
            sim = sims[name]
            c0, t = sim.collisions, time.process_time()
            sim.run(math.inf, max_collisions=args.chunk)
            cost[name].append((time.process_time() - t) / (sim.collisions - c0))
    ratio = np.array(cost["mix"]) / np.array(cost["poly"])
    q1, med, q3 = np.percentile(ratio, [25, 50, 75])
    if args.law == "identical":
        same = np.array_equal(poly.velocities, mix.velocities)
        note = f"trajectories bit-identical: {same}"
    else:
        note = "different eps per pair: dynamics differ"
    print(f"N = {args.n}, packing {args.packing}, {args.dim}D, {args.mode}, law {args.law}, "
          f"{args.rounds} rounds of {args.chunk} collisions; setup + compile {setup:.1f} s")
    print(f"CPU per collision: polydisperse {1e6 * np.median(cost['poly']):.3f} us, mixture "
          f"{1e6 * np.median(cost['mix']):.3f} us")
    print(f"mixture / polydisperse = {med:.4f} (middle half of rounds {q1:.4f} .. {q3:.4f}); {note}")
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")
    if args.record:
        import sys

        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import results

        scene = "mixture, one law for every pair" if args.law == "identical" else "mixture, a law per pair"
        rec = dict(table="scene_cost", id=f"{scene} {args.dim}D {args.mode} packing {args.packing:g} N={args.n}",
                   scene=scene, reference="polydisperse gas of the same particles", dim=args.dim, n=args.n,
                   packing=args.packing, neighbours=args.mode, ratio=round(float(med), 3),
                   quartiles=[round(float(q1), 3), round(float(q3), 3)], rounds=args.rounds)
        results.record_and_render([rec], "python scripts/benchmarks/species.py " + " ".join(sys.argv[1:]),
                                  load_average=max(load, os.getloadavg()[0]))


if __name__ == "__main__":
    main()
