"""Compiled soft-sphere compression for initial states of large systems (numba leaf module).

Spheres (disks) of radii R_i that overlap are pulled apart by the energy
minimiser FIRE (Bitzek, Koskinen, Gähler, Moseler & Gumbsch 2006) on the
harmonic pair energy

    U = sum_{i<j} (s'_ij - d_ij)^2 / 2  for d_ij < s'_ij,  s'_ij = (1 + w)(R_i + R_j),

w the swelling (a few per cent), until no pair is closer than R_i + R_j: a
hard-sphere state without overlap, most gaps near w (R_i + R_j). The last few
overlapping pairs, which FIRE resolves slowly, are pushed apart directly
(:func:`separate_pairs`). Forces are summed over a Verlet neighbour list: the
pairs within s'_ij + skin when it was built, each once (j > i), found by a scan
of particles sorted by cell (:func:`._montecarlo.sort_by_cell`); the list stays
valid while the two largest distances moved since add up to less than the skin.

The list is built in parallel threads (each row on its own); the forces in
parallel threads over the slabs of the sort, those of one parity at a time (a
slab's pairs reach into the next slab only), with per-slab sums combined in slab
order; the moves in parallel threads over fixed blocks of particles. The result
is the same for any number of threads."""

import math

import numba
import numpy as np

from granulargas._numba import inlined, jit
from granulargas.engine._cells import cell_coord
from granulargas.engine._geometry import min_image
from granulargas.initial._montecarlo import _periodic_row, _radius_range, _scan_window


def compression_grid(box, reach):
    """Cell counts (3,) of the sort for the neighbour lists of pairs within ``reach``
    (box (d,)): cells at least reach wide, so that the cells next to a particle's
    hold its neighbours; None where an axis is shorter than 4 reach."""
    box = np.asarray(box, dtype=np.float64)
    if float(box.min()) < 4.0 * reach:
        return None
    grid = np.ones(3, dtype=np.int64)
    grid[: len(box)] = (box / reach * (1.0 - 1e-9)).astype(np.int64)
    return grid


@inlined
def _row_neighbours(k, x, y, z, rk, a, b, r, radius, swell, skin, nbr, m, end, same):
    """Particles j > k of the sorted run [a, b) within (1 + swell)(R_k + R_j) + skin of
    (x, y, z), counted from m on and stored to nbr[m:end]; returns the new m. ``same``:
    all radii equal."""
    cut = (1.0 + swell) * 2.0 * rk + skin
    for j in range(max(a, k + 1), b):
        dx = x - r[j, 0]
        dy = y - r[j, 1]
        dz = z - r[j, 2]
        if not same:
            cut = (1.0 + swell) * (rk + radius[j]) + skin
        if dx * dx + dy * dy + dz * dz < cut * cut:
            if m < end:
                nbr[m] = j
            m += 1
    return m


@inlined
def _scan_neighbours(k, r, radius, box, ncell, start, reach, swell, skin, nbr, m, end, same):
    """:func:`_row_neighbours` over the rows of cells around particle k's (as filed by
    the sort, in the box): its own and the next one on either side in y and in z (3D),
    along x the cells within ``reach`` (a run of contiguous particles, or two across the
    periodic boundary); the rows filed before k's are skipped (j > k)."""
    nx = ncell[0]
    ny = ncell[1]
    nz = ncell[2]
    x = r[k, 0]
    y = r[k, 1]
    z = r[k, 2]
    ly, lz, mz, a1, b1, a2, b2, sx2 = _scan_window(x, y, z, box, ncell, reach)
    cy = cell_coord(y, box[1], ny)
    cz = cell_coord(z, box[2], nz)
    rk = radius[k]
    for oz in range(-1 if nz > 1 else 0, 2 if nz > 1 else 1):
        kz, zz = _periodic_row(cz + oz, nz, z, box[2])
        for oy in range(-1, 2):
            ky, yy = _periodic_row(cy + oy, ny, y, box[1])
            row = nx * (ky + ny * kz)
            if start[row + nx] <= k:  # (rows filed before k's: none of their particles is listed in k's row)
                continue
            m = _row_neighbours(k, x, yy, zz, rk, start[row + a1], start[row + b1], r, radius, swell, skin, nbr,
                                m, end, same)
            m = _row_neighbours(k, x - sx2, yy, zz, rk, start[row + a2], start[row + b2], r, radius, swell, skin,
                                nbr, m, end, same)
    return m


@jit(parallel=True)
def neighbour_counts(r, radius, box, ncell, start, swell, skin, counts):
    """counts[k] = the number of particles j > k within (1 + swell)(R_k + R_j) + skin
    of particle k (each pair once), for particles sorted by cell (:func:`._montecarlo.sort_by_cell`, just
    sorted) on a grid whose cells are at least (1 + swell) 2 R_max + skin wide, at
    least three of them along y and z (:func:`compression_grid`)."""
    rmin, rmax = _radius_range(radius)
    reach = ((1.0 + swell) * 2.0 * rmax + skin) * (1.0 + 1e-9)  # (+ rounding margin)
    empty = np.empty(0, dtype=np.int32)
    for k in numba.prange(r.shape[0]):
        counts[k] = _scan_neighbours(k, r, radius, box, ncell, start, reach, swell, skin, empty, 0, 0, rmin == rmax)


@jit(parallel=True)
def neighbour_rows(r, radius, box, ncell, start, swell, skin, offsets, nbr, counts):
    """The pairs of the neighbour list, each once: row k (the particles of
    :func:`neighbour_counts`, in scan order) in nbr[offsets[k]:offsets[k] + counts[k]],
    counts[k] their number; a row holds at most offsets[k + 1] - offsets[k] of them.
    Returns the number of rows that did not fit (their counts exceed the room: build
    again with more)."""
    rmin, rmax = _radius_range(radius)
    reach = ((1.0 + swell) * 2.0 * rmax + skin) * (1.0 + 1e-9)
    same = rmin == rmax
    full = 0
    for k in numba.prange(r.shape[0]):
        a = offsets[k]
        counts[k] = _scan_neighbours(k, r, radius, box, ncell, start, reach, swell, skin, nbr, a,
                                     offsets[k + 1], same) - a
        if counts[k] > offsets[k + 1] - a:
            full += 1
    return full


@inlined
def _row_forces(a, b, r, radius, box, offsets, counts, pairs, swell, f, limit):
    """The forces of the pairs of rows [a, b) of :func:`fire_forces`, added to f (rows in
    order, each row's partners j in list order). Returns (the number of pairs closer than
    R_i + R_j, the largest (s'_ij - d_ij) - (R_i + R_j) w/2, the number of partners
    j >= limit)."""
    hard = 0
    worst = -math.inf
    stray = 0
    for k in range(a, b):
        fx = 0.0
        fy = 0.0
        fz = 0.0
        rk = radius[k]
        for e in range(offsets[k], offsets[k] + counts[k]):  # (branchless: half the pairs overlap)
            j = pairs[e]
            stray += j >= limit
            dx = min_image(r[k, 0] - r[j, 0], box[0])
            dy = min_image(r[k, 1] - r[j, 1], box[1])
            dz = min_image(r[k, 2] - r[j, 2], box[2])
            s = rk + radius[j]
            d = math.sqrt(dx * dx + dy * dy + dz * dz)
            over = max(0.0, (1.0 + swell) * s - d)
            worst = max(worst, over - 0.5 * swell * s)
            hard += over > swell * s
            c = over / d
            fx += c * dx
            fy += c * dy
            fz += c * dz
            f[j, 0] -= c * dx
            f[j, 1] -= c * dy
            f[j, 2] -= c * dz
        f[k, 0] += fx
        f[k, 1] += fy
        f[k, 2] += fz
    return hard, worst, stray


@jit(parallel=True)
def fire_forces(r, radius, box, offsets, counts, pairs, swell, v, f, slab_start, sums):
    """Forces f (N, 3) of the swollen harmonic overlaps (module docstring), over the
    pairs of :func:`neighbour_rows` (each once, j > k), with the particles in the slabs
    of the sort that built the list: slab h holds particles [slab_start[h],
    slab_start[h + 1]) (slab_start (S + 1,), slab_start[S] = N).

    A list built by a scan whose slabs are at least a reach thick pairs a particle of
    slab h >= 1 with particles of slabs h and h + 1 only; slab 0 also with those of
    slab S - 1 (across the periodic boundary). The rows of slab h write the forces of
    slabs h and h + 1 only, so that the slabs h >= 2 of even index run in parallel
    threads, then those of odd index, then slab 0 on its own (which writes slab S - 1
    too). Every force is thus summed in an order fixed by the list and the slabs, and
    the sums F.v, |v|^2, |F|^2 are summed per slab (in ``sums`` (S, 6), scratch) and
    then over the slabs in order: the same result for any number of threads.

    Returns (F.v, |v|^2, |F|^2, the number of pairs closer than R_i + R_j, the largest
    (s'_ij - d_ij) - (R_i + R_j) w/2 of a pair (< 0 when every gap is >= w/2 contact
    distances), the number of pairs of slabs h >= 1 that reach beyond slab h + 1:
    nonzero means the slabs did not fit the list, and the forces are not to be used).
    """
    slabs = slab_start.shape[0] - 1
    for h in numba.prange(slabs):
        for k in range(slab_start[h], slab_start[h + 1]):
            f[k, 0] = 0.0
            f[k, 1] = 0.0
            f[k, 2] = 0.0
    for parity in range(2):
        for q in numba.prange((slabs - 1 + parity) // 2):
            h = 2 * q + 2 - parity  # even slabs from 2, then odd ones
            hs, ws, ss = _row_forces(slab_start[h], slab_start[h + 1], r, radius, box, offsets, counts, pairs,
                                     swell, f, slab_start[min(h + 2, slabs)])
            sums[h, 3] = hs
            sums[h, 4] = ws
            sums[h, 5] = ss
    hs, ws, ss = _row_forces(slab_start[0], slab_start[1], r, radius, box, offsets, counts, pairs, swell, f,
                             slab_start[slabs])
    sums[0, 3] = hs
    sums[0, 4] = ws
    sums[0, 5] = ss
    for h in numba.prange(slabs):
        ps = 0.0
        vs = 0.0
        fs = 0.0
        for k in range(slab_start[h], slab_start[h + 1]):
            ps += f[k, 0] * v[k, 0] + f[k, 1] * v[k, 1] + f[k, 2] * v[k, 2]
            vs += v[k, 0] * v[k, 0] + v[k, 1] * v[k, 1] + v[k, 2] * v[k, 2]
            fs += f[k, 0] * f[k, 0] + f[k, 1] * f[k, 1] + f[k, 2] * f[k, 2]
        sums[h, 0] = ps
        sums[h, 1] = vs
        sums[h, 2] = fs
    p = 0.0
    vv = 0.0
    ff = 0.0
    hard = 0
    worst = -math.inf
    stray = 0
    for h in range(slabs):
        p += sums[h, 0]
        vv += sums[h, 1]
        ff += sums[h, 2]
        hard += int(sums[h, 3])
        worst = max(worst, sums[h, 4])
        stray += int(sums[h, 5])
    return p, vv, ff, hard, worst, stray


@jit(parallel=True)
def follow_sort(dest, v, counts, v_tmp, c_tmp):
    """v (N, 3) and counts (N,) permuted as the particles by a sort (particle k to
    dest[k]); v_tmp and c_tmp (like v, counts) are scratch."""
    for k in numba.prange(dest.shape[0]):
        i = dest[k]
        v_tmp[i, 0] = v[k, 0]
        v_tmp[i, 1] = v[k, 1]
        v_tmp[i, 2] = v[k, 2]
        c_tmp[i] = counts[k]
    for k in numba.prange(dest.shape[0]):
        v[k, 0] = v_tmp[k, 0]
        v[k, 1] = v_tmp[k, 1]
        v[k, 2] = v_tmp[k, 2]
        counts[k] = c_tmp[k]


@jit
def separate_pairs(r, radius, box, offsets, counts, pairs, swell):
    """Each listed pair closer than R_i + R_j pushed apart along its axis to (1 + swell/2)
    (R_i + R_j), both particles by half (in list order, Gauss-Seidel: for the last few
    overlaps of a compression, which FIRE resolves slowly). Returns the number of pairs
    pushed."""
    pushed = 0
    for k in range(r.shape[0]):
        for e in range(offsets[k], offsets[k] + counts[k]):
            j = pairs[e]
            dx = min_image(r[k, 0] - r[j, 0], box[0])
            dy = min_image(r[k, 1] - r[j, 1], box[1])
            dz = min_image(r[k, 2] - r[j, 2], box[2])
            s = radius[k] + radius[j]
            d = math.sqrt(dx * dx + dy * dy + dz * dz)
            if d < s and d > 0.0:
                c = 0.5 * ((1.0 + 0.5 * swell) * s - d) / d
                r[k, 0] += c * dx
                r[k, 1] += c * dy
                r[k, 2] += c * dz
                r[j, 0] -= c * dx
                r[j, 1] -= c * dy
                r[j, 2] -= c * dz
                pushed += 1
    return pushed


@jit(parallel=True)
def fire_move(r, v, f, r0, keep, mix, dt, cap, block, moved):
    """One FIRE step: v = keep v + mix f (the velocity mixing; keep = 0 and mix = 0 stop
    the particles), then v += dt f, v scaled down to |v| dt <= cap, r += dt v
    (semi-implicit Euler, unit masses, each move at most ``cap`` long).
    moved[b] = the largest and the second largest distance from r0 of the particles of
    block b (a pair has come closer by at most the sum of the two largest over all
    blocks)."""
    n = r.shape[0]
    for b in numba.prange(moved.shape[0]):
        first = 0.0
        second = 0.0
        for k in range(b * block, min(n, (b + 1) * block)):
            wx = keep * v[k, 0] + mix * f[k, 0] + dt * f[k, 0]
            wy = keep * v[k, 1] + mix * f[k, 1] + dt * f[k, 1]
            wz = keep * v[k, 2] + mix * f[k, 2] + dt * f[k, 2]
            w2 = wx * wx + wy * wy + wz * wz
            if dt * dt * w2 > cap * cap:
                c = cap / (dt * math.sqrt(w2))
                wx *= c
                wy *= c
                wz *= c
            v[k, 0] = wx
            v[k, 1] = wy
            v[k, 2] = wz
            r[k, 0] += dt * wx
            r[k, 1] += dt * wy
            r[k, 2] += dt * wz
            dist2 = (r[k, 0] - r0[k, 0]) ** 2 + (r[k, 1] - r0[k, 1]) ** 2 + (r[k, 2] - r0[k, 2]) ** 2
            if dist2 > second:
                if dist2 > first:
                    second = first
                    first = dist2
                else:
                    second = dist2
        moved[b, 0] = math.sqrt(first)
        moved[b, 1] = math.sqrt(second)
