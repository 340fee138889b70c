"""Benchmark of the event-driven engine: collisions per second, JIT time, memory.

Each case runs in its own process (clean peak memory): random initial state,
warm-up to a steady state (5 collisions per particle), then ``--repeats`` timed runs of about
``max(2e5, N)`` collisions each; the median rate is printed, with the wall-clock
rate and the CPU-time rate of the process (the CPU rate is less sensitive to a
loaded machine). Memory: bytes per particle of the engine's internal state
(``sum of array sizes / N``) and the growth of the process's peak RSS during
the case divided by N (includes the initial-state construction).

JIT: the first compile is measured in a fresh process with the numba cache
disabled (``GRANULARGAS_NO_CACHE=1``); the cached load in a fresh process with
the cache on (import plus a first tiny run).

Usage::

    python scripts/benchmarks/run.py            # full table (N = 1e4, 1e5, 1e6; 3D eta 0.1/0.3/0.5, 2D, viscoelastic)
    python scripts/benchmarks/run.py --quick    # N = 1e4, 1e5 at eta = 0.3 only, fewer repeats
    python scripts/benchmarks/run.py --sizes 1e5 --packings 0.3 --dims 3 --rules elastic
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

HERE = os.path.dirname(os.path.abspath(__file__))


def _peak_rss_bytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def run_case(n, packing, dim, rule_name, repeats, seed=1, scene="periodic"):
    """One benchmark case in this process; returns a dict.

    ``scene``: "periodic" (the standard), "walls" (flat walls on the last axis, the
    same particles), or "driven:H" (white-noise driving at heating rate H, kicks every
    0.02 / zeta of the steady state: :func:`granulargas.theory.driving_interval`)."""
    import numpy as np

    from granulargas.engine import CollisionRule, Simulation
    from granulargas.initial import random_state

    # compile (from cache) before measuring memory
    warm = random_state(64, 0.2, dim, seed=0)
    Simulation(warm, CollisionRule.elastic()).run(0.1)
    rss0 = _peak_rss_bytes()
    t0 = time.perf_counter()
    walls = {"boundary": ("periodic",) * (dim - 1) + ("wall",)} if scene == "walls" else {}
    st = random_state(n, packing, dim, seed=seed, **walls)
    t_init = time.perf_counter() - t0
    if rule_name == "elastic":
        rule = CollisionRule.elastic()
    elif rule_name.partition(":")[0] == "viscoelastic":
        from granulargas.contact import prefactor_from_damping, restitution_table

        # "viscoelastic" = damping 0.1; "viscoelastic:1e-4" a nearly elastic gas, whose
        # event sequence matches the elastic one, so that only the rule's own cost differs
        damping = float(rule_name.partition(":")[2] or 0.1)
        k = prefactor_from_damping(damping)
        # largest impact speed: twice the fastest particle (with margin); reference pair
        gmax = 2.5 * float(np.max(np.linalg.norm(st.velocities, axis=1)))
        beta_max = min(40.0, 1.5 * k * (0.25 * gmax / 0.25) ** 0.2 + 0.1)
        rule = CollisionRule.viscoelastic(prefactor=k, table=restitution_table(beta_max))
    else:
        rule = CollisionRule.constant(float(rule_name))
    driving = None
    if scene.startswith("driven:"):
        from granulargas import theory
        from granulargas.engine import WhiteNoise

        h = float(scene.partition(":")[2])
        eps = rule.restitution if rule.kind == "constant" else 0.9
        nd = theory.number_density(packing, dim)
        t_ss = float(theory.driven_temperature(h, eps, nd, dim))
        zeta = float(theory.enskog_cooling_rate(eps, nd, t_ss, dim, a2=theory.driven_sonine_a2(eps, dim)))
        driving = WhiteNoise(h, theory.driving_interval(zeta), seed=seed)
    sim = Simulation(st, rule, **({"driving": driving} if driving else {}))
    t0 = time.perf_counter()
    # build + warm-up to a steady state: 5 collisions per particle, so that the timed runs
    # see aged neighbour lists and a memory order that has drifted from the initial sort
    sim.run(np.inf, max_collisions=max(200_000, 5 * n // 2))
    t_build = time.perf_counter() - t0
    per_run = max(200_000, n)
    wall, cpu = [], []
    for _ in range(repeats):
        c0 = sim.collisions
        w0, p0 = time.perf_counter(), time.process_time()
        sim.run(np.inf, max_collisions=per_run)
        w1, p1 = time.perf_counter(), time.process_time()
        wall.append((sim.collisions - c0) / (w1 - w0))
        cpu.append((sim.collisions - c0) / (p1 - p0))
    state_bytes, expiries, stale = _internals(sim)
    return dict(
        n=n, packing=packing, dim=dim, rule=rule_name,
        rate_wall=statistics.median(wall), rate_cpu=statistics.median(cpu),
        rate_wall_all=wall,
        bytes_per_particle=state_bytes / n,
        peak_rss_per_particle=(_peak_rss_bytes() - rss0) / n,
        events_per_collision=sim.events / max(1, sim.collisions),
        expiries_per_collision=expiries / max(1, sim.collisions),
        stale_per_collision=stale / max(1, sim.collisions),
        init_seconds=t_init, build_seconds=t_build, list_width=sim._nb_width, scene=scene,
        wall_collisions_per_collision=getattr(sim, "wall_collisions", 0) / max(1, sim.collisions),
    )


def _internals(sim):
    """(bytes of the engine state, list expiries, stale events) of the current build.

    Reads the named records of ``granulargas.engine._state``; falls back to the
    earlier layout (a dict of arrays with index-coded counters) so that
    ``scripts/ab/alternated.py`` can run this script against an older source tree.
    """
    engine = getattr(sim, "_engine", None)
    if engine is not None:
        from granulargas.engine._state import nbytes

        c = engine.counters[0]
        return nbytes(engine), float(c["expiries"]), float(c["stale"])
    s = sim._s
    return (sum(a.nbytes for a in s.values() if hasattr(a, "nbytes")), float(s["iscal"][4]),
            float(s["iscal"][5]))


def jit_times():
    """(first compile s, cached load s), each in a fresh process."""
    code = ("import time; t=time.perf_counter(); "
            "from granulargas.engine import Simulation, CollisionRule; "
            "from granulargas.initial import random_state; "
            "st=random_state(64, 0.2, 3, seed=0); "
            "Simulation(st, CollisionRule.elastic()).run(0.5); "
            "print(time.perf_counter()-t)")
    env = dict(os.environ, GRANULARGAS_NO_CACHE="1")
    first = float(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                 text=True, check=True).stdout.strip())
    subprocess.run([sys.executable, "-c", code], capture_output=True, check=True)  # fill cache
    cached = [float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                   check=True).stdout.strip()) for _ in range(3)]
    return first, statistics.median(cached)


def _rule_valid(name):
    """Whether ``name`` is a rule that :func:`run_case` understands."""
    if name in ("elastic", "viscoelastic"):
        return True
    head, _, arg = name.partition(":")
    try:
        value = float(arg if head == "viscoelastic" else name)
    except ValueError:
        return False
    return value > 0 if head == "viscoelastic" else 0 < value <= 1


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="N = 1e4, 1e5 at packing 0.3 (3D elastic, "
                   "2D, viscoelastic), 3 repeats")
    p.add_argument("--sizes", type=float, nargs="+", default=None)
    p.add_argument("--packings", type=float, nargs="+", default=None)
    p.add_argument("--dims", type=int, nargs="+", default=None)
    p.add_argument("--rules", nargs="+", default=None,
                   help="elastic, viscoelastic (damping 0.1), viscoelastic:DAMPING or a constant eps")
    p.add_argument("--repeats", type=int, default=None)
    p.add_argument("--no-jit", action="store_true", help="skip the JIT timing")
    p.add_argument("--json", default=None, help="also write the results to this JSON file")
    p.add_argument("--case", nargs=4, default=None, help=argparse.SUPPRESS)
    p.add_argument("--scene", default="periodic", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    for rule in args.rules or []:
        if not _rule_valid(rule):
            p.error(f"--rules {rule}: allowed are elastic, viscoelastic, viscoelastic:DAMPING "
                    f"(DAMPING > 0) and a constant eps in (0, 1]")

    if args.case:
        n, eta, dim, rule = args.case
        print(json.dumps(run_case(int(float(n)), float(eta), int(dim), rule, args.repeats or 5,
                                  scene=args.scene)))
        return 0

    if args.quick:
        sizes, packings = [1e4, 1e5], [0.3]
        repeats = args.repeats or 3
    else:
        sizes, packings = [1e4, 1e5, 1e6], [0.1, 0.3, 0.5]
        repeats = args.repeats or 5
    sizes = args.sizes or sizes
    packings = args.packings or packings
    cases = []
    for n in sizes:
        for dim in (args.dims or [3]):
            for eta in packings:
                for rule in (args.rules or ["elastic"]):
                    cases.append((n, eta if dim == 3 else min(0.7, eta * 5 / 3), dim, rule))
    if args.dims is None and args.rules is None:  # the standard extras: 2D and viscoelastic
        for n in sizes:
            cases.append((n, 0.5, 2, "elastic"))
            cases.append((n, 0.3, 3, "viscoelastic"))

    print(f"# granulargas engine benchmark, {time.strftime('%Y-%m-%d %H:%M')}, "
          f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f} at start")
    if not args.no_jit:
        first, cached = jit_times()
        print(f"# JIT: first compile + tiny run {first:.1f} s (no cache); cached load + tiny run {cached:.2f} s")
    print("# rate = median pair collisions per second over repeats (wall clock; CPU time of the process)")
    header = (f"{'N':>9} {'d':>2} {'eta':>5} {'rule':>12} {'Mcoll/s wall':>13} {'Mcoll/s cpu':>12} "
              f"{'B/particle':>10} {'peakRSS B/p':>11} {'ev/coll':>8} {'init s':>7}")
    print(header)
    results = []
    for n, eta, dim, rule in cases:
        out = subprocess.run([sys.executable, os.path.abspath(__file__), "--case", str(int(n)), str(eta),
                              str(dim), rule, "--repeats", str(repeats)],
                             capture_output=True, text=True)
        if out.returncode != 0:
            print(f"{int(n):>9} {dim:>2} {eta:>5} {rule:>12}  FAILED: {out.stderr.strip().splitlines()[-1]}")
            continue
        r = json.loads(out.stdout.strip().splitlines()[-1])
        results.append(r)
        print(f"{r['n']:>9} {r['dim']:>2} {r['packing']:>5} {r['rule']:>12} {r['rate_wall'] / 1e6:>13.3f} "
              f"{r['rate_cpu'] / 1e6:>12.3f} {r['bytes_per_particle']:>10.0f} "
              f"{r['peak_rss_per_particle']:>11.0f} {r['events_per_collision']:>8.2f} "
              f"{r['init_seconds']:>7.1f}", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
