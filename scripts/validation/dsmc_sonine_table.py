"""Sonine coefficients a2, a3 of the homogeneous cooling state by DSMC, across eps, in 2D and 3D.

For each eps a DSMC gas of N smooth inelastic hard spheres (disks) relaxes into the HCS
(``--relax`` collisions per particle), then a2 and a3 are averaged over ``--snapshots``
snapshots one collision per particle apart; the error is the standard error of that mean
from 10 batch means (successive snapshots are correlated: the printed lag-1
autocorrelation of a2 says how much). Printed with them: the first Sonine approximation
of van Noije & Ernst (1998) (``theory.sonine_a2``) and, as an independent check of the
stationary state, the ratio Q of the exact moment equation (Q = 1 in the HCS; a
Maxwellian gives Q - 1 ~ -a2), evaluated with numpy on the last ``--q-snapshots``
snapshots (its error from their scatter).

    python scripts/validation/dsmc_sonine_table.py              # N = 1e5, 200 snapshots, ~10 min on one core
    python scripts/validation/dsmc_sonine_table.py --quick
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from granulargas import theory  # noqa: E402
from granulargas.dsmc import DSMC  # noqa: E402
from granulargas.engine import CollisionRule  # noqa: E402
from granulargas.state import State  # noqa: E402
from tests.dsmc.hcs_reference import collisional_moment_ratio  # noqa: E402


def batch_error(x, batches=10):
    """Standard error of the mean of a correlated series from ``batches`` batch means."""
    m = len(x) // batches
    if m < 1:
        return float(np.std(x, ddof=1) / math.sqrt(len(x)))
    means = np.asarray(x[: m * batches]).reshape(batches, m).mean(axis=1)
    return float(means.std(ddof=1) / math.sqrt(batches))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--eps", type=float, nargs="+", default=[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9])
    ap.add_argument("--dims", type=int, nargs="+", choices=(2, 3), default=[2, 3])
    ap.add_argument("--n", type=float, default=1e5)
    ap.add_argument("--relax", type=float, default=30.0)
    ap.add_argument("--snapshots", type=int, default=200)
    ap.add_argument("--q-snapshots", type=int, default=40)
    ap.add_argument("--q-pairs", type=float, default=1e6)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    n = int(2e4 if args.quick else args.n)
    snaps = 30 if args.quick else args.snapshots
    q_pairs = int(2e5 if args.quick else args.q_pairs)
    print(f"HCS by DSMC: N = {n}, {args.relax:g} collisions per particle to relax, {snaps} snapshots "
          f"1 collision per particle apart ({n * snaps:.3g} velocities per case)")
    print(f"{'d':>2} {'eps':>5} {'a2':>9} {'+-':>8} {'a3':>9} {'+-':>8} {'a2 vNE':>9} {'a2/vNE':>7} "
          f"{'lag-1':>6} {'Q':>8} {'+-':>7} {'Q Maxw.':>8} {'s':>5}")
    for dim in args.dims:
        for eps in args.eps:
            t0 = time.perf_counter()
            v = np.random.default_rng(args.seed).standard_normal((n, dim))
            sim = DSMC(State(None, v, 0.5, 1.0, None), CollisionRule.constant(eps), packing_fraction=0.01,
                       seed=args.seed)
            sim.run(np.inf, max_collisions=int(args.relax * n / 2))
            a2, a3, q = [], [], []
            for k in range(snaps):
                sim.run(np.inf, max_collisions=n // 2)
                a2.append(sim.sonine_a2)
                a3.append(sim.sonine_a3)
                if k >= snaps - args.q_snapshots:
                    q.append(collisional_moment_ratio(sim.velocities / math.sqrt(sim.temperature), eps,
                                                      pairs=q_pairs, seed=k))
            a2, a3 = np.array(a2), np.array(a3)
            q, q_err = np.array([x[0] for x in q]), np.array([x[1] for x in q])
            q_max = collisional_moment_ratio(np.random.default_rng(7).standard_normal((n, dim)), eps,
                                             pairs=q_pairs * len(q), seed=1)[0]
            vne = float(theory.sonine_a2(eps, dim))
            lag = float(np.corrcoef(a2[:-1], a2[1:])[0, 1])
            e2, e3 = batch_error(a2), batch_error(a3)
            # scatter of the snapshots' Q: Monte Carlo error of the pair sums plus the sampling
            # noise of each snapshot's N velocities
            eq = q.std(ddof=1) / math.sqrt(len(q))
            print(f"{dim:>2} {eps:>5.2f} {a2.mean():>+9.5f} {e2:>8.5f} {a3.mean():>+9.5f} {e3:>8.5f} "
                  f"{vne:>+9.5f} {a2.mean() / vne:>7.3f} {lag:>6.2f} {q.mean():>8.5f} {eq:>7.5f} "
                  f"{q_max:>8.5f} {time.perf_counter() - t0:>5.0f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
