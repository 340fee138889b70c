"""Compiled cell and neighbour lists with a shell (numba leaf module).

Each particle i carries a list centre c_i (its position when its list was last
built) and may move at most ``shell/2`` away from it before its list expires
(an event). Invariant: for every pair with nearest-image |c_i - c_j| <
R_i + R_j + shell, j is in the list of i and i in the list of j. Two
particles not in each other's lists are therefore at least R_i + R_j apart
at all times: they cannot touch. When the list of i expires only i's list is
rebuilt, from a cell grid that holds the list centres (doubly linked lists per
cell, O(1) move), and i is added to / removed from its neighbours' lists
(Smallenburg, Eur. Phys. J. E 45, 22 (2022)). Cells are at least
2 R_max + shell wide, so the 27 (2D: 9) cells around c_i hold every candidate.

Particle data come as one record per particle, ``rec[i] = (x, y, z, vx, vy,
vz, t_i, R_i)`` (64 bytes, one cache line): positions at the particle's own
clock t_i, velocity, clock and radius.
"""

from granulargas._numba import jit
from granulargas.engine._geometry import min_image

OVERFLOW = 10


@jit(inline="always")
def cell_coord(x, length, n):
    c = int(x * (n / length))
    if c >= n:
        return n - 1
    if c < 0:
        return 0
    return c


@jit(inline="always")
def cell_index(x, y, z, box, ncell):
    cx = cell_coord(x, box[0], ncell[0])
    cy = cell_coord(y, box[1], ncell[1])
    cz = cell_coord(z, box[2], ncell[2])
    return cx + ncell[0] * (cy + ncell[1] * cz)


@jit(inline="always")
def stencil_size(ncell):
    """Cells around a point: 27 in 3D, 9 with a single layer in z (2D)."""
    return 27 if ncell[2] >= 3 else 9


@jit(inline="always")
def stencil_cell(cx, cy, cz, k, ncell):
    """Flat index of the k-th cell around cell (cx, cy, cz), periodic.

    k runs over ``stencil_size(ncell)`` cells with x fastest, then y, then z
    (offsets -1, 0, 1; z offset 0 in 2D).
    """
    zr = 1 if ncell[2] >= 3 else 0
    kx = (cx + k % 3 - 1) % ncell[0]
    ky = (cy + (k // 3) % 3 - 1) % ncell[1]
    kz = (cz + k // 9 - zr) % ncell[2]
    return kx + ncell[0] * (ky + ncell[1] * kz)


@jit(inline="always")
def cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of):
    h = cell_head[c]
    cell_next[i] = h
    cell_prev[i] = -1
    if h >= 0:
        cell_prev[h] = i
    cell_head[c] = i
    cell_of[i] = c


@jit(inline="always")
def cell_remove(i, cell_head, cell_next, cell_prev, cell_of):
    p = cell_prev[i]
    n = cell_next[i]
    if p >= 0:
        cell_next[p] = n
    else:
        cell_head[cell_of[i]] = n
    if n >= 0:
        cell_prev[n] = p


@jit(inline="always")
def _collect(i, x, y, z, ri, centre, rec, shell, box, ncell, cell_head, cell_next,
             nbl, nbn, scratch):
    """Candidates j != i with |c_j - (x,y,z)| < R_i + R_j + shell, into scratch.

    Returns their number, or -1 if a list would overflow.
    """
    m = nbl.shape[1]
    cx = cell_coord(x, box[0], ncell[0])
    cy = cell_coord(y, box[1], ncell[1])
    cz = cell_coord(z, box[2], ncell[2])
    zr = 1 if ncell[2] >= 3 else 0
    count = 0
    for oz in range(-zr, zr + 1):
        kz = cz + oz
        if kz < 0:
            kz += ncell[2]
        elif kz >= ncell[2]:
            kz -= ncell[2]
        for oy in range(-1, 2):
            ky = cy + oy
            if ky < 0:
                ky += ncell[1]
            elif ky >= ncell[1]:
                ky -= ncell[1]
            for ox in range(-1, 2):
                kx = cx + ox
                if kx < 0:
                    kx += ncell[0]
                elif kx >= ncell[0]:
                    kx -= ncell[0]
                j = cell_head[kx + ncell[0] * (ky + ncell[1] * kz)]
                while j >= 0:
                    if j != i:
                        dx = min_image(x - centre[j, 0], box[0])
                        dy = min_image(y - centre[j, 1], box[1])
                        dz = min_image(z - centre[j, 2], box[2])
                        cut = ri + rec[j, 7] + shell
                        if dx * dx + dy * dy + dz * dz < cut * cut:
                            if count >= m:
                                return -1
                            if nbn[j] >= m:
                                # j is full: fine only if i is already listed there
                                found = False
                                for k in range(nbn[j]):
                                    if nbl[j, k] == i:
                                        found = True
                                if not found:
                                    return -1
                            scratch[count] = j
                            count += 1
                    j = cell_next[j]
    return count


@jit
def rebuild_list(i, rec, centre, shell, box, ncell, cell_head, cell_next, cell_prev,
                 cell_of, nbl, nbn, scratch):
    """New list centre c_i = r_i and a new neighbour list for particle i.

    Nothing is modified when a list would overflow (returns OVERFLOW); the
    caller enlarges ``nbl`` and calls again. Returns 0 on success.
    """
    x = rec[i, 0]
    y = rec[i, 1]
    z = rec[i, 2]
    count = _collect(i, x, y, z, rec[i, 7], centre, rec, shell, box, ncell, cell_head,
                     cell_next, nbl, nbn, scratch)
    if count < 0:
        return OVERFLOW
    # drop i from its old neighbours' lists (swap with the last entry)
    for k in range(nbn[i]):
        j = nbl[i, k]
        last = nbn[j] - 1
        for q in range(last + 1):
            if nbl[j, q] == i:
                nbl[j, q] = nbl[j, last]
                nbn[j] = last
                break
    for k in range(count):
        j = scratch[k]
        nbl[i, k] = j
        nbl[j, nbn[j]] = i
        nbn[j] += 1
    nbn[i] = count
    c = cell_index(x, y, z, box, ncell)
    if c != cell_of[i]:
        cell_remove(i, cell_head, cell_next, cell_prev, cell_of)
        cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of)
    centre[i, 0] = x
    centre[i, 1] = y
    centre[i, 2] = z
    return 0


@jit
def build_all_lists(r, centre, rec, shell, box, ncell, cell_head, cell_next, cell_prev,
                    cell_of, nbl, nbn):
    """Centres = positions ``r`` (= rec[:, :3]), cells and all neighbour lists from scratch.

    Returns 0, or OVERFLOW if some list exceeds ``nbl.shape[1]``.
    """
    n = r.shape[0]
    m = nbl.shape[1]
    cell_head[:] = -1
    for i in range(n - 1, -1, -1):
        centre[i, 0] = r[i, 0]
        centre[i, 1] = r[i, 1]
        centre[i, 2] = r[i, 2]
        cell_insert(i, cell_index(r[i, 0], r[i, 1], r[i, 2], box, ncell), cell_head,
                    cell_next, cell_prev, cell_of)
    nbn[:] = 0
    for i in range(n):
        cx = cell_coord(r[i, 0], box[0], ncell[0])
        cy = cell_coord(r[i, 1], box[1], ncell[1])
        cz = cell_coord(r[i, 2], box[2], ncell[2])
        for k in range(stencil_size(ncell)):
            j = cell_head[stencil_cell(cx, cy, cz, k, ncell)]
            while j >= 0:
                if j > i:
                    dx = min_image(r[i, 0] - r[j, 0], box[0])
                    dy = min_image(r[i, 1] - r[j, 1], box[1])
                    dz = min_image(r[i, 2] - r[j, 2], box[2])
                    cut = rec[i, 7] + rec[j, 7] + shell
                    if dx * dx + dy * dy + dz * dz < cut * cut:
                        if nbn[i] >= m or nbn[j] >= m:
                            return OVERFLOW
                        nbl[i, nbn[i]] = j
                        nbn[i] += 1
                        nbl[j, nbn[j]] = i
                        nbn[j] += 1
                j = cell_next[j]
    return 0
