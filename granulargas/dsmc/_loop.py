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
A mixture has one chi_ij per pair of species: chi above is then the largest of them and
the acceptance has the further factor chi_ij / chi_max, the pair's weight in the species
record (:mod:`granulargas.engine._species`), which also gives the pair's collision law
and counts the collisions per pair of species (None: one kind of particle, the loop
compiled without any of it).
This is the Kac process / Bird's no-time-counter scheme with one global bound
and no time step: the waiting time between candidates is exponential with
rate Lambda, and Lambda is updated after every collision because G may
change (memoryless, so exact).

Between two collisions the velocities do not change, so after a collision the
candidates are drawn and tested until one is accepted, and its waiting time is
the sum of the exponential gaps of all of them, -log(U_1 ... U_m) / Lambda (a
Gamma variate; one logarithm per collision, not per candidate). It becomes
the *pending* collision, executed when the run reaches its time. The pending
collision is part of the state, so a run stopped anywhere and continued draws
exactly the numbers an uninterrupted run draws.

Memory: velocities in rows of 2 (2D) or 4 (3D, one padding word) float64, so
a particle is one aligned 16- or 32-byte piece of one cache line. Candidate
pairs come from the counter-based pair stream, so the rows of the pairs
``RING`` candidates ahead are prefetched while the current one is processed.
"""

import math

from granulargas._numba import inlined, jit
from granulargas.dsmc._collide import apply_pair_update, apply_rough_update, normal_part_2d, normal_part_3d
from granulargas.dsmc._majorant import build_histogram, class_edge, speed_class, top_classes
from granulargas.dsmc._random import pair_of, uniform
from granulargas.engine._collide import VISCOELASTIC, restitution
from granulargas.engine._prefetch import prefetch
from granulargas.engine._species import count_pair, pair_law, pair_weight

# status codes
DONE = 0  # reached ``until``
MAX_COLLISIONS = 1  # reached the collision target
BUDGET = 2  # candidate budget of this chunk used up (progress callback, then continue)
TABLE_RANGE = 3  # an impact beyond the restitution table

# scal slots (float64)
S_TIME = 0  # time of the last collision (``until`` after DONE)
S_NEXT = 1  # time of the pending collision
S_DISSIPATED = 2  # kinetic energy lost in collisions (cumulative)
S_RATE = 3  # Lambda / G = N (N-1)/2 chi sigma_max^(d-1) B_d / V
N_SCAL = 4

# iscal slots (int64)
I_COLLISIONS = 0
I_CANDIDATES = 1  # position in the pair stream: candidates drawn since the seed
I_TOP = 2  # highest occupied speed class (an upper estimate; exact after top_classes)
I_PENDING_I = 3  # pair of the pending (accepted, not yet executed) collision; -1: none
I_PENDING_J = 4
I_ERR_I = 5
I_ERR_J = 6
N_ISCAL = 7

# fpar slots
F_EPS = 0  # constant eps
F_PREFACTOR = 1  # viscoelastic pair prefactor k
F_INV_H = 2  # restitution table grid
F_SIGMA_MAX_POW = 3  # sigma_max^(d-1)
F_MASS = 4  # mass (monodisperse)
F_RADIUS = 5  # radius (monodisperse)
N_FPAR = 6

RING = 16  # candidates prefetched ahead (power of two)


@inlined
def _class_of(rec, i, dim):
    """Speed class of particle i."""
    w2 = rec[i, 0] * rec[i, 0] + rec[i, 1] * rec[i, 1]
    if dim == 3:
        w2 += rec[i, 2] * rec[i, 2]
    return speed_class(w2)


@jit
def recentre(rec, mass, mono, dim, hist):
    """Subtract the mass-weighted mean velocity from all velocities; recount the classes.

    Collisions conserve momentum only to rounding, so the mean of the peculiar
    velocities random-walks at ~1e-16 of their size. A gas that cools by many
    orders of magnitude would end up slower than that drift, the speeds measured
    from zero would no longer follow its temperature, and float64 could no longer
    resolve the velocity differences. Subtracting the mean every few collisions
    per particle (a change at the rounding level) keeps the velocities peculiar.
    Returns the highest occupied class.
    """
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    msum = 0.0
    n = rec.shape[0]
    for i in range(n):
        m = 1.0 if mono else mass[i]
        msum += m
        p0 += m * rec[i, 0]
        p1 += m * rec[i, 1]
        if dim == 3:
            p2 += m * rec[i, 2]
    p0 /= msum
    p1 /= msum
    p2 /= msum
    for i in range(n):
        rec[i, 0] -= p0
        rec[i, 1] -= p1
        if dim == 3:
            rec[i, 2] -= p2
    return build_histogram(rec, dim, hist)


@jit
def advance(rec, radius, mass, mono, dim, hist, rng, kind, fpar, coeffs, until, target, budget,
            recentre_every, ring, scal, iscal, species, rough=None):
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
    rng : uint64 (5,)
        Random state (:mod:`granulargas.dsmc._random`), advanced in place.
    kind : int
        Restitution kind of :mod:`granulargas.engine._collide`.
    until : float
        End time; collisions with time <= until are executed.
    target : int
        Stop right after the collision that makes ``iscal[I_COLLISIONS] == target``.
    budget : int
        Return BUDGET after the first collision once this many candidates were drawn.
    recentre_every : int
        :func:`recentre` runs after every collision whose count is a multiple of this.
    ring : int64 (2, RING)
        Work space for the pairs ahead (rebuilt on entry; not state).
    species : None or Species
        A mixture's law per pair of species, acceptance weights and pair counts
        (:class:`granulargas.engine._state.Species`, particle order = id order).
    rough : Spins or None
        Rough particles: the spins and the tangential law
        (:class:`granulargas.engine._state.Spins`; :func:`apply_rough_update`). None: smooth
        particles (the loop is then compiled without the rough update).

    Returns
    -------
    int
        Status code (DONE, MAX_COLLISIONS, BUDGET, TABLE_RANGE).
    """
    n = rec.shape[0]
    key = rng[4]
    eps_const = fpar[F_EPS]
    prefactor = fpar[F_PREFACTOR]
    inv_h = fpar[F_INV_H]
    smax_pow = fpar[F_SIGMA_MAX_POW]
    m0 = fpar[F_MASS]
    r0 = fpar[F_RADIUS]
    rate_per_bound = scal[S_RATE]
    k = iscal[I_CANDIDATES]
    coll = iscal[I_COLLISIONS]
    pi = iscal[I_PENDING_I]
    pj = iscal[I_PENDING_J]
    k1, k2 = top_classes(hist, iscal[I_TOP])
    bound = class_edge(k1) + class_edge(k2)
    inv_rate = 1.0 / (rate_per_bound * bound)
    t_next = scal[S_NEXT]
    time = scal[S_TIME]
    dissipated = scal[S_DISSIPATED]
    for q in range(k, k + RING):  # candidate q lives in slot q mod RING
        a, b = pair_of(key, q, n)
        ring[0, q & (RING - 1)] = a
        ring[1, q & (RING - 1)] = b
        prefetch(rec, a)
        prefetch(rec, b)
    end = k + budget
    next_recentre = (coll // recentre_every + 1) * recentre_every
    while True:
        if pi < 0:
            # ---- draw candidates until one is accepted; its time is the sum of the gaps
            prod = 1.0
            logs = 0.0
            while True:
                slot = k & (RING - 1)
                i = ring[0, slot]
                j = ring[1, slot]
                a, b = pair_of(key, k + RING, n)
                ring[0, slot] = a
                ring[1, slot] = b
                prefetch(rec, a)
                prefetch(rec, b)
                if not mono:
                    prefetch(radius, a)
                    prefetch(radius, b)
                k += 1
                gx = rec[i, 0] - rec[j, 0]
                gy = rec[i, 1] - rec[j, 1]
                g2 = gx * gx + gy * gy
                if dim == 3:
                    gz = rec[i, 2] - rec[j, 2]
                    g2 += gz * gz
                x = uniform(rng) * bound
                prod *= 1.0 - uniform(rng)
                if prod < 1e-280:
                    logs += math.log(prod)
                    prod = 1.0
                # a mixture: accept g w < x with w = chi_ij / chi_max (1.0 without species: no operation)
                w = pair_weight(species, i, j)
                g2 *= w * w
                if mono:
                    if x * x < g2:
                        break
                else:
                    # accept with sigma_ij^(d-1) g / (sigma_max^(d-1) G)
                    sij = radius[i] + radius[j]
                    s2 = sij * sij
                    if dim == 3:
                        s2 *= s2
                    x *= smax_pow
                    if x * x < g2 * s2:
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
        gx = rec[i, 0] - rec[j, 0]
        gy = rec[i, 1] - rec[j, 1]
        g2 = gx * gx + gy * gy
        gz = 0.0
        if dim == 3:
            gz = rec[i, 2] - rec[j, 2]
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
        eps_pair, k_pair = pair_law(eps_const, prefactor, species, i, j)
        eps = restitution(kind, eps_pair, k_pair, inv_h, coeffs, gn, r_eff, m_eff)
        if eps < 0.0:
            iscal[I_ERR_I] = i
            iscal[I_ERR_J] = j
            status = TABLE_RANGE
            break
        oi = _class_of(rec, i, dim)
        oj = _class_of(rec, j, dim)
        if rough is not None:
            ri = r0 if mono else radius[i]
            rj = r0 if mono else radius[j]
            dissipated += apply_rough_update(rec, rough, i, j, dim, px, py, pz, gn2, eps, mi, mj, ri, rj)
        else:
            apply_pair_update(rec, i, j, dim, px, py, pz, eps, mi, mj)
            dissipated += 0.5 * (1.0 - eps * eps) * m_eff * gn2
        count_pair(species, i, j)
        time = t_next
        pi = -1
        pj = -1
        coll += 1
        # speed classes follow the two new speeds, and so does the bound
        ni = _class_of(rec, i, dim)
        nj = _class_of(rec, j, dim)
        hist[oi] -= 1
        hist[oj] -= 1
        hist[ni] += 1
        hist[nj] += 1
        if coll >= next_recentre:
            next_recentre += recentre_every
            top = recentre(rec, mass, mono, dim, hist)
            k1, k2 = top_classes(hist, top)
            bound = class_edge(k1) + class_edge(k2)
            inv_rate = 1.0 / (rate_per_bound * bound)
        elif max(oi, oj, ni, nj) >= k2:  # else the two fastest are untouched
            n1, n2 = top_classes(hist, max(k1, ni, nj))
            if n1 != k1 or n2 != k2:
                k1 = n1
                k2 = n2
                bound = class_edge(k1) + class_edge(k2)
                inv_rate = 1.0 / (rate_per_bound * bound)
        if coll >= target:
            status = MAX_COLLISIONS
            break
        if k >= end:
            status = BUDGET
            break
    scal[S_TIME] = time
    scal[S_NEXT] = t_next
    scal[S_DISSIPATED] = dissipated
    iscal[I_CANDIDATES] = k
    iscal[I_COLLISIONS] = coll
    iscal[I_TOP] = k1
    iscal[I_PENDING_I] = pi
    iscal[I_PENDING_J] = pj
    return status
