"""The initial state of a run: the public engine state to start from."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class InitialState:
    """Public engine state to start from, in particle-id order (float64 / int64, C-contiguous).

    Attributes
    ----------
    positions, velocities : arrays (N, d)
    radii, masses : arrays (N,)
    box : array (d,)
        Box sides.
    boundary : tuple of str, optional
        One entry per axis, "periodic" or "wall" (default all periodic).
    species : array (N,) int32, optional
        Species index of each particle (default all 0).
    images : array (N, d) int64, optional
        Periodic images (a restart continues the unwrapped trajectories).
    time, collisions, events, dissipated_energy :
        Clock and counters to continue from (0 for a fresh state).
    wall_collisions, injected_energy, kick_step :
        Sphere-wall collisions, energy put in by the driving, index of the next driving
        step (restarts; None: the first step after ``time``).
    last_collision : array (N,), optional
        Time of each particle's last collision (TC model restarts).
    contact_until, contact_partner : arrays (N,), optional
        Contacts under way of collisions that take time (restarts; see
        :class:`granulargas.engine.Simulation`).
    three_body_contacts : int
        Collisions with a pair still in contact so far (restarts).
    source : str, optional
        File the state was read from (restarts).
    """

    positions: np.ndarray
    velocities: np.ndarray
    radii: np.ndarray
    masses: np.ndarray
    box: np.ndarray
    boundary: tuple | None = None
    species: np.ndarray | None = None
    images: np.ndarray | None = None
    time: float = 0.0
    collisions: int = 0
    events: int = 0
    dissipated_energy: float = 0.0
    wall_collisions: int = 0
    injected_energy: float = 0.0
    kick_step: int | None = None
    last_collision: np.ndarray | None = None
    source: str | None = None
    contact_until: np.ndarray | None = None
    contact_partner: np.ndarray | None = None
    three_body_contacts: int = 0

    def __post_init__(self):
        if self.species is None:
            self.species = np.zeros(len(self.radii), dtype=np.int32)

    def as_kwargs(self) -> dict:
        """The particle arrays and the box as keyword arguments of
        :class:`granulargas.engine.Simulation` (a fresh start)."""
        out = dict(positions=self.positions, velocities=self.velocities, radii=self.radii,
                   masses=self.masses, box=self.box)
        if self.boundary is not None and "wall" in self.boundary:
            out["boundary"] = tuple(self.boundary)
        return out
