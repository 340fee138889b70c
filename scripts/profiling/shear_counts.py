"""Why a sheared gas costs more per collision: event counts, a shear-rate ablation, and
instruction and cache-miss counts under cachegrind.

The gases are those of ``scripts/benchmarks/shear.py`` (3D, constant eps = 0.8, packing
``--packing``): ``periodic`` (a periodic box, the stress sums on), ``sheared`` (Lees-Edwards
at the steady rate a of the packing, whose Grad temperature is 1) and ``tiny`` (the
Lees-Edwards code at the rate 1e-6 a: the same boundaries, rows, images and stored y shift,
but a flow too slow to move anything: the lists' sliding lifetime and the slides of the cell
mode never come, and the memory order ages as in the periodic box).

``events``: the three gases in one process, each warmed up by ``--warmup`` collisions per
particle, then ``--repeats`` alternated rounds of ``--per-run`` collisions per particle. It
prints the median CPU time per collision of each, the median over rounds of the ratios
(sheared / periodic, tiny / periodic, sheared / tiny) and the events per collision by kind
from the engine's own counters: ``expiry`` (list expiries; the list mode), ``crossing`` (cell
crossings; the cell mode), ``stale`` (invalidated events popped), ``wall``, and the mean list
length (list mode) or the slides of the cell mode's sliding rows (global events) with the
particle scans they make (a slide scans every particle's new column). ``--margin`` sets the
lists' sliding margin (in shells) before the gases are built. Read: tiny / periodic is what
the sheared code costs by itself; sheared / tiny is what the flow adds (more events per
collision, a memory order that the sliding rows scatter).

``cachegrind``: for each size, mode and gas, a native process builds the gas and warms it up
(``--warmup`` collisions per particle) and saves its state with its memory order (the
engine's slot of each particle); then ``valgrind --tool=cachegrind`` runs two processes that
rebuild that state in the same memory order (every kernel loaded from the numba cache) and run
``--lengths`` K1 and K2 collisions per particle. The difference of the two runs' totals over
the difference of their collisions is the count per collision of the loop alone (start-up,
cache loads, the build and the first K1 collisions cancel): ``Ir`` (instructions), ``D1
miss`` (L1 data, reads + writes), ``LL miss`` (last level, reads + writes; ``--LL`` is the
simulated size, fixed so that the figures do not depend on this host: 16 MB, and 1 MB for a
cache the size of one core's L2) and ``D refs`` (data reads + writes); ``events`` is the
events per collision and ``native us`` the same difference of the CPU time of the native runs
(one process each, not alternated, code compiled for valgrind's CPU: a rough figure; take
the ratios of time from ``events``). numba compiles for the CPU that valgrind shows (its name
and features: no AVX-512), into a cache folder of its own (``--cache-dir``), in the native
processes too, so that the valgrind ones load it (the first call compiles every loop once
more, some minutes). Read: Ir per collision sheared / periodic against the time ratio of
``events`` tells how much of the extra cost is instructions; the misses per collision tell
how much is memory. One valgrind process at a time: about 0.5 minute each at N = 1e4, 1-2 at
N = 1e5.

    python scripts/profiling/shear_counts.py events --sizes 1e4 1e5 --modes lists cells
    python scripts/profiling/shear_counts.py cachegrind --sizes 1e5 --modes lists --LL 16777216,16,64 8388608,16,64
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import statistics
import subprocess
import sys
import tempfile
import time

EPS = 0.8
LE3 = ("periodic", "lees-edwards", "periodic")
TINY = 1e-6
GASES = ("periodic", "tiny", "sheared")
KINDS = ("expiries", "crossings", "stale", "wall_collisions")


def steady_rate(packing):
    from granulargas import theory

    n = float(theory.number_density(packing, 3))
    return theory.shear.grad_usf(EPS, 3, packing).a_star * float(theory.shear.reference_frequency(n, 1.0, 3))


def make(gas, n, mode, packing):
    from granulargas.engine import CollisionRule, Simulation
    from granulargas.engine.shear import Shear
    from granulargas.initial import random_state

    rule = CollisionRule.constant(EPS)
    if gas == "periodic":
        return Simulation(random_state(n, packing, 3, seed=1), rule, neighbours=mode, stress=True)
    a = steady_rate(packing) * (TINY if gas == "tiny" else 1.0)
    return Simulation(random_state(n, packing, 3, seed=1, boundary=LE3, shear=a), rule, neighbours=mode,
                      shear=Shear(a))


def counts(sim):
    c = sim._engine.counters[0]
    out = {k: int(c[k]) for k in ("collisions", "events", *KINDS)}
    sh = sim._space.shear
    out["slides"] = int(sh.slide[0]) if sh is not None and sim.neighbours == "cells" else 0
    return out


def per_collision(before, after, n):
    dc = after["collisions"] - before["collisions"]
    d = {k: (after[k] - before[k]) / dc for k in ("events", *KINDS, "slides")}
    d["scans"] = d["slides"] * n  # a slide scans every particle's new column
    return d


# ------------------------------------------------------------------ events and the rate ablation
def events(args):
    import numpy as np

    from granulargas.engine import _shear

    _shear.MARGIN = args.margin

    print(f"3D, eps = {EPS}, packing {args.packing}; steady rate a = {steady_rate(args.packing):.4g}, tiny = "
          f"{TINY:g} a; CPU time per collision, median of {args.repeats} alternated rounds of {args.per_run:g} "
          f"collisions per particle after {args.warmup:g}; lists' sliding margin {args.margin:g} shells; load "
          f"{os.getloadavg()[0]:.2f}")
    for n in (int(float(x)) for x in args.sizes):
        for mode in args.modes:
            sims = {g: make(g, n, mode, args.packing) for g in GASES}
            for sim in sims.values():
                sim.run(np.inf, max_collisions=int(args.warmup * n))
            cpu = {g: [] for g in GASES}
            kinds = {g: [] for g in GASES}
            for _ in range(args.repeats):
                for g, sim in sims.items():
                    b, p0 = counts(sim), time.process_time()
                    sim.run(np.inf, max_collisions=int(args.per_run * n))
                    dt = time.process_time() - p0
                    a = counts(sim)
                    cpu[g].append(dt / (a["collisions"] - b["collisions"]))
                    kinds[g].append(per_collision(b, a, n))
            ratio = {(x, y): statistics.median(p / q for p, q in zip(cpu[x], cpu[y]))
                     for x, y in (("sheared", "periodic"), ("tiny", "periodic"), ("sheared", "tiny"))}
            print(f"N = {n}, {mode}: " + ", ".join(f"{g} {1e6 * statistics.median(cpu[g]):.3f} us" for g in GASES)
                  + "; ratios " + ", ".join(f"{x}/{y} {r:.3f}" for (x, y), r in ratio.items())
                  + f" (load {os.getloadavg()[0]:.2f})")
            for g in GASES:
                m = {k: statistics.mean(d[k] for d in kinds[g]) for k in kinds[g][0]}
                extra = (f", mean list length {sims[g]._engine.lists.nbn.mean():.2f}" if mode == "lists" else
                         f", slides {m['slides']:.2e} (particle scans {m['scans']:.3f})")
                print(f"   {g:>8} per collision: events {m['events']:.3f}, expiry {m['expiries']:.3f}, crossing "
                      f"{m['crossings']:.3f}, stale {m['stale']:.3f}, wall {m['wall_collisions']:.3f}{extra}")
            sys.stdout.flush()


# ------------------------------------------------------------------ cachegrind
def _prepare(path, gas, n, mode, packing, warmup):
    """Build and warm up one gas natively; save its state and memory order."""
    import numpy as np

    sim = make(gas, n, mode, packing)
    sim.run(np.inf, max_collisions=int(warmup * n))
    with open(path, "wb") as f:
        pickle.dump(dict(state=sim.state, order=np.array(sim._engine.particles.ident), gas=gas, mode=mode,
                         rate=None if sim.shear is None else sim.shear.rate), f)


def _child(path, collisions, out):
    """Rebuild a saved gas in its saved memory order and run ``collisions`` collisions."""
    import numpy as np

    from granulargas.engine import CollisionRule, Simulation, simulation
    from granulargas.engine.shear import Shear

    with open(path, "rb") as f:
        saved = pickle.load(f)
    order = saved["order"].astype(np.int64)
    simulation.morton_order = lambda *a: order  # the slots the warmed-up engine had
    rule = CollisionRule.constant(EPS)
    if saved["rate"] is None:
        sim = Simulation(saved["state"], rule, neighbours=saved["mode"], stress=True)
    else:
        sim = Simulation(saved["state"], rule, neighbours=saved["mode"], shear=Shear(saved["rate"]))
    sim.run(np.inf, max_collisions=0)  # builds
    b, p0 = counts(sim), time.process_time()
    sim.run(np.inf, max_collisions=int(collisions))
    dt = time.process_time() - p0
    with open(out, "w") as f:
        json.dump(dict(before=b, after=counts(sim), cpu=dt), f)


def _valgrind_cpu():
    """The CPU name and features numba sees under valgrind (valgrind's own CPU, no AVX-512)."""
    with tempfile.NamedTemporaryFile("r", suffix=".txt") as f:
        subprocess.run(["valgrind", "-q", sys.executable, "-c", "import llvmlite.binding as ll; "
                        "ll.initialize_native_target(); "
                        f"open({f.name!r}, 'w').write(ll.get_host_cpu_name() + ' ' "
                        "+ ll.get_host_cpu_features().flatten())"], check=True)
        return open(f.name).read().split()


def _summary(path):
    """Cachegrind's totals: {event name: count}."""
    names = totals = None
    with open(path) as f:
        for line in f:
            if line.startswith("events:"):
                names = line.split()[1:]
            elif line.startswith("summary:"):
                totals = [int(x) for x in line.split()[1:]]
    return dict(zip(names, totals))


def cachegrind(args):
    me = os.path.abspath(__file__)
    env = dict(os.environ, NUMBA_CACHE_DIR=args.cache_dir)
    env["NUMBA_CPU_NAME"], env["NUMBA_CPU_FEATURES"] = _valgrind_cpu()
    with tempfile.TemporaryDirectory(prefix="shear_counts.") as work:
        _cachegrind(args, me, env, work)


def _cachegrind(args, me, env, work):
    k1, k2 = args.lengths
    print(f"cachegrind, D1 default; counts per collision from the runs of {k1:g} and {k2:g} collisions per "
          f"particle after a native warm-up of {args.warmup:g}; 3D, eps = {EPS}, packing {args.packing}")
    print(f"{'N':>7} {'mode':>6} {'LL':>9} {'gas':>10} {'Ir':>9} {'D1 miss':>8} {'LL miss':>8} {'D refs':>8} "
          f"{'events':>7} {'native us':>9}")
    for n in (int(float(x)) for x in args.sizes):
        for mode in args.modes:
            res = {}
            for gas in args.gases:
                saved = os.path.join(work, f"{gas}-{mode}-{n}.pkl")
                run = [sys.executable, me]
                subprocess.run(run + ["_prepare", saved, gas, str(n), mode, str(args.packing), str(args.warmup)],
                               env=env, check=True)
                for k in (k1, k2):
                    out = os.path.join(work, f"{gas}-{mode}-{n}-{k}")
                    # natively first: compiles what the rebuilt engine needs, and times it
                    subprocess.run(run + ["_child", saved, str(int(k * n)), out + ".native.json"], env=env, check=True)
                    with open(out + ".native.json") as f:
                        res[gas, k, "native"] = json.load(f)
                    for ll in args.LL:
                        cg = f"{out}-{ll}.cg"
                        done = subprocess.run(["nice", "-n", "5", "valgrind", "-q", "--tool=cachegrind",
                                               "--cache-sim=yes", f"--LL={ll}", f"--cachegrind-out-file={cg}"] + run
                                              + ["_child", saved, str(int(k * n)), cg + ".json"], env=env,
                                              stderr=subprocess.PIPE, text=True)
                        if done.returncode:  # (valgrind's notes on the host's caches are left out otherwise)
                            sys.exit(f"valgrind failed:\n{done.stderr}")
                        with open(cg + ".json") as f:
                            res[gas, k, ll] = dict(json.load(f), cg=_summary(cg))
            for ll in args.LL:
                rows = {}
                for gas in args.gases:
                    a, b = res[gas, k1, ll], res[gas, k2, ll]
                    dc = b["after"]["collisions"] - a["after"]["collisions"]
                    cg = {e: (b["cg"][e] - a["cg"][e]) / dc for e in b["cg"]}
                    native = (res[gas, k2, "native"]["cpu"] - res[gas, k1, "native"]["cpu"]) / dc
                    rows[gas] = r = dict(Ir=cg["Ir"], D1=cg["D1mr"] + cg["D1mw"], LL=cg["DLmr"] + cg["DLmw"],
                                         D=cg["Dr"] + cg["Dw"],
                                         events=(b["after"]["events"] - a["after"]["events"]) / dc,
                                         native=native)
                    print(f"{n:>7} {mode:>6} {ll.split(',')[0]:>9} {gas:>10} {r['Ir']:>9.0f} {r['D1']:>8.2f} "
                          f"{r['LL']:>8.2f} {r['D']:>8.0f} {r['events']:>7.3f} {1e6 * r['native']:>9.3f}")
                for gas in rows:
                    if gas != "periodic" and "periodic" in rows:
                        q = {k: rows[gas][k] / rows["periodic"][k] for k in ("Ir", "D1", "LL", "D", "events", "native")}
                        print(f"{'':>7} {'':>6} {'':>9} {gas + '/per':>10} " + " ".join(
                            f"{q[k]:>{w}.3f}" for k, w in (("Ir", 9), ("D1", 8), ("LL", 8), ("D", 8), ("events", 7),
                                                           ("native", 9))))
                sys.stdout.flush()


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "_prepare":
        _, path, gas, n, mode, packing, warmup = argv
        return _prepare(path, gas, int(n), mode, float(packing), float(warmup))
    if argv and argv[0] == "_child":
        return _child(*argv[1:])
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what", required=True)
    for name in ("events", "cachegrind"):
        p = sub.add_parser(name)
        p.add_argument("--sizes", nargs="*", default=["1e4", "1e5"])
        p.add_argument("--modes", nargs="*", choices=["lists", "cells"], default=["lists", "cells"])
        p.add_argument("--packing", type=float, default=0.1)
        p.add_argument("--warmup", type=float, default=10.0 if name == "cachegrind" else 2.0,
                       help="collisions per particle before counting")
    e = sub.choices["events"]
    e.add_argument("--per-run", type=float, default=2.0, help="collisions per particle per timed round")
    e.add_argument("--repeats", type=int, default=5)
    e.add_argument("--margin", type=float, default=1.0,
                   help="the lists' sliding margin in shells (granulargas.engine._shear.MARGIN; the engine's: 1)")
    c = sub.choices["cachegrind"]
    c.add_argument("--gases", nargs="*", choices=GASES, default=["periodic", "sheared"])
    c.add_argument("--lengths", type=float, nargs=2, default=[1.0, 3.0], help="collisions per particle of the two runs")
    c.add_argument("--LL", nargs="*", default=["16777216,16,64", "1048576,16,64"],
                   help="simulated last-level caches, size,ways,line (one valgrind run each)")
    c.add_argument("--cache-dir", default=os.path.join(tempfile.gettempdir(), "shear_counts-numba-cache"),
                   help="numba cache for the CPU valgrind shows")
    args = ap.parse_args(argv)
    (events if args.what == "events" else cachegrind)(args)


if __name__ == "__main__":
    main()
