"""Run a simulation from a TOML config and write an H5MD file.

``granulargas run CONFIG [--overwrite] [--restart FILE] [--output FILE]
[--set section.key=value ...] [--quiet]``: validates the config (exit 2 with
one line on a bad value, no file written), runs with a progress bar on a
terminal and prints a short summary.
"""

from __future__ import annotations

import signal

from granulargas.cli._args import add_override_argument, overrides_from
from granulargas.io.config import load_config
from granulargas.run.advise import summary_line
from granulargas.run.runner import run_config
from granulargas.run.validity import raise_if_invalid


def configure_parser(parser):
    parser.add_argument("config", help="TOML run configuration (every key: docs/configuration.md)")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--restart", metavar="FILE",
                        help="continue from the last snapshot of FILE (same as [initial] from = FILE)")
    parser.add_argument("--output", "-o", metavar="FILE", help="output file (overrides [output] file)")
    add_override_argument(parser, "collision.restitution=0.8")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress bar (the summary is still printed)")


def _terminate(signum, frame):
    raise KeyboardInterrupt


def run(args) -> int:
    overrides = overrides_from(args)
    if args.restart:
        overrides["initial.from"] = args.restart
    if args.output:
        overrides["output.file"] = args.output
    config = load_config(args.config, overrides)
    validity = raise_if_invalid(config)  # refuses runs that would leave float64; predicts T range, t_c/t_free
    try:  # SIGTERM closes the file like Ctrl-C (SIGKILL cannot be caught; frames are flushed anyway)
        previous = signal.signal(signal.SIGTERM, _terminate)
    except ValueError:
        previous = None  # not the main thread
    try:
        summary = run_config(config, overwrite=args.overwrite, quiet=args.quiet)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    advice = summary_line(config)
    print("\n".join(summary.lines() + validity.lines() + ([advice] if advice else [])))
    return 0
