"""Lees-Edwards boundaries: uniform shear flow in the event-driven engine (numba leaf module).

The flow is along x (axis 0), the gradient along y (axis 1), at the rate a > 0
(Lees & Edwards 1972). The box's images are periodic along x and z; the image k boxes
up (k = +-1) sits at x + k delta(t) and moves with v_x + k a L_y,

    delta(t) = a L_y t  (mod L_x),                                                 (1)

so that a particle that leaves through y = L_y re-enters at y - L_y with
x - delta(t) and v_x - a L_y (and the reverse at y = 0): :func:`le_wrap`. Particles
fly on straight lines in the laboratory frame, whose streaming velocity
u(y) = a (y - L_y/2) the images carry; the peculiar velocity is c = v - u(y) x.
A pair's nearest image (:func:`le_pair_delay`, :func:`le_separation`): k =
round((y_i - y_j)/L_y), dy -= k L_y, dx -= k delta(t), du_x -= k a L_y, then the x
minimum image; the pair's relative motion in that image is straight, so its collision
time is the engine's root (:func:`granulargas.engine._geometry.collision_delay`).

Space holds the sheared axis with period inf (the plain streaming and minimum image
leave y alone: :func:`granulargas.engine._loop.stream`); this module wraps y where a
neighbour search needs the particle inside the box: at a list expiry and at a cell
crossing through the sheared boundary, and in :func:`synchronised_le`. Inside the
compiled state y is stored shifted by + L_y (the box spans [L_y, 2 L_y)), so that a
particle that has left the box, and is not yet wrapped, never has a negative
coordinate (which the plain streaming would wrap by the period).

Image counters: the unwrapped position of a particle is
``x + img_x L_x + img_y a L_y t`` along x (the image shift of (1) without the
reduction mod L_x), ``y + img_y L_y``, ``z + img_z L_z``: :func:`le_wrap` keeps it
continuous.

Neighbour search: sliding rows
------------------------------
A cell grid fixed in the laboratory would see every particle stream through it at
u(y), up to a L_y / 2: the events would grow with the box. Instead each row of cells
(the cells with the same y index r, height w_y) slides along x with the streaming
velocity of its middle,

    u_r = a ((r + 1/2) w_y - L_y/2),    s_r(t) = u_r t (mod L_x),                   (2)

and a particle's x cell is counted in its row's frame, x - s_r(t). Rows r and r + 1
slide past each other at a w_y, also across the sheared boundary: the image of row 0
one box up is the row r = n_y with s_(n_y) = s_0 + a L_y t, eq. (1). Within a row the
particles move at their peculiar velocity plus at most a w_y / 2.

*Neighbour lists* (:func:`rebuild_list_le`, :func:`predict_expiry_le`). A particle's
list centre moves with its row: it is stored as (x - s_r(t_b), y, z) in float32, r the
row of y, t_b the time of the list's build (``ShearGeometry.built``). Two centres in the
same row keep their distance; in adjacent rows their x separation changes at a w_y, in
the direction the rows slide (row r + 1 moves towards +x against row r); rows two apart
are farther than w_y >= R_i + R_j + shell along y, which the sliding leaves alone. With a
margin D (:func:`list_margin`) and the lifetime T = D / (a w_y), a build of i at t_b lists
every j whose centre (its image through the sheared boundary included) comes within
R_i + R_j + shell of c_i while their rows slide by up to D (:func:`slid`: for a j in an
adjacent row the x separation is shortened by up to D on the side the sliding closes),
and i's list expires at the first of

    |r_i(t) - c_i(t)| = shell/2,    t = t_b + T                                        (3)

(:func:`budget_delay` with r_i - c_i moving at v_i - u_r). Why no collision is missed:
let i and j not be in each other's lists; the later of their two builds, at t*, found
that their centres stay at least R_i + R_j + shell apart while the rows slide by D, that
is until t* + T; both lists expire by min(t_i, t_j) + T <= t* + T. Until then
|r_i - r_j| >= |c_i - c_j| - |r_i - c_i| - |r_j - c_j| >= R_i + R_j + shell - shell/2
- shell/2. Listed pairs are predicted exactly, and every velocity change re-predicts
against the whole list, as without shear. (A budget shared by both lists, |r_i - c_i| +
a w_y (t - t_b) / 2 = shell/2, needs no margin, but the particles then spend the budget
at their peculiar speed plus a w_y / 2: about 1.5 times as many expiries at the steady
shear rate of packing 0.1.) The search covers 3 columns of i's row and 4 of each adjacent
row (D <= 2 w_x - cut), times 3 along z, and skips the cells the slid cut-off cannot
reach. The full build dates the lists back by up to T / 2 (spread over the particles), so
that they do not all end in one calendar window.

*Cell crossings* (:func:`predict_pair_cells_le`, :func:`cross_le`,
:func:`slide_scan`). Cells are at least 2 R_max (1 + 1e-6) wide, every particle sits
in the cell of its position in its row's frame, and a crossing of an x face (relative
velocity v_x - u_r), of a y face (into the next row, or through the sheared boundary,
re-counted in that row's frame) or of a z face is an event. Let phi = a w_y t mod L_x
= m w_x + f (0 <= f < w_x): the x offset of row r + 1 against row r. A point within
w_x of cell x of row r lies, in row r + 1's frame, in the 4 cells x - 2 - m .. x + 1 - m,
and in row r - 1's frame in x - 1 + m .. x + 2 + m, for every f in [0, w_x): so each
particle's neighbourhood is 3 cells of its own row and 4 of each adjacent row (times 3
along z), fixed while m is. m steps at the *slides*, t_k = k w_x / (a w_y), global
events (:func:`slide_scan`): each particle scans the one new column of its upper
window, and keeps the earlier of what it finds and its event (and its stored best pair,
if current). The two windows are mirror images (j in the upper window of i iff i is in
the lower window of j), so the lower particle of every pair that a slide makes adjacent
scans it. The completeness argument of :mod:`granulargas.engine._crossing` then holds
as it is, with "the last prediction of either" ranging over full scans, crossings and
slides, each scanning the cells that became adjacent (at the present m): an x crossing
1 column in each of the three rows; a z crossing the new layer of 11 columns; a y
crossing (:func:`_y_layer`) from column x of row r into row r + 1 lands in column
x - m - 1 or x - m of that row's frame (the point is within w_x of its old cell, eq. 2),
whose 3 own columns lay in the old upper window x - 2 - m .. x + 1 - m, and row r's new
lower window (x - 2 .. x + 1 or x - 1 .. x + 2) differs from the old own columns
x - 1 .. x + 1 by one column: the scan is the 4 columns of row r + 2 and that one
(mirrored for a crossing down; 15 cells instead of both windows' 24). It subtracts the
runs of columns as integers, so a landing column off by one at round-off only scans
more. The cells it leaves out were adjacent before the crossing, and the argument goes
back one prediction, as for the other faces.
"""

import math
from collections import namedtuple

import numpy as np

from granulargas._numba import inlined, inlined_ir, kernel
from granulargas.engine._calendar import cal_update
from granulargas.engine._cells import CELL_OVERFLOW, OVERFLOW, PREFETCH_CENTRES_FROM, slot_insert, slot_remove
from granulargas.engine._crossing import (
    NEXT,
    PAIR_J,
    PAIR_TAG,
    _scan_listed,
    earlier_face,
    face_gap,
    grid_insert,
    grid_remove,
)
from granulargas.engine._flight import stream
from granulargas.engine._geometry import collision_delay, min_image
from granulargas.engine._prefetch import prefetch

#: The sheared geometry and its mutable scalars (``Space.shear``; None without shear):
#: ``rate`` a > 0, box sides ``lx``, ``ly``, cell sides ``wx``, ``wy`` and counts ``nx``,
#: ``ny`` (the list-centre grid in the list mode, the crossing grid in the cell mode),
#: ``speed`` = a L_y (the image velocity), ``margin`` D and ``lifetime`` D / (a w_y) of the
#: lists (list mode, eq. 3; 0 and inf otherwise), ``slide_time``
#: = w_x / (a w_y) (cell mode: time between slides), ``slide`` (2,) i8 the index k of the
#: last slide and m = k mod n_x (kept, so that the scans need no integer division),
#: ``built`` (N,) f8 the build time of each particle's list (list mode; (1,) otherwise), ``thermostat`` (2,) f8: interval and temperature of the
#: velocity rescaling (interval inf: none), ``rescales`` (1,) i8 the index of the next one.
ShearGeometry = namedtuple("ShearGeometry", ["rate", "lx", "ly", "wx", "wy", "nx", "ny", "speed", "margin",
                                             "lifetime", "slide_time", "slide", "built", "thermostat", "rescales"])

#: Pressure-tensor accumulators (a (1,) record, ``Engine.stress``; None when not asked for):
#: ``s`` the kinetic sums sum m c_a c_b now (xx, yy, zz, xy, xz, yz), ``k`` their time
#: integrals and ``w`` the collisional sums sum r_ij,a Delta p_i,b, both since the last reset.
STRESS = np.dtype([("s", "f8", (6,)), ("k", "f8", (6,)), ("w", "f8", (6,))], align=True)

XX, YY, ZZ, XY, XZ, YZ = 0, 1, 2, 3, 4, 5

#: The lists' sliding margin D in shells (eq. 3): a wider margin lists more pairs of
#: adjacent rows, a narrower one ends lists sooner (lifetime D / (a w_y)). In the gas of
#: ``scripts/benchmarks/shear.py`` (N = 10^4, packing 0.1, the periodic shell 1.47, this
#: constant set before the ``Simulation`` is built) 0.5 and 1 cost within 2 % of each other
#: (2.7 and 2.2 list expiries per collision, lists of 12.8 and 13.9), 1.5 some 5 % more. The
#: default shell of a sheared gas counts the margin
#: (:func:`granulargas.engine.simulation.sheared_shell`).
MARGIN = 1.0


def list_margin(shell, cut, wx, lx):
    """The sliding margin D of the lists (eq. 3): :data:`MARGIN` shells, at most what the five
    columns of an adjacent row reach, 2 w_x - cut (cut = 2 R_max + shell), and L_x / 2 - cut
    (so that a pair's other x image stays beyond the cut-off)."""
    return min(MARGIN * shell, (min(2.0 * wx, 0.5 * lx) - cut) * (1.0 - 1e-9))


def shear_geometry(rate, box3, ncell, n, thermostat_interval=math.inf, thermostat_temperature=1.0,
                   slide=0, rescales=0, lists=True, shell=0.0, cut=0.0):
    """A :class:`ShearGeometry` with the dtypes the kernels are compiled for (``shell``, ``cut``:
    the list shell and 2 R_max + shell, list mode)."""
    lx, ly = float(box3[0]), float(box3[1])
    nx, ny = int(ncell[0]), int(ncell[1])
    wx, wy = lx / nx, ly / ny
    a = float(rate)
    margin = list_margin(float(shell), float(cut), wx, lx) if lists else 0.0
    lifetime = margin / (a * wy) if lists else math.inf
    return ShearGeometry(a, lx, ly, wx, wy, nx, ny, a * ly, margin, lifetime, wx / (a * wy),
                         np.array([slide, slide % nx], dtype=np.int64),
                         np.zeros(n if lists else 1), np.array([thermostat_interval, thermostat_temperature]),
                         np.array([rescales], dtype=np.int64))


# ------------------------------------------------------------------ frames and images
@inlined
def _reduce(x, length):
    """x mod length in [0, length)."""
    r = x - length * math.floor(x / length)
    return r if r < length else 0.0


@inlined
def image_offset(t, sh):
    """delta(t) of eq. (1), reduced into [-L_x/2, L_x/2) (a single minimum-image step
    then suffices for near pairs)."""
    d = _reduce(sh.speed * t, sh.lx)
    return d - sh.lx if d >= 0.5 * sh.lx else d


@inlined
def row_speed(rho, sh):
    """u_rho of eq. (2) (rho may be -1 or n_y: the images of the boundary rows)."""
    return sh.rate * ((rho + 0.5) * sh.wy - 0.5 * sh.ly)


@inlined
def row_offset(rho, t, sh):
    """s_rho(t) of eq. (2), in [0, L_x)."""
    return _reduce(row_speed(rho, sh) * t, sh.lx)


@inlined
def row_of(y, sh):
    r = int(y * (sh.ny / sh.ly))
    if r >= sh.ny:
        return sh.ny - 1
    if r < 0:
        return 0
    return r


@inlined
def col_of(xi, sh):
    c = int(xi * (sh.nx / sh.lx))
    if c >= sh.nx:
        return sh.nx - 1
    if c < 0:
        return 0
    return c


@inlined
def _wrap(c, n):
    if c < 0:
        return c + n
    if c >= n:
        return c - n
    return c


@inlined
def _wrap_far(c, n):
    """c mod n without an integer division, for the column runs of the cell scans, which
    start at most a few n_x outside [0, n_x)."""
    while c < 0:
        c += n
    while c >= n:
        c -= n
    return c


@inlined
def interior_row(r, sh):
    """Row r is not next to the sheared boundary and the box has at least 7 rows: every
    neighbour of a particle (list mode: of a list centre) in row r lies in rows r - 1 .. r + 1
    of the box, less than 3 w_y + round-off < L_y / 2 away along y, so its nearest image is
    k = 0 and the pair times are those of the periodic box."""
    return sh.ny >= 7 and 1 <= r <= sh.ny - 2


@inlined
def le_shift(i, t, rec, img, sh, up):
    """Move particle i (at time t) one image down (``up``: it left through y = L_y) or up
    (it left through y = 0): y -+ L_y, x -+ delta(t), v_x -+ a L_y, eq. (1); the image
    counters keep the unwrapped position continuous. Returns the change of v^2."""
    shift = sh.speed * t
    q = np.int32(math.floor(shift / sh.lx))
    d = shift - q * sh.lx
    v0 = rec[i, 3]
    if up:
        y = rec[i, 1] - sh.ly
        x = rec[i, 0] - d
        img[i, 0] -= q
        img[i, 1] += 1
        rec[i, 3] = v0 - sh.speed
    else:
        y = rec[i, 1] + sh.ly
        x = rec[i, 0] + d
        img[i, 0] += q
        img[i, 1] -= 1
        rec[i, 3] = v0 + sh.speed
    if x >= sh.lx:
        x -= sh.lx
        img[i, 0] += 1
    elif x < 0.0:
        x += sh.lx
        img[i, 0] -= 1
        if x >= sh.lx:  # -tiny + L rounds to L
            x = 0.0
            img[i, 0] += 1
    rec[i, 0] = x
    rec[i, 1] = y
    return rec[i, 3] * rec[i, 3] - v0 * v0


@inlined
def le_wrap(i, t, rec, img, sh):
    """Particle i (at time t) into [0, L_y) through the sheared boundary (:func:`le_shift`),
    if it is outside. Returns the change of v^2."""
    y = rec[i, 1]  # stored + L_y
    if y >= 2.0 * sh.ly:
        return le_shift(i, t, rec, img, sh, True)
    if y < sh.ly:
        dv2 = le_shift(i, t, rec, img, sh, False)
        if rec[i, 1] >= 2.0 * sh.ly:  # -tiny + L rounds to L
            rec[i, 1] = sh.ly
        return dv2
    return 0.0


@inlined
def le_pair_delay(j, t, xi, yi, zi, vx, vy, vz, ri, rec, period, sh, dlt):
    """Time from t until particle i (centre (xi, yi, zi) at t, velocity v, radius ri) touches
    particle j through j's nearest Lees-Edwards image (``dlt`` = :func:`image_offset` at t)."""
    dtj = t - rec[j, 6]
    dy = yi - (rec[j, 1] + rec[j, 4] * dtj)
    half = 0.5 * sh.ly
    k = (1.0 if dy > half else 0.0) - (1.0 if dy < -half else 0.0)
    return collision_delay(min_image(xi - (rec[j, 0] + rec[j, 3] * dtj) - k * dlt, period[0]),
                           dy - k * sh.ly,
                           min_image(zi - (rec[j, 2] + rec[j, 5] * dtj), period[2]),
                           vx - rec[j, 3] - k * sh.speed, vy - rec[j, 4], vz - rec[j, 5], ri + rec[j, 7])


@inlined
def le_separation(i, j, t, rec, period, sh):
    """(dx, dy, dz, ux, uy, uz): r_i - r_j and v_i - v_j through j's nearest image at t
    (both particles at t)."""
    dlt = image_offset(t, sh)
    dy = rec[i, 1] - rec[j, 1]
    half = 0.5 * sh.ly
    k = (1.0 if dy > half else 0.0) - (1.0 if dy < -half else 0.0)
    return (min_image(rec[i, 0] - rec[j, 0] - k * dlt, period[0]), dy - k * sh.ly,
            min_image(rec[i, 2] - rec[j, 2], period[2]),
            rec[i, 3] - rec[j, 3] - k * sh.speed, rec[i, 4] - rec[j, 4], rec[i, 5] - rec[j, 5])


# ------------------------------------------------------------------ neighbour lists
@inlined
def budget_delay(dx, dy, dz, wx, wy, wz, h, kappa):
    """Smallest s >= 0 with |d + w s| + kappa s = h (eq. 3 with h = shell/2 - kappa (t - t_b)):
    0 if |d| >= h. Squared: (w^2 - kappa^2) s^2 + 2 (d.w + h kappa) s + (d^2 - h^2) = 0,
    whose root of interest is -C / (B + sqrt(B^2 - A C)) (C < 0, B > 0 whenever
    |w| < kappa; the cancellation-free form)."""
    d2 = dx * dx + dy * dy + dz * dz
    if h <= 0.0 or d2 >= h * h:
        return 0.0
    a = wx * wx + wy * wy + wz * wz - kappa * kappa
    b = dx * wx + dy * wy + dz * wz + h * kappa
    c = d2 - h * h
    disc = b * b - a * c
    root = math.sqrt(disc if disc > 0.0 else 0.0)
    den = b + root
    if den <= 0.0:
        return math.inf if a >= 0.0 and b <= 0.0 and kappa == 0.0 else 0.0
    return -c / den


@inlined
def predict_expiry_le(i, t, rec, centre, period, half_shell, sh):
    """Time of i's list expiry, eq. (3) (i streamed to t; its y not wrapped since the build)."""
    r = row_of(np.float64(centre[i, 1]), sh)
    xc = np.float64(centre[i, 0]) + row_offset(r, t, sh)
    xc = xc - sh.lx if xc >= sh.lx else xc
    s = budget_delay(min_image(rec[i, 0] - xc, period[0]), rec[i, 1] - sh.ly - np.float64(centre[i, 1]),
                     min_image(rec[i, 2] - np.float64(centre[i, 2]), period[2]),
                     rec[i, 3] - row_speed(r, sh), rec[i, 4], rec[i, 5], half_shell, 0.0)
    end = sh.built[i] + sh.lifetime
    return min(t + s, end if end > t else t)


@inlined
def predict_pair_le(i, t, before, rec, nbl, nbn, period, sh):
    """:func:`granulargas.engine._loop.predict_pair` through the Lees-Edwards images."""
    xi = rec[i, 0]
    yi = rec[i, 1]
    zi = rec[i, 2]
    vx = rec[i, 3]
    vy = rec[i, 4]
    vz = rec[i, 5]
    ri = rec[i, 7]
    dlt = image_offset(t, sh)
    best = before
    p = -1
    for k in range(nbn[i]):
        j = nbl[i, k]
        tc = t + le_pair_delay(j, t, xi, yi, zi, vx, vy, vz, ri, rec, period, sh, dlt)
        better = tc < best
        best = tc if better else best
        p = j if better else p
    return best, p


@inlined
def slid(dx, o, margin):
    """The x separation x_i - x_j (frame of j's row) closest to 0 that the pair's centres reach
    while row r + o slides by up to ``margin`` against row r of i (eq. 3): row r + 1 moves
    towards +x, so a j above that is ahead of i (dx < 0) only moves away; one behind
    (dx > 0) comes up to margin nearer. Row r - 1 the mirror image; the own row not at all."""
    if o == 0:
        return dx
    u = dx if o > 0 else -dx
    return u - min(max(u, 0.0), margin)


@inlined
def _columns(c0, o, nx):
    """First column (unwrapped) and number of the columns around column c0 (of the query
    point) that a list search scans: 3 in its own row (o = 0); in row r + o the 4 that reach
    from cut behind to cut + D ahead of the sliding (margin D <= 2 w_x - cut), or all of a
    row of 3 columns (no cell twice)."""
    if o == 0:
        return c0 - 1, 3
    if nx < 4:
        return 0, nx
    return (c0 - 2 if o > 0 else c0 - 1), 4


@inlined
def _gap(x, lo, w):
    """Distance from x to the interval [lo, lo + w) (0 inside)."""
    if x < lo:
        return lo - x
    if x > lo + w:
        return x - lo - w
    return 0.0


@inlined
def _centre_cell(centre, i, sh, ncell, box):
    """Flat cell of the stored centre of i: (x in its row's frame, row, z)."""
    cz = int(np.float64(centre[i, 2]) * (ncell[2] / box[2]))
    cz = min(max(cz, 0), ncell[2] - 1)
    return col_of(np.float64(centre[i, 0]), sh) + ncell[0] * (row_of(np.float64(centre[i, 1]), sh)
                                                            + ncell[1] * cz)


@inlined
def row_step(t, sh):
    """phi = a w_y t mod L_x in [0, L_x): s_(r+1)(t) - s_r(t) (mod L_x) for every row r, the
    image of row 0 above the box (r + 1 = n_y) included (eq. 2 is linear in r)."""
    return _reduce(sh.rate * sh.wy * t, sh.lx)


@inlined
def _sq_gap(g):
    return g * g if g > 0.0 else 0.0


@inlined
def _row_columns(xr, o, sh):
    """The columns of row r + o that a list search scans around the query point ``xr`` (in
    that row's frame): first column (unwrapped) and the squared x gaps of up to 4
    columns, inf for a column not scanned. Own row (o = 0): 3 columns; row r + 1: the 4
    from cut behind to cut + D ahead (the two behind come D nearer while the rows slide,
    :func:`slid`), row r - 1 the mirror image; a row of 3 columns whole, once."""
    w = sh.wx
    c0 = col_of(xr, sh)
    lo = xr - c0 * w
    hi = (c0 + 1) * w - xr
    if o == 0:
        return c0 - 1, _sq_gap(lo), 0.0, _sq_gap(hi), math.inf
    if sh.nx < 4:
        return 0, 0.0, 0.0, 0.0, math.inf
    d = sh.margin
    if o > 0:
        return c0 - 2, _sq_gap(lo + w - d), _sq_gap(lo - d), 0.0, _sq_gap(hi)
    return c0 - 1, _sq_gap(lo), 0.0, _sq_gap(hi - d), _sq_gap(hi + w - d)


@inlined
def _col_entry(k, nx):
    """Wrapped column of unwrapped column k and its code 3 (x shift + 1) (stencil entries)."""
    if k < 0:
        return k + nx, 0
    if k >= nx:
        return k - nx, 6
    return k, 3


@inlined_ir
def collect_le(i, xo, yq, zq, r, phi, ri, rmax, m, shell, rec, lists, cells, space, sh):
    """Particles j != i whose centre (through the sheared images) comes within R_i + R_j +
    shell of the query point ((xo, yq, zq): x in the frame of its row r; ``phi`` =
    :func:`row_step` at the present time) while the rows slide by the margin D
    (:func:`slid`, eq. 3), into ``lists.scratch``: 3 columns of its own row and 4 of rows
    r - 1 and r + 1 (in their frames), times 3 along z (none beyond a wall on z). Returns
    the number, or -1 if more than m or the scratch is short.

    Passes, as :func:`granulargas.engine._cells._collect`: (1) the cells the slid cut-off can
    reach into ``lists.stencil`` (cell, row, and the periodic shifts of its column and
    layer), branch-free (every cell written, the count advancing on a reach), then each
    cell's row of ids prefetched; (2) a prefetch of every candidate's centre (large
    systems); (3) the branch-free distance tests, with the query point shifted by the
    cell's periodic offset (no minimum image: a scanned column or layer is the nearest
    image when the row has at least 6 columns and z at least 4 layers, or none to wrap;
    otherwise the minimum image is taken); (4) the hits compacted, with the exact cut-off
    for partners smaller than R_max."""
    scratch = lists.scratch
    stencil = lists.stencil
    centre = lists.centre
    cell_ids = cells.ids
    cell_n = cells.n
    ncell = space.ncell
    box = space.box
    period = space.period
    cap = scratch.shape[0]
    cut_max = ri + rmax + shell
    cut_max2 = cut_max * cut_max
    cz = int(zq * (ncell[2] / box[2]))
    cz = min(max(cz, 0), ncell[2] - 1)
    zr = 1 if ncell[2] >= 3 else 0
    shifted = sh.nx >= 6 and (ncell[2] >= 4 or period[2] == math.inf or space.dims == 2)
    # cells the cut-off (slid by the margin along x) cannot reach are skipped, as in
    # granulargas.engine._cells._reach, with its round-off margin
    wz = box[2] / ncell[2]
    lim = cut_max * (1.0 + 1e-9) + 1e-12 * (sh.lx + sh.ly + box[2])
    lim2 = lim * lim
    # the query point in the frames of rows r - 1 and r + 1 (x: s_(r+-1) = s_r +- phi) and
    # through the sheared boundary (y)
    xp = xo - phi
    xp = xp + sh.lx if xp < 0.0 else xp
    xm = xo + phi
    xm = xm - sh.lx if xm >= sh.lx else xm
    ym = yq + (sh.ly if r - 1 < 0 else 0.0)
    yp = yq - (sh.ly if r + 1 >= sh.ny else 0.0)
    # z layers: squared gaps, wrapped layer offsets and codes 9 (z shift + 1); none beyond a wall
    nxy = ncell[0] * ncell[1]
    zwall = period[2] == math.inf
    gzl = _sq_gap(zq - cz * wz)
    gzh = _sq_gap((cz + 1) * wz - zq)
    gzl = math.inf if zwall and cz == 0 else gzl
    gzh = math.inf if zwall and cz == ncell[2] - 1 else gzh
    kzl = nxy * (cz - 1 + (ncell[2] if cz == 0 else 0))
    kzh = nxy * (cz + 1 - (ncell[2] if cz == ncell[2] - 1 else 0))
    czl = 9 if cz > 0 else 0
    czh = 9 if cz < ncell[2] - 1 else 18
    ns = 0
    for o in range(-1, 2):
        rho = r + o
        g = _wrap(rho, sh.ny)
        ys = ym if o < 0 else (yp if o > 0 else yq)
        gy = _gap(ys, g * sh.wy, sh.wy)
        gy2 = gy * gy
        xr = xm if o < 0 else (xp if o > 0 else xo)
        x0, g0, g1, g2, g3 = _row_columns(xr, o, sh)
        k0, s0 = _col_entry(x0, sh.nx)
        k1, s1 = _col_entry(x0 + 1, sh.nx)
        k2, s2 = _col_entry(x0 + 2, sh.nx)
        k3, s3 = _col_entry(x0 + 3, sh.nx)
        for oz in range(-zr, zr + 1):
            gz = gzl if oz < 0 else (gzh if oz > 0 else 0.0)
            kz = kzl if oz < 0 else (kzh if oz > 0 else nxy * cz)
            code = 32 * (kz + ncell[0] * g) + (o + 1) + (czl if oz < 0 else (czh if oz > 0 else 9))
            gyz = gy2 + gz
            stencil[ns] = code + 32 * k0 + s0
            ns += g0 + gyz < lim2
            stencil[ns] = code + 32 * k1 + s1
            ns += g1 + gyz < lim2
            stencil[ns] = code + 32 * k2 + s2
            ns += g2 + gyz < lim2
            stencil[ns] = code + 32 * k3 + s3
            ns += g3 + gyz < lim2
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
        o = code % 3 - 1
        ys = ym if o < 0 else (yp if o > 0 else yq)
        qx = xm if o < 0 else (xp if o > 0 else xo)
        qz = zq
        if shifted:
            qx -= ((code // 3) % 3 - 1) * sh.lx
            qz -= (code // 9 - 1) * box[2]
        sgn = -1.0 if o < 0 else 1.0
        mo = 0.0 if o == 0 else sh.margin
        nq = cell_n[c]
        if count + nq > cap:
            return -1
        for q in range(nq):
            j = cell_ids[c, q]
            dx = qx - centre[j, 0]
            dz = qz - centre[j, 2]
            if not shifted:
                dx = min_image(dx, sh.lx)
                dz = min_image(dz, period[2])
            u = sgn * dx
            dx = u - min(max(u, 0.0), mo)  # slid(), branch-free
            dy = ys - centre[j, 1]
            scratch[count] = j
            count += (dx * dx + dy * dy + dz * dz < cut_max2) & (j != i)
    found = 0
    for k in range(count):
        j = scratch[k]
        cut = ri + rec[j, 7] + shell
        if cut < cut_max:
            # the exact cut-off: the same distance again through the images
            g = row_of(np.float64(centre[j, 1]), sh)
            best = math.inf
            for o in range(-1, 2):
                rho = r + o
                if _wrap(rho, sh.ny) != g:
                    continue
                ys = ym if o < 0 else (yp if o > 0 else yq)
                xr = xm if o < 0 else (xp if o > 0 else xo)
                dx = slid(min_image(xr - centre[j, 0], sh.lx), o, sh.margin)
                dy = ys - centre[j, 1]
                dz = min_image(zq - centre[j, 2], period[2])
                best = min(best, dx * dx + dy * dy + dz * dz)
            if best >= cut * cut:
                continue
        if found >= m:
            return -1
        scratch[found] = j
        found += 1
    return found


@inlined_ir
def rebuild_list_le(i, t, rec, lists, cells, space, rmax, shell, sh):
    """:func:`granulargas.engine._cells.rebuild_list` with list centres that move with their
    rows (i at time t, inside [0, L_y)): new centre (x - s_r(t), y, z) in float32, its
    build time t, and the lists of the neighbours that join or leave. Returns 0, OVERFLOW
    or CELL_OVERFLOW (nothing changed)."""
    centre = lists.centre
    nbl = lists.nbl
    nbn = lists.nbn
    scratch = lists.scratch
    mark = lists.mark
    cell_ids = cells.ids
    cell_n = cells.n
    ncell = space.ncell
    was = _centre_cell(centre, i, sh, ncell, space.box)
    yq = np.float64(np.float32(rec[i, 1] - sh.ly))
    zq = np.float64(np.float32(rec[i, 2]))
    r = row_of(yq, sh)
    xi32 = np.float32(_reduce(rec[i, 0] - row_offset(r, t, sh), sh.lx))
    xi = np.float64(xi32)
    if xi >= sh.lx:
        xi = 0.0
        xi32 = np.float32(0.0)
    cz = int(zq * (ncell[2] / space.box[2]))
    cz = min(max(cz, 0), ncell[2] - 1)
    c = col_of(xi, sh) + ncell[0] * (r + ncell[1] * cz)
    if c != was and cell_n[c] >= cell_ids.shape[1]:
        return CELL_OVERFLOW
    m = nbl.shape[1]
    count = collect_le(i, xi, yq, zq, r, row_step(t, sh), rec[i, 7], rmax, m, shell, rec, lists, cells, space, sh)
    if count < 0:
        return OVERFLOW
    nold = nbn[i]
    for k in range(count):
        prefetch(nbl, scratch[k])
        prefetch(nbn, scratch[k])
    for k in range(nold):
        prefetch(nbl, nbl[i, k])
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
    centre[i, 0] = xi32
    centre[i, 1] = yq
    centre[i, 2] = zq
    sh.built[i] = t
    return 0


@kernel
def build_all_lists_le(t, rec, lists, cells, space, shell, sh):
    """Every particle's centre (in its row's frame, float32), the cells and all lists at time
    t (all particles inside [0, L_y)). Returns 0, CELL_OVERFLOW or OVERFLOW."""
    centre = lists.centre
    nbl = lists.nbl
    nbn = lists.nbn
    cell_ids = cells.ids
    cell_n = cells.n
    ncell = space.ncell
    period = space.period
    n = rec.shape[0]
    m = nbl.shape[1]
    zr = 1 if ncell[2] >= 3 else 0
    cell_n[:] = 0
    for i in range(n):
        yq = np.float32(rec[i, 1] - sh.ly)
        r = row_of(np.float64(yq), sh)
        xi = np.float32(_reduce(rec[i, 0] - row_offset(r, t, sh), sh.lx))
        if np.float64(xi) >= sh.lx:
            xi = np.float32(0.0)
        centre[i, 0] = xi
        centre[i, 1] = yq
        centre[i, 2] = rec[i, 2]
        c = _centre_cell(centre, i, sh, ncell, space.box)
        if cell_n[c] >= cell_ids.shape[1]:
            return CELL_OVERFLOW
        slot_insert(i, c, cell_ids, cell_n)
        # build times spread over half a lifetime before t (a list may be taken as older
        # than it is: it ends sooner), so that the lists built together do not all end at
        # t + lifetime in one calendar window
        sh.built[i] = t - 0.5 * sh.lifetime * ((i * 0.6180339887498949) % 1.0) if sh.lifetime < math.inf else t
    nbn[:] = 0
    for i in range(n):
        yq = np.float64(centre[i, 1])
        zq = np.float64(centre[i, 2])
        r = row_of(yq, sh)
        xq = _reduce(np.float64(centre[i, 0]) + row_offset(r, t, sh), sh.lx)
        cz = int(zq * (ncell[2] / space.box[2]))
        cz = min(max(cz, 0), ncell[2] - 1)
        for o in range(-1, 2):
            rho = r + o
            g = _wrap(rho, sh.ny)
            ys = yq - (sh.ly if rho >= sh.ny else (-sh.ly if rho < 0 else 0.0))
            xr = _reduce(xq - row_offset(rho, t, sh), sh.lx)
            c0 = col_of(xr, sh)
            x0, ncol = _columns(c0, o, sh.nx)
            for oz in range(-zr, zr + 1):
                kz = cz + oz
                if kz < 0 or kz >= ncell[2]:
                    if period[2] == math.inf:
                        continue
                    kz = _wrap(kz, ncell[2])
                for ox in range(ncol):
                    c = _wrap(x0 + ox, sh.nx) + ncell[0] * (g + ncell[1] * kz)
                    for q in range(cell_n[c]):
                        j = cell_ids[c, q]
                        if j <= i:
                            continue
                        dx = slid(min_image(xr - centre[j, 0], sh.lx), o, sh.margin)
                        dy = ys - centre[j, 1]
                        dz = min_image(zq - centre[j, 2], period[2])
                        cut = rec[i, 7] + rec[j, 7] + shell
                        if dx * dx + dy * dy + dz * dz < cut * cut:
                            if nbn[i] >= m or nbn[j] >= m:
                                return OVERFLOW
                            nbl[i, nbn[i]] = j
                            nbn[i] += 1
                            nbl[j, nbn[j]] = i
                            nbn[j] += 1
    return 0


# ------------------------------------------------------------------ cell crossings
@inlined
def predict_crossing_le(i, t, rec, grid, space, sh):
    """Earliest cell crossing of i (streamed to t): (time, face 2 a + side); x in the frame
    of i's row (relative velocity v_x - u_r), y through the sheared boundary (period L_y)."""
    cell = grid.cell
    r = cell[i, 1]
    gap, speed, side = face_gap(_reduce(rec[i, 0] - row_offset(r, t, sh), sh.lx), rec[i, 3] - row_speed(r, sh),
                                cell[i, 0], grid.width[0], space.ncell[0], sh.lx)
    face = side
    # the earliest face, as in granulargas.engine._crossing.predict_crossing
    for a in range(1, space.dims):
        sheared = a == 1  # y: through the sheared boundary (stored + L_y, period L_y)
        g, v, sd = face_gap(rec[i, a] - (sh.ly if sheared else 0.0), rec[i, 3 + a], cell[i, a], grid.width[a],
                            space.ncell[a], sh.ly if sheared else space.period[a])
        gap, speed, face = earlier_face(gap, speed, face, g, v, 2 * a + sd)
    if speed == 0.0:
        return math.inf, face
    return t + gap / speed, face


@inlined
def _list_heads(first, k, head, g, c0, ncol, cz, z0, z1, ncell, period_z, nx):
    """Append to ``first`` the heads of the non-empty cells of row g, columns c0 .. c0 + ncol - 1
    (wrapped), z layers cz + z0 .. cz + z1 (none beyond a wall); returns the new count."""
    if ncol <= 0:
        return k
    start = _wrap_far(c0, nx)
    for oz in range(z0, z1 + 1):
        kz = cz + oz
        if kz < 0 or kz >= ncell[2]:
            if period_z == math.inf:
                continue
            kz = _wrap(kz, ncell[2])
        row = ncell[0] * (g + ncell[1] * kz)
        c = start
        for u in range(ncol):
            j = head[c + row]
            first[k] = j
            k += 1 if j >= 0 else 0
            c += 1
            c = 0 if c == nx else c
    return k


@inlined
def _scan_listed_le(first, k, t, before, rec, i, row_of_, period, sh):
    xi = rec[i, 0]
    yi = rec[i, 1]
    zi = rec[i, 2]
    vx = rec[i, 3]
    vy = rec[i, 4]
    vz = rec[i, 5]
    ri = rec[i, 7]
    dlt = image_offset(t, sh)
    best = before
    p = -1
    for q in range(1, k):
        j = first[q]
        while j >= 0:
            tc = t + le_pair_delay(j, t, xi, yi, zi, vx, vy, vz, ri, rec, period, sh, dlt)
            better = tc < best
            best = tc if better else best
            p = j if better else p
            j = row_of_[j, NEXT]
    return best, p


@inlined
def _windows(cx, m, nx):
    """First columns of the windows of the rows above (4 columns) and below (4 columns)."""
    return cx - 2 - m, cx - 1 + m


@inlined
def scan_le(i, t, before, rec, grid, space, sh, own0, own_n, up0, up_n, down0, down_n, z0, z1):
    """Earliest collision of i (streamed to t), before ``before``, with the particles of:
    columns own0 .. own0 + own_n - 1 of its own row, up0 .. of the row above, down0 .. of the
    row below (through the sheared boundary), z layers z0 .. z1 around its cell. (time,
    partner) or (``before``, -1).

    When i's row is not next to the sheared boundary and there are at least 7 rows, every
    candidate lies in rows r - 1 .. r + 1 of the box, less than 3 w_y + round-off < L_y / 2
    away along y: its nearest image is k = 0, and the pair times are those of the periodic
    box (:func:`granulargas.engine._crossing._scan_listed`, the sheared axis of period inf),
    the same numbers as :func:`le_pair_delay` gives without its image terms."""
    cell = grid.cell
    first = grid.fresh
    ncell = space.ncell
    r = cell[i, 1]
    cz = cell[i, 2]
    k = 1
    k = _list_heads(first, k, grid.head, r, own0, own_n, cz, z0, z1, ncell, space.period[2], sh.nx)
    k = _list_heads(first, k, grid.head, _wrap(r + 1, sh.ny), up0, up_n, cz, z0, z1, ncell, space.period[2], sh.nx)
    k = _list_heads(first, k, grid.head, _wrap(r - 1, sh.ny), down0, down_n, cz, z0, z1, ncell, space.period[2],
                    sh.nx)
    if interior_row(r, sh):
        return _scan_listed(first, k, t, before, rec[i, 0], rec[i, 1], rec[i, 2], rec[i, 3], rec[i, 4], rec[i, 5],
                            rec[i, 7], rec, cell, space.period, None)
    return _scan_listed_le(first, k, t, before, rec, i, cell, space.period, sh)


@inlined
def predict_pair_cells_le(i, t, before, rec, count, grid, space, sh):
    """:func:`granulargas.engine._crossing.predict_pair_cells` with sliding rows: the stored best
    pair right after a crossing, else the 3 + 4 + 4 columns (times 3 along z) around i."""
    if grid.fresh[0] == i:
        grid.fresh[0] = -1
        pt = grid.pair_t[i]
        pj = grid.cell[i, PAIR_J]
    else:
        zr = 1 if space.ncell[2] >= 3 else 0
        cx = grid.cell[i, 0]
        up0, down0 = _windows(cx, sh.slide[1], sh.nx)
        pt, pj = scan_le(i, t, math.inf, rec, grid, space, sh, cx - 1, 3, up0, 4, down0, 4, -zr, zr)
        grid.pair_t[i] = pt
        grid.cell[i, PAIR_J] = pj
        grid.cell[i, PAIR_TAG] = count[pj] if pj >= 0 else 0
    if pt < before:
        return pt, pj
    return before, -1


@inlined
def cross_le(i, face, t, rec, img, grid, space, sh):
    """Move i (at the face ``face`` of its cell, time t) into the cell beyond: an x face to
    the next column of its row, a y face into the next row (through the sheared boundary:
    :func:`le_wrap`) re-counted in that row's frame, a z face as without shear. Returns the
    change of v^2 (sheared boundary)."""
    a = face >> 1
    up = face & 1
    cell = grid.cell
    dv2 = 0.0
    if a == 0:
        cell[i, 0] = _wrap(cell[i, 0] + (1 if up else -1), sh.nx)
    elif a == 1:
        r = cell[i, 1] + (1 if up else -1)
        if r >= sh.ny or r < 0:
            # through the sheared boundary (the particle is at y = L_y or 0 to round-off;
            # it may land a round-off outside its new row, as at any face)
            dv2 = le_shift(i, t, rec, img, sh, r >= sh.ny)
            r = _wrap(r, sh.ny)
        cell[i, 1] = r
        cell[i, 0] = col_of(_reduce(rec[i, 0] - row_offset(r, t, sh), sh.lx), sh)
    else:
        n = space.ncell[2]
        c = cell[i, 2] + (1 if up else -1)
        cell[i, 2] = _wrap(c, n)
    grid_remove(i, grid)
    ncell = space.ncell
    grid_insert(i, cell[i, 0] + ncell[0] * (cell[i, 1] + ncell[1] * cell[i, 2]), grid)
    return dv2


@inlined(python=True)
def _minus(n0, nn, o0, on):
    """The columns n0 .. n0 + nn - 1 that are not among o0 .. o0 + on - 1 (integers, not
    wrapped; on >= nn - 1, so that the difference is a single run): (first, count), count <= 0
    if none."""
    if n0 < o0:
        return n0, min(nn, o0 - n0)
    return max(n0, o0 + on), n0 + nn - max(n0, o0 + on)


@inlined(python=True)
def _y_layer(cx, cxn, o, m, nx):
    """The columns that a crossing of a y face (``o`` = +1 up, -1 down) from column cx of
    its row into column cxn of the next makes adjacent, at the slide offset m: (own0, own_n,
    back0, back_n, ahead0), the runs of the new own row, the row left behind and the row
    ahead (4 columns from ahead0). The new own row lay in the old window of that row
    (columns cx - 2 - m .. cx + 1 - m up, cx - 1 + m .. cx + 2 + m down), the row left
    behind was the old own row (cx - 1 .. cx + 1): only the columns outside those are new.
    cxn is taken at the image nearest the old window (any image would be complete: a column
    outside the old run in integers is outside it modulo n_x too)."""
    old0 = cx - 2 - m if o > 0 else cx - 1 + m
    d = cxn - (old0 + 2)
    h = nx >> 1
    d = _wrap_far(d + h, nx) - h  # into [-h, n_x - h), h = n_x // 2
    c = old0 + 2 + d  # cxn unwrapped
    own0, own_n = _minus(c - 1, 3, old0, 4)
    back0 = c - 1 + m if o > 0 else c - 2 - m  # the window of the row left behind
    back0, back_n = _minus(back0, 4, cx - 1, 3)
    ahead0 = c - 2 - m if o > 0 else c - 1 + m
    return own0, own_n, back0, back_n, ahead0


@inlined
def scan_new_layer_le(i, t, face, cx_old, rec, count, grid, space, sh):
    """After i crossed ``face`` (from column ``cx_old`` of its row before the crossing): keep
    the better of its stored pair and the cells that became adjacent (x face: one column in
    each of the three rows; y face: the window of the row ahead and the columns of the other
    two rows that were not in i's old neighbourhood, :func:`_y_layer`; z face: the new layer
    of the three rows), and mark the stored pair current; nothing if the stored partner has
    collided since (the prediction then scans all)."""
    pj = grid.cell[i, PAIR_J]
    if pj >= 0 and count[pj] != grid.cell[i, PAIR_TAG]:
        return
    a = face >> 1
    o = 1 if face & 1 else -1
    cx = grid.cell[i, 0]
    zr = 1 if space.ncell[2] >= 3 else 0
    m = sh.slide[1]
    up0, down0 = _windows(cx, m, sh.nx)
    if a == 0:
        # the columns entering on the side of motion: own cx + o; above up0 + (3 if o > 0
        # else 0); below down0 + (3 if o > 0 else 0)
        e = 3 if o > 0 else 0
        pt, pn = scan_le(i, t, grid.pair_t[i], rec, grid, space, sh, cx + o, 1, up0 + e, 1, down0 + e, 1, -zr, zr)
    elif a == 1:
        own0, own_n, back0, back_n, ahead0 = _y_layer(cx_old, cx, o, m, sh.nx)
        if o > 0:
            pt, pn = scan_le(i, t, grid.pair_t[i], rec, grid, space, sh, own0, own_n, ahead0, 4, back0, back_n,
                             -zr, zr)
        else:
            pt, pn = scan_le(i, t, grid.pair_t[i], rec, grid, space, sh, own0, own_n, back0, back_n, ahead0, 4,
                             -zr, zr)
    else:
        pt, pn = scan_le(i, t, grid.pair_t[i], rec, grid, space, sh, cx - 1, 3, up0, 4, down0, 4, o, o)
    if pn >= 0:
        grid.pair_t[i] = pt
        grid.cell[i, PAIR_J] = pn
        grid.cell[i, PAIR_TAG] = count[pn]
    grid.fresh[0] = i


@inlined
def prefetch_around_le(i, grid, space, sh):
    """Prefetch hints for the cell heads that a full scan of particle i reads (no effect on
    results): per z layer, the line of its own row's cell and of the middles of the two
    adjacent rows' windows (:func:`_windows`)."""
    ncell = space.ncell
    nx = sh.nx
    cx = grid.cell[i, 0]
    r = grid.cell[i, 1]
    cz = grid.cell[i, 2]
    m = sh.slide[1]
    up = _wrap(r + 1, sh.ny)
    down = _wrap(r - 1, sh.ny)
    cu = _wrap(cx - m, nx)  # column 2 of the upper window
    cd = _wrap(cx + m, nx)  # column 1 of the lower window
    zr = 1 if ncell[2] >= 3 else 0
    for oz in range(-zr, zr + 1):
        kz = cz + oz
        if kz < 0 or kz >= ncell[2]:
            if space.period[2] == math.inf:
                continue
            kz = _wrap(kz, ncell[2])
        base = ncell[1] * kz
        prefetch(grid.head, cx + nx * (r + base))
        prefetch(grid.head, cu + nx * (up + base))
        prefetch(grid.head, cd + nx * (down + base))


@kernel
def build_grid_le(t, rec, grid, space, sh):
    """Every particle (inside [0, L_y) at t) into the cell of its position in its row's frame."""
    box = space.box
    ncell = space.ncell
    grid.head[:] = -1
    for i in range(rec.shape[0] - 1, -1, -1):
        r = row_of(rec[i, 1] - sh.ly, sh)
        grid.cell[i, 1] = r
        grid.cell[i, 0] = col_of(_reduce(rec[i, 0] - row_offset(r, t, sh), sh.lx), sh)
        c = int(rec[i, 2] * (ncell[2] / box[2]))
        grid.cell[i, 2] = min(max(c, 0), ncell[2] - 1)
        grid_insert(i, grid.cell[i, 0] + ncell[0] * (grid.cell[i, 1] + ncell[1] * grid.cell[i, 2]), grid)


# ------------------------------------------------------------------ stress
@inlined
def integrate_stress(stress, dt, sh):
    """Advance the kinetic sums of ``stress`` by dt of free flight and add their integral:
    with c_x = v_x - a (y - L_y/2), d c_x/dt = -a c_y, so S_xx' = -2a S_xy, S_xy' = -a S_yy,
    S_xz' = -a S_yz, the others constant (``sh`` None: a = 0). Nothing without ``stress``."""
    if stress is not None:
        st = stress[0]
        s = st.s
        k = st.k
        if sh is None:
            for q in range(6):
                k[q] += s[q] * dt
        else:
            a = sh.rate
            ad = a * dt
            k[XX] += (s[XX] - ad * s[XY] + ad * ad * s[YY] / 3.0) * dt
            k[XY] += (s[XY] - 0.5 * ad * s[YY]) * dt
            k[XZ] += (s[XZ] - 0.5 * ad * s[YZ]) * dt
            k[YY] += s[YY] * dt
            k[ZZ] += s[ZZ] * dt
            k[YZ] += s[YZ] * dt
            s[XX] += (-2.0 * s[XY] + ad * s[YY]) * ad
            s[XY] -= ad * s[YY]
            s[XZ] -= ad * s[YZ]


@inlined
def peculiar_x(i, rec, sh):
    """c_x of particle i at its clock (v_x without shear)."""
    if sh is None:
        return rec[i, 3]
    return rec[i, 3] - sh.rate * (rec[i, 1] - 1.5 * sh.ly)  # y stored + L_y


@inlined
def stress_jump(stress, m, cx, cy, cz, dvx, dvy, dvz):
    """Add m (c' c' - c c) for a velocity change dv of a particle of peculiar velocity c."""
    if stress is not None:
        s = stress[0].s
        s[XX] += m * (2.0 * cx + dvx) * dvx
        s[YY] += m * (2.0 * cy + dvy) * dvy
        s[ZZ] += m * (2.0 * cz + dvz) * dvz
        s[XY] += m * (cx * dvy + dvx * cy + dvx * dvy)
        s[XZ] += m * (cx * dvz + dvx * cz + dvx * dvz)
        s[YZ] += m * (cy * dvz + dvy * cz + dvy * dvz)


@inlined
def stress_virial(stress, f, nx, ny, nz):
    """Add r_ij (x) Delta p_i = f n (x) n of a collision (f = -impulse |r_ij|)."""
    if stress is not None:
        w = stress[0].w
        w[XX] += f * nx * nx
        w[YY] += f * ny * ny
        w[ZZ] += f * nz * nz
        w[XY] += f * nx * ny
        w[XZ] += f * nx * nz
        w[YZ] += f * ny * nz


@kernel
def stress_sums(rec, mass, sh, out):
    """sum m c_a c_b (xx, yy, zz, xy, xz, yz) of all particles at their own clocks into ``out``
    (all at one time)."""
    for q in range(6):
        out[q] = 0.0
    for i in range(rec.shape[0]):
        m = mass[i]
        cx = peculiar_x(i, rec, sh)
        cy = rec[i, 4]
        cz = rec[i, 5]
        out[XX] += m * cx * cx
        out[YY] += m * cy * cy
        out[ZZ] += m * cz * cz
        out[XY] += m * cx * cy
        out[XZ] += m * cx * cz
        out[YZ] += m * cy * cz


def stress_sums_of(rec, mass, sh, out):
    """:func:`stress_sums` in numpy, for a build made from Python (no kernel compiled for it):
    the same products, summed in the same order (``np.cumsum`` adds one term after the other),
    hence the same bits."""
    cx = rec[:, 3] if sh is None else rec[:, 3] - sh.rate * (rec[:, 1] - 1.5 * sh.ly)
    cy = rec[:, 4]
    cz = rec[:, 5]
    for q, (a, b) in zip((XX, YY, ZZ, XY, XZ, YZ), ((cx, cx), (cy, cy), (cz, cz), (cx, cy), (cx, cz), (cy, cz))):
        out[q] = np.cumsum(mass * a * b)[-1] if rec.shape[0] else 0.0


# ------------------------------------------------------------------ global events
@inlined
def next_slide(sh, oncells):
    """Time of the next slide (cell mode only; inf otherwise)."""
    if oncells is None:
        return math.inf
    return (sh.slide[0] + 1) * sh.slide_time


@inlined
def next_rescale(sh):
    """Time of the next thermostat rescaling ((k + 1/2) interval; inf without thermostat)."""
    dt = sh.thermostat[0]
    if dt == math.inf:
        return math.inf
    return (sh.rescales[0] + 0.5) * dt


@kernel(python=False)
def slide_scan(t, rec, img, count, events, grid, space, cal, sh):
    """The slide at t (the rows' x offsets step by one column against their neighbours): every
    particle streamed to t scans the new column of its upper window and keeps what it finds
    if earlier than its event (and its stored best pair, if that is current). Returns False
    on a calendar overflow."""
    sh.slide[0] += 1
    m = sh.slide[1] + 1
    m = 0 if m == sh.nx else m
    sh.slide[1] = m
    zr = 1 if space.ncell[2] >= 3 else 0
    period = space.period
    for i in range(rec.shape[0]):
        stream(i, t, rec, img, period, None)  # straight flights: shear has no gravity
        cx = grid.cell[i, 0]
        pt, pn = scan_le(i, t, math.inf, rec, grid, space, sh, cx, 0, cx - 2 - m, 1, cx, 0, -zr, zr)
        if pn < 0:
            continue
        pj = grid.cell[i, PAIR_J]
        if (pj < 0 or count[pj] == grid.cell[i, PAIR_TAG]) and pt < grid.pair_t[i]:
            grid.pair_t[i] = pt
            grid.cell[i, PAIR_J] = pn
            grid.cell[i, PAIR_TAG] = count[pn]
        if pt < cal.qt[i]:
            events.partner[i] = pn
            events.tag[i] = count[pn]
            if not cal_update(i, pt, cal):
                return False
    return True


@kernel
def synchronised_le(rec, img, period, t, sh, out_r, out_img, out_v):
    """Positions, images and velocities of all particles streamed to t and wrapped (through the
    sheared boundary too; no side effect)."""
    shift = sh.speed * t
    q = np.int64(math.floor(shift / sh.lx))
    d = shift - q * sh.lx
    for i in range(rec.shape[0]):
        dt = t - rec[i, 6]
        vx = rec[i, 3]
        kx = img[i, 0]
        ky = img[i, 1]
        x = rec[i, 0] + vx * dt
        y = rec[i, 1] - sh.ly + rec[i, 4] * dt
        if y >= sh.ly:
            y -= sh.ly
            x -= d
            kx -= q
            ky += 1
            vx -= sh.speed
        elif y < 0.0:
            y += sh.ly
            if y >= sh.ly:
                y = 0.0
            x += d
            kx += q
            ky -= 1
            vx += sh.speed
        while x >= sh.lx:
            x -= sh.lx
            kx += 1
        while x < 0.0:
            x += sh.lx
            kx -= 1
            if x >= sh.lx:
                x = 0.0
                kx += 1
        z = rec[i, 2] + rec[i, 5] * dt
        kz = img[i, 2]
        if z >= period[2]:
            z -= period[2]
            kz += 1
        elif z < 0.0:
            z += period[2]
            kz -= 1
            if z >= period[2]:
                z = 0.0
                kz += 1
        out_r[i, 0] = x
        out_r[i, 1] = y
        out_r[i, 2] = z
        out_img[i, 0] = kx
        out_img[i, 1] = ky
        out_img[i, 2] = kz
        out_v[i, 0] = vx
        out_v[i, 1] = rec[i, 4]
        out_v[i, 2] = rec[i, 5]
