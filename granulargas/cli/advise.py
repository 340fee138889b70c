"""Predict a run from its config alone: ``granulargas advise CONFIG [--json]``.

Prints the advice of :func:`granulargas.run.advise.advise`: the predicted temperature
at the run's end (the run summary's prediction), and the lines that apply to the
config's scene (:class:`granulargas.io.scene.Scene`: cooling, driven or elastic;
EDMD or DSMC; walls, material route, ...): the spread of eps and whether a constant
eps will do, the instability length, the model and collision duration the scene
needs, and the run-level checks of :func:`granulargas.run.validity.check_run`.
``--json`` prints one JSON object instead (:meth:`granulargas.run.advise.Advice.summary`).
"""

from __future__ import annotations

import json

from granulargas.cli._args import add_override_argument, overrides_from
from granulargas.errors import ConfigError
from granulargas.io.config import load_config
from granulargas.run.advise import DEFAULT_TOLERANCE, advise


def configure_parser(parser):
    parser.add_argument("config", help="TOML run configuration")
    parser.add_argument("--tolerance", type=float, default=DEFAULT_TOLERANCE,
                        help=f"allowed relative error of T(t) (default {DEFAULT_TOLERANCE:g})")
    parser.add_argument("--json", action="store_true",
                        help="print one JSON object (scene, temperature_end, ...) instead of the lines")
    add_override_argument(parser, "collision.damping=0.05")


def run(args) -> int:
    if not (0.0 < args.tolerance < 1.0):
        raise ConfigError(f"--tolerance = {args.tolerance:g}: must be in (0, 1)")
    config = load_config(args.config, overrides_from(args))
    adv = advise(config, args.tolerance)
    if args.json:
        print(json.dumps({"config": config.source, **adv.summary()}, indent=1, ensure_ascii=False))
    else:
        print("\n".join(adv.lines()))
    return 0
