"""What walls and driving cost: the same gas periodic, between walls, and driven, alternated.

Each round runs, for each size, the three scenes of ``scripts/benchmarks/run.py --case``
in fresh processes of this source tree (pinned to one core when ``taskset`` exists): the
periodic gas, the same particles with flat walls on the last axis (``--scene
walls``), and the periodic gas with white-noise driving (``--scene driven:H``,
kicks every 0.02 / zeta). It prints nanoseconds per pair collision (median over the
rounds, with the range of the per-round ratio to the periodic gas), events per
collision, and wall collisions per pair collision.

Usage::

    python scripts/benchmarks/run.py --sizes 1e4 1e5 --rounds 3
    python scripts/benchmarks/run.py --sizes 1e5 --rule 0.9 --heating-rate 0.1
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def case(n, packing, dim, rule, scene):
    cmd = [sys.executable, os.path.join(HERE, "scripts/benchmarks/run.py"), "--case", str(n), str(packing), str(dim),
           rule, "--scene", scene]
    if shutil.which("taskset"):
        cmd = ["taskset", "-c", str(os.cpu_count() - 1)] + cmd
    env = dict(os.environ, PYTHONPATH=os.path.dirname(HERE))  # this source tree
    out = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if out.returncode != 0:
        sys.exit(f"scripts/benchmarks/run.py: {scene} N = {n}: {out.stderr.strip().splitlines()[-1:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=float, nargs="+", default=[1e4, 1e5])
    p.add_argument("--packing", type=float, default=0.3)
    p.add_argument("--dim", type=int, default=3, choices=[2, 3])
    p.add_argument("--rule", default="0.9", help="elastic, viscoelastic or a constant eps (default 0.9)")
    p.add_argument("--heating-rate", type=float, default=0.1)
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args(argv)
    if args.rounds < 1 or any(n < 1000 for n in args.sizes) or not args.heating_rate > 0:
        p.error("--rounds >= 1, --sizes >= 1000, --heating-rate > 0")
    scenes = ["periodic", "walls", f"driven:{args.heating_rate:g}"]
    if args.rule == "elastic":
        scenes = scenes[:2]  # an elastic gas has no driven steady state
    res = {(s, n): [] for s in scenes for n in args.sizes}
    for r in range(args.rounds):
        for n in args.sizes:
            for s in scenes:
                x = case(int(n), args.packing, args.dim, args.rule, s)
                res[s, n].append(x)
                print(f"round {r + 1} N = {int(n):>8d} {s:>12}: {1e9 / x['rate_wall']:8.0f} ns/collision, "
                      f"{x['events_per_collision']:.3f} events/collision", flush=True)
    print(f"\n{args.dim}D, packing {args.packing}, rule {args.rule}; medians over {args.rounds} rounds")
    for n in args.sizes:
        base = res["periodic", n]
        for s in scenes:
            ns = statistics.median(1e9 / x["rate_wall"] for x in res[s, n])
            ratio = [b["rate_wall"] / x["rate_wall"] for b, x in zip(base, res[s, n])]
            ev = statistics.median(x["events_per_collision"] for x in res[s, n])
            wc = statistics.median(x["wall_collisions_per_collision"] for x in res[s, n])
            cpu = statistics.median(1e9 / x["rate_cpu"] for x in res[s, n])
            print(f"N = {int(n):>8d} {s:>12}: {ns:8.0f} ns/collision ({cpu:.0f} CPU), x{statistics.median(ratio):.3f} "
                  f"(range {min(ratio):.3f}..{max(ratio):.3f}) of periodic; {ev:.3f} events/collision, "
                  f"{wc:.4f} wall collisions per collision")


if __name__ == "__main__":
    main()
