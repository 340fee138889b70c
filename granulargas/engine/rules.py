"""Collision rules: which coefficient of restitution a collision gets.

A :class:`CollisionRule` is a small frozen description; the compiled loop sees
it as an integer kind, a float parameter vector and a coefficient table (see
:mod:`granulargas.engine._collide` for the collision law itself).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from granulargas.engine._collide import CONSTANT, ELASTIC, VISCOELASTIC
from granulargas.errors import ConfigError

_DUMMY_COEFFS = np.zeros((1, 4))


@dataclass(frozen=True)
class CollisionRule:
    """How the normal relative velocity changes in a collision.

    Build with :meth:`elastic`, :meth:`constant` or :meth:`viscoelastic`.

    Attributes
    ----------
    kind : str
        "elastic", "constant" or "viscoelastic".
    restitution : float
        Constant coefficient of restitution (kind "constant").
    tc_time : float or None
        TC model (Luding & McNamara 1998): a collision within ``tc_time`` of
        either particle's previous collision is elastic. None: off.
    prefactor : float
        Viscoelastic pair prefactor k: beta = k (R_eff g_n / m_eff^2)^(1/5).
    table : object
        Restitution table with ``inv_h`` and ``coeffs`` (kind "viscoelastic").
    """

    kind: str
    restitution: float = 1.0
    tc_time: float | None = None
    prefactor: float = 0.0
    table: Any = None

    @classmethod
    def elastic(cls) -> "CollisionRule":
        """Elastic collisions, eps = 1."""
        return cls("elastic")

    @classmethod
    def constant(cls, restitution: float, tc_time: float | None = None) -> "CollisionRule":
        """Constant coefficient of restitution 0 < eps <= 1, optionally with the TC model."""
        restitution = float(restitution)
        if not 0.0 < restitution <= 1.0:
            raise ConfigError(f"restitution = {restitution}: allowed range is 0 < eps <= 1")
        if tc_time is not None:
            tc_time = float(tc_time)
            if not tc_time > 0.0:
                raise ConfigError(f"tc_time = {tc_time}: must be > 0 (or None to switch the TC model off)")
        return cls("constant", restitution=restitution, tc_time=tc_time)

    @classmethod
    def viscoelastic(cls, prefactor: float, table: Any, tc_time: float | None = None) -> "CollisionRule":
        """Viscoelastic eps(beta) from a restitution table, beta = k (R_eff g_n / m_eff^2)^(1/5)."""
        prefactor = float(prefactor)
        if not prefactor >= 0.0:
            raise ConfigError(f"viscoelastic prefactor = {prefactor}: must be >= 0")
        if table is None or not hasattr(table, "inv_h") or not hasattr(table, "coeffs"):
            raise ConfigError("viscoelastic rule needs a restitution table with inv_h and coeffs")
        return cls("viscoelastic", prefactor=prefactor, table=table,
                   tc_time=None if tc_time is None else float(tc_time))

    # -- what the compiled loop sees
    def kernel_arguments(self):
        """(kind code, eps, tc_time or -1, prefactor, inv_h, coeffs) for the compiled loop."""
        kind = {"elastic": ELASTIC, "constant": CONSTANT, "viscoelastic": VISCOELASTIC}[self.kind]
        tc = -1.0 if self.tc_time is None else float(self.tc_time)
        if self.kind == "viscoelastic":
            coeffs = np.ascontiguousarray(self.table.coeffs, dtype=np.float64)
            inv_h = float(self.table.inv_h)
        else:
            coeffs = _DUMMY_COEFFS
            inv_h = 1.0
        eps = self.restitution if self.kind == "constant" else 1.0
        return kind, eps, tc, self.prefactor, inv_h, coeffs
