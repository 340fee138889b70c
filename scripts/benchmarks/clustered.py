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

Usage::

    granulargas run configs/clustering_2d_constant.toml
    python scripts/benchmarks/clustered.py runs/clustering_2d_constant.h5 --frames 31 35 39
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.io.config import parse_config
from granulargas.io.h5md import load_snapshot, read_parameters
from granulargas.state import State


def _rule(path):
    cfg = parse_config(read_parameters(path)["config"], str(path))
    c = cfg.collision
    if c.model == "constant":
        return CollisionRule.constant(c.restitution, tc_time=c.tc_time), cfg
    if c.model == "elastic":
        return CollisionRule.elastic(), cfg
    raise SystemExit(f"{path}: collision.model = {c.model!r}: this benchmark takes elastic or constant runs")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("file", help="H5MD file of an elastic or constant-restitution run")
    p.add_argument("--frames", type=int, nargs="+", default=[31, 35, 39])
    p.add_argument("--warmup", type=float, default=0.5, help="collisions per particle before timing")
    p.add_argument("--collisions", type=float, default=1.0, help="collisions per particle per timed run")
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args(argv)
    rule, cfg = _rule(args.file)
    s = cfg.system
    t0 = time.perf_counter()
    warm = random_state(64, 0.2, s.dimension, seed=0)
    Simulation(warm, rule).run(0.1)
    print(f"JIT compile and first run: {time.perf_counter() - t0:.1f} s")

    states = {}
    hom = random_state(s.particles, s.packing_fraction, s.dimension, seed=s.seed)
    states["homogeneous"] = Simulation(hom, rule)
    for k in args.frames:
        snap = load_snapshot(args.file, k)
        states[f"frame {k} (t = {snap.time:.4g})"] = Simulation(
            State(snap.positions, snap.velocities, snap.radii, snap.masses, snap.box, time=snap.time,
                  images=snap.images, last_collision=snap.last_collision), rule)
    n = s.particles
    rec = {}
    for name, sim in states.items():
        sim.run(np.inf, max_collisions=sim.collisions + int(args.warmup * n))
        rec[name] = ([], [])
    per_run = int(args.collisions * n)
    for _ in range(args.rounds):
        for name, sim in states.items():
            c0, e0 = sim.collisions, sim.events
            t = time.process_time()
            sim.run(np.inf, max_collisions=c0 + per_run)
            dt = time.process_time() - t
            rec[name][0].append((sim.collisions - c0) / dt)
            rec[name][1].append((sim.events - e0) / max(sim.collisions - c0, 1))
    base = statistics.median(rec["homogeneous"][0])
    print(f"{s.dimension}D, N = {n}, packing {s.packing_fraction}, rule {cfg.collision.model}; "
          f"{args.rounds} alternated rounds of {per_run} collisions, CPU time")
    print(f"{'state':<28} {'M coll/s':>9} {'events/coll':>12} {'vs homogeneous':>15}")
    for name, (rates, epc) in rec.items():
        r = statistics.median(rates)
        print(f"{name:<28} {r / 1e6:9.3f} {statistics.median(epc):12.2f} {r / base:15.2f}")


if __name__ == "__main__":
    main()
