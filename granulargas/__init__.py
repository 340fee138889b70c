"""granulargas: event-driven simulation of granular gases.

Collisions follow the viscoelastic coefficient of restitution eps(g) of
Schwager & Pöschel (1997), tabulated once by :mod:`granulargas.contact` and
looked up by the compiled event loop in :mod:`granulargas.engine`.
"""

__version__ = "0.1.0"


def __getattr__(name):
    # Lazy: importing the package must not trigger numba compilation.
    if name in ("Simulation", "CollisionRule"):
        from granulargas import engine

        return getattr(engine, name)
    raise AttributeError(f"module 'granulargas' has no attribute {name!r}")
