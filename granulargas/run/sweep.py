"""Parameter sweeps and ensembles: the sweep file, its runs, the executor.

A sweep file names a base config and the parameters to vary::

    base = "hcs_constant_3d.toml"        # relative to the sweep file
    output_dir = "runs/restitution"      # relative to the sweep file; one .h5 per run
    mode = "product"                     # "product" (every combination) or "zip"

    [set]                                # overrides applied to every run
    run.collisions_per_particle = 100

    [vary]                               # lists, ranges, linspaces, seeds
    collision.restitution = [0.9, 0.8, 0.7]
    system.seed = { range = [1, 4] }     # 1, 2, 3, 4 (both ends included)
    # system.packing_fraction = { linspace = [0.05, 0.2, 4] }
    # collision.damping = { logspace = [-3, -1, 3] }

Every run is the base config with dotted-key overrides (validated exactly like
file values by :func:`granulargas.io.config.load_config`) and writes its own H5MD
file. ``index.json`` in the output directory records, for each run, its name, file,
parameters and status; it is rewritten atomically after each run finishes, so it is
always valid.

Execution goes through any :class:`concurrent.futures.Executor`: a local process
pool (``--workers N``, default) or a Dask cluster (``--scheduler ADDRESS``, via
``dask.distributed.Client(ADDRESS).get_executor()``). The engine is deterministic,
so the same sweep gives bit-identical files on either.

Reruns skip runs that the index records as done and whose file still opens; a
missing, half-written or failed run is done again (its file is overwritten). A
failed run is reported with its parameters and does not stop the others.
"""

from __future__ import annotations

import difflib
import itertools
import math
import multiprocessing
import os
import time
import tomllib
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

import h5py

from granulargas.errors import ConfigError, InputFileError
from granulargas.io.config import load_config, parse_config
from granulargas.io.paths import existing_directory
from granulargas.io.sweep_index import INDEX_NAME, read_index, write_index
from granulargas.run.runner import run_config

_TOP_KEYS = {"base", "output_dir", "mode", "set", "vary", "name"}


@dataclass(frozen=True)
class RunSpec:
    """One run of a sweep: a name, its output file and its overrides."""

    name: str
    file: str  # absolute path
    parameters: dict  # varied dotted keys -> value
    overrides: dict = field(default_factory=dict)  # everything applied to the base


@dataclass(frozen=True)
class Sweep:
    path: Path
    base: Path
    output_dir: Path
    runs: tuple[RunSpec, ...]

    @property
    def index_path(self) -> Path:
        return self.output_dir / INDEX_NAME


#: most runs a sweep may have: ``index.json`` is rewritten after every run (so that it is always
#: valid), a cost that grows as the square of the number of runs
MAX_RUNS = 10_000


def _flatten(path: Path, table, prefix: str) -> dict:
    if not isinstance(table, dict):
        raise ConfigError(f"{path}: {prefix.rstrip('.')} = {table!r}: must be a table")
    out = {}
    for key, value in table.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, dict) and not _is_generator(value):
            out.update(_flatten(path, value, dotted + "."))
        else:
            out[dotted] = value
    return out


def _is_generator(value: dict) -> bool:
    return len(value) == 1 and next(iter(value)) in ("range", "linspace", "logspace")


def _count(path: Path, key: str, spec) -> int:
    """How many values ``spec`` gives, without expanding it (ConfigError if malformed)."""
    where = f"{path}: vary.{key}"
    if isinstance(spec, list):
        if not spec:
            raise ConfigError(f"{where} = []: give at least one value")
        return len(spec)
    if isinstance(spec, dict):
        (kind, args), = spec.items()
        numbers = isinstance(args, list) and all(isinstance(a, (int, float)) and not isinstance(a, bool)
                                                 for a in args)
        if not numbers or not all(math.isfinite(a) for a in args):
            raise ConfigError(f"{where}.{kind} = {args!r}: expected a list of finite numbers")
        if kind == "range":
            if not all(isinstance(a, int) for a in args) or len(args) not in (2, 3) or (len(args) == 3 and args[2] == 0):
                raise ConfigError(f"{where}.range = {args!r}: expected integers [first, last] or [first, last, step] "
                                  "(both ends included: [1, 4] gives 1, 2, 3, 4), step != 0")
            first, last, step = (*args, 1)[:3]
            count = max(0, (last - first) // step + 1)  # len(inclusive_range(...)) without its ssize_t bound
        else:
            if len(args) != 3 or not isinstance(args[2], int) or args[2] < 1:
                raise ConfigError(f"{where}.{kind} = {args!r}: expected [start, stop, count] with count >= 1")
            if kind == "logspace" and max(abs(args[0]), abs(args[1])) > 300:
                raise ConfigError(f"{where}.logspace = {args!r}: exponents must lie in [-300, 300] (float64)")
            count = args[2]
        if count == 0:
            raise ConfigError(f"{where} = {spec!r}: gives no values")
        return count
    if isinstance(spec, (int, float, str, bool)):
        return 1
    raise ConfigError(f"{where} = {spec!r}: expected a list, a value, or range/linspace/logspace")


def inclusive_range(first: int, last: int, step: int = 1) -> range:
    """``{ range = [first, last, step] }``: first, first + step, ... up to and including ``last``
    when a step lands on it (``[1, 4]``: 1, 2, 3, 4; ``[1, 10, 4]``: 1, 5, 9; ``[4, 1, -1]``: 4, 3, 2, 1),
    as ``linspace`` includes both ends."""
    return range(first, last + (1 if step > 0 else -1), step)


def _expand_values(path: Path, key: str, spec) -> list:
    """A list of values from a list, a scalar, or {range|linspace|logspace = [...]}."""
    _count(path, key, spec)
    if isinstance(spec, list):
        return spec
    if isinstance(spec, dict):
        (kind, args), = spec.items()
        if kind == "range":
            return list(inclusive_range(*args))
        a, b, n = args
        step = (b - a) / (n - 1) if n > 1 else 0.0
        values = [a + i * step for i in range(n)]
        return [10.0**v for v in values] if kind == "logspace" else values
    return [spec]


def format_value(value) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def load_sweep(path: str | os.PathLike, *, validate: bool = True) -> Sweep:
    """Read and expand a sweep file; with ``validate`` every run's config is checked too
    (:func:`granulargas.io.config.load_config`), so a bad value stops the sweep before any
    run starts, with one line naming the run and the key."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise InputFileError(f"{path}: sweep file not found") from None
    except IsADirectoryError:
        raise InputFileError(f"{path}: is a directory, not a sweep file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputFileError(f"{path}: cannot read sweep file ({exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: TOML syntax error: {exc}") from None
    unknown = sorted(set(data) - _TOP_KEYS)
    if unknown:
        close = difflib.get_close_matches(unknown[0], sorted(_TOP_KEYS), n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ConfigError(f"{path}: unknown key {unknown[0]!r}; allowed: {', '.join(sorted(_TOP_KEYS))}{hint}")
    if not isinstance(data.get("base"), str) or not data["base"].strip():
        raise ConfigError(f"{path}: key 'base' is required: the path of the base config (string)")
    for key in ("output_dir", "name"):
        if key in data and (not isinstance(data[key], str) or not data[key].strip()):
            raise ConfigError(f"{path}: {key} = {data[key]!r}: must be a non-empty string")
    base = (path.parent / data["base"]).resolve()
    if not base.is_file():
        raise InputFileError(f"{path}: base = {data['base']!r}: no such config file ({base})")
    out_name = str(data.get("output_dir", f"runs/{path.stem}"))
    out_dir = (path.parent / out_name).resolve()
    if not out_dir.is_dir():  # the sweep makes output_dir itself, never its parents
        existing_directory(out_dir, f"{path}: output_dir = {out_name!r}")
    mode = data.get("mode", "product")
    if mode not in ("product", "zip"):
        raise ConfigError(f"{path}: mode = {mode!r}; allowed: 'product', 'zip'")
    fixed = _flatten(path, data.get("set", {}), "set.")
    fixed = {k[len("set."):]: v for k, v in fixed.items()}
    vary = _flatten(path, data.get("vary", {}), "vary.")
    vary = {k[len("vary."):]: v for k, v in vary.items()}
    if not vary:
        raise ConfigError(f"{path}: [vary] is empty: name at least one parameter to vary")
    keys = sorted(vary)
    counts = [_count(path, key, vary[key]) for key in keys]
    if mode == "zip":
        if len(set(counts)) != 1:
            raise ConfigError(f"{path}: mode = 'zip' needs lists of equal length; got {dict(zip(keys, counts))}")
        total = counts[0]
    else:
        total = math.prod(counts)
    if total > MAX_RUNS:
        raise ConfigError(f"{path}: [vary] gives {total:.4g} runs; at most {MAX_RUNS} (index.json is rewritten "
                          "after every run); split the sweep")
    value_lists = [_expand_values(path, key, vary[key]) for key in keys]
    combos = list(zip(*value_lists)) if mode == "zip" else list(itertools.product(*value_lists))
    width = max(3, len(str(len(combos) - 1)))
    runs = []
    for i, combo in enumerate(combos):
        params = dict(zip(keys, combo))
        name = f"run_{i:0{width}d}"
        file = str(out_dir / f"{name}.h5")
        overrides = {**fixed, **params, "output.file": file}
        runs.append(RunSpec(name=name, file=file, parameters=params, overrides=overrides))
    if validate:
        try:  # read once; each run's overrides are validated on it
            text = base.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise InputFileError(f"{path}: base = {data['base']!r}: cannot read ({exc})") from None
        for spec in runs:
            try:
                parse_config(text, source=str(base), overrides=spec.overrides)
            except ConfigError as exc:
                params = ", ".join(f"{k}={format_value(v)}" for k, v in spec.parameters.items())
                raise ConfigError(f"{path}: {spec.name} ({params}): {exc}") from None
    return Sweep(path=path, base=base, output_dir=out_dir, runs=tuple(runs))


def run_one(base: str, overrides: dict) -> dict:
    """Run one sweep member in a worker; never raises (errors come back as data)."""
    start = time.perf_counter()
    try:
        config = load_config(base, overrides=overrides)
        summary = run_config(config, overwrite=True, quiet=True)
        return {
            "status": "done",
            "collisions": int(summary.collisions),
            "final_temperature": float(summary.final_temperature),
            "wall_time": time.perf_counter() - start,
        }
    except Exception as exc:  # reported per run; the sweep goes on
        return {"status": "failed", "error": f"{type(exc).__name__}: {exc}", "wall_time": time.perf_counter() - start}


def _write_index(sweep: Sweep, entries: dict) -> None:
    write_index(
        sweep.output_dir,
        {"sweep": str(sweep.path.resolve()), "base": str(sweep.base), "runs": [entries[r.name] for r in sweep.runs]},
    )


def _file_is_readable(file: str) -> bool:
    try:
        with h5py.File(file, "r") as fh:
            return "h5md" in fh
    except Exception:
        return False


def run_sweep(sweep: Sweep, executor: Executor, *, log=print) -> list[dict]:
    """Run every member of ``sweep`` not already done; return the index entries."""
    previous = {}
    if sweep.index_path.is_file():
        try:
            previous = {e["name"]: e for e in read_index(sweep.index_path)["runs"]}
        except (OSError, ValueError, KeyError):
            previous = {}
    entries, todo = {}, []
    for spec in sweep.runs:
        entry = {"name": spec.name, "file": spec.file, "parameters": spec.parameters, "status": "pending"}
        old = previous.get(spec.name)
        if (
            old
            and old.get("status") == "done"
            and old.get("parameters") == spec.parameters
            and _file_is_readable(spec.file)
        ):
            entries[spec.name] = old
            log(f"skip {spec.name}: done ({spec.file})")
            continue
        entries[spec.name] = entry
        todo.append(spec)
    _write_index(sweep, entries)
    futures = {executor.submit(run_one, str(sweep.base), spec.overrides): spec for spec in todo}
    for future in as_completed(futures):
        spec = futures[future]
        try:
            result = future.result()
        except Exception as exc:  # the worker itself died
            result = {"status": "failed", "error": f"{type(exc).__name__}: {exc}"}
        entries[spec.name] = {**entries[spec.name], **result}
        _write_index(sweep, entries)
        params = ", ".join(f"{k}={format_value(v)}" for k, v in spec.parameters.items())
        if result["status"] == "done":
            log(f"done {spec.name} ({params}): {result['collisions']} collisions in {result['wall_time']:.1f} s")
        else:
            log(f"FAILED {spec.name} ({params}): {result['error']}")
    return [entries[r.name] for r in sweep.runs]


def make_executor(workers: int | None = None, scheduler: str | None = None):
    """A process pool, or a Dask executor when ``scheduler`` is given.

    Returns ``(executor, close)``; call ``close()`` when done.
    """
    if scheduler:
        try:  # optional dependency (the 'dask' extra), imported only when asked for
            from dask.distributed import Client
        except ImportError:
            raise InputFileError(
                "--scheduler needs dask.distributed: pip install 'granulargas[dask]'"
            ) from None
        try:
            client = Client(scheduler, timeout="10s")
        except OSError as exc:
            raise InputFileError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
        return client.get_executor(pure=False), client.close
    workers = workers or max(1, os.cpu_count() or 1)
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))
    return pool, pool.shutdown
