"""Compiled collision law of rough spheres and disks (numba leaf module, plain floats).

Particles i and j (masses m, radii R, moments of inertia ``I = kappa m R^2``, i.e.
``kappa = 4 I / (m sigma^2)``: 2/5 for a uniform sphere, 1/2 for a uniform disk) touch
with n the unit vector from j to i, as in :mod:`granulargas.engine._collide`. The contact
point lies at ``-R_i n`` from i and ``+R_j n`` from j, so the relative velocity of the
contact points is

    g = u - s x n,   u = v_i - v_j,   s = R_i w_i + R_j w_j,                          (1)

with normal part ``u_n = g.n = u.n < 0`` (approaching; the spins do not enter) and
tangential part ``g_t = g - u_n n``. An impulse J on i at the contact point (-J on j)
changes ``v_i += J / m_i``, ``v_j -= J / m_j``, ``w_i -= (n x J) / (kappa_i m_i R_i)``,
``w_j -= (n x J) / (kappa_j m_j R_j)``, and hence g by

    Delta g_n = J_n / m_eff,   Delta g_t = J_t / m_t,
    1 / m_eff = 1/m_i + 1/m_j,   1 / m_t = 1/m_eff + 1/(kappa_i m_i) + 1/(kappa_j m_j).   (2)

The collision law (sign convention: ``beta_t = -1`` smooth, ``+1`` perfectly rough)
sets ``g_n' = -eps g_n`` and, for a constant tangential restitution, ``g_t' = -beta_t g_t``:

    J = -(1 + eps) m_eff u_n n - c g_t,   c = (1 + beta_t) m_t.                          (3)

Walton's model (Walton 1993; Luding, Huthmann, McNamara & Zippelius 1998) with a friction
coefficient mu and a sticking value beta_0 takes ``c = (1 + beta_0) m_t`` unless the
tangential impulse would exceed the Coulomb limit ``mu |J_n|``; the contact then slides,
``c = mu (1 + eps) m_eff |u_n| / |g_t|``, which is ``beta_t = -1 + mu (1 + eps)(m_eff/m_t)
|u_n|/|g_t|`` (for identical particles ``m_eff/m_t = 1 + 1/kappa``).

Conserved: linear momentum, and the angular momentum of each particle about the contact
point (the impulse acts there), so the total angular momentum as well. The kinetic energy
(translational plus rotational) changes by ``J.(g + g')/2``:

    loss = (m_eff / 2)(1 - eps^2) u_n^2 + c |g_t|^2 (1 - c / (2 m_t)),                (4)

which for a constant beta_t is ``(m_eff/2)(1 - eps^2) u_n^2 + (m_t/2)(1 - beta_t^2)|g_t|^2``;
for identical particles ``m_t = m_eff kappa / (1 + kappa)``.

A flat wall is the limit ``m_j, R_j -> inf`` at rest: n the wall normal into the gas,
``s = R_i w_i``, ``m_eff = m_i``, ``1 / m_t = (1 + 1/kappa_i) / m_i``.

2D: the same formulas with z components zero; the spin is ``w = (0, 0, w_z)`` and only
w_z changes (n x g_t lies along z).

Usage on plain floats (the engine's pair and wall events and the DSMC)::

    un, gtx, gty, gtz = contact_slip(ux, uy, uz, nx, ny, nz, sx, sy, sz)
    fi, fj, ti, tj, si, sj, loss, impulse = rough_pair_collision(
        un, gtx*gtx + gty*gty + gtz*gtz, m_i, m_j, kappa_i, kappa_j, R_i, R_j, eps, model, beta, mu)
    v_i -= fi n + ti g_t;  v_j += fj n + tj g_t
    w_i += si (n x g_t);   w_j += sj (n x g_t)

With ``beta = -1`` (constant model) c = 0 and the velocities, the loss and the impulse are
those of :func:`granulargas.engine._collide.pair_collision` bit for bit.
"""

import math

from granulargas._numba import inlined
from granulargas.engine._collide import pair_collision, wall_collision

#: tangential models
TANGENTIAL_CONSTANT = 0
TANGENTIAL_COULOMB = 1


@inlined
def contact_slip(ux, uy, uz, nx, ny, nz, sx, sy, sz):
    """(u_n, g_t): normal relative velocity and tangential contact velocity, eq. (1).

    ``u`` = v_i - v_j, ``n`` the unit normal from j to i, ``s`` = R_i w_i + R_j w_j
    (a wall: u = v_i, s = R_i w_i, n into the gas).
    """
    un = ux * nx + uy * ny + uz * nz
    gx = ux - (sy * nz - sz * ny) - un * nx
    gy = uy - (sz * nx - sx * nz) - un * ny
    gz = uz - (sx * ny - sy * nx) - un * nz
    return un, gx, gy, gz


@inlined
def tangential_coefficient(un, gt2, m_eff, m_tan, eps, model, beta, mu):
    """c >= 0 of eq. (3): the tangential impulse on i is -c g_t.

    ``gt2`` = |g_t|^2; constant model: (1 + beta) m_t; Coulomb: the same capped at
    mu (1 + eps) m_eff |u_n| / |g_t|.
    """
    c = (1.0 + beta) * m_tan
    if model == TANGENTIAL_COULOMB:
        limit = mu * (1.0 + eps) * m_eff * abs(un)
        if c * c * gt2 > limit * limit:
            c = limit / math.sqrt(gt2)
    return c


@inlined
def rough_pair_collision(un, gt2, mi, mj, ki, kj, ri, rj, eps, model, beta, mu):
    """Velocity and spin changes, energy loss and normal impulse of a rough pair collision.

    Parameters
    ----------
    un, gt2 : float
        u_n < 0 and |g_t|^2 of :func:`contact_slip`.
    mi, mj, ki, kj, ri, rj : float
        Masses, kappa = I / (m R^2) and radii.
    eps : float
        Normal restitution.
    model, beta, mu : int, float, float
        TANGENTIAL_CONSTANT with beta_t, or TANGENTIAL_COULOMB with beta_0 and mu.

    Returns
    -------
    fi, fj : float
        Normal part: v_i -= fi n, v_j += fj n (:func:`~granulargas.engine._collide.pair_collision`).
    ti, tj : float
        Tangential part: v_i -= ti g_t, v_j += tj g_t.
    si, sj : float
        Spins: w_i += si (n x g_t), w_j += sj (n x g_t).
    loss : float
        Kinetic energy lost (translation and rotation), eq. (4).
    impulse : float
        (1 + eps) m_eff u_n (< 0), the normal impulse as in the smooth law (virial).
    """
    fi, fj, loss, impulse = pair_collision(un, mi, mj, eps)
    inv_mt = 1.0 / mi + 1.0 / mj + 1.0 / (ki * mi) + 1.0 / (kj * mj)
    c = tangential_coefficient(un, gt2, mi * mj / (mi + mj), 1.0 / inv_mt, eps, model, beta, mu)
    loss += c * gt2 * (1.0 - 0.5 * c * inv_mt)
    return fi, fj, c / mi, c / mj, c / (ki * mi * ri), c / (kj * mj * rj), loss, impulse



@inlined
def apply_rough_pair(rec, col, w, i, j, dim, nx, ny, nz, gx, gy, gz, fi, fj, ti, tj, si, sj):
    """Apply the changes of :func:`rough_pair_collision` in place: velocities in the columns
    ``col``, ``col + 1`` (and ``col + 2`` when ``dim == 3``) of ``rec``, spins in ``w`` (N, 3)."""
    rec[i, col] -= fi * nx + ti * gx
    rec[i, col + 1] -= fi * ny + ti * gy
    rec[j, col] += fj * nx + tj * gx
    rec[j, col + 1] += fj * ny + tj * gy
    if dim == 3:
        rec[i, col + 2] -= fi * nz + ti * gz
        rec[j, col + 2] += fj * nz + tj * gz
    cx = ny * gz - nz * gy
    cy = nz * gx - nx * gz
    cz = nx * gy - ny * gx
    w[i, 0] += si * cx
    w[i, 1] += si * cy
    w[i, 2] += si * cz
    w[j, 0] += sj * cx
    w[j, 1] += sj * cy
    w[j, 2] += sj * cz

@inlined
def rough_wall_collision(vn, gt2, mi, ki, ri, eps, model, beta, mu):
    """Rough particle against a flat wall at rest (n into the gas, ``vn`` = v_i.n of either sign).

    Returns
    -------
    vn_new : float
        -eps vn (:func:`~granulargas.engine._collide.wall_collision`).
    ti : float
        v_i -= ti g_t (tangential components).
    si : float
        w_i += si (n x g_t).
    loss : float
        Kinetic energy lost, eq. (4) in the wall limit.
    momentum : float
        Normal momentum delivered to the wall, (1 + eps) m_i |vn|.
    """
    vn_new, loss, momentum = wall_collision(vn, mi, eps)
    inv_mt = (1.0 + 1.0 / ki) / mi
    c = tangential_coefficient(vn, gt2, mi, 1.0 / inv_mt, eps, model, beta, mu)
    loss += c * gt2 * (1.0 - 0.5 * c * inv_mt)
    return vn_new, c / mi, c / (ki * mi * ri), loss, momentum
