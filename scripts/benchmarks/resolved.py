"""Cost of collisions that take time: the resolved viscoelastic rule against the instantaneous one.

The same gas (3D, N particles at a packing fraction, pair prefactor k = 0.1,
compression prefactor q) is run with both rules, alternated for several rounds;
each run first does a warm-up (JIT compile or cache load, queue build) and then
times ``--collisions`` collisions by the process's CPU time. Prints the rates,
their medians, the ratio and the resolved run's share of three-body contacts.

    python scripts/benchmarks/resolved.py [--particles 10000] [--packing 0.1] [--compression 0.01] [--rounds 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from granulargas.contact import oblique_table, restitution_table
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--particles", type=int, default=10000)
    ap.add_argument("--packing", type=float, default=0.1)
    ap.add_argument("--compression", type=float, default=0.01, help="q (delta = q g^(4/5) for reference spheres)")
    ap.add_argument("--collisions", type=int, default=300000)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    w = time.perf_counter()
    table, oblique = restitution_table(1.0), oblique_table(0.39, 0.125)
    print(f"tables: {time.perf_counter() - w:.3g} s (cached after the first build)")
    rules = {"instantaneous": CollisionRule.viscoelastic(0.1, table),
             "resolved": CollisionRule.viscoelastic(0.1, table, duration="resolved",
                                                    compression=args.compression, oblique=oblique)}
    state = random_state(args.particles, args.packing, 3, seed=1)
    rates = {name: [] for name in rules}
    share = float("nan")
    for r in range(args.rounds):
        for name, rule in rules.items():
            sim = Simulation(state, rule)
            w = time.perf_counter()
            sim.run(np.inf, max_collisions=20000)
            warm = time.perf_counter() - w
            t, c0 = time.process_time(), sim.collisions
            sim.run(np.inf, max_collisions=args.collisions)
            rates[name].append((sim.collisions - c0) / (time.process_time() - t))
            if name == "resolved":
                share = sim.three_body_contacts / sim.collisions
            print(f"round {r + 1} {name:14s} {rates[name][-1] / 1e6:.3f} M collisions/s (CPU), "
                  f"warm-up {warm:.3g} s")
    a, b = statistics.median(rates["instantaneous"]), statistics.median(rates["resolved"])
    print(f"medians: instantaneous {a / 1e6:.3f}, resolved {b / 1e6:.3f} M collisions/s; resolved / instantaneous "
          f"{b / a:.3f} ({1e6 * (1 / b - 1 / a):.3g} us more per collision); three-body share {share:.3g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
