"""Collision rules: which coefficient of restitution a collision gets.

A :class:`CollisionRule` is a small frozen description; the compiled loop sees
it as a :class:`granulargas.engine._state.RuleParams` record (integer kind,
constant eps, TC time, prefactor and coefficient table; see
:mod:`granulargas.engine._collide` for the collision law itself). Sphere-wall
collisions follow the same rule with R_eff = R_i and m_eff = m_i (a flat,
infinitely heavy wall of the same material); a constant-eps rule may give the
walls their own ``wall_restitution``.

A restitution floor, ``elastic_below`` = v (the ElasticV of DynamO, Bannerman, Sargant &
Lue 2011), makes every collision (pair or wall) whose normal relative speed is below v
elastic: a grain coming to rest on a floor under gravity, or a cluster on a shaken plate,
then bounces on at about that speed instead of colliding ever faster (the inelastic
collapse of a bouncing ball, a Zeno trap that no event-driven loop can pass).

A viscoelastic rule with ``duration="resolved"`` makes collisions take time:
the pair's outcome (outgoing velocity, contact duration, where the pair leaves
the contact) comes from the oblique-contact table and the pair jumps onto its
outgoing line (:mod:`granulargas.engine._resolved`). It needs the contact
stiffness as well as the damping: the compression prefactor
q = (2 Y / (3 (1 - nu^2)))^(-2/5) of
:func:`granulargas.contact.oblique.compression_prefactor` in reduced units.

A mixture has one law per pair of species (:class:`granulargas.engine.pairs.PairTable`):
``CollisionRule.constant`` with a symmetric (S, S) table of restitutions (and walls one
per species), ``CollisionRule.viscoelastic`` with an (S, S) table of prefactors,
``CollisionRule.elastic(species=S)``. The simulation then needs the species of every
particle; the collision counts per pair of species come with it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from granulargas.engine._collide import CONSTANT, ELASTIC, VISCOELASTIC
from granulargas.engine._state import RuleParams, rule_params
from granulargas.engine.pairs import PairTable
from granulargas.errors import ConfigError

#: How long a collision takes: "instantaneous", or "resolved" (viscoelastic only).
DURATIONS = ("instantaneous", "resolved")


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
    duration : str
        "instantaneous" (every kind) or "resolved" (viscoelastic: collisions
        that take time).
    compression : float
        Resolved rule: compression prefactor q, X = q (m_eff^2 g_n^4 / R_eff)^(1/5).
    oblique : object
        Resolved rule: the oblique-contact table
        (:class:`granulargas.contact.oblique_grid.ObliqueTable`) of the same contact end.
    elastic_below : float or None
        Restitution floor: a collision whose normal relative speed is below it is
        elastic (constant and instantaneous viscoelastic rules). None: off.
    pairs : PairTable or None
        One law per pair of species (a mixture); ``restitution``, ``wall_restitution`` and
        ``prefactor`` then hold those of the first species' own pair, (0, 0).
    """

    kind: str
    restitution: float = 1.0
    tc_time: float | None = None
    prefactor: float = 0.0
    table: Any = None
    wall_restitution: float | None = None
    duration: str = "instantaneous"
    compression: float = 0.0
    oblique: Any = None
    elastic_below: float | None = None
    pairs: PairTable | None = None

    @classmethod
    def elastic(cls, species: int | None = None) -> "CollisionRule":
        """Elastic collisions, eps = 1 (``species``: a mixture of that many species, whose
        collisions are counted per pair of species)."""
        if species is None:
            return cls("elastic")
        if not (isinstance(species, int) and species >= 1):
            raise ConfigError(f"species = {species!r}: the number of species, an integer >= 1")
        return cls("elastic", pairs=PairTable.elastic(species))

    @classmethod
    def constant(cls, restitution, tc_time: float | None = None,
                 wall_restitution=None, elastic_below: float | None = None) -> "CollisionRule":
        """Constant coefficient of restitution 0 < eps <= 1, optionally with the TC model,
        a separate constant eps for sphere-wall collisions and a restitution floor.

        A mixture: ``restitution`` a symmetric (S, S) table eps_ij, ``wall_restitution``
        one number or one per species (default eps_ii)."""
        if np.ndim(restitution) == 2:
            table = PairTable.constant(restitution, wall_restitution)
            rule = cls.constant(table.restitution[0][0], tc_time, table.wall_restitution[0], elastic_below)
            return replace(rule, pairs=table)
        if np.ndim(wall_restitution) == 1:
            raise ConfigError("wall_restitution: one value per species needs a table of restitutions per pair")
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
                   wall_restitution=wall_restitution, elastic_below=_floor(elastic_below))

    @classmethod
    def viscoelastic(cls, prefactor: float, table: Any, tc_time: float | None = None,
                     duration: str = "instantaneous", compression: float | None = None,
                     oblique: Any = None, elastic_below: float | None = None) -> "CollisionRule":
        """Viscoelastic eps(beta) from a restitution table, beta = k (R_eff g_n / m_eff^2)^(1/5).

        ``duration="resolved"``: collisions take time (module docstring); needs
        ``compression`` (q > 0) and ``oblique`` (an ObliqueTable), and no TC model.
        A mixture: ``prefactor`` a symmetric (S, S) table k_ij (instantaneous collisions).
        """
        if np.ndim(prefactor) == 2:
            pairs = PairTable.viscoelastic(prefactor)
            if duration != "instantaneous":
                raise ConfigError('duration = "resolved" takes one material: a table of prefactors per pair '
                                  "of species needs instantaneous collisions")
            rule = cls.viscoelastic(pairs.prefactor[0][0], table, tc_time, elastic_below=elastic_below)
            return replace(rule, pairs=pairs)
        prefactor = float(prefactor)
        if not prefactor >= 0.0:
            raise ConfigError(f"viscoelastic prefactor = {prefactor}: must be >= 0")
        if table is None or not hasattr(table, "inv_h") or not hasattr(table, "coeffs"):
            raise ConfigError("viscoelastic rule needs a restitution table with inv_h and coeffs")
        if duration not in DURATIONS:
            raise ConfigError(f"duration = {duration!r}: must be one of {', '.join(DURATIONS)}")
        if duration == "instantaneous":
            if compression is not None or oblique is not None:
                raise ConfigError('compression and oblique are used only with duration = "resolved"')
            return cls("viscoelastic", prefactor=prefactor, table=table,
                       tc_time=None if tc_time is None else float(tc_time), elastic_below=_floor(elastic_below))
        if tc_time is not None:
            raise ConfigError('tc_time: the TC model is not used with duration = "resolved"')
        if elastic_below is not None:
            raise ConfigError('elastic_below: collisions that take time (duration = "resolved") have no '
                              'restitution to set to 1')
        compression = float("nan") if compression is None else float(compression)
        if not (compression > 0.0 and compression < float("inf")):
            raise ConfigError(f'duration = "resolved" needs the compression prefactor q > 0 (the contact '
                              f'stiffness; contact.oblique.compression_prefactor), got {compression}')
        if oblique is None or not all(hasattr(oblique, a) for a in ("inv_hs", "inv_hd", "coeffs")):
            raise ConfigError('duration = "resolved" needs an oblique-contact table (contact.oblique_table)')
        end = getattr(table, "end", None)
        if end is not None and getattr(oblique, "end", end) != end:
            raise ConfigError(f"the oblique-contact table ends at {oblique.end!r}, the restitution table "
                              f"at {end!r}: give both for the same contact end")
        return cls("viscoelastic", prefactor=prefactor, table=table, duration="resolved",
                   compression=compression, oblique=oblique)

    @property
    def species(self) -> int:
        """Number of species of the rule's pair table (0: one law for all pairs)."""
        return 0 if self.pairs is None else self.pairs.count

    @property
    def resolved(self) -> bool:
        """True for collisions that take time."""
        return self.duration == "resolved"

    # -- what the compiled loop sees
    def compiled(self) -> RuleParams:
        """The rule as the compiled kernels see it (:class:`~granulargas.engine._state.RuleParams`)."""
        kind = {"elastic": ELASTIC, "constant": CONSTANT, "viscoelastic": VISCOELASTIC}[self.kind]
        tc = -1.0 if self.tc_time is None else float(self.tc_time)
        eps = self.restitution if self.kind == "constant" else 1.0
        floor = 0.0 if self.elastic_below is None else float(self.elastic_below)
        if self.kind == "viscoelastic":
            return rule_params(kind, eps, tc, self.prefactor, float(self.table.inv_h),
                               self.table.coeffs, oblique=self.oblique, compression=self.compression,
                               elastic_below=floor)
        return rule_params(kind, eps, tc, self.prefactor, wall_eps=self.wall_restitution, elastic_below=floor)

    def kernel_arguments(self):
        """(kind code, eps, tc_time or -1, prefactor, inv_h, coeffs): the first six fields of
        :meth:`compiled`, for kernels that take them as plain arguments (the DSMC)."""
        r = self.compiled()
        return r.kind, r.eps, r.tc_time, r.prefactor, r.inv_h, r.coeffs


def _floor(elastic_below):
    """The restitution floor as a float > 0, or None."""
    if elastic_below is None:
        return None
    v = float(elastic_below)
    if not (v > 0.0 and v < float("inf")):
        raise ConfigError(f"elastic_below = {elastic_below}: must be a speed > 0 (or None for no floor)")
    return v
