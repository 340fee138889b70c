"""Command line: ``granulargas <command> ...`` (also ``python -m granulargas``).

Each command lives in its own module of this package (``granulargas.cli.run``,
``.epsilon``, ``.analyze``, ``.advise``, ``.sweep``, ``.export``, ``.compile``) exposing
``configure_parser(parser)`` and ``run(args) -> int``; shared argument helpers
are in :mod:`granulargas.cli._args`. This file only wires them. The command
modules are imported lazily (:func:`build_parser` imports only the one named on
the command line) so that ``granulargas --help`` stays instant and one command's
import cost (numba, scipy) is not paid by the others.

A :class:`granulargas.errors.UserError` becomes one line on stderr (``error: ...``,
``interrupted: ...`` for a run stopped by a signal) and its exit code; no traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from granulargas import __version__
from granulargas.errors import UserError

# name -> (module, one-line help)
COMMANDS = {
    "run": ("granulargas.cli.run", "run a simulation from a TOML config, writing H5MD"),
    "epsilon": ("granulargas.cli.epsilon", "coefficient of restitution and contact duration"),
    "analyze": ("granulargas.cli.analyze", "report on a run's H5MD file or a sweep against kinetic theory (--plot, --json)"),
    "advise": ("granulargas.cli.advise", "is a constant restitution good enough for this config?"),
    "sweep": ("granulargas.cli.sweep", "run a parameter sweep / ensemble from a sweep file"),
    "export": ("granulargas.cli.export", "export a run for LAMMPS or OVITO (GSD)"),
    "compile": ("granulargas.cli.compile", "compile every kind of run once, ahead of the first runs"),
}


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The parser; only the module of the command named in ``argv`` is imported."""
    parser = argparse.ArgumentParser(
        prog="granulargas",
        description="Event-driven simulation of viscoelastic granular gases.",
    )
    parser.add_argument("--version", action="version", version=f"granulargas {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    chosen = next((a for a in (argv or []) if not a.startswith("-")), None)
    for name, (module_name, help_text) in COMMANDS.items():
        if name != chosen:
            sub.add_parser(name, help=help_text, description=help_text)
            continue
        module = importlib.import_module(module_name)
        p = sub.add_parser(name, help=help_text, description=(module.__doc__ or help_text).strip().splitlines()[0])
        module.configure_parser(p)
        p.set_defaults(_run=module.run)
    return parser


def one_line(text: str) -> str:
    """``text`` with line breaks (of any kind, e.g. typed into a file name) escaped."""
    return "".join(ch if ch.isprintable() or ch == " " else f"\\x{ord(ch):02x}" if ord(ch) < 256
                   else f"\\u{ord(ch):04x}" for ch in text)


def main(argv: list[str] | None = None) -> int:
    if argv is None:
        argv = sys.argv[1:]
    parser = build_parser(argv)
    args = parser.parse_args(argv)
    if getattr(args, "_run", None) is None:
        parser.print_help()
        return 2
    try:
        return int(args._run(args) or 0)
    except UserError as exc:
        print(f"{exc.prefix}: {one_line(str(exc))}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:  # a signal when there was no state to keep
        signum = getattr(exc, "signum", 2)
        name = {2: "SIGINT", 15: "SIGTERM"}.get(signum, f"signal {signum}")
        print(f"interrupted: {name}", file=sys.stderr)
        return 128 + signum


if __name__ == "__main__":
    raise SystemExit(main())
