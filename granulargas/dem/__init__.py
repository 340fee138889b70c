"""Time-stepped DEM (LAMMPS) with the same contact law as the event-driven engine.

* :mod:`~granulargas.dem.lammps` -- the contact mapping (Young modulus, Poisson
  ratio, dissipation time <-> our pair prefactor), LAMMPS data and input files,
  running ``lmp`` and reading its thermo output;
* :mod:`~granulargas.dem.export` -- a run config as a LAMMPS run with the same
  initial state (``granulargas export lammps``).
"""
