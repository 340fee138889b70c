"""The tangential law of rough particles: :class:`TangentialRule`.

A rough particle spins; a collision reverses the tangential velocity of the contact
points by ``-beta_t`` (``beta_t = -1`` smooth, ``+1`` perfectly rough) or, with Walton's
model, by ``-beta_0`` unless the Coulomb limit ``mu |J_n|`` caps the tangential impulse
(:mod:`granulargas.engine._rough`, where the law and its sign convention are derived).
The normal restitution is the :class:`~granulargas.engine.rules.CollisionRule`'s; the
moments of inertia are the particles' (``State.inertia``: kappa = I / (m R^2) per
particle) and the spins their ``angular_velocities``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas.engine._rough import TANGENTIAL_CONSTANT, TANGENTIAL_COULOMB
from granulargas.errors import ConfigError
from granulargas.theory.rough import DEFAULT_INERTIA, MAX_INERTIA

#: ``TangentialRule.model``: a constant beta_t, or Walton's Coulomb model
MODELS = ("constant", "coulomb")


def _beta(name, value):
    value = float(value)
    if not -1.0 <= value <= 1.0:
        raise ConfigError(f"{name} = {value}: the tangential restitution must be in [-1, 1] "
                          "(-1 smooth, +1 perfectly rough)")
    return value


def _mu(name, value):
    value = float(value)
    if not (value >= 0.0 and math.isfinite(value)):
        raise ConfigError(f"{name} = {value}: a friction coefficient must be finite and >= 0")
    return value


@dataclass(frozen=True)
class TangentialRule:
    """How the tangential velocity of the contact points changes in a collision.

    Build with :meth:`constant` or :meth:`coulomb`.

    Attributes
    ----------
    model : str
        "constant" or "coulomb".
    restitution : float
        beta_t (constant) or the sticking value beta_0 (coulomb), in [-1, 1].
    friction : float
        mu of the Coulomb limit (coulomb).
    wall_restitution, wall_friction : float or None
        The same for particle-wall contacts (None: the pair values).
    """

    model: str = "constant"
    restitution: float = -1.0
    friction: float = 0.0
    wall_restitution: float | None = None
    wall_friction: float | None = None

    def __post_init__(self):
        if self.model not in MODELS:
            raise ConfigError(f"tangential model = {self.model!r}: must be one of {', '.join(MODELS)}")
        object.__setattr__(self, "restitution", _beta("tangential restitution", self.restitution))
        object.__setattr__(self, "friction", _mu("friction", self.friction))
        if self.wall_restitution is not None:
            object.__setattr__(self, "wall_restitution", _beta("wall tangential restitution",
                                                               self.wall_restitution))
        if self.wall_friction is not None:
            object.__setattr__(self, "wall_friction", _mu("wall friction", self.wall_friction))
        if self.model == "constant" and (self.friction != 0.0 or self.wall_friction is not None):
            raise ConfigError('friction is used only with the tangential model "coulomb"')

    @classmethod
    def constant(cls, restitution: float, wall_restitution: float | None = None) -> "TangentialRule":
        """A constant tangential restitution beta_t (walls: ``wall_restitution``, default beta_t)."""
        return cls("constant", restitution, 0.0, wall_restitution)

    @classmethod
    def coulomb(cls, restitution: float, friction: float, wall_restitution: float | None = None,
                wall_friction: float | None = None) -> "TangentialRule":
        """Walton's model: sticking contacts get beta_0 = ``restitution``, sliding ones the Coulomb
        limit of ``friction``."""
        return cls("coulomb", restitution, friction, wall_restitution, wall_friction)

    @property
    def code(self) -> int:
        """The model code of the compiled law."""
        return TANGENTIAL_CONSTANT if self.model == "constant" else TANGENTIAL_COULOMB

    @property
    def wall_beta(self) -> float:
        return self.restitution if self.wall_restitution is None else self.wall_restitution

    @property
    def wall_mu(self) -> float:
        return self.friction if self.wall_friction is None else self.wall_friction

    def parameters(self) -> dict:
        """The rule as the H5MD ``parameters/`` group stores it."""
        return {"model": self.model, "restitution": self.restitution, "friction": self.friction,
                "wall_restitution": self.wall_beta, "wall_friction": self.wall_mu}


def spins_of(state) -> tuple:
    """(w, kappa) of a state for a rough simulation: the angular velocities as (N, 3) rows
    (2D: the spin about z in the last column; default 0) and kappa (N,) (default: a uniform
    sphere or disk), both in particle-id order, checked."""
    n, d = state.n, state.dimension
    kappa = state.array("inertia") if state.inertia is not None else np.full(n, DEFAULT_INERTIA[d])
    if not np.all((kappa > 0.0) & (kappa <= MAX_INERTIA[d] * (1.0 + 1e-12))):
        raise ConfigError(f"inertia: every kappa = I / (m R^2) must be in (0, {MAX_INERTIA[d]:.4g}] in {d}D "
                          "(no mass outside the surface)")
    w = state.array("angular_velocities")
    if not np.all(np.isfinite(w)):
        raise ConfigError("angular_velocities: non-finite values")
    w3 = np.zeros((n, 3))
    if d == 3:
        w3[:] = w
    else:
        w3[:, 2] = w[:, 0]
    return w3, kappa


def public_spins(w3, dimension: int) -> np.ndarray:
    """The angular velocities as the state holds them: (N, 3) in 3D, (N, 1) in 2D (a copy)."""
    return w3.copy() if dimension == 3 else w3[:, 2:3].copy()


def rotational_temperature(w3, kappa, masses, radii, dimension: int) -> float:
    """T_rot = sum I_i |w_i|^2 / (d_r N), I_i = kappa_i m_i R_i^2 (d_r = 3 in 3D, 1 in 2D)."""
    inertia = kappa * masses * radii**2
    return float(np.sum(inertia * np.sum(w3 * w3, axis=1)) / ((3 if dimension == 3 else 1) * len(kappa)))


def spin_kick_scale(driving, dimension: int) -> float:
    """Standard deviation of a spin kick for unit moment of inertia, sqrt(dT_rot/dt x interval)
    (:mod:`granulargas.engine._spin`); 0 without driving."""
    if driving is None:
        return 0.0
    return math.sqrt(driving.rotational_rate(dimension) * driving.interval)
