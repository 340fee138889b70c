"""Fingerprints of the final state of a set of small scenes, to show that a change keeps
trajectories bit for bit.

Each scene is a config (TOML text below) run through :func:`granulargas.run.runner.run_config`
into a temporary directory, so the script exercises what a user's run does: config, initial
state, collision rule, driving, engine or DSMC, H5MD writer, restart reader. The fingerprint
of a scene is the SHA-256 of the file's last frame (every per-frame element of
``particles/all``, with its step and time) and of its last observables sample (every
observable except the pressures and the pressure tensor, which are window averages over the
last interval and so depend on where a run started). Parameters (wall times, versions) are left out.

A scene ``X+restart`` runs the first half of ``X`` and continues from that file to the end:
its fingerprint must equal that of ``X`` (restart equality), which the script checks.

Run it on two source trees and compare the output (the JSON written with ``--json``)::

    python scripts/ab/state_hashes.py --json /tmp/new.json
    PYTHONPATH=/path/to/other/tree python scripts/ab/state_hashes.py --json /tmp/old.json
    python scripts/ab/state_hashes.py --compare /tmp/old.json /tmp/new.json

``--scenes NAME ...`` runs some of the scenes only; ``--list`` names them. A new scene is one
entry of :data:`SCENES`.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

#: a soft rubber-like material (contact time / mean free time ~ 0.1 at packing 0.1): collisions take time
RUBBER = """[collision.material]
young_modulus = 1e6
poisson_ratio = 0.3
dissipation_time = 1e-5
diameter = 0.01
density = 1000
speed_unit = 0.5
"""

#: name -> (config text without [output], end time)
SCENES = {
    "elastic-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.25
seed = 1
[collision]
model = "elastic"
[run]
neighbours = "lists"
""", 10.0),
    "elastic-3d-cells": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.05
seed = 2
[collision]
model = "elastic"
[run]
neighbours = "cells"
""", 10.0),
    "constant-2d-lists": ("""
[system]
dimension = 2
particles = 400
packing_fraction = 0.3
seed = 3
[collision]
model = "constant"
restitution = 0.8
[run]
neighbours = "lists"
""", 10.0),
    "constant-2d-cells": ("""
[system]
dimension = 2
particles = 400
packing_fraction = 0.1
seed = 4
[collision]
model = "constant"
restitution = 0.8
[run]
neighbours = "cells"
""", 10.0),
    "tc-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.2
seed = 5
[collision]
model = "constant"
restitution = 0.5
tc_time = 0.01
[run]
neighbours = "lists"
""", 10.0),
    "viscoelastic-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.15
seed = 6
[collision]
model = "viscoelastic"
damping = 0.2
[run]
neighbours = "lists"
""", 10.0),
    "viscoelastic-2d-cells": ("""
[system]
dimension = 2
particles = 400
packing_fraction = 0.1
seed = 7
[collision]
model = "viscoelastic"
damping = 0.2
[run]
neighbours = "cells"
""", 10.0),
    "polydisperse-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.2
seed = 8
[particles]
diameter = {min = 0.8, max = 1.2}
density = 1.0
[collision]
model = "constant"
restitution = 0.9
[run]
neighbours = "lists"
""", 10.0),
    "walls-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.15
seed = 9
boundary = ["periodic", "periodic", "wall"]
[collision]
model = "constant"
restitution = 0.9
wall_restitution = 0.8
[run]
neighbours = "lists"
""", 10.0),
    "walls-2d-cells": ("""
[system]
dimension = 2
particles = 400
packing_fraction = 0.1
seed = 10
boundary = ["wall", "periodic"]
[collision]
model = "elastic"
[run]
neighbours = "cells"
""", 10.0),
    "driven-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.1
seed = 11
[collision]
model = "constant"
restitution = 0.8
[driving]
model = "white_noise"
heating_rate = 0.5
interval = 0.05
[run]
neighbours = "lists"
""", 10.0),
    "driven-walls-2d-cells": ("""
[system]
dimension = 2
particles = 400
packing_fraction = 0.1
seed = 12
boundary = ["periodic", "wall"]
[collision]
model = "viscoelastic"
damping = 0.1
[driving]
model = "white_noise"
heating_rate = 0.5
interval = 0.05
[run]
neighbours = "cells"
""", 10.0),
    "resolved-3d-lists": ("""
[system]
dimension = 3
particles = 200
packing_fraction = 0.1
seed = 13
[collision]
model = "viscoelastic"
duration = "resolved"
""" + RUBBER + """
[run]
neighbours = "lists"
""", 10.0),
    "dsmc-3d": ("""
[system]
dimension = 3
particles = 2000
packing_fraction = 0.05
seed = 14
[collision]
model = "viscoelastic"
damping = 0.1
[run]
method = "dsmc"
""", 10.0),
    "dsmc-driven-2d": ("""
[system]
dimension = 2
particles = 2000
packing_fraction = 0.05
seed = 15
[collision]
model = "constant"
restitution = 0.7
[driving]
model = "white_noise"
heating_rate = 0.5
interval = 0.05
[run]
method = "dsmc"
""", 10.0),
    "rough-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.15
seed = 16
[particles]
inertia = 0.4
[initial]
rotational_temperature = 0.5
[collision]
model = "constant"
restitution = 0.8
[collision.tangential]
model = "coulomb"
restitution = 0.5
friction = 0.2
[run]
neighbours = "lists"
""", 10.0),
    "rough-driven-2d-cells": ("""
[system]
dimension = 2
particles = 400
packing_fraction = 0.1
seed = 17
[particles]
inertia = 0.5
[collision]
model = "viscoelastic"
damping = 0.1
[collision.tangential]
restitution = 0.0
[driving]
heating_rate = 0.5
rotational_fraction = 0.5
[run]
neighbours = "cells"
""", 10.0),
    "rough-dsmc-3d": ("""
[system]
dimension = 3
particles = 2000
packing_fraction = 0.05
seed = 18
[particles]
inertia = 0.4
[collision]
model = "constant"
restitution = 0.9
[collision.tangential]
restitution = -0.5
[run]
method = "dsmc"
""", 10.0),
    "species-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.15
seed = 19
[[species]]
name = "big"
fraction = 0.5
diameter = 1.2
mass = 2.0
[[species]]
name = "small"
fraction = 0.5
diameter = 0.8
mass = 1.0
[collision]
model = "constant"
restitution = { "big-big" = 0.9, "big-small" = 0.8, "small-small" = 0.7 }
[run]
neighbours = "lists"
""", 10.0),
    "species-dsmc-3d": ("""
[system]
dimension = 3
particles = 2000
packing_fraction = 0.05
seed = 20
[[species]]
name = "heavy"
fraction = 0.5
diameter = 1.0
mass = 4.0
[[species]]
name = "light"
fraction = 0.5
diameter = 1.0
mass = 1.0
[collision]
model = "constant"
restitution = 0.8
[run]
method = "dsmc"
""", 10.0),
    "vibrated-2d-cells": ("""
[system]
dimension = 2
particles = 300
packing_fraction = 0.05
seed = 21
boundary = ["periodic", "wall"]
[collision]
model = "constant"
restitution = 0.9
elastic_below = 1e-3
[gravity]
acceleration = [0.0, -1.0]
[walls]
y_low = { kind = "vibrating", amplitude = 0.05, frequency = 3.183, waveform = "sine" }
[run]
neighbours = "cells"
""", 10.0),
    "thermal-gravity-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.1
seed = 22
boundary = ["periodic", "periodic", "wall"]
[collision]
model = "viscoelastic"
damping = 0.1
[gravity]
acceleration = [0.0, 0.0, -0.5]
[walls]
z_low = { kind = "thermal", temperature = 1.0 }
z_high = { kind = "vibrating", amplitude = 0.05, frequency = 1.0, waveform = "triangle" }
[run]
neighbours = "lists"
""", 10.0),
    "shear-3d-lists": ("""
[system]
dimension = 3
particles = 400
packing_fraction = 0.1
seed = 23
boundary = ["periodic", "lees-edwards", "periodic"]
[collision]
model = "elastic"
[shear]
rate = 0.3
thermostat_temperature = 1.0
[run]
neighbours = "lists"
""", 10.0),
    "shear-3d-lists-rows": ("""
[system]
dimension = 3
particles = 2000
packing_fraction = 0.1
seed = 23
boundary = ["periodic", "lees-edwards", "periodic"]
[collision]
model = "constant"
restitution = 0.8
[shear]
rate = 0.59
[run]
neighbours = "lists"
""", 4.0),
    "shear-2d-cells": ("""
[system]
dimension = 2
particles = 400
packing_fraction = 0.1
seed = 24
boundary = ["periodic", "lees-edwards"]
[collision]
model = "constant"
restitution = 0.9
[shear]
rate = 0.5
thermostat_temperature = 1.0
thermostat_interval = 0.05
[run]
neighbours = "cells"
""", 10.0),
    "shear-3d-cells": ("""
[system]
dimension = 3
particles = 1000
packing_fraction = 0.1
seed = 26
boundary = ["periodic", "lees-edwards", "periodic"]
[collision]
model = "constant"
restitution = 0.8
[shear]
rate = 0.5
thermostat_temperature = 1.0
thermostat_interval = 0.05
[run]
neighbours = "cells"
""", 10.0),
    "shear-dsmc-3d": ("""
[system]
dimension = 3
particles = 2000
packing_fraction = 0.02
seed = 25
boundary = ["periodic", "lees-edwards", "periodic"]
[collision]
model = "viscoelastic"
damping = 0.1
[shear]
rate = 0.2
thermostat_temperature = 1.0
[run]
method = "dsmc"
""", 10.0),
}
#: scenes continued from a file written at half their end time (fingerprint: that of the scene)
RESTARTS = ("tc-3d-lists", "viscoelastic-2d-cells", "walls-3d-lists", "driven-walls-2d-cells", "resolved-3d-lists",
            "dsmc-driven-2d", "rough-3d-lists", "rough-dsmc-3d", "species-3d-lists", "vibrated-2d-cells",
            "shear-3d-lists", "shear-dsmc-3d")

#: observables left out of the fingerprint: averages over the last sampling window
WINDOWED = ("pressure", "wall_pressure", "pressure_tensor")


def fingerprint(path) -> str:
    """SHA-256 of the last frame and the last observables sample of an H5MD file (module docstring)."""
    h = hashlib.sha256()
    with h5py.File(path, "r") as f:
        part = f["particles/all"]
        names = []
        part.visit(names.append)
        for name in sorted(names):
            obj = part[name]
            if not isinstance(obj, h5py.Dataset):
                continue
            value = obj[()] if obj.ndim == 0 or name.split("/")[-1] not in ("value", "step", "time") else obj[-1]
            h.update(name.encode())
            h.update(np.ascontiguousarray(value).tobytes())
        for name in sorted(f["observables"]):
            if name in WINDOWED:
                continue
            g = f["observables"][name]
            h.update(name.encode())
            for key in ("step", "time", "value"):
                h.update(np.ascontiguousarray(g[key][-1]).tobytes())
    return h.hexdigest()


def run_scene(text: str, end: float, out: Path, until: float | None = None, restart: Path | None = None) -> Path:
    """Run a scene to ``until`` (default its end); the output schedule is that of the whole scene,
    so that a run to half the end synchronises where the whole run does."""
    from granulargas.io.config import parse_config
    from granulargas.run.runner import run_config

    body = text + f"\n[output]\nfile = \"{out}\"\nsnapshot_interval = {end / 4}\nobservables_interval = {end / 8}\n"
    overrides = {"run.end_time": end if until is None else until}
    if restart is not None:
        overrides["initial.from"] = str(restart)
    run_config(parse_config(body, "scene.toml", overrides), quiet=True, log=lambda line: None)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", metavar="NAME", help="run these scenes only")
    ap.add_argument("--json", metavar="FILE", help="also write {scene: fingerprint} to FILE")
    ap.add_argument("--compare", nargs=2, metavar=("A", "B"), help="compare two JSON outputs and exit")
    ap.add_argument("--list", action="store_true", help="name the scenes and exit")
    args = ap.parse_args(argv)
    if args.list:
        print("\n".join(list(SCENES) + [f"{x}+restart" for x in RESTARTS]))
        return 0
    if args.compare:
        a, b = (json.loads(Path(p).read_text()) for p in args.compare)
        differ = sorted(k for k in set(a) & set(b) if a[k] != b[k])
        for k in sorted(set(a) | set(b)):
            mark = "only in one" if k not in a or k not in b else ("DIFFERENT" if k in differ else "same")
            print(f"{k:30s} {mark}")
        return 1 if differ else 0
    import granulargas

    print(f"# granulargas from {Path(granulargas.__file__).parent}")
    wanted = args.scenes or list(SCENES)
    unknown = [x for x in wanted if x not in SCENES]
    if unknown:
        print(f"error: --scenes: unknown scene {unknown[0]!r}; --list names them", file=sys.stderr)
        return 2
    result, status = {}, 0
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name in wanted:
            text, end = SCENES[name]
            w = time.perf_counter()
            result[name] = fingerprint(run_scene(text, end, tmp / f"{name}.h5"))
            print(f"{name:30s} {result[name][:16]}  ({time.perf_counter() - w:.1f} s)", flush=True)
            if name in RESTARTS:
                half = run_scene(text, end, tmp / f"{name}-half.h5", until=end / 2)
                key = f"{name}+restart"
                result[key] = fingerprint(run_scene(text, end, tmp / f"{name}-rest.h5", restart=half))
                same = result[key] == result[name]
                status |= not same
                print(f"{key:30s} {result[key][:16]}  {'= the uninterrupted run' if same else 'DIFFERS'}",
                      flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1) + "\n")
    return status


if __name__ == "__main__":
    sys.exit(main())
