"""A very large system end to end: initial state, build, collisions, memory.

Default: 10^7 spheres at packing 0.3 (about 5 GB and 10 minutes on one core).
Prints the initial-state time, the engine state in bytes per particle, the peak
RSS of the process and the collision rate of a second, timed batch.

Usage::

    python scripts/benchmarks/run.py
    python scripts/benchmarks/run.py --particles 1e6 --collisions 2e6
"""

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.errors import UserError


def _peak_gb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--particles", type=float, default=1e7)
    p.add_argument("--packing", type=float, default=0.3)
    p.add_argument("--collisions", type=float, default=5e6, help="per batch (two batches)")
    args = p.parse_args(argv)
    n, batch = int(args.particles), int(args.collisions)
    t0 = time.perf_counter()
    st = random_state(n, args.packing, 3, seed=1)
    print(f"initial state {time.perf_counter() - t0:.0f} s, peak RSS {_peak_gb():.2f} GB", flush=True)
    sim = Simulation(st, CollisionRule.elastic())
    del st
    t0 = time.perf_counter()
    sim.run(np.inf, max_collisions=batch)
    state = sum(a.nbytes for a in sim._s.values() if hasattr(a, "nbytes"))
    print(f"build + {batch:.0e} collisions {time.perf_counter() - t0:.0f} s; engine state "
          f"{state / n:.0f} B/particle; peak RSS {_peak_gb():.2f} GB", flush=True)
    t0 = time.perf_counter()
    sim.run(np.inf, max_collisions=batch)
    print(f"next {batch:.0e} collisions: {batch / (time.perf_counter() - t0) / 1e6:.3f} M collisions/s",
          flush=True)


if __name__ == "__main__":
    try:
        main()
    except UserError as err:
        sys.exit(f"{Path(__file__).name}: {err}")
