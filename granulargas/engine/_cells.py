"""Compiled cell and neighbour lists with a shell (numba leaf module).

Each particle i carries a list centre c_i (its position when its list was last
built, stored as float32) and may move at most ``shell/2`` away from it before
its list expires (an event). Invariant: for every pair with nearest-image
|c_i - c_j| < R_i + R_j + shell, j is in the list of i and i in the list of j.
Two particles not in each other's lists are therefore at least R_i + R_j apart
at all times: they cannot touch. The argument holds for any point c_i within
shell/2 of particle i, so rounding the centres costs nothing as long as every
test (each rebuild, the expiry time) uses the same stored centres; it halves
their memory (12 bytes per particle). When the list of i expires only i's list is rebuilt, from a
cell grid that holds the list centres (a row of slots per cell, one cache line
for up to 16), and i is added to / removed from the lists of the neighbours
that join or leave (Smallenburg, Eur. Phys. J. E 45, 22 (2022)). Cells are at
least 2 R_max + shell wide, so the 27 (2D: 9) cells around c_i hold every
candidate. A full build is every list expiring at once: the lists start empty and each
rebuild adds its particle to the lists of its new neighbours
(:meth:`granulargas.engine.simulation.Simulation._first_events_by_the_loop`).

Particle data come as one record per particle, ``rec[i] = (x, y, z, vx, vy,
vz, t_i, R_i)`` (64 bytes, one cache line): positions at the particle's own
clock t_i, velocity, clock and radius. The lists and cells are the records
:class:`~granulargas.engine._state.Lists` and :class:`~granulargas.engine._state.Cells`;
the geometry is :class:`~granulargas.engine._state.Space`. On a wall axis
(period inf) the cells do not wrap: the cells beyond the walls do not exist.
"""

import math


import numpy as np

from granulargas._numba import inlined, inlined_ir, kernel
from granulargas.engine._geometry import min_image
from granulargas.engine._prefetch import prefetch

OVERFLOW = 10
CELL_OVERFLOW = 11
#: Below this many particles the list centres (12 bytes each) stay in the L2 cache and
#: the rebuild's prefetch pass over the candidates' centres only costs time.
PREFETCH_CENTRES_FROM = 32768


@inlined
def cell_coord(x, length, n):
    c = int(x * (n / length))
    if c >= n:
        return n - 1
    if c < 0:
        return 0
    return c


@inlined
def cell_index(x, y, z, box, ncell):
    cx = cell_coord(x, box[0], ncell[0])
    cy = cell_coord(y, box[1], ncell[1])
    cz = cell_coord(z, box[2], ncell[2])
    return cx + ncell[0] * (cy + ncell[1] * cz)


@inlined
def cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of):
    h = cell_head[c]
    cell_next[i] = h
    cell_prev[i] = -1
    if h >= 0:
        cell_prev[h] = i
    cell_head[c] = i
    cell_of[i] = c


@inlined
def cell_remove(i, cell_head, cell_next, cell_prev, cell_of):
    p = cell_prev[i]
    n = cell_next[i]
    if p >= 0:
        cell_next[p] = n
    else:
        cell_head[cell_of[i]] = n
    if n >= 0:
        cell_prev[n] = p


@inlined
def slot_insert(i, c, cell_ids, cell_n):
    """Append particle i to cell c (the caller has checked the capacity)."""
    q = cell_n[c]
    cell_ids[c, q] = i
    cell_n[c] = q + 1


@inlined
def slot_remove(i, c, cell_ids, cell_n):
    """Remove particle i from its cell c (the cell's last entry takes its slot).

    A scan of the row (one or two cache lines, just read by the rebuild) rather
    than a stored slot index: that saves 4 bytes per particle and a store into
    the moved particle's row.
    """
    last = cell_n[c] - 1
    for q in range(last + 1):
        if cell_ids[c, q] == i:
            cell_ids[c, q] = cell_ids[c, last]
            break
    cell_n[c] = last


@inlined_ir
def _gaps2(x, c, length, n):
    """Squared distances from x to the lower and upper faces of its cell c (0 if outside)."""
    w = length / n
    lo = x - c * w
    hi = (c + 1) * w - x
    lo = lo if lo > 0.0 else 0.0
    hi = hi if hi > 0.0 else 0.0
    return lo * lo, hi * hi


@inlined_ir
def _pick(o, lo2, hi2):
    if o < 0:
        return lo2
    if o > 0:
        return hi2
    return 0.0


@inlined
def _reach(x, y, z, cut, space, stencil):
    """Cells around (x, y, z) that a sphere of radius ``cut`` can reach, into ``stencil``.

    Of the 27 (2D: 9) cells of side >= cut around the point's cell, a face
    neighbour is always reached, an edge or corner neighbour only if the
    point is within ``cut`` of the shared edge or corner (on average 20.6 of
    27 cells in 3D, 8.1 of 9 in 2D, for a cut-off equal to the cell side); a cell
    beyond a wall never. The gap test keeps a margin of 1e-9 cut
    plus 1e-12 box lengths against round-off in the cell assignment. Entries are
    ``32 c + code`` with code = (ox + 1) + 3 (oy + 1) + 9 (oz + 1); returns their number.
    ``stencil`` needs room for 27 entries whatever the number (every cell of a row is
    written, the count advances when the cell is reached).
    """
    box = space.box
    ncell = space.ncell
    period = space.period
    cx = cell_coord(x, box[0], ncell[0])
    cy = cell_coord(y, box[1], ncell[1])
    cz = cell_coord(z, box[2], ncell[2])
    zr = 1 if ncell[2] >= 3 else 0
    lim = cut * (1.0 + 1e-9) + 1e-12 * (box[0] + box[1] + box[2])
    lim2 = lim * lim
    xl, xh = _gaps2(x, cx, box[0], ncell[0])
    yl, yh = _gaps2(y, cy, box[1], ncell[1])
    zl, zh = _gaps2(z, cz, box[2], ncell[2])
    if period[0] == math.inf:  # a wall axis: no cells beyond the walls
        xl = math.inf if cx == 0 else xl
        xh = math.inf if cx == ncell[0] - 1 else xh
    if period[1] == math.inf:
        yl = math.inf if cy == 0 else yl
        yh = math.inf if cy == ncell[1] - 1 else yh
    if period[2] == math.inf:
        zl = math.inf if cz == 0 else zl
        zh = math.inf if cz == ncell[2] - 1 else zh
    if zr == 0:
        zl = 0.0
        zh = 0.0
    # no branches on the gap tests (coin tosses for the branch predictor)
    nx = ncell[0]
    x0 = _wrap(cx - 1, nx)
    x2 = _wrap(cx + 1, nx)
    y0 = nx * _wrap(cy - 1, ncell[1])
    y1 = nx * cy
    y2 = nx * _wrap(cy + 1, ncell[1])
    ns = 0
    for oz in range(-zr, zr + 1):
        gz = _pick(oz, zl, zh)
        kz = nx * ncell[1] * _wrap(cz + oz, ncell[2])
        for oy in range(-1, 2):
            gyz = _pick(oy, yl, yh) + gz
            row = 32 * (kz + (y0 if oy < 0 else (y2 if oy > 0 else y1))) + 3 * (oy + 1) + 9 * (oz + 1)
            stencil[ns] = row + 32 * x0
            ns += xl + gyz < lim2
            stencil[ns] = row + 32 * cx + 1
            ns += gyz < lim2
            stencil[ns] = row + 32 * x2 + 2
            ns += xh + gyz < lim2
    return ns


@inlined_ir
def _collect(i, x, y, z, ri, rmax, m, shell, rec, lists, cells, space):
    """Particles j != i with |c_j - (x,y,z)| < R_i + R_j + shell, into scratch.

    Passes, so that the cache misses of one pass overlap: (1) the cells around
    (x, y, z) that the cut-off sphere reaches (:func:`_reach`) into
    ``stencil``, with a prefetch for each cell's row, (2) a prefetch for the
    centre of every particle in them (beyond :data:`PREFETCH_CENTRES_FROM`
    particles), (3) the distance tests against
    R_i + R_max + shell, branch-free (every candidate is written, the count
    advances on a hit: a branch on data still in flight would serialise the
    misses), each cell with the query point shifted by the cell's periodic
    offset so that no minimum image is needed, (4) the hits compacted in
    place, with the exact cut-off for partners smaller than R_max. Returns the
    number found, or -1 if more than ``m`` are found or ``scratch`` is shorter
    than the candidates (the caller enlarges both).
    """
    scratch = lists.scratch
    stencil = lists.stencil
    centre = lists.centre
    cell_ids = cells.ids
    cell_n = cells.n
    box = space.box
    ncell = space.ncell
    period = space.period
    cap = scratch.shape[0]
    cx = cell_coord(x, box[0], ncell[0])
    cy = cell_coord(y, box[1], ncell[1])
    cz = cell_coord(z, box[2], ncell[2])
    cut_max = ri + rmax + shell
    cut_max2 = cut_max * cut_max
    ns = _reach(x, y, z, cut_max, space, stencil)
    for k in range(ns):
        prefetch(cell_ids, stencil[k] >> 5)
    if centre.shape[0] > PREFETCH_CENTRES_FROM:
        for k in range(ns):
            c = stencil[k] >> 5
            for q in range(cell_n[c]):
                prefetch(centre, cell_ids[c, q])
    count = 0
    for k in range(ns):
        c = stencil[k] >> 5
        code = stencil[k] & 31
        qx = x - _shift(cx + code % 3 - 1, ncell[0], box[0])
        qy = y - _shift(cy + (code // 3) % 3 - 1, ncell[1], box[1])
        qz = z - _shift(cz + code // 9 - 1, ncell[2], box[2])
        nq = cell_n[c]
        if count + nq > cap:
            return -1
        for q in range(nq):
            j = cell_ids[c, q]
            dx = qx - centre[j, 0]
            dy = qy - centre[j, 1]
            dz = qz - centre[j, 2]
            scratch[count] = j
            count += (dx * dx + dy * dy + dz * dz < cut_max2) & (j != i)
    found = 0
    for k in range(count):
        j = scratch[k]
        cut = ri + rec[j, 7] + shell
        if cut < cut_max:
            dx = min_image(x - centre[j, 0], period[0])
            dy = min_image(y - centre[j, 1], period[1])
            dz = min_image(z - centre[j, 2], period[2])
            if dx * dx + dy * dy + dz * dz >= cut * cut:
                continue
        if found >= m:
            return -1
        scratch[found] = j
        found += 1
    return found


@inlined_ir
def prefetch_cells(x, y, z, cut, space, cells, stencil):
    """Prefetch hints for the cell rows a list rebuild around (x, y, z) will read.

    (x, y, z) may lie up to shell/2 outside the box; cell_coord clamps it.
    ``stencil`` is scratch space.
    """
    ns = _reach(x, y, z, cut, space, stencil)
    for k in range(ns):
        c = stencil[k] >> 5
        prefetch(cells.ids, c)
        prefetch(cells.n, c)


@inlined
def _wrap(c, n):
    if c < 0:
        return c + n
    if c >= n:
        return c - n
    return c


@inlined_ir
def _shift(c, n, length):
    """Periodic offset of unwrapped cell coordinate c: the cell's contents sit at x + shift."""
    if c < 0:
        return -length
    if c >= n:
        return length
    return 0.0


@kernel(python=False)
def rebuild_list(i, rec, lists, cells, space, rmax, shell):
    """New list centre c_i = r_i and a new neighbour list for particle i.

    Only the differences to the old list touch other particles' lists: i is
    removed from the lists of old neighbours that are not new ones, and added
    to those of new ones that were not old ones (old and new told apart by the
    per-particle byte ``lists.mark``, linear in the list lengths). Nothing is modified when a
    list or a cell would overflow (returns OVERFLOW or CELL_OVERFLOW); the
    caller enlarges ``nbl`` or ``cell_ids`` and calls again. Returns 0 on success.
    """
    centre = lists.centre
    nbl = lists.nbl
    nbn = lists.nbn
    scratch = lists.scratch
    mark = lists.mark
    cell_ids = cells.ids
    cell_n = cells.n
    # the cell of the old centre (a function of the stored centre, so not stored itself)
    was = cell_index(np.float64(centre[i, 0]), np.float64(centre[i, 1]), np.float64(centre[i, 2]),
                     space.box, space.ncell)
    # the new centre, rounded as stored: the cell, the candidates and the expiry all use it
    x = np.float64(np.float32(rec[i, 0]))
    y = np.float64(np.float32(rec[i, 1]))
    z = np.float64(np.float32(rec[i, 2]))
    c = cell_index(x, y, z, space.box, space.ncell)
    if c != was and cell_n[c] >= cell_ids.shape[1]:
        return CELL_OVERFLOW
    m = nbl.shape[1]
    count = _collect(i, x, y, z, rec[i, 7], rmax, m, shell, rec, lists, cells, space)
    if count < 0:  # more than m found (or scratch too short)
        return OVERFLOW
    nold = nbn[i]
    for k in range(count):
        prefetch(nbl, scratch[k])
        prefetch(nbn, scratch[k])
    for k in range(nold):
        prefetch(nbl, nbl[i, k])
    # mark[j]: 1 = old neighbour only, 2 = old and new; all zero again on return
    for k in range(nold):
        mark[nbl[i, k]] = 1
    full = False
    for k in range(count):
        j = scratch[k]
        if mark[j] != 0:
            mark[j] = 2
        elif nbn[j] >= m:
            full = True
    if full:
        for k in range(nold):
            mark[nbl[i, k]] = 0
        return OVERFLOW
    # old neighbours that are not new ones lose i (swap with their last entry)
    for k in range(nold):
        j = nbl[i, k]
        if mark[j] == 1:
            mark[j] = 0
            last = nbn[j] - 1
            for q in range(last + 1):
                if nbl[j, q] == i:
                    nbl[j, q] = nbl[j, last]
                    nbn[j] = last
                    break
    # new neighbours that were not old ones gain i
    for k in range(count):
        j = scratch[k]
        if mark[j] == 2:
            mark[j] = 0
        else:
            nbl[j, nbn[j]] = i
            nbn[j] += 1
    for k in range(count):
        nbl[i, k] = scratch[k]
    nbn[i] = count
    if c != was:
        slot_remove(i, was, cell_ids, cell_n)
        slot_insert(i, c, cell_ids, cell_n)
    centre[i, 0] = x
    centre[i, 1] = y
    centre[i, 2] = z
    return 0
