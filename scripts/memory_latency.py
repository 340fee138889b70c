"""Memory latency of this machine: a dependent-load chase over working sets of growing size.

Each step loads the index of the next cache line from a random permutation, so
every load waits for the previous one: the time per step is the latency of the
level of the memory hierarchy the working set fits in. The engine's design
counts cache lines because beyond the L2 cache this latency is ~100 ns.

Usage::

    python scripts/memory_latency.py                 # 0.75 .. 300 MB
    python scripts/memory_latency.py --sizes 4 64    # MB
"""

import argparse
import time

import numpy as np
from numba import njit


@njit(cache=True)
def _chase(nxt, steps):
    j = 0
    for _ in range(steps):
        j = nxt[j]
    return j


def latency_ns(megabytes, steps=2_000_000, seed=0):
    """Nanoseconds per dependent load over a random cyclic walk of ``megabytes`` (one load per line)."""
    lines = max(2, int(megabytes * 2**20 / 64))
    order = np.random.default_rng(seed).permutation(lines)
    nxt = np.zeros(lines * 8, dtype=np.int64)  # one int64 used per 64-byte line
    nxt[order[:-1] * 8] = order[1:] * 8
    nxt[order[-1] * 8] = order[0] * 8
    _chase(nxt, 10)
    t0 = time.perf_counter()
    _chase(nxt, steps)
    return (time.perf_counter() - t0) / steps * 1e9


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=float, nargs="+", default=[0.75, 4, 8, 16, 32, 64, 300],
                   help="working-set sizes in MB")
    args = p.parse_args(argv)
    for mb in args.sizes:
        print(f"{mb:7.2f} MB: {latency_ns(mb):6.1f} ns per dependent load", flush=True)


if __name__ == "__main__":
    main()
