"""Long elastic run: >= 1e8 collisions without energy drift beyond round-off and without overlaps.

Elastic hard spheres (3D, packing 0.3 by default) through the public engine API.
Every ``--check`` collisions: relative kinetic-energy change ``|E/E0 - 1|``,
momentum drift, and overlaps of the synchronised configuration (periodic k-d
tree, any pair closer than ``(R_i + R_j)(1 - 1e-9)``). Reference for the energy:
each elastic collision rounds the two new velocities, a relative error of a few
``eps_mach = 2.2e-16`` of the pair's energy, so an unbiased accumulation grows
like ``sqrt(C) eps_mach`` and a biased one like ``C eps_mach / N`` at most;
the pass mark is ``|E/E0 - 1| < 100 sqrt(C) eps_mach``.

    python scripts/validation/long_run_stability.py [--quick] [--collisions 1e8] [--particles 10000]

Writes ``docs/figures/choice_long_run.png`` (energy drift against collisions).
Prints wall time and rate; a run with 1e8 collisions takes 1e8 / rate seconds
(rate ~1e5..1e6 collisions/s depending on the machine and its load).
"""

from __future__ import annotations

import argparse
import math
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy.spatial import cKDTree

from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state

EPS_MACH = np.finfo(float).eps


def overlaps(sim):
    """Number of overlapping pairs (periodic) and the smallest gap ratio |r_ij| / (R_i + R_j)."""
    pos = sim.positions
    box = sim.box
    r = sim.radii
    tree = cKDTree(np.mod(pos, box), boxsize=box)
    pairs = tree.query_pairs(2.0 * float(r.max()) * 1.0000001, output_type="ndarray")
    if len(pairs) == 0:
        return 0, math.inf
    d = pos[pairs[:, 0]] - pos[pairs[:, 1]]
    d -= box * np.round(d / box)
    ratio = np.linalg.norm(d, axis=1) / (r[pairs[:, 0]] + r[pairs[:, 1]])
    return int(np.sum(ratio < 1.0 - 1e-9)), float(ratio.min())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="1e6 collisions, 2000 particles")
    ap.add_argument("--collisions", type=float, default=1e8)
    ap.add_argument("--particles", type=int, default=10000)
    ap.add_argument("--packing", type=float, default=0.3)
    ap.add_argument("--checks", type=int, default=20, help="number of checkpoints")
    ap.add_argument("--out", default="docs/figures/choice_long_run.png")
    args = ap.parse_args(argv)
    total, n = int(args.collisions), args.particles
    if args.quick:
        total, n = 1_000_000, 2000
    st = random_state(n=n, packing=args.packing, dimension=3, temperature=1.0, seed=7)
    sim = Simulation(st, CollisionRule.elastic())
    t0 = time.perf_counter()
    sim.run(until=1e-3)  # JIT compile / cache load
    print(f"compile/load + build: {time.perf_counter() - t0:.1f} s")
    E0, P0 = sim.kinetic_energy, sim.momentum.copy()
    rows = []
    wall0 = time.perf_counter()
    targets = np.unique(np.geomspace(min(1000, total), total, args.checks).astype(np.int64))
    for target in targets:
        sim.run(until=math.inf, max_collisions=int(target) - sim.collisions)
        dE = sim.kinetic_energy / E0 - 1.0
        dP = float(np.max(np.abs(sim.momentum - P0))) / math.sqrt(2 * E0 * n / 3)
        bad, closest = overlaps(sim)
        wall = time.perf_counter() - wall0
        rows.append((sim.collisions, dE, dP, bad, closest, wall))
        print(f"{sim.collisions:12d} collisions  t = {sim.time:10.5g}  |E/E0 - 1| = {abs(dE):.2e}  "
              f"momentum drift {dP:.1e}  overlaps {bad}  min |r_ij|/(R_i+R_j) = {closest:.12f}  "
              f"wall {wall:7.1f} s ({sim.collisions / wall:.3g} coll/s)", flush=True)
    rows = np.array(rows)
    C, dE = rows[:, 0], np.abs(rows[:, 1])
    ok_E = bool(np.all(dE < 100 * np.sqrt(C) * EPS_MACH))
    ok_O = bool(np.all(rows[:, 3] == 0))
    print(f"{'PASS' if ok_E and ok_O else 'FAIL'}: {int(C[-1])} collisions, N = {n}, packing {args.packing}: "
          f"max |E/E0 - 1| = {dE.max():.2e} (sqrt(C) eps_mach = {math.sqrt(C[-1]) * EPS_MACH:.1e}), "
          f"overlaps {int(rows[:, 3].sum())}; wall {rows[-1, 5]:.0f} s")

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.loglog(C, np.maximum(dE, 1e-18), "o-", label="|E(C)/E0 - 1| (measured)")
    ax.loglog(C, np.sqrt(C) * EPS_MACH, "k--", label="sqrt(C) eps_mach (random round-off)")
    ax.loglog(C, C * EPS_MACH, "k:", label="C eps_mach (systematic, per collision)")
    ax.set_xlabel("collisions C")
    ax.set_ylabel("relative kinetic-energy change")
    ax.set_title(f"elastic EDMD, N = {n}, packing {args.packing}: overlaps {int(rows[:, 3].sum())}", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")
    return 0 if ok_E and ok_O else 1


if __name__ == "__main__":
    raise SystemExit(main())
