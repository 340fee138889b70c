"""Compiled hard-sphere Monte Carlo sweeps for initial states (numba leaf module).

Random single-particle displacements, rejected on overlap. Two ways to find
the candidates:

* particles sorted by cell before each sweep (:func:`sort_by_cell`,
  :func:`sorted_sweep`): the cells of a row are contiguous in memory, so a scan
  reads a few contiguous runs of positions instead of following a linked list
  per cell (each list of ~1 particle costs a mispredicted loop exit and a
  dependent load); cells are left stale during the sweep and the scan reaches
  2 R_max + step, which finds every particle moved since the sort. The sweep
  runs slab by slab, so that the slabs of one parity run in parallel threads
  with a result independent of the thread count;
* doubly linked cell lists on a grid of width >= 2 R_max (reused from
  :mod:`granulargas.engine._cells`), kept up to date by every move: for small
  systems, small boxes, long moves (dilute gases) and the overlap pushes of the
  growth steps.

Random numbers of a sweep: either an (N, d) array ``u`` of uniforms that Python
fills from the seeded numpy Generator (small systems), or, for the sorted
sweeps of large ones, a 64-bit ``key`` that Python draws per sweep from the
Generator: the displacement of particle i along axis a then uses the
(d i + a)-th output of the SplitMix64 generator (Steele, Lea & Flood 2014)
started from the key. SplitMix64's n-th output is a closed function of
(key, n), so each is computed where it is used (no array of N d random numbers
to fill and read per sweep). Either way the result is reproducible everywhere.
"""

import math

import numba
import numpy as np

from granulargas._numba import inlined, jit, kernel
from granulargas.engine._cells import _wrap, cell_coord, cell_index, cell_insert, cell_remove
from granulargas.engine._geometry import min_image


_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)


@inlined
def splitmix_uniform(key, n):
    """The n-th (n >= 0) output of SplitMix64 started from ``key``, as a double in [0, 1)
    (its top 53 bits); key and n uint64."""
    z = key + (n + np.uint64(1)) * _GOLDEN
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    z = z ^ (z >> np.uint64(31))
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


#: the axes as int64 constants: a Python int would be typed as its literal, one compile per axis
_X, _Y, _Z = np.int64(0), np.int64(1), np.int64(2)


@inlined
def _uniform(key, u, i, a, dim):
    """Uniform a (axis) of particle i: u[i, a] if u holds a sweep's numbers, else from the key."""
    if u.shape[0] > 0:
        return u[i, a]
    return splitmix_uniform(key, np.uint64(dim * i + a))


@inlined
def _trial(r, i, step, key, u, dim, box):
    """Trial position r_i + step (2 u - 1) (u of particle i: :func:`_uniform`), wrapped
    into the box; x = box[0] flags a move to skip (-tiny + L rounded to L)."""
    x = r[i, 0] + step * (2.0 * _uniform(key, u, i, _X, dim) - 1.0)
    y = r[i, 1] + step * (2.0 * _uniform(key, u, i, _Y, dim) - 1.0)
    z = r[i, 2] + step * (2.0 * _uniform(key, u, i, _Z, dim) - 1.0) if dim == 3 else r[i, 2]
    x = x - box[0] if x >= box[0] else (x + box[0] if x < 0.0 else x)
    y = y - box[1] if y >= box[1] else (y + box[1] if y < 0.0 else y)
    z = z - box[2] if z >= box[2] else (z + box[2] if z < 0.0 else z)
    if x >= box[0] or y >= box[1] or z >= box[2]:
        x = box[0]
    return x, y, z


@jit
def sweep_uniforms(key, n, dim):
    """The (n, dim) uniforms a sweep with ``key`` uses (for tests and analysis)."""
    out = np.empty((n, dim))
    for i in range(n):
        for a in range(dim):
            out[i, a] = splitmix_uniform(key, np.uint64(dim * i + a))
    return out


@kernel
def fill_cells(r, box, ncell, cell_head, cell_next, cell_prev, cell_of):
    cell_head[:] = -1
    for i in range(r.shape[0] - 1, -1, -1):
        cell_insert(i, cell_index(r[i, 0], r[i, 1], r[i, 2], box, ncell), cell_head, cell_next,
                    cell_prev, cell_of)


@kernel
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


@kernel
def sweep(r, radius, box, ncell, cell_head, cell_next, cell_prev, cell_of, step, key, u, dim):
    """One sweep of displacement moves r_i += step (2 u_i - 1), u_i the sweep's uniforms:
    the rows of ``u`` (N, dim), or if u is empty those of ``key`` (uint64; module
    docstring); dim = 2 or 3. Returns the accepted count."""
    accepted = 0
    for i in range(r.shape[0]):
        x, y, z = _trial(r, i, step, key, u, dim, box)
        if x >= box[0]:
            continue
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


@kernel
def wrap_positions(r, box):
    """Positions wrapped into the box (a coordinate that rounds to L becomes 0)."""
    for k in range(r.shape[0]):
        r[k, 0] = _in_box(r[k, 0], box[0])
        r[k, 1] = _in_box(r[k, 1], box[1])
        r[k, 2] = _in_box(r[k, 2], box[2])


@kernel
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


@kernel
def relax_sweep(r, radius, box, ncell, cell_head, cell_next, cell_prev, cell_of, step, key, u, dim):
    """Sweep of moves accepted when the moved particle's overlap depth does not grow.

    Moves r_i += step (2 u_i - 1) as in :func:`sweep`. Non-overlapping particles
    therefore move as hard spheres while overlapping ones are pushed apart
    (zero-temperature overlap relaxation). Returns the number of particles still
    overlapping after their move.
    """
    overlapping = 0
    for i in range(r.shape[0]):
        old = overlap_depth(i, r[i, 0], r[i, 1], r[i, 2], r, radius, box, ncell, cell_head,
                            cell_next)
        x, y, z = _trial(r, i, step, key, u, dim, box)
        if x >= box[0]:
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


@kernel
def overlapping(r, radius, box, ncell, cell_head, cell_next, out):
    """Indices of all particles overlapping some other one, into out; returns the count."""
    m = 0
    for i in range(r.shape[0]):
        if overlaps(i, r[i, 0], r[i, 1], r[i, 2], r, radius, box, ncell, cell_head, cell_next):
            out[m] = i
            m += 1
    return m


@kernel
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
        m0 = m
        # one scan of the cells around (x, y, z) serves both passes: pass 0 at i's place (the
        # push and the near particles), pass 1 at its new place when the near particles do
        # not suffice (its new overlaps)
        for scan in range(2):
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
                                if scan == 1:
                                    if d2 < s * s and m < out.shape[0]:
                                        out[m] = j
                                        m += 1
                                else:
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
            if scan == 1:
                break
            if px == 0.0 and py == 0.0 and pz == 0.0:
                break
            x += kick[k] * px
            y += kick[k] * py
            z += kick[k] * pz
            x = x - box[0] if x >= box[0] else (x + box[0] if x < 0.0 else x)
            y = y - box[1] if y >= box[1] else (y + box[1] if y < 0.0 else y)
            z = z - box[2] if z >= box[2] else (z + box[2] if z < 0.0 else z)
            if x >= box[0] or y >= box[1] or z >= box[2]:
                break
            c = cell_index(x, y, z, box, ncell)
            if c != cell_of[i]:
                cell_remove(i, cell_head, cell_next, cell_prev, cell_of)
                cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of)
            r[i, 0] = x
            r[i, 1] = y
            r[i, 2] = z
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
                break
        if m > m0 and m < out.shape[0]:
            out[m] = i
            m += 1
    return m


@kernel
def distinct(values, m, seen, out):
    """Distinct entries of values[:m] into out (first-occurrence order); returns their number.

    ``seen`` (bool, N) must be all False on entry and is all False again on return.
    """
    return _unmark(seen, out, _first_seen(values, 0, m, seen, out, 0))


@inlined
def _first_seen(values, a, b, seen, out, u):
    """Append the entries of values[a:b] not yet seen to out[u:] (marking them in seen);
    returns the new count."""
    for k in range(a, b):
        v = values[k]
        if not seen[v]:
            seen[v] = True
            out[u] = v
            u += 1
    return u


@inlined
def _unmark(seen, out, u):
    """seen all False again after out[:u] were marked; returns u."""
    for k in range(u):
        seen[out[k]] = False
    return u


@jit
def sort_by_cell(r, radius, ids, box, ncell, start, cell_of, r_tmp, f_tmp, i_tmp, dest):
    """Stable counting sort of the particles by cell (row by row along x): r (N, 3),
    radius (N,) and ids (N,) permuted in place, positions wrapped into the box;
    start (n_cells + 1,) receives the first index of each cell (start[-1] = N),
    cell_of (N,) int the cell of each particle (sorted order), dest (N,) int the new
    index of each old one. r_tmp, f_tmp and i_tmp (like r, radius, ids) are scratch."""
    n = r.shape[0]
    nc = ncell[0] * ncell[1] * ncell[2]
    start[: nc + 1] = 0
    for k in range(n):
        r[k, 0] = _in_box(r[k, 0], box[0])
        r[k, 1] = _in_box(r[k, 1], box[1])
        r[k, 2] = _in_box(r[k, 2], box[2])
        c = cell_index(r[k, 0], r[k, 1], r[k, 2], box, ncell)
        cell_of[k] = c
        start[c + 1] += 1
    for c in range(1, nc + 1):
        start[c] += start[c - 1]
    for k in range(n):
        c = cell_of[k]
        d = start[c]
        start[c] = d + 1
        dest[k] = d
        r_tmp[d, 0] = r[k, 0]
        r_tmp[d, 1] = r[k, 1]
        r_tmp[d, 2] = r[k, 2]
        f_tmp[d] = radius[k]
        i_tmp[d] = ids[k]
    for c in range(nc, 0, -1):
        start[c] = start[c - 1]
    start[0] = 0
    for c in range(nc):
        for k in range(start[c], start[c + 1]):
            cell_of[k] = c
    r[:] = r_tmp
    radius[:] = f_tmp
    ids[:] = i_tmp


@inlined
def _in_box(x, length):
    """x wrapped into [0, length) (a value that rounds to length becomes 0)."""
    x = x - length if x >= length else (x + length if x < 0.0 else x)
    return 0.0 if x >= length else x


@inlined
def _row_overlaps(k, x, y, z, rk, a, b, r, radius, same):
    if same:  # equal radii: one contact distance
        s2 = 4.0 * rk * rk
        for j in range(a, b):
            dx = x - r[j, 0]
            dy = y - r[j, 1]
            dz = z - r[j, 2]
            if dx * dx + dy * dy + dz * dz < s2 and j != k:
                return True
        return False
    for j in range(a, b):
        dx = x - r[j, 0]
        dy = y - r[j, 1]
        dz = z - r[j, 2]
        s = rk + radius[j]
        if dx * dx + dy * dy + dz * dz < s * s and j != k:
            return True
    return False


@inlined
def _radius_range(radius):
    """Smallest and largest radius."""
    rmin = math.inf
    rmax = 0.0
    for k in range(radius.shape[0]):
        rmin = min(rmin, radius[k])
        rmax = max(rmax, radius[k])
    return rmin, rmax


@inlined
def _scan_window(x, y, z, box, ncell, reach):
    """The cells a scan of particles sorted by cell visits around (x, y, z) (in the box):
    the two rows in y and in z (3D) nearest the point, from (ly, lz), mz rows in z; along x
    the cells within ``reach`` as up to two runs of a row, [a1, b1) unshifted and [a2, b2)
    across the periodic boundary, whose particles are seen shifted by sx2."""
    nx = ncell[0]
    ny = ncell[1]
    nz = ncell[2]
    fy = y * (ny / box[1])
    cy = min(int(fy), ny - 1)
    ly = cy - 1 if fy - cy < 0.5 else cy
    if nz > 1:
        fz = z * (nz / box[2])
        cz = min(int(fz), nz - 1)
        lz = cz - 1 if fz - cz < 0.5 else cz
        mz = 2
    else:
        lz = 0
        mz = 1
    xl = int(math.floor((x - reach) * (nx / box[0])))
    xh = min(int(math.floor((x + reach) * (nx / box[0]))), xl + nx - 1)
    a1 = xl
    b1 = xh + 1
    a2 = 0
    b2 = 0
    sx2 = 0.0
    if xl < 0:
        a1 = 0
        a2 = xl + nx
        b2 = nx
        sx2 = -box[0]
    elif xh >= nx:
        b1 = nx
        b2 = xh + 1 - nx
        sx2 = box[0]
    return ly, lz, mz, a1, b1, a2, b2, sx2


@inlined
def _periodic_row(c, n, x, length):
    """Row index c (at most one period outside [0, n)) wrapped into it, and the query
    coordinate x shifted so that the row's particles are seen at their periodic image."""
    if c < 0:
        return c + n, x + length
    if c >= n:
        return c - n, x - length
    return c, x


@jit
def sorted_overlaps(k, x, y, z, r, radius, box, ncell, start, reach, same):
    """True if particle k at (x, y, z) overlaps another one, for particles sorted by cell
    (:func:`sort_by_cell`) on a grid whose y and z cells (3D) are >= 2 ``reach`` wide
    and with ncell[0] cells along x: scans the two rows in y and z nearest the point,
    along x the cells within ``reach``. Every particle within reach of the point is
    scanned, whatever cell it is filed under."""
    nx = ncell[0]
    ny = ncell[1]
    nz = ncell[2]
    ly, lz, mz, a1, b1, a2, b2, sx2 = _scan_window(x, y, z, box, ncell, reach)
    rk = radius[k]
    for oz in range(mz):
        kz, zz = _periodic_row(lz + oz, nz, z, box[2])
        for oy in range(2):
            ky, yy = _periodic_row(ly + oy, ny, y, box[1])
            row = nx * (ky + ny * kz)
            if _row_overlaps(k, x, yy, zz, rk, start[row + a1], start[row + b1], r, radius, same):
                return True
            if _row_overlaps(k, x - sx2, yy, zz, rk, start[row + a2], start[row + b2], r, radius, same):
                return True
    return False


@inlined
def _wrapped(x, length):
    return x - length if x >= length else (x + length if x < 0.0 else x)


@inlined
def _sorted_move(k, r, radius, box, ncell, start, step, key, dim, reach, same):
    """Move k of a sweep over cell-sorted particles; True if accepted."""
    n = np.uint64(dim * k)
    xu = r[k, 0] + step * (2.0 * splitmix_uniform(key, n) - 1.0)
    yu = r[k, 1] + step * (2.0 * splitmix_uniform(key, n + np.uint64(1)) - 1.0)
    zu = r[k, 2] + step * (2.0 * splitmix_uniform(key, n + np.uint64(2)) - 1.0) if dim == 3 else r[k, 2]
    x = _wrapped(xu, box[0])
    y = _wrapped(yu, box[1])
    z = _wrapped(zu, box[2])
    if x >= box[0] or y >= box[1] or z >= box[2]:
        return False  # -tiny + L rounded to L: skip this move
    if sorted_overlaps(k, x, y, z, r, radius, box, ncell, start, reach, same):
        return False
    r[k, 0] = xu
    r[k, 1] = yu
    r[k, 2] = zu
    return True


@jit(parallel=True)
def sorted_sweep(r, radius, box, ncell, start, step, key, dim):
    """One sweep of displacement moves r_k += step (2 u_k - 1) (as :func:`sweep`) over
    particles sorted by cell, on a grid (:func:`sorted_overlaps`) with reach = 2 R_max
    + step: the particles already moved in this sweep are less than ``step`` from
    where they were filed, so they are still found. Until the end of the sweep a
    moved particle keeps its coordinates unwrapped (next to its cell, possibly
    outside the box), so that the periodic shift of its cell applies to it.

    Order: the slabs of cells (z layers in 3D, y rows in 2D; an even number of
    them, each >= 2 reach thick) of even index first, then those of odd index; in
    each slab the particles in their sorted order. The moves in one slab neither
    read nor write what the moves in another slab of the same parity do (a scan
    reaches into the two neighbouring slabs only, which do not move meanwhile),
    so the slabs of a parity run in parallel threads and the result is the same
    for any number of threads. Returns the accepted count.
    """
    rmin, reach = _radius_range(radius)
    same = rmin == reach
    reach = (2.0 * reach + step) * (1.0 + 1e-9)  # (+ rounding margin)
    if ncell[2] > 1:
        slabs = ncell[2]
        per_slab = ncell[0] * ncell[1]
    else:
        slabs = ncell[1]
        per_slab = ncell[0]
    accepted = 0
    for parity in range(2):
        for h in numba.prange(slabs // 2):
            slab = 2 * h + parity
            for k in range(start[slab * per_slab], start[(slab + 1) * per_slab]):
                if _sorted_move(k, r, radius, box, ncell, start, step, key, dim, reach, same):
                    accepted += 1
    for k in range(r.shape[0]):  # (the same wrap as at the move)
        r[k, 0] = _wrapped(r[k, 0], box[0])
        r[k, 1] = _wrapped(r[k, 1], box[1])
        r[k, 2] = _wrapped(r[k, 2], box[2])
    return accepted


@jit(parallel=True)
def sorted_overlapping(r, radius, box, ncell, start, flags):
    """flags[k] = particle k overlaps some other one, for particles sorted by cell
    (:func:`sort_by_cell`, positions as filed) on a grid of :func:`sorted_overlaps`
    with reach 2 R_max; returns the number of overlapping particles."""
    rmin, reach = _radius_range(radius)
    same = rmin == reach
    reach = 2.0 * reach * (1.0 + 1e-9)  # (+ rounding margin)
    count = 0
    for k in numba.prange(r.shape[0]):
        hit = sorted_overlaps(k, r[k, 0], r[k, 1], r[k, 2], r, radius, box, ncell, start, reach, same)
        flags[k] = hit
        if hit:
            count += 1
    return count


@inlined
def _row_push(k, x, y, z, rk, a, b, r, radius, margin, far, near, nn, px, py, pz, same):
    cap = near.shape[0]
    s = 2.0 * rk
    for j in range(a, b):
        dx = x - r[j, 0]
        dy = y - r[j, 1]
        dz = z - r[j, 2]
        d2 = dx * dx + dy * dy + dz * dz
        if not same:
            s = rk + radius[j]
        if d2 < s * s and d2 > 0.0 and j != k:
            dd = d2**0.5
            f = (0.5 * (s - dd) + margin * s) / dd
            px += f * dx
            py += f * dy
            pz += f * dz
        if nn < cap:  # stored unconditionally, kept if within s + far (no branch)
            near[nn] = j
        nn += (d2 < (s + far) * (s + far)) & (j != k)
    return nn, px, py, pz


@jit
def sorted_scan(k, x, y, z, r, radius, box, ncell, start, reach, margin, far, near, same):
    """Overlap push of particle k at (x, y, z) (in the box) and its neighbours, for
    particles sorted by cell (:func:`sort_by_cell`; scan as :func:`sorted_overlaps`,
    over every particle filed within ``reach`` of the point).

    Returns (nn, px, py, pz): the push sum_j [(R_k + R_j - d)/2 + margin (R_k + R_j)]
    n_kj over the overlaps, and the number nn of particles j within R_k + R_j +
    ``far``, whose indices go to near[:nn] (entries beyond the buffer are counted,
    not stored). ``same``: all radii equal.
    """
    nx = ncell[0]
    ny = ncell[1]
    nz = ncell[2]
    ly, lz, mz, a1, b1, a2, b2, sx2 = _scan_window(x, y, z, box, ncell, reach)
    rk = radius[k]
    nn = 0
    px = 0.0
    py = 0.0
    pz = 0.0
    for oz in range(mz):
        kz, zz = _periodic_row(lz + oz, nz, z, box[2])
        for oy in range(2):
            ky, yy = _periodic_row(ly + oy, ny, y, box[1])
            row = nx * (ky + ny * kz)
            nn, px, py, pz = _row_push(k, x, yy, zz, rk, start[row + a1], start[row + b1], r, radius, margin,
                                       far, near, nn, px, py, pz, same)
            nn, px, py, pz = _row_push(k, x - sx2, yy, zz, rk, start[row + a2], start[row + b2], r, radius,
                                       margin, far, near, nn, px, py, pz, same)
    return nn, px, py, pz


@jit
def group_by_slab(idx, filed, ncell, grouped, slab_start):
    """The entries of idx grouped by the slab of their cell (z layers in 3D, y rows in
    2D; stable counting sort) into grouped; slab_start (slabs + 1,) the offsets."""
    per_slab = ncell[0] * ncell[1] if ncell[2] > 1 else ncell[0]
    slab_start[:] = 0
    for q in range(idx.shape[0]):
        slab_start[filed[idx[q]] // per_slab + 1] += 1
    for h in range(1, slab_start.shape[0]):
        slab_start[h] += slab_start[h - 1]
    for q in range(idx.shape[0]):
        h = filed[idx[q]] // per_slab
        grouped[slab_start[h]] = idx[q]
        slab_start[h] += 1
    for h in range(slab_start.shape[0] - 1, 0, -1):
        slab_start[h] = slab_start[h - 1]
    slab_start[0] = 0


@jit(parallel=True)
def sorted_push(idx, slab_start, r, radius, box, ncell, start, filed, cap, kick, margin, out, out_n):
    """Push each particle of ``idx`` out of its overlaps (as :func:`push_some`), for
    particles sorted by cell (:func:`sort_by_cell`, which files particle k in cell
    filed[k]) on a grid of :func:`sorted_overlaps` with reach 2 R_max + cap.

    A pushed particle keeps its coordinates unwrapped (next to the cell it is filed
    in) and stays within ``cap`` of that cell on every axis: a push that would take
    it further is shortened (same direction) to end there. Every particle thus lies
    within cap of its cell, and every particle within 2 R_max of a point within the
    box is among those a scan with reach 2 R_max + cap reads. New overlaps after
    the push are looked up among the particles the first scan found within
    R_k + R_j + R_k when the push is shorter than R_k, else by a second scan.

    ``idx`` is grouped by slab (:func:`group_by_slab`, offsets slab_start): the
    slabs of even index are pushed first, then those of odd index, each slab in
    its order in idx, the slabs of one parity in parallel threads (as
    :func:`sorted_sweep`: a particle stays within cap of its slab, so its scan
    reads its own slab and the two next to it, which do not move meanwhile); the
    result is the same for any number of threads. The particles still involved in
    overlaps after the pushes of slab h (with repetitions) are written to
    out[40 a:], a = slab_start[h], their number to out_n[h]. Returns the number of
    shortened pushes.
    """
    rmin, rmax = _radius_range(radius)
    same = rmin == rmax
    reach = (2.0 * rmax + cap) * (1.0 + 1e-9)  # (+ rounding margin)
    slabs = slab_start.shape[0] - 1
    clamped = 0
    for parity in range(2):
        for h in numba.prange(slabs // 2):
            slab = 2 * h + parity
            a = slab_start[slab]
            b = slab_start[slab + 1]
            if b > a:
                near = np.empty(256, dtype=np.int64)
                m, c = _push_run(idx, a, b, r, radius, box, ncell, start, filed, cap, kick, margin, near, out,
                                 40 * a, 40 * b, same, reach)
                out_n[slab] = m - 40 * a
                clamped += c
            else:
                out_n[slab] = 0
    return clamped


@jit
def sorted_push_serial(idx, slab_start, r, radius, box, ncell, start, filed, cap, kick, margin, out, out_n):
    """:func:`sorted_push` on one thread, in the same order (the same result): for passes
    over a few particles, where starting threads would cost more than it saves."""
    rmin, rmax = _radius_range(radius)
    same = rmin == rmax
    reach = (2.0 * rmax + cap) * (1.0 + 1e-9)  # (+ rounding margin)
    slabs = slab_start.shape[0] - 1
    near = np.empty(256, dtype=np.int64)
    clamped = 0
    for parity in range(2):
        for h in range(slabs // 2):
            slab = 2 * h + parity
            a = slab_start[slab]
            b = slab_start[slab + 1]
            m, c = _push_run(idx, a, b, r, radius, box, ncell, start, filed, cap, kick, margin, near, out,
                             40 * a, 40 * b, same, reach)
            out_n[slab] = m - 40 * a
            clamped += c
    return clamped


@jit
def _push_run(idx, qa, qb, r, radius, box, ncell, start, filed, cap, kick, margin, near, out, m, mend, same,
              reach):
    """Pushes of idx[qa:qb] (:func:`sorted_push`), writing to out[m:mend]; returns (the
    new end of out, the number of shortened pushes)."""
    nx = ncell[0]
    ny = ncell[1]
    wx = box[0] / nx
    wy = box[1] / ny
    wz = box[2] / ncell[2]
    cap_near = near.shape[0]
    clamped = 0
    for q in range(qa, qb):
        k = idx[q]
        x = _in_box(r[k, 0], box[0])
        y = _in_box(r[k, 1], box[1])
        z = _in_box(r[k, 2], box[2])
        rk = radius[k]
        nn, px, py, pz = sorted_scan(k, x, y, z, r, radius, box, ncell, start, reach, margin, rk, near, same)
        if px == 0.0 and py == 0.0 and pz == 0.0:
            continue
        px *= kick[q]
        py *= kick[q]
        pz *= kick[q]
        c = filed[k]
        cx = c % nx
        cy = (c // nx) % ny
        cz = c // (nx * ny)
        t = 1.0
        t = _clamp(t, r[k, 0], px, cx * wx - cap, (cx + 1) * wx + cap)
        t = _clamp(t, r[k, 1], py, cy * wy - cap, (cy + 1) * wy + cap)
        if ncell[2] > 1:
            t = _clamp(t, r[k, 2], pz, cz * wz - cap, (cz + 1) * wz + cap)
        if t < 1.0:
            clamped += 1
            px *= t
            py *= t
            pz *= t
        r[k, 0] += px
        r[k, 1] += py
        r[k, 2] += pz
        m0 = m
        if nn <= cap_near and px * px + py * py + pz * pz < rk * rk:
            for e in range(nn):
                j = near[e]
                dx = min_image(r[k, 0] - r[j, 0], box[0])
                dy = min_image(r[k, 1] - r[j, 1], box[1])
                dz = min_image(r[k, 2] - r[j, 2], box[2])
                s = rk + radius[j]
                if dx * dx + dy * dy + dz * dz < s * s and m < mend:
                    out[m] = j
                    m += 1
        else:
            x = _in_box(r[k, 0], box[0])
            y = _in_box(r[k, 1], box[1])
            z = _in_box(r[k, 2], box[2])
            nn, px, py, pz = sorted_scan(k, x, y, z, r, radius, box, ncell, start, reach, 0.0, 0.0, near, same)
            for e in range(min(nn, cap_near)):
                if m < mend:
                    out[m] = near[e]
                    m += 1
            if nn > cap_near and m == m0 and m < mend:  # partners not all stored: list k
                out[m] = k
                m += 1
                continue
        if m > m0 and m < mend:
            out[m] = k
            m += 1
    return m, clamped


@jit
def distinct_runs(values, bases, counts, seen, out):
    """Distinct entries of the runs values[bases[h]:bases[h] + counts[h]] (in order) into
    out (first-occurrence order); returns their number. ``seen`` as in :func:`distinct`."""
    u = 0
    for h in range(counts.shape[0]):
        u = _first_seen(values, bases[h], bases[h] + counts[h], seen, out, u)
    return _unmark(seen, out, u)


@inlined
def _clamp(t, x, p, lo, hi):
    """Largest t' in [0, t] with x + t' p within [lo, hi] (x within it; 0 if x lies
    beyond by rounding and p points further out)."""
    if p > 0.0 and x + t * p > hi:
        return max(0.0, (hi - x) / p)
    if p < 0.0 and x + t * p < lo:
        return max(0.0, (lo - x) / p)
    return t
