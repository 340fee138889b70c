"""granulargas: event-driven simulation of granular gases.

Collisions follow the viscoelastic coefficient of restitution eps(g) of
Schwager & Pöschel (1997), tabulated once by :mod:`granulargas.contact` and
looked up by the compiled event loop in :mod:`granulargas.engine`.

The names a notebook starts with (``import granulargas as gg``), each defined
in the module that ``_PUBLIC`` below names:

* a config run: :func:`load_config`, :func:`simulate`, :func:`load_run` and its
  :class:`Result` (the observables as a table, the snapshots, the analysis),
  :func:`analyze`;
* the engine and its initial states: :class:`Simulation`,
  :class:`CollisionRule`, :class:`TangentialRule` (rough particles), :class:`WhiteNoise`, :class:`DSMC`,
  :func:`random_state`, :class:`State` (the state a simulation takes whole);
* the contact: :func:`restitution` (eps of one impact's damping beta).

Importing the package loads none of them: each is imported on first use
(module ``__getattr__``), so that ``granulargas --help`` does not load numba.
"""

import importlib as _importlib

__version__ = "0.1.0"

#: public name -> "module:attribute" that defines it (imported on first access). No name may be
#: that of a subpackage: importing ``granulargas.run`` sets the attribute ``run`` of the package.
_PUBLIC = {
    # a config run and its result
    "load_config": "granulargas.io.config:load_config",
    "simulate": "granulargas.api:simulate",
    "load_run": "granulargas.api:load_run",
    "Result": "granulargas.api:Result",
    "analyze": "granulargas.api:analyze",
    # the engine and the initial states
    "Simulation": "granulargas.engine:Simulation",
    "CollisionRule": "granulargas.engine:CollisionRule",
    "TangentialRule": "granulargas.engine:TangentialRule",
    "WhiteNoise": "granulargas.engine:WhiteNoise",
    "DSMC": "granulargas.dsmc:DSMC",
    "random_state": "granulargas.initial:random_state",
    "State": "granulargas.state:State",
    # the contact
    "restitution": "granulargas.contact:restitution",
}

__all__ = sorted(_PUBLIC)


def __getattr__(name):
    # Lazy: importing the package must not import numba (granulargas --help stays fast).
    target = _PUBLIC.get(name)
    if target is None:
        raise AttributeError(f"module 'granulargas' has no attribute {name!r}")
    module, _, attribute = target.partition(":")
    value = getattr(_importlib.import_module(module), attribute)
    globals()[name] = value  # later look-ups skip __getattr__
    return value


def __dir__():
    return sorted(set(globals()) | set(_PUBLIC))
