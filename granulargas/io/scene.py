"""What kind of run a config or a file holds: the scene, and which statements apply to it.

``granulargas advise``, the run summary (:mod:`granulargas.run.validity`,
:mod:`granulargas.run.advise`) and ``granulargas analyze`` each say things that hold
for some runs only: a box longer than the shear-instability length clusters, but a
DSMC run has no box; a cooling curve says nothing about a driven gas. Each of them
reads the run's :class:`Scene` (from the config, :meth:`Scene.from_config`, or from
a file, :meth:`Scene.from_file`) and asks :meth:`Scene.shows` whether a statement
applies, so the scenes of every statement are listed once, in :data:`STATEMENTS`.

A scene is a handful of orthogonal fields:

* ``method``: ``"edmd"`` (the event-driven engine: particles in space) or ``"dsmc"``
  (the homogeneous Enskog-Boltzmann gas: velocities only, no space);
* ``model``: the collision law, ``"elastic"``, ``"constant"``, ``"viscoelastic"``, or
  ``"unknown"`` (a file that does not record it);
* ``kind``: how the energy goes, ``"cooling"`` (dissipative, no driving), ``"driven"``
  (white-noise driving), ``"shear"`` (uniform shear flow: viscous heating against the
  collisional loss, or a thermostat), ``"vibrated"`` (gravity, or thermal or vibrating walls:
  the walls put energy in, or the gas settles on a floor), ``"elastic"`` (conserved) or
  ``"unknown"``;
* ``walls``, ``gravity``, ``resolved`` (collisions that take time), ``polydisperse``, ``tc_model``
  (the TC model's elastic collisions), ``material`` (the material route: the contact
  stiffness and so the contact time is known), ``rough`` (rough particles: spins and a
  tangential law; two temperatures), ``mixture`` (species, ``[[species]]``: the temperature
  of each species; the one-component theory is that of the mean particle).

A new scene (another boundary, a force field, a tangential law, species) adds a field
here, sets it in both constructors, and adjusts the predicates of the statements it
changes.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Callable

import numpy as np

from granulargas.io.h5md import load_snapshot, read_parameters

__all__ = ["Scene", "Statement", "STATEMENTS", "MODELS", "KINDS"]

#: collision models the theory knows
MODELS = ("elastic", "constant", "viscoelastic")
#: how a run's energy goes
KINDS = ("cooling", "driven", "shear", "vibrated", "elastic", "unknown")


@dataclass(frozen=True)
class Scene:
    """The kind of run (module docstring). Build with :meth:`from_config` or :meth:`from_file`."""

    method: str = "edmd"
    dimension: int = 3
    model: str = "elastic"
    kind: str = "elastic"
    walls: bool = False
    gravity: bool = False
    resolved: bool = False
    polydisperse: bool = False
    tc_model: bool = False
    material: bool = False
    rough: bool = False
    mixture: bool = False

    @property
    def space(self) -> bool:
        """Whether the run has positions (the engine) or not (DSMC: a homogeneous gas)."""
        return self.method != "dsmc"

    def shows(self, statement: str) -> bool:
        """Whether ``statement`` (a key of :data:`STATEMENTS`) applies to this scene."""
        return STATEMENTS[statement].applies(self)

    @classmethod
    def from_config(cls, config) -> "Scene":
        """The scene of a :class:`granulargas.io.config.RunConfig`."""
        s, c, p = config.system, config.collision, config.particles
        driving = config.driving
        gravity = config.gravity is not None and any(config.gravity.vector)
        vibrated = gravity or (config.walls is not None and config.walls.moving)
        # a mixture's tables per pair: it cools if any pair does
        eps = min(c.restitution.values()) if isinstance(c.restitution, dict) else c.restitution
        damping = max(c.damping.values()) if isinstance(c.damping, dict) else c.damping
        mixture = bool(getattr(config, "species", ()))
        return cls(
            method=config.run.method, dimension=s.dimension, model=c.model,
            kind="vibrated" if vibrated else _kind(c.model, eps, damping if c.material is None else 1.0,
                                                    driving is not None and driving.heating_rate > 0.0,
                                                    getattr(config, "shear", None) is not None),
            walls="wall" in s.boundary, gravity=gravity, resolved=c.duration == "resolved",
            polydisperse=bool(not mixture and p.polydisperse and p.diameter_max > p.diameter_min),
            tc_model=c.tc_time is not None,
            material=c.material is not None, mixture=mixture,
            rough=c.tangential is not None,
        )

    @classmethod
    def from_parameters(cls, parameters: dict, dimension: int, boundary=(), radii=None, masses=None,
                        contacts: bool = False) -> "Scene":
        """The scene of a file: its ``parameters/`` group (:func:`granulargas.io.h5md.read_parameters`),
        the box's boundary per axis, the particles' radii and masses, and whether it stores
        contacts under way (collisions that take time)."""
        coll = parameters.get("collision", {}) or {}
        model = str(coll.get("model", "unknown"))
        if model not in MODELS:
            model = "unknown"
        drv = parameters.get("driving")
        driven = isinstance(drv, dict) and _float(drv.get("heating_rate"), 0.0) > 0.0
        sheared = isinstance(parameters.get("shear"), dict)
        material = isinstance(parameters.get("units_si"), dict)
        grav = parameters.get("gravity")
        gravity = isinstance(grav, dict) and bool(np.any(np.asarray(grav.get("acceleration", 1.0), float) != 0.0))
        walls = parameters.get("walls")
        moving = isinstance(walls, dict) and any(isinstance(w, dict) and w.get("kind") in ("thermal", "vibrating")
                                                  for w in walls.values())
        mixture = isinstance(parameters.get("species"), dict)
        poly = False
        for values in (radii, masses):
            if not mixture and values is not None and np.size(values) and np.ptp(np.asarray(values)) > 0:
                poly = True
        return cls(
            method=str(parameters.get("method", "edmd")), dimension=int(dimension), model=model,
            kind="vibrated" if (gravity or moving) and model != "unknown" else
            _kind(model, _float(coll.get("restitution"), None), _float(coll.get("prefactor"), None), driven,
                  sheared),
            walls="wall" in tuple(boundary), gravity=gravity,
            resolved=bool(contacts) or coll.get("duration") == "resolved",
            polydisperse=poly, tc_model=_float(coll.get("tc_time"), None) is not None, material=material,
            mixture=mixture, rough=isinstance(parameters.get("tangential"), dict),
        )

    @classmethod
    def from_file(cls, path) -> "Scene":
        """The scene of one of our H5MD files."""
        snap = load_snapshot(path, 0)
        return cls.from_parameters(read_parameters(path), snap.box.shape[0], snap.boundary, snap.radii,
                                   snap.masses, snap.contact_until is not None)

    def describe(self) -> str:
        """One line: "EDMD, 3D, cooling, constant eps, walls" and the like."""
        law = {"constant": "constant eps", "viscoelastic": "viscoelastic eps(g)", "elastic": "elastic",
               "unknown": "collision model not recorded"}[self.model]
        parts = ["DSMC (no space)" if self.method == "dsmc" else "EDMD", f"{self.dimension}D"]
        if self.kind not in ("elastic", "unknown"):
            parts.append("uniform shear flow" if self.kind == "shear" else self.kind)
        parts.append(law)
        parts += [name for name, on in (("walls", self.walls), ("gravity", self.gravity),
                                        ("collisions that take time", self.resolved),
                                        ("polydisperse", self.polydisperse), ("TC model", self.tc_model),
                                        ("material route", self.material), ("mixture", self.mixture),
                                        ("rough particles", self.rough)) if on]
        return ", ".join(parts)

    def as_dict(self) -> dict:
        """The fields, for JSON."""
        return asdict(self)


def _float(value, default):
    try:
        return default if value is None else float(value)
    except (TypeError, ValueError):
        return default


def _kind(model: str, restitution, damping, driven: bool, sheared: bool = False) -> str:
    """How the energy of a run goes: "shear", "driven", "cooling", "elastic" or "unknown"."""
    if model == "unknown":
        return "unknown"
    if sheared:
        return "shear"
    if driven:
        return "driven"
    if model == "constant":
        return "unknown" if restitution is None else "cooling" if restitution < 1.0 else "elastic"
    if model == "viscoelastic":
        return "unknown" if damping is None else "cooling" if damping > 0.0 else "elastic"
    return "elastic"


@dataclass(frozen=True)
class Statement:
    """A statement the tools make about a run, and the scenes it applies to."""

    text: str
    applies: Callable[[Scene], bool]


def _cools(s: Scene) -> bool:
    return s.kind == "cooling"


#: every statement of advise, the run summary and analyze that holds for some scenes only
STATEMENTS = {
    "cooling_curve": Statement(
        "T(t) of the homogeneous cooling state (kinetic theory)", _cools),
    "driven_state": Statement(
        "relaxation to the steady temperature of the white-noise driving", lambda s: s.kind == "driven"),
    "shear_state": Statement(
        "uniform shear flow: the steady state of viscous heating against the collisional loss (or the "
        "thermostat's), a*, eta*, the normal stresses (Grad solution)", lambda s: s.kind == "shear"),
    "conserved_energy": Statement(
        "elastic collisions: T stays at T0 (energy drift, equation of state)", lambda s: s.kind == "elastic"),
    "eps_spread": Statement(
        "the spread of eps over thermal impacts between the run's hottest and coldest moments",
        lambda s: s.model == "viscoelastic" and s.kind in ("cooling", "driven", "shear")),
    "constant_or_viscoelastic": Statement(
        "best constant eps against the viscoelastic T(t), or the damping of the same initial cooling rate "
        "(compares cooling curves of smooth particles of one kind)",
        lambda s: _cools(s) and s.model in ("constant", "viscoelastic") and not s.rough and not s.mixture),
    "rough": Statement(
        "two temperatures (translation, rotation) by the Maxwellian energy balances, and how far smooth "
        "particles would take T_tr(t)", lambda s: s.rough and not s.mixture and s.kind != "vibrated"),
    "instability": Statement(
        "box length against the shear-instability length L_c: clusters and shear modes in space",
        lambda s: s.space and _cools(s)),
    "homogeneous_by_construction": Statement(
        "DSMC has no space: the homogeneous gas, whatever the box; a real box of it clusters beyond L_c",
        lambda s: not s.space and _cools(s)),
    "collapse": Statement(
        "inelastic collapse of a constant eps without the TC model (dense regions in space)",
        lambda s: s.space and s.model == "constant" and not s.tc_model and s.kind in ("cooling", "driven", "shear")),
    "pressure": Statement(
        "the pressure (collisional virial) and Z = P/(nT)", lambda s: s.space and not s.gravity),
    "wall_pressure": Statement(
        "the wall pressure and the density profile across the walls", lambda s: s.walls and s.kind != "vibrated"),
    "vibrated_scene": Statement(
        "the scene of gravity and thermal or vibrating walls: Gamma, the leading-order bed, the energy balance, "
        "the profiles along gravity", lambda s: s.kind == "vibrated"),
    "contact_time": Statement(
        "t_c / t_free of the contacts (material route) or tc_time / t_free (TC model)",
        lambda s: (s.model == "viscoelastic" and s.material) or s.tc_model),
    "contact_time_unknown": Statement(
        "t_c / t_free not determined (the damping route fixes beta only)",
        lambda s: s.model == "viscoelastic" and not s.material and s.kind != "elastic"),
    "duration": Statement(
        "instantaneous or resolved collisions, or DEM, from the contact time (material route)",
        lambda s: s.model == "viscoelastic" and s.material),
    "three_body": Statement(
        "collisions that met a pair still in contact", lambda s: s.resolved),
    "polydisperse_theory": Statement(
        "the theory is that of identical particles of the mean diameter", lambda s: s.polydisperse),
    "species_temperatures": Statement(
        "the temperature of each species of a mixture (Garzó & Dufty 1999), which equipartition does not fix",
        lambda s: s.mixture and not s.rough and s.model != "unknown"),
    "mixture_mean_particle": Statement(
        "a mixture's one-component predictions are those of its mean particle and mean law", lambda s: s.mixture),
    "theory_comparison": Statement(
        "any comparison with kinetic theory (needs the collision model)", lambda s: s.model != "unknown"),
}
