"""Binary mixtures against Garzó & Dufty (1999): the temperature ratio T1/T2 of the homogeneous
cooling state (and of the white-noise driven state), from the event-driven engine and the DSMC.

For each case (mass ratio m1/m2, size ratio sigma1/sigma2, constant eps for every pair, equal
numbers) a gas of N particles starts Maxwellian at one temperature; after a transient of
``--transient`` collisions per particle the ratio T1/T2 of the species' temperatures is
averaged over ``--average`` more, sampled every collision per particle; the error is the
standard error of 10 block means. The theory is the Maxwellian one of Garzó & Dufty (1999)
(:func:`granulargas.theory.mixture.hcs_temperature_ratios`), dilute (chi = 1) or, for the
``--dense`` cases, Enskog with the BGHLM chi_ij. The DSMC solves the dilute Boltzmann
equation (chi = 1); the engine runs at packing ``--packing`` (dilute) and at the dense
cases' packing fractions, in a box below the shear-instability length (a larger box clusters, and
a shared flow velocity makes the heavy species look hotter).

Writes a table (stdout, and ``--json``) and a figure (``--figure``).

Usage::

    python scripts/validation/mixture_validation.py --figure docs/figures/mixture_hcs.png --json mixture_hcs.json
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time

import numpy as np

from granulargas import theory
from granulargas.analysis.cooling import block_mean
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, Simulation, WhiteNoise
from granulargas.initial import random_state
from granulargas.initial.lattice_gas import maxwell_velocities
from granulargas.observables import species_moments
from granulargas.state import State
from granulargas.theory.mixture import driven_temperature_ratios, hcs_temperature_ratios

#: (m1/m2, sigma1/sigma2, eps): the mass ratios 2-10, size ratios 0.5-2 and eps 0.7-0.9 of the range
#: where the Maxwellian theory is known to be accurate to a few per cent
CASES = [(2.0, 1.0, 0.9), (4.0, 1.0, 0.8), (10.0, 1.0, 0.8), (10.0, 1.0, 0.9), (2.0, 1.0, 0.7),
         (8.0, 2.0, 0.8), (1.0, 2.0, 0.8), (1.0, 0.5, 0.8), (4.0, 0.5, 0.7), (2.0, 2.0, 0.9), (5.0, 1.0, 0.7)]
#: finite density (engine only): (m1/m2, sigma1/sigma2, eps, packing)
DENSE = [(4.0, 1.0, 0.8, 0.2), (4.0, 1.0, 0.8, 0.3), (4.0, 1.0, 0.95, 0.3), (2.0, 1.0, 0.8, 0.3),
         (4.0, 2.0, 0.9, 0.2)]


def species_of(n):
    return np.repeat([0, 1], [n // 2, n - n // 2]).astype(np.int32)


def particles(n, mass_ratio, size_ratio):
    of = species_of(n)
    m = np.array([mass_ratio, 1.0])[of]
    r = 0.5 * np.array([size_ratio, 1.0])[of]
    return of, r, m


def measure(sim, of, n, transient, average):
    sim.run(math.inf, max_collisions=int(transient * n / 2))
    ratios = []
    for _ in range(int(average)):
        sim.run(math.inf, max_collisions=n // 2)
        t, _ = species_moments(sim.velocities, sim.masses, of, 2)
        ratios.append(t[0] / t[1])
    return block_mean(ratios)


def dsmc_case(mass_ratio, size_ratio, eps, n, transient, average, seed, driving=None):
    of, r, m = particles(n, mass_ratio, size_ratio)
    v = maxwell_velocities(m, 3, 1.0, rng=np.random.default_rng(seed))
    st = State(None, v, r, m, None, species=of)
    sim = DSMC(st, CollisionRule.constant(np.full((2, 2), eps)), packing_fraction=0.001, chi=1.0, seed=seed,
               driving=driving)
    return measure(sim, of, n, transient, average)


def edmd_case(mass_ratio, size_ratio, eps, n, packing, transient, average, seed, driving=None):
    of, r, m = particles(n, mass_ratio, size_ratio)
    rng = np.random.default_rng(seed)
    perm = rng.permutation(n)  # species placed at random
    of, r, m = of[perm], r[perm], m[perm]
    st = random_state(n, packing, 3, seed=seed, radii=r, masses=m).replace(species=of)
    sim = Simulation(st, CollisionRule.constant(np.full((2, 2), eps)), neighbours="auto", driving=driving)
    return measure(sim, of, n, transient, average)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n-dsmc", type=int, default=20000)
    ap.add_argument("--n-edmd", type=int, default=4000)
    ap.add_argument("--packing", type=float, default=0.02, help="the engine's dilute packing fraction")
    ap.add_argument("--transient", type=float, default=30.0, help="collisions per particle before averaging")
    ap.add_argument("--average", type=float, default=40.0, help="collisions per particle averaged")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--figure")
    ap.add_argument("--json")
    ap.add_argument("--replot", metavar="JSON", help="only draw --figure from the table a previous --json wrote")
    args = ap.parse_args()
    if args.replot:
        with open(args.replot) as fh:
            plot(json.load(fh)["rows"], args.figure)
        return
    start = time.perf_counter()
    rows = []
    print(f"{'m1/m2':>6} {'s1/s2':>6} {'eps':>5} {'theory':>8} {'DSMC':>16} {'dev':>7} {'EDMD':>16} {'dev':>7}")
    for mr, sr, eps in CASES:
        th = hcs_temperature_ratios([mr, 1.0], [sr, 1.0], [0.5, 0.5], eps)
        th = th[0] / th[1]
        d, de = dsmc_case(mr, sr, eps, args.n_dsmc, args.transient, args.average, args.seed)
        e, ee = edmd_case(mr, sr, eps, args.n_edmd, args.packing, args.transient, args.average, args.seed)
        rows.append(dict(kind="hcs", mass_ratio=mr, size_ratio=sr, eps=eps, packing=0.0, theory=th, dsmc=d,
                         dsmc_error=de, edmd=e, edmd_error=ee, edmd_packing=args.packing))
        print(f"{mr:6g} {sr:6g} {eps:5g} {th:8.4f} {d:9.4f} +- {de:.4f} {100 * (d / th - 1):+6.2f}% "
              f"{e:9.4f} +- {ee:.4f} {100 * (e / th - 1):+6.2f}%", flush=True)
    print("finite density (engine; theory: Enskog, BGHLM chi_ij, Maxwellian); the box below the shear-instability "
          "length of the mean particle (fewer particles), so that the gas stays homogeneous")
    for mr, sr, eps, phi in DENSE:
        th = hcs_temperature_ratios([mr, 1.0], [sr, 1.0], [0.5, 0.5], eps, packing=phi)
        th = th[0] / th[1]
        dil = hcs_temperature_ratios([mr, 1.0], [sr, 1.0], [0.5, 0.5], eps)
        sigma = 0.5 * (1.0 + sr)
        n_dens = phi / float(theory.particle_volume(sigma, 3))
        lc = float(theory.instability_length(eps, n_dens, 3, sigma))
        n = int(min(args.n_edmd, math.floor(n_dens * (0.95 * lc) ** 3)))
        e, ee = edmd_case(mr, sr, eps, n, phi, args.transient, 3 * args.average, args.seed)
        rows.append(dict(kind="hcs-dense", mass_ratio=mr, size_ratio=sr, eps=eps, packing=phi, theory=th,
                         theory_dilute=dil[0] / dil[1], edmd=e, edmd_error=ee, n=n, instability_length=lc))
        print(f"{mr:6g} {sr:6g} {eps:5g} phi {phi:4g} N {n:5d} (L_c {lc:.3g}) Enskog {th:.4f} (dilute "
              f"{dil[0] / dil[1]:.4f}) EDMD {e:.4f} +- {ee:.4f} {100 * (e / th - 1):+6.2f}%", flush=True)
    print("white-noise driven, every species heated at the same dT_i/dt (granulargas's driving)")
    for mr, sr, eps in [(4.0, 1.0, 0.8), (1.0, 2.0, 0.8)]:
        th = driven_temperature_ratios([mr, 1.0], [sr, 1.0], [0.5, 0.5], eps, noise="equal_heating")
        th = th[0] / th[1]
        # heating rate: a steady temperature near 1 (Enskog, mean particle)
        h = float(theory.enskog_cooling_rate(eps, 0.001 * 6 / math.pi, 1.0, 3, a2=0.0))
        d, de = dsmc_case(mr, sr, eps, args.n_dsmc, args.transient, args.average, args.seed,
                          driving=WhiteNoise(h, 0.01 / h, seed=args.seed))
        h_e = float(theory.enskog_cooling_rate(eps, args.packing * 6 / math.pi, 1.0, 3, a2=0.0))
        e, ee = edmd_case(mr, sr, eps, args.n_edmd, args.packing, args.transient, args.average, args.seed,
                          driving=WhiteNoise(h_e, 0.01 / h_e, seed=args.seed))
        rows.append(dict(kind="driven", mass_ratio=mr, size_ratio=sr, eps=eps, packing=0.0, theory=th, dsmc=d,
                         dsmc_error=de, edmd=e, edmd_error=ee, edmd_packing=args.packing))
        print(f"{mr:6g} {sr:6g} {eps:5g} {th:8.4f} {d:9.4f} +- {de:.4f} {100 * (d / th - 1):+6.2f}% "
              f"{e:9.4f} +- {ee:.4f} {100 * (e / th - 1):+6.2f}%", flush=True)
    load = os.getloadavg()
    print(f"wall time {time.perf_counter() - start:.0f} s; load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"rows": rows, "arguments": vars(args)}, fh, indent=1)
    if args.figure:
        plot(rows, args.figure)


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.6), gridspec_kw={"width_ratios": [3, 2]})
    hcs = [r for r in rows if r["kind"] in ("hcs", "driven")]
    x = np.arange(len(hcs))
    th = np.array([r["theory"] for r in hcs])
    ax.plot(x, th, "k_", ms=18, mew=2, label="Garzó & Dufty 1999 (Maxwellian)")
    ax.errorbar(x - 0.12, [r["dsmc"] for r in hcs], yerr=[r["dsmc_error"] for r in hcs], fmt="o", ms=4,
                label="DSMC (dilute)")
    ax.errorbar(x + 0.12, [r["edmd"] for r in hcs], yerr=[r["edmd_error"] for r in hcs], fmt="s", ms=4,
                label=f"EDMD (packing {hcs[0]['edmd_packing']:g})")
    ax.set_xticks(x)
    ax.set_xticklabels([f"{r['mass_ratio']:g}, {r['size_ratio']:g}, {r['eps']:g}" + ("\ndriven" if r["kind"] ==
                                                                                         "driven" else "")
                        for r in hcs], rotation=60, fontsize=7)
    ax.set_xlabel("m1/m2, sigma1/sigma2, eps (equal numbers)")
    ax.set_ylabel("T1 / T2")
    ax.legend(fontsize=8)
    ax.set_title("homogeneous cooling and driven states", fontsize=10)
    dense = [r for r in rows if r["kind"] == "hcs-dense"]
    y = np.arange(len(dense))
    bx.plot(y, [r["theory_dilute"] for r in dense], "_", color="0.6", ms=24, mew=4, label="dilute")
    bx.plot(y, [r["theory"] for r in dense], "k_", ms=18, mew=2, label="Enskog (BGHLM chi_ij; one size: = dilute)")
    bx.errorbar(y, [r["edmd"] for r in dense], yerr=[r["edmd_error"] for r in dense], fmt="s", ms=4, color="C1",
                label="EDMD")
    bx.set_xticks(y)
    bx.set_xticklabels([f"{r['mass_ratio']:g}, {r['size_ratio']:g}, {r['eps']:g}\nphi {r['packing']:g}"
                        for r in dense], fontsize=7)
    bx.set_ylabel("T1 / T2")
    top = max(r["edmd"] + r["edmd_error"] for r in dense)
    bx.set_ylim(top=1.0 + 1.3 * (top - 1.0))  # room for the legend above the points
    bx.legend(fontsize=8, loc="upper right")
    bx.set_title("finite density", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
