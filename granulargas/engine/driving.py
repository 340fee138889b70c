"""Driving (energy input) of a granular gas: the white-noise thermostat.

A :class:`WhiteNoise` is a small frozen description; the compiled loop applies
its kicks (:mod:`granulargas.engine._drive`) every ``interval`` time units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from granulargas.errors import ConfigError


@dataclass(frozen=True)
class WhiteNoise:
    """Independent Gaussian velocity kicks to every particle, momentum-conserving.

    Attributes
    ----------
    heating_rate : float
        H >= 0: the driving alone raises the granular temperature as dT/dt = H
        (reduced units T0 per time unit).
    interval : float
        Time between kicks dt_k > 0 (kicks at (k + 1/2) dt_k, k = 0, 1, ...); the
        steady state does not depend on it once
        zeta(T) dt_k << 1 (zeta the cooling rate; see
        :func:`granulargas.theory.driving_interval`).
    seed : int
        Seed of the kicks' counter-based random stream (0 <= seed < 2^64).
    rotational_fraction : float
        Rough particles: the fraction lambda of the power (d/2 H per particle) that goes to the
        spins as random angular-velocity kicks (the splitting thermostat of Megías & Santos
        2022); the velocities then get (1 - lambda) H. 0 <= lambda <= 1; smooth particles
        need 0.
    """

    heating_rate: float
    interval: float
    seed: int = 0
    rotational_fraction: float = 0.0

    @property
    def translational_rate(self) -> float:
        """dT_tr/dt of the velocity kicks alone, (1 - lambda) H."""
        return (1.0 - self.rotational_fraction) * self.heating_rate

    def rotational_rate(self, dimension: int) -> float:
        """dT_rot/dt of the spin kicks alone, lambda H d_t / d_r (3D: lambda H; 2D: 2 lambda H)."""
        return self.rotational_fraction * self.heating_rate * (1.0 if dimension == 3 else 2.0)

    def __post_init__(self):
        h, dt = float(self.heating_rate), float(self.interval)
        if not (h >= 0.0 and math.isfinite(h)):
            raise ConfigError(f"heating_rate = {self.heating_rate}: must be finite and >= 0")
        if not (dt > 0.0 and math.isfinite(dt)):
            raise ConfigError(f"driving interval = {self.interval}: must be finite and > 0")
        if not 0 <= int(self.seed) < 2**64:
            raise ConfigError(f"driving seed = {self.seed}: allowed range is 0 <= seed < 2^64")
        lam = float(self.rotational_fraction)
        if not 0.0 <= lam <= 1.0:
            raise ConfigError(f"rotational_fraction = {self.rotational_fraction}: must be in [0, 1]")
        object.__setattr__(self, "heating_rate", h)
        object.__setattr__(self, "interval", dt)
        object.__setattr__(self, "seed", int(self.seed))
        object.__setattr__(self, "rotational_fraction", lam)
