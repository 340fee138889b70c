"""Uniform shear flow at finite density: the event-driven engine against the DSMC of the
Enskog equation, and both against the Grad solution.

For each packing fraction the gas (3D, constant restitution alpha) is sheared at the rate
whose Grad-Enskog steady temperature is T = 1 (:func:`granulargas.theory.shear.grad_usf`
with the packing's contact value), once with hard spheres and Lees-Edwards boundaries
(engine, N particles) and once by the DSMC of the homogeneous Enskog equation with the
same chi (N_DSMC particles). The steady state, from a quarter of the run on, gives the
temperature, the reduced shear rate a* = a / nu0(T), the reduced viscosity
eta* = -P_xy / (a eta0(T)) and the normal stresses P_xx / p, P_yy / p, P_zz / p (kinetic
plus collisional transfer in both methods), with block-mean errors (10 blocks), or
errors from the scatter of independent seeds (``--seeds``). For the engine the last
column is the energy of the longest flow mode along the vorticity axis z over its
equipartition value (:func:`shear_mode_energy`): the DSMC is homogeneous by construction,
the engine's box is not, and a shear mode that grows in it carries energy that the
temperature (relative to the imposed flow) counts.

The engine includes the velocity correlations of a dense gas that the Enskog equation
leaves out, so the two are expected to part slowly as the density grows (Montanero,
Garzó, Santos & Brey 1999 found the Enskog DSMC close to molecular dynamics up to
moderate densities); the Grad solution misses both by a few per cent already in the
dilute limit (Brey, Ruiz-Montero & Moreno 1997).

    python scripts/validation/shear_density.py                    # ~5 min alone on one core
    python scripts/validation/shear_density.py --packings 0.05 --quick

Prints the table of ``docs/shear.md`` ("Finite density").
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from granulargas import theory
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, Simulation
from granulargas.engine.shear import Shear
from granulargas.initial import maxwell_velocities, random_state
from granulargas.state import State

QUANTITIES = ("T", "a_star", "eta_star", "Pxx", "Pyy", "Pzz", "mode")


def shear_mode_energy(sim):
    """N |sum_i c_x,i exp(2 pi i z_i / L_z) / N|^2 / T: the energy of the flow velocity along x
    with the longest wavelength along z (the vorticity axis), over its equipartition value 1
    (a homogeneous gas: 1 within fluctuations; a growing shear mode: above)."""
    c = sim.peculiar_velocities()
    c = c - c.mean(axis=0)
    z = sim.positions[:, 2] / sim.box[2]
    f = np.sum(c[:, 0] * np.exp(2j * np.pi * z))
    return float(abs(f) ** 2 / len(c) / sim.temperature)


def block_mean(x, blocks=10):
    """Mean of ``x`` and the standard error from ``blocks`` block means."""
    x = np.asarray(x, dtype=float)
    b = x[: len(x) // blocks * blocks].reshape(blocks, -1).mean(axis=1)
    return float(x.mean()), float(b.std(ddof=1) / math.sqrt(blocks))


def steady(sim, rate, dim, n, t_relax, t_end, windows):
    """Block means of the steady quantities (:data:`QUANTITIES`) over ``windows`` windows."""
    sim.run(t_relax)
    window = sim.pressure_tensor_window if isinstance(sim, DSMC) else (lambda: sim.pressure_windows()[1])
    window()
    rows = []
    for t in np.linspace(t_relax, t_end, windows + 1)[1:]:
        sim.run(t)
        p = window()
        temp = sim.temperature
        trace = float(np.trace(p)) / dim
        rows.append((temp, rate / float(theory.shear.reference_frequency(n, temp, dim)),
                     -p[0, 1] / (rate * float(theory.shear.dilute_viscosity(temp, dim))),
                     p[0, 0] / trace, p[1, 1] / trace, p[2, 2] / trace,
                     math.nan if isinstance(sim, DSMC) else shear_mode_energy(sim)))
    rows = np.array(rows)
    return {q: block_mean(rows[:, k]) for k, q in enumerate(QUANTITIES)}


def combined(runs):
    """One run: its block means and errors; several seeds: the mean over seeds and the
    standard error from their scatter (independent of the block errors)."""
    if len(runs) == 1:
        return runs[0]
    out = {}
    for q in QUANTITIES:
        x = np.array([r[q][0] for r in runs])
        out[q] = (float(x.mean()), float(x.std(ddof=1) / math.sqrt(len(x))))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--packings", type=float, nargs="+", default=[0.05, 0.1, 0.2])
    ap.add_argument("--restitution", type=float, default=0.9)
    ap.add_argument("--n", type=int, default=500, help="engine particles")
    ap.add_argument("--n-dsmc", type=int, default=10000, help="DSMC particles")
    ap.add_argument("--relax", type=float, default=25.0, help="relaxation, in mean free times chi nu0")
    ap.add_argument("--length", type=float, default=150.0, help="sampled steady state, in mean free times")
    ap.add_argument("--seed", type=int, default=1, help="first seed")
    ap.add_argument("--seeds", type=int, default=1,
                    help="independent runs of each method; with several, errors from their scatter")
    ap.add_argument("--quick", action="store_true", help="short runs, to check the script")
    args = ap.parse_args(argv)
    dim, eps = 3, args.restitution
    if args.quick:
        args.relax, args.length, args.n_dsmc = 5.0, 20.0, 2000
    print(f"3D, alpha = {eps}, engine N = {args.n}, DSMC N = {args.n_dsmc}; steady state over "
          f"{args.length:g} mean free times after {args.relax:g}; "
          + ("block-mean errors" if args.seeds == 1 else f"errors from the scatter of {args.seeds} seeds"))
    print("| packing | chi | method | T / T_Grad | a* | eta* | P_xx/p | P_yy/p | P_zz/p | E_x(k_z) / T |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for phi in args.packings:
        grad = theory.shear.grad_usf(eps, dim, phi)
        n = float(theory.number_density(phi, dim))
        nu0 = float(theory.shear.reference_frequency(n, 1.0, dim))
        rate = grad.a_star * nu0
        t_free = 1.0 / (grad.chi * nu0)
        t_relax, t_end = args.relax * t_free, (args.relax + args.length) * t_free
        rule = CollisionRule.constant(eps)
        t0 = time.process_time()
        md_runs, ds_runs = [], []
        for seed in range(args.seed, args.seed + args.seeds):
            st = random_state(args.n, phi, dim, seed=seed, boundary=("periodic", "lees-edwards", "periodic"),
                              shear=rate)
            md_runs.append(steady(Simulation(st, rule, shear=Shear(rate), stress=True), rate, dim, n, t_relax,
                                  t_end, 100))
        t1 = time.process_time()
        for seed in range(args.seed, args.seed + args.seeds):
            # no positions, no box: the DSMC takes the density
            gas = State(None, maxwell_velocities(np.ones(args.n_dsmc), dim, seed=seed), 0.5, 1.0, None)
            ds_runs.append(steady(DSMC(gas, rule, packing_fraction=phi, seed=seed, shear=Shear(rate)), rate, dim, n,
                                  t_relax, t_end, 100))
        t2 = time.process_time()
        md, ds = combined(md_runs), combined(ds_runs)
        for name, res in (("engine", md), ("DSMC", ds)):
            cells = [f"{res[q][0]:.4f} ± {res[q][1]:.4f}" for q in QUANTITIES[:-1]]
            cells.append("—" if name == "DSMC" else f"{res['mode'][0]:.1f} ± {res['mode'][1]:.1f}")
            print(f"| {phi:g} | {grad.chi:.3f} | {name} | " + " | ".join(cells) + " |")
        p = grad.pressure
        print(f"| {phi:g} | {grad.chi:.3f} | Grad | 1 | {grad.a_star:.4f} | {grad.eta_star:.4f} | "
              f"{p[0, 0]:.4f} | {p[1, 1]:.4f} | {p[2, 2]:.4f} | 1 |")
        gaps = [(md[q][0] - ds[q][0]) / math.hypot(md[q][1], ds[q][1]) for q in QUANTITIES[:-1]]
        print(f"  engine - DSMC in combined standard errors: "
              + ", ".join(f"{q} {g:+.1f}" for q, g in zip(QUANTITIES, gaps))
              + f"  (CPU s: engine {t1 - t0:.0f}, DSMC {t2 - t1:.0f})", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
