"""Rough particles in the event loop: spins, the rough pair and wall collisions, spin kicks (numba).

The engine keeps the spins of rough particles in a record of their own,
:class:`granulargas.engine._state.Spins` (``engine.spins``; None for smooth particles,
whose loop then compiles without any of this): ``w`` (N, 3) f8 the angular velocities
in memory order (2D: only ``w[:, 2]``, the spin about z, is used), ``kappa`` (N,) f8 the
particles' ``I / (m R^2)``, and the tangential law: ``model``
(:data:`~granulargas.engine._rough.TANGENTIAL_CONSTANT` or ``TANGENTIAL_COULOMB``),
``beta``, ``mu`` for pairs, ``wall_beta``, ``wall_mu`` for walls, and ``kick_scale``, the
standard deviation of a spin kick of the white-noise driving for unit moment of inertia.

The collision law is :mod:`granulargas.engine._rough` on plain floats; the functions
here read and write the engine's arrays (velocities in ``rec[:, 3:6]``, radii in
``rec[:, 7]``) and return what the loop's counters need:

* the energy lost (translation and rotation) goes to ``dissipated``;
* the change of the rotational energy ``drot``, so that the loop's running sum of
  ``m v^2`` (the kinetic part of the pressure) follows the translational energy:
  ``sum_mv2 -= 2 (loss + drot)``.

With ``beta_t = -1`` every spin change is exactly 0.0 and every velocity change that of
the smooth law, so the trajectories are the smooth ones bit for bit.

Spin kicks of the white-noise driving: every particle's spin gets an independent
Gaussian kick of standard deviation ``kick_scale / sqrt(I_i)`` per rotational component
(``I_i = kappa_i m_i R_i^2``) from the driving's counter-based stream
(:func:`granulargas.engine._drive.kick_normals`) under a key of its own (the seed with
:data:`SPIN_KEY` mixed in), so that the translational kicks are the same numbers with
and without spins. No mean is removed (the spins carry no conserved momentum), so
``T_rot = I <w^2> / d_r`` rises by ``kick_scale^2`` per kick on average.
"""

import math

import numpy as np

from granulargas._numba import inlined, kernel
from granulargas.engine._drive import kick_normals
from granulargas.engine._rough import (
    TANGENTIAL_CONSTANT,
    apply_rough_pair,
    contact_slip,
    rough_pair_collision,
    rough_wall_collision,
)

#: mixed into the driving's seed for the spin kicks (an arbitrary odd 64-bit word)
SPIN_KEY = np.uint64(0x5851F42D4C957F2D)


@inlined
def _spin_energy(w, k, i, m, r):
    """I |w_i|^2 of slot i (no factor 1/2)."""
    return k[i] * m * r * r * (w[i, 0] * w[i, 0] + w[i, 1] * w[i, 1] + w[i, 2] * w[i, 2])


@inlined
def rough_pair(i, j, nx, ny, nz, un, eps, rec, mass, spins, elastic):
    """Rough collision of slots i and j (streamed, touching, approaching; n the unit vector
    from j to i, ``un`` < 0 the normal relative velocity as the smooth law gets it, so that
    beta_t = -1 reproduces it bit for bit) with normal restitution eps, in place. Returns
    (loss, impulse, drot):
    the energy lost, the normal impulse (1 + eps) m_eff u_n (virial) and the change of the
    pair's rotational energy. ``elastic`` (the TC model's collisions): frictionless as well."""
    w = spins.w
    kap = spins.kappa
    mi = mass[i]
    mj = mass[j]
    ri = rec[i, 7]
    rj = rec[j, 7]
    e0 = _spin_energy(w, kap, i, mi, ri) + _spin_energy(w, kap, j, mj, rj)
    _, gx, gy, gz = contact_slip(rec[i, 3] - rec[j, 3], rec[i, 4] - rec[j, 4], rec[i, 5] - rec[j, 5], nx, ny, nz,
                                 ri * w[i, 0] + rj * w[j, 0], ri * w[i, 1] + rj * w[j, 1],
                                 ri * w[i, 2] + rj * w[j, 2])
    model = TANGENTIAL_CONSTANT if elastic else spins.model
    beta = -1.0 if elastic else spins.beta
    fi, fj, ti, tj, si, sj, loss, impulse = rough_pair_collision(
        un, gx * gx + gy * gy + gz * gz, mi, mj, kap[i], kap[j], ri, rj, eps, model, beta, spins.mu)
    apply_rough_pair(rec, 3, w, i, j, 3, nx, ny, nz, gx, gy, gz, fi, fj, ti, tj, si, sj)  # 2D: z rows stay 0
    drot = 0.5 * (_spin_energy(w, kap, i, mi, ri) + _spin_energy(w, kap, j, mj, rj) - e0)
    return loss, impulse, drot


@inlined
def rough_wall(i, a, side, eps, rec, mass, spins, elastic):
    """Slot i (streamed, moving into the wall) against the wall 2 a + side at rest, in place.

    Returns (loss, momentum, drot): the energy lost, the normal momentum the wall receives
    and the change of the particle's rotational energy. ``elastic`` (the TC model's
    collisions): frictionless as well.
    """
    w = spins.w
    kap = spins.kappa
    mi = mass[i]
    ri = rec[i, 7]
    e0 = _spin_energy(w, kap, i, mi, ri)
    nrm = 1.0 if side == 0 else -1.0  # the wall normal into the gas, along axis a
    nx = nrm if a == 0 else 0.0
    ny = nrm if a == 1 else 0.0
    nz = nrm if a == 2 else 0.0
    un, gx, gy, gz = contact_slip(rec[i, 3], rec[i, 4], rec[i, 5], nx, ny, nz, ri * w[i, 0], ri * w[i, 1],
                                  ri * w[i, 2])
    model = TANGENTIAL_CONSTANT if elastic else spins.model
    beta = -1.0 if elastic else spins.wall_beta
    vn_new, ti, si, loss, momentum = rough_wall_collision(
        rec[i, 3 + a], gx * gx + gy * gy + gz * gz, mi, kap[i], ri, eps, model, beta, spins.wall_mu)
    rec[i, 3] -= ti * gx
    rec[i, 4] -= ti * gy
    rec[i, 5] -= ti * gz
    rec[i, 3 + a] = vn_new  # g_t has no component along the normal
    w[i, 0] += si * (ny * gz - nz * gy)
    w[i, 1] += si * (nz * gx - nx * gz)
    w[i, 2] += si * (nx * gy - ny * gx)
    drot = 0.5 * (_spin_energy(w, kap, i, mi, ri) - e0)
    return loss, momentum, drot


@inlined
def spin_kick(w, i, inertia, key, step, ident, dims, scale):
    """Kick row i of the spins ``w`` (moment of inertia ``inertia``); returns the energy added."""
    g1, g2, g3 = kick_normals(key, step, ident)
    s = scale / math.sqrt(inertia)
    e0 = w[i, 0] * w[i, 0] + w[i, 1] * w[i, 1] + w[i, 2] * w[i, 2]
    if dims == 3:
        w[i, 0] += s * g1
        w[i, 1] += s * g2
        w[i, 2] += s * g3
    else:
        w[i, 2] += s * g1
    return 0.5 * inertia * (w[i, 0] * w[i, 0] + w[i, 1] * w[i, 1] + w[i, 2] * w[i, 2] - e0)


@kernel
def kick_spins(rec, mass, ident, dims, spins, seed, step):
    """One driving step of the engine's spins (module docstring), in place; returns the energy added."""
    w = spins.w
    kap = spins.kappa
    key = np.uint64(seed) ^ SPIN_KEY
    gained = 0.0
    for i in range(w.shape[0]):
        inertia = kap[i] * mass[i] * rec[i, 7] * rec[i, 7]
        gained += spin_kick(w, i, inertia, key, step, ident[i], dims, spins.kick_scale)
    return gained


@kernel
def kick_spin_rows(w, inertia, dims, seed, step, scale):
    """One driving step of spins ``w`` (N, 3) in particle-id order with moments of inertia
    ``inertia`` (N,) (the DSMC's), the same numbers as :func:`kick_spins`; returns the energy added."""
    key = np.uint64(seed) ^ SPIN_KEY
    gained = 0.0
    for i in range(w.shape[0]):
        gained += spin_kick(w, i, inertia[i], key, step, i, dims, scale)
    return gained
