"""granulargas: event-driven simulation of granular gases.

Collisions follow the viscoelastic coefficient of restitution eps(g) of
Schwager & Pöschel (1997), tabulated once by :mod:`granulargas.contact` and
looked up by the compiled event loop in :mod:`granulargas.engine`.
"""

import sys

from granulargas._moved import MovedModuleFinder

__version__ = "0.1.0"

# old module paths (granulargas._moved.MOVED) keep working, with a DeprecationWarning; first in
# line, so that no other installed copy of the package answers for an old name
if not any(isinstance(f, MovedModuleFinder) for f in sys.meta_path):
    sys.meta_path.insert(0, MovedModuleFinder())


def __getattr__(name):
    # Lazy: importing the package must not trigger numba compilation.
    if name in ("Simulation", "CollisionRule"):
        from granulargas import engine

        return getattr(engine, name)
    raise AttributeError(f"module 'granulargas' has no attribute {name!r}")
