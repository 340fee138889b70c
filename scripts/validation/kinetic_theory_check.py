"""The kinetic theory of granulargas.theory.gas against the engine and against DSMC.

The same homogeneous gas (Maxwellian start at T0 = 1, a given restitution law) cools

* by the moment equations of the Enskog-Boltzmann equation in the first Sonine
  approximation with the exact eps(g) (:func:`granulargas.theory.gas.cooling_curve`),
* in the event-driven engine (hard spheres in a periodic box, several seeds), and
* by DSMC of the Enskog-Boltzmann equation with the engine's collision rule and the
  same chi (:mod:`granulargas.dsmc`, if installed): the exact solution the moment
  equations approximate, without the velocity correlations of a real gas.

Printed: T/T_theory - 1 of the engine (mean +- standard error over seeds) and of the
DSMC, a2 of all three, and the leading-order law in the damping for comparison.

    python scripts/validation/kinetic_theory_check.py                       # quickstart gas, ~2 min alone
    python scripts/validation/kinetic_theory_check.py --dim 2 --packing 0.05
    python scripts/validation/kinetic_theory_check.py --restitution 0.8     # constant eps instead
    python scripts/validation/kinetic_theory_check.py --quick               # small, to check the script
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from granulargas import theory
from granulargas.analysis.cooling import sonine_coefficients, temperature
from granulargas.contact import prefactor_from_damping, restitution_table
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.state import State
from granulargas.theory.gas import Gas, cooling_curve


def observe(sim, times, velocities):
    out = np.empty((len(times), 2))
    for k, t in enumerate(times):
        sim.run(t)
        v = velocities(sim)
        out[k] = temperature(v), sonine_coefficients(v)[0]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dim", type=int, choices=(2, 3), default=3)
    ap.add_argument("--packing", type=float, default=0.1)
    ap.add_argument("--damping", type=float, default=0.1, help="viscoelastic: beta at g = 1 of two reference particles")
    ap.add_argument("--restitution", type=float, default=None, help="constant eps instead of the viscoelastic law")
    ap.add_argument("--n", type=int, default=2000, help="engine particles per seed")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--dsmc-n", type=float, default=1e6, help="DSMC particles")
    ap.add_argument("--end", type=float, default=100.0)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    d, eta = args.dim, args.packing
    n, seeds, dsmc_n, end = args.n, args.seeds, int(args.dsmc_n), args.end
    if args.quick:
        n, seeds, dsmc_n, end = 400, 2, 20000, 10.0
    nd = float(theory.number_density(eta, d))
    if args.restitution is None:
        k = prefactor_from_damping(args.damping)
        gas = Gas(d, eta, nd, 1.0, 1.0, 1.0, "viscoelastic", prefactor=k)
        table = restitution_table(gas.beta(40.0) * 1.2)
        rule = CollisionRule.viscoelastic(k, table)
        law = f"viscoelastic, damping {args.damping}"
        tau_closed = theory.viscoelastic_tau0(k, nd, 1.0, d, chi=gas.chi)

        def closed(t):
            return theory.viscoelastic_temperature(t, 1.0, tau_closed)
    else:
        eps = args.restitution
        gas = Gas(d, eta, nd, 1.0, 1.0, 1.0, "constant", restitution=eps)
        rule = CollisionRule.constant(eps)
        law = f"constant eps = {eps}"
        tau_closed = theory.haff_tau0(eps, nd, 1.0, d, chi=gas.chi)

        def closed(t):
            return theory.haff_temperature(t, 1.0, tau_closed)
    times = np.geomspace(0.02 * end, end, 12)
    curve = cooling_curve(gas, t_end=end)
    T_th, a2_th = curve.temperature_at(times), curve.a2_at(times)
    print(f"{d}D, packing {eta}, {law}, chi = {gas.chi:.5f}; engine N = {n} x {seeds} seeds", flush=True)

    engine = []
    for seed in range(seeds):
        state = random_state(n, eta, d, seed=seed)
        sim = Simulation(state, rule)
        engine.append(observe(sim, times, lambda s: s.velocities))
        print(f"  engine seed {seed}: {sim.collisions} collisions", flush=True)
    engine = np.array(engine)
    ratio = engine[:, :, 0] / T_th - 1
    r_mean = ratio.mean(axis=0)
    r_err = ratio.std(axis=0, ddof=1) / math.sqrt(seeds) if seeds > 1 else np.full(times.shape, np.nan)

    dsmc = None
    try:
        from granulargas.dsmc import DSMC
    except ImportError:
        print("  DSMC: granulargas.dsmc is not installed; engine only")
    else:
        rng = np.random.default_rng(7)
        v = rng.standard_normal((dsmc_n, d))
        v -= v.mean(axis=0)
        v /= math.sqrt(temperature(v))
        sim = DSMC(State(None, v, 0.5, 1.0, None), rule, packing_fraction=eta, chi=gas.chi, seed=3)
        dsmc = observe(sim, times, lambda s: s.velocities)
        print(f"  DSMC: N = {dsmc_n}, {sim.collisions} collisions", flush=True)

    head = f"{'t':>9} {'T_theory':>10} {'engine/theory-1':>19}"
    head += f" {'DSMC/theory-1':>14}" if dsmc is not None else ""
    head += f" {'closed/theory-1':>16} {'a2 theory':>10} {'a2 engine':>10}" + (f" {'a2 DSMC':>9}" if dsmc is not None else "")
    print(head)
    for q, t in enumerate(times):
        line = f"{t:9.4g} {T_th[q]:10.5g} {100 * r_mean[q]:+8.3f} +- {100 * r_err[q]:5.3f} %"
        if dsmc is not None:
            line += f" {100 * (dsmc[q, 0] / T_th[q] - 1):+12.3f} %"
        line += f" {100 * (closed(t) / T_th[q] - 1):+14.2f} % {a2_th[q]:+10.5f} {engine[:, q, 1].mean():+10.5f}"
        if dsmc is not None:
            line += f" {dsmc[q, 1]:+9.5f}"
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
