"""White-noise driven steady state against kinetic theory, and its independence of the kick interval.

A gas of constant eps (or viscoelastic) is driven by white-noise kicks every dt_k
(``granulargas.engine.WhiteNoise``) at heating rate H; after a relaxation of
``--relax`` cooling times, T and a2 = d/(d+2) <c^4>/<c^2>^2 - 1 are averaged over
``--measure`` cooling times (about four samples per cooling time, each half-way
between two kicks, where T equals its average over the kick interval to second
order in zeta dt_k; errors from 10 blocks).
The theory: zeta(T) T = H with the Enskog cooling rate and van Noije & Ernst's
driven a2 (``theory.driven_temperature``, ``theory.driven_sonine_a2``); for a
viscoelastic gas the first Sonine moment equations with the exact eps(g)
(``theory.driven_state``), and a2 of the effective-restitution model of Dubey et
al. (2013) (``theory.viscoelastic_driven_state``) for comparison. The a2 estimator over N particles is
biased by -2/(dN) (printed corrected).

Usage::

    python scripts/validation/driven_steady_state.py                          # 3D eps = 0.8, zeta dt_k = 0.002 ... 0.5
    python scripts/validation/driven_steady_state.py --dim 2 --eps 0.7 --packing 0.1
    python scripts/validation/driven_steady_state.py --damping 0.1 --fractions 0.01
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np


def measure(args, fraction, seed):
    from granulargas import theory
    from granulargas.engine import CollisionRule, Simulation, WhiteNoise
    from granulargas.initial import random_state

    d = args.dim
    n_dens = theory.number_density(args.packing, d)
    h = args.heating_rate
    if args.damping is None:
        rule = CollisionRule.constant(args.eps)
        t_th = float(theory.driven_temperature(h, args.eps, n_dens, d))
        a2_th = a2_eff = float(theory.driven_sonine_a2(args.eps, d))
        eps_eff = args.eps
    else:
        from granulargas.contact import prefactor_from_damping, restitution_table

        from granulargas.theory.gas import Gas

        k = prefactor_from_damping(args.damping)
        _, a2_eff, eps_eff = theory.viscoelastic_driven_state(h, k, n_dens, d)
        gas = Gas(dimension=d, packing_fraction=args.packing, density=n_dens, sigma=1.0, mass=1.0,
                  temperature=1.0, model="viscoelastic", prefactor=k)
        t_th, a2_th = theory.driven_state(gas, h)
        rule = CollisionRule.viscoelastic(k, restitution_table(min(40.0, 3.0 * k * (40 * t_th) ** 0.1 + 0.1)))
    zeta = float(theory.enskog_cooling_rate(eps_eff, n_dens, t_th, d, a2=a2_th))
    dt_k = theory.driving_interval(zeta, fraction)
    st = random_state(args.particles, args.packing, d, temperature=t_th, seed=seed)
    sim = Simulation(st, rule, driving=WhiteNoise(h, dt_k, seed=seed))
    spacing = max(1, round(0.25 / zeta / dt_k))  # kicks between samples
    first = max(1, round(args.relax / zeta / dt_k))
    ts, a2s = [], []
    for k in range(int(round(args.measure / (spacing * dt_k * zeta)))):
        sim.run((first + k * spacing) * dt_k)  # kicks at (k + 1/2) dt_k
        v = sim.velocities
        c = v - v.mean(axis=0)
        c2 = np.sum(c * c, axis=1)
        ts.append(np.mean(c2) / d)
        a2s.append(d / (d + 2) * np.mean(c2**2) / np.mean(c2) ** 2 - 1 + 2 / (d * sim.n))
    ts, a2s = np.array(ts), np.array(a2s)
    blocks = lambda x: x[: len(x) // 10 * 10].reshape(10, -1).mean(axis=1)
    bt, ba = blocks(ts), blocks(a2s)
    return dict(fraction=fraction, dt_k=dt_k, omega_dt=float(theory.collision_frequency(n_dens, t_th, d)) * dt_k,
                T=bt.mean(), T_err=bt.std(ddof=1) / math.sqrt(10), a2=ba.mean(),
                a2_err=ba.std(ddof=1) / math.sqrt(10), T_th=t_th, a2_th=a2_th, a2_eff=a2_eff,
                collisions=sim.collisions, kicks=sim.kick_step)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dim", type=int, default=3, choices=[2, 3])
    p.add_argument("--eps", type=float, default=0.8)
    p.add_argument("--damping", type=float, default=None, help="viscoelastic gas of this damping")
    p.add_argument("--packing", type=float, default=0.05)
    p.add_argument("--particles", type=int, default=2000)
    p.add_argument("--heating-rate", type=float, default=0.1)
    p.add_argument("--fractions", type=float, nargs="+", default=[0.002, 0.01, 0.05, 0.2, 0.5],
                   help="values of zeta(T_ss) dt_k")
    p.add_argument("--relax", type=float, default=5.0, help="cooling times before measuring")
    p.add_argument("--measure", type=float, default=200.0, help="cooling times measured")
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args(argv)
    if not (0 < args.eps <= 1 and 0 < args.packing < 0.5 and args.particles >= 50
            and args.heating_rate > 0 and all(f > 0 for f in args.fractions)):
        p.error("need 0 < eps <= 1, 0 < packing < 0.5, particles >= 50, heating rate > 0, fractions > 0")
    what = f"damping {args.damping}" if args.damping is not None else f"eps = {args.eps}"
    print(f"# {args.dim}D, {what}, packing {args.packing}, N = {args.particles}, H = {args.heating_rate}, "
          f"{args.measure:g} cooling times measured")
    print(f"{'zeta dt_k':>9} {'omega dt_k':>10} {'T/T_th':>16} {'a2':>18} {'a2 theory':>9} "
          f"{'collisions':>10} {'kicks':>7} {'s':>6}")
    for f in args.fractions:
        w = time.perf_counter()
        r = measure(args, f, args.seed)
        print(f"{f:9.4g} {r['omega_dt']:10.4g} {r['T'] / r['T_th']:8.4f} +- {r['T_err'] / r['T_th']:.4f} "
              f"{r['a2']:9.4f} +- {r['a2_err']:.4f} {r['a2_th']:9.4f} {r['collisions']:10d} "
              f"{r['kicks']:7d} {time.perf_counter() - w:6.0f}"
              + (f"   (a2 of the eps_eff model {r['a2_eff']:+.4f})" if args.damping is not None else ""),
              flush=True)


if __name__ == "__main__":
    main()
