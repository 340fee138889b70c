"""A viscoelastic granular gas by DSMC and by the event-driven engine: T(t) and a2(t).

The same gas (packing 0.02, viscoelastic eps(g_n) of the same restitution table and pair
prefactor, Maxwellian start at T0 = 1) cools in the engine (hard spheres in a periodic
box, several seeds) and in the DSMC (the homogeneous Enskog-Boltzmann equation with the
engine's collision rule and chi of the packing fraction; one large sample as the
low-noise reference and DSMC runs of the engine's size for the seed scatter). Printed:
T and a2 of both at the sample times, the ratio T_engine/T_DSMC - 1 with its error from
the seed scatter, and the collision frequency of both against Enskog's at the current
temperature. The figure shows T/T0, the ratio and a2 against time.

    python scripts/validation/dsmc_vs_engine.py                  # 3D, ~6 min alone on one core
    python scripts/validation/dsmc_vs_engine.py --dim 2
    python scripts/validation/dsmc_vs_engine.py --quick          # small, to check the script

Writes ``docs/figures/dsmc_vs_engine_viscoelastic_{d}d.png`` (``--figure`` to change).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

from granulargas import theory
from granulargas.contact import prefactor_from_damping, restitution_table
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.observables import energy_moments, sample_history
from granulargas.run.prepare import beta_bound
from granulargas.state import State
from granulargas.theory.gas import Gas, viscoelastic_cooling


def observe(v):
    t, a2, a3 = energy_moments(np.ascontiguousarray(v), v.shape[1], np.ones(1))
    return t, a2



def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dim", type=int, choices=(2, 3), default=3)
    ap.add_argument("--packing", type=float, default=0.02)
    ap.add_argument("--damping", type=float, default=0.1, help="beta at g = 1 of two reference particles")
    ap.add_argument("--n", type=int, default=20000, help="engine particles per seed")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--reference-n", type=float, default=1e6, help="particles of the DSMC reference")
    ap.add_argument("--end", type=float, default=None, help="end time (default: ~100 collisions per particle)")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--figure", type=Path, default=None)
    args = ap.parse_args(argv)
    d, eta = args.dim, args.packing
    n = 2000 if args.quick else args.n
    seeds = 2 if args.quick else args.seeds
    ref_n = int(2e4 if args.quick else args.reference_n)
    k = prefactor_from_damping(args.damping)
    nd = theory.number_density(eta, d)
    chi = float(theory.contact_value(eta, d))
    omega0 = float(theory.collision_frequency(nd, 1.0, d, chi=chi))
    end = args.end if args.end is not None else (80.0 if args.quick else 1000.0) / omega0
    times = np.geomspace(0.5 / omega0, end, 14 if args.quick else 28)
    print(f"{d}D, packing {eta}, damping {args.damping} (prefactor k = {k:.5g}), chi = {chi:.5f}, "
          f"omega(T0) = {omega0:.5f}; engine N = {n} x {seeds} seeds, DSMC reference N = {ref_n}", flush=True)

    engine, dsmc_small = [], []
    wall = {"engine": 0.0, "dsmc": 0.0}
    table = None
    for seed in range(seeds):
        state = random_state(n, eta, d, seed=seed)
        if table is None:
            table = restitution_table(beta_bound(k, state) * 1.5)
        rule = CollisionRule.viscoelastic(k, table)
        sim = Simulation(state, rule)
        t0 = time.perf_counter()
        engine.append(sample_history(sim, times))
        wall["engine"] += time.perf_counter() - t0
        small = DSMC(state, rule, seed=100 + seed)
        dsmc_small.append(sample_history(small, times))
        print(f"  seed {seed}: engine {int(engine[-1][-1, 2])} collisions, DSMC {int(dsmc_small[-1][-1, 2])}",
              flush=True)
    rng = np.random.default_rng(7)
    v = rng.standard_normal((ref_n, d))
    big_table = restitution_table(max(table.beta_max, beta_bound(k, random_state(2, 1e-3, d, seed=0)) * 1.5))
    v *= 1.0 / math.sqrt(observe(v - v.mean(axis=0))[0])
    ref = DSMC(State(None, v, 0.5, 1.0, None), CollisionRule.viscoelastic(k, big_table), packing_fraction=eta,
               seed=3)
    t0 = time.perf_counter()
    reference = sample_history(ref, times)
    wall["dsmc"] = time.perf_counter() - t0
    engine, dsmc_small = np.array(engine), np.array(dsmc_small)
    # kinetic theory with the exact eps(g_n) and a Maxwellian distribution (a2 = 0)
    gas = Gas(dimension=d, packing_fraction=eta, density=nd, sigma=1.0, mass=1.0, temperature=1.0,
              model="viscoelastic", prefactor=k)
    t_theory = viscoelastic_cooling(gas, t_min_ratio=1e-6).temperature_at(times)

    t_eng, a2_eng = engine[:, :, 0], engine[:, :, 1]
    ratio = t_eng / reference[None, :, 0] - 1.0
    r_mean, r_err = ratio.mean(axis=0), ratio.std(axis=0, ddof=1) / math.sqrt(seeds)
    small_ratio = dsmc_small[:, :, 0] / reference[None, :, 0] - 1.0
    s_mean, s_err = small_ratio.mean(axis=0), small_ratio.std(axis=0, ddof=1) / math.sqrt(seeds)
    a2_mean, a2_err = a2_eng.mean(axis=0), a2_eng.std(axis=0, ddof=1) / math.sqrt(seeds)
    s_per_particle = 2 * reference[:, 2] / ref_n
    print(f"  wall: engine {wall['engine']:.1f} s for {int(engine[:, -1, 2].sum())} collisions; "
          f"DSMC reference {wall['dsmc']:.1f} s for {int(reference[-1, 2])} collisions")
    theory_ratio = t_theory / reference[:, 0] - 1.0
    print(f"{'t':>9} {'coll/part':>9} {'T_DSMC':>10} {'T_eng/T_DSMC-1':>16} {'DSMC(N)/ref-1':>15} "
          f"{'theory/DSMC-1':>13} {'a2_DSMC':>9} {'a2_engine':>16}")
    for q, t in enumerate(times):
        print(f"{t:9.4g} {s_per_particle[q]:9.2f} {reference[q, 0]:10.5g} "
              f"{r_mean[q] * 100:+7.3f} +- {r_err[q] * 100:5.3f} % {s_mean[q] * 100:+6.3f} +- {s_err[q] * 100:4.3f} % "
              f"{theory_ratio[q] * 100:+11.3f} % {reference[q, 1]:+9.5f} {a2_mean[q]:+9.5f} +- {a2_err[q]:.5f}")
    # collision frequency per particle over the run, against Enskog at the running temperature
    def rate_ratio(h, n_part, density):
        dt = np.diff(np.concatenate([[0.0], times]))
        dc = np.diff(np.concatenate([[0.0], h[:, 2]]))
        t_mid = np.sqrt(np.concatenate([[1.0], h[:-1, 0]]) * h[:, 0])
        return 2 * dc / (n_part * dt) / theory.collision_frequency(density, t_mid, d, chi=chi)

    eng_rate = np.mean([rate_ratio(e, n, nd * (n - 1) / n) for e in engine], axis=0)
    ref_rate = rate_ratio(reference, ref_n, nd * (ref_n - 1) / ref_n)
    print("collision frequency / Enskog omega(T) (geometric-mean T of each interval; both include the "
          "Sonine factor of the real distribution):")
    print("  engine " + " ".join(f"{x:.4f}" for x in eng_rate[::3]))
    print("  DSMC   " + " ".join(f"{x:.4f}" for x in ref_rate[::3]))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(6.6, 8.4), sharex=True, gridspec_kw={"height_ratios": [2.2, 1.4, 1.4]})
    ax = axes[0]
    for s in range(seeds):
        ax.loglog(times, t_eng[s], ".", ms=3, color="C0", label="engine (event-driven)" if s == 0 else None)
    ax.loglog(times, reference[:, 0], "k-", lw=1, label=f"DSMC, N = {ref_n:.0e}")
    ax.loglog(times, t_theory, "r--", lw=0.8, label="kinetic theory, exact eps, $a_2$ = 0")
    ax.set_ylabel("$T/T_0$")
    ax.legend(fontsize=8)
    ax.set_title(f"{d}D viscoelastic gas, packing {eta}, damping {args.damping}: engine (N = {n}, "
                 f"{seeds} seeds) and DSMC", fontsize=9)
    ax = axes[1]
    ax.errorbar(times, r_mean * 100, yerr=r_err * 100, fmt="o", ms=3, color="C0", label="engine / DSMC - 1")
    ax.errorbar(times, s_mean * 100, yerr=s_err * 100, fmt="s", ms=3, color="C2",
                label=f"DSMC (N = {n}) / DSMC - 1")
    ax.plot(times, theory_ratio * 100, "r-", lw=1, label="kinetic theory (exact eps, $a_2$ = 0) / DSMC - 1")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_ylabel("T ratio - 1 (%)")
    ax.legend(fontsize=8)
    ax = axes[2]
    ax.errorbar(times, a2_mean, yerr=a2_err, fmt="o", ms=3, color="C0", label="engine")
    ax.plot(times, reference[:, 1], "k-", lw=1, label="DSMC")
    ax.set_ylabel("$a_2$")
    ax.set_xscale("log")
    ax.set_xlabel("$t$ ($\\sigma\\sqrt{m/T_0}$)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = args.figure or Path(f"docs/figures/dsmc_vs_engine_viscoelastic_{d}d.png")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
