"""Compiled collision rule for smooth spheres (numba leaf module).

With n the unit vector from j to i, relative velocity u = v_i - v_j and
u_n = u.n < 0 (approaching), the post-collision velocities are

    v_i' = v_i - (1 + eps) m_j / (m_i + m_j) u_n n
    v_j' = v_j + (1 + eps) m_i / (m_i + m_j) u_n n                   (2)

so momentum is conserved, the tangential relative velocity is kept and the
normal one becomes -eps u_n. The kinetic energy lost is
(1 - eps^2) m_eff u_n^2 / 2 with m_eff = m_i m_j / (m_i + m_j).

eps is 1 (elastic), a constant, or the viscoelastic eps(beta) with
beta = k (R_eff g_n / m_eff^2)^(1/5) (Schwager & Pöschel (1997), eq. (3); ARCHITECTURE.md), read
from the tabulated spline :func:`granulargas.contact.lookup.table_lookup`.
TC model (Luding & McNamara 1998): if either particle collided less than
``tc_time`` ago the collision is elastic.
"""

from granulargas._numba import jit
from granulargas.contact.lookup import table_lookup

ELASTIC = 0
CONSTANT = 1
VISCOELASTIC = 2


@jit(inline="always")
def restitution(kind, eps_const, prefactor, inv_h, coeffs, gn, r_eff, m_eff):
    """Coefficient of restitution of one collision (-1.0 if beyond the table)."""
    if kind == ELASTIC:
        return 1.0
    if kind == CONSTANT:
        return eps_const
    beta = prefactor * (r_eff * gn / (m_eff * m_eff)) ** 0.2
    return table_lookup(beta, inv_h, coeffs)
