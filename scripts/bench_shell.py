"""Events per collision and speed against the neighbour-list shell.

For each packing fraction and shell width (in diameters) the same random state
(3D or 2D, elastic or viscoelastic) runs in this process: warm-up of 5 collisions per
particle, then ``--repeats`` timed runs of max(2e5, N) collisions; printed per
case: events, list expiries and stale events per collision, mean neighbour-list
length, and the median rate in collisions per second of CPU time (and of the
wall clock). The shells are interleaved within each round (``--rounds``), so a
loaded machine slows all of them alike.

Usage::

    python scripts/benchmarks/neighbours.py --n 1e4 --packings 0.05 0.1 --shells 1.2 2 3 4
    python scripts/benchmarks/neighbours.py --rule viscoelastic     # damping 0.1, cooling
    python scripts/benchmarks/neighbours.py --dimension 2 --packings 0.1 0.25 0.4 --shells 0 0.5 1 1.5
"""

import argparse
import statistics
import time

import numpy as np

from granulargas.engine import CollisionRule, Simulation
from granulargas.engine.simulation import default_shell
from granulargas.initial import random_state


def make_rule(name):
    if name == "elastic":
        return CollisionRule.elastic()
    from granulargas.contact import restitution_table
    from granulargas.contact.material import prefactor_from_damping

    return CollisionRule.viscoelastic(prefactor=prefactor_from_damping(0.1), table=restitution_table(5.0))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=float, default=1e4)
    p.add_argument("--packings", type=float, nargs="+", default=[0.05, 0.1])
    p.add_argument("--shells", type=float, nargs="+", default=[0.0, 2.0, 3.0, 4.0],
                   help="shell widths in diameters (0: the engine's default)")
    p.add_argument("--rule", choices=["elastic", "viscoelastic"], default="elastic")
    p.add_argument("--dimension", type=int, choices=[2, 3], default=3)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args(argv)
    n = int(args.n)
    rule = make_rule(args.rule)
    warm = random_state(64, 0.2, args.dimension, seed=0)
    Simulation(warm, rule).run(0.1)
    for eta in args.packings:
        st = random_state(n, eta, args.dimension, seed=args.seed)
        sims = {}
        for shell in args.shells:
            width = default_shell(eta, args.dimension) if shell == 0.0 else shell
            sim = Simulation(st, rule, shell=width)
            sim.run(np.inf, max_collisions=max(200_000, 5 * n // 2))
            sims[width] = (sim, [], [], [sim.events, sim.collisions, *_counts(sim)])
        per_run = max(200_000, n)
        for _ in range(args.rounds):
            for sim, cpu, wall, _start in sims.values():
                c0 = sim.collisions
                w0, p0 = time.perf_counter(), time.process_time()
                sim.run(np.inf, max_collisions=per_run)
                w1, p1 = time.perf_counter(), time.process_time()
                cpu.append((sim.collisions - c0) / (p1 - p0))
                wall.append((sim.collisions - c0) / (w1 - w0))
        for width, (sim, cpu, wall, start) in sims.items():
            ev0, c0, x0, s0 = start
            col = sim.collisions - c0
            x, s = _counts(sim)
            lists = sim._engine.lists.nbn
            print(f"{args.dimension}D packing {eta} {args.rule} N={n} shell {width:.2f}: "
                  f"events/collision {(sim.events - ev0) / col:.3f} (expiries {(x - x0) / col:.3f}, "
                  f"stale {(s - s0) / col:.3f}), list length {float(np.mean(lists)):.1f}, "
                  f"{statistics.median(cpu) / 1e6:.4f} M collisions/s CPU "
                  f"({statistics.median(wall) / 1e6:.4f} wall)", flush=True)


def _counts(sim):
    c = sim._engine.counters[0]
    return float(c["expiries"]), float(c["stale"])


if __name__ == "__main__":
    main()
