"""Is a constant restitution good enough for this config? (``granulargas advise CONFIG``)

Prints the advice of :func:`granulargas.run.advise.advise` and the run-level
checks of :func:`granulargas.run.validity.check_run` that the advice does not
already state.
"""

from __future__ import annotations

from granulargas.cli._args import add_override_argument, overrides_from
from granulargas.errors import ConfigError
from granulargas.io.config import load_config
from granulargas.run.advise import DEFAULT_TOLERANCE, advise
from granulargas.run.validity import check_run


def configure_parser(parser):
    parser.add_argument("config", help="TOML run configuration")
    parser.add_argument("--tolerance", type=float, default=DEFAULT_TOLERANCE,
                        help=f"allowed relative error of T(t) (default {DEFAULT_TOLERANCE:g})")
    add_override_argument(parser, "collision.damping=0.05")


def run(args) -> int:
    if not (0.0 < args.tolerance < 1.0):
        raise ConfigError(f"--tolerance = {args.tolerance:g}: must be in (0, 1)")
    config = load_config(args.config, overrides_from(args))
    adv = advise(config, args.tolerance)
    print("\n".join(adv.lines()))
    rv = check_run(config)
    extra = [ln for ln in rv.lines()[1:] if not ln.startswith("validity     beta")]
    if extra:
        print("\n".join(extra))
    return 0
