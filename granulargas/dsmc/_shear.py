"""Uniform shear flow in the DSMC: the homogeneous USF of the Enskog-Boltzmann equation (numba).

In the Lagrangian frame of the flow u = a y x the gas is homogeneous in its peculiar
velocities V, which obey (no thermostat)

    dV_x/dt = -a V_y  between collisions, V_y and V_z constant,                     (U1)

so V_x(t) = V_x(t_0) - a V_y (t - t_0) exactly. The velocities are stored as they were at
a reference time t_r (``rec`` = V(t_r); V(t) from (U1) when needed) and brought to a new
t_r in one pass over the particles when the window [t_r, t_r + w/a] ends (w =
:data:`WINDOW`), or when the driver synchronises.

For a pair at contact, particle j at r_i + sigma k (k the unit vector from i to j), the
flow's difference over sigma is part of the relative velocity (Enskog's kernel with the
shear; the dilute Boltzmann limit drops it with sigma -> 0 at fixed density times sigma^(d-1)):

    w = V_i - V_j - a sigma k_y x,   the pair collides at the rate
    chi sigma^(d-1)/V Theta(w.k)(w.k) per unit solid angle of k.                  (U2)

The majorant (a true bound while (U1) changes the velocities). In the window, with
g = V_i - V_j at t_r and tau = t - t_r <= w/a, |g(t)| <= |g|(1 + a tau) <= |g|(1 + w), and
(w.k)_+ <= (g(t).k)_+ + (-a sigma k_x k_y)_+ (the positive part is subadditive), whose
integral over k is B_d |g(t)| + C_d a sigma (B_3 = pi, B_2 = 2; C_d = int (k_x k_y)_+ dk:
4/3 in 3D, 1 in 2D). Hence, with G the speed-class bound of
:mod:`granulargas.dsmc._majorant` on the speeds at t_r, the candidates of rate

    Lambda = N (N - 1)/2 chi sigma^(d-1) B_d [G (1 + w) + (C_d/B_d) a sigma] / V      (U3)

(uniform pairs, a Poisson process; G updated after every collision as in
:mod:`granulargas.dsmc._loop`) are thinned in three exact steps:

1. accept with (|g| (1 + w) + c) / (G (1 + w) + c), c = (C_d/B_d) a sigma (the pair's bound
   over the window; no time needed); its time t then follows from the exponential gaps
   (one logarithm per accepted candidate);
2. at t, accept with (|g(t)| + c) / (|g| (1 + w) + c);
3. draw k from the mixture of (g(t).k)_+ (weight B_d |g(t)|: the engine-free normal of
   :mod:`granulargas.dsmc._collide`) and (-a k_x k_y)_+ (weight C_d a sigma: |k_x k_y| on
   the two quadrants where k_x k_y has the sign of -a, cos(theta) the median of three
   uniforms in 3D), and accept with (w.k)_+ / [(g(t).k)_+ + (-a sigma k_x k_y)_+].

The accepted (pair, k, t) then have the density of (U2). A candidate beyond the window's
end is dropped and the process restarts at the end, with the velocities brought to it
(memoryless: exact). The collision is the smooth-sphere rule on w.k; it dissipates
(1 - eps^2) m_eff (w.k)^2 / 2 and moves the momentum m_eff (1 + eps)(w.k) k across sigma k
(collisional transfer, -a times its xy part the collisional viscous heating).

The pressure tensor: the kinetic sums S_ab = sum m V_a V_b evolve between collisions by
(U1) (S_xx' = -2a S_xy, S_xy' = -a S_yy, S_xz' = -a S_yz; integrated exactly, as the
engine's :func:`granulargas.engine._shear.integrate_stress`) and jump at collisions; the
collisional sums add sigma m_eff (1 + eps)(w.k) k_a k_b. Identical particles only.
"""

import math

import numpy as np

from granulargas._numba import inlined, jit
from granulargas.dsmc._collide import normal_part_2d, normal_part_3d
from granulargas.dsmc._majorant import build_histogram, class_edge, speed_class, top_classes
from granulargas.dsmc._random import pair_of, uniform
from granulargas.engine._collide import VISCOELASTIC, restitution
from granulargas.engine._prefetch import prefetch

# status codes (as dsmc._loop)
DONE = 0
MAX_COLLISIONS = 1
BUDGET = 2
TABLE_RANGE = 3

#: the window of the majorant: a tau <= WINDOW (the bound on |g(t)| grows by 1 + WINDOW)
WINDOW = 0.25
#: C_d / B_d of eq. (U3): (4/3)/pi in 3D, 1/2 in 2D
C_OVER_B = {3: 4.0 / (3.0 * math.pi), 2: 0.5}

# scal slots of the sheared loop (float64)
S_TIME = 0
S_NEXT = 1
S_DISSIPATED = 2
S_RATE = 3  # N (N-1)/2 chi sigma^(d-1) B_d / V
S_REF = 4  # t_r: the time the stored velocities are at
S_SHEAR = 5  # a
S_SIGMA = 6  # sigma
S_EPS = 7
S_PREFACTOR = 8
S_INV_H = 9
S_MASS = 10
S_C = 11  # (C_d / B_d) a sigma
N_SCAL = 12

# iscal slots (int64)
I_COLLISIONS = 0
I_CANDIDATES = 1
I_TOP = 2
I_PENDING_I = 3
I_PENDING_J = 4
I_ERR_I = 5
I_ERR_J = 6
I_REBASES = 7
N_ISCAL = 8

# stress: s (6) kinetic sums now, k (6) their integrals, w (6) collisional sums (xx, yy, zz, xy, xz, yz)
XX, YY, ZZ, XY, XZ, YZ = 0, 1, 2, 3, 4, 5

RING = 16


@inlined
def _class_of(rec, i, dim):
    w2 = rec[i, 0] * rec[i, 0] + rec[i, 1] * rec[i, 1]
    if dim == 3:
        w2 += rec[i, 2] * rec[i, 2]
    return speed_class(w2)


@inlined
def _integrate(stress, a, dt):
    """Advance the kinetic sums by dt of (U1) and add their integrals."""
    ad = a * dt
    s0, s1, s2, s3, s4, s5 = stress[0], stress[1], stress[2], stress[3], stress[4], stress[5]
    stress[6 + XX] += (s0 - ad * s3 + ad * ad * s1 / 3.0) * dt
    stress[6 + YY] += s1 * dt
    stress[6 + ZZ] += s2 * dt
    stress[6 + XY] += (s3 - 0.5 * ad * s1) * dt
    stress[6 + XZ] += (s4 - 0.5 * ad * s5) * dt
    stress[6 + YZ] += s5 * dt
    stress[XX] = s0 + (-2.0 * s3 + ad * s1) * ad
    stress[XY] = s3 - ad * s1
    stress[XZ] = s4 - ad * s5


@inlined
def _jump(stress, m, vx, vy, vz, dx, dy, dz):
    stress[XX] += m * (2.0 * vx + dx) * dx
    stress[YY] += m * (2.0 * vy + dy) * dy
    stress[ZZ] += m * (2.0 * vz + dz) * dz
    stress[XY] += m * (vx * dy + dx * vy + dx * dy)
    stress[XZ] += m * (vx * dz + dx * vz + dx * dz)
    stress[YZ] += m * (vy * dz + dy * vz + dy * dz)


@jit
def stress_sums(rec, dim, mass, a, tau, stress):
    """Kinetic sums sum m V_a V_b at t_r + tau of the stored velocities into stress[0:6]."""
    for q in range(6):
        stress[q] = 0.0
    for i in range(rec.shape[0]):
        vy = rec[i, 1]
        vx = rec[i, 0] - a * vy * tau
        vz = rec[i, 2] if dim == 3 else 0.0
        stress[XX] += mass * vx * vx
        stress[YY] += mass * vy * vy
        stress[ZZ] += mass * vz * vz
        stress[XY] += mass * vx * vy
        stress[XZ] += mass * vx * vz
        stress[YZ] += mass * vy * vz


@jit
def rebase(rec, dim, a, tau, hist):
    """The stored velocities brought from t_r to t_r + tau, eq. (U1); the speed classes
    recounted. Returns the highest class."""
    for i in range(rec.shape[0]):
        rec[i, 0] -= a * rec[i, 1] * tau
    return build_histogram(rec, dim, hist)


@inlined
def _quadrant_normal(state, a, dim):
    """A unit vector with density proportional to (-a k_x k_y)_+ (eq. (U3) step 3)."""
    u = uniform(state)
    beta = 0.5 * math.acos(1.0 - 2.0 * u)  # density sin(2 beta) on [0, pi/2)
    half = uniform(state) < 0.5
    # quadrants where k_x k_y < 0 (a > 0): phi in [pi/2, pi) or [3 pi/2, 2 pi); else the other two
    base = (0.5 * math.pi if a > 0.0 else 0.0) + (math.pi if half else 0.0)
    phi = base + beta
    cx = math.cos(phi)
    cy = math.sin(phi)
    if dim == 2:
        return cx, cy, 0.0
    # cos(theta) with density (3/4)(1 - c^2) on [-1, 1]: the median of three uniforms
    x1 = 2.0 * uniform(state) - 1.0
    x2 = 2.0 * uniform(state) - 1.0
    x3 = 2.0 * uniform(state) - 1.0
    c = max(min(x1, x2), min(max(x1, x2), x3))
    s = math.sqrt(1.0 - c * c)
    return s * cx, s * cy, c


@jit
def advance_usf(rec, dim, hist, rng, kind, coeffs, until, t_end_window, target, budget, ring, scal, iscal,
                stress):
    """Collide under uniform shear until ``until``, ``target`` collisions or about ``budget``
    candidates (module doc). ``rec`` holds V(t_r) (identical particles). The window ends at
    ``t_end_window``: a candidate beyond it is dropped, and the loop returns DONE with the
    time at the window's end (the driver rebases and calls again) when ``until`` is later.
    Status codes as :func:`granulargas.dsmc._loop.advance`."""
    n = rec.shape[0]
    key = rng[4]
    a = scal[S_SHEAR]
    sigma = scal[S_SIGMA]
    m = scal[S_MASS]
    c_shift = scal[S_C]
    eps_const = scal[S_EPS]
    prefactor = scal[S_PREFACTOR]
    inv_h = scal[S_INV_H]
    rate_per_bound = scal[S_RATE]
    t_ref = scal[S_REF]
    grow = 1.0 + WINDOW
    k = iscal[I_CANDIDATES]
    coll = iscal[I_COLLISIONS]
    pi = iscal[I_PENDING_I]
    pj = iscal[I_PENDING_J]
    k1, k2 = top_classes(hist, iscal[I_TOP])
    bound = (class_edge(k1) + class_edge(k2)) * grow + c_shift
    inv_rate = 1.0 / (rate_per_bound * bound)
    t_next = scal[S_NEXT]
    time = scal[S_TIME]
    dissipated = scal[S_DISSIPATED]
    for q in range(k, k + RING):
        i0, j0 = pair_of(key, q, n)
        ring[0, q & (RING - 1)] = i0
        ring[1, q & (RING - 1)] = j0
        prefetch(rec, i0)
        prefetch(rec, j0)
    end = k + budget
    status = DONE
    while True:
        if pi < 0:
            if k >= end:  # the budget also bounds the candidates that steps 2 and 3 reject
                status = BUDGET
                break
            # ---- step 1: candidates until one is accepted with its window bound
            prod = 1.0
            logs = 0.0
            while True:
                slot = k & (RING - 1)
                i = ring[0, slot]
                j = ring[1, slot]
                i0, j0 = pair_of(key, k + RING, n)
                ring[0, slot] = i0
                ring[1, slot] = j0
                prefetch(rec, i0)
                prefetch(rec, j0)
                k += 1
                gx = rec[i, 0] - rec[j, 0]
                gy = rec[i, 1] - rec[j, 1]
                g2 = gx * gx + gy * gy
                if dim == 3:
                    gz = rec[i, 2] - rec[j, 2]
                    g2 += gz * gz
                x = uniform(rng) * bound - c_shift
                prod *= 1.0 - uniform(rng)
                if prod < 1e-280:
                    logs += math.log(prod)
                    prod = 1.0
                if x < 0.0 or x * x < g2 * grow * grow:
                    break
            t_next = time - (logs + math.log(prod)) * inv_rate
            pi = i
            pj = j
        if t_next > t_end_window:
            if t_end_window > until:
                time = until
                status = DONE
                break
            # the window ends first: drop the candidate, restart there (the driver rebases)
            _integrate(stress, a, t_end_window - time)
            time = t_end_window
            pi = -1
            pj = -1
            status = DONE
            break
        if t_next > until:
            _integrate(stress, a, until - time)
            time = until
            status = DONE
            break
        # ---- steps 2 and 3 at the candidate's time
        _integrate(stress, a, t_next - time)
        time = t_next
        i = pi
        j = pj
        pi = -1
        pj = -1
        tau = time - t_ref
        gy = rec[i, 1] - rec[j, 1]
        gx0 = rec[i, 0] - rec[j, 0]
        gz = rec[i, 2] - rec[j, 2] if dim == 3 else 0.0
        gx = gx0 - a * gy * tau
        g_ref = math.sqrt(gx0 * gx0 + gy * gy + gz * gz)
        g2 = gx * gx + gy * gy + gz * gz
        g_now = math.sqrt(g2)
        total = g_now + c_shift
        if uniform(rng) * (g_ref * grow + c_shift) >= total:
            continue  # step 2 rejects: the process goes on from this time
        if uniform(rng) * total < g_now:
            if dim == 3:
                px, py, pz, gn2 = normal_part_3d(rng, gx, gy, gz, g2)
            else:
                px, py, gn2 = normal_part_2d(rng, gx, gy, g2)
                pz = 0.0
            gk = math.sqrt(gn2)
            if gk <= 0.0:
                continue
            kx = px / gk
            ky = py / gk
            kz = pz / gk
        else:
            kx, ky, kz = _quadrant_normal(rng, a, dim)
            gk = gx * kx + gy * ky + gz * kz
        shift = -a * sigma * kx * ky
        wk = gk + shift
        den = (gk if gk > 0.0 else 0.0) + (shift if shift > 0.0 else 0.0)
        if not (wk > 0.0 and uniform(rng) * den < wk):
            continue  # step 3 rejects
        m_eff = 0.5 * m
        gn = wk if kind == VISCOELASTIC else 0.0
        eps = restitution(kind, eps_const, prefactor, inv_h, coeffs, gn, 0.5 * sigma * 0.5, m_eff)
        if eps < 0.0:
            iscal[I_ERR_I] = i
            iscal[I_ERR_J] = j
            status = TABLE_RANGE
            break
        oi = _class_of(rec, i, dim)
        oj = _class_of(rec, j, dim)
        f = 0.5 * (1.0 + eps) * wk  # velocity change of each along k (equal masses)
        dvx = f * kx
        dvy = f * ky
        dvz = f * kz
        # the kinetic sums take the change of V(t) = stored - a V_y tau x
        vix = rec[i, 0] - a * rec[i, 1] * tau
        vjx = rec[j, 0] - a * rec[j, 1] * tau
        _jump(stress, m, vix, rec[i, 1], rec[i, 2] if dim == 3 else 0.0, -dvx, -dvy, -dvz)
        _jump(stress, m, vjx, rec[j, 1], rec[j, 2] if dim == 3 else 0.0, dvx, dvy, dvz)
        tr = sigma * m_eff * (1.0 + eps) * wk
        stress[12 + XX] += tr * kx * kx
        stress[12 + YY] += tr * ky * ky
        stress[12 + ZZ] += tr * kz * kz
        stress[12 + XY] += tr * kx * ky
        stress[12 + XZ] += tr * kx * kz
        stress[12 + YZ] += tr * ky * kz
        # stored velocities: V(t_r) changes by dV + a dV_y tau x
        rec[i, 0] -= dvx + a * dvy * tau
        rec[i, 1] -= dvy
        rec[j, 0] += dvx + a * dvy * tau
        rec[j, 1] += dvy
        if dim == 3:
            rec[i, 2] -= dvz
            rec[j, 2] += dvz
        dissipated += 0.5 * (1.0 - eps * eps) * m_eff * wk * wk
        coll += 1
        ni = _class_of(rec, i, dim)
        nj = _class_of(rec, j, dim)
        hist[oi] -= 1
        hist[oj] -= 1
        hist[ni] += 1
        hist[nj] += 1
        if max(oi, oj, ni, nj) >= k2:
            n1, n2 = top_classes(hist, max(k1, ni, nj))
            if n1 != k1 or n2 != k2:
                k1 = n1
                k2 = n2
                bound = (class_edge(k1) + class_edge(k2)) * grow + c_shift
                inv_rate = 1.0 / (rate_per_bound * bound)
        if coll >= target:
            status = MAX_COLLISIONS
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
