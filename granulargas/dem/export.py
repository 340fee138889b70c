"""A run config as a LAMMPS run: same initial state, same contact law.

:func:`export_lammps` (``granulargas export lammps CONFIG [-o DIR]``) writes a
LAMMPS data file and input script that start from the same initial state as
``granulargas run CONFIG`` (same seed, same particles, built by
:func:`granulargas.run.prepare.initial_state`) with the same contact law
(:mod:`granulargas.dem.lammps`: hertz/material + damping viscoelastic, a
stiffness whose contact time is a stated fraction of the mean free time), and
the same walls (``f`` boundaries and ``fix wall/gran`` of the same contact law).
A mixture's species become atom types, each pair of species with its own contact
(prefactor, and on the material route the pair's effective modulus).
A driven run has no LAMMPS counterpart here and is refused.
"""

from __future__ import annotations

from pathlib import Path

from granulargas.dem import lammps
from granulargas.errors import ConfigError
from granulargas.io.paths import existing_directory
from granulargas.contact.material import effective_modulus
from granulargas.run.prepare import (initial_state, pair_prefactors, reduced_prefactor, reduced_young_modulus,
                                     reference_mass_si, species_indices)
from granulargas.run.schedule import DEFAULT_OBSERVABLE_SAMPLES


def export_lammps(config, directory, *, contact_fraction: float | None = 0.01, steps_per_contact: int = 50,
                  end_time: float | None = None, poisson_ratio: float | None = None, name: str = "granulargas",
                  pressure: bool = False, contact_pairs: bool = False):
    """Write LAMMPS data + input for a run config (same initial state as ``granulargas run``).

    Parameters
    ----------
    config : RunConfig
        A viscoelastic (or elastic) config.
    directory : path
        Output directory for ``data.<name>``, ``in.<name>``, ``granulargas_lammps.json``.
    contact_fraction : float or None
        See :func:`granulargas.dem.lammps.write_lammps_gas`. None: the stiffness of the
        config's ``[collision.material]`` (:func:`granulargas.run.prepare.reduced_young_modulus`),
        the contact that ``[collision] duration = "resolved"`` resolves.
    steps_per_contact, pressure, contact_pairs :
        See :func:`granulargas.dem.lammps.write_lammps_gas`.
    end_time : float, optional
        Simulated time (default: the config's ``run.end_time``).
    poisson_ratio : float, optional
        Default: the config's material value, else 0.3 (only Y / (1 - nu^2) matters).

    Returns
    -------
    granulargas.dem.lammps.LammpsExport
    """
    c = config.collision
    if config.run.method == "dsmc":
        raise ConfigError(f'{config.source}: run.method = "dsmc": a DSMC run has no positions; LAMMPS export '
                          'writes a spatial run (export the config with run.method = "edmd")')
    for section in ("gravity", "walls"):
        if getattr(config, section) is not None:
            raise ConfigError(f"{config.source}: [{section}]: the LAMMPS export writes flat hard walls and no field "
                              f"(export the config without [{section}])")
    if c.model == "constant":
        raise ConfigError(
            f"{config.source}: collision.model = \"constant\": LAMMPS export needs the viscoelastic "
            "(or elastic) contact law"
        )
    if config.driving is not None and config.driving.heating_rate > 0.0:
        raise ConfigError(f"{config.source}: [driving]: LAMMPS export does not write the white-noise "
                          "driving; export an undriven config")
    if c.tangential is not None:
        raise ConfigError(f"{config.source}: collision.tangential = {{...}}: LAMMPS export writes the normal "
                          "viscoelastic contact only (no tangential law for rough particles); export a config "
                          "without [collision.tangential]")
    end_time = config.run.end_time if end_time is None else end_time
    if end_time is None:
        raise ConfigError(f"{config.source}: run.end_time is not set: LAMMPS runs for a fixed time (use --end-time)")
    young = None
    mixture = bool(config.species)
    if poisson_ratio is None:
        poisson_ratio = (c.material.poisson_ratio if c.material is not None and c.material.poisson_ratio is not None
                         and not mixture else lammps.DEFAULT_POISSON)
    if contact_fraction is None:
        if c.material is None:
            raise ConfigError(f"{config.source}: no [collision.material]: the material stiffness needs it "
                              "(give a contact fraction instead)")
        # a mixture: per pair of species Y with Y / (1 - nu^2) = 2 Y*_ij (the pair's effective modulus)
        young = pair_young_moduli(config, poisson_ratio) if mixture else reduced_young_modulus(config)
    if c.model == "elastic":
        prefactor, end = 0.0, "overlap"
    else:
        prefactor, end = (pair_prefactors(config) if mixture else reduced_prefactor(config)), c.contact_end
    if not Path(directory).is_dir():  # the export makes DIR itself, never its parents
        existing_directory(directory, f"--output {directory}")
    state = initial_state(config)
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
        time_origin=state.time, boundary=config.system.boundary, young_modulus=young, pressure=pressure,
        contact_pairs=contact_pairs, species=species_indices(config),
    )


def pair_young_moduli(config, poisson_ratio: float):
    """A mixture's LAMMPS E per pair of species (reduced units, (S, S)): E / (1 - nu^2) = 2 Y*_ij with
    Y*_ij the effective modulus of the two species' materials
    (:func:`granulargas.contact.material.effective_modulus`; constants of the species or of
    ``[collision.material]``), so that LAMMPS's explicit pair coefficient of hertz/material has the
    pair's stiffness."""
    import numpy as np

    m = config.collision.material
    unit = m.diameter**3 / (reference_mass_si(m) * m.speed_unit**2)  # Pa -> reduced energy / length^3
    consts = [(sp.young_modulus or m.young_modulus, sp.poisson_ratio if sp.poisson_ratio is not None
               else m.poisson_ratio) for sp in config.species]
    return np.array([[2.0 * (1.0 - poisson_ratio**2) * effective_modulus(*a, *b) * unit for b in consts]
                     for a in consts])
