"""What the Fletcher-32 checksums of the H5MD files cost: writing and reading frames with and without.

Every dataset :class:`granulargas.io.h5md.H5MDWriter` creates carries HDF5's Fletcher-32 filter
(``granulargas.io.h5md.CHECKSUMS``); HDF5 computes a chunk's checksum when it writes it and checks
it when it reads it. This script writes files of N particles (3D, F frames of positions,
velocities and images, and the observables samples a run writes between them), alternating the
filter on and off (A B B A ..., so that each pair shares the machine's state), reads every frame
back (:func:`granulargas.io.h5md.iter_snapshots`), and prints the medians over the rounds of the
CPU time per frame written and read, and the ratio with / without.

Usage::

    python scripts/benchmarks/checksums.py                       # N = 1e4 and 1e5, 20 frames, 9 rounds
    python scripts/benchmarks/checksums.py --particles 1000000 --frames 5 --rounds 5
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from granulargas.io import h5md

SAMPLES_PER_FRAME = 10


def write(path: Path, n: int, frames: int, rng) -> float:
    """CPU time of writing ``frames`` frames (and 10 observables samples per frame) of n particles."""
    d = 3
    box = np.full(d, (n / 0.1 * np.pi / 6) ** (1 / 3))
    pos = rng.uniform(0, box[0], (n, d))
    vel = rng.normal(size=(n, d))
    img = rng.integers(-3, 3, (n, d))
    t0 = time.process_time()
    with h5md.H5MDWriter(path, box, np.full(n, 0.5), np.ones(n), overwrite=True,
                         parameters={"collision": {"model": "elastic"}}) as w:
        step = 0
        for k in range(frames):
            for _ in range(SAMPLES_PER_FRAME):
                step += 1
                w.write_observables(step, float(step), {"temperature": 1.0, "kinetic_energy": 1.5 * n,
                                                        "collisions": step, "events": step,
                                                        "dissipated_energy": 0.0, "momentum": np.zeros(d),
                                                        "pressure": 1.0, "sonine_a2": 0.0, "sonine_a3": 0.0},
                                    flush=False)
            w.write_snapshot(step, float(step), pos, vel + k, img)
    return time.process_time() - t0


def read(path: Path) -> float:
    """CPU time of reading every frame back."""
    t0 = time.process_time()
    for snap in h5md.iter_snapshots(path):
        snap.velocities.sum()
    return time.process_time() - t0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--particles", type=int, nargs="+", default=[10_000, 100_000])
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--dir", default=None, help="where to write the files (default: a temporary directory)")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(1)
    with tempfile.TemporaryDirectory(dir=args.dir) as tmp:
        path = Path(tmp) / "bench.h5"
        print(f"{'N':>9} {'frames':>6} {'write ms/frame (off, on)':>26} {'ratio':>6} "
              f"{'read ms/frame (off, on)':>25} {'ratio':>6} {'MB':>7}")
        for n in args.particles:
            times = {(op, on): [] for op in ("write", "read") for on in (False, True)}
            for r in range(args.rounds):
                for on in ((False, True) if r % 2 == 0 else (True, False)):
                    h5md.CHECKSUMS = on
                    times["write", on].append(write(path, n, args.frames, rng) / args.frames)
                    times["read", on].append(read(path) / args.frames)
            size = path.stat().st_size / 1e6
            med = {k: statistics.median(v) * 1e3 for k, v in times.items()}
            print(f"{n:9d} {args.frames:6d} {med['write', False]:12.3g} {med['write', True]:12.3g} "
                  f"{med['write', True] / med['write', False]:7.3f} {med['read', False]:11.3g} "
                  f"{med['read', True]:12.3g} {med['read', True] / med['read', False]:7.3f} {size:7.1f}")
        h5md.CHECKSUMS = True


if __name__ == "__main__":
    main()
