"""Compiled lookup of the oblique-contact table and the resolved collision (a numba leaf module).

The table (built by :mod:`granulargas.contact.oblique_grid`) covers the box
s = sqrt(beta) in [0, n_s h_s), zeta = sqrt(c) / (1 + sqrt(c)) in [0, 1],
delta in [0, n_d h_d), cut into cells; in cell (a, b, d) with local variables
u = 2 (position in the cell) - 1 in [-1, 1]

    f_k = sum_{i,j,l} coeffs[a, b, d, k, i, j, l] u_s^i u_zeta^j u_delta^l,

k = 0, 1, 2 for eps_s, tau_s (1 + c) and M (1 + c)^2 (equations in
:mod:`granulargas.contact.oblique`). Out of range gives a status, never an
extrapolation.
"""

import math

from granulargas._numba import jit

#: Status codes of :func:`oblique_lookup` and :func:`resolve_collision`.
LOOKUP_OK = 0
LOOKUP_BETA_RANGE = 1
LOOKUP_DELTA_RANGE = 2
LOOKUP_BAD_INPUT = 3


@jit
def oblique_lookup(beta, c, delta, inv_hs, inv_hd, coeffs, out):
    """eps_s, tau_s and M of an oblique contact by table lookup.

    Parameters
    ----------
    beta, c, delta : float
        Parameters of eq. (3) of :mod:`granulargas.contact.oblique` (c may be inf).
    inv_hs, inv_hd : float
        1 / cell width in sqrt(beta) and in delta.
    coeffs : float64 array (n_s, n_zeta, n_d, 3, p_s, p_zeta, p_d)
    out : float64 array (>= 3,)
        Receives eps_s, tau_s, M.

    Returns
    -------
    int
        LOOKUP_OK, LOOKUP_BETA_RANGE (beta < 0 or beyond the table),
        LOOKUP_DELTA_RANGE, or LOOKUP_BAD_INPUT (c < 0 or nan).
    """
    n_s, n_z, n_d = coeffs.shape[0], coeffs.shape[1], coeffs.shape[2]
    p_s, p_z, p_d = coeffs.shape[4], coeffs.shape[5], coeffs.shape[6]
    if not (c >= 0.0):
        return LOOKUP_BAD_INPUT
    xs = math.sqrt(beta) * inv_hs if beta >= 0.0 else math.nan
    if not (xs < n_s):  # also beta < 0 and nan
        return LOOKUP_BETA_RANGE
    xd = delta * inv_hd
    if not (xd >= 0.0 and xd < n_d):
        return LOOKUP_DELTA_RANGE
    a = int(xs)
    us = 2.0 * (xs - a) - 1.0
    d = int(xd)
    ud = 2.0 * (xd - d) - 1.0
    q = math.sqrt(c)
    xz = (1.0 - 1.0 / (1.0 + q)) * n_z  # zeta = sqrt(c) / (1 + sqrt(c)), 1 at c = inf
    b = int(xz)
    if b >= n_z:
        b = n_z - 1
    uz = 2.0 * (xz - b) - 1.0
    # the cell's block coeffs[a, b, d] is contiguous: walk it backwards for the nested Horner scheme
    flat = coeffs.reshape(-1)
    blk = p_s * p_z * p_d
    o = ((a * n_z + b) * n_d + d) * 3 * blk - 1
    for k in range(3):
        o += blk
        i_o = o
        v = 0.0
        for i in range(p_s):
            vz = 0.0
            for j in range(p_z):
                vd = 0.0
                for l in range(p_d):
                    vd = vd * ud + flat[i_o]
                    i_o -= 1
                vz = vz * uz + vd
            v = v * us + vz
        out[k] = v
    # undo the normalisation: tau_s (1 + c) and M (1 + c)^2 stay O(1) for grazing impacts
    w = 1.0 / (1.0 + c)
    out[1] *= w
    out[2] *= w * w
    return LOOKUP_OK


@jit
def resolve_collision(normal_speed, tangential_speed, distance, damping_constant, compression_constant,
                      inv_hs, inv_hd, coeffs, work, out):
    """Outcome of a frictionless viscoelastic collision that takes time, in the frame of first touch.

    Parameters
    ----------
    normal_speed : float
        g_n > 0, approach speed along n_0 (the unit vector from j to i at touch).
    tangential_speed : float
        g_t >= 0, along the unit tangential direction e_t of the relative velocity.
    distance : float
        D = R_i + R_j.
    damping_constant : float
        beta / g_n^{1/5} of the pair, (3/2) A rho^{2/5} (the pair constant b_ij of
        :func:`granulargas.contact.material.pair_constant`).
    compression_constant : float
        X / g_n^{4/5} of the pair, rho^{-2/5}.
    inv_hs, inv_hd, coeffs :
        The table (see :func:`oblique_lookup`).
    work : float64 array (>= 3,)
        Scratch.
    out : float64 array (>= 5,)
        Receives t_c (touch to separation), the relative velocity after the
        contact along n_0 and e_t (the approach velocity was (-g_n, g_t)), and
        the relative position x_i - x_j at separation along n_0 and e_t.

    Returns
    -------
    int
        Status of :func:`oblique_lookup` (LOOKUP_BAD_INPUT also for g_n <= 0).
    """
    g_n = normal_speed
    g_t = tangential_speed
    if not (g_n > 0.0 and g_t >= 0.0 and distance > 0.0):
        return LOOKUP_BAD_INPUT
    beta = damping_constant * g_n ** 0.2
    scale_x = compression_constant * g_n ** 0.8
    delta = scale_x / distance
    ratio = g_t / g_n
    c = delta * ratio * ratio
    status = oblique_lookup(beta, c, delta, inv_hs, inv_hd, coeffs, work)
    if status != LOOKUP_OK:
        return status
    eps_s = work[0]
    tau_s = work[1]
    # Delta phi = sqrt(c delta) (tau_s + delta M), sqrt(c delta) = delta g_t / g_n
    dphi = delta * ratio * (tau_s + delta * work[2])
    cs = math.cos(dphi)
    sn = math.sin(dphi)
    out[0] = tau_s * scale_x / g_n
    out[1] = eps_s * g_n * cs - g_t * sn
    out[2] = eps_s * g_n * sn + g_t * cs
    out[3] = distance * cs
    out[4] = distance * sn
    return LOOKUP_OK


@jit
def oblique_lookup_many(beta, c, delta, inv_hs, inv_hd, coeffs, out):
    """:func:`oblique_lookup` over arrays; out (n, 3) (nan where out of range). Returns the count of misses."""
    misses = 0
    for i in range(beta.shape[0]):
        st = oblique_lookup(beta[i], c[i], delta[i], inv_hs, inv_hd, coeffs, out[i])
        if st != LOOKUP_OK:
            misses += 1
            for k in range(3):
                out[i, k] = math.nan
    return misses
