"""What a run compiles: the variants of the package's compiled code, named for the user.

numba compiles a kernel for the types of its arguments, and the engine is built so
that a feature a run does not use leaves no code in its loop (ARCHITECTURE.md,
``mode_flags``): each kind of run therefore compiles a loop of its own, once, the
first time such a run is made, and every later run of that kind loads it from the
cache (:func:`granulargas._numba.cache_location`). :data:`VARIANTS` lists these
kinds, one entry each: its name (``granulargas compile NAME``), what it is (the
line a run prints before it compiles it), the tiny run that compiles it, and
which runs use it. What does *not* make a variant: the dimension (2D runs use the
3D kernels with z = 0), the collision rule (elastic, constant, viscoelastic and
the TC model share one loop), polydispersity (run-time data), the numbers of
particles and of snapshots. Species do (``[[species]]``: the loops with the law per
pair of species). Walls at rest are a second build of each engine variant without a
wall scene (a box without wall axes compiles its loop without the walls' code): the
variant's tiny build makes both, a periodic run and one with a wall axis
(:func:`walled_twin`).

A feature that adds a compiled variant adds one entry here: its tiny config (the
keys that select it, on top of :data:`TINY`), the variants it builds on
(``after``: their kernels are compiled first, so that parallel builds do not
compile the same kernel twice), and the test of a config that selects it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from granulargas.engine.simulation import neighbour_mode
from granulargas.initial.lattice_gas import SORTED_MIN_PARTICLES
from granulargas.io.config import RunConfig, parse_config

#: the tiny run every engine variant's build starts from (3D, 64 spheres, viscoelastic)
TINY = {
    "system.dimension": 3, "system.particles": 64, "system.packing_fraction": 0.05, "system.seed": 1,
    "collision.model": "viscoelastic", "collision.damping": 0.1,
    "run.collisions_per_particle": 4, "output.snapshots": 2,
}
#: a soft material for collisions that take time (t_c / t_free ~ 0.1 at packing 0.1)
_MATERIAL = {
    "collision.material.young_modulus": 1e6, "collision.material.poisson_ratio": 0.3,
    "collision.material.dissipation_time": 1e-5, "collision.material.diameter": 0.01,
    "collision.material.density": 1000, "collision.material.speed_unit": 0.5,
    "collision.duration": "resolved", "system.packing_fraction": 0.1, "collision.damping": None,
}
_DRIVEN = {"driving.model": "white_noise", "driving.heating_rate": 0.005}
#: a floor under gravity; a vibrating wall without and with gravity (the loops of the flight and of the
#: wall kinds)
_GRAVITY = {"system.boundary": ["periodic", "periodic", "wall"], "gravity.acceleration": [0.0, 0.0, -0.1],
            "collision.elastic_below": 1e-3}
_WALLS = {"system.boundary": ["periodic", "periodic", "wall"], "collision.elastic_below": 1e-3,
          "walls.z_low.kind": "vibrating", "walls.z_low.amplitude": 0.05, "walls.z_low.frequency": 1.0}
_GRAVITY_WALLS = {**_GRAVITY, **_WALLS}
_DSMC = {"run.method": "dsmc", "system.particles": 256}
#: rough particles (spins and a tangential restitution): a loop of their own
_ROUGH = {"collision.tangential.restitution": 0.0}
_ROUGH_DRIVEN = {**_DRIVEN, "driving.rotational_fraction": 0.5}
#: uniform shear flow: Lees-Edwards boundaries on y (the sheared loops of both neighbour modes and the DSMC
#: of uniform shear flow), a constant restitution as in the example configs, the rate of the steady state at T0
_SHEAR = {"system.boundary": ["periodic", "lees-edwards", "periodic"], "shear.rate": 0.292,
          "collision.model": "constant", "collision.restitution": 0.8, "collision.damping": None}
#: a mixture: two species, the law per pair of species (the loops compiled with the species record)
_MIXTURE = {"species": [{"name": "a", "fraction": 0.5}, {"name": "b", "fraction": 0.5, "diameter": 0.8}],
            "collision.damping": {"a-a": 0.1, "a-b": 0.1, "b-b": 0.1}}


def _placement(config: RunConfig) -> bool:
    return config.run.method == "edmd" and not config.initial.from_file


def scene_kind(config: RunConfig) -> str | None:
    """The engine's flight and wall kinds: "gravity-walls" (gravity, thermal or vibrating
    walls), "walls" (thermal or vibrating walls), "gravity" (hard walls at rest) or None."""
    walls = config.walls is not None and config.walls.moving
    gravity = config.gravity is not None and any(config.gravity.vector)
    if walls:
        return "gravity-walls" if gravity else "walls"
    return "gravity" if gravity else None


def _engine(mode: str, resolved: bool = False, driven: bool = False, rough: bool = False, mixture: bool = False,
            scene: str | None = None, sheared: bool = False) -> Callable[[RunConfig, str], bool]:
    """Runs of the event-driven engine in neighbour mode ``mode`` (with collisions that take
    time: ``resolved``; ``driven``: the driven ones only; ``rough``: rough particles;
    ``mixture``: those with species; ``scene``: their :func:`scene_kind`; ``sheared``: those
    with ``[shear]``, Lees-Edwards boundaries)."""
    def uses(config: RunConfig, neighbours: str) -> bool:
        return (config.run.method == "edmd" and neighbours == mode
                and (config.collision.duration == "resolved") == resolved
                and config.collision.rough == rough
                and (config.driving is not None or not driven) and bool(config.species) == mixture
                and scene_kind(config) == scene and (config.shear is not None) == sheared)
    return uses


def _dsmc(driven: bool = False, rough: bool = False, mixture: bool = False,
          sheared: bool = False) -> Callable[[RunConfig, str], bool]:
    return lambda config, neighbours: (config.run.method == "dsmc" and config.collision.rough == rough
                                       and (config.driving is not None or not driven)
                                       and bool(config.species) == mixture and (config.shear is not None) == sheared)


@dataclass(frozen=True)
class Variant:
    """One compiled variant: ``name``, ``what`` it is (for the user), the ``config`` keys of
    its tiny build (on top of :data:`TINY`; None: ``build`` instead), the variants whose
    kernels it reuses (``after``: built first), and ``uses(config, neighbours)``: whether
    a run of ``config`` in that neighbour mode needs it."""

    name: str
    what: str
    config: dict | None
    uses: Callable[[RunConfig, str], bool]
    after: tuple = ()
    build: Callable[[], None] | None = field(default=None, compare=False)
    #: a run announces the variant before compiling it; the initial placement compiles
    #: before the run can tell a bad config from a good one (a placement too dense for
    #: its radii fails there), and bad input gets one line on stderr: not announced
    announced: bool = True

    @property
    def walled(self) -> bool:
        """Whether the variant has a second build with walls at rest (:func:`walled_twin`):
        the engine's variants whose tiny run has no wall axis (collisions that take time
        have periodic boundaries only)."""
        return (self.build is None and self.config.get("run.method", "edmd") == "edmd"
                and "wall" not in self.config.get("system.boundary", ())
                and self.config.get("collision.duration") != "resolved")


def _build_placement():
    """The initial placement's kernels of small systems: sweeps, and the growth steps with
    pushes that dense and polydisperse states need."""
    from granulargas.initial import random_state

    random_state(64, 0.05, 3, seed=1)
    random_state(64, 0.45, 3, seed=1, radii=[0.4, 0.5] * 32)


def _build_large_placement():
    """The large systems' placement: sweeps over sorted particles (threads) and the compression."""
    from granulargas.initial import random_state

    random_state(SORTED_MIN_PARTICLES, 0.45, 3, seed=1)


#: every compiled variant, one entry each (module docstring)
VARIANTS = (
    Variant("placement", "the initial placement", None, lambda c, m: _placement(c), build=_build_placement,
            announced=False),
    Variant("placement-large", f"the initial placement of large systems (from {SORTED_MIN_PARTICLES} particles)",
            None, lambda c, m: _placement(c) and c.system.particles >= SORTED_MIN_PARTICLES,
            after=("placement",), build=_build_large_placement, announced=False),
    Variant("lists", "the neighbour-list engine", {"run.neighbours": "lists"}, _engine("lists"),
            after=("placement",)),
    Variant("cells", "the cell-crossing engine", {"run.neighbours": "cells"}, _engine("cells"),
            after=("placement", "lists")),
    Variant("lists-driven", "its driving step", {"run.neighbours": "lists", **_DRIVEN},
            _engine("lists", driven=True), after=("lists",)),
    Variant("cells-driven", "its driving step", {"run.neighbours": "cells", **_DRIVEN},
            _engine("cells", driven=True), after=("cells",)),
    Variant("lists-gravity", "the neighbour-list engine under gravity", {"run.neighbours": "lists", **_GRAVITY},
            _engine("lists", scene="gravity"), after=("lists",)),
    Variant("cells-gravity", "the cell-crossing engine under gravity", {"run.neighbours": "cells", **_GRAVITY},
            _engine("cells", scene="gravity"), after=("cells",)),
    Variant("lists-walls", "the neighbour-list engine with thermal or vibrating walls",
            {"run.neighbours": "lists", **_WALLS}, _engine("lists", scene="walls"), after=("lists",)),
    Variant("cells-walls", "the cell-crossing engine with thermal or vibrating walls",
            {"run.neighbours": "cells", **_WALLS}, _engine("cells", scene="walls"), after=("cells",)),
    Variant("lists-gravity-walls", "the neighbour-list engine under gravity with thermal or vibrating walls",
            {"run.neighbours": "lists", **_GRAVITY_WALLS}, _engine("lists", scene="gravity-walls"),
            after=("lists-gravity", "lists-walls")),
    Variant("cells-gravity-walls", "the cell-crossing engine under gravity with thermal or vibrating walls",
            {"run.neighbours": "cells", **_GRAVITY_WALLS}, _engine("cells", scene="gravity-walls"),
            after=("cells-gravity", "cells-walls")),
    Variant("resolved", "the engine of collisions that take time", {"run.neighbours": "lists", **_MATERIAL},
            _engine("lists", resolved=True), after=("placement", "lists")),
    Variant("resolved-driven", "its driving step", {"run.neighbours": "lists", **_MATERIAL, **_DRIVEN},
            _engine("lists", resolved=True, driven=True), after=("resolved",)),
    Variant("dsmc", "the DSMC", _DSMC, _dsmc()),
    Variant("dsmc-driven", "its driving step", {**_DSMC, **_DRIVEN}, _dsmc(driven=True), after=("dsmc",)),
    Variant("lists-rough", "the neighbour-list engine of rough particles", {"run.neighbours": "lists", **_ROUGH},
            _engine("lists", rough=True), after=("placement", "lists")),
    Variant("cells-rough", "the cell-crossing engine of rough particles", {"run.neighbours": "cells", **_ROUGH},
            _engine("cells", rough=True), after=("placement", "cells")),
    Variant("lists-rough-driven", "its driving step", {"run.neighbours": "lists", **_ROUGH, **_ROUGH_DRIVEN},
            _engine("lists", driven=True, rough=True), after=("lists-rough",)),
    Variant("cells-rough-driven", "its driving step", {"run.neighbours": "cells", **_ROUGH, **_ROUGH_DRIVEN},
            _engine("cells", driven=True, rough=True), after=("cells-rough",)),
    Variant("dsmc-rough", "the DSMC of rough particles", {**_DSMC, **_ROUGH}, _dsmc(rough=True), after=("dsmc",)),
    Variant("dsmc-rough-driven", "its driving step", {**_DSMC, **_ROUGH, **_ROUGH_DRIVEN},
            _dsmc(driven=True, rough=True), after=("dsmc-rough",)),
    Variant("lists-mixture", "the neighbour-list engine of mixtures", {"run.neighbours": "lists", **_MIXTURE},
            _engine("lists", mixture=True), after=("placement", "lists")),
    Variant("cells-mixture", "the cell-crossing engine of mixtures", {"run.neighbours": "cells", **_MIXTURE},
            _engine("cells", mixture=True), after=("placement", "cells")),
    Variant("lists-mixture-driven", "its driving step", {"run.neighbours": "lists", **_MIXTURE, **_DRIVEN},
            _engine("lists", driven=True, mixture=True), after=("lists-mixture",)),
    Variant("cells-mixture-driven", "its driving step", {"run.neighbours": "cells", **_MIXTURE, **_DRIVEN},
            _engine("cells", driven=True, mixture=True), after=("cells-mixture",)),
    Variant("dsmc-mixture", "the DSMC of mixtures", {**_DSMC, **_MIXTURE}, _dsmc(mixture=True), after=("dsmc",)),
    Variant("dsmc-mixture-driven", "its driving step", {**_DSMC, **_MIXTURE, **_DRIVEN},
            _dsmc(driven=True, mixture=True), after=("dsmc-mixture",)),
    Variant("lists-shear", "the neighbour-list engine of uniform shear flow (Lees-Edwards boundaries)",
            {"run.neighbours": "lists", **_SHEAR}, _engine("lists", sheared=True), after=("placement", "lists")),
    Variant("cells-shear", "the cell-crossing engine of uniform shear flow (Lees-Edwards boundaries)",
            {"run.neighbours": "cells", **_SHEAR}, _engine("cells", sheared=True), after=("placement", "cells")),
    Variant("dsmc-shear", "the DSMC of uniform shear flow", {**_DSMC, **_SHEAR}, _dsmc(sheared=True),
            after=("dsmc",)),
)
BY_NAME = {v.name: v for v in VARIANTS}


def run_neighbours(config: RunConfig, packing: float | None = None) -> str:
    """The engine's neighbour mode for ``config`` ("auto" resolved as the engine does, at the
    config's packing fraction or at ``packing``, the state's own)."""
    if config.collision.duration == "resolved":
        return "lists"
    eta = config.system.packing_fraction if packing is None else packing
    return neighbour_mode(config.run.neighbours, eta, config.system.dimension)


def variants_for(config: RunConfig, neighbours: str | None = None) -> list[Variant]:
    """The variants a run of ``config`` (in neighbour mode ``neighbours``, default
    :func:`run_neighbours`) compiles the first time it is made."""
    mode = neighbours or run_neighbours(config)
    return [v for v in VARIANTS if v.uses(config, mode)]


def describe(variants) -> str:
    """``the initial placement and the cell-crossing engine``: the variants' ``what``, joined
    (a driving step, "its driving step", follows its engine)."""
    parts = [v.what for v in variants]
    if not parts:
        return "the run's kernels"
    return parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]


def tiny_config(variant: Variant, directory, extra: dict | None = None, suffix: str = "") -> RunConfig:
    """The tiny run that compiles ``variant`` (its output file in ``directory``); ``extra``: config
    keys on top of the variant's, ``suffix``: added to its name (output file, config source)."""
    label = variant.name + suffix
    keys = {**TINY, **variant.config, **(extra or {}), "output.file": str(Path(directory) / f"{label}.h5")}
    species = keys.pop("species", [])
    sections: dict[str, dict] = {}
    for key, value in keys.items():
        if value is None:
            continue
        section, _, name = key.rpartition(".")
        sections.setdefault(section, {})[name] = value
    text = []
    for section, values in sections.items():
        text.append(f"[{section}]")
        text += [f"{name} = {_toml(value)}" for name, value in values.items()]
    for table in species:
        text.append("[[species]]")
        text += [f"{name} = {_toml(value)}" for name, value in table.items()]
    return parse_config("\n".join(text) + "\n", source=f"<{label}>")


def walled_twin(variant: Variant, directory) -> RunConfig:
    """The tiny run of ``variant`` in a box with walls at rest on z (its loop's second build,
    with the walls' code; :attr:`Variant.walled`)."""
    boundary = list(variant.config.get("system.boundary", ["periodic"] * 3))
    boundary[2] = "wall"
    return tiny_config(variant, directory, {"system.boundary": boundary}, suffix="-walled")


def _toml(value) -> str:
    """A value of a tiny config as TOML (inline tables for dicts)."""
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{json.dumps(k)} = {_toml(v)}" for k, v in value.items()) + " }"
    return json.dumps(value)
