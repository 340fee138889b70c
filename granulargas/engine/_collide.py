"""Compiled collision law for smooth spheres (numba leaf module).

Pair collision. With n the unit vector from j to i, relative velocity
u = v_i - v_j and u_n = u.n < 0 (approaching), the post-collision velocities are

    v_i' = v_i - (1 + eps) m_j / (m_i + m_j) u_n n
    v_j' = v_j + (1 + eps) m_i / (m_i + m_j) u_n n                   (2)

so momentum is conserved, the tangential relative velocity is kept and the
normal one becomes -eps u_n. The kinetic energy lost is
(1 - eps^2) m_eff u_n^2 / 2 with m_eff = m_i m_j / (m_i + m_j); the momentum
given to i is Delta p_i = -(1 + eps) m_eff u_n n, so the collision adds
r_ij . Delta p_i = -(1 + eps) m_eff u_n |r_ij| to the virial.

Sphere-wall collision: a flat wall of the same material, infinitely heavy, is the
limit m_j -> inf, R_j -> inf of (2): the normal velocity v_n becomes -eps v_n,
with eps from the same rule at R_eff = R_i, m_eff = m_i; the wall receives the
normal momentum (1 + eps) m_i |v_n| and the energy lost is (1 - eps^2) m_i v_n^2 / 2.

eps is 1 (elastic), a constant, or the viscoelastic eps(beta) with
beta = k (R_eff g_n / m_eff^2)^(1/5) (Schwager & Pöschel (1997), eq. (3); ARCHITECTURE.md), read
from the tabulated spline :func:`granulargas.contact.lookup.table_lookup`.
TC model (Luding & McNamara 1998): if a particle collided less than
``tc_time`` ago the collision is elastic.

Everything here works on plain floats, so that other collision-driven methods
(the DSMC of :mod:`granulargas.dsmc`) apply exactly the same law::

    eps = restitution(kind, eps_const, prefactor, inv_h, coeffs, g_n, r_eff, m_eff)
    fi, fj, loss, impulse = pair_collision(u_n, m_i, m_j, eps)
    v_i -= fi * n;  v_j += fj * n          # loss = energy lost, impulse = (1 + eps) m_eff u_n
"""

from granulargas._numba import inlined
from granulargas.contact.lookup import table_lookup

ELASTIC = 0
CONSTANT = 1
VISCOELASTIC = 2


@inlined
def restitution(kind, eps_const, prefactor, inv_h, coeffs, gn, r_eff, m_eff):
    """Coefficient of restitution of one collision (-1.0 if beyond the table).

    Parameters
    ----------
    kind : int
        ELASTIC, CONSTANT or VISCOELASTIC.
    eps_const : float
        The constant eps (kind CONSTANT).
    prefactor, inv_h, coeffs
        Viscoelastic pair prefactor k and the restitution table (kind VISCOELASTIC).
    gn : float
        Normal impact speed |u_n| > 0.
    r_eff, m_eff : float
        Effective radius and mass of the contact (R_i for a wall, m_i for a wall).
    """
    if kind == ELASTIC:
        return 1.0
    if kind == CONSTANT:
        return eps_const
    beta = prefactor * (r_eff * gn / (m_eff * m_eff)) ** 0.2
    return table_lookup(beta, inv_h, coeffs)


@inlined
def pair_collision(un, mi, mj, eps):
    """Velocity changes, energy loss and impulse of a pair collision, eq. (2).

    Parameters
    ----------
    un : float
        Normal relative velocity (v_i - v_j).n < 0, n the unit vector from j to i.
    mi, mj : float
        Masses.
    eps : float
        Coefficient of restitution.

    Returns
    -------
    fi, fj : float
        v_i' = v_i - fi n, v_j' = v_j + fj n.
    loss : float
        Kinetic energy lost, (1 - eps^2) m_eff u_n^2 / 2.
    impulse : float
        (1 + eps) m_eff u_n (< 0): Delta p_i = impulse n; the virial term is
        impulse |r_ij| (r_ij . Delta p_i).
    """
    msum = mi + mj
    m_eff = mi * mj / msum
    f = (1.0 + eps) * un / msum
    return f * mj, f * mi, 0.5 * (1.0 - eps * eps) * m_eff * un * un, (1.0 + eps) * m_eff * un


@inlined
def wall_collision(vn, mi, eps):
    """Sphere-wall collision: (new normal velocity, energy lost, momentum given to the wall).

    ``vn`` is the velocity component along the wall normal (either sign); the
    momentum delivered is (1 + eps) m_i |v_n| >= 0.
    """
    g = abs(vn)
    return -eps * vn, 0.5 * (1.0 - eps * eps) * mi * vn * vn, (1.0 + eps) * mi * g
