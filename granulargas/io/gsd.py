"""Export a run for LAMMPS (same physics, time-stepped DEM) or OVITO (GSD).

``granulargas export lammps CONFIG [-o DIR]`` writes a LAMMPS data file and
input script that start from the same initial state as ``granulargas run
CONFIG`` (same seed, same particles) with the same contact law
(:mod:`granulargas.io.lammps`: hertz/material + damping viscoelastic, a
stiffness whose contact time is a stated fraction of the mean free time).

``granulargas export gsd FILE.h5 [-o FILE.gsd]`` converts every snapshot of
an H5MD file to a GSD trajectory (HOOMD schema, read natively by OVITO, 2D
included): positions (shifted to the box centred on 0), velocities, image
flags, diameters, masses, species as types, the box, and per frame the
event count as ``configuration/step`` and the time as ``log/granulargas/time``.
GSD stores single precision (the HOOMD schema).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from granulargas.errors import ConfigError, InputFileError, UserError

#: Time of each frame in the GSD file (OVITO shows log/ entries as global attributes).
GSD_TIME_KEY = "granulargas/time"


def _import_gsd():
    try:
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
    from granulargas.io.h5md import iter_snapshots, snapshot_count

    hoomd = _import_gsd()
    h5_path = Path(h5_path)
    gsd_path = Path(gsd_path) if gsd_path is not None else h5_path.with_suffix(".gsd")
    if gsd_path.resolve() == h5_path.resolve():
        raise InputFileError(f"{gsd_path}: output would overwrite the input file")
    if gsd_path.exists() and not overwrite:
        raise InputFileError(f"{gsd_path}: output file exists (use --overwrite to replace it)")
    if snapshot_count(h5_path) == 0:
        raise InputFileError(f"{h5_path}: holds no snapshot")
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


# --------------------------------------------------------------------------- LAMMPS


def export_lammps(config, directory, *, contact_fraction: float = 0.01, steps_per_contact: int = 50,
                  end_time: float | None = None, poisson_ratio: float | None = None, name: str = "granulargas"):
    """Write LAMMPS data + input for a run config (same initial state as ``granulargas run``).

    Parameters
    ----------
    config : RunConfig
        A viscoelastic (or elastic) config.
    directory : path
        Output directory for ``data.<name>``, ``in.<name>``, ``granulargas_lammps.json``.
    contact_fraction, steps_per_contact :
        See :func:`granulargas.io.lammps.write_lammps_gas`.
    end_time : float, optional
        Simulated time (default: the config's ``run.end_time``).
    poisson_ratio : float, optional
        Default: the config's material value, else 0.3 (only Y / (1 - nu^2) matters).

    Returns
    -------
    granulargas.io.lammps.LammpsExport
    """
    from granulargas.io import lammps, setup
    from granulargas.io.runner import DEFAULT_OBSERVABLE_SAMPLES

    c = config.collision
    if c.model == "constant":
        raise ConfigError(
            f"{config.source}: collision.model = \"constant\": LAMMPS export needs the viscoelastic "
            "(or elastic) contact law"
        )
    end_time = config.run.end_time if end_time is None else end_time
    if end_time is None:
        raise ConfigError(f"{config.source}: run.end_time is not set: LAMMPS runs for a fixed time (use --end-time)")
    if c.model == "elastic":
        prefactor, end = 0.0, "overlap"
    else:
        prefactor, end = setup.reduced_prefactor(config), c.contact_end
    if poisson_ratio is None:
        poisson_ratio = c.material.poisson_ratio if c.material is not None else lammps.DEFAULT_POISSON
    state = setup.restart_state(config) if config.initial.from_file else setup.fresh_state(config)
    if config.initial.from_file:
        end_time = end_time - state.time
        if end_time <= 0:
            raise ConfigError(f"{config.source}: run.end_time = {end_time + state.time}: restart file is already at "
                              f"t = {state.time}")
    interval = config.output.observables_interval or end_time / DEFAULT_OBSERVABLE_SAMPLES
    return lammps.write_lammps_gas(
        directory, state.positions, state.velocities, state.radii, state.masses, state.box, prefactor,
        end=end, end_time=end_time, thermo_interval=interval, contact_fraction=contact_fraction,
        steps_per_contact=steps_per_contact, poisson_ratio=poisson_ratio, name=name, source=config.source,
        time_origin=state.time,
    )


# --------------------------------------------------------------------------- CLI


def configure_parser(parser):
    sub = parser.add_subparsers(dest="format", metavar="FORMAT", required=True)
    p = sub.add_parser("lammps", help="LAMMPS data + input with the same initial state and contact law",
                       description="Write a LAMMPS (pair_style granular) run equivalent to a config.")
    p.add_argument("config", help="TOML run configuration")
    p.add_argument("-o", "--output", metavar="DIR", default=None,
                   help="output directory (default: lammps_<config name>)")
    p.add_argument("--contact-fraction", type=float, default=0.01, metavar="F",
                   help="contact time / mean free time, sets the stiffness (default 0.01)")
    p.add_argument("--steps-per-contact", type=int, default=50, metavar="N",
                   help="timestep = contact time / N (default 50)")
    p.add_argument("--end-time", type=float, default=None, metavar="T",
                   help="simulated time (default: run.end_time of the config)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a config value, as in granulargas run (repeatable)")
    g = sub.add_parser("gsd", help="GSD trajectory of an H5MD file (opens in OVITO)",
                       description="Convert every snapshot of an H5MD file to GSD (HOOMD schema).")
    g.add_argument("file", help="H5MD file written by granulargas run")
    g.add_argument("-o", "--output", metavar="FILE.gsd", default=None, help="output (default: FILE with .gsd)")
    g.add_argument("--overwrite", action="store_true", help="replace an existing output file")


def run(args) -> int:
    if args.format == "gsd":
        path, frames = export_gsd(args.file, args.output, overwrite=args.overwrite)
        print(f"wrote {path} ({frames} frames)")
        return 0
    from granulargas.io.config import load_config
    from granulargas.io.run_command import parse_override

    overrides = dict(parse_override(t) for t in args.overrides)
    config = load_config(args.config, overrides)
    directory = Path(args.output) if args.output else Path(f"lammps_{Path(args.config).stem}")
    ex = export_lammps(config, directory, contact_fraction=args.contact_fraction,
                       steps_per_contact=args.steps_per_contact, end_time=args.end_time)
    print(f"wrote {ex.input_file} and {ex.data_file}")
    print(f"  Y = {ex.contact.young_modulus:.6g}, A = {ex.contact.dissipation_time:.6g}, end = {ex.contact.end}"
          f"{' (limit_damping)' if ex.contact.end == 'force' else ''}")
    print(f"  contact time {ex.contact_time:.4g} = {ex.contact_fraction:g} x mean free time {ex.mean_free_time:.4g};"
          f" timestep {ex.timestep:.4g}, {ex.steps} steps")
    print(f"  run: cd {directory} && lmp -in {ex.input_file.name}")
    return 0
