"""Wall time of ``random_state`` (random non-overlapping placement + velocities).

Usage::

    python scripts/bench_initial_state.py                       # 1e6: 3D 0.1, 0.3, 0.45; 2D 0.7
    python scripts/bench_initial_state.py --cases 1e5:0.45:3    # N:packing:dimension
"""

import argparse
import sys
import time
from pathlib import Path

from granulargas.initial import random_state
from granulargas.errors import UserError

DEFAULT = ["1e6:0.1:3", "1e6:0.3:3", "1e6:0.45:3", "1e6:0.7:2"]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", nargs="+", default=DEFAULT, help="N:packing:dimension")
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args(argv)
    cases = []
    for case in args.cases:
        try:
            n, eta, d = case.split(":")
            cases.append((int(float(n)), float(eta), int(d)))
        except ValueError:
            p.error(f"--cases {case!r}: expected N:packing:dimension, e.g. 1e6:0.45:3")
    for n, eta, d in cases:
        random_state(500, eta, d, seed=0)  # compile (or load) the kernels first
        t0 = time.perf_counter()
        random_state(n, eta, d, seed=args.seed)
        print(f"N = {n:.0e}, packing {eta}, {d}D: {time.perf_counter() - t0:.1f} s", flush=True)


if __name__ == "__main__":
    try:
        main()
    except UserError as err:
        sys.exit(f"{Path(__file__).name}: {err}")
