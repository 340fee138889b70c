"""Velocity distribution of the homogeneous cooling state by DSMC: Sonine coefficients
and the exponential high-energy tail against kinetic theory.

For each case (dimension, constant eps) a DSMC gas of N particles relaxes into the
homogeneous cooling state (HCS), then snapshots of the scaled speeds c = |v|/v_T
(v_T = sqrt(2T/m)) are pooled. Printed per case: the time-averaged a2, a3 against
the first Sonine approximation of van Noije & Ernst (1998); the reduced cooling rate
zeta* measured from T(t) against its first-Sonine value; the tail constant A of
f(c) ~ exp(-A c) fitted in several windows against A = 2 B_d / zeta*
(Esipov & Pöschel 1997; van Noije & Ernst 1998; see
:mod:`granulargas.analysis.velocity`). The figure shows f(c) on a log scale with the
Maxwellian, the Sonine forms and the fitted tail, and the local slope -d ln f/dc.

    python scripts/validation/velocity_distribution.py                      # ~3 min alone on one core
    python scripts/validation/velocity_distribution.py --quick              # small, to check the script
    python scripts/validation/velocity_distribution.py --cases 2:0.5 3:0.7  # other cases

Writes ``docs/figures/dsmc_velocity_distribution.png`` (``--figure`` to change).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

from granulargas import theory
from granulargas.analysis import velocity as vd
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule
from granulargas.state import State


def parse_case(text):
    try:
        dim, eps = text.split(":")
        dim, eps = int(dim), float(eps)
    except ValueError:
        raise argparse.ArgumentTypeError(f"case {text!r}: expected DIM:EPS, e.g. 2:0.3")
    if dim not in (2, 3) or not 0.0 < eps < 1.0:
        raise argparse.ArgumentTypeError(f"case {text!r}: DIM must be 2 or 3 and 0 < EPS < 1")
    return dim, eps


def run_case(dim, eps, n, relax, snapshots, spacing, seed, c_max, log):
    """HCS of one case: (histogram, times, temperatures, dsmc)."""
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((n, dim))
    sim = DSMC(State(None, v, 0.5, 1.0, None), CollisionRule.constant(eps), packing_fraction=0.01, seed=seed)
    start = time.perf_counter()
    sim.run(np.inf, max_collisions=int(relax * n / 2))
    hist = vd.SpeedHistogram(dim, c_max=c_max, bins=int(c_max / 0.05))
    times, temps = [], []
    per = max(1, int(spacing * n / 2))
    for _ in range(snapshots):
        sim.run(np.inf, max_collisions=per)
        hist.add(sim.velocities)
        times.append(sim.time)
        temps.append(sim.temperature)
    wall = time.perf_counter() - start
    log(f"  d={dim} eps={eps}: {sim.collisions:.3g} collisions in {wall:.1f} s "
        f"({sim.collisions / wall / 1e6:.2f} M/s wall), T/T0 = {temps[-1]:.3g}, "
        f"{hist.samples:.3g} speeds pooled")
    return hist, np.array(times), np.array(temps), sim


def tail_windows(hist, a_theory):
    """Fits from c_min = A (where exp(-A c) overtakes exp(-c^2)) and neighbouring starts."""
    fits = []
    for c_min in np.round(np.array([0.8, 0.9, 1.0, 1.1]) * a_theory / 0.05) * 0.05:
        try:
            fits.append(vd.fit_exponential_tail(hist, float(c_min)))
        except ValueError:
            pass
    return fits


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", nargs="+", type=parse_case, default=[(2, 0.3), (3, 0.3)])
    ap.add_argument("--n", type=float, default=1e6, help="particles (default 1e6)")
    ap.add_argument("--relax", type=float, default=30.0, help="collisions per particle before sampling")
    ap.add_argument("--snapshots", type=int, default=400)
    ap.add_argument("--spacing", type=float, default=0.5, help="collisions per particle between snapshots")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quick", action="store_true", help="N = 1e5, 60 snapshots")
    ap.add_argument("--figure", type=Path, default=Path("docs/figures/dsmc_velocity_distribution.png"))
    args = ap.parse_args(argv)
    n = int(1e5) if args.quick else int(args.n)
    snapshots = 60 if args.quick else args.snapshots

    def log(msg):
        print(msg, flush=True)

    log(f"HCS by DSMC, N = {n}, {args.relax:g} collisions per particle to relax, {snapshots} snapshots "
        f"every {args.spacing:g} collisions per particle")
    panels = []
    for dim, eps in args.cases:
        hist, t, temp, sim = run_case(dim, eps, n, args.relax, snapshots, args.spacing, args.seed,
                                      c_max=9.0, log=log)
        a2, a2e, a3, a3e = hist.sonine()
        a2_vne = float(theory.sonine_a2(eps, dim))
        zeta, zeta_err = vd.reduced_cooling_rate(t, temp, (sim.n - 1) / sim.volume, sim.chi, dim)
        zeta_sonine = vd.sonine_cooling_rate(eps, dim, a2)
        a_measured = vd.tail_constant(zeta, dim)
        a_vne = vd.tail_constant(vd.sonine_cooling_rate(eps, dim, a2_vne), dim)
        log(f"    a2 = {a2:.5f} +- {a2e:.5f}   (van Noije-Ernst {a2_vne:.5f}: ratio {a2 / a2_vne:.3f})")
        log(f"    a3 = {a3:.5f} +- {a3e:.5f}")
        log(f"    zeta* = {zeta:.5f} +- {zeta_err:.5f} measured, {zeta_sonine:.5f} first Sonine with "
            f"the measured a2")
        log(f"    tail constant A = 2 B_d/zeta* = {a_measured:.4f} (measured zeta*), {a_vne:.4f} "
            f"(first Sonine, van Noije-Ernst a2)")
        fits = tail_windows(hist, a_measured)
        for f in fits:
            log(f"    fit exp(-A c), c >= {f.c_min:.2f}: A = {f.A:.4f} +- {f.A_err:.4f} "
                f"({f.counts} speeds, deviance/bin {f.deviance_per_bin:.2f}; "
                f"{(f.A - a_measured) / a_measured * 100:+.1f} % from theory)")
        # the figure shows the window starting at 0.9 A
        main_fit = fits[1] if len(fits) > 1 else (fits[0] if fits else None)
        panels.append(dict(hist=hist, fit=main_fit, a2_theory=a2_vne,
                           A_theory={"theory, measured $\\zeta^*$": a_measured},
                           label=f"{dim}D, $\\varepsilon$ = {eps}: HCS by DSMC, N = {n:.0e}, "
                                 f"{hist.snapshots} snapshots"))
    args.figure.parent.mkdir(parents=True, exist_ok=True)
    vd.plot_velocity_distribution(panels, args.figure)
    log(f"wrote {args.figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
