"""The collision law per pair of species: :class:`PairTable`.

A mixture of S species has one law per pair of species, all of the rule's kind: a
constant restitution eps_ij, or the viscoelastic eps(beta) with the pair's prefactor
k_ij in beta = k_ij (R_eff g_n / m_eff^2)^(1/5) (the restitution table eps(beta) is the
same function for every pair: one table serves them all). A particle meets a wall by
the law of its own species: a constant eps_i, or the prefactor k_ii of a flat wall of
its own material. The table is symmetric, eps_ij = eps_ji: a property of the pair.

:class:`granulargas.engine.CollisionRule` carries a ``PairTable`` when built with
per-pair values (``CollisionRule.constant`` with a matrix of restitutions,
``CollisionRule.viscoelastic`` with a matrix of prefactors); the compiled loop looks
it up by the species of the two particles (:mod:`granulargas.engine._species`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from granulargas.errors import ConfigError


def _matrix(value, name: str, low: float, high: float, low_open: bool) -> tuple:
    a = np.asarray(value, dtype=np.float64)
    if a.ndim != 2 or a.shape[0] != a.shape[1] or a.shape[0] < 1:
        raise ConfigError(f"{name}: a square table (S, S) of one value per pair of species, got shape {a.shape}")
    if not np.array_equal(a, a.T):
        i, j = map(int, np.argwhere(a != a.T)[0])
        raise ConfigError(f"{name}: [{i}][{j}] = {a[i, j]:g} but [{j}][{i}] = {a[j, i]:g}: the law is a property "
                          "of the pair, the table must be symmetric")
    ok = np.isfinite(a) & (a > low if low_open else a >= low) & (a <= high)
    if not ok.all():
        i, j = map(int, np.argwhere(~ok)[0])
        raise ConfigError(f"{name}: [{i}][{j}] = {a[i, j]:g}: allowed range is "
                          f"{'(' if low_open else '['}{low:g}, {high:g}]")
    return tuple(tuple(float(x) for x in row) for row in a)


def _vector(value, size: int, name: str, low: float, high: float, low_open: bool) -> tuple:
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(size, float(a))
    if a.shape != (size,):
        raise ConfigError(f"{name}: one value per species ({size}), got shape {a.shape}")
    ok = np.isfinite(a) & (a > low if low_open else a >= low) & (a <= high)
    if not ok.all():
        i = int(np.argwhere(~ok)[0][0])
        raise ConfigError(f"{name}: [{i}] = {a[i]:g}: allowed range is {'(' if low_open else '['}{low:g}, {high:g}]")
    return tuple(float(x) for x in a)


@dataclass(frozen=True)
class PairTable:
    """One collision law per pair of species (module docstring).

    Attributes
    ----------
    restitution : tuple of tuples (S, S)
        Constant eps_ij (a constant rule; 1 for the others).
    prefactor : tuple of tuples (S, S)
        Viscoelastic k_ij (a viscoelastic rule; 0 for the others).
    wall_restitution : tuple (S,)
        Constant eps of a particle of species i against a wall (a constant rule).
    wall_prefactor : tuple (S,)
        Viscoelastic k of species i against a flat wall of its own material (k_ii).
    """

    restitution: tuple
    prefactor: tuple
    wall_restitution: tuple
    wall_prefactor: tuple

    @property
    def count(self) -> int:
        """Number of species S."""
        return len(self.restitution)

    @classmethod
    def constant(cls, restitution, wall_restitution=None) -> "PairTable":
        """eps_ij (S, S) in (0, 1], symmetric; walls: one eps, one per species, or None (eps_ii)."""
        eps = _matrix(restitution, "restitution", 0.0, 1.0, True)
        size = len(eps)
        walls = tuple(eps[i][i] for i in range(size)) if wall_restitution is None else \
            _vector(wall_restitution, size, "wall_restitution", 0.0, 1.0, True)
        return cls(eps, tuple((0.0,) * size for _ in range(size)), walls, (0.0,) * size)

    @classmethod
    def viscoelastic(cls, prefactor) -> "PairTable":
        """k_ij (S, S) >= 0, symmetric; a particle meets a wall with its own species' k_ii."""
        k = _matrix(prefactor, "viscoelastic prefactor", 0.0, np.inf, False)
        size = len(k)
        return cls(tuple((1.0,) * size for _ in range(size)), k, (1.0,) * size,
                   tuple(k[i][i] for i in range(size)))

    @classmethod
    def elastic(cls, count: int) -> "PairTable":
        """Elastic collisions for every pair of ``count`` species (the counts per pair still kept)."""
        return cls(tuple((1.0,) * count for _ in range(count)), tuple((0.0,) * count for _ in range(count)),
                   (1.0,) * count, (0.0,) * count)

    def arrays(self) -> dict:
        """The table as float64 arrays: restitution, prefactor (S, S), wall_restitution,
        wall_prefactor (S,)."""
        return {name: np.array(getattr(self, name), dtype=np.float64)
                for name in ("restitution", "prefactor", "wall_restitution", "wall_prefactor")}


def species_of_state(state, rule):
    """(species (N,) int32, raw pair counts (S*S,) int64) of a state for a rule with a pair table
    of S species: every species index in [0, S); the counts to continue from are the state's
    ``species_collisions`` (S, S) (their upper triangle, :func:`pair_count_matrix` inverted)."""
    size = rule.pairs.count
    of = state.array("species")
    bad = np.flatnonzero((of < 0) | (of >= size))
    if len(bad):
        k = int(bad[0])
        raise ConfigError(f"species: particle {k} has species {int(of[k])}, but the rule's pair table has "
                          f"{size} species (indices 0 to {size - 1})")
    counts = np.zeros((size, size), dtype=np.int64)
    given = state.species_collisions
    if given is not None:
        given = np.asarray(given)
        if given.shape != (size, size):
            raise ConfigError(f"species_collisions: shape {given.shape}, the rule has {size} species")
        counts = np.triu(given).astype(np.int64)
    return np.ascontiguousarray(of, dtype=np.int32), counts.reshape(-1)


def pair_count_matrix(raw, size: int) -> np.ndarray:
    """The symmetric (S, S) collision counts per pair of species from the engine's raw counts
    (S*S,) by ordered slot pair: C = R + R^T off the diagonal, R on it."""
    r = np.asarray(raw, dtype=np.int64).reshape(size, size)
    c = r + r.T
    np.fill_diagonal(c, np.diagonal(r))
    return c
