"""Rough particles in a run: the observables a rough run samples.

``rotational_temperature`` and the cumulants ``cumulant_a20``, ``cumulant_a02``,
``cumulant_a11`` (:func:`granulargas.observables.rough_moments`: velocities scaled by the
translational, spins by the rotational temperature) of an engine or DSMC run with a
tangential rule; ``temperature`` stays the translational one.
"""

from __future__ import annotations

import numpy as np

from granulargas.io.h5md import ROUGH_OBSERVABLES
from granulargas.observables import rotational_observables as _moments


def rotational_observables(sim) -> dict:
    """The rough observables of a simulation (``Simulation`` or ``DSMC`` with a tangential rule)."""
    moments = sim.inertia * sim.masses * sim.radii**2
    out = _moments(sim.velocities, sim.angular_velocities, sim.masses, moments)
    return {name: float(out[name]) for name in ROUGH_OBSERVABLES}


def moments_of_inertia(inertia, masses, radii) -> np.ndarray:
    """I_i = kappa_i m_i R_i^2."""
    return np.asarray(inertia) * np.asarray(masses) * np.asarray(radii) ** 2
