"""The sweep index file (``index.json``): one entry per run of a sweep.

Written by :mod:`granulargas.run.sweep` (atomically, after every finished run) and
read by :mod:`granulargas.analysis.ensemble`. Each entry holds ``name``, ``file``
(absolute path of the run's H5MD file), ``parameters`` (varied dotted keys ->
value) and ``status`` (``pending``, ``done`` or ``failed``, with ``error``).
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

INDEX_NAME = "index.json"


def read_index(path: str | os.PathLike) -> dict:
    """The sweep index ``{"sweep": ..., "base": ..., "runs": [entry, ...]}``.

    ``path`` is the index file or the sweep's output directory.
    """
    path = Path(path)
    if path.is_dir():
        path = path / INDEX_NAME
    with open(path) as fh:
        return json.load(fh)


def write_index(directory: str | os.PathLike, payload: dict) -> Path:
    """Write ``payload`` as ``directory/index.json`` atomically (temp file + rename)."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".index.", suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(payload, fh, indent=1)
    os.replace(tmp, directory / INDEX_NAME)
    return directory / INDEX_NAME
