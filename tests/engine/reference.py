"""A naive O(N^2) event-driven reference (pure numpy; independent of the engine).

All particles move together; the next collision is the minimum over all pairs
and all 3^d periodic images of the textbook quadratic root. Used to check the
engine's event sequence on small systems.
"""

import itertools

import numpy as np


def next_collision(pos, vel, radii, box):
    """(delay, i, j) of the next collision from the current state (inf, -1, -1 if none)."""
    n, d = pos.shape
    best = (np.inf, -1, -1)
    shifts = np.array(list(itertools.product((-1, 0, 1), repeat=d)), dtype=float) * box
    iu, ju = np.triu_indices(n, 1)
    dr0 = pos[iu] - pos[ju]
    dv = vel[iu] - vel[ju]
    sig = radii[iu] + radii[ju]
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
        k = int(np.argmin(t))
        if t[k] < best[0]:
            best = (float(t[k]), int(iu[k]), int(ju[k]))
    return best


def collide(pos, vel, radii, masses, box, i, j, eps):
    """Smooth-sphere collision of i and j (nearest image) with restitution eps, in place."""
    dr = pos[i] - pos[j]
    dr -= box * np.round(dr / box)
    nrm = dr / np.linalg.norm(dr)
    un = float(np.dot(vel[i] - vel[j], nrm))
    mi, mj = masses[i], masses[j]
    vel[i] -= (1 + eps) * mj / (mi + mj) * un * nrm
    vel[j] += (1 + eps) * mi / (mi + mj) * un * nrm
    return un


def run_reference(pos, vel, radii, masses, box, ncoll, eps=1.0):
    """Event sequence [(time, i, j)] of the first ``ncoll`` collisions, global clock."""
    pos = pos.copy()
    vel = vel.copy()
    t = 0.0
    out = []
    for _ in range(ncoll):
        dt, i, j = next_collision(pos, vel, radii, box)
        pos += vel * dt
        pos %= box
        t += dt
        collide(pos, vel, radii, masses, box, i, j, eps)
        out.append((t, min(i, j), max(i, j)))
    return out, pos, vel
