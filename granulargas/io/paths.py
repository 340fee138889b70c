"""Checks of the paths a user types for output, before anything is written.

Output directories are never created implicitly: a typo in a path would
otherwise go unnoticed (``runs/qickstart/x.h5`` silently making a new
directory). Every command that writes a file or a directory checks its path
here first and refuses with one line naming the path.
"""

from __future__ import annotations

import os
from pathlib import Path

from granulargas.errors import InputFileError


def existing_directory(path, where: str) -> Path:
    """The directory that will hold ``path``; :class:`InputFileError` if it does not
    exist, is not a directory or cannot be written. ``where`` names the path's origin
    in the message (e.g. ``"--plot x.png"``)."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.exists():
        probe = parent
        while not probe.exists() and probe != probe.parent:
            probe = probe.parent
        if probe.exists() and not probe.is_dir():
            raise InputFileError(f"{where}: {probe} is not a directory")
        raise InputFileError(f"{where}: directory {parent} does not exist (it is not created; make it first "
                             "or choose another path)")
    if not parent.is_dir():
        raise InputFileError(f"{where}: {parent} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputFileError(f"{where}: directory {parent} is not writable")
    return parent


def output_file(path, where: str, *, overwrite: bool = False) -> Path:
    """Check an output file's path: its directory exists and can be written, the path is
    not a directory, and an existing file is replaced only with ``overwrite``."""
    path = Path(path)
    if path.is_dir():
        raise InputFileError(f"{where}: is a directory")
    existing_directory(path, where)
    if path.exists() and not overwrite:
        raise InputFileError(f"{where}: file exists (use --overwrite to replace it)")
    return path
