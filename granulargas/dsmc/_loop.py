"""The compiled DSMC loop: the sequential majorant process (numba).

Homogeneous Enskog-Boltzmann equation for N particles in a volume V: the pair
(i, j) collides at the rate

    r_ij = chi sigma_ij^(d-1) B_d |v_i - v_j| / V,   B_d = integral over the unit sphere of
    Theta(g^.k)(g^.k) dk = pi^((d-1)/2) / Gamma((d+1)/2)  (pi in 3D, 2 in 2D),

and the collision normal k then has the density Theta(g.k)(g.k) (see
:mod:`granulargas.dsmc._collide`). Each particle thus collides at the Enskog
frequency of the density (N - 1)/V of its partners. With the bound
G >= |v_i - v_j| (:mod:`granulargas.dsmc._majorant`) and sigma_max the largest
diameter, every pair's rate is at most chi sigma_max^(d-1) B_d G / V, so the
candidates form a Poisson process of total rate

    Lambda = N (N - 1)/2 chi sigma_max^(d-1) B_d G / V,

each a uniformly drawn pair, accepted with probability
sigma_ij^(d-1) |v_i - v_j| / (sigma_max^(d-1) G) (thinning; Lewis & Shedler 1979).
This is the Kac process / Bird's no-time-counter scheme with one global bound
and no time step: the waiting time between candidates is exponential with
rate Lambda, redrawn after every collision because G may change (memoryless,
so exact). The next candidate's time is part of the state, so a run stopped at
any time and continued draws exactly the numbers an uninterrupted run draws.

Memory: velocities in rows of 2 (2D) or 4 (3D, one padding word) float64, so
a particle is one aligned 16- or 32-byte piece of one cache line. Candidate
pairs come from the counter-based pair stream, so the rows of the pairs
``RING`` candidates ahead are prefetched while the current one is processed.
"""

import math

import numpy as np

from granulargas._numba import jit
from granulargas.dsmc._collide import apply_pair_update, normal_part_2d, normal_part_3d
from granulargas.dsmc._majorant import (
    build_fast_set,
    choose_fast_class,
    flip_fast,
    majorant_parts,
    select_fast,
    speed_class,
    top_classes,
)
from granulargas.dsmc._random import bounded, pair_of, uniform
from granulargas.engine._collide import VISCOELASTIC, restitution
from granulargas.engine._prefetch import prefetch

# status codes
DONE = 0  # reached ``until``
MAX_COLLISIONS = 1  # reached the collision target
BUDGET = 2  # candidate budget of this chunk used up (progress callback, then continue)
TABLE_RANGE = 3  # an impact beyond the restitution table

# scal slots (float64)
S_TIME = 0  # time of the last collision (``until`` after DONE)
S_NEXT = 1  # time of the pending collision
S_DISSIPATED = 2  # kinetic energy lost in collisions (cumulative)
S_RATE = 3  # c = chi sigma_max^(d-1) B_d / V: a pair's majorant rate per unit of bound
S_FRAME = 4  # 4, 5, 6: frame velocity u of the speed classes
N_SCAL = 7

# iscal slots (int64)
I_COLLISIONS = 0
I_CANDIDATES = 1  # candidates drawn (statistics)
I_PAIR_STREAM = 2  # position in the pair stream (state)
I_TOP = 3  # highest occupied speed class (an upper estimate; exact after top_classes)
I_FAST_CLASS = 4  # kf: particles of class > kf are fast (state)
I_N_FAST = 5  # number of fast particles
I_PENDING_I = 6  # pair of the pending (accepted, not yet executed) collision; -1: none
I_PENDING_J = 7
I_ERR_I = 8
I_ERR_J = 9
N_ISCAL = 10

# fpar slots
F_EPS = 0  # constant eps
F_PREFACTOR = 1  # viscoelastic pair prefactor k
F_INV_H = 2  # restitution table grid
F_SIGMA_MAX_POW = 3  # sigma_max^(d-1)
F_MASS = 4  # mass (monodisperse)
F_RADIUS = 5  # radius (monodisperse)
N_FPAR = 6

RING = 16  # candidates prefetched ahead (power of two)


@jit(inline="always")
def _speed2(rec, i, dim, fx, fy, fz):
    cx = rec[i, 0] - fx
    cy = rec[i, 1] - fy
    w2 = cx * cx + cy * cy
    if dim == 3:
        cz = rec[i, 2] - fz
        w2 += cz * cz
    return w2


@jit
def reselect_fast(rec, dim, hist, iscal, scal, bits, fen):
    """Choose the fast-class threshold for the current speeds and rebuild the fast set."""
    k1, k2 = top_classes(hist, iscal[I_TOP])
    kf = choose_fast_class(hist, k1, k2, rec.shape[0])
    iscal[I_FAST_CLASS] = kf
    iscal[I_N_FAST] = build_fast_set(rec, dim, scal[S_FRAME:S_FRAME + 3], kf, bits, fen)


@jit
def advance(rec, radius, mass, mono, dim, hist, bits, fen, rng, kind, fpar, coeffs, until, target,
            budget, reselect_every, ring, scal, iscal):
    """Collide until ``until``, ``target`` collisions or about ``budget`` candidates.

    Parameters
    ----------
    rec : float64 (N, 2) or (N, 4)
        Velocities (columns 0..dim-1), modified in place.
    radius, mass : float64 (N,)
        Per-particle radius and mass (read only when ``mono`` is False).
    mono : bool
        All particles alike (radius fpar[F_RADIUS], mass fpar[F_MASS]).
    hist : int64 (8192,)
        Speed-class counts (:mod:`granulargas.dsmc._majorant`), kept current.
    bits, fen : uint64 (W,), int64 (W + 1,)
        Fast set (:func:`granulargas.dsmc._majorant.build_fast_set`), kept current.
    rng : uint64 (5,)
        Random state (:mod:`granulargas.dsmc._random`), advanced in place.
    kind : int
        Restitution kind of :mod:`granulargas.engine._collide`.
    until : float
        End time; collisions with time <= until are processed.
    target : int
        Stop right after the collision that makes ``iscal[I_COLLISIONS] == target``.
    budget : int
        Return BUDGET after the first collision once this many candidates were drawn.
    reselect_every : int
        The fast threshold is chosen anew whenever the collision count is a multiple.
    ring : int64 (2, RING)
        Work space for the pairs ahead (rebuilt on entry; not state).

    Returns
    -------
    int
        Status code (DONE, MAX_COLLISIONS, BUDGET, TABLE_RANGE).
    """
    n = rec.shape[0]
    key = rng[4]
    fx = scal[S_FRAME]
    fy = scal[S_FRAME + 1]
    fz = scal[S_FRAME + 2] if dim == 3 else 0.0
    eps_const = fpar[F_EPS]
    prefactor = fpar[F_PREFACTOR]
    inv_h = fpar[F_INV_H]
    smax_pow = fpar[F_SIGMA_MAX_POW]
    m0 = fpar[F_MASS]
    r0 = fpar[F_RADIUS]
    c_rate = scal[S_RATE]
    half_pairs = 0.5 * n * (n - 1.0)
    k = iscal[I_PAIR_STREAM]
    cand = iscal[I_CANDIDATES]
    coll = iscal[I_COLLISIONS]
    pi = iscal[I_PENDING_I]
    pj = iscal[I_PENDING_J]
    kf = iscal[I_FAST_CLASS]
    nfast = iscal[I_N_FAST]
    k1, k2 = top_classes(hist, iscal[I_TOP])
    a, b = majorant_parts(k1, k2, kf)
    rate_a = half_pairs * a
    rate_b = (n - 1.0) * nfast * b
    inv_rate = 1.0 / (c_rate * (rate_a + rate_b))
    p_a = rate_a / (rate_a + rate_b)  # exactly 1 when there is no fast particle
    inv_p_a = 1.0 / p_a
    inv_p_b = 1.0 / (1.0 - p_a) if p_a < 1.0 else 0.0
    next_reselect = (coll // reselect_every + 1) * reselect_every
    t_next = scal[S_NEXT]
    time = scal[S_TIME]
    dissipated = scal[S_DISSIPATED]
    for q in range(RING):
        u1, u2 = pair_of(key, k + q, n)
        ring[0, q] = u1
        ring[1, q] = u2
        prefetch(rec, u1)
        prefetch(rec, u2)
    end = cand + budget
    while True:
        if pi < 0:
            # ---- draw candidates until one is accepted; its time is the sum of the gaps
            prod = 1.0
            logs = 0.0
            while True:
                cand += 1
                prod *= 1.0 - uniform(rng)
                if prod < 1e-280:
                    logs += math.log(prod)
                    prod = 1.0
                u = uniform(rng)
                if u < p_a:
                    # process A: a uniform pair, bound a + b (f_i + f_j)
                    x = u * inv_p_a
                    slot = k & (RING - 1)
                    i = ring[0, slot]
                    j = ring[1, slot]
                    u1, u2 = pair_of(key, k + RING, n)
                    ring[0, slot] = u1
                    ring[1, slot] = u2
                    prefetch(rec, u1)
                    prefetch(rec, u2)
                    if not mono:
                        prefetch(radius, u1)
                        prefetch(radius, u2)
                        prefetch(mass, u1)
                        prefetch(mass, u2)
                    k += 1
                    fast = 0
                else:
                    # process B: a fast particle and any other, bound a + b (1 + f_j)
                    x = (u - p_a) * inv_p_b
                    i = select_fast(bounded(rng, np.uint64(nfast)), bits, fen)
                    j = bounded(rng, np.uint64(n - 1))
                    if j >= i:
                        j += 1
                    fast = 1
                gx = rec[i, 0] - rec[j, 0]
                gy = rec[i, 1] - rec[j, 1]
                g2 = gx * gx + gy * gy
                if dim == 3:
                    gz = rec[i, 2] - rec[j, 2]
                    g2 += gz * gz
                if not mono:
                    sij = radius[i] + radius[j]
                    s2 = sij * sij
                    if dim == 3:
                        s2 *= s2
                    x *= smax_pow
                    g2 *= s2
                # the bound is at least a: most rejections need no speed classes
                xa = x * a
                if xa * xa >= g2:
                    continue
                if fast == 0 and speed_class(_speed2(rec, i, dim, fx, fy, fz)) > kf:
                    fast += 1
                if speed_class(_speed2(rec, j, dim, fx, fy, fz)) > kf:
                    fast += 1
                xm = x * (a + b * fast)
                if xm * xm < g2:
                    break
            t_next = time - (logs + math.log(prod)) * inv_rate
            pi = i
            pj = j
        if t_next > until:
            time = until
            status = DONE
            break
        # ---- the pending collision
        i = pi
        j = pj
        vix = rec[i, 0]
        viy = rec[i, 1]
        vjx = rec[j, 0]
        vjy = rec[j, 1]
        gx = vix - vjx
        gy = viy - vjy
        g2 = gx * gx + gy * gy
        viz = 0.0
        vjz = 0.0
        gz = 0.0
        if dim == 3:
            viz = rec[i, 2]
            vjz = rec[j, 2]
            gz = viz - vjz
            g2 += gz * gz
        if mono:
            mi = m0
            mj = m0
            r_eff = 0.5 * r0
        else:
            mi = mass[i]
            mj = mass[j]
            r_eff = radius[i] * radius[j] / (radius[i] + radius[j])
        if dim == 3:
            px, py, pz, gn2 = normal_part_3d(rng, gx, gy, gz, g2)
        else:
            px, py, gn2 = normal_part_2d(rng, gx, gy, g2)
            pz = 0.0
        m_eff = mi * mj / (mi + mj)
        gn = math.sqrt(gn2) if kind == VISCOELASTIC else 0.0
        eps = restitution(kind, eps_const, prefactor, inv_h, coeffs, gn, r_eff, m_eff)
        if eps < 0.0:
            iscal[I_ERR_I] = i
            iscal[I_ERR_J] = j
            status = TABLE_RANGE
            break
        oi = speed_class(_speed2(rec, i, dim, fx, fy, fz))
        oj = speed_class(_speed2(rec, j, dim, fx, fy, fz))
        apply_pair_update(rec, i, j, dim, px, py, pz, eps, mi, mj)
        dissipated += 0.5 * (1.0 - eps * eps) * m_eff * gn2
        time = t_next
        pi = -1
        pj = -1
        coll += 1
        # speed classes and fast set follow the two new speeds; so does the bound
        ni = speed_class(_speed2(rec, i, dim, fx, fy, fz))
        nj = speed_class(_speed2(rec, j, dim, fx, fy, fz))
        hist[oi] -= 1
        hist[oj] -= 1
        hist[ni] += 1
        hist[nj] += 1
        changed = False
        if (oi > kf) != (ni > kf):
            d_i = 1 if ni > kf else -1
            flip_fast(i, d_i, bits, fen)
            nfast += d_i
            changed = True
        if (oj > kf) != (nj > kf):
            d_j = 1 if nj > kf else -1
            flip_fast(j, d_j, bits, fen)
            nfast += d_j
            changed = True
        n1, n2 = top_classes(hist, max(k1, ni, nj))
        if coll >= next_reselect:
            next_reselect += reselect_every
            kf = choose_fast_class(hist, n1, n2, n)
            nfast = build_fast_set(rec, dim, scal[S_FRAME:S_FRAME + 3], kf, bits, fen)
            k1 = -1  # force the bound's update
        if n1 != k1 or n2 != k2:
            k1 = n1
            k2 = n2
            a, b = majorant_parts(k1, k2, kf)
            rate_a = half_pairs * a
            changed = True
        if changed:
            rate_b = (n - 1.0) * nfast * b
            inv_rate = 1.0 / (c_rate * (rate_a + rate_b))
            p_a = rate_a / (rate_a + rate_b)
            inv_p_a = 1.0 / p_a
            inv_p_b = 1.0 / (1.0 - p_a) if p_a < 1.0 else 0.0
        if coll >= target:
            status = MAX_COLLISIONS
            break
        if cand >= end:
            status = BUDGET
            break
    scal[S_TIME] = time
    scal[S_NEXT] = t_next
    scal[S_DISSIPATED] = dissipated
    iscal[I_PAIR_STREAM] = k
    iscal[I_CANDIDATES] = cand
    iscal[I_COLLISIONS] = coll
    iscal[I_TOP] = k1
    iscal[I_FAST_CLASS] = kf
    iscal[I_N_FAST] = nfast
    iscal[I_PENDING_I] = pi
    iscal[I_PENDING_J] = pj
    return status
