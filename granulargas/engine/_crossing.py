"""Cell-crossing neighbour search: no lists, each particle in the cell of its position (numba leaf module).

The alternative to neighbour lists for dilute gases (the "Cell" variant of
the event-driven code of Smallenburg (2022), and the cell method of Rapaport
(2004), ch. 14). The box is cut into a grid of cells at least as wide as
the largest contact distance 2 R_max; every particle belongs to the cell its
position is in (:class:`~granulargas.engine._state.Grid`: a doubly linked list
per cell). Two particles in cells that are not neighbours (27 around a cell,
9 in 2D) are more than 2 R_max apart and cannot touch. A particle's events are:

* a pair collision with a particle of its own or a neighbouring cell;
* a cell crossing: the moment its position reaches a face of its cell
  (``face`` = 2 a + side, as the wall index; on a wall axis the faces at the
  walls are never crossed). Executing it moves the particle to the next cell
  (periodic on periodic axes); its next prediction then covers the particles
  of the new neighbourhood.

Each particle keeps one event (:mod:`granulargas.engine._loop`), the earlier
of its crossing and its best pair; the best pair itself is kept apart
(``Grid.pair_t`` and the columns ``PAIR_J``, ``PAIR_TAG`` of ``Grid.cell``: time,
partner, partner's collision count then), whether it comes before the crossing or not. A full prediction
(after a collision, a stale event, at a build or a driving step) scans the
particles of all 27 (2D: 9) cells around the particle. A crossing scans only
the layer of 9 (2D: 3) cells that became adjacent, and keeps the better of
those and the stored pair -- as the C code adds only the new cells' collisions
to its event tree; if the stored partner has collided since, the particle
scans all its cells instead (a stale best pair may have hidden the next
best). Why it is complete: let i, k touch at t* on their present lines, and
look at the last prediction of either before t* (say of i, at t1). Neither
crosses a face in (t1, t*), so at t1 both are in the cells they touch from,
which are neighbours. A full prediction at t1 sees k. A crossing at t1 sees
k if k's cell is in the new layer; otherwise k's cell was adjacent to i's
previous cell as well, and the same holds one prediction earlier -- back to
a full prediction, which every velocity change of i or k is. On the way, each
prediction that saw the pair computed t* (no velocity changed since), and the
kept minimum is at most t*.

A particle may sit a round-off distance outside its cell (the faces are
multiples of the cell width L / n); :func:`crossing_delay` measures the
position from the cell's lower face by the nearest image and returns 0 for a
particle moving out through a face it is already beyond, and cells are wider
than 2 R_max by a relative margin of :data:`MARGIN` that covers it.
"""

import math

import numpy as np

from granulargas._numba import inlined, kernel
from granulargas.engine._flight import face_delay, pair_delay
from granulargas.engine._geometry import min_image
from granulargas.engine._prefetch import prefetch

#: cells are at least (1 + MARGIN) times the largest contact distance wide
MARGIN = 1e-6

# columns of a particle's row of Grid.cell: cell coordinates, flat cell index, the
# links of its cell's list, its best pair's partner and that partner's count then
FLAT = 3
NEXT = 4
PREV = 5
PAIR_J = 6
PAIR_TAG = 7

#: length of ``Grid.fresh``: [0] the slot whose stored pair a crossing has just brought up
#: to date, [1:] scratch of the scans, the first particles of the (at most 27) non-empty cells
FRESH_SIZE = 28


def particle_rows(n):
    """The per-particle data of a cell crossing in one 64-byte row per particle (one cache
    line; the C code's particle record does the same): views of one buffer of n rows, as
    int32 columns 0-7 ``cell`` (``Grid.cell``, partners -1), 8 ``partner``, 9 ``tag``
    (``Events``), 10 ``where`` (``Calendar``), and float64 columns 6 ``qt`` (``Calendar``,
    inf) and 7 ``pair_t`` (``Grid``, inf). Returns (cell, partner, tag, where, qt, pair_t)."""
    buf = np.zeros(n * 8 + 8)
    offset = (-buf.ctypes.data % 64) // 8
    f8 = buf[offset : offset + n * 8].reshape(n, 8)
    i4 = f8.view(np.int32)
    cell = i4[:, :8]
    cell[:, PAIR_J] = -1
    partner = i4[:, 8]
    partner[:] = -1
    f8[:, 6:] = np.inf
    return cell, partner, i4[:, 9], i4[:, 10], f8[:, 6], f8[:, 7]


@inlined
def face_gap(x, v, c, width, n, period):
    """Distance along one axis from coordinate x (in cell c of width ``width``, n cells),
    moving at v, to the face it moves to, and that face's side (0 lower, 1 upper).

    Returns (gap >= 0, |v|, side); |v| = 0 on a wall axis at the face that is a
    wall (never crossed) and for v = 0 (of either sign).

    The direction of motion is a coin toss for the branch predictor, and LLVM turns a
    select of floats into a branch: the choice is made by weights s, 1 - s in {0, 1}
    instead (a * 1 + b * 0 = a exactly for finite a, b, up to the sign of a zero).
    """
    rel = min_image(x - c * width, period)  # position from the lower face, [-round-off, width + ...]
    up = v > 0.0
    s = 1.0 if up else 0.0
    r = 1.0 - s
    gap = (width - rel) * s + rel * r
    speed = v * s - v * r
    if period == math.inf:
        if (c == n - 1) if up else (c == 0):
            speed = 0.0
    return (gap if gap > 0.0 else 0.0), speed, np.int64(up)


@inlined
def earlier_face(gap, speed, face, g, v, other):
    """The earlier of the crossing kept so far (``gap`` at ``speed``, ``face``) and that of face
    ``other`` (``g`` at ``v``), compared as g |speed| < gap |v| without a division and chosen
    without a branch (weights, as in :func:`face_gap`); a zero speed never crosses."""
    take = ((g * speed < gap * v) | (speed == 0.0)) & (v > 0.0)
    s = np.float64(take)
    r = 1.0 - s
    return g * s + gap * r, v * s + speed * r, other if take else face


@inlined
def predict_crossing(i, t, rec, grid, space, flight):
    """Earliest cell crossing of particle i (streamed to t): (time, face 2 a + side).

    The axis whose face comes first has the least gap / speed; the times are
    compared as gap_a |v_b| < gap_b |v_a| and one division gives the delay
    (inf if the particle crosses no face). The axis is chosen without a branch
    (weights, as in :func:`face_gap`). Under gravity (``flight`` not None) each axis's
    first crossing is the root of a quadratic
    (:func:`granulargas.engine._flight.face_delay`), and the earliest is kept.
    """
    cell = grid.cell
    if flight is not None:
        best = math.inf
        face = np.int64(0)
        for a in range(space.dims):
            c = cell[i, a]
            n = space.ncell[a]
            per = space.period[a]
            width = grid.width[a]
            s, side = face_delay(min_image(rec[i, a] - c * width, per), rec[i, 3 + a], flight[a], width,
                                 per < math.inf or c > 0, per < math.inf or c < n - 1)
            if s < best:
                best = s
                face = 2 * a + side
        return t + best, face
    gap, speed, side = face_gap(rec[i, 0], rec[i, 3], cell[i, 0], grid.width[0], space.ncell[0],
                                space.period[0])
    face = side
    for a in range(1, space.dims):
        g, v, sd = face_gap(rec[i, a], rec[i, 3 + a], cell[i, a], grid.width[a], space.ncell[a],
                            space.period[a])
        gap, speed, face = earlier_face(gap, speed, face, g, v, 2 * a + sd)
    if speed == 0.0:
        return math.inf, face
    return t + gap / speed, face


@inlined
def _neighbour(c, o, n, period):
    """Cell coordinate c + o, wrapped on a periodic axis; -1 beyond a wall."""
    k = c + o
    if k < 0:
        return k + n if period < math.inf else -1
    if k >= n:
        return k - n if period < math.inf else -1
    return k


@inlined
def _scan_listed(first, k, t, before, xi, yi, zi, vx, vy, vz, ri, rec, row_of, period, flight):
    """Second pass of the cell scans: the earliest collision, before ``before``, of the
    particle at (xi, yi, zi) moving with (vx, vy, vz), radius ri, at time t, with the
    particles of the cells whose first particles are ``first[1:k]`` (each cell's chain
    followed through its ``NEXT`` links): (time, partner slot) or (``before``, -1)."""
    best = before
    p = -1
    for q in range(1, k):
        j = first[q]
        while j >= 0:
            tc = t + pair_delay(j, t, xi, yi, zi, vx, vy, vz, ri, rec, period, flight)
            better = tc < best
            best = tc if better else best
            p = j if better else p
            j = row_of[j, NEXT]
    return best, p


@kernel(python=False)
def scan_cells(i, t, before, rec, head, row_of, first, ncell, period, x0, x1, y0, y1, z0, z1, flight):
    """Earliest collision of particle i (streamed to t) with the particles of the cells at
    offsets [x0, x1] x [y0, y1] x [z0, z1] from its cell, before ``before``: (time,
    partner slot) or (``before``, -1). It takes ``head``, ``row_of`` (= ``cell``) and
    ``first`` (= ``fresh``) of the :class:`~granulargas.engine._state.Grid` and ``ncell``,
    ``period`` of the ``Space``, not the whole records: a call passes each array as
    several words on the stack.

    i itself may be among the candidates and gives inf (no relative motion). The
    cells beyond a wall do not exist; with 3 cells on a periodic axis a cell may
    be visited twice (harmless). A call: the loop inlines only the scans of
    cells inside the grid (:func:`scan_block`), the common case.

    Two passes: the first particles of the non-empty cells are listed in
    ``first[1:]`` (one store per cell, no branch on whether it is empty), then
    the listed cells' particles are scanned in the same order. Most cells of a
    dilute gas are empty, and a loop that branched on each cell's occupancy would
    mispredict at every occupied one.
    """
    cx = row_of[i, 0]
    cy = row_of[i, 1]
    cz = row_of[i, 2]
    xi = rec[i, 0]
    yi = rec[i, 1]
    zi = rec[i, 2]
    vx = rec[i, 3]
    vy = rec[i, 4]
    vz = rec[i, 5]
    ri = rec[i, 7]
    k = 1
    for oz in range(z0, z1 + 1):
        kz = _neighbour(cz, oz, ncell[2], period[2])
        if kz < 0:
            continue
        for oy in range(y0, y1 + 1):
            ky = _neighbour(cy, oy, ncell[1], period[1])
            if ky < 0:
                continue
            row = ncell[0] * (ky + ncell[1] * kz)
            for ox in range(x0, x1 + 1):
                kx = _neighbour(cx, ox, ncell[0], period[0])
                if kx < 0:
                    continue
                j = head[kx + row]
                first[k] = j
                k += 1 if j >= 0 else 0
    return _scan_listed(first, k, t, before, xi, yi, zi, vx, vy, vz, ri, rec, row_of, period, flight)


@inlined
def _interior(i, grid, space):
    """Whether particle i's cell and all its neighbours lie inside the grid (3D; no wrap)."""
    ncell = space.ncell
    cell = grid.cell
    return (cell[i, 0] >= 1 and cell[i, 0] <= ncell[0] - 2 and cell[i, 1] >= 1 and cell[i, 1] <= ncell[1] - 2
            and cell[i, 2] >= 1 and cell[i, 2] <= ncell[2] - 2)


@inlined
def scan_block(i, t, before, rec, grid, space, c0, s1, s2, n0, flight):
    """:func:`scan_cells` over cells of flat index c0 + u s1 + w s2 + v (w, u in 0..2,
    v in 0..n0-1, in this order) -- the cells around an interior cell, without wraps; the
    same two passes. (The coordinate differences keep their nearest-image tests: a particle
    that has just crossed a periodic face may sit a round-off distance on the far side of
    the box from its new cell.)"""
    head = grid.head
    row_of = grid.cell
    period = space.period
    xi = rec[i, 0]
    yi = rec[i, 1]
    zi = rec[i, 2]
    vx = rec[i, 3]
    vy = rec[i, 4]
    vz = rec[i, 5]
    ri = rec[i, 7]
    first = grid.fresh
    k = 1
    for w in range(3):
        for u in range(3):
            b = c0 + u * s1 + w * s2
            for v in range(n0):
                j = head[b + v]
                first[k] = j
                k += 1 if j >= 0 else 0
    return _scan_listed(first, k, t, before, xi, yi, zi, vx, vy, vz, ri, rec, row_of, period, flight)


@inlined
def predict_pair_cells(i, t, before, rec, count, grid, space, flight):
    """Earliest collision of particle i (streamed to t) before ``before``: (time, partner
    slot) or (``before``, -1).

    Right after a crossing of i (``grid.fresh[0] == i``) the stored best pair is
    current; otherwise all 27 (2D: 9) cells around i are scanned and the best
    pair stored, whether before ``before`` or not.
    """
    if grid.fresh[0] == i:
        grid.fresh[0] = -1
        pt = grid.pair_t[i]
        pj = grid.cell[i, PAIR_J]
    else:
        if _interior(i, grid, space):
            nx = space.ncell[0]
            sz = nx * space.ncell[1]
            pt, pj = scan_block(i, t, math.inf, rec, grid, space, grid.cell[i, FLAT] - 1 - nx - sz, nx, sz, 3,
                                flight)
        else:
            zr = 1 if space.ncell[2] >= 3 else 0
            pt, pj = scan_cells(i, t, math.inf, rec, grid.head, grid.cell, grid.fresh, space.ncell, space.period,
                                -1, 1, -1, 1, -zr, zr, flight)
        grid.pair_t[i] = pt
        grid.cell[i, PAIR_J] = pj
        grid.cell[i, PAIR_TAG] = count[pj] if pj >= 0 else 0
    if pt < before:
        return pt, pj
    return before, -1


@inlined
def scan_new_layer(i, t, face, rec, count, grid, space, flight):
    """After i crossed ``face`` into its present cell: keep the better of the stored pair
    and the particles of the layer of cells that became adjacent, and mark the stored
    pair current (``grid.fresh``); if the stored partner has collided since, do
    nothing (the prediction then scans all cells)."""
    pj = grid.cell[i, PAIR_J]
    if pj >= 0 and count[pj] != grid.cell[i, PAIR_TAG]:
        return
    a = face >> 1
    o = 1 if face & 1 else -1
    if _interior(i, grid, space):
        # the layer's cells in the order of scan_cells: the other two axes, the slower outside
        nx = space.ncell[0]
        sz = nx * space.ncell[1]
        sa = 1 if a == 0 else (nx if a == 1 else sz)
        s1 = nx if a == 0 else 1
        s2 = nx if a == 2 else sz
        pt, pn = scan_block(i, t, grid.pair_t[i], rec, grid, space, grid.cell[i, FLAT] + o * sa - s1 - s2,
                            s1, s2, 1, flight)
    else:
        zr = 1 if space.ncell[2] >= 3 else 0
        x0 = o if a == 0 else -1
        x1 = o if a == 0 else 1
        y0 = o if a == 1 else -1
        y1 = o if a == 1 else 1
        z0 = o if a == 2 else -zr
        z1 = o if a == 2 else zr
        pt, pn = scan_cells(i, t, grid.pair_t[i], rec, grid.head, grid.cell, grid.fresh, space.ncell, space.period,
                            x0, x1, y0, y1, z0, z1, flight)
    if pn >= 0:
        grid.pair_t[i] = pt
        grid.cell[i, PAIR_J] = pn
        grid.cell[i, PAIR_TAG] = count[pn]
    grid.fresh[0] = i


@inlined
def grid_insert(i, c, grid):
    """Put particle i at the head of cell c's list."""
    head = grid.head
    row = grid.cell
    h = head[c]
    row[i, NEXT] = h
    row[i, PREV] = -1
    if h >= 0:
        row[h, PREV] = i
    head[c] = i
    row[i, FLAT] = c


@inlined
def grid_remove(i, grid):
    """Take particle i out of its cell's list."""
    row = grid.cell
    q = row[i, PREV]
    n = row[i, NEXT]
    if q >= 0:
        row[q, NEXT] = n
    else:
        grid.head[row[i, FLAT]] = n
    if n >= 0:
        row[n, PREV] = q


@inlined
def cross(i, face, grid, space):
    """Move particle i (at the face ``face`` of its cell) into the cell beyond that face."""
    a = face >> 1
    n = space.ncell[a]
    c = grid.cell[i, a] + (1 if face & 1 else -1)
    if c < 0:
        c += n
    elif c >= n:
        c -= n
    grid_remove(i, grid)
    grid.cell[i, a] = c
    ncell = space.ncell
    grid_insert(i, grid.cell[i, 0] + ncell[0] * (grid.cell[i, 1] + ncell[1] * grid.cell[i, 2]), grid)


@kernel
def build_grid(rec, grid, space):
    """Every particle into the cell of its position (slot order: a pure function of the state)."""
    box = space.box
    ncell = space.ncell
    grid.head[:] = -1
    for i in range(rec.shape[0] - 1, -1, -1):  # inserted at the head: each cell lists its slots ascending
        for a in range(3):
            c = int(rec[i, a] * (ncell[a] / box[a]))
            grid.cell[i, a] = min(max(c, 0), ncell[a] - 1)
        grid_insert(i, grid.cell[i, 0] + ncell[0] * (grid.cell[i, 1] + ncell[1] * grid.cell[i, 2]), grid)


@inlined
def prefetch_around(i, grid, space):
    """Prefetch hints for the cell heads around particle i's cell (no effect on results):
    one per row of 3 cells (the middle one's line)."""
    ncell = space.ncell
    if _interior(i, grid, space):
        nx = ncell[0]
        sz = nx * ncell[1]
        c = grid.cell[i, FLAT] - nx - sz
        for w in range(3):
            for u in range(3):
                prefetch(grid.head, c + u * nx + w * sz)
        return
    period = space.period
    cx = grid.cell[i, 0]
    cy = grid.cell[i, 1]
    cz = grid.cell[i, 2]
    zr = 1 if ncell[2] >= 3 else 0
    for oz in range(-zr, zr + 1):
        kz = _neighbour(cz, oz, ncell[2], period[2])
        if kz < 0:
            continue
        for oy in range(-1, 2):
            ky = _neighbour(cy, oy, ncell[1], period[1])
            if ky >= 0:
                prefetch(grid.head, cx + ncell[0] * (ky + ncell[1] * kz))
