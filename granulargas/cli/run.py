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
import warnings

from granulargas.cli._args import add_override_argument, overrides_from
from granulargas.io.config import load_config
from granulargas.run import predictions
from granulargas.run.advise import method_line, summary_line
from granulargas.run.runner import Interrupted, RunInterrupted, run_config, stop_on_signals
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
        kept = predictions.load(config)  # this config's checks passed before: its lines, no theory solved
        warned = []
        try:
            with warnings.catch_warnings(record=True) as warned:
                # refuses runs that would leave float64; predicts T range, t_c/t_free
                validity = kept.validity if kept else tuple(raise_if_invalid(config).lines())
        finally:
            _show(warned)
        try:
            summary = run_config(config, overwrite=args.overwrite, quiet=args.quiet, append=args.append, stop=stop)
        except RunInterrupted as exc:
            raise RunInterrupted(f"{exc}; continue with: {continue_command(args, exc.output)}", signum=exc.signum,
                                 time=exc.time, collisions=exc.collisions, output=exc.output) from None
        except Exception:
            # a signal before the output file existed raises at once; inside numba's compiler
            # it surfaces as the compiler's own error: the signal is the cause
            if stop.signum is not None:
                raise Interrupted(stop.signum) from None
            raise
    if kept:
        advice = kept.advice
    else:
        warned_advice = []
        try:
            with warnings.catch_warnings(record=True) as warned_advice:
                advice = tuple(line for line in (summary_line(config), method_line(config)) if line)
        finally:
            _show(warned_advice)
        if not warned and not warned_advice:
            predictions.store(config, predictions.Predictions(validity, advice))
    print("\n".join(summary.lines() + list(validity) + list(advice)))
    return 0


def _show(caught) -> None:
    """Show warnings recorded while the predictions were solved, as they would have been shown."""
    for w in caught:
        warnings.showwarning(w.message, w.category, w.filename, w.lineno, w.file, w.line)
