"""Collision normals of the Enskog-Boltzmann kernel and the pair velocity update (numba).

For a pair with relative velocity g = v_i - v_j the collision integral weighs
the unit vector k (from i to j at contact) with Theta(g.k) (g.k). The update
needs only the normal part of g,

    p = (g.k) k,        g_n = g.k = |p|,

drawn directly from that weight, without building k:

* 3D: k is cosine-distributed about g/|g|. With e uniform on the unit sphere,
  (g/|g| + e)/|g/|g| + e| has exactly that law, and then
  p = (g + |g| e)/2, g_n^2 = (|g|^2 + |g| g.e)/2 -- the isotropic scattering
  of hard spheres (Bird 1994, "Molecular Gas Dynamics and the Direct
  Simulation of Gas Flows", sec. 2.5). e comes from Marsaglia's (1972) method
  (Ann. Math. Stat. 43, 645): a point (a, b) uniform in the unit disk, s = a^2+b^2,
  e = (2a sqrt(1-s), 2b sqrt(1-s), 1-2s); no trigonometric functions.
* 2D: the angle theta between k and g has density cos(theta)/2 on
  (-pi/2, pi/2), so sin(theta) = 2U - 1 is uniform; with c^2 = 1 - sin^2,
  p = c^2 g + c sin(theta) g_perp (g_perp = g rotated by +90 degrees), g_n^2 = c^2 |g|^2.

Rough particles (:func:`apply_rough_update`): the tangential law needs the unit normal
itself, ``n = -p / g_n`` (from j to i, as in the engine), and then the engine's rough law
(:mod:`granulargas.engine._rough`) with the spins; one square root and one division more
per collision than the smooth update.

The velocity update is the smooth-sphere rule of
:mod:`granulargas.engine._collide`:

    v_i' = v_i - (1 + eps) m_j/(m_i + m_j) p,   v_j' = v_j + (1 + eps) m_i/(m_i + m_j) p,

with the energy loss (1 - eps^2) m_eff g_n^2 / 2. It is written here on p rather than
calling :func:`granulargas.engine._collide.pair_collision`, which takes the unit normal and
u_n: building them costs a square root and a division per collision, which lowered the
DSMC's collision rate by about 10 % (N = 10^5, 3D, constant eps, CPU time,
``scripts/benchmarks/dsmc.py``: 7.3 against 8.1 M collisions/s); the restitution itself is the
engine's (:func:`granulargas.engine._collide.restitution`).
"""

import math

import numpy as np

from granulargas._numba import inlined
from granulargas.dsmc._random import next_u64
from granulargas.engine._rough import apply_rough_pair, contact_slip, rough_pair_collision

_MASK32 = np.uint64(0xFFFFFFFF)
_S32 = np.uint64(32)
_INV31 = 1.0 / 2147483648.0  # 2^-31


@inlined
def normal_part_3d(state, gx, gy, gz, g2):
    """(p_x, p_y, p_z, g_n^2) for a 3D pair with relative velocity g (|g|^2 = g2 > 0)."""
    while True:
        r = next_u64(state)
        a = np.float64(r & _MASK32) * _INV31 - 1.0
        b = np.float64(r >> _S32) * _INV31 - 1.0
        s = a * a + b * b
        if s < 1.0:
            break
    f = 2.0 * math.sqrt(1.0 - s)
    ex = a * f
    ey = b * f
    ez = 1.0 - 2.0 * s
    g = math.sqrt(g2)
    px = 0.5 * (gx + g * ex)
    py = 0.5 * (gy + g * ey)
    pz = 0.5 * (gz + g * ez)
    gn2 = 0.5 * (g2 + g * (gx * ex + gy * ey + gz * ez))
    return px, py, pz, gn2


@inlined
def normal_part_2d(state, gx, gy, g2):
    """(p_x, p_y, g_n^2) for a 2D pair with relative velocity g (|g|^2 = g2 > 0)."""
    sn = np.float64(next_u64(state) >> np.uint64(11)) * (2.0 / 9007199254740992.0) - 1.0
    c2 = 1.0 - sn * sn
    cs = sn * math.sqrt(c2)
    px = c2 * gx - cs * gy
    py = c2 * gy + cs * gx
    return px, py, c2 * g2


@inlined
def apply_pair_update(rec, i, j, dim, px, py, pz, eps, mi, mj):
    """Smooth-sphere velocity update of the pair (i, j) from the normal part p of their
    relative velocity; momentum is conserved exactly up to rounding."""
    f = (1.0 + eps) / (mi + mj)
    fi = f * mj
    fj = f * mi
    rec[i, 0] -= fi * px
    rec[i, 1] -= fi * py
    rec[j, 0] += fj * px
    rec[j, 1] += fj * py
    if dim == 3:
        rec[i, 2] -= fi * pz
        rec[j, 2] += fj * pz


@inlined
def apply_rough_update(rec, spins, i, j, dim, px, py, pz, gn2, eps, mi, mj, ri, rj):
    """Rough update of the pair (i, j) from the normal part p of their relative velocity
    (k = p / |p| from i to j); ``spins``: the engine's :class:`~granulargas.engine._state.Spins`
    record (``w`` (N, 3), 2D the z column; ``kappa`` (N,) or one shared value (1,)).
    Returns the energy lost (translation and rotation)."""
    gn = math.sqrt(gn2)
    if not gn > 0.0:  # a grazing candidate (probability zero): nothing to do
        return 0.0
    inv = -1.0 / gn
    nx = px * inv
    ny = py * inv
    nz = pz * inv
    w = spins.w
    kap = spins.kappa
    ki = kap[0] if kap.shape[0] == 1 else kap[i]
    kj = kap[0] if kap.shape[0] == 1 else kap[j]
    uz = rec[i, 2] - rec[j, 2] if dim == 3 else 0.0
    un, gx, gy, gz = contact_slip(rec[i, 0] - rec[j, 0], rec[i, 1] - rec[j, 1], uz, nx, ny, nz,
                                  ri * w[i, 0] + rj * w[j, 0], ri * w[i, 1] + rj * w[j, 1],
                                  ri * w[i, 2] + rj * w[j, 2])
    fi, fj, ti, tj, si, sj, loss, _ = rough_pair_collision(un, gx * gx + gy * gy + gz * gz, mi, mj, ki, kj, ri, rj,
                                                           eps, spins.model, spins.beta, spins.mu)
    apply_rough_pair(rec, 0, w, i, j, dim, nx, ny, nz, gx, gy, gz, fi, fj, ti, tj, si, sj)
    return loss
