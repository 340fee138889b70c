"""Cost of uniform shear flow: Lees-Edwards against periodic per collision, and the DSMC of USF.

Engine: the same gas (3D, constant eps = 0.8, packing ``--packing``) in a periodic box and
sheared at the rate whose Grad steady temperature is T0 = 1 (so the sheared gas stays at
T0 and both runs see the same collision frequency), both neighbour modes. Both simulations
live in this process; after a warm-up they run ``--per-run`` collisions each, alternated
(periodic, sheared, periodic, ...) for ``--repeats`` rounds, and the table gives the median
CPU time per collision of each and the median over rounds of the ratio of the sheared to the
periodic time within a round (alternation cancels most of a loaded machine's drift). The
stress sums are on in both (a config run keeps them for the pressure tensor).

DSMC: collisions per CPU second of the DSMC of USF (3D, eps = 0.8, packing 0.02, the steady
rate), median of ``--repeats`` timed runs after a warm-up, at ``--dsmc-sizes``.

    python scripts/benchmarks/shear.py                          # engine N = 1e4, 1e5; DSMC N = 1e6
    python scripts/benchmarks/shear.py --sizes 1e4 --dsmc-sizes 1e5 --repeats 3

``--record`` writes each figure into ``docs/performance/results.json`` (table of uniform shear
flow) and rewrites the performance page.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

from granulargas import theory
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, Simulation
from granulargas.engine.shear import Shear
from granulargas.initial import random_state
from granulargas.state import State

EPS = 0.8
LE3 = ("periodic", "lees-edwards", "periodic")


def steady_rate(packing, dim=3):
    n = float(theory.number_density(packing, dim))
    return theory.shear.grad_usf(EPS, dim, packing).a_star * float(theory.shear.reference_frequency(n, 1.0, dim))


def _cpu_per_collision(sim, count):
    c0, p0 = sim.collisions, time.process_time()
    sim.run(float("inf"), max_collisions=count)
    return (time.process_time() - p0) / max(sim.collisions - c0, 1)


def engine_case(n, mode, packing, per_run, repeats):
    a = steady_rate(packing)
    rule = CollisionRule.constant(EPS)
    periodic = Simulation(random_state(n, packing, 3, seed=1), rule, neighbours=mode, stress=True)
    sheared = Simulation(random_state(n, packing, 3, seed=1, boundary=LE3, shear=a), rule, neighbours=mode,
                         shear=Shear(a))
    for sim in (periodic, sheared):  # warm-up: compile, build, and let the sheared gas set up its flow;
        for _ in range(2):  # a second run compiles what a continued run adds (the sheared synchronisation)
            sim.run(float("inf"), max_collisions=n)
    tp, ts, ratio = [], [], []
    for _ in range(repeats):
        p = _cpu_per_collision(periodic, per_run)
        s = _cpu_per_collision(sheared, per_run)
        tp.append(p)
        ts.append(s)
        ratio.append(s / p)
    return statistics.median(tp), statistics.median(ts), statistics.median(ratio), min(ratio), max(ratio)


def dsmc_case(n, per_run, repeats):
    packing = 0.02
    a = steady_rate(packing)
    rng = np.random.default_rng(1)
    v = rng.standard_normal((n, 3))
    v -= v.mean(axis=0)
    sim = DSMC(State(None, v, np.full(n, 0.5), np.ones(n), None), CollisionRule.constant(EPS),
               packing_fraction=packing, seed=1, shear=Shear(a))
    sim.run(float("inf"), max_collisions=per_run)
    rates = []
    for _ in range(repeats):
        c0, p0 = sim.collisions, time.process_time()
        sim.run(float("inf"), max_collisions=per_run)
        rates.append((sim.collisions - c0) / (time.process_time() - p0))
    return statistics.median(rates), min(rates), max(rates)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=float, nargs="*", default=[1e4, 1e5])
    ap.add_argument("--modes", nargs="*", default=["lists", "cells"])
    ap.add_argument("--packing", type=float, default=0.1)
    ap.add_argument("--per-run", type=float, default=2.0, help="collisions per particle per timed run")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--dsmc-sizes", type=float, nargs="*", default=[1e6])
    ap.add_argument("--record", action="store_true", help="write the figures into docs/performance/results.json "
                    "and rewrite the performance page (table of uniform shear flow)")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import results

    load, commit, records = os.getloadavg()[0], results.this_commit(), []
    print(f"engine: 3D, eps = {EPS}, packing {args.packing}, CPU time per collision (median of {args.repeats} "
          "alternated rounds)")
    print(f"{'N':>8} {'mode':>6} {'periodic (us)':>14} {'sheared (us)':>13} {'ratio':>7} {'range':>13}")
    for n in (int(x) for x in args.sizes):
        for mode in args.modes:
            tp, ts, r, lo, hi = engine_case(n, mode, args.packing, int(args.per_run * n), args.repeats)
            print(f"{n:>8} {mode:>6} {1e6 * tp:>14.3f} {1e6 * ts:>13.3f} {r:>7.3f} {lo:>6.3f}-{hi:<6.3f}", flush=True)
            records.append(dict(table="uniform_shear", id=f"lees-edwards 3D {mode} packing {args.packing:g} N={n}",
                                method="edmd", dim=3, n=n, packing=args.packing, neighbours=mode, restitution=EPS,
                                ratio=round(r, 3), ratio_range=[round(lo, 3), round(hi, 3)], rounds=args.repeats))
    for n in (int(x) for x in args.dsmc_sizes):
        med, lo, hi = dsmc_case(n, int(args.per_run * n), args.repeats)
        print(f"DSMC of USF, 3D, N = {n}: {med / 1e6:.3g} M collisions per CPU second (range {lo / 1e6:.3g}-"
              f"{hi / 1e6:.3g})", flush=True)
        records.append(dict(table="uniform_shear", id=f"dsmc 3D packing 0.02 N={n}", method="dsmc", dim=3, n=n,
                            packing=0.02, restitution=EPS, rate_cpu=round(med / 1e6, 2),
                            rate_range=[round(lo / 1e6, 2), round(hi / 1e6, 2)], rounds=args.repeats))
    if args.record:
        words = argv if argv is not None else sys.argv[1:]
        results.record_and_render(records, " ".join(["python scripts/benchmarks/shear.py", *words]),
                                  load_average=max(load, os.getloadavg()[0]), commit=commit)


if __name__ == "__main__":
    main()
