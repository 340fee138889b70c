"""Event-driven engine: hard spheres (3D) and disks (2D), periodic or walled per axis.

Public API (contract in ARCHITECTURE.md)::

    from granulargas.engine import Simulation, CollisionRule, TangentialRule, WhiteNoise, Wall, Walls
"""

from granulargas.engine.driving import WhiteNoise
from granulargas.engine.rules import CollisionRule
from granulargas.engine.simulation import Simulation
from granulargas.engine.tangential import TangentialRule
from granulargas.engine.walls import Wall, Walls

__all__ = ["Simulation", "CollisionRule", "TangentialRule", "WhiteNoise", "Wall", "Walls"]
