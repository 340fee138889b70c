"""A naive O(N^2) event-driven reference (pure numpy; independent of the engine).

All particles move together; the next event is the minimum over all pairs and
all 3^d periodic images (periodic axes only) of the textbook quadratic root,
and over every particle and every wall (flat walls at 0 and L on the axes
listed in ``walls``) of the time to touch it. Used to check the engine's
event sequence on small systems.

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
