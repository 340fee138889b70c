"""Helpers of the property-based tests of the command line (``tests/cli/test_fuzz_*.py``).

* :data:`BASES`: small valid configs (64 to 100 particles, short runs) that the
  strategies mutate; :func:`mutated_config` draws one and 1 to 3 mutations of it
  (a key set to any TOML value, a key dropped, an unknown key or section added, a
  section dropped; some of them as ``--set`` overrides).
* :func:`to_toml`: a TOML writer for the mutated documents (non-finite floats,
  ``-0.0``, nested tables, mixed arrays).
* :func:`invoke`: runs a command as the user would, in this process through
  :func:`granulargas.cli.main` (stdout and stderr captured) or in a subprocess, with
  a wall-clock bound; :func:`check_outcome` checks what every example must satisfy.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import io
import math
import os
import re
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from hypothesis import strategies as st

# ------------------------------------------------------------------------ configs

_OUTPUT = {"file": "out.h5", "snapshots": 3}

BASES = {
    "constant-3d": {
        "system": {"dimension": 3, "particles": 64, "packing_fraction": 0.1, "seed": 1},
        "particles": {"diameter": 1.0, "mass": 1.0},
        "initial": {"temperature": 1.0},
        "collision": {"model": "constant", "restitution": 0.9},
        "run": {"end_time": 1.0},
        "output": dict(_OUTPUT),
    },
    "viscoelastic-2d": {
        "system": {"dimension": 2, "particles": 64, "packing_fraction": 0.2, "seed": 2},
        "collision": {"model": "viscoelastic", "damping": 0.1, "contact_end": "overlap"},
        "run": {"end_time": 1.0, "collisions_per_particle": 2.0},
        "output": {"file": "out.h5", "snapshot_interval": 0.5, "observables_interval": 0.25},
    },
    "material-3d": {
        "system": {"dimension": 3, "particles": 64, "packing_fraction": 0.15, "seed": 3},
        "collision": {"model": "viscoelastic", "contact_end": "force",
                      "material": {"young_modulus": 1.0e7, "poisson_ratio": 0.3, "dissipation_time": 1.0e-6,
                                   "diameter": 0.01, "density": 1000.0, "speed_unit": 1.0}},
        "run": {"end_time": 0.5},
        "output": {"file": "out.h5", "snapshots": 4, "first_snapshot": 0.1},
    },
    "polydisperse-elastic": {
        "system": {"dimension": 3, "particles": 80, "packing_fraction": 0.1, "seed": 4},
        "particles": {"diameter": {"min": 0.8, "max": 1.2}, "density": 2.0},
        "collision": {"model": "elastic"},
        "run": {"collisions_per_particle": 1.0},
        "output": {"file": "out.h5"},
    },
    "vibrated-2d": {
        "system": {"dimension": 2, "particles": 64, "packing_fraction": 0.05, "seed": 6,
                   "boundary": ["periodic", "wall"]},
        "collision": {"model": "constant", "restitution": 0.9, "elastic_below": 0.001},
        "gravity": {"acceleration": [0.0, -1.0]},
        "walls": {"y_low": {"kind": "vibrating", "amplitude": 0.1, "frequency": 1.5, "waveform": "sine"},
                  "y_high": {"kind": "thermal", "temperature": 1.0}},
        "run": {"end_time": 1.0},
        "output": dict(_OUTPUT),
    },
    "shear-3d": {
        "system": {"dimension": 3, "particles": 64, "packing_fraction": 0.1, "seed": 6,
                   "boundary": ["periodic", "lees-edwards", "periodic"]},
        "collision": {"model": "constant", "restitution": 0.9},
        "shear": {"rate": 0.4046},  # steady at T0 = 1: the run checks accept its short run
        "run": {"end_time": 1.0},
        "output": {"file": "out.h5", "snapshots": 2},
    },
    "shear-thermostat-2d": {
        "system": {"dimension": 2, "particles": 100, "packing_fraction": 0.1, "seed": 7,
                   "boundary": ["periodic", "lees-edwards"]},
        "collision": {"model": "elastic"},
        "shear": {"rate": 0.1, "thermostat_temperature": 1.0, "thermostat_interval": 0.05},
        "run": {"end_time": 1.0, "method": "dsmc"},
        "output": {"file": "out.h5", "snapshots": 2},
    },
    "rough-2d": {
        "system": {"dimension": 2, "particles": 64, "packing_fraction": 0.1, "seed": 6},
        "particles": {"inertia": 0.5},
        "initial": {"temperature": 1.0, "rotational_temperature": 0.5},
        "collision": {"model": "constant", "restitution": 0.9, "tangential": {"model": "constant", "restitution": 0.0}},
        "driving": {"heating_rate": 0.1, "rotational_fraction": 0.3},
        "run": {"end_time": 0.5},
        "output": {"file": "out.h5", "snapshots": 3},
    },
    "coulomb-walls-3d": {
        "system": {"dimension": 3, "particles": 64, "packing_fraction": 0.1, "seed": 7,
                   "boundary": ["wall", "periodic", "periodic"]},
        "collision": {"model": "viscoelastic", "damping": 0.1,
                      "tangential": {"model": "coulomb", "restitution": 0.4, "friction": 0.3,
                                     "wall_restitution": 0.2, "wall_friction": 0.5}},
        "run": {"end_time": 0.5},
        "output": {"file": "out.h5", "snapshots": 3},
    },
    "tc-2d": {
        "system": {"dimension": 2, "particles": 100, "packing_fraction": 0.3, "seed": 5},
        "collision": {"model": "constant", "restitution": 0.5, "tc_time": 1e-3},
        "run": {"end_time": 0.5},
        "output": {"file": "out.h5", "snapshots": 2},
    },
    "mixture-3d": {
        "species": [{"name": "big", "count": 24, "diameter": 1.3, "mass": 3.0},
                    {"name": "small", "count": 40, "diameter": 0.8, "density": 2.0}],
        "system": {"dimension": 3, "packing_fraction": 0.1, "seed": 6},
        "collision": {"model": "constant", "restitution": {"big-big": 0.9, "big-small": 0.8, "small-small": 0.85}},
        "run": {"end_time": 1.0},
        "output": dict(_OUTPUT),
    },
    "mixture-material-dsmc-2d": {
        "species": [{"name": "glass", "fraction": 0.6, "young_modulus": 6.3e10, "poisson_ratio": 0.24,
                     "dissipation_time": 2e-9},
                    {"name": "steel", "fraction": 0.4, "diameter": 0.9, "density": 3.1, "young_modulus": 2.1e11,
                     "poisson_ratio": 0.29, "dissipation_time": 1e-9}],
        "system": {"dimension": 2, "particles": 100, "packing_fraction": 0.05, "seed": 7},
        "collision": {"model": "viscoelastic",
                      "material": {"diameter": 0.001, "density": 2500.0, "speed_unit": 0.5}},
        "run": {"collisions_per_particle": 2.0, "method": "dsmc"},
        "output": {"file": "out.h5", "snapshots": 3},
    },
}

#: the bases of the scenes every fuzz test mutates (default of :func:`mutated_config`); the sheared
#: bases (:data:`SHEAR_BASES`) have tests of their own
SHEAR_BASES = tuple(name for name in BASES if name.startswith("shear"))
GENERAL_BASES = tuple(name for name in BASES if name not in SHEAR_BASES)

#: values the brief of the fuzz tests names, and neighbours of them
SPECIAL = [0, -0.0, 0.0, -1, -1.5, 1e-300, 5e-324, 1e308, -1e308, math.inf, -math.inf, math.nan,
           2**63 - 1, -(2**63), 2**31, 1, 2, 0.5, True, False, "", "x", "0.5", "constant", "elastic",
           "viscoelastic", "force", "overlap", [], [1, 2], ["a", 1.5], {}, {"min": 0.9, "max": 1.1},
           {"a": 1}]

#: type-keeping extremes for numeric keys: the ends of float64 and int64, signs, zeros
EXTREMES = [0, -0.0, -1, -2.5, 1e-300, 5e-324, 1e308, -1e308, math.inf, -math.inf, math.nan, 2**63 - 1,
            -(2**63), 2**31, 2**53 + 1, 1e-100, 1e100, 1e-50, 1e50, 1e-12, 1e12, 3, 1e9]


def _bounds():
    """The ends of every range the config schema declares (and just beyond them)."""
    try:
        from granulargas.io.config import config_schema
    except ImportError:  # a validator without a schema
        return []
    out = []
    for key in config_schema():
        for x in (key.low, key.high, *(key.high_by_dimension or {}).values()):
            if x is not None and math.isfinite(x):
                out += [x, math.nextafter(x, math.inf), math.nextafter(x, -math.inf), x * 1.5, x / 1.5]
    return sorted({x for x in out if math.isfinite(x)})


BOUNDS = _bounds()

_KEY_NAMES = st.sampled_from(["particle", "partcles", "temprature", "seed2", "end", "x", "model", "file",
                              "diameter", "min", "from", "damping", "restitutions", "snapshot"])


def _toml_values(depth: int = 1):
    scalars = st.one_of(
        st.sampled_from(SPECIAL),
        st.integers(min_value=-(2**63), max_value=2**63 - 1),
        st.floats(allow_nan=True, allow_infinity=True),
        st.booleans(),
        st.text(max_size=6),
    )
    if depth == 0:
        return scalars
    inner = _toml_values(depth - 1)
    return st.one_of(scalars, scalars, scalars, st.lists(inner, max_size=3),
                     st.dictionaries(_KEY_NAMES, inner, max_size=2))


def _paths(doc: dict, prefix=()) -> list[tuple]:
    """Every key path of a nested document (tables included)."""
    out = []
    for key, value in doc.items():
        out.append(prefix + (key,))
        if isinstance(value, dict):
            out += _paths(value, prefix + (key,))
        elif isinstance(value, list) and value and all(isinstance(x, dict) for x in value):  # [[species]]
            for k, item in enumerate(value):
                out.append(prefix + (key, k))
                out += _paths(item, prefix + (key, k))
    return out


def _override_key(doc: dict, path: tuple) -> str | None:
    """The ``--set`` key of a path (a species' key by the species' name), or None if it has none."""
    if len(path) > 1 and isinstance(path[1], int):
        item = _get(doc, path[:2])
        name = item.get("name") if isinstance(item, dict) else None
        if len(path) != 3 or not isinstance(name, str) or not name or any(c in name for c in ".=\"\\ "):
            return None
        return f"{path[0]}.{name}.{path[2]}"
    return ".".join(map(str, path))


@dataclass
class Mutation:
    kind: str  # "set", "drop", "unknown-key", "drop-section", "unknown-section", "scale"
    path: tuple
    value: object = None
    as_override: bool = False

    def __repr__(self):
        extra = "" if self.kind in ("drop", "drop-section") else f" = {self.value!r}"
        return f"{self.kind} {'.'.join(map(str, self.path))}{extra}{' (--set)' if self.as_override else ''}"


@dataclass
class MutatedConfig:
    base: str
    document: dict
    overrides: list = field(default_factory=list)  # ["section.key=<toml>"]
    mutations: list = field(default_factory=list)

    def __repr__(self):
        return f"MutatedConfig({self.base}: {self.mutations})"


@st.composite
def mutated_config(draw, bases=None):
    """A valid base config with 1 to 3 mutations (see the module docstring)."""
    name = draw(st.sampled_from(GENERAL_BASES if bases is None else bases))
    doc = copy.deepcopy(BASES[name])
    overrides, done = [], []
    # half of the examples change values only within what the schema allows (legal runs of
    # other sizes, rules and models); the others also break things
    legal = draw(st.booleans())
    for _ in range(draw(st.sampled_from([1, 1, 1, 2, 3]))):
        paths = _paths(doc)
        kind = "plausible" if legal else draw(st.sampled_from(
            ["extreme", "extreme", "extreme", "extreme", "plausible", "set", "set", "scale", "scale", "drop",
             "unknown-key", "drop-section", "unknown-section"]))
        if kind == "plausible":
            m = _plausible(draw, doc, paths)
            if m is None:
                continue
            kind = "done"
        if kind in ("set", "scale", "drop", "extreme") and not paths:
            kind = "unknown-section"
        if kind == "done":
            pass
        elif kind == "extreme":
            numeric = [p for p in paths if isinstance(_get(doc, p), (int, float)) and not isinstance(_get(doc, p), bool)]
            if not numeric:
                continue
            path = draw(st.sampled_from(numeric))
            pool = EXTREMES + (BOUNDS if BOUNDS else [])
            value = draw(st.sampled_from(pool))
            if isinstance(_get(doc, path), int) and isinstance(value, float) and value.is_integer() and abs(value) < 2**63:
                value = int(value) if draw(st.booleans()) else value
            m = Mutation("set", path, value)
        elif kind == "scale":
            numeric = [p for p in paths if isinstance(_get(doc, p), (int, float)) and not isinstance(_get(doc, p), bool)]
            if not numeric:
                continue
            path = draw(st.sampled_from(numeric))
            factor = draw(st.sampled_from([0.5, 2, 10, 1000, -1, 1e-10, 1e10]))
            old = _get(doc, path)
            value = type(old)(old * factor) if isinstance(old, int) and float(old * factor).is_integer() else old * factor
            m = Mutation("set", path, value)
        elif kind == "set":
            path = draw(st.sampled_from(paths))
            m = Mutation("set", path, draw(_toml_values()))
        elif kind == "drop":
            m = Mutation("drop", draw(st.sampled_from([p for p in paths if len(p) > 1] or paths)))
        elif kind == "unknown-key":
            sections = [p for p in paths if isinstance(_get(doc, p), dict)] or [("system",)]
            m = Mutation("set", draw(st.sampled_from(sections)) + (draw(_KEY_NAMES),), draw(_toml_values(0)))
        elif kind == "drop-section":
            m = Mutation("drop", (draw(st.sampled_from(list(doc) or ["system"])),))
        else:
            m = Mutation("set", (draw(st.sampled_from(["sytem", "runs", "outputs", "extra"])),),
                         {draw(_KEY_NAMES): draw(_toml_values(0))})
        # a set of a key two levels deep or less may go through --set instead of the file
        key = _override_key(doc, m.path) if m.kind == "set" else None
        if key is not None and 2 <= len(m.path) <= 3 and not isinstance(m.value, dict) and draw(st.booleans()):
            m.as_override = True
            overrides.append(f"{key}={_value(m.value)}")
        else:
            _apply(doc, m)
        done.append(m)
    return MutatedConfig(name, doc, overrides, done)


def _plausible(draw, doc, paths):
    """A value the schema allows for one of the document's keys, or another allowed choice
    (legal runs of the same size: counts up to 400, values within a factor 1000)."""
    try:
        from granulargas.io.config import config_schema
    except ImportError:
        return None
    keys = {tuple(k.dotted.split(".")): k for k in config_schema()}
    schema_path = lambda p: (p[0], p[2]) if len(p) == 3 and isinstance(p[1], int) else p  # noqa: E731
    known = [p for p in paths if schema_path(p) in keys and keys[schema_path(p)].type != "table"]
    if not known:
        return None
    path = draw(st.sampled_from(known))
    key, old = keys[schema_path(path)], _get(doc, path)
    if key.choices is not None:
        return Mutation("set", path, draw(st.sampled_from(list(key.choices))))
    if key.type == "string" or isinstance(old, (dict, str, bool)) or not isinstance(old, (int, float)):
        return None
    low = key.low if key.low is not None else -1e300
    high = min(x for x in (key.high, *(key.high_by_dimension or {}).values(), 1e300) if x is not None)
    if key.type == "integer":
        top = {"particles": 400, "snapshots": 50}.get(key.key, 2**31)
        return Mutation("set", path, draw(st.integers(int(max(low, 0)), int(min(high, top)))))
    a = max(low, abs(old) / 1000.0) if old else max(low, 1e-3)
    b = min(high, abs(old) * 1000.0) if old else min(high, 1e3)
    if not a < b:
        return None
    x = math.exp(draw(st.floats(math.log(max(a, 1e-300)), math.log(b))))
    x = min(max(x, a), b)
    if (key.low_open and x <= key.low) or (key.high_open and x >= high):
        return None
    return Mutation("set", path, x)


def _get(doc, path):
    node = doc
    for part in path:
        node = node[part]
    return node


def _apply(doc, m: Mutation):
    node = doc
    for part in m.path[:-1]:
        if isinstance(node, list):  # an entry of an array of tables
            node = node[part]
            continue
        nxt = node.get(part)
        if not isinstance(nxt, (dict, list)) or (isinstance(nxt, list) and not all(isinstance(x, dict) for x in nxt)):
            nxt = node[part] = {}
        node = nxt
    if isinstance(node, list):  # a whole entry of an array of tables
        if m.kind == "drop":
            del node[m.path[-1]]
        else:
            node[m.path[-1]] = m.value
    elif m.kind == "drop":
        node.pop(m.path[-1], None)
    else:
        node[m.path[-1]] = m.value


# ------------------------------------------------------------------------ TOML


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _string(k)


def _string(s: str) -> str:
    out = []
    for ch in s:
        code = ord(ch)
        if ch == "\\":
            out.append("\\\\")
        elif ch == '"':
            out.append('\\"')
        elif code < 0x20 or code == 0x7F or 0xD800 <= code <= 0xDFFF:
            out.append(f"\\u{code:04X}" if code < 0xD800 or code > 0xDFFF else "\\uFFFD")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v))


def to_toml(doc: dict) -> str:
    """A nested dict as TOML: top-level scalars first, then one [table] per section
    (sub-tables of sections as [section.sub], deeper tables inline)."""
    lines = [f"{_key(k)} = {_value(v)}" for k, v in doc.items() if not isinstance(v, dict)]
    for name, table in doc.items():
        if not isinstance(table, dict):
            continue
        lines.append(f"\n[{_key(name)}]")
        subs = []
        for k, v in table.items():
            if isinstance(v, dict) and v and all(not isinstance(x, dict) for x in v.values()) and k != "diameter":
                subs.append((k, v))
            else:
                lines.append(f"{_key(k)} = {_value(v)}")
        for k, v in subs:
            lines.append(f"\n[{_key(name)}.{_key(k)}]")
            lines += [f"{_key(kk)} = {_value(vv)}" for kk, vv in v.items()]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------ running


@dataclass
class Outcome:
    code: int | None  # None: still running when killed (subprocess)
    stdout: str
    stderr: str
    seconds: float
    interrupted_by_bound: bool = False
    exception: BaseException | None = None


def _snapshot_tree(root: Path) -> dict:
    out = {}
    for p in sorted(root.rglob("*")):
        if p.is_file():
            out[str(p.relative_to(root))] = hashlib.sha256(p.read_bytes()).hexdigest()
        elif p.is_dir():
            out[str(p.relative_to(root)) + "/"] = "dir"
    return out


def invoke(argv, cwd: Path, *, bound: float = 30.0, subprocess_run: bool = False, env=None) -> Outcome:
    """Run ``granulargas ARGV`` in ``cwd``; after ``bound`` seconds send SIGINT (the
    command must then stop at its next chunk boundary and exit 130).

    In-process: ``granulargas.cli.main(argv)`` with stdout/stderr captured; an
    exception escaping ``main`` is returned in ``Outcome.exception`` (exit 1, like
    the real interpreter). A command that does not return within ``4 bound`` after
    the SIGINT is a hang: faulthandler dumps the stacks and ends the test process.
    """
    start = time.perf_counter()
    trace = os.environ.get("GRANULARGAS_FUZZ_TRACE")  # a file: every example is appended before it runs
    if trace:
        with open(trace, "a") as fh:
            texts = {p.name: p.read_text(errors="replace") for p in Path(cwd).glob("*.toml")}
            fh.write(f"=== {argv}\n" + "".join(f"--- {k}\n{v}" for k, v in texts.items()))
    if subprocess_run:
        proc = subprocess.Popen([sys.executable, "-m", "granulargas", *argv], cwd=cwd, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, env=env)
        fired = False
        try:
            out, err = proc.communicate(timeout=bound)
        except subprocess.TimeoutExpired:
            fired = True
            proc.send_signal(signal.SIGINT)
            try:
                out, err = proc.communicate(timeout=4 * bound)
            except subprocess.TimeoutExpired:
                proc.kill()
                out, err = proc.communicate()
                return Outcome(None, out, err, time.perf_counter() - start, True)
        return Outcome(proc.returncode, out, err, time.perf_counter() - start, fired)

    import faulthandler

    from granulargas.cli import main

    fired = threading.Event()
    done = threading.Event()

    def alarm():
        if not done.wait(bound):
            fired.set()
            os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Thread(target=alarm, daemon=True)
    out, err = io.StringIO(), io.StringIO()
    old = os.getcwd()
    os.chdir(cwd)
    faulthandler.dump_traceback_later(5 * bound, exit=True)
    timer.start()
    code, exc = None, None
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(list(argv))
            except SystemExit as e:  # argparse
                code = e.code if isinstance(e.code, int) else 2
            except KeyboardInterrupt as e:  # escaped the command's own handling
                code, exc = 1, e
            except Exception as e:  # noqa: BLE001 (a traceback: what the property forbids)
                code, exc = 1, e
    finally:
        done.set()
        faulthandler.cancel_dump_traceback_later()
        os.chdir(old)
        timer.join()
    if trace:
        with open(trace, "a") as fh:
            fh.write(f"--> exit {code} ({time.perf_counter() - start:.2f} s) {err.getvalue().strip()[:200]}\n")
    return Outcome(code, out.getvalue(), err.getvalue(), time.perf_counter() - start, fired.is_set(), exc)


#: what names a key or a file in a one-line error: a dotted key of a known section, a [section], a
#: file name, or the key of a ``--set`` override as given (``override: sytem.particle = 0: ...``)
KEY_RE = re.compile(r"\b(system|particles|initial|collision|driving|gravity|walls|shear|run|output|species)(\.[A-Za-z_0-9]+)+|\[[^\]]+\]"
                    r"|\.(toml|h5|png|gsd)\b|^error: override: [^ ]+ = ")


def check_outcome(o: Outcome, before: dict, after: dict, *, output_made: bool = True, long_runs: bool = False):
    """What every example must satisfy (the brief of the fuzz tests):

    * exit 0 (a result), 2 (bad input: one line on stderr naming the key or the file,
      no traceback, nothing created, nothing changed) or 3 (a run that cannot continue,
      one line); 130 only when the wall-clock bound sent SIGINT (the run stops at a
      chunk boundary and keeps its state);
    * no traceback on stderr, no exception escaping ``main``;
    * files that existed before are unchanged (except the output of a successful
      or interrupted run).
    """
    assert o.exception is None, f"exception escaped: {type(o.exception).__name__}: {o.exception}\n{o.stderr[-2000:]}"
    assert o.code is not None, f"hang: no exit within the bound after SIGINT\n{o.stderr[-2000:]}"
    assert "Traceback" not in o.stderr, o.stderr[-3000:]
    if o.interrupted_by_bound:
        assert long_runs, f"no result within {o.seconds:.3g} s: a hang\n{o.stderr[-2000:]}"
        assert o.code in (0, 2, 3, 130), (o.code, o.stderr)
    else:
        assert o.code in (0, 2, 3), (o.code, o.stderr[-2000:])
    changed = {k for k in before if after.get(k) != before[k]}
    if o.code in (2, 3) or not output_made:
        # warnings and the announcement of a first compile ("compiling ... (once; ...)") are not the error
        lines = [ln for ln in o.stderr.splitlines()
                 if ln.strip() and not ln.startswith(("warning:", "compiling "))]
        if o.code in (2, 3):
            assert len(lines) == 1, o.stderr
            assert lines[0].startswith("error: "), lines
        if o.code == 2:
            assert KEY_RE.search(lines[0]) or "--" in lines[0], f"names no key or file: {lines[0]}"
            assert changed == set(), (changed, lines)
            assert set(after) - set(before) == set(), (set(after) - set(before), lines)
    return changed
