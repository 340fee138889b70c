r"""Collisions that take time: the pair jumps onto its outgoing line (numba leaf module).

A frictionless viscoelastic contact lasts t_c and turns the contact normal
while the spheres overlap (equations and table in :mod:`granulargas.contact.oblique`).
The engine keeps its straight-line dynamics and applies the whole contact at
the moment of first touch t_0, as Müller & Pöschel (2013) do: with
n_0 = r_0 / |r_0| (r_0 = x_i - x_j, |r_0| = D = R_i + R_j), u = v_i - v_j,
g_n = -u . n_0, e_t the unit vector of the tangential part g_t e_t of u,
:func:`granulargas.contact.oblique_lookup.resolve_collision` gives t_c, the
relative velocity v' after the contact and the relative position r_s at
separation, in the frame (n_0, e_t). The pair is put on the straight line it
leaves the contact on, extended back to t_0:

    a = r_s - v' t_c                                                   (1)
    x_i += m_j / M (a - r_0),   x_j -= m_i / M (a - r_0)
    v_i += m_j / M (v' - u),    v_j -= m_i / M (v' - u)                (2)

(M = m_i + m_j). The centre of mass and the total momentum are untouched; from
t_0 + t_c on both spheres are exactly on the trajectories of the contact force
(Newton), before that on the virtual extension of their outgoing lines, which
pass inside |r| < D. While t < t_0 + t_c the pair is "in contact": each
particle's ``contacts.until`` and ``contacts.partner`` hold the end and the
partner, and :func:`granulargas.engine._loop.predict` does not predict that
pair (the extended lines overlap). The energy lost is
m_eff (|u|^2 - |v'|^2) / 2 (m_eff = m_i m_j / M).

Pressure: the collisional virial of the contact, the integral of r . F dt,
together with the kinetic term m_eff |v'|^2 t_c that the virtual lines carry
instead of the true relative motion, is m_eff (a . v' - r_0 . u) (integrate
m_eff r . r'' by parts); an instantaneous collision (a = r_0) gives the usual
r_0 . Delta p_i.

Third particles: a collision of i with k while i is still in contact with
another particle (t < ``until[i]``, ``partner[i]`` != k) is a three-body
contact, which this two-body scheme does not describe. It is counted
(``counters.three_body``) and resolved by the same rule from the current,
virtual state; i's contact then continues until the later of the two ends,
with partner k. The scheme is for dilute gases, where their fraction of the
collisions is ~ t_c / t_free.

The jump moves each sphere by O(X) (about -eps g_n t_c along n_0); a sphere
that lands beyond half the shell from its list centre gets a list expiry at
once (:func:`granulargas.engine._loop.predict_expiry` returns zero delay),
whose rebuild moves it to its new cell.
"""

import math

from granulargas._numba import inlined, kernel
from granulargas.contact.oblique_lookup import LOOKUP_BETA_RANGE, LOOKUP_OK, resolve_collision

#: Status codes (the loop passes them on): the impact lies beyond the oblique-contact
#: table in beta, or in delta (err_i, err_j name the pair).
OBLIQUE_BETA_RANGE = 22
OBLIQUE_DELTA_RANGE = 23


@inlined
def _wrap(i, a, x, rec, img, period):
    """Store coordinate a of slot i, wrapped into [0, period) (images counted)."""
    if x >= period:
        x -= period
        img[i, a] += 1
    elif x < 0.0:
        x += period
        img[i, a] -= 1
        if x >= period:  # -tiny + L rounds to L
            x = 0.0
            img[i, a] += 1
    rec[i, a] = x


@kernel(python=False)
def resolved_pair(i, j, te, dx, dy, dz, p, contacts, c, rule, period):
    """Collision that takes time of slots i, j (streamed to te, touching, approaching).

    (dx, dy, dz) = r_0, the nearest-image x_i - x_j. Applies eqs. (1)-(2) of the
    module docstring, the energy lost and the virial to the counters ``c``, and
    marks the contact. Returns 0, or OBLIQUE_BETA_RANGE / OBLIQUE_DELTA_RANGE
    (nothing changed; ``c.err_i``, ``c.err_j`` set).
    """
    rec = p.rec
    until = contacts.until
    partner = contacts.partner
    out = contacts.out
    dist = math.sqrt(dx * dx + dy * dy + dz * dz)
    inv = 1.0 / dist
    nx = dx * inv
    ny = dy * inv
    nz = dz * inv
    ux = rec[i, 3] - rec[j, 3]
    uy = rec[i, 4] - rec[j, 4]
    uz = rec[i, 5] - rec[j, 5]
    un = ux * nx + uy * ny + uz * nz  # < 0
    tx = ux - un * nx
    ty = uy - un * ny
    tz = uz - un * nz
    gt = math.sqrt(tx * tx + ty * ty + tz * tz)
    if gt > 0.0:
        tx /= gt
        ty /= gt
        tz /= gt
    ri = rec[i, 7]
    rj = rec[j, 7]
    mi = p.mass[i]
    mj = p.mass[j]
    msum = mi + mj
    m_eff = mi * mj / msum
    r_eff = ri * rj / (ri + rj)
    damping = rule.prefactor * (r_eff / (m_eff * m_eff)) ** 0.2
    compression = rule.compression * (m_eff * m_eff / r_eff) ** 0.2
    st = resolve_collision(-un, gt, ri + rj, damping, compression, rule.ob_inv_hs, rule.ob_inv_hd,
                           rule.ob_coeffs, contacts.work, out)
    if st != LOOKUP_OK:
        c.err_i = i
        c.err_j = j
        return OBLIQUE_BETA_RANGE if st == LOOKUP_BETA_RANGE else OBLIQUE_DELTA_RANGE
    if (until[i] > te and partner[i] != j) or (until[j] > te and partner[j] != i):
        c.three_body += 1
    tc = out[0]
    # outgoing relative velocity v' and the point a of its line at te, eq. (1)
    wx = out[1] * nx + out[2] * tx
    wy = out[1] * ny + out[2] * ty
    wz = out[1] * nz + out[2] * tz
    an = out[3] - out[1] * tc
    at = out[4] - out[2] * tc
    ax = an * nx + at * tx
    ay = an * ny + at * ty
    az = an * nz + at * tz
    fi = mj / msum
    fj = mi / msum
    # eq. (2): centre of mass and momentum untouched
    sx = ax - dx
    sy = ay - dy
    sz = az - dz
    _wrap(i, 0, rec[i, 0] + fi * sx, rec, p.img, period[0])
    _wrap(i, 1, rec[i, 1] + fi * sy, rec, p.img, period[1])
    _wrap(i, 2, rec[i, 2] + fi * sz, rec, p.img, period[2])
    _wrap(j, 0, rec[j, 0] - fj * sx, rec, p.img, period[0])
    _wrap(j, 1, rec[j, 1] - fj * sy, rec, p.img, period[1])
    _wrap(j, 2, rec[j, 2] - fj * sz, rec, p.img, period[2])
    ex = wx - ux
    ey = wy - uy
    ez = wz - uz
    rec[i, 3] += fi * ex
    rec[i, 4] += fi * ey
    rec[i, 5] += fi * ez
    rec[j, 3] -= fj * ex
    rec[j, 4] -= fj * ey
    rec[j, 5] -= fj * ez
    loss = 0.5 * m_eff * ((ux * ux + uy * uy + uz * uz) - (wx * wx + wy * wy + wz * wz))
    c.dissipated += loss
    c.sum_mv2 -= 2.0 * loss
    c.virial += m_eff * ((ax * wx + ay * wy + az * wz) - (dx * ux + dy * uy + dz * uz))
    end = te + tc
    until[i] = end if end > until[i] else until[i]
    until[j] = end if end > until[j] else until[j]
    partner[i] = j
    partner[j] = i
    return 0
