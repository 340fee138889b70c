"""Memory latency of this machine: a dependent-load chase over working sets of growing size.

Each step loads the index of the next cache line from a random permutation, so
every load waits for the previous one: the time per step is the latency of the
level of the memory hierarchy the working set fits in. The engine's design
counts cache lines because beyond the L2 cache this latency is ~100 ns.

With ``--chains K ...`` it also walks K independent chains at once (each
step advances every chain): the time per load then shows how many misses the
core overlaps, i.e. what prefetching and independent loads can buy.

Usage::

    python scripts/profiling/memory_latency.py                 # 0.75 .. 300 MB
    python scripts/profiling/memory_latency.py --sizes 4 64    # MB
    python scripts/profiling/memory_latency.py --sizes 64 512 --chains 1 4 16 32
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


@njit(cache=True)
def _chase_many(nxt, cur, steps):
    for _ in range(steps):
        for c in range(cur.shape[0]):
            cur[c] = nxt[cur[c]]
    return cur[0]


def _cycle(megabytes, seed):
    """One random cyclic walk over the lines of ``megabytes`` (one int64 used per 64-byte line)."""
    lines = max(2, int(megabytes * 2**20 / 64))
    order = np.random.default_rng(seed).permutation(lines)
    nxt = np.zeros(lines * 8, dtype=np.int64)
    nxt[order[:-1] * 8] = order[1:] * 8
    nxt[order[-1] * 8] = order[0] * 8
    return nxt, order * 8


def throughput_ns(megabytes, chains, loads=2_000_000, seed=0):
    """Nanoseconds per load with ``chains`` independent walks in flight (evenly spaced on the cycle)."""
    nxt, order = _cycle(megabytes, seed)
    cur = order[np.linspace(0, len(order) - 1, chains, endpoint=False).astype(np.int64)].copy()
    steps = max(1000, loads // chains)
    _chase_many(nxt, cur, 10)
    t0 = time.perf_counter()
    _chase_many(nxt, cur, steps)
    return (time.perf_counter() - t0) / (steps * chains) * 1e9


def latency_ns(megabytes, steps=2_000_000, seed=0):
    """Nanoseconds per dependent load over a random cyclic walk of ``megabytes`` (one load per line)."""
    nxt, _ = _cycle(megabytes, seed)
    _chase(nxt, 10)
    t0 = time.perf_counter()
    _chase(nxt, steps)
    return (time.perf_counter() - t0) / steps * 1e9


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=float, nargs="+", default=[0.75, 4, 8, 16, 32, 64, 300],
                   help="working-set sizes in MB")
    p.add_argument("--chains", type=int, nargs="+", default=[],
                   help="also time this many independent chains at once (ns per load)")
    args = p.parse_args(argv)
    if any(mb <= 0 for mb in args.sizes) or any(k < 1 for k in args.chains):
        p.error("--sizes must be > 0 MB and --chains >= 1")
    for mb in args.sizes:
        print(f"{mb:7.2f} MB: {latency_ns(mb):6.1f} ns per dependent load", flush=True)
        for k in args.chains:
            print(f"{'':7s}    {k:3d} chains: {throughput_ns(mb, k):6.1f} ns per load", flush=True)


if __name__ == "__main__":
    main()
