"""The collision law per pair of species, as the compiled kernels look it up (numba leaf module).

A mixture's law is a small table indexed by the species of the two particles
(:class:`granulargas.engine.pairs.PairTable`); the compiled loops (the engine's and the
DSMC's) see it as the :class:`granulargas.engine._state.Species` record: ``of`` the
species of each particle slot, ``count`` the number S of species, per pair q = S s_i + s_j
the constant restitution ``eps[q]``, viscoelastic prefactor ``prefactor[q]`` and the DSMC's
acceptance weight ``weight[q]`` = chi_ij / max chi (symmetric tables, stored in full so that
a lookup is one multiply-add and one load), per species the wall's ``wall_eps[s]`` and
``wall_prefactor[s]``, and the pair collision counts ``pairs[q]`` (both orders; the driver
adds q and its transpose).

Every function here takes ``species`` as None or a ``Species`` record and branches on
``species is None``, which numba resolves by the argument's type before it types the
function (as for the contacts of the resolved rule): with None the lookup returns the one law's own scalars -- the very values
the one-component loop reads -- the weight is 1 and the count does nothing, so a run
without species compiles to the loop it had without this module. The restitution itself
then comes from :func:`granulargas.engine._collide.restitution` with the pair's values,
for the engine and the DSMC alike.
"""

from granulargas._numba import inlined


@inlined
def pair_law(eps, prefactor, species, i, j):
    """(eps, prefactor) of the pair of slots i, j: the one law's constant restitution ``eps``
    and viscoelastic ``prefactor``, or the pair's entries of the species table."""
    if species is None:
        return eps, prefactor
    q = species.of[i] * species.count + species.of[j]
    return species.eps[q], species.prefactor[q]


@inlined
def wall_law(eps, prefactor, species, i):
    """(eps, prefactor) of a collision of slot i with a wall: the one law's wall restitution
    ``eps`` and ``prefactor``, or those of i's species."""
    if species is None:
        return eps, prefactor
    s = species.of[i]
    return species.wall_eps[s], species.wall_prefactor[s]


@inlined
def pair_weight(species, i, j):
    """The DSMC's acceptance weight chi_ij / max chi of the pair (1.0 without species)."""
    if species is None:
        return 1.0
    return species.weight[species.of[i] * species.count + species.of[j]]


@inlined
def count_pair(species, i, j):
    """Count a collision of slots i and j in the species-pair table (None: nothing)."""
    if species is None:
        return
    species.pairs[species.of[i] * species.count + species.of[j]] += 1
