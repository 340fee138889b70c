"""Collision rules: which coefficient of restitution a collision gets.

A :class:`CollisionRule` is a small frozen description; the compiled loop sees
it as a :class:`granulargas.engine._state.RuleParams` record (integer kind,
constant eps, TC time, prefactor and coefficient table; see
:mod:`granulargas.engine._collide` for the collision law itself). Sphere-wall
collisions follow the same rule with R_eff = R_i and m_eff = m_i (a flat,
infinitely heavy wall of the same material); a constant-eps rule may give the
walls their own ``wall_restitution``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from granulargas.engine._collide import CONSTANT, ELASTIC, VISCOELASTIC
from granulargas.engine._state import RuleParams, rule_params
from granulargas.errors import ConfigError


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
    wall_restitution : float or None
        Constant eps of sphere-wall collisions (kind "constant"; None: the same
        as ``restitution``). Elastic rules have elastic walls, viscoelastic rules
        eps(beta) at the sphere-plane contact.
    """

    kind: str
    restitution: float = 1.0
    tc_time: float | None = None
    prefactor: float = 0.0
    table: Any = None
    wall_restitution: float | None = None

    @classmethod
    def elastic(cls) -> "CollisionRule":
        """Elastic collisions, eps = 1."""
        return cls("elastic")

    @classmethod
    def constant(cls, restitution: float, tc_time: float | None = None,
                 wall_restitution: float | None = None) -> "CollisionRule":
        """Constant coefficient of restitution 0 < eps <= 1, optionally with the TC model
        and a separate constant eps for sphere-wall collisions."""
        restitution = float(restitution)
        if not 0.0 < restitution <= 1.0:
            raise ConfigError(f"restitution = {restitution}: allowed range is 0 < eps <= 1")
        if wall_restitution is not None:
            wall_restitution = float(wall_restitution)
            if not 0.0 < wall_restitution <= 1.0:
                raise ConfigError(f"wall_restitution = {wall_restitution}: allowed range is "
                                  f"0 < eps <= 1")
        if tc_time is not None:
            tc_time = float(tc_time)
            if not tc_time > 0.0:
                raise ConfigError(f"tc_time = {tc_time}: must be > 0 (or None to switch the TC model off)")
        return cls("constant", restitution=restitution, tc_time=tc_time,
                   wall_restitution=wall_restitution)

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
    def compiled(self) -> RuleParams:
        """The rule as the compiled kernels see it (:class:`~granulargas.engine._state.RuleParams`)."""
        kind = {"elastic": ELASTIC, "constant": CONSTANT, "viscoelastic": VISCOELASTIC}[self.kind]
        tc = -1.0 if self.tc_time is None else float(self.tc_time)
        eps = self.restitution if self.kind == "constant" else 1.0
        if self.kind == "viscoelastic":
            return rule_params(kind, eps, tc, self.prefactor, float(self.table.inv_h),
                               self.table.coeffs)
        return rule_params(kind, eps, tc, self.prefactor, wall_eps=self.wall_restitution)

    def kernel_arguments(self):
        """(kind code, eps, tc_time or -1, prefactor, inv_h, coeffs): the first six fields of
        :meth:`compiled`, for kernels that take them as plain arguments (the DSMC)."""
        r = self.compiled()
        return r.kind, r.eps, r.tc_time, r.prefactor, r.inv_h, r.coeffs
