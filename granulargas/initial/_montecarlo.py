"""Compiled hard-sphere Monte Carlo sweeps for initial states (numba leaf module).

Random single-particle displacements, rejected on overlap; candidates come
from a cell grid of width >= 2 R_max (doubly linked cell lists, reused from
:mod:`granulargas.engine._cells`). Random numbers are drawn in Python (seeded
numpy Generator) and passed in, so the result is reproducible everywhere.
"""

from granulargas._numba import jit
from granulargas.engine._cells import _wrap, cell_coord, cell_index, cell_insert, cell_remove
from granulargas.engine._geometry import min_image


@jit
def fill_cells(r, box, ncell, cell_head, cell_next, cell_prev, cell_of):
    cell_head[:] = -1
    for i in range(r.shape[0] - 1, -1, -1):
        cell_insert(i, cell_index(r[i, 0], r[i, 1], r[i, 2], box, ncell), cell_head, cell_next,
                    cell_prev, cell_of)


@jit
def overlaps(i, x, y, z, r, radius, box, ncell, cell_head, cell_next):
    """True if a sphere of radius[i] at (x, y, z) overlaps any particle j != i."""
    cx = cell_coord(x, box[0], ncell[0])
    cy = cell_coord(y, box[1], ncell[1])
    cz = cell_coord(z, box[2], ncell[2])
    for oz in range(-1 if ncell[2] >= 3 else 0, 2 if ncell[2] >= 3 else 1):
        kz = _wrap(cz + oz, ncell[2])
        for oy in range(-1, 2):
            row = ncell[0] * (_wrap(cy + oy, ncell[1]) + ncell[1] * kz)
            for ox in range(-1, 2):
                j = cell_head[_wrap(cx + ox, ncell[0]) + row]
                while j >= 0:
                    if j != i:
                        dx = min_image(x - r[j, 0], box[0])
                        dy = min_image(y - r[j, 1], box[1])
                        dz = min_image(z - r[j, 2], box[2])
                        s = radius[i] + radius[j]
                        if dx * dx + dy * dy + dz * dz < s * s:
                            return True
                    j = cell_next[j]
    return False


@jit
def sweep(r, radius, box, ncell, cell_head, cell_next, cell_prev, cell_of, step, u):
    """One sweep of displacement moves r_i += step (2 u[i] - 1) (u (N, d) uniform in
    [0, 1), d = 2 or 3); returns the accepted count."""
    accepted = 0
    three = u.shape[1] == 3
    for i in range(r.shape[0]):
        x = r[i, 0] + step * (2.0 * u[i, 0] - 1.0)
        y = r[i, 1] + step * (2.0 * u[i, 1] - 1.0)
        z = r[i, 2] + step * (2.0 * u[i, 2] - 1.0) if three else r[i, 2]
        x = x - box[0] if x >= box[0] else (x + box[0] if x < 0.0 else x)
        y = y - box[1] if y >= box[1] else (y + box[1] if y < 0.0 else y)
        z = z - box[2] if z >= box[2] else (z + box[2] if z < 0.0 else z)
        if x >= box[0] or y >= box[1] or z >= box[2]:
            continue  # -tiny + L rounded to L: skip this move
        if overlaps(i, x, y, z, r, radius, box, ncell, cell_head, cell_next):
            continue
        c = cell_index(x, y, z, box, ncell)
        if c != cell_of[i]:
            cell_remove(i, cell_head, cell_next, cell_prev, cell_of)
            cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of)
        r[i, 0] = x
        r[i, 1] = y
        r[i, 2] = z
        accepted += 1
    return accepted


@jit
def overlap_depth(i, x, y, z, r, radius, box, ncell, cell_head, cell_next):
    """Sum over j != i of max(0, R_i + R_j - |r_ij|) for particle i placed at (x, y, z)."""
    cx = cell_coord(x, box[0], ncell[0])
    cy = cell_coord(y, box[1], ncell[1])
    cz = cell_coord(z, box[2], ncell[2])
    total = 0.0
    for oz in range(-1 if ncell[2] >= 3 else 0, 2 if ncell[2] >= 3 else 1):
        kz = _wrap(cz + oz, ncell[2])
        for oy in range(-1, 2):
            row = ncell[0] * (_wrap(cy + oy, ncell[1]) + ncell[1] * kz)
            for ox in range(-1, 2):
                j = cell_head[_wrap(cx + ox, ncell[0]) + row]
                while j >= 0:
                    if j != i:
                        dx = min_image(x - r[j, 0], box[0])
                        dy = min_image(y - r[j, 1], box[1])
                        dz = min_image(z - r[j, 2], box[2])
                        s = radius[i] + radius[j]
                        d2 = dx * dx + dy * dy + dz * dz
                        if d2 < s * s:
                            total += s - d2**0.5
                    j = cell_next[j]
    return total


@jit
def relax_sweep(r, radius, box, ncell, cell_head, cell_next, cell_prev, cell_of, step, u):
    """Sweep of moves accepted when the moved particle's overlap depth does not grow.

    Moves r_i += step (2 u[i] - 1) as in :func:`sweep`. Non-overlapping particles therefore move as hard spheres while overlapping
    ones are pushed apart (zero-temperature overlap relaxation). Returns the
    number of particles still overlapping after their move.
    """
    overlapping = 0
    for i in range(r.shape[0]):
        old = overlap_depth(i, r[i, 0], r[i, 1], r[i, 2], r, radius, box, ncell, cell_head,
                            cell_next)
        x = r[i, 0] + step * (2.0 * u[i, 0] - 1.0)
        y = r[i, 1] + step * (2.0 * u[i, 1] - 1.0)
        z = r[i, 2] + step * (2.0 * u[i, 2] - 1.0) if u.shape[1] == 3 else r[i, 2]
        x = x - box[0] if x >= box[0] else (x + box[0] if x < 0.0 else x)
        y = y - box[1] if y >= box[1] else (y + box[1] if y < 0.0 else y)
        z = z - box[2] if z >= box[2] else (z + box[2] if z < 0.0 else z)
        if x >= box[0] or y >= box[1] or z >= box[2]:
            if old > 0.0:
                overlapping += 1
            continue
        new = overlap_depth(i, x, y, z, r, radius, box, ncell, cell_head, cell_next)
        if new > old or (old > 0.0 and new == old):
            if old > 0.0:
                overlapping += 1
            continue
        c = cell_index(x, y, z, box, ncell)
        if c != cell_of[i]:
            cell_remove(i, cell_head, cell_next, cell_prev, cell_of)
            cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of)
        r[i, 0] = x
        r[i, 1] = y
        r[i, 2] = z
        if new > 0.0:
            overlapping += 1
    return overlapping


@jit
def _overlap_partners(i, x, y, z, r, radius, box, ncell, cell_head, cell_next, out, m):
    """Append i's overlap partners to out[m:], return the new length."""
    cx = cell_coord(x, box[0], ncell[0])
    cy = cell_coord(y, box[1], ncell[1])
    cz = cell_coord(z, box[2], ncell[2])
    for oz in range(-1 if ncell[2] >= 3 else 0, 2 if ncell[2] >= 3 else 1):
        kz = _wrap(cz + oz, ncell[2])
        for oy in range(-1, 2):
            row = ncell[0] * (_wrap(cy + oy, ncell[1]) + ncell[1] * kz)
            for ox in range(-1, 2):
                j = cell_head[_wrap(cx + ox, ncell[0]) + row]
                while j >= 0:
                    if j != i:
                        dx = min_image(x - r[j, 0], box[0])
                        dy = min_image(y - r[j, 1], box[1])
                        dz = min_image(z - r[j, 2], box[2])
                        s = radius[i] + radius[j]
                        if dx * dx + dy * dy + dz * dz < s * s and m < out.shape[0]:
                            out[m] = j
                            m += 1
                    j = cell_next[j]
    return m


@jit
def overlapping(r, radius, box, ncell, cell_head, cell_next, out):
    """Indices of all particles overlapping some other one, into out; returns the count."""
    m = 0
    for i in range(r.shape[0]):
        if overlaps(i, r[i, 0], r[i, 1], r[i, 2], r, radius, box, ncell, cell_head, cell_next):
            out[m] = i
            m += 1
    return m


@jit
def push_some(idx, r, radius, box, ncell, cell_head, cell_next, cell_prev, cell_of, kick, margin, near,
              out):
    """Push each particle of ``idx`` out of its overlaps (Gauss-Seidel descent).

    Particle i moves by sum_j [(R_i + R_j - d_ij)/2 + margin (R_i + R_j)] n_ij,
    i.e. by a little more than its half of every overlap, so that overlaps
    disappear in a finite number of passes (a larger margin opens the gaps a
    growth step closed in fewer passes); the push is scaled by ``kick[k]``
    (random, around 1) to break the symmetric deadlocks of a particle squeezed
    between two others. Writes the particles still
    involved in overlaps (with repetitions) into ``out``; returns their number.

    The scan of the 27 cells around i also keeps in ``near`` (int64 scratch) the
    particles within R_i + R_j + reach of i, reach = R_i: when the push is shorter
    than reach these are the only ones i can overlap at its new place (triangle
    inequality), so the new overlaps are found without a second scan of the cells.
    """
    m = 0
    cap = near.shape[0]
    for k in range(idx.shape[0]):
        i = idx[k]
        x = r[i, 0]
        y = r[i, 1]
        z = r[i, 2]
        px = 0.0
        py = 0.0
        pz = 0.0
        reach = radius[i]
        nn = 0
        cx = cell_coord(x, box[0], ncell[0])
        cy = cell_coord(y, box[1], ncell[1])
        cz = cell_coord(z, box[2], ncell[2])
        for oz in range(-1 if ncell[2] >= 3 else 0, 2 if ncell[2] >= 3 else 1):
            kz = _wrap(cz + oz, ncell[2])
            for oy in range(-1, 2):
                row = ncell[0] * (_wrap(cy + oy, ncell[1]) + ncell[1] * kz)
                for ox in range(-1, 2):
                    j = cell_head[_wrap(cx + ox, ncell[0]) + row]
                    while j >= 0:
                        if j != i:
                            dx = min_image(x - r[j, 0], box[0])
                            dy = min_image(y - r[j, 1], box[1])
                            dz = min_image(z - r[j, 2], box[2])
                            s = radius[i] + radius[j]
                            d2 = dx * dx + dy * dy + dz * dz
                            if d2 < s * s and d2 > 0.0:
                                dd = d2**0.5
                                f = (0.5 * (s - dd) + margin * s) / dd
                                px += f * dx
                                py += f * dy
                                pz += f * dz
                            if d2 < (s + reach) * (s + reach):
                                if nn < cap:
                                    near[nn] = j
                                nn += 1
                        j = cell_next[j]
        if px == 0.0 and py == 0.0 and pz == 0.0:
            continue
        x += kick[k] * px
        y += kick[k] * py
        z += kick[k] * pz
        x = x - box[0] if x >= box[0] else (x + box[0] if x < 0.0 else x)
        y = y - box[1] if y >= box[1] else (y + box[1] if y < 0.0 else y)
        z = z - box[2] if z >= box[2] else (z + box[2] if z < 0.0 else z)
        if x >= box[0] or y >= box[1] or z >= box[2]:
            continue
        c = cell_index(x, y, z, box, ncell)
        if c != cell_of[i]:
            cell_remove(i, cell_head, cell_next, cell_prev, cell_of)
            cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of)
        r[i, 0] = x
        r[i, 1] = y
        r[i, 2] = z
        m0 = m
        moved2 = kick[k] * kick[k] * (px * px + py * py + pz * pz)
        if nn <= cap and moved2 < reach * reach:
            for q in range(nn):
                j = near[q]
                dx = min_image(x - r[j, 0], box[0])
                dy = min_image(y - r[j, 1], box[1])
                dz = min_image(z - r[j, 2], box[2])
                s = radius[i] + radius[j]
                if dx * dx + dy * dy + dz * dz < s * s and m < out.shape[0]:
                    out[m] = j
                    m += 1
        else:
            m = _overlap_partners(i, x, y, z, r, radius, box, ncell, cell_head, cell_next, out, m)
        if m > m0 and m < out.shape[0]:
            out[m] = i
            m += 1
    return m


@jit
def distinct(values, m, seen, out):
    """Distinct entries of values[:m] into out (first-occurrence order); returns their number.

    ``seen`` (bool, N) must be all False on entry and is all False again on return.
    """
    u = 0
    for k in range(m):
        v = values[k]
        if not seen[v]:
            seen[v] = True
            out[u] = v
            u += 1
    for k in range(u):
        seen[out[k]] = False
    return u
