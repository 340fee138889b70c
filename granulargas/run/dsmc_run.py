"""A config's DSMC run (``run.method = "dsmc"``) as the runner drives it.

:class:`DSMCRun` is a :class:`granulargas.dsmc.DSMC` with the few names the runner
(:mod:`granulargas.run.runner`) uses on an engine ``Simulation``: ``events`` (the
frames' step: pair collisions), ``synchronise()`` (nothing to do: the DSMC state is
always synchronised), ``positions``/``images`` (None: a homogeneous gas has none),
``boundary``. :func:`make_dsmc` builds it from a
:class:`granulargas.run.prepare.Setup`: the density is that of the config's box
(the volume of ``system.packing_fraction``), chi the Enskog value
:func:`granulargas.theory.contact_value` of that packing fraction (the one the
theory module uses), the collision rule the engine's (same restitution table and
pair prefactor), and the random streams seeded with ``system.seed``, or continued
from the restart file's stored DSMC state; ``[driving]`` gives the engine's white-noise
kicks (:class:`granulargas.engine.WhiteNoise`, the same kick law and random stream).
"""

from __future__ import annotations

import numpy as np

from granulargas.dsmc import DSMC
from granulargas.observables import kinetic_energy_momentum, species_moments
from granulargas.run.rough import rotational_observables


class DSMCRun(DSMC):
    """:class:`granulargas.dsmc.DSMC` with the runner's view of a simulation (module docstring)."""

    positions = None
    images = None
    last_collision = None

    @property
    def events(self) -> int:
        """The frames' step of a DSMC file: pair collisions so far."""
        return self.collisions

    @property
    def boundary(self) -> tuple:
        return self._boundary

    def synchronise(self):
        """Nothing to do without shear (velocities and time are always the state at :attr:`time`);
        under shear the stored velocities are brought to :attr:`time` (:meth:`DSMC.synchronise`)."""
        DSMC.synchronise(self)

    def observables(self) -> dict:
        """One observables sample (:mod:`granulargas.io.h5md`): no pressure; ``events`` is the
        count of candidate pairs drawn."""
        t, a2, a3 = self._moments()
        ke, *p = kinetic_energy_momentum(self._current_rec(), self.dimension, self._mass_arg)
        driven = {} if self.driving is None else {"injected_energy": float(self.injected_energy),
                                                   "kick_step": int(self.kick_step)}
        if self.shear is not None:
            if self.shear.thermostat:
                driven = {"injected_energy": float(self.injected_energy), "kick_step": 0}
            driven["pressure_tensor"] = self.pressure_tensor_window()
        return {**driven, **self.species_observables(),
            "temperature": float(t),
            "kinetic_energy": float(ke),
            "collisions": int(self.collisions),
            "events": int(self.candidates),
            "dissipated_energy": float(self.dissipated_energy),
            "momentum": np.array(p[:self.dimension], dtype=np.float64),
            "sonine_a2": float(a2),
            "sonine_a3": float(a3),
            **(rotational_observables(self) if self.tangential is not None else {}),
        }


    def species_observables(self) -> dict:
        """A mixture's observables: temperature and a2 of each species, collisions per pair of
        species (none without a pair table in the rule)."""
        if self._species is None:
            return {}
        temperature, a2 = species_moments(self.velocities, self.masses, self._species.of, self.rule.species)
        return {"species_temperature": temperature, "species_sonine_a2": a2,
                "species_collisions": self.species_collisions}


def make_dsmc(config, setup) -> DSMCRun:
    """The DSMC of a prepared config (module docstring): the volume of the state's box, the
    restart file's continuation if the state has one; a mixture's chi per pair of species
    (:func:`granulargas.run.prepare.mixture_contact_values`)."""
    dsmc = setup.parameters["dsmc"]
    chi = dsmc.get("chi_pairs", dsmc["chi"])
    return DSMCRun(setup.state, setup.rule, chi=chi, seed=config.system.seed, driving=setup.driving,
                   shear=setup.shear, tangential=setup.tangential)
