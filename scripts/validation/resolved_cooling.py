"""A dilute soft cooling gas with instantaneous and with resolved collisions (no DEM).

Runs the same config (a rubber-like material, t_c / t_free ~ 0.01-0.1 set by the
speed unit) with ``[collision] duration = "instantaneous"`` and ``"resolved"`` and
prints, at a few times, T(t), the collision count, the pressure and, for the
resolved run, the share of collisions that met a pair still in contact. The two
differ where the contact's duration matters: the outgoing direction turns, the
pair leaves the contact later and elsewhere (docs/engine.md, "Collisions that take
time"); comparing both with LAMMPS is the validation (docs/validation.md).

    python scripts/validation/resolved_cooling.py [--particles 2000] [--packing 0.05] [--speed-unit 0.5]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from granulargas.io.config import load_config
from granulargas.io.h5md import read_observables
from granulargas.run.runner import run_config
from granulargas.run.validity import contact_time_ratio

CONFIG = """
[system]
dimension = 3
particles = {n}
packing_fraction = {packing}
seed = {seed}

[collision]
model = "viscoelastic"
duration = "{duration}"

[collision.material]
young_modulus = 1e6
poisson_ratio = 0.3
dissipation_time = 1e-5
diameter = 0.01
density = 1000
speed_unit = {speed}

[run]
end_time = {end}

[output]
file = "{out}"
observables_interval = {dt}
snapshot_interval = {end}
"""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--particles", type=int, default=2000)
    ap.add_argument("--packing", type=float, default=0.05)
    ap.add_argument("--speed-unit", type=float, default=0.5, help="m/s; smaller: longer contacts")
    ap.add_argument("--end", type=float, default=40.0)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for duration in ("instantaneous", "resolved"):
            path = Path(tmp) / f"{duration}.toml"
            path.write_text(CONFIG.format(n=args.particles, packing=args.packing, seed=args.seed,
                                          duration=duration, speed=args.speed_unit, end=args.end,
                                          dt=args.end / 8, out=Path(tmp) / f"{duration}.h5"))
            cfg = load_config(path)
            if duration == "instantaneous":
                print(f"t_c / t_free at T0 = {contact_time_ratio(cfg):.3g}")
            w = time.perf_counter()
            summary = run_config(cfg)
            wall = time.perf_counter() - w
            obs = read_observables(summary.output)
            results[duration] = obs
            extra = ""
            if summary.three_body_contacts is not None:
                extra = (f", three-body {summary.three_body_contacts} "
                         f"({100 * summary.three_body_contacts / summary.collisions:.3g} %)")
            print(f"{duration:14s} {summary.collisions} collisions in {wall:.3g} s{extra}")
    a, b = results["instantaneous"], results["resolved"]
    print(f"{'t':>8s} {'T inst':>10s} {'T res':>10s} {'ratio':>8s} {'coll inst':>10s} {'coll res':>10s} "
          f"{'P inst':>10s} {'P res':>10s}")
    for k in range(len(a["temperature"][1])):
        t = a["temperature"][1][k]
        ta, tb = a["temperature"][2][k], b["temperature"][2][k]
        print(f"{t:8.3g} {ta:10.5g} {tb:10.5g} {tb / ta:8.4f} {a['collisions'][2][k]:10d} "
              f"{b['collisions'][2][k]:10d} {a['pressure'][2][k]:10.4g} {b['pressure'][2][k]:10.4g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
