"""Temperature of a dilute vibrated bed against the plate velocity and the number of layers.

Disks (2D, default) or spheres under gravity g = 1 on a floor vibrating as A sin(omega t)
with a small amplitude A (``--amplitude``), constant restitution e between particles and an
elastic floor; a hard lid high above. For each number of particles per unit floor length N_L
(area N_A in 3D) and plate velocity A omega, the bed runs to a steady state (the second half
of ``--time`` averaged) and its temperature T = m <c^2> / d is compared with the leading-order
balance of plate input and collisional loss (Kumaran 1998; McNamara & Luding 1998;
:func:`granulargas.theory.vibrated.vibrated_bed_temperature`), which holds for
(1 - e^2) N_L sigma << 1, m <U^2> << T and A << T / (m g). The table gives T / T_theory with
those small parameters, and the height h of the centre of mass above the floor against
that of a dilute barometric column at the measured T, h_baro = sigma/2 + T/(m g)
(:func:`granulargas.analysis.vibrated.centre_of_mass_height`, the same as ``analyze`` reports);
the figure (``--figure``) T against A omega per N_L beside the theory's
(A omega)^2, and T / T_theory against (1 - e^2) N_L.

Usage::

    python scripts/validation/vibrated_bed_scaling.py --figure docs/figures/vibrated_bed_scaling.png
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from granulargas.analysis.elastic import block_mean
from granulargas.analysis.vibrated import barometric_height, centre_of_mass, centre_of_mass_height
from granulargas.engine import CollisionRule, Simulation, Wall, Walls
from granulargas.initial import random_state
from granulargas.theory import vibrated as V


def run_bed(column, speed, e, dim, amplitude, t_end, width, seed):
    """(T mean, T error, centre-of-mass height mean, bed parameters) of one bed."""
    u2 = 0.5 * speed**2
    p = V.bed_parameters(column, e, amplitude, u2, 1.0, dim)
    T_th = p["temperature"]
    n = max(int(round(column * width ** (dim - 1))), 100)
    width = (n / column) ** (1.0 / (dim - 1))  # the floor that holds n particles at this column
    height = max(12.0 * T_th, 30.0)
    # placed within about three gravitational heights (no potential energy to shed first), then
    # given the tall box
    low = max(3.0 * T_th, 12.0 * (column + 1.0), 10.0)
    aspect = [width] * (dim - 1) + [low]
    unit = math.pi / 6.0 if dim == 3 else math.pi / 4.0
    packing = n * unit / np.prod(aspect)
    margins = np.zeros((dim, 2))
    margins[-1, 0] = 2.0 * amplitude
    st = random_state(n, packing, dim, temperature=T_th, seed=seed, aspect=aspect,
                      boundary=("periodic",) * (dim - 1) + ("wall",), margins=margins)
    st = st.replace(box=np.array([width] * (dim - 1) + [max(height, low)]))
    nu = speed / (2.0 * math.pi * amplitude)
    walls = Walls(**{"xyz"[dim - 1] + "_low": Wall.vibrating(amplitude, nu)})
    g = [0.0] * (dim - 1) + [-1.0]
    sim = Simulation(st, CollisionRule.constant(e, wall_restitution=1.0, elastic_below=1e-4),
                     gravity=g, walls=walls, neighbours="cells")
    temps, times, coms = [], [], []
    for k in range(1, 201):
        sim.run(k * t_end / 200)
        if k > 100:
            temps.append(sim.temperature)
            times.append(sim.time)
            coms.append(centre_of_mass(sim.positions, 1.0, dim - 1))
    T, Te = block_mean(temps)
    # above the floor's rest position, A inside the box
    com, _ = centre_of_mass_height(times, coms, floor=amplitude, t_from=times[0])
    return T, Te, com, p, n


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dim", type=int, default=2, choices=(2, 3))
    ap.add_argument("--columns", type=float, nargs="+", default=[0.1, 0.3, 1.0, 3.0])
    ap.add_argument("--speeds", type=float, nargs="+", default=[0.5, 1.0, 2.0])
    ap.add_argument("--restitution", type=float, default=0.9)
    ap.add_argument("--amplitude", type=float, default=0.02)
    ap.add_argument("--time", type=float, default=2000.0)
    ap.add_argument("--width", type=float, default=100.0, help="floor length (2D) or side (3D), at least")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--figure", help="write the figure here")
    args = ap.parse_args(argv)
    e = args.restitution
    rows = []
    print(f"# {args.dim}D, e = {e:g} (elastic floor), A = {args.amplitude:g}, g = 1, steady state: second half of "
          f"t = {args.time:g}")
    print(f"{'N_L':>6} {'A omega':>8} {'N':>5} {'T':>10} {'T_theory':>9} {'T/T_th':>12} {'(1-e^2)N':>9} "
          f"{'m<U^2>/T':>9} {'A m g/T':>8} {'floor eta':>9} {'h/h_baro':>8} {'s':>6}")
    for column in args.columns:
        for speed in args.speeds:
            t0 = time.perf_counter()
            T, Te, com, p, n = run_bed(column, speed, e, args.dim, args.amplitude, args.time, args.width, args.seed)
            rows.append((column, speed, T, Te, p))
            print(f"{column:6.3g} {speed:8.3g} {n:5d} {T:10.4g} {p['temperature']:9.4g} "
                  f"{T / p['temperature']:7.3f}±{Te / p['temperature']:.3f} {p['dissipation']:9.3g} "
                  f"{p['plate_speed']:9.3g} {p['amplitude']:8.2g} {p['floor_packing']:9.2g} {com / barometric_height(T, 1.0):8.3f} "
                  f"{time.perf_counter() - t0:6.0f}", flush=True)
    if args.figure:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4.2))
        for column in args.columns:
            r = [x for x in rows if x[0] == column]
            s = np.array([x[1] for x in r])
            line = a1.errorbar(s, [x[2] for x in r], yerr=[x[3] for x in r], fmt="o", label=f"N_L = {column:g}")
            th = [V.vibrated_bed_temperature(column, e, 0.5 * u**2, args.dim) for u in s]
            a1.plot(s, th, "-", color=line[0].get_color(), lw=1)
        a1.set_xscale("log")
        a1.set_xticks(args.speeds, [f"{x:g}" for x in args.speeds])
        a1.minorticks_off()
        a1.set_yscale("log")
        a1.set_xlabel("plate velocity A omega")
        a1.set_ylabel("T (points); leading order (lines)")
        a1.legend(fontsize=8)
        for speed in args.speeds:
            r = [x for x in rows if x[1] == speed]
            a2.errorbar([x[4]["dissipation"] for x in r], [x[2] / x[4]["temperature"] for x in r],
                        yerr=[x[3] / x[4]["temperature"] for x in r], fmt="o-", label=f"A omega = {speed:g}")
        a2.axhline(1.0, color="k", lw=0.8)
        a2.set_xscale("log")
        ticks = sorted({x[4]["dissipation"] for x in rows})
        a2.set_xticks(ticks, [f"{x:.2g}" for x in ticks])
        a2.minorticks_off()
        a2.set_xlabel("(1 - e^2) N_L sigma")
        a2.set_ylabel("T / T_theory")
        a2.legend(fontsize=8)
        fig.suptitle(f"Dilute vibrated bed ({args.dim}D, e = {e:g}): T against the leading-order balance "
                     f"(Kumaran 1998)", fontsize=10)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=110)
        print(f"wrote {args.figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
