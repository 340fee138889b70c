"""A naive O(N^2) event-driven reference (pure numpy; independent of the engine).

All particles move together; the next event is the minimum over all pairs and
all 3^d periodic images (periodic axes only) of the textbook quadratic root,
and over every particle and every wall (flat walls at 0 and L on the axes
listed in ``walls``) of the time to touch it. Used to check the engine's
event sequence on small systems.

Lees-Edwards (``shear`` = a, flow along x, gradient along y): the image of the box
k_y boxes up sits at x + k_y a L_y t and moves with v_x + k_y a L_y; the reference
tries every image (k_x in -2..2 to cover the slid rows) of every pair, and a particle
that leaves [0, L_y) re-enters at the other side with x and v_x shifted by the image's.

Gravity and wall kinds (:func:`run_scene`): all particles fly on parabolas together (the
pair times are those of the straight relative motion); a wall at rest is touched at the
smallest root of the textbook quadratic at which the gap closes (``numpy.roots``), a
vibrating wall at the first sign change of the gap sampled densely and refined by
bisection (no bound, no safe steps: a method independent of the engine's); a thermal wall
draws the outgoing velocity from a pure-Python SplitMix64 of the same counters.

Rough particles (spins ``w``, moments of inertia ``I = kappa m R^2``): the collision is
computed as a rigid-body impulse problem, independently of the engine's algebra
(:func:`rough_impulse`): the change of the contact-point relative velocity is linear in the
impulse J, ``Delta g = K J`` with K built from the masses, inertias and lever arms, and J
solves ``K J = g' - g`` for the target ``g'`` (normal part ``-eps g_n``, tangential part
``-beta g_t``); Walton's Coulomb model replaces the tangential part of J by
``-mu |J_n| g_t/|g_t|`` when the sticking impulse exceeds that.
"""

import itertools

import numpy as np

from granulargas.contact.lookup import table_lookup


def next_collision(pos, vel, radii, box, walls=(), excluded=None):
    """(delay, i, j) of the next pair collision from the current state (inf, -1, -1 if none).

    ``excluded``: an array over the pairs (i < j, ``np.triu_indices`` order) of the delay
    before which a pair cannot collide (a contact under way of the resolved rule; 0: none);
    such a pair's collision is that delay plus the root from its state then."""
    n, d = pos.shape
    best = (np.inf, -1, -1)
    periodic = np.array([a not in walls for a in range(d)], dtype=float)
    shifts = np.array(list(itertools.product((-1, 0, 1), repeat=d)), dtype=float) * box
    if walls:  # no images across a wall
        shifts = np.unique(shifts * periodic, axis=0)
    iu, ju = np.triu_indices(n, 1)
    dr0 = pos[iu] - pos[ju]
    dv = vel[iu] - vel[ju]
    sig = radii[iu] + radii[ju]
    h = np.zeros(len(iu)) if excluded is None else excluded
    dr0 = dr0 + dv * h[:, None]
    for s in shifts:
        dr = dr0 + s
        b = np.sum(dr * dv, axis=1)
        a = np.sum(dv * dv, axis=1)
        c = np.sum(dr * dr, axis=1) - sig**2
        disc = b * b - a * c
        ok = (b < 0) & (disc >= 0) & (a > 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(ok, (-b - np.sqrt(np.where(ok, disc, 0.0))) / np.where(ok, a, 1.0), np.inf)
        t = np.where(ok & (c <= 0), 0.0, t)  # overlapping and approaching: now
        t = t + h
        k = int(np.argmin(t))
        if t[k] < best[0]:
            best = (float(t[k]), int(iu[k]), int(ju[k]))
    return best


def next_wall_collision(pos, vel, radii, box, walls):
    """(delay, i, axis, side) of the next sphere-wall contact (inf, -1, -1, -1 if none)."""
    best = (np.inf, -1, -1, -1)
    for a in walls:
        x, v = pos[:, a], vel[:, a]
        with np.errstate(divide="ignore", invalid="ignore"):
            t_low = np.where(v < 0, np.maximum(x - radii, 0.0) / -v, np.inf)
            t_high = np.where(v > 0, np.maximum(box[a] - radii - x, 0.0) / v, np.inf)
        for side, t in ((0, t_low), (1, t_high)):
            k = int(np.argmin(t))
            if t[k] < best[0]:
                best = (float(t[k]), k, a, side)
    return best


def next_event(pos, vel, radii, box, walls=()):
    """("pair", delay, i, j) or ("wall", delay, i, axis) of the next event."""
    tp, i, j = next_collision(pos, vel, radii, box, walls)
    tw, k, a, _ = next_wall_collision(pos, vel, radii, box, walls)
    if tw < tp:
        return "wall", tw, k, a
    return "pair", tp, i, j


def restitution(rule, gn, r_eff, m_eff):
    """eps of a collision by ``rule`` (engine CollisionRule: kind, restitution, prefactor, table)."""
    if rule.kind == "elastic":
        return 1.0
    if rule.kind == "constant":
        return rule.restitution
    beta = rule.prefactor * (r_eff * gn / m_eff**2) ** 0.2
    return table_lookup(beta, rule.table.inv_h, rule.table.coeffs)


def collide(pos, vel, radii, masses, box, i, j, eps, walls=()):
    """Smooth-sphere collision of i and j (nearest image) with restitution eps, in place."""
    dr = pos[i] - pos[j]
    for a in range(len(box)):
        if a not in walls:
            dr[a] -= box[a] * np.round(dr[a] / box[a])
    nrm = dr / np.linalg.norm(dr)
    un = float(np.dot(vel[i] - vel[j], nrm))
    mi, mj = masses[i], masses[j]
    vel[i] -= (1 + eps) * mj / (mi + mj) * un * nrm
    vel[j] += (1 + eps) * mi / (mi + mj) * un * nrm
    return un


def bounce(vel, i, axis, eps):
    """Sphere i hits a flat wall normal to ``axis``: v_n -> -eps v_n, in place; returns v_n."""
    vn = float(vel[i, axis])
    vel[i, axis] = -eps * vn
    return vn


def collide_resolved(pos, vel, radii, masses, box, i, j, rule):
    """Collision that takes time (rule: a resolved CollisionRule): the pair jumps onto its
    outgoing line, from the oblique table's Python lookup and the frame algebra of
    :func:`granulargas.contact.oblique.frame_outcome`, in place. Returns t_c."""
    from granulargas.contact.oblique import frame_outcome

    dr = pos[i] - pos[j]
    dr -= box * np.round(dr / box)
    dist = radii[i] + radii[j]
    n0 = dr / np.linalg.norm(dr)
    u = vel[i] - vel[j]
    g_n = -float(u @ n0)
    vt = u + g_n * n0
    g_t = float(np.linalg.norm(vt))
    e_t = vt / g_t if g_t > 0 else np.zeros_like(vt)
    mi, mj = masses[i], masses[j]
    m_eff = mi * mj / (mi + mj)
    r_eff = radii[i] * radii[j] / dist
    beta = rule.prefactor * (r_eff * g_n / m_eff**2) ** 0.2
    delta = rule.compression * (m_eff**2 * g_n**4 / r_eff) ** 0.2 / dist
    c = delta * (g_t / g_n) ** 2
    eps_s, tau_s, turn = rule.oblique.lookup(beta, c, delta)
    out = frame_outcome(eps_s, tau_s, turn, beta, c, delta, eps_s, g_n, g_t, dist)
    v_out = out.velocity[0] * n0 + out.velocity[1] * e_t
    a = (out.position[0] - out.velocity[0] * out.duration) * n0 + (out.position[1] - out.velocity[1] * out.duration) * e_t
    pos[i] += mj / (mi + mj) * (a - dr)
    pos[j] -= mi / (mi + mj) * (a - dr)
    vel[i] += mj / (mi + mj) * (v_out - u)
    vel[j] -= mi / (mi + mj) * (v_out - u)
    return out.duration


def _skew(r):
    """Matrices [r]x with [r]x a = r x a, for r of shape (..., 3)."""
    z = np.zeros(r.shape[:-1])
    return np.stack([np.stack([z, -r[..., 2], r[..., 1]], -1),
                     np.stack([r[..., 2], z, -r[..., 0]], -1),
                     np.stack([-r[..., 1], r[..., 0], z], -1)], -2)


def rough_impulse(vi, vj, wi, wj, n, mi, mj, Ii, Ij, ri, rj, eps, beta, mu=None):
    """Impulse J on i (-J on j) at the contact of a rough collision; arrays (..., 3), scalars
    broadcast. n: unit vector from j to i; a wall is ``mj = Ij = inf`` with ``vj = wj = 0``.

    The contact point is at r_i = -R_i n from i and r_j = R_j n from j; the contact
    velocities are v + w x r, and an impulse J at the contact changes g = c_i - c_j by
    K J with K = (1/m_i + 1/m_j) 1 - [r_i]x[r_i]x / I_i - [r_j]x[r_j]x / I_j.
    ``mu`` None: constant beta; else Walton's model with the sticking value beta.
    """
    n = np.asarray(n, dtype=float)
    r_i = -np.asarray(ri, dtype=float)[..., None] * n
    r_j = np.asarray(rj, dtype=float)[..., None] * n
    g = (vi + np.cross(wi, r_i)) - (vj + np.cross(wj, r_j))
    gn = np.sum(g * n, -1)[..., None] * n
    gt = g - gn
    eye = np.eye(3)
    inv_m = 1.0 / np.asarray(mi, dtype=float) + 1.0 / np.asarray(mj, dtype=float)
    Si, Sj = _skew(r_i), _skew(r_j)
    K = (inv_m[..., None, None] * eye - Si @ Si / np.asarray(Ii, dtype=float)[..., None, None])
    with np.errstate(invalid="ignore"):
        Kj = Sj @ Sj / np.asarray(Ij, dtype=float)[..., None, None]
    K = K - np.where(np.isfinite(Kj), Kj, 0.0)
    target = -np.asarray(eps, dtype=float)[..., None] * gn - np.asarray(beta, dtype=float)[..., None] * gt
    J = np.linalg.solve(K, (target - g)[..., None])[..., 0]
    if mu is None:
        return J
    Jn = np.sum(J * n, -1)
    Jt = J - Jn[..., None] * n
    limit = np.asarray(mu, dtype=float) * np.abs(Jn)
    size = np.linalg.norm(Jt, axis=-1)
    gsize = np.linalg.norm(gt, axis=-1)
    slide = size > limit
    with np.errstate(invalid="ignore", divide="ignore"):
        Jt_slide = -limit[..., None] * gt / np.where(gsize > 0, gsize, 1.0)[..., None]
    return np.where(slide[..., None], Jn[..., None] * n + Jt_slide, J)


def apply_rough_impulse(vi, vj, wi, wj, n, mi, mj, Ii, Ij, ri, rj, J):
    """New (vi, vj, wi, wj) after the impulse J on i at the contact (-J on j)."""
    r_i = -np.asarray(ri, dtype=float)[..., None] * n
    r_j = np.asarray(rj, dtype=float)[..., None] * n
    mi = np.asarray(mi, dtype=float)[..., None]
    mj = np.asarray(mj, dtype=float)[..., None]
    return (vi + J / mi, vj - J / mj, wi + np.cross(r_i, J) / np.asarray(Ii, dtype=float)[..., None],
            wj - np.cross(r_j, J) / np.asarray(Ij, dtype=float)[..., None])


def collide_rough(pos, vel, spin, radii, masses, inertia, box, i, j, eps, beta, mu=None, walls=()):
    """Rough collision of i and j (nearest image), in place; ``inertia`` = kappa per particle,
    ``spin`` (N, 3) (2D: only the z column used). Velocities and positions may be 2D."""
    d = len(box)
    dr = pos[i] - pos[j]
    for a in range(d):
        if a not in walls:
            dr[a] -= box[a] * np.round(dr[a] / box[a])
    n = np.zeros(3)
    n[:d] = dr / np.linalg.norm(dr)
    v = np.zeros((2, 3))
    v[:, :d] = vel[[i, j]]
    mi, mj = masses[i], masses[j]
    Ii = inertia[i] * mi * radii[i] ** 2
    Ij = inertia[j] * mj * radii[j] ** 2
    J = rough_impulse(v[0], v[1], spin[i], spin[j], n, mi, mj, Ii, Ij, radii[i], radii[j], eps, beta, mu)
    vi, vj, wi, wj = apply_rough_impulse(v[0], v[1], spin[i], spin[j], n, mi, mj, Ii, Ij, radii[i], radii[j], J)
    vel[i], vel[j] = vi[:d], vj[:d]
    spin[i], spin[j] = wi, wj


def bounce_rough(vel, spin, radii, masses, inertia, i, axis, eps, beta, mu=None):
    """Rough particle i against the flat wall normal to ``axis`` it moves into, in place."""
    d = vel.shape[1]
    n = np.zeros(3)
    n[axis] = 1.0 if vel[i, axis] < 0 else -1.0  # into the gas
    v = np.zeros(3)
    v[:d] = vel[i]
    mi = masses[i]
    Ii = inertia[i] * mi * radii[i] ** 2
    zero = np.zeros(3)
    J = rough_impulse(v, zero, spin[i], zero, n, mi, np.inf, Ii, np.inf, radii[i], 0.0, eps, beta, mu)
    vi, _, wi, _ = apply_rough_impulse(v, zero, spin[i], zero, n, mi, np.inf, Ii, np.inf, radii[i], 0.0, J)
    vel[i] = vi[:d]
    spin[i] = wi


def pair_restitution(eps, species, i, j, un, radii, masses):
    """eps of a collision of i and j: ``eps`` one number, a table (S, S) indexed by the two
    particles' ``species``, or a function ``eps(s_i, s_j, g_n, r_eff, m_eff)``."""
    si, sj = (0, 0) if species is None else (int(species[i]), int(species[j]))
    if callable(eps):
        r_eff = radii[i] * radii[j] / (radii[i] + radii[j])
        m_eff = masses[i] * masses[j] / (masses[i] + masses[j])
        return float(eps(si, sj, abs(un), r_eff, m_eff))
    return float(eps) if np.ndim(eps) == 0 else float(np.asarray(eps)[si, sj])


def wall_restitution(wall_eps, species, i, vn, radii, masses):
    """eps of particle i against a wall: one number, one per species, or a function
    ``wall_eps(s_i, |v_n|, R_i, m_i)``."""
    si = 0 if species is None else int(species[i])
    if callable(wall_eps):
        return float(wall_eps(si, abs(vn), radii[i], masses[i]))
    return float(wall_eps) if np.ndim(wall_eps) == 0 else float(np.asarray(wall_eps)[si])


def run_reference(pos, vel, radii, masses, box, ncoll, eps=1.0, walls=(), wall_eps=None, rule=None, rough=None,
                  species=None):
    """Event sequence [(time, i, j)] of the first ``ncoll`` events, global clock; a wall
    collision of particle i with a wall of axis a appears as (time, i, -1 - a).

    ``rule``: a resolved CollisionRule (collisions that take time; no walls): a pair in
    contact is not predicted until its contact ends.

    ``rough``: rough particles, a dict with ``spin`` (N, 3), ``inertia`` (kappa, (N,)),
    ``beta`` and ``mu`` (None: constant beta), optionally ``wall_beta`` and ``wall_mu``; the
    spins after the events are then returned as a fourth value.

    ``species`` (N,) ints: a mixture; ``eps`` is then a table (S, S) or a function of the
    pair (:func:`pair_restitution`), ``wall_eps`` one per species (:func:`wall_restitution`)."""
    pos = pos.copy()
    vel = vel.copy()
    spin = None if rough is None else np.array(rough["spin"], dtype=float)
    if wall_eps is None:
        wall_eps = eps if species is None else (
            np.diagonal(np.asarray(eps)) if not callable(eps) else
            (lambda s, g, r, m: eps(s, s, g, r, m)))

    t = 0.0
    out = []
    n = len(pos)
    until = np.full(n, -np.inf)
    partner = np.full(n, -1)
    iu, ju = np.triu_indices(n, 1)
    for _ in range(ncoll):
        if rule is not None:
            end = np.maximum(np.where(partner[iu] == ju, until[iu], -np.inf),
                             np.where(partner[ju] == iu, until[ju], -np.inf))
            excluded = np.maximum(end - t, 0.0)
            dt, i, j = next_collision(pos, vel, radii, box, excluded=excluded)
            pos += vel * dt
            pos %= box
            t += dt
            tc = collide_resolved(pos, vel, radii, masses, box, i, j, rule)
            pos %= box
            until[i] = max(until[i], t + tc)
            until[j] = max(until[j], t + tc)
            partner[i], partner[j] = j, i
            out.append((t, min(i, j), max(i, j)))
            continue
        kind, dt, i, j = next_event(pos, vel, radii, box, walls)
        pos += vel * dt
        for a in range(len(box)):
            if a not in walls:
                pos[:, a] %= box[a]
        t += dt
        if kind == "pair":
            dr = pos[i] - pos[j]
            for a in range(len(box)):
                if a not in walls:
                    dr[a] -= box[a] * np.round(dr[a] / box[a])
            un = float(np.dot(vel[i] - vel[j], dr / np.linalg.norm(dr)))
            e = pair_restitution(eps, species, i, j, un, radii, masses)
            if rough is None:
                collide(pos, vel, radii, masses, box, i, j, e, walls)
            else:
                collide_rough(pos, vel, spin, radii, masses, rough["inertia"], box, i, j, e,
                              rough["beta"], rough.get("mu"), walls)
            out.append((t, min(i, j), max(i, j)))
        else:
            e = wall_restitution(wall_eps, species, i, vel[i, j], radii, masses)
            if rough is None:
                bounce(vel, i, j, e)
            else:
                bounce_rough(vel, spin, radii, masses, rough["inertia"], i, j, e,
                             rough.get("wall_beta", rough["beta"]), rough.get("wall_mu", rough.get("mu")))

            out.append((t, i, -1 - j))
    if rough is not None:
        return out, pos, vel, spin
    return out, pos, vel


# ------------------------------------------------------------------ Lees-Edwards
def le_offset(box, shear, t):
    """The x offset of the image one box up at time t, a L_y t reduced into [0, L_x)."""
    return (shear * box[1] * t) % box[0]


def next_collision_le(pos, vel, radii, box, shear, t, walls=()):
    """(delay, i, j) of the next pair collision under Lees-Edwards images at time t."""
    n, d = pos.shape
    best = (np.inf, -1, -1)
    dlt = le_offset(box, shear, t)
    ranges = [range(-2, 3), range(-1, 2)] + [range(-1, 2) if 2 not in walls else range(0, 1)] * (d - 2)
    iu, ju = np.triu_indices(n, 1)
    dr0 = pos[iu] - pos[ju]
    dv0 = vel[iu] - vel[ju]
    sig = radii[iu] + radii[ju]
    for k in itertools.product(*ranges):
        shift = np.array(k, dtype=float) * box
        shift[0] += k[1] * dlt
        dr = dr0 - shift
        dv = dv0.copy()
        dv[:, 0] -= k[1] * shear * box[1]
        b = np.sum(dr * dv, axis=1)
        a = np.sum(dv * dv, axis=1)
        c = np.sum(dr * dr, axis=1) - sig**2
        disc = b * b - a * c
        ok = (b < 0) & (disc >= 0) & (a > 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            tt = np.where(ok, (-b - np.sqrt(np.where(ok, disc, 0.0))) / np.where(ok, a, 1.0), np.inf)
        tt = np.where(ok & (c <= 0), 0.0, tt)
        m = int(np.argmin(tt))
        if tt[m] < best[0]:
            best = (float(tt[m]), int(iu[m]), int(ju[m]))
    return best


def stream_le(pos, vel, box, shear, t, dt, walls=()):
    """All particles moved by dt from time t on straight lines, then wrapped: through the
    sheared y boundary with the image's x offset and velocity, periodically on x (and z)."""
    pos += vel * dt
    dlt = le_offset(box, shear, t + dt)
    up = pos[:, 1] >= box[1]
    down = pos[:, 1] < 0.0
    pos[up, 1] -= box[1]
    pos[up, 0] -= dlt
    vel[up, 0] -= shear * box[1]
    pos[down, 1] += box[1]
    pos[down, 0] += dlt
    vel[down, 0] += shear * box[1]
    pos[:, 0] %= box[0]
    if pos.shape[1] == 3 and 2 not in walls:
        pos[:, 2] %= box[2]


def le_separation(pos, vel, box, shear, t, i, j):
    """r_i - r_j and v_i - v_j through the nearest Lees-Edwards image of j."""
    dr = pos[i] - pos[j]
    dv = vel[i] - vel[j]
    ky = np.round(dr[1] / box[1])
    dr[1] -= ky * box[1]
    dr[0] -= ky * le_offset(box, shear, t)
    dv[0] -= ky * shear * box[1]
    dr[0] -= box[0] * np.round(dr[0] / box[0])
    if len(box) == 3:
        dr[2] -= box[2] * np.round(dr[2] / box[2])
    return dr, dv


def run_reference_le(pos, vel, radii, masses, box, shear, ncoll, eps=1.0, t=0.0):
    """Event sequence [(time, i, j)] of the first ``ncoll`` collisions under Lees-Edwards
    boundaries (rate ``shear``) from time t; returns (events, pos, vel)."""
    pos = pos.copy()
    vel = vel.copy()
    out = []
    for _ in range(ncoll):
        dt, i, j = next_collision_le(pos, vel, radii, box, shear, t)
        stream_le(pos, vel, box, shear, t, dt)
        t += dt
        dr, dv = le_separation(pos, vel, box, shear, t, i, j)
        nrm = dr / np.linalg.norm(dr)
        un = float(dv @ nrm)
        mi, mj = masses[i], masses[j]
        vel[i] -= (1 + eps) * mj / (mi + mj) * un * nrm
        vel[j] += (1 + eps) * mi / (mi + mj) * un * nrm
        out.append((t, min(i, j), max(i, j)))
    return out, pos, vel
# ------------------------------------------------------------------ gravity and wall kinds
_MASK = (1 << 64) - 1
_GAMMA = 0x9E3779B97F4A7C15
_SALT = 0x5851F42D4C957F2D


def _mix64(z):
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK
    return z ^ (z >> 31)


def wall_uniforms(seed, k):
    """Four uniforms in (0, 1] of the k-th wall collision (pure-Python SplitMix64)."""
    key = _mix64(int(seed) ^ _SALT)
    return tuple(1.0 - (_mix64((key + (((k << 2) | r) * _GAMMA)) & _MASK) >> 11) * 2.0**-53 for r in range(4))


def wave(waveform, tau, amp, nu, phase):
    """Displacement of a vibrating wall at time tau (phase in radians)."""
    th = 2.0 * np.pi * nu * np.asarray(tau, dtype=float) + phase
    if waveform == "sine":
        return amp * np.sin(th)
    if waveform == "triangle":
        return amp * (2.0 / np.pi) * np.arcsin(np.sin(th))
    u = np.mod(th / (2.0 * np.pi), 1.0)
    return amp * 16.0 * np.where(u < 0.5, u * (0.5 - u), -(u - 0.5) * (1.0 - u))


def wall_velocity(waveform, tau, amp, nu, phase):
    """W'(tau): the derivative of :func:`wave`, written out."""
    om = 2.0 * np.pi * nu
    th = om * np.asarray(tau, dtype=float) + phase
    if waveform == "sine":
        return amp * om * np.cos(th)
    u = np.mod(th / (2.0 * np.pi), 1.0)
    if waveform == "triangle":
        return np.where((u >= 0.25) & (u < 0.75), -4.0 * amp * nu, 4.0 * amp * nu)
    return amp * nu * np.where(u < 0.5, 8.0 - 32.0 * u, -(8.0 - 32.0 * (u - 0.5)))


def wall_position(kinds, box, a, side, t):
    """Position of wall (a, side) at time t: a vibrating wall rests A inside the box."""
    w = kinds.get((a, side), {"kind": "hard"})
    base = 0.0 if side == 0 else box[a]
    if w["kind"] != "vibrating":
        return base
    amp = w["amplitude"]
    rest = base + amp if side == 0 else base - amp
    return rest + float(wave(w["waveform"], t, amp, w["frequency"], w.get("phase", 0.0)))


def _static_contact(h, u, a):
    """Smallest s >= 0 with h + u s + a s^2/2 = 0 where the gap closes (textbook roots)."""
    if h <= 0.0:
        if u < 0 or (u == 0 and a < 0):
            return 0.0
    roots = np.roots([0.5 * a, u, h]) if a != 0 else (np.array([-h / u]) if u != 0 else np.array([]))
    best = np.inf
    for r in np.atleast_1d(roots):
        if abs(r.imag) > 1e-12 * max(1.0, abs(r.real)):
            continue
        r = r.real
        if r >= -1e-14 and u + a * r <= 1e-12 and r < best:
            best = max(r, 0.0)
    return best


def _vibrating_contact(x, v, g, radius, box, a, side, t, w, horizon, samples=4000):
    """First sign change of the gap to a vibrating wall in (0, horizon], by dense sampling
    (``samples`` per plate period, at least 2000 in all) and bisection; inf if none."""
    amp, nu, wf, ph = w["amplitude"], w["frequency"], w["waveform"], w.get("phase", 0.0)

    def gap(s):
        z = x + v * s + 0.5 * g * s * s
        if side == 0:
            return z - radius - (amp + wave(wf, t + s, amp, nu, ph))
        return (box[a] - amp + wave(wf, t + s, amp, nu, ph)) - radius - z

    if not np.isfinite(horizon):
        horizon = 50.0 / nu
    n = int(max(2000, samples * horizon * nu)) + 1
    s = np.linspace(0.0, horizon, n)
    y = gap(s)
    bad = np.flatnonzero(y <= 0.0)
    if len(bad) == 0:
        return np.inf
    k = bad[0]
    if k == 0:
        u = v - wall_velocity(wf, t, amp, nu, ph)
        return 0.0 if (u < 0 if side == 0 else u > 0) else np.inf
    lo, hi = s[k - 1], s[k]
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if gap(mid) > 0.0:
            lo = mid
        else:
            hi = mid
    return hi


def next_wall_event(pos, vel, radii, box, walls, t, gravity, kinds, horizon):
    """(delay, i, axis, side) of the next sphere-wall contact of any kind, from time t."""
    best = (np.inf, -1, -1, -1)
    for a in walls:
        ga = 0.0 if gravity is None else gravity[a]
        for i in range(len(pos)):
            for side in (0, 1):
                w = kinds.get((a, side), {"kind": "hard"})
                lim = min(best[0], horizon)
                if w["kind"] == "vibrating":
                    s = _vibrating_contact(pos[i, a], vel[i, a], ga, radii[i], box, a, side, t, w, lim)
                elif side == 0:
                    s = _static_contact(pos[i, a] - radii[i], vel[i, a], ga)
                else:
                    s = _static_contact(box[a] - radii[i] - pos[i, a], -vel[i, a], -ga)
                if s < best[0]:
                    best = (float(s), i, a, side)
    return best


def run_scene(pos, vel, radii, masses, box, nevents, *, walls=(), gravity=None, kinds=None, eps=1.0,
              wall_eps=None, elastic_below=0.0, seed=0, t0=0.0, wall_count=0, species=None):
    """Event sequence under gravity with walls of any kind, global clock: [(time, i, j)] with
    j >= 0 for a pair (i < j) and j = -1 - (2 axis + side) for a wall; returns (events, pos,
    vel, wall_work). ``kinds``: {(axis, side): {"kind": "hard" | "thermal" | "vibrating",
    "amplitude", "frequency", "waveform", "phase" (radians), "temperature"}}; ``seed`` and
    ``wall_count`` (the wall collisions so far) key the thermal draws. ``species``: a mixture
    (``eps`` a table (S, S), ``wall_eps`` one per species, as in :func:`run_reference`)."""
    pos = np.array(pos, dtype=float)
    vel = np.array(vel, dtype=float)
    d = pos.shape[1]
    g = None if gravity is None else np.asarray(gravity, dtype=float)
    kinds = kinds or {}
    if wall_eps is None:
        wall_eps = eps if species is None else np.diagonal(np.asarray(eps))
    t = t0
    out = []
    work = 0.0
    for _ in range(nevents):
        tp, i, j = next_collision(pos, vel, radii, box, walls)
        tw, k, a, side = next_wall_event(pos, vel, radii, box, walls, t, g, kinds, tp)
        dt = min(tp, tw)
        pos += vel * dt + (0.0 if g is None else 0.5 * g * dt * dt)
        if g is not None:
            vel += g * dt
        for b in range(d):
            if b not in walls:
                pos[:, b] %= box[b]
        t += dt
        if tp <= tw:
            dr = pos[i] - pos[j]
            for b in range(d):
                if b not in walls:
                    dr[b] -= box[b] * np.round(dr[b] / box[b])
            un = float(np.dot(vel[i] - vel[j], dr / np.linalg.norm(dr)))
            e = 1.0 if -un < elastic_below else pair_restitution(eps, species, i, j, un, radii, masses)
            collide(pos, vel, radii, masses, box, i, j, e, walls)
            out.append((t, min(i, j), max(i, j)))
            continue
        w = kinds.get((a, side), {"kind": "hard"})
        vn = vel[k, a]
        e0 = 0.5 * masses[k] * float(vel[k] @ vel[k])
        if w["kind"] == "thermal":
            u1, u2, u3, u4 = wall_uniforms(seed, wall_count)
            scale = np.sqrt(w["temperature"] / masses[k])
            out_n = scale * np.sqrt(-2.0 * np.log(u1))
            r = np.sqrt(-2.0 * np.log(u3))
            tang = [scale * r * np.cos(2 * np.pi * u4), scale * r * np.sin(2 * np.pi * u4)]
            vel[k, a] = out_n if side == 0 else -out_n
            m = 0
            for b in range(d):
                if b != a:
                    vel[k, b] = tang[m]
                    m += 1
            work += 0.5 * masses[k] * float(vel[k] @ vel[k]) - e0
        else:
            wv = 0.0
            if w["kind"] == "vibrating":
                wv = float(wall_velocity(w["waveform"], t, w["amplitude"], w["frequency"], w.get("phase", 0.0)))
            u = vn - wv
            e = 1.0 if abs(u) < elastic_below else wall_restitution(wall_eps, species, k, u, radii, masses)
            vel[k, a] = wv - e * u
            if w["kind"] == "vibrating":
                work += 0.5 * masses[k] * float(vel[k] @ vel[k]) - e0 + 0.5 * (1 - e * e) * masses[k] * u * u
        wall_count += 1
        out.append((t, k, -1 - (2 * a + side)))
    return out, pos, vel, work
