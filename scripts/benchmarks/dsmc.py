"""Benchmark of the DSMC against the event-driven engine: collisions per second, JIT, memory.

Both methods in one run, on the same gas (3D by default, constant eps = 0.9, Maxwellian
start). Every case runs in its own process (clean peak memory): initial state, warm-up,
then ``--repeats`` timed runs; the process reports the median rate over its runs, both
wall-clock and CPU time of the process (the CPU rate is less sensitive to a loaded
machine). The cases are run in ``--rounds`` alternated rounds (DSMC, engine, DSMC, ...)
and the table shows the median over rounds. Memory: bytes per particle of the DSMC's
state arrays (velocities in padded rows; radii and masses only for unlike particles; the
64 kB speed-class table is fixed), and the growth of the process's peak RSS during the
case divided by N (includes building the initial state).

The engine's rate depends on the packing fraction (dilute gases have more events per
collision), the DSMC's does not: the engine runs at the ``--packings`` given, the DSMC
at the first of them.

JIT: first compile of the DSMC kernels in a fresh process with the numba cache disabled
(``GRANULARGAS_NO_CACHE=1``), and the cached load in a fresh process, each with a tiny run.

    taskset -c 1 python scripts/benchmarks/dsmc.py            # N = 1e4, 1e5, 1e6; engine at packing 0.02 and 0.3
    taskset -c 1 python scripts/benchmarks/dsmc.py --quick    # N = 1e4, 1e5, 2 rounds
    python scripts/benchmarks/dsmc.py --sizes 1e6 --methods dsmc --dims 2 3
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

EPS = 0.9


def _peak_rss_bytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _timed(sim, per_run, repeats):
    wall, cpu = [], []
    for _ in range(repeats):
        c0 = sim.collisions
        w0, p0 = time.perf_counter(), time.process_time()
        sim.run(float("inf"), max_collisions=per_run)
        w1, p1 = time.perf_counter(), time.process_time()
        wall.append((sim.collisions - c0) / (w1 - w0))
        cpu.append((sim.collisions - c0) / (p1 - p0))
    return statistics.median(wall), statistics.median(cpu)


def run_case(method, n, dim, packing, repeats, seed=1):
    """One case in this process; returns a dict."""
    import numpy as np

    from granulargas.engine import CollisionRule

    rule = CollisionRule.constant(EPS)
    if method == "dsmc":
        from granulargas.dsmc import DSMC
        from granulargas.state import State

        DSMC(State(None, np.ones((4, dim)) * np.arange(4)[:, None], 0.5, 1.0, None), rule,
             packing_fraction=0.1).run(1.0)
        rss0 = _peak_rss_bytes()
        t0 = time.perf_counter()
        v = np.random.default_rng(seed).standard_normal((n, dim))
        sim = DSMC(State(None, v, 0.5, 1.0, None), rule, packing_fraction=packing, seed=seed)
        del v
        t_init = time.perf_counter() - t0
        sim.run(float("inf"), max_collisions=max(200_000, 2 * n))
        rate_wall, rate_cpu = _timed(sim, max(2_000_000, 2 * n), repeats)
        state = sim._rec.nbytes + (0 if sim._mono else sim._rad_k.nbytes + sim._mas_k.nbytes)
        extra = dict(acceptance=sim.acceptance, bytes_per_particle=state / n,
                     fixed_bytes=sim._hist.nbytes + sim._rng.nbytes + sim._ring.nbytes)
    else:
        from granulargas.engine import Simulation
        from granulargas.initial import random_state

        warm = random_state(64, 0.2, dim, seed=0)
        Simulation(warm, rule).run(0.1)
        rss0 = _peak_rss_bytes()
        t0 = time.perf_counter()
        st = random_state(n, packing, dim, seed=seed)
        t_init = time.perf_counter() - t0
        sim = Simulation(st, rule)
        del st
        sim.run(float("inf"), max_collisions=max(200_000, 2 * n))
        rate_wall, rate_cpu = _timed(sim, max(200_000, n), repeats)
        extra = dict(acceptance=float("nan"), bytes_per_particle=float("nan"), fixed_bytes=0)
    return dict(method=method, n=n, dim=dim, packing=packing, rate_wall=rate_wall, rate_cpu=rate_cpu,
                peak_rss_per_particle=(_peak_rss_bytes() - rss0) / n, init_seconds=t_init, **extra)


def jit_times(dim=3):
    """(first compile s, cached load s) of the DSMC, each in a fresh process."""
    code = ("import time; t=time.perf_counter(); import numpy as np; "
            "from granulargas.dsmc import DSMC; from granulargas.engine import CollisionRule; "
            "from granulargas.state import State; "
            f"DSMC(State(None, np.random.default_rng(0).standard_normal((64, {dim})), 0.5, 1.0, None), "
            "CollisionRule.constant(0.9), packing_fraction=0.1).run(1.0); "
            "print(time.perf_counter()-t)")
    env = dict(os.environ, GRANULARGAS_NO_CACHE="1")
    first = float(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                                 check=True).stdout.strip())
    subprocess.run([sys.executable, "-c", code], capture_output=True, check=True)  # fill the cache
    cached = [float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                   check=True).stdout.strip()) for _ in range(3)]
    return first, statistics.median(cached)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="N = 1e4, 1e5; 2 rounds of 3 repeats")
    ap.add_argument("--sizes", type=float, nargs="+", default=None)
    ap.add_argument("--dims", type=int, nargs="+", choices=(2, 3), default=[3])
    ap.add_argument("--packings", type=float, nargs="+", default=[0.02, 0.3],
                    help="engine packings; the DSMC runs at the first")
    ap.add_argument("--methods", nargs="+", choices=("dsmc", "engine"), default=["dsmc", "engine"])
    ap.add_argument("--rounds", type=int, default=None)
    ap.add_argument("--repeats", type=int, default=None)
    ap.add_argument("--no-jit", action="store_true")
    ap.add_argument("--json", default=None)
    ap.add_argument("--case", nargs=4, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.case:
        method, n, dim, eta = args.case
        print(json.dumps(run_case(method, int(float(n)), int(dim), float(eta), args.repeats or 3)))
        return 0
    for eta in args.packings:
        if not 0 < eta < 0.5:
            ap.error(f"--packings {eta}: allowed range is (0, 0.5)")
    sizes = args.sizes or ([1e4, 1e5] if args.quick else [1e4, 1e5, 1e6])
    rounds = args.rounds or (2 if args.quick else 3)
    repeats = args.repeats or 3
    cases = []
    for n in sizes:
        for dim in args.dims:
            if "dsmc" in args.methods:
                cases.append(("dsmc", int(n), dim, args.packings[0]))
            if "engine" in args.methods:
                cases.extend(("engine", int(n), dim, eta) for eta in args.packings)
    print(f"# DSMC and engine benchmark, {time.strftime('%Y-%m-%d %H:%M')}, {os.cpu_count()} CPUs, "
          f"load average {os.getloadavg()[0]:.2f} at start, affinity {sorted(os.sched_getaffinity(0))}")
    print(f"# 3D/2D gas, constant eps = {EPS}; {rounds} alternated rounds x {repeats} timed runs per process")
    if not args.no_jit:
        first, cached = jit_times(args.dims[0])
        print(f"# DSMC JIT: first compile + tiny run {first:.1f} s (no cache); cached load + tiny run "
              f"{cached:.2f} s")
    results = {c: [] for c in cases}
    for r in range(rounds):
        for case in cases:
            method, n, dim, eta = case
            out = subprocess.run([sys.executable, os.path.abspath(__file__), "--case", method, str(n), str(dim),
                                  str(eta), "--repeats", str(repeats)], capture_output=True, text=True)
            if out.returncode != 0:
                print(f"# {case}: FAILED: {out.stderr.strip().splitlines()[-1]}", flush=True)
                continue
            results[case].append(json.loads(out.stdout.strip().splitlines()[-1]))
        print(f"# round {r + 1}/{rounds} done", flush=True)
    header = (f"{'method':>7} {'N':>8} {'d':>2} {'eta':>5} {'Mcoll/s wall':>12} {'Mcoll/s cpu':>11} "
              f"{'accept':>6} {'B/particle':>10} {'peakRSS B/p':>11} {'init s':>6}")
    print(header)
    summary = []
    for case, rs in results.items():
        if not rs:
            continue
        med = {k: statistics.median(x[k] for x in rs) for k in ("rate_wall", "rate_cpu", "peak_rss_per_particle",
                                                                  "init_seconds")}
        r0 = rs[0]
        summary.append(dict(r0, **med, rounds=len(rs), rate_cpu_rounds=[x["rate_cpu"] for x in rs]))
        print(f"{r0['method']:>7} {r0['n']:>8} {r0['dim']:>2} {r0['packing']:>5} {med['rate_wall'] / 1e6:>12.3f} "
              f"{med['rate_cpu'] / 1e6:>11.3f} {r0['acceptance']:>6.3f} {r0['bytes_per_particle']:>10.1f} "
              f"{med['peak_rss_per_particle']:>11.0f} {med['init_seconds']:>6.1f}", flush=True)
    dsmc = {(s["n"], s["dim"]): s for s in summary if s["method"] == "dsmc"}
    for s in summary:
        if s["method"] == "engine" and (s["n"], s["dim"]) in dsmc:
            d = dsmc[(s["n"], s["dim"])]
            print(f"# N = {s['n']}, {s['dim']}D: DSMC / engine at packing {s['packing']}: "
                  f"x{d['rate_cpu'] / s['rate_cpu']:.1f} (CPU time), x{d['rate_wall'] / s['rate_wall']:.1f} (wall)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
