"""Initial states: random non-overlapping placement (a lattice gas relaxed by
hard-sphere Monte Carlo) and Maxwell-Boltzmann velocities.

* :func:`random_state` -- the one route from particle sizes, masses, packing
  fraction, temperature and seed to a :class:`granulargas.state.State`
  (:mod:`~granulargas.initial.lattice_gas` explains the algorithm); config runs
  (:func:`granulargas.run.prepare.fresh_state`) go through it too;
* :func:`random_positions`, :func:`maxwell_velocities`, :func:`box_for_packing`,
  :func:`fluid_s0` -- its steps; :func:`maxwell_spins` -- the spins of rough particles.
"""

from granulargas.initial.lattice_gas import (
    box_for_packing,
    fluid_s0,
    maxwell_spins,
    maxwell_velocities,
    random_positions,
    random_state,
)

__all__ = ["box_for_packing", "fluid_s0", "maxwell_spins", "maxwell_velocities", "random_positions",
           "random_state"]
