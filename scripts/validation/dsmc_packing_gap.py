"""Where DSMC stops being the gas: the EDMD-DSMC gap in the collision rate against packing.

The same config (3D, constant eps, Maxwellian start) runs through ``granulargas run``
with ``run.method = "edmd"`` and ``"dsmc"`` at several packing fractions and seeds.
Measured for each run over the window from ``--skip`` to ``--collisions`` collisions
per particle: the collision frequency per particle divided by sqrt(T),

    omega* = (2 dC / N) / integral sqrt(T) dt   /   (4 sqrt(pi) chi n sigma^2 / sqrt(m)),

i.e. in units of Enskog's value with the theory module's chi, and the energy lost per
collision per T, (dE_diss / dC) / T (trapezoid over the samples). Both methods first run ``--relax`` elastic collisions per
particle and restart from there (``initial.from``): the random placement's pair structure
is not the equilibrium one, and at packing 0.4 its collision rate is still ~5 % above
Enskog's after 12 collisions per particle without it (the elastic control,
``--eps 1``, shows it). DSMC solves the
Enskog-Boltzmann equation, so its omega* is 1 up to (N - 1)/N and the first-Sonine
correction of a2 (~ -a2/16); the engine's departs from it where velocity correlations
and the pair structure of the real gas matter. Printed: both with the standard error
over the seeds, and their ratio. Each run's box is compared with the instability length
(a box above it clusters: the engine then measures a different, inhomogeneous gas).

    python scripts/validation/dsmc_packing_gap.py            # packings 0.02 .. 0.4, 4 seeds, ~ a few minutes
    python scripts/validation/dsmc_packing_gap.py --quick    # to check the script
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from granulargas import theory
from granulargas.io.config import parse_config
from granulargas.io.h5md import read_observables
from granulargas.run.runner import run_config

CONFIG = """
[system]
dimension = 3
particles = {n}
packing_fraction = {eta}
seed = {seed}

[collision]
model = "constant"
restitution = {eps}

[initial]
{initial}

[run]
method = "{method}"
collisions_per_particle = {s}

[output]
file = "{out}"
snapshots = 2
"""


def measure(path, n, skip):
    """(omega / sqrt(T), energy lost per collision / T) over the window after ``skip``
    collisions per particle, from the observables."""
    obs = read_observables(path)
    t = obs["temperature"][1]
    temp = obs["temperature"][2]
    coll = obs["collisions"][2].astype(float)
    diss = obs["dissipated_energy"][2]
    keep = 2.0 * coll / n >= skip
    t, temp, coll, diss = t[keep], temp[keep], coll[keep], diss[keep]
    root = np.sqrt(temp)
    integral = float(np.sum(0.5 * (root[1:] + root[:-1]) * np.diff(t)))
    omega = 2.0 * (coll[-1] - coll[0]) / n / integral
    per_t = np.diff(diss) / np.maximum(np.diff(coll), 1.0) / (0.5 * (temp[1:] + temp[:-1]))
    weights = np.diff(coll)
    return omega, float(np.sum(per_t * weights) / np.sum(weights))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--packings", type=float, nargs="+", default=[0.02, 0.05, 0.1, 0.2, 0.3, 0.4])
    ap.add_argument("--eps", type=float, default=0.95)
    ap.add_argument("--n", type=int, default=4000)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--collisions", type=float, default=12.0, help="collisions per particle per run")
    ap.add_argument("--skip", type=float, default=2.0, help="collisions per particle left out at the start")
    ap.add_argument("--relax", type=float, default=30.0,
                    help="elastic collisions per particle first (the hard-sphere structure of the random "
                         "placement relaxes; the inelastic run restarts from there)")
    ap.add_argument("--quick", action="store_true", help="N = 1000, 2 seeds, packings 0.02 and 0.3")
    args = ap.parse_args(argv)
    if args.quick:
        args.n, args.seeds, args.packings = 1000, 2, [0.02, 0.3]
    d, sigma, m = 3, 1.0, 1.0
    print(f"3D, constant eps = {args.eps}, N = {args.n}, {args.seeds} seeds, {args.relax:g} elastic collisions per "
          f"particle first, then the window {args.skip:g} to {args.collisions:g} collisions per particle")
    print(f"{'packing':>8} {'box/L_c':>8} {'omega* EDMD':>16} {'omega* DSMC':>16} {'EDMD/DSMC':>16} "
          f"{'loss/coll/T EDMD':>19} {'DSMC':>19} {'wall EDMD, DSMC':>16}")
    with tempfile.TemporaryDirectory() as tmp:
        for eta in args.packings:
            dens = float(theory.number_density(eta, d, sigma))
            chi = float(theory.contact_value(eta, d))
            enskog = 4.0 * math.sqrt(math.pi) * chi * dens * sigma**2 / math.sqrt(m)
            box = (args.n * math.pi / 6.0 / eta) ** (1.0 / 3.0)
            l_c = float(theory.instability_length(args.eps, dens, d, sigma)) if args.eps < 1.0 else math.inf
            res = {}
            for method in ("edmd", "dsmc"):
                om, loss, wall = [], [], 0.0
                for seed in range(1, args.seeds + 1):
                    out = Path(tmp) / f"{method}_{eta}_{seed}.h5"
                    initial = ""
                    if args.relax > 0:
                        relaxed = Path(tmp) / "relaxed.h5"
                        text = CONFIG.format(n=args.n, eta=eta, seed=seed, eps=1.0, method=method, s=args.relax,
                                             out=relaxed, initial="")
                        run_config(parse_config(text, source=f"<{method} {eta} relax>"), overwrite=True)
                        initial = f'from = "{relaxed}"'
                    text = CONFIG.format(n=args.n, eta=eta, seed=seed, eps=args.eps, method=method,
                                         s=args.relax + args.collisions, out=out, initial=initial)
                    w = time.perf_counter()
                    run_config(parse_config(text, source=f"<{method} {eta}>"), overwrite=True)
                    wall += time.perf_counter() - w
                    o, lo = measure(out, args.n, args.relax + args.skip)
                    om.append(o / enskog)
                    loss.append(lo)
                    out.unlink()
                om, loss = np.array(om), np.array(loss)
                res[method] = (om.mean(), om.std(ddof=1) / math.sqrt(len(om)), loss.mean(),
                               loss.std(ddof=1) / math.sqrt(len(loss)), wall)
            e, s = res["edmd"], res["dsmc"]
            ratio = e[0] / s[0]
            ratio_err = ratio * math.hypot(e[1] / e[0], s[1] / s[0])
            print(f"{eta:8.3g} {box / l_c:8.3g} {e[0]:9.4f} +- {e[1]:.4f} {s[0]:9.4f} +- {s[1]:.4f} "
                  f"{ratio:9.4f} +- {ratio_err:.4f} {e[2]:8.5f} +- {e[3]:.1e} {s[2]:8.5f} +- {s[3]:.1e} "
                  f"{e[4]:7.1f}, {s[4]:5.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
