"""Inelastic collapse of a dense 2D gas with constant eps, the TC model, and the viscoelastic rule.

Scene: disks, packing fraction 0.4, eps = 0.5 (constant), one seed.

1. Constant eps without a guard: the run proceeds until a group of disks
   collides ever faster (McNamara & Young 1994); the engine's detector raises
   :class:`granulargas.errors.InelasticCollapseError`. A deterministic rerun
   to ``t_collapse - delta`` shows the number of collisions still to come
   before ``t_collapse`` diverging as delta -> 0 (logarithmically: a geometric
   sequence of collision times), where a normal gas would have ~N omega delta / 2.
2. The TC model (Luding & McNamara 1998; ``CollisionRule.constant(eps,
   tc_time=...)``): a collision within ``tc_time`` of a particle's previous one
   is elastic. Runs for several tc_time go through; the accuracy cost is their
   T(t) against the unguarded run (same initial state) before the collapse.
3. The viscoelastic rule with the damping whose gas cools at the same initial
   rate (eps -> 1 at low impact speed): no guard needed.

    python scripts/validation/collapse_demo.py [--quick]

Writes ``docs/figures/choice_collapse.png``. A few minutes in full.
"""

from __future__ import annotations

import argparse
import math
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import brentq

from granulargas import theory
from granulargas.run import validity as V
from granulargas.contact import restitution_table
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.errors import InelasticCollapseError


def record(sim, t_end, dt, budget):
    """Run in steps of max(dt, 5 % of t) to t_end (or the collision budget); (t, C, T, rate), error or None."""
    rows = [(sim.time, sim.collisions, sim.temperature, math.nan)]
    err = None
    wall0 = time.perf_counter()
    while sim.time < t_end and sim.collisions < budget:
        try:
            sim.run(until=min(sim.time + max(dt, 0.05 * sim.time), t_end), max_collisions=budget - sim.collisions)
        except InelasticCollapseError as exc:
            err = exc
            break
        rows.append((sim.time, sim.collisions, sim.temperature, sim.collision_rate))
    return np.array(rows), err, time.perf_counter() - wall0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--particles", type=int, default=2000)
    ap.add_argument("--packing", type=float, default=0.4)
    ap.add_argument("--restitution", type=float, default=0.5)
    ap.add_argument("--out", default="docs/figures/choice_collapse.png")
    args = ap.parse_args(argv)
    n, eta, eps = args.particles, args.packing, args.restitution
    budget = 6_000_000
    if args.quick:
        n, budget = 1000, 1_000_000
    wall0 = time.perf_counter()
    st = random_state(n=n, packing=eta, dimension=2, temperature=1.0, seed=1)
    dens = theory.number_density(eta, 2)
    omega0 = float(theory.collision_frequency(dens, 1.0, 2))
    t_free = 1.0 / omega0

    # 1. unguarded constant eps: run until the detector fires
    sim = Simulation(st, CollisionRule.constant(eps))
    plain, err, wall = record(sim, math.inf, 1.0, budget)
    if err is None:
        raise SystemExit("no collapse within the collision budget; lower --restitution or raise --packing")
    t_col, c_col = sim.time, sim.collisions
    print(f"constant eps = {eps}: InelasticCollapseError after {wall:.1f} s wall:\n  {err}")
    # rerun (deterministic) and count the collisions still to come before t_col
    sim = Simulation(st, CollisionRule.constant(eps))
    deltas = np.geomspace(0.3 * t_col, 1e-9 * t_col, 40)
    remaining = []
    for d in deltas:
        try:
            sim.run(until=t_col - d)
        except InelasticCollapseError:
            break
        remaining.append(c_col - sim.collisions)
    deltas = deltas[: len(remaining)]
    rate_late = plain[-1, 3]  # collisions per particle per unit time just before
    print(f"  collisions remaining before t_collapse: {remaining[0]} at delta = {deltas[0]:.3g}, "
          f"{remaining[-1]} at delta = {deltas[-1]:.3g} (a homogeneous gas: {n * rate_late * deltas[-1] / 2:.2g})")

    # 2. TC model
    t_run = 2.0 * t_col
    tc_runs = {}
    for f in (1e-6, 1e-4, 1e-2):
        sim = Simulation(st, CollisionRule.constant(eps, tc_time=f * t_free))
        rows, e2, w2 = record(sim, t_run, 1.0, budget)
        tc_runs[f] = (rows, e2, w2)
        on = plain[:, 0] <= rows[-1, 0]
        Ttc = np.interp(plain[on, 0], rows[:, 0], rows[:, 2])
        dev = np.max(np.abs(Ttc / plain[on, 2] - 1))
        print(f"TC tc_time = {f:g} t_free: reached t = {rows[-1, 0]:.4g} ({'collapse!' if e2 else 'ok'}), "
              f"{rows[-1, 1] / n * 2:.4g} collisions per particle, {w2:.1f} s wall; "
              f"max |T_TC/T_plain - 1| before t_collapse = {100 * dev:.2g} %")

    # 3. viscoelastic with the same initial cooling rate
    gas = V.Gas(dimension=2, packing_fraction=eta, density=dens, sigma=1.0, mass=1.0, temperature=1.0,
                model="viscoelastic", prefactor=1.0)
    from dataclasses import replace

    def mismatch(lb):
        return V.effective_inelasticity(replace(gas, prefactor=math.exp(lb)), 1.0) - (1 - eps**2)

    b = math.exp(brentq(mismatch, math.log(1e-3), math.log(5.0)))
    gas = replace(gas, prefactor=b)  # reduced units: k = b = damping for unit particles
    table = restitution_table(b * (2 * math.sqrt(2 * n)) ** 0.2 * 1.01)
    sim = Simulation(st, CollisionRule.viscoelastic(prefactor=b, table=table))
    visco, e3, w3 = record(sim, t_run, 1.0, budget)
    print(f"viscoelastic damping = {b:.4g} (same initial cooling rate): reached t = {visco[-1, 0]:.4g} "
          f"({'collapse!' if e3 else 'ok'}), {visco[-1, 1] / n * 2:.4g} collisions per particle, {w3:.1f} s wall")
    print(f"total wall {time.perf_counter() - wall0:.0f} s (N = {n}, packing {eta}, eps = {eps})")

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    ax = axes[0]
    ax.loglog(deltas, 2 * np.array(remaining) / n, "o-", color="C3", ms=4, label="constant eps: measured")
    ax.loglog(deltas, rate_late * deltas, "k--", label="homogeneous gas at the last rate")
    ax.set_xlabel("t_collapse - t")
    ax.set_ylabel("collisions per particle still to come")
    ax.set_title("event count diverges before the collapse", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[1]
    tt = np.geomspace(0.1, t_run, 200)
    ax.loglog(tt, theory.haff_temperature(tt, 1.0, theory.haff_tau0(eps, dens, 1.0, 2)), color="0.6", lw=4,
              alpha=0.5, label="Haff (homogeneous theory)")
    ax.loglog(plain[1:, 0], plain[1:, 2], color="C3", lw=2, label="constant eps (no guard)")
    ax.plot(plain[-1, 0], plain[-1, 2], "X", color="C3", ms=12, label="InelasticCollapseError")
    for (f, (rows, _, _)), c in zip(tc_runs.items(), ("C0", "C1", "C2")):
        ax.loglog(rows[1:, 0], rows[1:, 2], color=c, lw=1, label=f"TC, tc_time = {f:g} t_free")
    ax.loglog(visco[1:, 0], visco[1:, 2], color="k", lw=1.5, label=f"viscoelastic, damping {b:.3g}")
    ax.set_xlabel("time t")
    ax.set_ylabel("temperature T / T0")
    ax.set_title(f"2D, N = {n}, packing {eta}, eps = {eps}", fontsize=10)
    ax.legend(fontsize=7)
    ax = axes[2]
    for (f, (rows, _, _)), c in zip(tc_runs.items(), ("C0", "C1", "C2")):
        on = plain[:, 0] <= rows[-1, 0]
        ratio = np.interp(plain[on, 0], rows[:, 0], rows[:, 2]) / plain[on, 2] - 1
        ax.plot(plain[on, 0][1:], 100 * ratio[1:], color=c, label=f"tc_time = {f:g} t_free")
    ax.set_xscale("log")
    ax.set_xlabel("time t (before the collapse)")
    ax.set_ylabel("T_TC / T_unguarded - 1  [%]")
    ax.set_title("accuracy cost of the TC model", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
