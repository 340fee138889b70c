"""Parameter sweeps and ensembles: the sweep file, its runs, the executor.

A sweep file names a base config and the parameters to vary::

    base = "hcs_constant_3d.toml"        # relative to the sweep file
    output_dir = "runs/restitution"      # relative to the sweep file; one .h5 per run
    mode = "product"                     # "product" (every combination) or "zip"

    [set]                                # overrides applied to every run
    run.collisions_per_particle = 100

    [vary]                               # lists, ranges, linspaces, seeds
    collision.restitution = [0.9, 0.8, 0.7]
    system.seed = { range = [1, 5] }     # 1, 2, 3, 4 (Python range semantics)
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

import itertools
import multiprocessing
import os
import time
import tomllib
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

import h5py

from granulargas.errors import ConfigError, InputFileError
from granulargas.io.config import load_config
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


def _flatten(table: dict, prefix: str = "") -> dict:
    out = {}
    for key, value in table.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, dict) and not _is_generator(value):
            out.update(_flatten(value, dotted + "."))
        else:
            out[dotted] = value
    return out


def _is_generator(value: dict) -> bool:
    return len(value) == 1 and next(iter(value)) in ("range", "linspace", "logspace")


def _expand_values(path: Path, key: str, spec) -> list:
    """A list of values from a list, a scalar, or {range|linspace|logspace = [...]}."""
    where = f"{path}: vary.{key}"
    if isinstance(spec, list):
        if not spec:
            raise ConfigError(f"{where} = []: give at least one value")
        return spec
    if isinstance(spec, dict):
        (kind, args), = spec.items()
        if not isinstance(args, list) or not all(isinstance(a, (int, float)) for a in args):
            raise ConfigError(f"{where}.{kind} = {args!r}: expected a list of numbers")
        if kind == "range":
            if not all(isinstance(a, int) for a in args) or not 1 <= len(args) <= 3:
                raise ConfigError(f"{where}.range = {args!r}: expected 1 to 3 integers [start, stop, step]")
            values = list(range(*args))
        else:
            if len(args) != 3 or not isinstance(args[2], int) or args[2] < 1:
                raise ConfigError(f"{where}.{kind} = {args!r}: expected [start, stop, count] with count >= 1")
            a, b, n = args
            step = (b - a) / (n - 1) if n > 1 else 0.0
            values = [a + i * step for i in range(n)]
            if kind == "logspace":
                values = [10.0**v for v in values]
        if not values:
            raise ConfigError(f"{where} = {spec!r}: gives no values")
        return values
    if isinstance(spec, (int, float, str, bool)):
        return [spec]
    raise ConfigError(f"{where} = {spec!r}: expected a list, a value, or range/linspace/logspace")


def format_value(value) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def load_sweep(path: str | os.PathLike) -> Sweep:
    """Read and expand a sweep file (the base config is validated per run later)."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise InputFileError(f"{path}: sweep file not found") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: TOML syntax error: {exc}") from None
    unknown = sorted(set(data) - _TOP_KEYS)
    if unknown:
        raise ConfigError(f"{path}: unknown key {unknown[0]!r}; allowed: {', '.join(sorted(_TOP_KEYS))}")
    if not isinstance(data.get("base"), str):
        raise ConfigError(f"{path}: key 'base' is required: the path of the base config (string)")
    base = (path.parent / data["base"]).resolve()
    if not base.is_file():
        raise InputFileError(f"{path}: base = {data['base']!r}: no such config file ({base})")
    out_dir = (path.parent / str(data.get("output_dir", f"runs/{path.stem}"))).resolve()
    mode = data.get("mode", "product")
    if mode not in ("product", "zip"):
        raise ConfigError(f"{path}: mode = {mode!r}; allowed: 'product', 'zip'")
    fixed = _flatten(data.get("set", {}))
    vary = _flatten(data.get("vary", {}))
    if not vary:
        raise ConfigError(f"{path}: [vary] is empty: name at least one parameter to vary")
    keys = sorted(vary)
    value_lists = [_expand_values(path, key, vary[key]) for key in keys]
    if mode == "zip":
        lengths = {len(v) for v in value_lists}
        if len(lengths) != 1:
            raise ConfigError(f"{path}: mode = 'zip' needs lists of equal length; got {dict(zip(keys, map(len, value_lists)))}")
        combos = list(zip(*value_lists))
    else:
        combos = list(itertools.product(*value_lists))
    width = max(3, len(str(len(combos) - 1)))
    runs = []
    for i, combo in enumerate(combos):
        params = dict(zip(keys, combo))
        name = f"run_{i:0{width}d}"
        file = str(out_dir / f"{name}.h5")
        overrides = {**fixed, **params, "output.file": file}
        runs.append(RunSpec(name=name, file=file, parameters=params, overrides=overrides))
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
