"""The benchmark runner: every speed figure of the performance page, by named sets of cases.

Each case runs in its own process (clean peak memory): initial state, warm-up to a steady
state (5 collisions per particle: aged neighbour lists, memory order drifted from the initial
sort), then ``--repeats`` timed runs of ``max(2e5, N)`` collisions; printed are the median
rates in collisions per second of CPU time of the process (less sensitive to a loaded machine)
and of the wall clock, the events per collision, the engine state in bytes per particle
(``sum of array sizes / N``) and the growth of the process's peak RSS per particle (including
the initial state).

Sets of cases (``--list`` prints them):

* ``table``: the engine at N ~ 1e4, 1e5, 1e6: 3D elastic at packing 0.3 and 0.5 (neighbour
  lists) and at 0.05 and 0.1 (cell crossings), 2D at 0.5, 3D viscoelastic at 0.3;
* ``quick``: 3D elastic at packing 0.3 (N ~ 1e4, 1e5) and 0.05 (N ~ 1e4);
* ``scenes``: one gas (3D, packing 0.3, constant eps = 0.9) periodic, between walls on the
  last axis, and driven by white noise (H = 0.1, kicks every 0.02 / zeta);
* ``large``: 1e7 spheres at packing 0.3 (about 5 GB and 10 minutes on one core);
* ``dsmc``: the DSMC against the engine on the same gas (``scripts/benchmarks/dsmc.py``);
* ``compile``: the first JIT compile of each neighbour mode (CPU time of a fresh process with
  an empty numba cache) and the cached load;
* ``initial``: the initial placement (``random_state``) of large dense states;
* ``all``: every set above.

``--record`` writes the figures into ``docs/performance/results.json`` (replacing the
records of the same cases) and rewrites the performance page from it
(``scripts/benchmarks/performance_page.py``). The side by side with Smallenburg's C code
has its own harness (``scripts/benchmarks/neighbours.py --c-single/--c-cell``), as do the
first-run start-up (``scripts/benchmarks/startup.py``) and the comparisons with LAMMPS
(``scripts/lammps/``).

Usage::

    python scripts/benchmarks/run.py quick                    # a few minutes
    python scripts/benchmarks/run.py all --record             # hours: every record of the page
    python scripts/benchmarks/run.py table scenes --only "N~1e4" --record
    python scripts/benchmarks/run.py --case 10976 0.3 3 elastic [--neighbours cells] [--scene walls]
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
SIZES_3D = (10976, 108000, 1000188)  # 4 n^3: the sizes the C code runs (FCC start)
SIZES_2D = (10000, 100000, 1000000)
THREADS = int(os.environ.get("NUMBA_NUM_THREADS", os.cpu_count()))  # the initial placement's threads


def magnitude(n):
    """``"1e4"`` for N of about 10^4 (the order of magnitude that names a case)."""
    return f"1e{len(str(int(n))) - 1}"


def engine_case(n, packing, dim, rule="elastic", neighbours="lists", scene="periodic", repeats=5, warmup=None):
    """A case of the engine: its id in the results file and its parameters."""
    cid = f"{dim}D {scene} {rule} {neighbours} packing {packing:g} N~{magnitude(n)}"
    return dict(kind="engine", id=cid, n=int(n), packing=packing, dim=dim, rule=rule, neighbours=neighbours,
                scene=scene, repeats=repeats, warmup=warmup)


def case_sets():
    """Named sets of cases: a list of case dicts per set name."""
    table = []
    for k in range(3):
        n3, n2 = SIZES_3D[k], SIZES_2D[k]
        table += [engine_case(n3, 0.3, 3), engine_case(n3, 0.5, 3), engine_case(n3, 0.05, 3, neighbours="cells"),
                  engine_case(n3, 0.1, 3, neighbours="cells"), engine_case(n2, 0.5, 2),
                  engine_case(n3, 0.3, 3, rule="viscoelastic")]
    scenes = []
    for n in SIZES_3D[:2]:
        scenes += [engine_case(n, 0.3, 3, rule="0.9", scene=s) for s in ("periodic", "walls", "driven:0.1")]
    dsmc = [dict(kind="dsmc", id=f"{d}D N~{magnitude(n)}", n=n, dim=d, packings=(0.02, 0.3))
            for d in (3,) for n in (10**4, 10**5, 10**6)]
    sets = {
        "table": table,
        "quick": [engine_case(SIZES_3D[0], 0.3, 3, repeats=3), engine_case(SIZES_3D[1], 0.3, 3, repeats=3),
                  engine_case(SIZES_3D[0], 0.05, 3, neighbours="cells", repeats=3)],
        "scenes": scenes,
        "large": [engine_case(10**7, 0.3, 3, repeats=1, warmup=5 * 10**6)],
        "dsmc": dsmc,
        "compile": [dict(kind="compile", id=f"3D {mode}", neighbours=mode) for mode in ("lists", "cells")],
        "initial": [dict(kind="initial", id=f"{d}D packing {eta:g} N~{magnitude(n)} threads {THREADS}", n=n, packing=eta,
                         dim=d)
                    for n, eta, d in ((10**6, 0.5, 3), (10**7, 0.3, 3), (10**6, 0.7, 2))],
    }
    sets["all"] = [c for name in ("table", "scenes", "large", "dsmc", "compile", "initial") for c in sets[name]]
    return sets


def _peak_rss_bytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def run_case(n, packing, dim, rule_name, repeats, seed=1, scene="periodic", neighbours="lists",
             warmup=None):
    """One benchmark case in this process; returns a dict.

    ``scene``: "periodic" (the standard), "walls" (flat walls on the last axis, the
    same particles), or "driven:H" (white-noise driving at heating rate H, kicks every
    0.02 / zeta of the steady state: :func:`granulargas.theory.driving_interval`).
    ``neighbours``: the engine's neighbour search ("lists", "cells"). ``warmup``: collisions
    before the timed runs (default: 5 per particle, at least 2e5)."""
    import numpy as np

    from granulargas.engine import CollisionRule, Simulation
    from granulargas.initial import random_state

    # compile (from cache) before measuring memory
    warm = random_state(64, 0.2, dim, seed=0)
    Simulation(warm, CollisionRule.elastic(), neighbours=neighbours).run(0.1)
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
    sim = Simulation(st, rule, neighbours=neighbours, **({"driving": driving} if driving else {}))
    del st
    t0 = time.perf_counter()
    # build + warm-up to a steady state: 5 collisions per particle, so that the timed runs
    # see aged neighbour lists and a memory order that has drifted from the initial sort
    sim.run(np.inf, max_collisions=max(200_000, 5 * n // 2) if warmup is None else warmup)
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
        init_seconds=t_init, build_seconds=t_build, scene=scene, neighbours=sim.neighbours,
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


def compile_seconds(neighbours="lists"):
    """(first compile, cached load) in CPU seconds of a 64-sphere run, each in a fresh process
    (``scripts/benchmarks/startup.py``'s measurement: an empty numba cache, then the filled one)."""
    import tempfile

    import startup

    root = os.path.dirname(os.path.dirname(HERE))
    with tempfile.TemporaryDirectory() as cache:
        first, _ = startup.engine_compile(root, neighbours, cache)
        cached = [startup.engine_compile(root, neighbours, cache)[0] for _ in range(3)]
    return first, statistics.median(cached)


def initial_seconds(n, packing, dim, seed=1):
    """Wall and CPU seconds of one ``random_state`` placement (kernels compiled beforehand)."""
    from granulargas.initial import random_state

    random_state(500, packing, dim, seed=0)
    w0, p0 = time.perf_counter(), time.process_time()
    random_state(n, packing, dim, seed=seed)
    return time.perf_counter() - w0, time.process_time() - p0


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


def _child(args):
    """Run ``args`` (a list) as a fresh Python process; the last line of its output as JSON."""
    out = subprocess.run([sys.executable, *args], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError((out.stderr.strip().splitlines() or ["no output"])[-1])
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure(case):
    """Run one case (in fresh processes); the record of the results file (without its stamp)."""
    kind = case["kind"]
    if kind == "engine":
        args = [os.path.abspath(__file__), "--case", str(case["n"]), str(case["packing"]), str(case["dim"]),
                case["rule"], "--neighbours", case["neighbours"], "--scene", case["scene"],
                "--repeats", str(case["repeats"])]
        if case["warmup"] is not None:
            args += ["--warmup", str(case["warmup"])]
        r = _child(args)
        return dict(table="engine", id=case["id"], n=r["n"], dim=r["dim"], packing=r["packing"], rule=r["rule"],
                    neighbours=r["neighbours"], scene=r["scene"], rate_cpu=round(r["rate_cpu"] / 1e6, 4),
                    rate_wall=round(r["rate_wall"] / 1e6, 4), events_per_collision=round(r["events_per_collision"], 2),
                    bytes_per_particle=round(r["bytes_per_particle"]),
                    peak_rss_per_particle=round(r["peak_rss_per_particle"]), repeats=case["repeats"])
    if kind == "dsmc":
        script = os.path.join(HERE, "dsmc.py")
        d = _child([script, "--case", "dsmc", str(case["n"]), str(case["dim"]), str(case["packings"][0])])
        rec = dict(table="dsmc", id=case["id"], n=case["n"], dim=case["dim"], rate_cpu=round(d["rate_cpu"] / 1e6, 3),
                   acceptance=round(d["acceptance"], 3), bytes_per_particle=round(d["bytes_per_particle"]))
        for eta in case["packings"]:
            e = _child([script, "--case", "engine", str(case["n"]), str(case["dim"]), str(eta)])
            rec[f"engine_rate_cpu_{eta:g}"] = round(e["rate_cpu"] / 1e6, 4)
        return rec
    if kind == "compile":
        first, cached = compile_seconds(case["neighbours"])
        return dict(table="compile", id=case["id"], first_seconds=round(first, 1), cached_seconds=round(cached, 2))
    if kind == "initial":
        w, c = _child([os.path.abspath(__file__), "--initial", str(case["n"]), str(case["packing"]), str(case["dim"])])
        return dict(table="initial", id=case["id"], n=case["n"], packing=case["packing"], dim=case["dim"],
                    wall_seconds=round(w, 1), cpu_seconds=round(c, 1),
                    threads=THREADS)
    raise ValueError(kind)


def _show(rec):
    skip = {"table", "id"}
    return f"{rec['table']:>8} | {rec['id']:<44} | " + ", ".join(f"{k} {v}" for k, v in rec.items() if k not in skip
                                                               and k not in ("n", "dim", "packing", "rule",
                                                                             "neighbours", "scene"))


def main(argv=None):
    sets = case_sets()
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("sets", nargs="*", help=f"sets of cases: {', '.join(sets)}")
    p.add_argument("--only", default=None, help="only the cases whose id contains this text")
    p.add_argument("--list", action="store_true", help="print the cases of the sets and exit")
    p.add_argument("--record", action="store_true",
                   help="write the figures into docs/performance/results.json and rewrite the performance page")
    p.add_argument("--case", nargs=4, default=None, help=argparse.SUPPRESS)
    p.add_argument("--initial", nargs=3, default=None, help=argparse.SUPPRESS)
    p.add_argument("--scene", default="periodic", help=argparse.SUPPRESS)
    p.add_argument("--neighbours", default="lists", choices=["lists", "cells"], help=argparse.SUPPRESS)
    p.add_argument("--repeats", type=int, default=5, help=argparse.SUPPRESS)
    p.add_argument("--warmup", type=int, default=None, help=argparse.SUPPRESS)
    args = p.parse_args(argv)

    if args.case:  # one engine case in this process (the runner's child; scripts/ab/alternated.py)
        n, eta, dim, rule = args.case
        if not _rule_valid(rule):
            p.error(f"rule {rule}: allowed are elastic, viscoelastic, viscoelastic:DAMPING (DAMPING > 0) "
                    f"and a constant eps in (0, 1]")
        print(json.dumps(run_case(int(float(n)), float(eta), int(dim), rule, args.repeats, scene=args.scene,
                                  neighbours=args.neighbours, warmup=args.warmup)))
        return 0
    if args.initial:
        n, eta, dim = args.initial
        print(json.dumps(initial_seconds(int(float(n)), float(eta), int(dim))))
        return 0
    unknown = [s for s in args.sets if s not in sets]
    if not args.sets or unknown:
        p.error(f"sets: {' '.join(unknown) or '(none given)'}: allowed are {', '.join(sets)}")
    cases, seen = [], set()
    for name in args.sets:
        for c in sets[name]:
            if (c["kind"], c["id"]) not in seen and (args.only is None or args.only in c["id"]):
                seen.add((c["kind"], c["id"]))
                cases.append(c)
    if args.list:
        for c in cases:
            print(f"{c['kind']:>8} | {c['id']}")
        return 0
    load = os.getloadavg()[0]
    commit = _commit()
    print(f"# granulargas benchmark, {time.strftime('%Y-%m-%d %H:%M')}, {os.cpu_count()} CPUs, "
          f"load average {load:.2f} at start; rates in million collisions per second (CPU time)", flush=True)
    records = []
    for c in cases:
        try:
            rec = measure(c)
        except RuntimeError as err:
            print(f"{c['kind']:>8} | {c['id']:<44} | FAILED: {err}", flush=True)
            continue
        records.append(rec)
        print(_show(rec), flush=True)
    if args.record and records:
        import results

        command = "python scripts/benchmarks/run.py " + " ".join(args.sets) + (
            f" --only {args.only!r}" if args.only else "")
        results.record_and_render(records, command, load_average=max(load, os.getloadavg()[0]), commit=commit)
    return 0


def _commit():
    """The source tree's commit when the measurement starts (``scripts/benchmarks/results.py``)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import results

    return results.this_commit()


if __name__ == "__main__":
    sys.exit(main())
