"""Argument helpers shared by the commands: ``--set section.key=value`` overrides."""

from __future__ import annotations

import tomllib

from granulargas.errors import ConfigError


def parse_override(text: str):
    """``section.key=value`` -> (key, value); the value is read as TOML, else as a string."""
    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise ConfigError(f"--set {text}: expected section.key=value")
    raw = raw.strip()
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return key, value


def add_override_argument(parser, example: str = "collision.restitution=0.8", help_text: str | None = None):
    """The repeatable ``--set KEY=VALUE`` option (stored as ``args.overrides``)."""
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help=help_text or f"override a config value, e.g. --set {example} (repeatable)")


def overrides_from(args) -> dict:
    """The ``--set`` overrides of parsed arguments as a dict of dotted keys."""
    return dict(parse_override(t) for t in args.overrides)
