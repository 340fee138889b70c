"""Parameter sweeps and ensembles: ``granulargas sweep SWEEP.toml``.

The sweep file format and the execution are described in
:mod:`granulargas.run.sweep`.
"""

from __future__ import annotations

import argparse
import sys

from granulargas.errors import ConfigError
from granulargas.run.sweep import format_value, load_sweep, make_executor, run_sweep


def configure_parser(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("sweep_file", metavar="SWEEP.toml",
                        help="sweep file: base config, [set] overrides, [vary] values as lists, "
                             "{ range = [first, last] } (integers, both ends included: [1, 4] is 1, 2, 3, 4; "
                             "[first, last, step]), { linspace = [a, b, n] } or { logspace = [a, b, n] } "
                             "(docs/sweeps.md)")
    parser.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    parser.add_argument("--scheduler", default=None, metavar="ADDRESS",
                        help="run on a Dask cluster, e.g. tcp://host:8786 (needs the 'dask' extra)")
    parser.add_argument("--dry-run", action="store_true", help="list the runs and exit")


def run(args) -> int:
    sweep = load_sweep(args.sweep_file)
    if args.workers is not None and args.workers < 1:
        raise ConfigError(f"--workers = {args.workers}: must be at least 1")
    print(f"sweep {sweep.path}: {len(sweep.runs)} runs of {sweep.base} -> {sweep.output_dir}")
    if args.dry_run:
        for spec in sweep.runs:
            params = ", ".join(f"{k}={format_value(v)}" for k, v in spec.parameters.items())
            print(f"  {spec.name}: {params}")
        return 0
    executor, close = make_executor(args.workers, args.scheduler)
    try:
        entries = run_sweep(sweep, executor)
    finally:
        close()
    failed = [e for e in entries if e["status"] != "done"]
    print(f"{len(entries) - len(failed)} of {len(entries)} runs done; index: {sweep.index_path}")
    if failed:
        print(f"{len(failed)} runs failed; rerun the same command to retry them", file=sys.stderr)
        return 1
    return 0
