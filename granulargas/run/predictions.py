"""The run summary's predictions, kept on disk for the next run of the same gas.

The validity and advice lines of ``granulargas run`` are kinetic theory of the config
alone (:mod:`granulargas.run.validity`, :mod:`granulargas.run.advise`; nothing is
simulated): the same config gives the same lines whatever its seed or output file.
Solving them (cooling ODEs, the HCS splines, root finders) loads scipy and costs a small
run about 0.6 s of CPU, more than the run itself once its compiled code is cached. So
``granulargas run`` keeps them as a small JSON file in the table cache
(:func:`granulargas.contact.table.cache_dir`, ``predictions-<digest>.json``), keyed by

* the config with its output file and seed left out (every other key, the config's
  file name included: the lines name it);
* the package's own files (source and data: any edit computes them again);
* the Python, numpy and scipy versions.

Only predictions that passed every check and raised no warning are kept (a refused
config is refused afresh each time, and a warning is shown each time). ``GRANULARGAS_NO_CACHE=1``
turns the cache off, as it does that of the compiled code. A file that cannot be read
is a miss; one that cannot be written is skipped without a word (the run has its lines).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
import platform
import tempfile
from pathlib import Path

import numpy as np

from granulargas.contact.table import cache_dir

__all__ = ["Predictions", "cache_enabled", "cache_file", "load", "store"]

#: bumped when the stored fields change
FORMAT = 1

_PACKAGE = Path(__file__).resolve().parents[1]


@dataclasses.dataclass(frozen=True)
class Predictions:
    """The lines a run prints after its own: the run checks' (``validity``) and the advice's."""

    validity: tuple
    advice: tuple


def cache_enabled() -> bool:
    """False when ``GRANULARGAS_NO_CACHE`` is set to 1, true or yes."""
    return os.environ.get("GRANULARGAS_NO_CACHE", "") not in ("1", "true", "yes")


@functools.lru_cache(maxsize=1)
def _package_digest() -> str:
    """sha256 of every file of the package (paths and contents), bytecode caches left out."""
    h = hashlib.sha256()
    for path in sorted(p for p in _PACKAGE.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
        h.update(str(path.relative_to(_PACKAGE)).encode() + b"\0")
        h.update(path.read_bytes())
    return h.hexdigest()


def _physics(config) -> dict:
    """The config as the predictions see it: everything but the output file and the seed."""
    out = dataclasses.asdict(config)
    out.pop("text", None)  # the file's text, comments included; its values are the fields
    out["output"].pop("file", None)
    out["system"].pop("seed", None)
    return out


def cache_file(config) -> Path:
    """Where the predictions of ``config`` are kept (module doc)."""
    import scipy  # its top level only (numba loads it anyway): the version

    key = {"format": FORMAT, "config": _physics(config), "package": _package_digest(),
           "python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__}
    digest = hashlib.sha256(json.dumps(key, sort_keys=True, default=repr).encode()).hexdigest()[:24]
    return cache_dir() / f"predictions-{digest}.json"


def load(config) -> Predictions | None:
    """The kept predictions of ``config``, or None (none kept, cache off, unreadable file)."""
    if not cache_enabled():
        return None
    try:
        data = json.loads(cache_file(config).read_text())
        if data.get("format") != FORMAT:
            return None
        return Predictions(tuple(str(x) for x in data["validity"]), tuple(str(x) for x in data["advice"]))
    except (OSError, ValueError, KeyError, TypeError):
        return None


def store(config, predictions: Predictions) -> None:
    """Keep ``predictions`` for the next run of ``config`` (atomically; nothing if the cache is
    off or cannot be written)."""
    if not cache_enabled():
        return
    text = json.dumps({"format": FORMAT, "validity": list(predictions.validity), "advice": list(predictions.advice)})
    path = cache_file(config)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".predictions-", suffix=".tmp")
    except OSError:
        return
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except OSError:
        Path(tmp).unlink(missing_ok=True)
