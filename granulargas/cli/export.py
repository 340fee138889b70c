"""Export a run for LAMMPS (same physics, time-stepped DEM) or OVITO (GSD).

``granulargas export lammps CONFIG [-o DIR]``: :func:`granulargas.dem.export.export_lammps`;
``granulargas export gsd FILE.h5 [-o FILE.gsd]``: :func:`granulargas.io.gsd.export_gsd`.
"""

from __future__ import annotations

from pathlib import Path

from granulargas.cli._args import add_override_argument, overrides_from
from granulargas.dem.export import export_lammps
from granulargas.io.config import load_config
from granulargas.io.gsd import GSD_TIME_KEY, export_gsd  # noqa: F401  (GSD_TIME_KEY: the old io.export name)

def configure_parser(parser):
    sub = parser.add_subparsers(dest="format", metavar="FORMAT", required=True)
    p = sub.add_parser("lammps", help="LAMMPS data + input with the same initial state and contact law",
                       description="Write a LAMMPS (pair_style granular) run equivalent to a config.")
    p.add_argument("config", help="TOML run configuration")
    p.add_argument("-o", "--output", metavar="DIR", default=None,
                   help="output directory (default: lammps_<config name>)")
    p.add_argument("--contact-fraction", type=float, default=0.01, metavar="F",
                   help="contact time / mean free time, sets the stiffness (default 0.01)")
    p.add_argument("--material-stiffness", action="store_true",
                   help="the Young modulus of [collision.material] (the contact that duration = \"resolved\" "
                        "resolves) instead of --contact-fraction")
    p.add_argument("--steps-per-contact", type=int, default=50, metavar="N",
                   help="timestep = contact time / N (default 50)")
    p.add_argument("--end-time", type=float, default=None, metavar="T",
                   help="simulated time (default: run.end_time of the config)")
    add_override_argument(p, help_text="override a config value, as in granulargas run (repeatable)")
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
    config = load_config(args.config, overrides_from(args))
    directory = Path(args.output) if args.output else Path(f"lammps_{Path(args.config).stem}")
    fraction = None if args.material_stiffness else args.contact_fraction
    ex = export_lammps(config, directory, contact_fraction=fraction,
                       steps_per_contact=args.steps_per_contact, end_time=args.end_time)
    print(f"wrote {ex.input_file} and {ex.data_file}")
    print(f"  Y = {ex.contact.young_modulus:.6g}, A = {ex.contact.dissipation_time:.6g}, end = {ex.contact.end}"
          f"{' (limit_damping)' if ex.contact.end == 'force' else ''}")
    print(f"  contact time {ex.contact_time:.4g} = {ex.contact_fraction:.4g} x mean free time {ex.mean_free_time:.4g};"
          f" timestep {ex.timestep:.4g}, {ex.steps} steps")
    print(f"  run: cd {directory} && lmp -in {ex.input_file.name}")
    return 0
