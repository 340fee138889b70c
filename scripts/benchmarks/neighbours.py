"""The neighbour search: cell crossings against neighbour lists, cell widths and list shells,
and the side by side with Smallenburg's C code.

For each N and packing fraction the same random state (3D, or 2D with
``--dimension 2``) runs with each
neighbour search (``--modes``: ``lists`` with the default shell, ``cells`` with
cells one diameter wide, ``cells:X`` with cells (1 + X) diameters wide, ``lists:X`` with a list shell
of X diameters) in this process: a warm-up of 5 collisions per particle, then ``--rounds`` alternated
timed runs of max(2e5, N) collisions each. Printed per case: events per
collision (list expiries or cell crossings, stale events), and the median rate
in million collisions per second of CPU time (and of the wall clock). The
viscoelastic rule (damping 0.1) cools the gas during the runs. The first JIT
compile of each mode's loop (a 64-particle run; 0 s when numba's cache is
warm) is printed separately.

With ``--c-cell BINARY`` / ``--c-single BINARY`` (Smallenburg's "Cell" and
"Single" variants, built with their own flags; not part of this repository)
each round also runs the C code at the same N and packing from its FCC start
(elastic only): two runs, to ``T_FROM`` = 3 and to 3 plus the time of about
``--c-collisions`` collisions (Enskog rate), each pinned with taskset to the
core of ``--core``; the rate is the collision difference over the difference of
the children's CPU times. The C code fixes N = 4 n^3 (10976, 108000).

Usage::

    taskset -c 1 python scripts/benchmarks/neighbours.py --n 10976 --packings 0.05 0.1
    taskset -c 1 python scripts/benchmarks/neighbours.py --rule viscoelastic --modes lists cells cells:0.5
    taskset -c 1 python scripts/benchmarks/neighbours.py --c-cell /path/Cell/md --c-single /path/Single/md
    python scripts/benchmarks/neighbours.py --dimension 2 --n 1e4 --packings 0.05 0.25 --modes lists lists:2 lists:4

``--record`` writes the figures into ``docs/performance/results.json``
(``scripts/benchmarks/results.py``) and rewrites the performance page: the engine's rate per
case for the default ``lists`` and ``cells`` modes, the ratio to the C code where it ran,
and, when several modes ran on an elastic 3D gas, every mode's rate and events per collision
(the page's chart of speed against events per collision). With ``--crossover`` it writes
instead, per dimension, N and packing, the rates of the default ``lists`` and ``cells`` modes
side by side (the page's table of the crossover that ``neighbours = "auto"`` follows,
:data:`granulargas.engine.simulation.CELLS_BELOW`)::

    python scripts/benchmarks/neighbours.py --dimension 2 --n 1e4 1e5 --packings 0.05 0.1 0.2 0.3 0.4 0.5 \
        --modes cells lists --rounds 3 --record --crossover

``--plot FILE`` draws the rate against the events per collision, one panel per
N and packing, one point per mode (the C codes' rates as horizontal lines):
the trade-off between fewer, dearer events (wider cells, wider list shells) and
more, cheaper ones.
"""

import argparse
import math
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.theory import collision_frequency


def make_rule(name):
    if name == "elastic":
        return CollisionRule.elastic()
    from granulargas.contact import restitution_table
    from granulargas.contact.material import prefactor_from_damping

    return CollisionRule.viscoelastic(prefactor=prefactor_from_damping(0.1), table=restitution_table(5.0))


def mode_kwargs(mode):
    """Simulation keywords of a ``--modes`` entry."""
    if mode == "lists":
        return dict(neighbours="lists")
    if mode == "cells":
        return dict(neighbours="cells")
    name, extra = mode.split(":")
    if name not in ("lists", "cells"):
        raise SystemExit(f"--modes: {mode!r}: expected lists, cells, lists:SHELL or cells:SHELL")
    return dict(neighbours=name, shell=float(extra))


def compile_seconds(rule, modes):
    out = {}
    for mode in modes:
        st = random_state(64, 0.1, 3, seed=0)
        t = time.perf_counter()
        Simulation(st, rule, **mode_kwargs(mode)).run(0.1)
        out[mode] = time.perf_counter() - t
    return out


def c_run(binary, n, packing, end, core):
    """(CPU seconds, collisions) of one run of the C code to simulated time ``end``."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    text = subprocess.run(["taskset", "-c", str(core), binary, str(n), str(packing), f"{end:g}", "1"],
                          capture_output=True, text=True, cwd=tempfile.gettempdir(), check=True).stdout
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    rows = re.findall(r"Simtime: ([\d.]+), Collisions: (\d+)", text)
    return r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime, int(rows[-1][1])


def c_rate(binary, n, packing, collisions, core):
    """Million collisions per CPU second of the C code between t = 3 and 3 + the time of
    ``collisions`` collisions (Enskog frequency at T = 1)."""
    omega = float(collision_frequency(6.0 * packing / math.pi, 1.0, 3))
    span = max(1.0, math.ceil(2.0 * collisions / (n * omega)))
    c0, n0 = c_run(binary, n, packing, 3.0, core)
    c1, n1 = c_run(binary, n, packing, 3.0 + span, core)
    return (n1 - n0) / (c1 - c0) / 1e6


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=float, nargs="+", default=[10976])
    p.add_argument("--packings", type=float, nargs="+", default=[0.05, 0.1])
    p.add_argument("--modes", nargs="+", default=["lists", "cells"])
    p.add_argument("--rule", choices=["elastic", "viscoelastic"], default="elastic")
    p.add_argument("--dimension", type=int, choices=[2, 3], default=3)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--c-cell", help="binary of the C code's Cell variant")
    p.add_argument("--c-single", help="binary of the C code's Single variant")
    p.add_argument("--c-collisions", type=float, default=2e6)
    p.add_argument("--core", type=int, default=1)
    p.add_argument("--plot", help="PNG file: rate against events per collision")
    p.add_argument("--record", action="store_true",
                   help="write the figures into docs/performance/results.json and rewrite the performance page")
    p.add_argument("--crossover", action="store_true",
                   help="with --record: write the lists' and the cells' rates side by side (the crossover "
                        "table) instead of the engine's records")
    args = p.parse_args(argv)
    load = os.getloadavg()[0]
    commit = _commit()
    results = []
    rule = make_rule(args.rule)
    for mode, s in compile_seconds(rule, args.modes).items():
        print(f"first run (JIT compile, 0 when cached) {mode}: {s:.1f} s", flush=True)
    c_codes = {k: v for k, v in (("C Cell", args.c_cell), ("C Single", args.c_single)) if v}
    for n in (int(x) for x in args.n):
        for eta in args.packings:
            st = random_state(n, eta, args.dimension, seed=args.seed)
            runs = {}
            for mode in args.modes:
                sim = Simulation(st, rule, **mode_kwargs(mode))
                sim.run(np.inf, max_collisions=max(200_000, 5 * n // 2))
                runs[mode] = (sim, [], [], _counts(sim))
            c_rates = {name: [] for name in c_codes}
            per_run = max(200_000, n)
            for _ in range(args.rounds):
                for sim, cpu, wall, _start in runs.values():
                    c0 = sim.collisions
                    w0, p0 = time.perf_counter(), time.process_time()
                    sim.run(np.inf, max_collisions=per_run)
                    w1, p1 = time.perf_counter(), time.process_time()
                    cpu.append((sim.collisions - c0) / (p1 - p0))
                    wall.append((sim.collisions - c0) / (w1 - w0))
                if args.rule == "elastic" and args.dimension == 3:
                    for name, binary in c_codes.items():
                        c_rates[name].append(c_rate(binary, n, eta, args.c_collisions, args.core))
            for mode, (sim, cpu, wall, start) in runs.items():
                now = _counts(sim)
                col = now["collisions"] - start["collisions"]
                per = {k: (now[k] - start[k]) / col for k in ("events", "expiries", "crossings", "stale")}
                bound = (f"crossings {per['crossings']:.3f}" if sim.neighbours == "cells"
                         else f"expiries {per['expiries']:.3f}")
                if sim.neighbours == "lists":
                    bound += f", mean list length {float(np.mean(sim._engine.lists.nbn)):.1f}"
                print(f"{args.dimension}D N={n} packing {eta} {args.rule} {mode} (shell {sim.shell:.3f}): events/collision "
                      f"{per['events']:.3f} ({bound}, stale {per['stale']:.3f}), "
                      f"{statistics.median(cpu) / 1e6:.4f} M collisions/s CPU "
                      f"({statistics.median(wall) / 1e6:.4f} wall; rounds "
                      f"{' '.join(f'{x / 1e6:.4f}' for x in cpu)})", flush=True)
                results.append(dict(n=n, packing=eta, mode=mode, shell=sim.shell, neighbours=sim.neighbours,
                                    events=per["events"], rate=statistics.median(cpu) / 1e6))
            for name, rates in c_rates.items():
                if rates:
                    print(f"N={n} packing {eta} elastic {name}: {statistics.median(rates):.4f} M collisions/s "
                          f"CPU (rounds {' '.join(f'{x:.4f}' for x in rates)})", flush=True)
                    results.append(dict(n=n, packing=eta, mode=name, rate=statistics.median(rates)))
    if args.plot:
        plot(results, args.plot, f"{args.dimension}D, {args.rule}")
    if args.record:
        record(results, args, argv if argv is not None else sys.argv[1:], max(load, os.getloadavg()[0]), commit)


def record(results, args, argv, load, commit):
    """Write the engine's, the C code's and the chart's records into the results file; rewrite the page."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import results as results_file

    words, skip = [], False
    for w in argv:  # the command as recorded: the C code's binaries are not part of the repository
        words.append("BINARY" if skip else w)
        skip = w in ("--c-cell", "--c-single")
    command = "python scripts/benchmarks/neighbours.py " + " ".join(words)
    ours = [r for r in results if not r["mode"].startswith("C ")]
    if args.crossover:
        rate = {(r["mode"], r["n"], r["packing"]): r for r in ours}
        records = []
        for (mode, n, eta), r in sorted(rate.items()):
            other = rate.get(("lists", n, eta))
            if mode == "cells" and other:
                records.append(dict(table="crossover", id=f"{args.dimension}D {args.rule} packing {eta:g} N={n}",
                                    dim=args.dimension, rule=args.rule, n=n, packing=eta,
                                    cells_rate_cpu=round(r["rate"], 4), lists_rate_cpu=round(other["rate"], 4),
                                    cells_events=round(r["events"], 2), lists_events=round(other["events"], 2),
                                    rounds=args.rounds))
        if not records:
            raise SystemExit("--crossover: needs both --modes cells and lists")
        results_file.record_and_render(records, command, load_average=load, commit=commit)
        return
    records = []
    for r in ours:
        if r["mode"] in ("lists", "cells"):
            mag = f"1e{len(str(r['n'])) - 1}"
            records.append(dict(table="engine", id=f"{args.dimension}D periodic {args.rule} {r['mode']} packing "
                                f"{r['packing']:g} N~{mag}", n=r["n"], dim=args.dimension, packing=r["packing"],
                                rule=args.rule, neighbours=r["mode"], scene="periodic", rate_cpu=round(r["rate"], 4),
                                events_per_collision=round(r["events"], 2), rounds=args.rounds))
            variant = "C Cell" if r["mode"] == "cells" else "C Single"
            c = [x for x in results if x["mode"] == variant and (x["n"], x["packing"]) == (r["n"], r["packing"])]
            if c:
                records.append(dict(table="c_code", id=f"{r['mode']} packing {r['packing']:g} N={r['n']}", n=r["n"],
                                    packing=r["packing"], neighbours=r["mode"], rate_cpu=round(r["rate"], 4),
                                    c_variant=variant[2:], c_rate_cpu=round(c[0]["rate"], 4), rounds=args.rounds))
    if args.rule == "elastic" and args.dimension == 3 and len(args.modes) > 1:
        for r in ours:
            width = 1.0 + r["shell"] if r["neighbours"] == "cells" else r["shell"]
            records.append(dict(table="dilute", id=f"{r['mode']} packing {r['packing']:g} N={r['n']}", n=r["n"],
                                packing=r["packing"], mode=r["mode"], width=round(width, 1),
                                rate_cpu=round(r["rate"], 4), events_per_collision=round(r["events"], 2)))
    results_file.record_and_render(records, command, load_average=load, commit=commit)


def plot(results, path, title):
    """Rate against events per collision, one panel per (N, packing); C codes as lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = sorted({(r["n"], r["packing"]) for r in results})
    fig, axes = plt.subplots(1, len(cases), figsize=(4.8 * len(cases), 4.0), squeeze=False)
    styles = {"lists": ("s", "C0"), "cells": ("o", "C1")}
    for ax, (n, eta) in zip(axes[0], cases):
        rows = [r for r in results if (r["n"], r["packing"]) == (n, eta)]
        for kind, (marker, colour) in styles.items():
            pts = sorted((r["events"], r["rate"], r["shell"]) for r in rows if r["mode"].split(":")[0] == kind)
            if not pts:
                continue
            x, y, shell = zip(*pts)
            ax.plot(x, y, marker=marker, color=colour, ls="-", label=f"{kind} (labels: "
                    + ("cell width" if kind == "cells" else "shell") + ", diameters)")
            for xi, yi, si in pts:
                ax.annotate(f"{1 + si:.2g}" if kind == "cells" else f"{si:.2g}", (xi, yi),
                            textcoords="offset points", xytext=(4, 4), fontsize=8, color=colour)
        for k, r in enumerate(r for r in rows if r["mode"].startswith("C ")):
            ax.axhline(r["rate"], color=f"C{k + 2}", ls="--", label=f"{r['mode']} code")
        ax.axvline(2.0, color="0.6", ls=":", lw=1, label="2 events per collision")
        ax.set_xlabel("events per collision")
        ax.set_ylabel("million collisions per CPU second")
        ax.set_title(f"N = {n}, packing {eta:g}")
        top = max(r["rate"] for r in rows)
        right = max(max(r.get("events", 0.0) for r in rows), 2.0)
        ax.set_ylim(0.0, 1.15 * top)
        ax.set_xlim(0.0, 1.12 * right)
        ax.legend(fontsize=8)
    fig.suptitle(f"Speed against events per collision ({title})")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def _counts(sim):
    c = sim._engine.counters[0]
    return {k: float(c[k]) for k in ("events", "collisions", "expiries", "crossings", "stale")}


def _commit():
    """The source tree's commit when the measurement starts (``scripts/benchmarks/results.py``)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import results

    return results.this_commit()


if __name__ == "__main__":
    main()
