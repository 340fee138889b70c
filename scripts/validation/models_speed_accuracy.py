"""Event-driven MD against DSMC: what each costs for a given accuracy, and where DSMC fails.

Both methods use the same collision rule (the engine's CollisionRule, the same restitution
table and pair prefactor); DSMC solves the homogeneous Enskog-Boltzmann equation, which has
no positions, so it misses whatever the positions carry.

1. **Speed against accuracy** (one dilute viscoelastic cooling scene: 3D, packing 0.02,
   damping 0.1, T0 = 1, about 100 collisions per particle). The reference is a long DSMC
   run (``--reference-n`` particles). Each method runs at several sample sizes N with
   several seeds; the error of a run is the root mean square over the sample times of
   T/T_ref - 1 and of a2 - a2_ref; its cost is the process time of building the
   initial state and running it (the JIT compile is done beforehand). The engine's error
   has a floor: the finite-density correlations of real hard spheres, which the
   Enskog-Boltzmann equation leaves out (a few tenths of a per cent at this packing).
2. **Packing scan** (3D, constant eps = 0.9, about 30 collisions per particle after 30
   elastic ones that relax the random placement's pair structure): the temperature and
   the collision count of the engine against DSMC at the same packing. Enskog's
   molecular chaos holds for dilute gases; the gap grows with the packing (velocity
   correlations). N = 1500 keeps every box near or below the shear-instability length
   L_c (printed), so that the gap is not clustering.
3. **Clustering** (2D, constant eps = 0.8, packing 0.1, a box ~10 L_c): the engine's gas
   leaves the homogeneous cooling state (shear modes, then clusters) and cools more slowly
   than Haff's law; DSMC, without space, stays homogeneous and follows Haff's law.

    python scripts/validation/models_speed_accuracy.py            # ~10 min alone on one core
    python scripts/validation/models_speed_accuracy.py --quick    # small, to check the script

Writes ``docs/figures/models_speed_accuracy.png`` and ``docs/figures/models_where_dsmc_fails.png``
(``--prefix`` to change).
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


def moments(v):
    """(T, a2) of the peculiar velocities of unit-mass particles."""
    t, a2, _ = energy_moments(np.ascontiguousarray(v), v.shape[1], np.ones(1))
    return t, a2



def maxwellian(n, d, seed):
    """Velocities of n unit-mass particles at exactly T = 1 with zero total momentum."""
    v = np.random.default_rng(seed).standard_normal((n, d))
    v -= v.mean(axis=0)
    return v / math.sqrt(moments(v)[0])


def engine_run(n, eta, d, rule, seed, times, relax=0.0):
    """(history, seconds) of one engine run; the seconds include the initial state.

    ``relax`` > 0: first that many elastic collisions per particle, then the velocities
    rescaled to T = 1 (the random placement's pair structure is not the equilibrium one).
    """
    c0 = time.process_time()
    st = random_state(n, eta, d, seed=seed)
    if relax > 0.0:
        warm = Simulation(st, CollisionRule.elastic())
        omega0 = float(theory.collision_frequency(theory.number_density(eta, d), 1.0, d,
                                                  chi=theory.contact_value(eta, d)))
        warm.run(relax / omega0)
        v = warm.velocities - warm.velocities.mean(axis=0)
        st = st.replace(positions=warm.positions, velocities=v / math.sqrt(moments(v)[0]))
    sim = Simulation(st, rule)
    h = sample_history(sim, times)
    return h, time.process_time() - c0


def dsmc_run(n, eta, d, rule, seed, times, chi):
    c0 = time.process_time()
    sim = DSMC(State(None, maxwellian(n, d, seed), 0.5, 1.0, None), rule, packing_fraction=eta, chi=chi, seed=seed)
    h = sample_history(sim, times)
    return h, time.process_time() - c0


def warm_up(d, rule, chi):
    """Compile the kernels once so that no timed run pays for it."""
    times = np.array([0.05])
    engine_run(64, 0.1, d, rule, 0, times)
    dsmc_run(64, 0.1, d, rule, 0, times, chi)


def speed_accuracy(args):
    d, eta = 3, 0.02
    k = prefactor_from_damping(0.1)
    chi = float(theory.contact_value(eta, d))
    nd = theory.number_density(eta, d)
    omega0 = float(theory.collision_frequency(nd, 1.0, d, chi=chi))
    end = (30.0 if args.quick else 100.0) / omega0
    times = np.geomspace(1.0 / omega0, end, 12)
    table = restitution_table(beta_bound(k, random_state(2, 1e-3, d, seed=0)) * 2.0)
    rule = CollisionRule.viscoelastic(k, table)
    warm_up(d, rule, chi)
    ref_n = int(2e4 if args.quick else args.reference_n)
    refs = [dsmc_run(ref_n, eta, d, rule, 1000 + s, times, chi)[0] for s in range(2)]
    ref = np.mean(refs, axis=0)
    print(f"1. speed against accuracy: 3D viscoelastic (damping 0.1), packing {eta}, to t = {end:.4g} "
          f"(~{2 * ref[-1, 2] / ref_n:.0f} collisions per particle, T = {ref[-1, 0]:.4g}); reference: DSMC "
          f"N = {ref_n:.0e} x 2", flush=True)
    sizes = {"engine": (500, 1000) if args.quick else (500, 2000, 8000),
             "DSMC": (1000, 10000) if args.quick else (1000, 10000, 100000, 1000000)}
    seeds = 2 if args.quick else 3
    rows = []
    for method, ns in sizes.items():
        for n in ns:
            err_t, err_a2, cost = [], [], []
            for s in range(seeds):
                if method == "engine":
                    h, sec = engine_run(n, eta, d, rule, s, times)
                else:
                    h, sec = dsmc_run(n, eta, d, rule, s, times, chi)
                err_t.append(math.sqrt(np.mean((h[:, 0] / ref[:, 0] - 1.0) ** 2)))
                err_a2.append(math.sqrt(np.mean((h[:, 1] - ref[:, 1]) ** 2)))
                cost.append(sec)
            rows.append((method, n, float(np.median(cost)), float(np.median(err_t)), float(np.median(err_a2))))
            print(f"   {method:6s} N = {n:8d}: {rows[-1][2]:8.3f} s  rms(T/T_ref - 1) = {rows[-1][3]:.2e}  "
                  f"rms(a2 - a2_ref) = {rows[-1][4]:.2e}   (medians of {seeds} seeds)", flush=True)
    return rows, ref_n


def packing_scan(args):
    d, eps = 3, 0.9
    rule = CollisionRule.constant(eps)
    n = 1000 if args.quick else 1500
    seeds = 2 if args.quick else 8
    packings = (0.02, 0.1, 0.25) if args.quick else (0.02, 0.05, 0.1, 0.2, 0.3, 0.4)
    print(f"2. packing scan: 3D, constant eps = {eps}, engine N = {n} x {seeds} seeds, DSMC N = 1e5 (errors: seed scatter)", flush=True)
    out = []
    for eta in packings:
        chi = float(theory.contact_value(eta, d))
        nd = theory.number_density(eta, d)
        omega0 = float(theory.collision_frequency(nd, 1.0, d, chi=chi))
        t_end = 30.0 / omega0
        times = np.array([t_end])
        eng = [engine_run(n, eta, d, rule, s, times, relax=30.0)[0][-1] for s in range(seeds)]
        ref = dsmc_run(100000, eta, d, rule, 7, times, chi)[0][-1]
        ratio_t = np.array([e[0] / ref[0] for e in eng])
        ratio_c = np.array([(e[2] / n) / (ref[2] / 100000) for e in eng])
        box = (n * theory.particle_volume(1.0, d) / eta) ** (1.0 / d)
        lc = float(theory.instability_length(eps, nd, d))
        out.append((eta, ratio_t.mean() - 1, ratio_t.std(ddof=1) / math.sqrt(seeds), ratio_c.mean() - 1,
                    ratio_c.std(ddof=1) / math.sqrt(seeds), box / lc))
        print(f"   packing {eta:4.2f}: T_engine/T_DSMC - 1 = {out[-1][1] * 100:+.2f} +- {out[-1][2] * 100:.2f} %, "
              f"collisions engine/DSMC - 1 = {out[-1][3] * 100:+.2f} +- {out[-1][4] * 100:.2f} %  (L/L_c = "
              f"{box / lc:.2f})", flush=True)
    return out


def clustering(args):
    d, eps, eta = 2, 0.8, 0.1
    n = 4000 if args.quick else 20000
    rule_engine = CollisionRule.constant(eps, tc_time=1e-4)  # TC model: no inelastic collapse in clusters
    rule_dsmc = CollisionRule.constant(eps)
    chi = float(theory.contact_value(eta, d))
    nd = theory.number_density(eta, d)
    omega0 = float(theory.collision_frequency(nd, 1.0, d, chi=chi))
    box = (n * theory.particle_volume(1.0, d) / eta) ** (1.0 / d)
    lc = float(theory.instability_length(eps, nd, d))
    end = (100.0 if args.quick else 400.0) / omega0
    times = np.geomspace(1.0 / omega0, end, 16)
    st = random_state(n, eta, d, seed=1)
    eng = sample_history(Simulation(st, rule_engine), times)
    ref = sample_history(DSMC(State(None, maxwellian(100000, d, 3), 0.5, 1.0, None), rule_dsmc, packing_fraction=eta,
                              chi=chi, seed=3), times)
    print(f"3. clustering: 2D, constant eps = {eps}, packing {eta}, N = {n}, L = {box:.4g} = {box / lc:.1f} L_c",
          flush=True)
    for q in range(0, len(times), 3):
        print(f"   t = {times[q]:8.4g}: T_engine/T_DSMC = {eng[q, 0] / ref[q, 0]:.4f}", flush=True)
    return times, eng, ref, box / lc, n


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reference-n", type=float, default=2e6)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--prefix", type=Path, default=Path("docs/figures/models"))
    args = ap.parse_args(argv)
    rows, ref_n = speed_accuracy(args)
    scan = packing_scan(args)
    clus = clustering(args)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.2))
    for ax, col, label in ((axes[0], 3, "rms of $T/T_\\mathrm{ref} - 1$"), (axes[1], 4, "rms of $a_2 - a_{2,\\mathrm{ref}}$")):
        for method, marker, color in (("engine", "o", "C0"), ("DSMC", "s", "C1")):
            r = [x for x in rows if x[0] == method]
            ax.loglog([x[2] for x in r], [x[col] for x in r], marker + "-", color=color,
                      label="event-driven MD" if method == "engine" else "DSMC")
            for x in r:
                ax.annotate(f"N={x[1]:.0e}".replace("e+0", "e"), (x[2], x[col]), fontsize=7,
                            textcoords="offset points", xytext=(4, 4))
        ax.set_xlabel("CPU time per run (s)")
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
    fig.suptitle(f"Cost against accuracy: 3D viscoelastic cooling (damping 0.1), packing 0.02; reference DSMC "
                 f"N = {ref_n:.0e}", fontsize=9)
    fig.tight_layout()
    path1 = Path(f"{args.prefix}_speed_accuracy.png")
    fig.savefig(path1, dpi=130)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.2))
    ax = axes[0]
    eta = [s[0] for s in scan]
    ax.errorbar(eta, [100 * s[1] for s in scan], yerr=[100 * s[2] for s in scan], fmt="o-",
                label="temperature: engine / DSMC - 1")
    ax.errorbar(eta, [100 * s[3] for s in scan], yerr=[100 * s[4] for s in scan], fmt="s-",
                label="collisions: engine / DSMC - 1")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("packing fraction")
    ax.set_ylabel("gap (%)")
    ax.set_title("3D, constant ε = 0.9, N = 1500, ~30 collisions per particle (relaxed start)", fontsize=9)
    ax.legend(fontsize=8)
    times, eng, ref, l_ratio, n = clus
    ax = axes[1]
    ax.loglog(times, eng[:, 0], "o-", ms=3, label=f"event-driven MD (N = {n})")
    ax.loglog(times, ref[:, 0], "k-", label="DSMC (homogeneous)")
    ax.set_xlabel("$t$ ($\\sigma\\sqrt{m/T_0}$)")
    ax.set_ylabel("$T/T_0$")
    ax.set_title(f"2D, constant ε = 0.8, packing 0.1, box = {l_ratio:.0f} $L_c$: clusters", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path2 = Path(f"{args.prefix}_where_dsmc_fails.png")
    fig.savefig(path2, dpi=130)
    print(f"wrote {path1}, {path2}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
