"""Collision rate of clustered frames against a homogeneous gas of the same N and packing.

A cooling granular gas beyond the shear-instability length forms clusters: local
packings range from nearly 0 to close packing while the engine's neighbour-list
shell is chosen once, from the global packing. This script takes late frames of a
run (by default of ``configs/clustering_2d_constant.toml``), restarts the engine
from each with the run's collision rule, and measures collisions per CPU second
against a homogeneous gas of the same particles, packing and rule (random
placement, Maxwell-Boltzmann velocities). Each state first runs ``--warmup``
collisions per particle, then ``--rounds`` alternated timed runs of
``--collisions`` collisions per particle; printed per state: the median rate,
events per collision and the rate relative to the
homogeneous gas. JIT compile is done (and reported) before the timed runs.

``--modes lists cells`` runs every state in each neighbour mode (the Python API's
default is lists) and adds the ratio of the cells' rate to the lists'. ``--config
CONFIG --times T ...`` takes its states from a run made here instead of a file: the
config's gas from its random initial state, run with cell crossings, stopped at each
time T (a clustering gas at several stages of its clustering).

Usage::

    granulargas run configs/clustering_2d_constant.toml
    python scripts/benchmarks/clustered.py runs/clustering_2d_constant.h5 --frames 31 35 39
    python scripts/benchmarks/clustered.py --config configs/clustering_2d_constant.toml --times 20 100 300 \
        --modes lists cells
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.io.config import load_config, parse_config
from granulargas.io.h5md import load_snapshot, read_parameters
from granulargas.state import State


def _rule(path=None, config=None):
    cfg = load_config(config) if config else parse_config(read_parameters(path)["config"], str(path))
    c = cfg.collision
    if c.model == "constant":
        return CollisionRule.constant(c.restitution, tc_time=c.tc_time), cfg
    if c.model == "elastic":
        return CollisionRule.elastic(), cfg
    raise SystemExit(f"{path}: collision.model = {c.model!r}: this benchmark takes elastic or constant runs")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("file", nargs="?", help="H5MD file of an elastic or constant-restitution run")
    p.add_argument("--frames", type=int, nargs="+", default=[31, 35, 39])
    p.add_argument("--config", help="instead of a file: this config's gas, run here to each of --times")
    p.add_argument("--times", type=float, nargs="+", default=[20.0, 100.0, 300.0])
    p.add_argument("--modes", nargs="+", default=["lists"], choices=["lists", "cells"])
    p.add_argument("--warmup", type=float, default=0.5, help="collisions per particle before timing")
    p.add_argument("--collisions", type=float, default=1.0, help="collisions per particle per timed run")
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args(argv)
    if (args.file is None) == (args.config is None):
        raise SystemExit("give an H5MD file or --config")
    rule, cfg = _rule(args.file, args.config)
    s = cfg.system
    t0 = time.perf_counter()
    warm = random_state(64, 0.2, s.dimension, seed=0)
    for mode in args.modes:
        Simulation(warm, rule, neighbours=mode).run(0.1)
    print(f"JIT compile and first run: {time.perf_counter() - t0:.1f} s")

    hom = random_state(s.particles, s.packing_fraction, s.dimension, seed=s.seed)
    frames = {"homogeneous": hom}
    if args.config:
        evolving = Simulation(hom, rule, neighbours="cells")
        for t in args.times:
            evolving.run(t)
            frames[f"t = {t:g}"] = evolving.state
    else:
        for k in args.frames:
            snap = load_snapshot(args.file, k)
            frames[f"frame {k} (t = {snap.time:.4g})"] = State(
                snap.positions, snap.velocities, snap.radii, snap.masses, snap.box, time=snap.time,
                images=snap.images, last_collision=snap.last_collision)
    states = {(name, mode): Simulation(st, rule, neighbours=mode) for name, st in frames.items() for mode in args.modes}
    n = s.particles
    rec = {}
    for key, sim in states.items():
        sim.run(np.inf, max_collisions=int(args.warmup * n))
        rec[key] = ([], [])
    per_run = int(args.collisions * n)
    for _ in range(args.rounds):
        for key, sim in states.items():
            c0, e0 = sim.collisions, sim.events
            t = time.process_time()
            sim.run(np.inf, max_collisions=per_run)
            dt = time.process_time() - t
            rec[key][0].append((sim.collisions - c0) / dt)
            rec[key][1].append((sim.events - e0) / max(sim.collisions - c0, 1))
    rate = {key: statistics.median(r) for key, (r, _) in rec.items()}
    print(f"{s.dimension}D, N = {n}, packing {s.packing_fraction}, rule {cfg.collision.model}; "
          f"{args.rounds} alternated rounds of {per_run} collisions, CPU time")
    head = f"{'state':<28} {'mode':<6} {'M coll/s':>9} {'events/coll':>12} {'vs homogeneous':>15}"
    print(head + (f" {'cells / lists':>14}" if len(args.modes) == 2 else ""))
    for (name, mode), (_, epc) in rec.items():
        line = (f"{name:<28} {mode:<6} {rate[name, mode] / 1e6:9.3f} {statistics.median(epc):12.2f} "
                f"{rate[name, mode] / rate['homogeneous', mode]:15.2f}")
        if len(args.modes) == 2 and mode == "cells":
            line += f" {rate[name, 'cells'] / rate[name, 'lists']:14.2f}"
        print(line)


if __name__ == "__main__":
    main()
