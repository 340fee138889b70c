"""GSD trajectories (HOOMD schema) of our H5MD files, for OVITO.

:func:`export_gsd` (``granulargas export gsd FILE.h5 [-o FILE.gsd]``) converts every snapshot of
an H5MD file to a GSD trajectory (HOOMD schema, read natively by OVITO, 2D
included): positions (shifted to the box centred on 0), velocities, image
flags, diameters, masses, species as types, the box, and per frame the
event count as ``configuration/step`` and the time as ``log/granulargas/time``.
GSD stores single precision (the HOOMD schema).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from granulargas.errors import InputFileError, UserError
from granulargas.io.h5md import has_positions, iter_snapshots, snapshot_count
from granulargas.io.paths import output_file

#: Time of each frame in the GSD file (OVITO shows log/ entries as global attributes).
GSD_TIME_KEY = "granulargas/time"


def _import_gsd():
    try:  # optional dependency (the 'export' extra): imported only when a GSD file is written
        import gsd.hoomd
    except ImportError:
        raise UserError("the gsd package is needed for GSD export: pip install 'granulargas[export]'") from None
    return gsd.hoomd


# --------------------------------------------------------------------------- GSD


def export_gsd(h5_path, gsd_path=None, *, overwrite: bool = False) -> tuple[Path, int]:
    """Write every snapshot of one of our H5MD files to a GSD trajectory.

    Parameters
    ----------
    h5_path : path
        H5MD file written by ``granulargas run``.
    gsd_path : path, optional
        Output (default: ``h5_path`` with suffix ``.gsd``).
    overwrite : bool
        Replace an existing output file.

    Returns
    -------
    (Path, int)
        The GSD file and the number of frames written.

    Notes
    -----
    GSD boxes are centred on the origin: a position x in [0, L) is written as
    x - L/2 (a rigid translation of the periodic system); image flags are
    kept, so x_unwrapped - L/2 = position + image L. In 2D, Lz = 0 and z = 0
    (``configuration/dimensions`` = 2).
    """
    hoomd = _import_gsd()
    h5_path = Path(h5_path)
    gsd_path = Path(gsd_path) if gsd_path is not None else h5_path.with_suffix(".gsd")
    if gsd_path.resolve() == h5_path.resolve():
        raise InputFileError(f"{gsd_path}: output would overwrite the input file")
    if gsd_path.exists() and not overwrite and not gsd_path.is_dir():
        raise InputFileError(f"{gsd_path}: output file exists (use --overwrite to replace it)")
    output_file(gsd_path, str(gsd_path), overwrite=overwrite)
    if snapshot_count(h5_path) == 0:
        raise InputFileError(f"{h5_path}: holds no snapshot")
    if not has_positions(h5_path):
        raise InputFileError(f"{h5_path}: DSMC file has no positions: nothing to export to GSD "
                             "(granulargas analyze reads its velocities)")
    tmp = gsd_path.with_name(gsd_path.name + ".part")
    frames = 0
    try:
        with hoomd.open(str(tmp), mode="w") as traj:
            static = None
            for snap in iter_snapshots(h5_path):
                if static is None:
                    static = _gsd_static(snap)
                traj.append(_gsd_frame(hoomd, snap, static))
                frames += 1
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise InputFileError(f"{gsd_path}: cannot write GSD file ({exc})") from None
    except BaseException:  # a damaged input frame, an interrupt: no partial output stays behind
        tmp.unlink(missing_ok=True)
        raise
    tmp.replace(gsd_path)
    return gsd_path, frames


def _gsd_static(snap):
    species = np.asarray(snap.species, dtype=np.int64)
    kinds = np.unique(species)
    typeid = np.searchsorted(kinds, species).astype(np.uint32)
    types = [f"S{k}" for k in kinds]
    return typeid, types, 2.0 * np.asarray(snap.radii), np.asarray(snap.masses)


def _gsd_frame(hoomd, snap, static):
    typeid, types, diameters, masses = static
    n, d = snap.positions.shape
    box = np.asarray(snap.box, dtype=np.float64)
    pos = np.zeros((n, 3))
    vel = np.zeros((n, 3))
    img = np.zeros((n, 3), dtype=np.int32)
    pos[:, :d] = np.asarray(snap.positions) - 0.5 * box
    vel[:, :d] = snap.velocities
    img[:, :d] = snap.images
    frame = hoomd.Frame()
    frame.configuration.step = int(snap.step)
    frame.configuration.dimensions = d
    frame.configuration.box = [box[0], box[1], box[2] if d == 3 else 0.0, 0.0, 0.0, 0.0]
    frame.particles.N = n
    frame.particles.types = types
    frame.particles.typeid = typeid
    frame.particles.position = pos
    frame.particles.velocity = vel
    frame.particles.image = img
    frame.particles.diameter = diameters
    frame.particles.mass = masses
    frame.log[GSD_TIME_KEY] = np.array([snap.time], dtype=np.float64)
    return frame
