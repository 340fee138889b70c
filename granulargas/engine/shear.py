"""Uniform shear flow: the public description :class:`Shear`.

The flow u = a (y - L_y/2) x: Lees-Edwards boundaries on y in the engine
(:mod:`granulargas.engine._shear`), the homogeneous shear flow of the Enskog-Boltzmann
equation in the DSMC (:mod:`granulargas.dsmc._shear`). Optionally a thermostat holds the
temperature: the peculiar velocities are rescaled to it at the times (k + 1/2) dt (a
Gaussian thermostat applied at discrete times; the elastic gas needs one, since shear
only heats it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from granulargas.errors import ConfigError


@dataclass(frozen=True)
class Shear:
    """Uniform shear flow along x with the gradient along y.

    Attributes
    ----------
    rate : float
        The shear rate a > 0 (the image of the box one box up moves at a L_y along x).
    temperature : float or None
        The thermostat's temperature (None: no thermostat; viscous heating then balances
        the collisional loss of an inelastic gas).
    interval : float or None
        Time between the thermostat's rescalings (given with ``temperature``).
    """

    rate: float
    temperature: float | None = None
    interval: float | None = None

    def __post_init__(self):
        a = float(self.rate)
        if not (a > 0.0 and math.isfinite(a)):
            raise ConfigError(f"shear rate = {self.rate}: must be finite and > 0")
        object.__setattr__(self, "rate", a)
        if (self.temperature is None) != (self.interval is None):
            raise ConfigError("shear thermostat: give both temperature and interval, or neither")
        if self.temperature is not None:
            t, dt = float(self.temperature), float(self.interval)
            if not (t > 0.0 and math.isfinite(t)):
                raise ConfigError(f"thermostat temperature = {self.temperature}: must be finite and > 0")
            if not (dt > 0.0 and math.isfinite(dt)):
                raise ConfigError(f"thermostat interval = {self.interval}: must be finite and > 0")
            object.__setattr__(self, "temperature", t)
            object.__setattr__(self, "interval", dt)

    @property
    def thermostat(self) -> bool:
        return self.temperature is not None

    def first_step(self, time: float) -> int:
        """Index k of the first thermostat step (at (k + 1/2) interval) after ``time``."""
        if not self.thermostat:
            return 0
        k = max(0, int(math.floor(time / self.interval - 0.5)))
        while (k + 0.5) * self.interval <= time:
            k += 1
        return k
