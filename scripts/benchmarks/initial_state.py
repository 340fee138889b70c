"""Wall and CPU time of ``random_state`` (random non-overlapping placement + velocities).

Usage::

    python scripts/benchmarks/initial_state.py                       # 1e6: 3D 0.1, 0.3, 0.45, 0.5; 2D 0.7
    python scripts/benchmarks/initial_state.py --cases 1e6:0.5:3 1e7:0.3:3 --repeat 3

Each case: the kernels are compiled (or loaded from the cache) on a 500-particle
state first (on the code path of N particles: the sorted, parallel kernels when
N >= ``SORTED_MIN_PARTICLES``) and that time is printed separately; then ``--repeat`` placements of
the N particles (seeds ``--seed``, ``--seed`` + 1, ...), each timed by the wall
clock and by the process's CPU time; the medians are printed.
"""

import argparse
import statistics
import sys
import time
from pathlib import Path

from granulargas.errors import UserError
from granulargas.initial import lattice_gas, random_state

DEFAULT = ["1e6:0.1:3", "1e6:0.3:3", "1e6:0.45:3", "1e6:0.5:3", "1e6:0.7:2"]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", nargs="+", default=DEFAULT, help="N:packing:dimension")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--repeat", type=int, default=1, help="placements per case (median printed)")
    args = p.parse_args(argv)
    cases = []
    for case in args.cases:
        try:
            n, eta, d = case.split(":")
            cases.append((int(float(n)), float(eta), int(d)))
        except ValueError:
            p.error(f"--cases {case!r}: expected N:packing:dimension, e.g. 1e6:0.45:3")
    for n, eta, d in cases:
        t0 = time.perf_counter()
        threshold = getattr(lattice_gas, "SORTED_MIN_PARTICLES", 0)
        if n >= threshold:  # the large systems' kernels on 500 particles
            lattice_gas.SORTED_MIN_PARTICLES = 0
        try:
            random_state(500, eta, d, seed=0)  # compile (or load) the kernels first
        finally:
            lattice_gas.SORTED_MIN_PARTICLES = threshold
        jit = time.perf_counter() - t0
        wall, cpu = [], []
        for k in range(args.repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            random_state(n, eta, d, seed=args.seed + k)
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        print(f"N = {n:.0e}, packing {eta}, {d}D: {statistics.median(wall):.1f} s wall, "
              f"{statistics.median(cpu):.1f} s CPU (median of {args.repeat}; runs "
              f"{', '.join(f'{w:.1f}' for w in wall)} s); compile/load + 500 particles {jit:.1f} s",
              flush=True)


if __name__ == "__main__":
    try:
        main()
    except UserError as err:
        sys.exit(f"{Path(__file__).name}: {err}")
