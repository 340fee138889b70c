"""Event-driven engine: hard spheres (3D) and disks (2D) in a periodic box.

Public API (contract in ARCHITECTURE.md)::

    from granulargas.engine import Simulation, CollisionRule
"""

from granulargas.engine.rules import CollisionRule
from granulargas.engine.simulation import Simulation

__all__ = ["Simulation", "CollisionRule"]
