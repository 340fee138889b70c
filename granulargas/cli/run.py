"""Run a simulation from a TOML config and write an H5MD file.

``granulargas run CONFIG [--overwrite] [--restart FILE [--append]] [--output FILE]
[--set section.key=value ...] [--quiet]``: validates the config (exit 2 with
one line on a bad value, no file written), runs with a progress bar on a
terminal and prints a short summary. Ctrl-C (SIGINT) or SIGTERM stops the run at
the next chunk boundary, keeps the state reached as the file's last frame and
prints the command that continues it (exit 130 / 143).
"""

from __future__ import annotations

import shlex

from granulargas.cli._args import add_override_argument, overrides_from
from granulargas.io.config import load_config
from granulargas.run.advise import method_line, summary_line
from granulargas.run.runner import RunInterrupted, run_config, stop_on_signals
from granulargas.run.validity import raise_if_invalid


def configure_parser(parser):
    parser.add_argument("config", help="TOML run configuration (every key: docs/configuration.md)")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    parser.add_argument("--restart", metavar="FILE",
                        help="continue from the last snapshot of FILE (same as [initial] from = FILE)")
    parser.add_argument("--append", action="store_true",
                        help="with --restart: continue into FILE itself, extending its datasets (same physics)")
    parser.add_argument("--output", "-o", metavar="FILE", help="output file (overrides [output] file)")
    add_override_argument(parser, "collision.restitution=0.8")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress bar (the summary is still printed)")


def continue_command(args, output) -> str:
    """The command line that continues an interrupted run into its file."""
    argv = ["granulargas", "run", args.config, "--restart", str(output), "--append"]
    for text in args.overrides:
        key = text.partition("=")[0].strip()
        if key not in ("initial.from", "output.file"):
            argv += ["--set", text]
    if args.quiet:
        argv.append("--quiet")
    return shlex.join(argv)


def run(args) -> int:
    overrides = overrides_from(args)
    if args.restart:
        overrides["initial.from"] = args.restart
    if args.output:
        overrides["output.file"] = args.output
    elif args.append and args.restart:
        overrides["output.file"] = args.restart
    with stop_on_signals() as stop:  # before this returns a signal stops at once (nothing to keep)
        config = load_config(args.config, overrides)
        validity = raise_if_invalid(config)  # refuses runs that would leave float64; predicts T range, t_c/t_free
        try:
            summary = run_config(config, overwrite=args.overwrite, quiet=args.quiet, append=args.append, stop=stop)
        except RunInterrupted as exc:
            raise RunInterrupted(f"{exc}; continue with: {continue_command(args, exc.output)}", signum=exc.signum,
                                 time=exc.time, collisions=exc.collisions, output=exc.output) from None
    advice = [line for line in (summary_line(config), method_line(config)) if line]
    print("\n".join(summary.lines() + validity.lines() + advice))
    return 0
