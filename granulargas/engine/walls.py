"""Wall kinds of a simulation: :class:`Wall` (one side of a wall axis) and :class:`Walls` (all of them).

Small frozen descriptions, as :class:`~granulargas.engine.driving.WhiteNoise`; the compiled
loop sees them as a :class:`~granulargas.engine._state.WallSpec` (:meth:`Walls.compiled`)
and applies them in :mod:`granulargas.engine._walls` (the physics, the contact search and
its proof are there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas.engine import _walls
from granulargas.engine._state import WallSpec, wall_spec
from granulargas.errors import ConfigError

#: the sides of the wall axes, index 2 axis + side
SIDES = ("x_low", "x_high", "y_low", "y_high", "z_low", "z_high")
KINDS = tuple(_walls.KINDS)
WAVEFORMS = tuple(_walls.WAVEFORMS)


@dataclass(frozen=True)
class Wall:
    """One side of a wall axis.

    Build with :meth:`hard`, :meth:`thermal` or :meth:`vibrating`.

    Attributes
    ----------
    kind : str
        "hard" (at rest, the run's restitution), "thermal" (at rest, diffuse at
        ``temperature``) or "vibrating" (W(t) = amplitude x waveform(2 pi frequency t +
        phase) about a rest position ``amplitude`` inside the box).
    amplitude, frequency, phase : float
        Vibrating wall: A > 0, nu > 0 (cycles per unit time), phi (radians).
    waveform : str
        Vibrating wall: "sine", "triangle" or "biparabolic".
    temperature : float
        Thermal wall: T_w > 0.
    """

    kind: str = "hard"
    amplitude: float = 0.0
    frequency: float = 0.0
    waveform: str = "sine"
    phase: float = 0.0
    temperature: float = 0.0

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ConfigError(f"wall kind = {self.kind!r}: must be one of {', '.join(KINDS)}")
        if self.waveform not in WAVEFORMS:
            raise ConfigError(f"waveform = {self.waveform!r}: must be one of {', '.join(WAVEFORMS)}")
        for name in ("amplitude", "frequency", "phase", "temperature"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise ConfigError(f"wall {name} = {getattr(self, name)}: must be finite")
            object.__setattr__(self, name, value)
        if self.kind == "vibrating" and not (self.amplitude > 0.0 and self.frequency > 0.0):
            raise ConfigError(f"vibrating wall: amplitude = {self.amplitude:g} and frequency = {self.frequency:g} "
                              f"must both be > 0")
        if self.kind == "thermal" and not self.temperature > 0.0:
            raise ConfigError(f"thermal wall: temperature = {self.temperature:g} must be > 0")

    @classmethod
    def hard(cls) -> "Wall":
        """A flat wall at rest with the run's restitution."""
        return cls("hard")

    @classmethod
    def thermal(cls, temperature: float) -> "Wall":
        """A diffuse wall at rest at temperature T_w."""
        return cls("thermal", temperature=temperature)

    @classmethod
    def vibrating(cls, amplitude: float, frequency: float, waveform: str = "sine", phase: float = 0.0) -> "Wall":
        """A wall vibrating along its normal (amplitude A, frequency nu, phase phi in radians)."""
        return cls("vibrating", amplitude=amplitude, frequency=frequency, waveform=waveform, phase=phase)

    @property
    def reach(self) -> float:
        """How far into the box the wall moves from its face: 2A (vibrating), 0 (at rest)."""
        return 2.0 * self.amplitude if self.kind == "vibrating" else 0.0

    @property
    def max_speed(self) -> float:
        """sup |W'|: A omega (sine), (2/pi) A omega (triangle), (4/pi) A omega (bi-parabolic); 0 at rest."""
        if self.kind != "vibrating":
            return 0.0
        return _walls.velocity_bound(self.waveform, self.amplitude, self.frequency)

    @property
    def mean_square_velocity(self) -> float:
        """<W'^2> over a period (0 at rest)."""
        if self.kind != "vibrating":
            return 0.0
        return _walls.mean_square_velocity(self.waveform, self.amplitude, self.frequency)

    def position(self, box_side: float, side: int, t) -> np.ndarray:
        """Position of the wall at time(s) t on an axis of length ``box_side``: 0 or L at rest;
        A + W(t) (lower) or L - A + W(t) (upper) for a vibrating wall."""
        t = np.asarray(t, dtype=float)
        base = 0.0 if side == 0 else float(box_side)
        if self.kind != "vibrating":
            return np.full(t.shape, base)
        u = np.mod(self.frequency * t + self.phase / (2.0 * math.pi), 1.0)
        if self.waveform == "sine":
            w = np.sin(2.0 * math.pi * u)
        elif self.waveform == "triangle":
            w = np.where(u < 0.25, 4.0 * u, np.where(u < 0.75, 2.0 - 4.0 * u, 4.0 * u - 4.0))
        else:
            w = np.where(u < 0.5, u * (8.0 - 16.0 * u), -(u - 0.5) * (8.0 - 16.0 * (u - 0.5)))
        rest = base + self.amplitude if side == 0 else base - self.amplitude
        return rest + self.amplitude * w


@dataclass(frozen=True)
class Walls:
    """The kind of every side of the wall axes (a side left as None is a hard wall at rest) and the
    seed of the thermal walls' counter-based draws."""

    x_low: Wall | None = None
    x_high: Wall | None = None
    y_low: Wall | None = None
    y_high: Wall | None = None
    z_low: Wall | None = None
    z_high: Wall | None = None
    seed: int = 0

    def __post_init__(self):
        for name in SIDES:
            w = getattr(self, name)
            if w is not None and not isinstance(w, Wall):
                raise ConfigError(f"walls {name} = {w!r}: must be a Wall (Wall.hard(), Wall.thermal(T), "
                                  f"Wall.vibrating(A, nu))")
        if not 0 <= int(self.seed) < 2**64:
            raise ConfigError(f"walls seed = {self.seed}: allowed range is 0 <= seed < 2^64")
        object.__setattr__(self, "seed", int(self.seed))

    def side(self, axis: int, side: int) -> Wall:
        """The wall of an axis and side (0 lower, 1 upper)."""
        return getattr(self, SIDES[2 * axis + side]) or Wall.hard()

    @property
    def moving(self) -> bool:
        """Whether any side is thermal or vibrating."""
        return any(getattr(self, s) is not None and getattr(self, s).kind != "hard" for s in SIDES)

    def given(self) -> list[tuple[int, int, Wall]]:
        """(axis, side, wall) of the sides given."""
        return [(k // 2, k % 2, getattr(self, s)) for k, s in enumerate(SIDES) if getattr(self, s) is not None]

    def compiled(self) -> WallSpec:
        """The kinds as the compiled loop sees them."""
        kind = np.zeros((3, 2))
        wf = np.zeros((3, 2))
        amp = np.zeros((3, 2))
        nu = np.zeros((3, 2))
        phase = np.zeros((3, 2))
        temp = np.zeros((3, 2))
        for a, side, w in self.given():
            kind[a, side] = _walls.KINDS[w.kind]
            if w.kind == "vibrating":
                wf[a, side] = _walls.WAVEFORMS[w.waveform]
                amp[a, side], nu[a, side], phase[a, side] = w.amplitude, w.frequency, w.phase
            if w.kind == "thermal":
                temp[a, side] = w.temperature
        return wall_spec(kind, wf, amp, nu, phase, temp, self.seed)
