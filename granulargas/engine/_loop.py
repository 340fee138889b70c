"""The compiled event loop (numba): pop, validate, dispatch; one place per event kind.

One event per particle (Smallenburg 2022; Paul 2007): particle i stores the
earliest of its own events -- a collision with a particle of its neighbour
list, the moment it leaves the sphere of radius shell/2 around its list centre
("list expiry"), or a collision with a wall -- in its slot of
:class:`~granulargas.engine._state.Events`: ``partner[i]`` is the partner's slot
(>= 0) or the kind code of a one-particle event (< 0), ``tag[i]`` the partner's
collision counter at prediction time (pair) or the wall index (wall). A popped
pair event whose partner has collided since is stale and is simply
re-predicted. A pair collision needs to be scheduled by only one of the two:
whichever changes its velocity first re-predicts against all its neighbours,
the other included. The white-noise driving is a global event source: every
particle is kicked at the times (k + 1/2) dt_k; :func:`advance_driven` runs the
loop up to each driving step and executes it, so that the loop of an undriven run
carries no trace of it.

Event kinds, each with one predict and one execute function here:

=========  ====  =======================  ==========================
kind       code  predict                  execute
=========  ====  =======================  ==========================
PAIR       >= 0  :func:`predict_pair`     :func:`execute_pair`
EXPIRY     -1    :func:`predict_expiry`   :func:`execute_expiry`
WALL       -2    :func:`predict_wall`     :func:`execute_wall`
KICK       -3    :func:`predict_kick`     :func:`execute_kick`
CROSS      -5    :func:`predict_crossing` :func:`execute_crossing`
=========  ====  =======================  ==========================

(STALE, -4, is what validation makes of a pair event whose partner changed
course.) :func:`predict` keeps the earliest of a particle's own kinds.

Two neighbour modes share the loop: neighbour lists (EXPIRY events, the
records ``Lists`` and ``Cells``) or cell crossings (CROSS events, no lists:
:mod:`granulargas.engine._crossing`; ``engine.lists`` is then a ``Grid`` and
``engine.cells`` None). :func:`advance` and :func:`predict` take the mode as two
arguments, ``onlists`` and ``oncells``, one of them 1 and the other None
(:func:`mode_flags`), and branch on ``is not None``: numba removes the branches
of a None-typed argument before typing, so each mode's build of the loop carries
none of the other's code (numba overloads would do the same at about twice the
first compile time).

Particles stream lazily: each carries its own clock and is moved to the
current time only when it takes part in an event. The data a prediction reads
for a neighbour sit in one 64-byte record per particle,
``rec[i] = (x, y, z, vx, vy, vz, t_i, R_i)``, so that one cache line serves it.

Memory: beyond the 1 MB L2 cache of the machines we measure on, every random
access costs ~100-160 ns, so at N >~ 10^4 an event waits mostly on cache
misses, and the design counts cache lines: the event calendar
(:mod:`granulargas.engine._calendar`) updates in O(1) lines instead of a heap's
O(log N) dependent misses; a list rebuild reads cell rows and centres in
independent passes (:mod:`granulargas.engine._cells`); and after each event
:func:`prefetch_next` issues prefetch hints (no effect on results) for every
per-particle row of the next event's particle and its partner, the records of
its neighbours, and the rows of the likely event after it
(:func:`granulargas.engine._calendar.cal_after_next`: right for 97-98 % of
events, ``scripts/profiling/profile_loop.py``), so that these misses overlap with the
current work; before a list expiry it also prefetches the cell rows around the
particle and its neighbours' list rows. Where the time goes per part of the
loop: ``python scripts/profiling/profile_loop.py 1e4 1e6`` (cycle counters compiled into
a second build of this loop, :mod:`granulargas.engine._probe`); per source line of
the production build: ``python scripts/profiling/perf_loop.py 1e4`` (``perf`` samples); two source
trees compared by alternated runs: ``python scripts/ab/alternated.py OTHER_TREE .
--sizes 1e4 1e6``; the numbers are in docs/performance.md.

Status codes (the Python driver raises ``granulargas.errors`` exceptions):
0 reached ``until``; 1 event budget of this chunk used (call again);
2 ``max_collisions`` reached; 10 a neighbour list is full, 11 a cell is full
(enlarge, call again: nothing was lost); 20 inelastic collapse (a particle collided
``collapse_count`` times in a row less than ``collapse_dt`` after its previous
collision); 21 impact beyond the restitution table; 22, 23 impact beyond the
oblique-contact table in beta, in delta (resolved rule: the driver extends the
table and calls again, nothing was lost); 30 watchdog (an event in
the past or an endless run of zero-time events: round-off trouble); 31 more
simultaneous events than the event calendar's window holds.
"""

import math

import numpy as np

from granulargas._numba import inlined, inlined_ir, kernel
from granulargas.engine._calendar import (
    cal_after_next,
    cal_build,
    cal_look_ahead,
    cal_next_time,
    cal_first,
    cal_update,
    cal_update_ring,
    cal_update_root,
)
from granulargas.engine._cells import prefetch_cells, rebuild_list
from granulargas.engine._collide import pair_collision, restitution, wall_collision
from granulargas.engine._crossing import (
    cross,
    predict_crossing,
    predict_pair_cells,
    prefetch_around,
    scan_new_layer,
)
from granulargas.engine._drive import kick_velocities
from granulargas.engine._flight import expiry_delay, pair_delay, partner_at, stream
from granulargas.engine._geometry import collision_delay, min_image, wall_delay
from granulargas.engine._prefetch import prefetch
from granulargas.engine._resolved import resolved_pair
from granulargas.engine._shear import (
    cross_le,
    integrate_stress,
    interior_row,
    le_separation,
    le_wrap,
    next_rescale,
    next_slide,
    peculiar_x,
    predict_crossing_le,
    predict_expiry_le,
    predict_pair_cells_le,
    predict_pair_le,
    prefetch_around_le,
    rebuild_list_le,
    row_of,
    scan_new_layer_le,
    slide_scan,
    stress_jump,
    stress_sums,
    stress_virial,
)
from granulargas.engine._species import count_pair, pair_law, wall_law
from granulargas.engine._spin import kick_spins, rough_pair, rough_wall
from granulargas.engine._walls import (
    RECHECK,
    THERMAL,
    VIBRATING,
    moving_wall_collision,
    predict_walls,
    thermal_velocity,
    wall_motion,
)
from granulargas.engine._probe import (
    COLLIDE,
    GLOBAL,
    PEEK,
    POP,
    PREDICT,
    PREFETCH,
    REBUILD,
    STALE as P_STALE,
    UPDATE,
    WALL as P_WALL,
    probe as tick,
    probe_guess,
    probe_start,
)

# status codes
DONE = 0
BUDGET = 1
MAX_COLLISIONS = 2
COLLAPSE = 20
TABLE_RANGE = 21
WATCHDOG = 30
CALENDAR = 31
#: :func:`collide_pair` of a pair that separates (round-off): nothing happened
RECEDING = -1

# event kinds
PAIR = 0
EXPIRY = -1
WALL = -2
KICK = -3
STALE = -4
CROSS = -5


# --------------------------------------------------------------------- predict
@inlined
def predict_expiry(i, t, rec, centre, period, half_shell, flight):
    """Time at which particle i (streamed to t) is ``half_shell`` from its list centre (under
    gravity a lower bound of it: :func:`granulargas.engine._flight.expiry_delay`)."""
    return t + expiry_delay(min_image(rec[i, 0] - centre[i, 0], period[0]),
                            min_image(rec[i, 1] - centre[i, 1], period[1]),
                            min_image(rec[i, 2] - centre[i, 2], period[2]),
                            rec[i, 3], rec[i, 4], rec[i, 5], half_shell, flight)


@inlined
def predict_pair(i, t, before, rec, nbl, nbn, period, flight):
    """Earliest collision of particle i (streamed to t) with its neighbours before ``before``.

    Returns (time, partner slot), or (``before``, -1) if there is none. Branch-free
    over the neighbours (see :func:`granulargas.engine._geometry.collision_delay`).
    """
    xi = rec[i, 0]
    yi = rec[i, 1]
    zi = rec[i, 2]
    vx = rec[i, 3]
    vy = rec[i, 4]
    vz = rec[i, 5]
    ri = rec[i, 7]
    best = before
    p = -1
    for k in range(nbn[i]):
        j = nbl[i, k]
        tc = t + pair_delay(j, t, xi, yi, zi, vx, vy, vz, ri, rec, period, flight)
        better = tc < best
        best = tc if better else best
        p = j if better else p
    return best, p


@kernel(python=False)
def predict_pair_except(i, t, before, rec, nbl, nbn, period, contacts, flight):
    """:func:`predict_pair` for a particle whose contact is under way (resolved rule,
    :mod:`granulargas.engine._resolved`).

    A neighbour j with a contact under way between i and j (j = ``partner[i]``, or
    ``partner[j]`` = i; after a third-particle collision the two differ) cannot
    collide with i before that contact ends, at e = the later of the two ends: its
    collision time is e plus the delay from the pair's state at e (0 if the
    extended lines still overlap there and approach; none for the receding pair
    of an undisturbed contact).
    """
    skip = contacts.partner[i]
    until = contacts.until
    partner = contacts.partner
    xi = rec[i, 0]
    yi = rec[i, 1]
    zi = rec[i, 2]
    vx = rec[i, 3]
    vy = rec[i, 4]
    vz = rec[i, 5]
    ri = rec[i, 7]
    best = before
    p = -1
    for k in range(nbn[i]):
        j = nbl[i, k]
        xj, yj, zj, wx, wy, wz = partner_at(j, t - rec[j, 6], rec, flight)
        end = until[i] if j == skip else -math.inf
        if partner[j] == i and until[j] > end:
            end = until[j]
        h = end - t if end > t else 0.0
        ux = vx - wx
        uy = vy - wy
        uz = vz - wz
        s = collision_delay(min_image(xi - xj + ux * h, period[0]),
                            min_image(yi - yj + uy * h, period[1]),
                            min_image(zi - zj + uz * h, period[2]),
                            ux, uy, uz, ri + rec[j, 7])
        tc = t + h + s
        better = tc < best
        best = tc if better else best
        p = j if better else p
    return best, p


@inlined
def in_contact(contacts, i, t):
    """Whether particle i's contact is under way at t (always False without contacts:
    ``contacts`` is None for the instantaneous rules, so that their loop compiles
    without any of the resolved rule's code)."""
    if contacts is None:
        return False
    return contacts.until[i] > t


@inlined
def predict_pair_contact(i, t, before, rec, lists, period, contacts, flight):
    """:func:`predict_pair_except` (``contacts`` None: never called, returns (before, -1))."""
    if contacts is None:
        return before, np.int64(-1)
    return predict_pair_except(i, t, before, rec, lists.nbl, lists.nbn, period, contacts, flight)


@inlined
def collide_resolved(i, j, te, dx, dy, dz, p, contacts, c, rule, period):
    """:func:`granulargas.engine._resolved.resolved_pair` (``contacts`` None: never called)."""
    if contacts is None:
        return 0
    return resolved_pair(i, j, te, dx, dy, dz, p, contacts, c, rule, period)


@inlined
def collide_rough(i, j, nx, ny, nz, un, eps, rec, mass, spins, elastic):
    """:func:`granulargas.engine._spin.rough_pair` (``spins`` None: never called)."""
    if spins is None:
        return 0.0, 0.0, 0.0
    return rough_pair(i, j, nx, ny, nz, un, eps, rec, mass, spins, elastic)


@inlined
def bounce_rough(i, a, side, eps, rec, mass, spins, elastic):
    """:func:`granulargas.engine._spin.rough_wall` (``spins`` None: never called)."""
    if spins is None:
        return 0.0, 0.0, 0.0
    return rough_wall(i, a, side, eps, rec, mass, spins, elastic)


@inlined
def kick_rough(rec, mass, ident, dims, spins, seed, step):
    """:func:`granulargas.engine._spin.kick_spins` (``spins`` None: never called)."""
    if spins is None:
        return 0.0
    return kick_spins(rec, mass, ident, dims, spins, seed, step)


@inlined
def predict_wall(i, t, before, rec, space, flight, wallkinds):
    """Earliest wall collision of particle i (streamed to t): (time, wall index 2 a + side).

    (inf, 0) without wall axes. With gravity (``flight``) or wall kinds other than hard
    walls at rest (``wallkinds``) :func:`granulargas.engine._walls.predict_walls`, which
    may stop looking at ``before`` (i's earliest other event, after which it is predicted
    again) and tags a re-check with :data:`~granulargas.engine._walls.RECHECK`.
    """
    if flight is not None or wallkinds is not None:
        return predict_walls(i, t, before, rec, space, flight, wallkinds)
    best = math.inf
    wall = 0
    axes = space.wall_axes
    for k in range(axes.shape[0]):
        a = axes[k]
        s, side = wall_delay(rec[i, a], rec[i, 3 + a], rec[i, 7], space.box[a])
        if s < best:
            best = s
            wall = 2 * a + side
    return t + best, wall


@inlined
def predict_kick(c, prm):
    """Time of the next driving step, (k + 1/2) dt_k (inf without driving)."""
    return (c.kick_step + 0.5) * prm.kick_interval if prm.kick_interval < math.inf else math.inf


def mode_flags(cells):
    """(onlists, oncells) of :func:`advance` and :func:`predict`: (1, None) for the
    neighbour lists (``cells`` the cell record), (None, 1) for cell crossings (``cells`` None)."""
    return (1, None) if cells is not None else (None, 1)


@inlined
def settle_event(i, t, best, p, tag, rec, events, space, flight, wallkinds):
    """The earlier of i's predicted event (time ``best``, partner or kind ``p``, ``tag``) and
    its next wall impact into i's event slot; returns that event's time."""
    tw, wall = predict_wall(i, t, best, rec, space, flight, wallkinds)
    if tw < best:
        best = tw
        p = WALL
        tag = wall
    events.partner[i] = p
    events.tag[i] = tag
    return best


@inlined
def predict_sheared(i, t, rec, count, events, lists, onlists, oncells, space, half_shell, shear):
    """:func:`predict` under Lees-Edwards boundaries (:mod:`granulargas.engine._shear`: list
    centres and cells in the frames of sliding rows, pairs through the sheared images)."""
    best = math.inf
    kind = np.int64(EXPIRY)
    tag = np.int64(0)
    p = np.int64(-1)
    if onlists is not None:
        best = predict_expiry_le(i, t, rec, lists.centre, space.period, half_shell, shear)
        if interior_row(row_of(np.float64(lists.centre[i, 1]), shear), shear):
            best, p = predict_pair(i, t, best, rec, lists.nbl, lists.nbn, space.period, None)
        else:
            best, p = predict_pair_le(i, t, best, rec, lists.nbl, lists.nbn, space.period, shear)
    if oncells is not None:
        best, face = predict_crossing_le(i, t, rec, lists, space, shear)
        kind = np.int64(CROSS)
        tag = np.int64(face)
        best, p = predict_pair_cells_le(i, t, best, rec, count, lists, space, shear)
    if p >= 0:
        tag = np.int64(count[p])
    else:
        p = kind
    return settle_event(i, t, best, p, tag, rec, events, space, None, None)


@kernel(python=False)
def predict(i, t, rec, count, events, lists, onlists, oncells, space, half_shell, contacts, flight, wallkinds,
            shear):
    """Earliest event of particle i (streamed to t); sets its slot and returns the time.

    ``lists`` is the neighbour lists (``onlists`` = 1, ``oncells`` = None) or the cell
    grid of the cell-crossing mode (``onlists`` = None, ``oncells`` = 1). Each mode's
    build keeps only its own branches: numba removes a branch on ``x is not None`` of
    a None-typed argument before typing (overloads would too, at about twice the first
    compile time).

    ``contacts`` (resolved rule; None otherwise): while i's contact is under way
    (t < ``contacts.until[i]``; the end of a contact of i with j is never before j's)
    its contact partners are left out (:func:`predict_pair_except`).

    ``flight`` (None: straight; gravity: the (3,) acceleration) and ``wallkinds`` (None:
    hard walls at rest; else a :class:`~granulargas.engine._state.WallSpec`): numba removes
    their branches for None, as for the mode flags.

    ``shear`` (Lees-Edwards; None otherwise): :func:`predict_sheared` (straight flights and
    hard walls only: gravity and wall kinds are refused with shear)."""
    if shear is not None:
        return predict_sheared(i, t, rec, count, events, lists, onlists, oncells, space, half_shell, shear)
    best = math.inf
    kind = np.int64(EXPIRY)
    tag = np.int64(0)
    p = np.int64(-1)
    if onlists is not None:
        best = predict_expiry(i, t, rec, lists.centre, space.period, half_shell, flight)
    if oncells is not None:
        best, face = predict_crossing(i, t, rec, lists, space, flight)
        kind = np.int64(CROSS)
        tag = np.int64(face)
    if in_contact(contacts, i, t):
        best, p = predict_pair_contact(i, t, best, rec, lists, space.period, contacts, flight)
    else:
        if onlists is not None:
            best, p = predict_pair(i, t, best, rec, lists.nbl, lists.nbn, space.period, flight)
        if oncells is not None:
            best, p = predict_pair_cells(i, t, best, rec, count, lists, space, flight)
    if p >= 0:
        tag = np.int64(count[p])
    else:
        p = kind
    return settle_event(i, t, best, p, tag, rec, events, space, flight, wallkinds)


@inlined
def predict_listed(i, t, rec, count, events, lists, space, half_shell, contacts, flight, wallkinds, shear):
    """:func:`predict` in the neighbour-list mode, inlined into the loop's two hot sites
    (the particle of the event and its collision partner; ``predict`` itself is a call)."""
    if shear is not None:
        return predict_sheared(i, t, rec, count, events, lists, 1, None, space, half_shell, shear)
    best = predict_expiry(i, t, rec, lists.centre, space.period, half_shell, flight)
    tag = np.int64(0)
    if in_contact(contacts, i, t):
        best, p = predict_pair_contact(i, t, best, rec, lists, space.period, contacts, flight)
    else:
        best, p = predict_pair(i, t, best, rec, lists.nbl, lists.nbn, space.period, flight)
    if p >= 0:
        tag = np.int64(count[p])
    else:
        p = np.int64(EXPIRY)
    return settle_event(i, t, best, p, tag, rec, events, space, flight, wallkinds)


@inlined_ir
def predict_cells(i, t, rec, count, events, grid, space, flight, wallkinds, shear):
    """:func:`predict` in the cell-crossing mode (no contacts there), for the loop to inline
    at its two hot sites, the event's own particle and a collision partner: the crossing,
    the best pair (the stored one right after a crossing of i, else the scan of the cells
    around i), the walls. (Inlined at the partner too it costs ~0.4 s of first compile and
    saves 1-4 % of the run time at packing 0.05-0.1.)"""
    if shear is not None:
        return predict_sheared(i, t, rec, count, events, grid, None, 1, space, 0.0, shear)
    best, face = predict_crossing(i, t, rec, grid, space, flight)
    tag = np.int64(face)
    p = np.int64(CROSS)
    best, pj = predict_pair_cells(i, t, best, rec, count, grid, space, flight)
    if pj >= 0:
        p = np.int64(pj)
        tag = np.int64(count[p])
    return settle_event(i, t, best, p, tag, rec, events, space, flight, wallkinds)


@inlined_ir
def predict_after_collapse(i, t, p, events, lists, onlists, oncells, prm, contacts, shear):
    """i's next event after an inelastic collapse (a rare path that ends the loop with its
    calendar whole): the list mode's own inlined :func:`predict_listed`, so that its builds of
    the loop compile no :func:`predict`; the cell mode calls :func:`predict` (a third copy of the
    IR-inlined :func:`predict_cells` would cost its first compile more)."""
    if onlists is not None:
        ti = predict_listed(i, t, p.rec, p.count, events, lists, prm.space, prm.half_shell, contacts, prm.flight,
                            prm.wallkinds, shear)
    if oncells is not None:
        ti = predict(i, t, p.rec, p.count, events, lists, onlists, oncells, prm.space, prm.half_shell, contacts,
                     prm.flight, prm.wallkinds, shear)
    return ti


@kernel
def predict_all(t, rec, count, events, lists, onlists, oncells, space, half_shell, contacts, flight, wallkinds,
                shear, times):
    """Predict the event of every particle (all clocks at t) into ``times``."""
    for i in range(rec.shape[0]):
        times[i] = predict(i, t, rec, count, events, lists, onlists, oncells, space, half_shell, contacts, flight,
                           wallkinds, shear)


# --------------------------------------------------------------------- execute
@inlined
def _collapse_watch(i, te, p, prm):
    """Count runs of ever faster re-collisions of particle i; note the collision time."""
    if te - p.lastcoll[i] < prm.collapse_dt:
        p.rapid[i] += 1
    else:
        p.rapid[i] = 0
    p.lastcoll[i] = te


@inlined
def collide_pair(i, j, te, p, c, prm, contacts, shear, stress, spins, species):
    """The collision of i and j at te, both streamed to te: validate (approaching), collide,
    count. Returns DONE, RECEDING (the pair separates: round-off, nothing happened) or
    TABLE_RANGE / OBLIQUE_*_RANGE (``c.err_i``, ``c.err_j`` set).

    With ``contacts`` (the resolved rule; None otherwise) the pair collides by
    :func:`granulargas.engine._resolved.resolved_pair`; with ``spins`` (rough particles; None
    otherwise) by :func:`granulargas.engine._spin.rough_pair`, except the TC model's elastic
    collisions, which are also frictionless. With ``species`` (a mixture; None otherwise) the
    pair's normal law comes from the species table and the collision is counted per pair of
    species (:mod:`granulargas.engine._species`); the tangential law is the same for every pair.
    ``shear``: the pair through its nearest Lees-Edwards image; ``stress``: the pressure tensor's
    sums take the collision (smooth particles only).

    The same in both neighbour modes (no argument depends on the mode), so one compiled library
    serves every build of the loop with these types, each inlining it (LLVM's ``alwaysinline``).
    """
    rec = p.rec
    period = prm.space.period
    rule = prm.rule
    flight = prm.flight
    stream(i, te, rec, p.img, period, flight)
    stream(j, te, rec, p.img, period, flight)
    if shear is not None:
        dx, dy, dz, ux, uy, uz = le_separation(i, j, te, rec, period, shear)
    else:
        dx = min_image(rec[i, 0] - rec[j, 0], period[0])
        dy = min_image(rec[i, 1] - rec[j, 1], period[1])
        dz = min_image(rec[i, 2] - rec[j, 2], period[2])
        ux = rec[i, 3] - rec[j, 3]
        uy = rec[i, 4] - rec[j, 4]
        uz = rec[i, 5] - rec[j, 5]
    b = dx * ux + dy * uy + dz * uz
    if b >= 0.0:  # receding (round-off): nothing happens
        return RECEDING
    if contacts is not None:
        status = collide_resolved(i, j, te, dx, dy, dz, p, contacts, c, rule, period)
        if status != DONE:
            return status
    else:
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        inv = 1.0 / dist
        nx = dx * inv
        ny = dy * inv
        nz = dz * inv
        un = b * inv  # normal relative velocity, < 0
        mi = p.mass[i]
        mj = p.mass[j]
        lastcoll = p.lastcoll
        if (rule.tc_time > 0.0 and (te - lastcoll[i] < rule.tc_time or te - lastcoll[j] < rule.tc_time)
                or -un < rule.elastic_below):
            eps = 1.0
        else:
            r_eff = rec[i, 7] * rec[j, 7] / (rec[i, 7] + rec[j, 7])
            eps_pair, k_pair = pair_law(rule.eps, rule.prefactor, species, i, j)
            eps = restitution(rule.kind, eps_pair, k_pair, rule.inv_h, rule.coeffs, -un,
                              r_eff, mi * mj / (mi + mj))
            if eps < 0.0:
                c.err_i = i
                c.err_j = j
                return TABLE_RANGE
        if spins is not None:
            elastic = rule.tc_time > 0.0 and (te - lastcoll[i] < rule.tc_time or te - lastcoll[j] < rule.tc_time)
            loss, impulse, drot = collide_rough(i, j, nx, ny, nz, un, eps, rec, p.mass, spins, elastic)
            c.sum_mv2 -= 2.0 * drot
        else:
            fi, fj, loss, impulse = pair_collision(un, mi, mj, eps)
            if stress is not None:
                stress_jump(stress, mi, peculiar_x(i, rec, shear), rec[i, 4], rec[i, 5], -fi * nx, -fi * ny, -fi * nz)
                stress_jump(stress, mj, peculiar_x(j, rec, shear), rec[j, 4], rec[j, 5], fj * nx, fj * ny, fj * nz)
                stress_virial(stress, -impulse * dist, nx, ny, nz)
            rec[i, 3] -= fi * nx
            rec[i, 4] -= fi * ny
            rec[i, 5] -= fi * nz
            rec[j, 3] += fj * nx
            rec[j, 4] += fj * ny
            rec[j, 5] += fj * nz
        c.dissipated += loss
        c.sum_mv2 -= 2.0 * loss
        c.virial -= impulse * dist
    p.count[i] += 1
    p.count[j] += 1
    c.collisions += 1
    count_pair(species, i, j)
    _collapse_watch(i, te, p, prm)
    _collapse_watch(j, te, p, prm)
    return DONE


@inlined_ir
def execute_pair(i, j, te, p, ev, lists, onlists, oncells, cal, c, prm, contacts, shear, stress, spins, species):
    """Pair collision of i and j at te (:func:`collide_pair`), then j's next event.

    Returns DONE, or TABLE_RANGE / OBLIQUE_*_RANGE / COLLAPSE / CALENDAR (``c.err_i``,
    ``c.err_j`` set).
    """
    status = collide_pair(i, j, te, p, c, prm, contacts, shear, stress, spins, species)
    if status == RECEDING:
        return DONE
    if status != DONE:
        return status
    rec = p.rec
    flight = prm.flight
    wallkinds = prm.wallkinds
    if onlists is not None:
        tj = predict_listed(j, te, rec, p.count, ev, lists, prm.space, prm.half_shell, contacts, flight, wallkinds,
                            shear)
    if oncells is not None:
        tj = predict_cells(j, te, rec, p.count, ev, lists, prm.space, flight, wallkinds, shear)
    if not cal_update_ring(j, tj, cal):
        return CALENDAR
    if p.rapid[i] >= prm.collapse_count or p.rapid[j] >= prm.collapse_count:
        ti = predict_after_collapse(i, te, p, ev, lists, onlists, oncells, prm, contacts, shear)
        status = COLLAPSE if cal_update(i, ti, cal) else CALENDAR
        c.events += 1
        c.err_i = i
        c.err_j = j
        return status
    return DONE


@inlined_ir
def _expired(i, st, c):
    """Count a list expiry whose rebuild returned ``st`` (0, or the error with i noted)."""
    if st != 0:
        c.err_i = i
        c.err_j = -1
        return st
    c.expiries += 1
    return DONE


@inlined_ir
def execute_expiry(i, te, p, lists, cells, c, prm):
    """List expiry of i at te: a new list centre and neighbour list (OVERFLOW/CELL_OVERFLOW
    if a list or a cell is full: nothing changed, the driver enlarges and calls again)."""
    stream(i, te, p.rec, p.img, prm.space.period, prm.flight)
    return _expired(i, rebuild_list(i, p.rec, lists, cells, prm.space, prm.rmax, prm.shell), c)


@inlined_ir
def execute_expiry_le(i, te, p, lists, cells, c, prm, shear):
    """:func:`execute_expiry` under Lees-Edwards boundaries: i first back inside [0, L_y)
    through the sheared boundary, the centre in its row's frame
    (:func:`granulargas.engine._shear.rebuild_list_le`, inlined at the level of its IR).
    A function of its own, called under the loop's own ``shear is not None``: numba prunes
    that branch of an unsheared loop before it inlines IR, whereas a branch on the argument
    of an IR-inlined callee is pruned only after the inlining, and the sheared rebuild and
    search would be copied and typed into every list loop (about 6 s of compile)."""
    stream(i, te, p.rec, p.img, prm.space.period, prm.flight)
    dv2 = le_wrap(i, te, p.rec, p.img, shear)
    if dv2 != 0.0:  # (the mass row only when i went through the sheared boundary)
        c.sum_mv2 += p.mass[i] * dv2
    return _expired(i, rebuild_list_le(i, te, p.rec, lists, cells, prm.space, prm.rmax, prm.shell, shear), c)


@inlined_ir
def execute_crossing(i, face, te, p, grid, c, prm, shear):
    """Cell crossing of i at te through face ``face`` (2 a + side): into the next cell
    (:func:`granulargas.engine._crossing.cross`) and its best pair updated with the
    layer of cells that became adjacent (:func:`~granulargas.engine._crossing.scan_new_layer`);
    the loop's prediction of i then uses it."""
    stream(i, te, p.rec, p.img, prm.space.period, prm.flight)
    if shear is not None:
        cx_old = grid.cell[i, 0]
        dv2 = cross_le(i, face, te, p.rec, p.img, grid, prm.space, shear)
        if dv2 != 0.0:  # (the mass row only when i went through the sheared boundary)
            c.sum_mv2 += p.mass[i] * dv2
        scan_new_layer_le(i, te, face, cx_old, p.rec, p.count, grid, prm.space, shear)
    else:
        cross(i, face, grid, prm.space)
        scan_new_layer(i, te, face, p.rec, p.count, grid, prm.space, prm.flight)
    c.crossings += 1
    return DONE


@kernel(python=False)
def execute_wall(i, wall, te, p, c, walls, prm, flight, wallkinds, shear, stress, spins, species):
    """Collision of i with wall ``wall`` (2 a + side) at te, by the run's rule at R_eff = R_i,
    m_eff = m_i (rough particles: :func:`granulargas.engine._spin.rough_wall`, except the TC
    model's elastic collisions; a mixture: the normal law of i's species; hard walls at rest;
    other kinds: :func:`execute_wall_kind`, smooth particles only). Returns DONE, TABLE_RANGE
    or COLLAPSE."""
    rec = p.rec
    rule = prm.rule
    stream(i, te, rec, p.img, prm.space.period, flight)
    if wallkinds is not None:
        return execute_wall_kind(i, wall, te, p, c, walls, prm, wallkinds, species)
    a = wall >> 1
    side = wall & 1
    vn = rec[i, 3 + a]
    if (vn < 0.0) if side == 0 else (vn > 0.0):  # moving into the wall
        mi = p.mass[i]
        if rule.tc_time > 0.0 and te - p.lastcoll[i] < rule.tc_time or abs(vn) < rule.elastic_below:
            eps = 1.0
        else:
            eps_wall, k_wall = wall_law(rule.wall_eps, rule.prefactor, species, i)
            eps = restitution(rule.kind, eps_wall, k_wall, rule.inv_h, rule.coeffs,
                              abs(vn), rec[i, 7], mi)
            if eps < 0.0:
                c.err_i = i
                c.err_j = -1
                return TABLE_RANGE
        if spins is not None:
            elastic = rule.tc_time > 0.0 and te - p.lastcoll[i] < rule.tc_time
            loss, impulse, drot = bounce_rough(i, a, side, eps, rec, p.mass, spins, elastic)
            c.sum_mv2 -= 2.0 * drot
        else:
            v_new, loss, impulse = wall_collision(vn, mi, eps)
            if stress is not None:
                dv = v_new - vn
                stress_jump(stress, mi, peculiar_x(i, rec, shear), rec[i, 4], rec[i, 5], dv if a == 0 else 0.0,
                            dv if a == 1 else 0.0, dv if a == 2 else 0.0)
            rec[i, 3 + a] = v_new
        c.dissipated += loss
        c.sum_mv2 -= 2.0 * loss
        walls.impulse[a, side] += impulse
        p.count[i] += 1
        c.wall_collisions += 1
        _collapse_watch(i, te, p, prm)
        if p.rapid[i] >= prm.collapse_count:
            c.err_i = i
            c.err_j = -1
            return COLLAPSE
    return DONE


@inlined
def execute_wall_kind(i, wall, te, p, c, walls, prm, spec, species):
    """Collision of i (streamed to te) with wall ``wall`` of kind ``spec.kind[a, side]``
    (:mod:`granulargas.engine._walls`): hard (at rest), thermal (outgoing velocity drawn
    from the wall's Maxwellian flux) or vibrating (the rule at the normal speed relative to
    the wall, the wall's velocity at te; a mixture: the law of i's species). The energy a
    thermal or vibrating wall gives the
    gas is added to ``walls.work``. A re-check event (tag bit ``RECHECK``) changes nothing.
    Inlined into :func:`execute_wall`: a second call, which passes the particle and parameter
    records again, cost about as much as the collision itself."""
    if wall & RECHECK:
        walls.rechecks[0] += 1
        return DONE
    rec = p.rec
    rule = prm.rule
    a = wall >> 1
    side = wall & 1
    kind = spec.kind[a, side]
    vn = rec[i, 3 + a]
    mi = p.mass[i]
    if kind == THERMAL:
        if not ((vn < 0.0) if side == 0 else (vn > 0.0)):
            return DONE
        out, t1, t2 = thermal_velocity(spec.seed, c.wall_collisions, math.sqrt(spec.temperature[a, side] / mi))
        e_old = rec[i, 3] * rec[i, 3] + rec[i, 4] * rec[i, 4] + rec[i, 5] * rec[i, 5]
        rec[i, 3 + a] = out if side == 0 else -out
        m = 0
        for b in range(prm.space.dims):
            if b != a:
                rec[i, 3 + b] = t1 if m == 0 else t2
                m += 1
        e_new = rec[i, 3] * rec[i, 3] + rec[i, 4] * rec[i, 4] + rec[i, 5] * rec[i, 5]
        walls.work[a, side] += 0.5 * mi * (e_new - e_old)
        walls.impulse[a, side] += mi * (abs(vn) + out)
        c.sum_mv2 += mi * (e_new - e_old)
    else:
        _, wv, _ = wall_motion(spec, a, side, te)
        u = vn - wv
        if (u >= 0.0) if side == 0 else (u <= 0.0):  # not moving into the wall
            return DONE
        g = abs(u)
        if rule.tc_time > 0.0 and te - p.lastcoll[i] < rule.tc_time or g < rule.elastic_below:
            eps = 1.0
        else:
            eps_wall, k_wall = wall_law(rule.wall_eps, rule.prefactor, species, i)
            eps = restitution(rule.kind, eps_wall, k_wall, rule.inv_h, rule.coeffs, g, rec[i, 7], mi)
            if eps < 0.0:
                c.err_i = i
                c.err_j = -1
                return TABLE_RANGE
        v_new, loss, work, impulse = moving_wall_collision(vn, wv, eps, mi, side)
        rec[i, 3 + a] = v_new
        c.dissipated += loss
        c.sum_mv2 += mi * (v_new * v_new - vn * vn)
        walls.impulse[a, side] += impulse
        if kind == VIBRATING:
            walls.work[a, side] += work
    p.count[i] += 1
    c.wall_collisions += 1
    _collapse_watch(i, te, p, prm)
    if p.rapid[i] >= prm.collapse_count:
        c.err_i = i
        c.err_j = -1
        return COLLAPSE
    return DONE


@kernel(python=False)
def execute_kick(t, p, ev, lists, onlists, oncells, cal, c, prm, contacts, shear, stress, spins):
    """Driving step at t: every particle streamed to t and kicked (:mod:`_drive`, eq. 1; rough
    particles' spins too, :func:`granulargas.engine._spin.kick_spins`); every event predicted
    anew and the calendar rebuilt (O(N))."""
    rec = p.rec
    n = rec.shape[0]
    for i in range(n):
        stream(i, t, rec, p.img, prm.space.period, prm.flight)
    c.injected += kick_velocities(rec, 3, p.mass, p.ident, prm.space.dims, prm.kick_seed,
                                  c.kick_step, prm.kick_scale)
    if spins is not None:
        c.injected += kick_rough(rec, p.mass, p.ident, prm.space.dims, spins, prm.kick_seed, c.kick_step)
    s = 0.0
    for i in range(n):
        s += p.mass[i] * (rec[i, 3] * rec[i, 3] + rec[i, 4] * rec[i, 4] + rec[i, 5] * rec[i, 5])
    c.sum_mv2 = s
    c.kick_step += 1
    c.kicks += 1
    if stress is not None:
        stress_sums(rec, p.mass, shear, stress[0].s)
    predict_all(t, rec, p.count, ev, lists, onlists, oncells, prm.space, prm.half_shell, contacts, prm.flight,
                prm.wallkinds, shear, cal.qt)
    return DONE if cal_build(t, cal) else CALENDAR


@kernel(python=False)
def execute_rescale(t, p, ev, lists, onlists, oncells, cal, c, prm, shear, stress):
    """Thermostat step at t (sheared runs): every particle streamed to t, the peculiar
    velocities c = v - a (y - L_y/2) x scaled so that m <c^2>/d is the thermostat's
    temperature (a Gaussian thermostat applied at discrete times), every event predicted anew
    and the calendar rebuilt. The energy taken out counts as negative injected energy."""
    rec = p.rec
    n = rec.shape[0]
    for i in range(n):
        stream(i, t, rec, p.img, prm.space.period, prm.flight)
    e2 = 0.0
    for i in range(n):
        cx = peculiar_x(i, rec, shear)
        e2 += p.mass[i] * (cx * cx + rec[i, 4] * rec[i, 4] + rec[i, 5] * rec[i, 5])
    target = shear.thermostat[1] * prm.space.dims * n
    scale = math.sqrt(target / e2) if e2 > 0.0 else 1.0
    s = 0.0
    for i in range(n):
        u = rec[i, 3] - peculiar_x(i, rec, shear)
        rec[i, 3] = u + scale * (rec[i, 3] - u)
        rec[i, 4] *= scale
        rec[i, 5] *= scale
        s += p.mass[i] * (rec[i, 3] * rec[i, 3] + rec[i, 4] * rec[i, 4] + rec[i, 5] * rec[i, 5])
    c.injected += 0.5 * (target - e2)
    c.sum_mv2 = s
    shear.rescales[0] += 1
    if stress is not None:
        stress_sums(rec, p.mass, shear, stress[0].s)
    predict_all(t, rec, p.count, ev, lists, onlists, oncells, prm.space, prm.half_shell, None, prm.flight,
                prm.wallkinds, shear, cal.qt)
    return DONE if cal_build(t, cal) else CALENDAR


# -------------------------------------------------------------------- prefetch
@inlined_ir
def _prefetch_particle(i, p, ev, lists, cal):
    """Prefetch hints for the per-particle rows an event of particle i touches (not
    ``img``, which only a wrap through the box writes)."""
    prefetch(p.rec, i)
    prefetch(lists.centre, i)
    prefetch(p.mass, i)
    prefetch(p.count, i)
    prefetch(ev.tag, i)
    prefetch(p.lastcoll, i)
    prefetch(p.rapid, i)
    prefetch(lists.nbl, i)
    prefetch(lists.nbn, i)
    prefetch(ev.partner, i)
    prefetch(cal.qt, i)
    prefetch(cal.where, i)


@inlined_ir
def prefetch_next_cells(i1, p, ev, grid, cal, prm, shear):
    """Prefetch hints for the next event of the cell-crossing mode: the rows of particle
    i1 and its partner, the cell heads around i1, and the rows of the likely event after
    it (``shear``: the cells of the sliding rows' windows). Returns that event's guessed
    particle (-1: none). (A particle's cell, event and
    calendar data share one row of ``grid.cell``: :func:`~granulargas.engine._crossing.particle_rows`.)"""
    rec = p.rec
    p1 = ev.partner[i1]
    prefetch(grid.cell, i1)
    if shear is None:
        prefetch_around(i1, grid, prm.space)
    else:
        prefetch_around_le(i1, grid, prm.space, shear)
    if p1 >= 0:
        prefetch(rec, p1)
        prefetch(grid.cell, p1)
        prefetch(p.mass, p1)
        prefetch(p.count, p1)
        prefetch(p.lastcoll, p1)
        prefetch(p.rapid, p1)
        prefetch(p.mass, i1)
        prefetch(p.lastcoll, i1)
        prefetch(p.rapid, i1)
        prefetch(p.count, i1)
    i2 = cal_after_next(cal, p1)
    if i2 >= 0:
        prefetch(rec, i2)
        prefetch(grid.cell, i2)
    return i2


@inlined_ir
def prefetch_next_lists(i1, p, ev, lists, cells, cal, prm, shear):
    """Prefetch hints for the next event, particle i1 (no effect on results).

    The rows of its partner, the records of its neighbours, for a list expiry the
    cell rows around it and its neighbours' list rows (the rebuild rewrites the
    lists of neighbours that leave or join, mostly among the present ones), and
    the rows of the likely event after it (:func:`cal_after_next`), so that their
    cache misses overlap with work. Returns the guessed particle of the event
    after next (-1: none), for the profiler.
    """
    rec = p.rec
    nbl = lists.nbl
    nbn = lists.nbn
    p1 = ev.partner[i1]
    if p1 >= 0:
        _prefetch_particle(p1, p, ev, lists, cal)
        prefetch(p.mass, i1)  # the rows only a collision of i1 touches
        prefetch(p.lastcoll, i1)
        prefetch(p.rapid, i1)
        prefetch(p.count, i1)
    elif p1 == EXPIRY:
        dt1 = cal_next_time(cal) - rec[i1, 6]
        if prm.space.shear is None:  # (sheared: the centres' cells are counted in the rows' frames)
            prefetch_cells(rec[i1, 0] + rec[i1, 3] * dt1, rec[i1, 1] + rec[i1, 4] * dt1,
                           rec[i1, 2] + rec[i1, 5] * dt1,
                           rec[i1, 7] + prm.rmax + prm.shell, prm.space, cells, lists.stencil)
        for k in range(nbn[i1]):
            prefetch(nbl, nbl[i1, k])
            prefetch(nbn, nbl[i1, k])
        prefetch(lists.centre, i1)  # the rebuild finds its old cell from it
    for k in range(nbn[i1]):
        prefetch(rec, nbl[i1, k])
    prefetch(cal.where, i1)
    if shear is not None:  # the list's build time, read by the expiry's prediction
        prefetch(shear.built, i1)
    i2 = cal_after_next(cal, p1)
    if i2 >= 0:
        prefetch(rec, i2)
        prefetch(nbl, i2)
        prefetch(nbn, i2)
        prefetch(ev.partner, i2)
        prefetch(ev.tag, i2)
        prefetch(lists.centre, i2)
        if shear is not None:
            prefetch(shear.built, i2)
    return i2


# ------------------------------------------------------------------------ loop
@kernel
def advance(engine, onlists, oncells, prm, until, max_events, max_collisions, probe, shear=None, stress=None,
            walls=None):
    """Process events in time order until ``until`` (or a budget); see module doc.

    Parameters
    ----------
    engine : Engine
        The state (:mod:`granulargas.engine._state`), changed in place; its
        counters record carries the time, observables sums and event counts.
    prm : Params
        Rule, geometry, list and driving parameters.
    until : float
        Process every event with time <= until; then time = until (status DONE).
    max_events : int
        Event budget of this call (status BUDGET when used).
    max_collisions : int
        Stop right after the pair collision that makes ``collisions`` reach it.
    probe : None or int64 array
        None: the production build. An array of :data:`_probe.PROBE_SIZE`
        compiles the cycle counters in (``scripts/profiling/profile_loop.py``).
    shear : None or ShearGeometry
        Lees-Edwards boundaries (``prm.space.shear``; :mod:`granulargas.engine._shear`),
        an argument of its own so that numba removes its branches when it is None.
    stress : None or STRESS record
        The pressure tensor's sums (``engine.stress``), likewise.
    walls : None or Walls
        ``engine.walls`` in a box with wall axes; None without any (no wall event can occur),
        so that the build of a box without walls carries none of the walls' code.

    Returns
    -------
    int
        Status code (module doc).
    """
    p = engine.particles
    ev = engine.events
    lists = engine.lists
    cells = engine.cells
    cal = engine.calendar
    c = engine.counters[0]
    contacts = engine.contacts
    spins = engine.spins
    species = engine.species
    rec = p.rec
    time = c.time
    zero_advance = 0
    zero_limit = 1000 + rec.shape[0]
    events_end = c.events + max_events
    status = DONE
    clock = probe_start(probe)
    guess = -1  # the prefetch's guess of the event after next (checked by the profiler)
    pending = -1
    while True:
        if c.events >= events_end:
            status = BUDGET
            break
        # ---- pop (the peek after the previous event has opened the window)
        i = cal_first(cal)
        if i < 0:
            if i == -2:
                status = CALENDAR
            break
        te = cal_next_time(cal)  # = qt[i]: the heap root's copy
        if te > until or te == math.inf:
            break
        # ---- validate: time order, no endless zero-time streaks
        if te <= time:
            if te < time:
                c.err_i = i
                c.err_j = ev.partner[i]
                status = WATCHDOG
                break
            zero_advance += 1
            if zero_advance > zero_limit:
                c.err_i = i
                c.err_j = ev.partner[i]
                status = WATCHDOG
                break
        else:
            zero_advance = 0
        c.kin_int += c.sum_mv2 * (te - time)
        integrate_stress(stress, te - time, shear)
        time = te
        j = np.int64(ev.partner[i])  # one signature for the callees (partner is int32)
        probe_guess(probe, i == pending)
        clock = tick(probe, POP, clock)
        # ---- dispatch
        if j >= 0 and p.count[j] == ev.tag[i]:
            if onlists is not None:  # j's list row is in cache: start the misses of predict(j)
                for k in range(lists.nbn[j]):
                    prefetch(rec, lists.nbl[j, k])
            status = execute_pair(i, j, te, p, ev, lists, onlists, oncells, cal, c, prm, contacts, shear, stress,
                                  spins, species)
            clock = tick(probe, COLLIDE, clock)
            if status != DONE:
                break
        elif j == EXPIRY or j == CROSS:  # the one of the two this mode has
            if onlists is not None:
                if shear is not None:
                    status = execute_expiry_le(i, te, p, lists, cells, c, prm, shear)
                else:
                    status = execute_expiry(i, te, p, lists, cells, c, prm)
            if oncells is not None:
                status = execute_crossing(i, ev.tag[i], te, p, lists, c, prm, shear)
            clock = tick(probe, REBUILD, clock)
            if status != DONE:
                break
        elif j == WALL:  # (never without wall axes: that build has no walls)
            if walls is not None:
                status = execute_wall(i, ev.tag[i], te, p, c, walls, prm, prm.flight, prm.wallkinds, shear, stress,
                                      spins, species)
                clock = tick(probe, P_WALL, clock)
                if status != DONE:
                    if status == COLLAPSE:
                        ti = predict_after_collapse(i, te, p, ev, lists, onlists, oncells, prm, contacts, shear)
                        if not cal_update(i, ti, cal):
                            status = CALENDAR
                        c.events += 1
                    break
        else:
            # ---- stale event: the partner changed course; just re-predict
            stream(i, te, rec, p.img, prm.space.period, prm.flight)
            c.stale += 1
            clock = tick(probe, P_STALE, clock)
        # ---- re-predict the particle of the event
        if onlists is not None:
            ti = predict_listed(i, te, rec, p.count, ev, lists, prm.space, prm.half_shell, contacts, prm.flight,
                                prm.wallkinds, shear)
        if oncells is not None:
            ti = predict_cells(i, te, rec, p.count, ev, lists, prm.space, prm.flight, prm.wallkinds, shear)
        clock = tick(probe, PREDICT, clock)
        if not cal_update_root(i, ti, cal):  # i's event is the small heap's root
            status = CALENDAR
            break
        c.events += 1
        clock = tick(probe, UPDATE, clock)
        # ---- prefetch hints for the next events (no effect on results)
        i1 = cal_first(cal)
        clock = tick(probe, PEEK, clock)
        if i1 == -2:
            status = CALENDAR
            break
        cal_look_ahead(cal)
        pending = guess
        guess = -1
        if i1 >= 0:
            if onlists is not None:
                guess = prefetch_next_lists(i1, p, ev, lists, cells, cal, prm, shear)
            if oncells is not None:
                guess = prefetch_next_cells(i1, p, ev, lists, cal, prm, shear)
        clock = tick(probe, PREFETCH, clock)
        if c.collisions >= max_collisions:
            status = MAX_COLLISIONS
            break
    c.time = time
    if status == DONE and until < math.inf:
        c.kin_int += c.sum_mv2 * (until - time)
        integrate_stress(stress, until - time, shear)
        c.time = until
    return status


@kernel
def advance_driven(engine, onlists, oncells, prm, until, max_events, max_collisions, probe, shear=None, stress=None,
                   walls=None):
    """:func:`advance` with the white-noise driving: the driving step is a global event.

    Runs :func:`advance` up to the next driving step (k + 1/2) dt_k (:func:`predict_kick`;
    events at the same time come first), executes it (:func:`execute_kick`, one
    event) and goes on, until ``until`` or a budget. A step due at ``until``
    itself is executed. Same arguments and status codes as :func:`advance`.
    """
    c = engine.counters[0]
    events_end = c.events + max_events
    while True:
        t_kick = predict_kick(c, prm)
        stop = t_kick if t_kick < until else until
        status = advance(engine, onlists, oncells, prm, stop, events_end - c.events, max_collisions, probe, shear,
                         stress, walls)
        if status != DONE or t_kick > until:
            return status
        status = execute_kick(c.time, engine.particles, engine.events, engine.lists, onlists, oncells,
                              engine.calendar, c, prm, engine.contacts, shear, stress, engine.spins)
        c.events += 1
        if status != DONE or c.time >= until:
            return status
        if c.events >= events_end:
            return BUDGET


@kernel
def advance_sheared(engine, onlists, oncells, prm, until, max_events, max_collisions, probe, shear, stress,
                    walls=None):
    """:func:`advance` under Lees-Edwards boundaries, with their global events: the slides of
    the cell mode (:func:`granulargas.engine._shear.slide_scan`), the thermostat's rescaling
    (:func:`execute_rescale`) and the white-noise driving's steps (:func:`execute_kick`).
    Events of the loop at the same time come first; a global event due at ``until`` itself
    is executed. Same arguments and status codes as :func:`advance`."""
    c = engine.counters[0]
    sh = shear
    events_end = c.events + max_events
    while True:
        t_kick = predict_kick(c, prm)
        t_slide = next_slide(sh, oncells)
        t_rescale = next_rescale(sh)
        t_next = min(t_kick, t_slide, t_rescale)
        stop = t_next if t_next < until else until
        status = advance(engine, onlists, oncells, prm, stop, events_end - c.events, max_collisions, probe, shear,
                         stress, walls)
        if status != DONE or t_next > until:
            return status
        clock = probe_start(probe)
        if t_slide == t_next:
            if oncells is not None:  # slides only in the cell mode
                if not slide_scan(c.time, engine.particles.rec, engine.particles.img, engine.particles.count,
                                  engine.events, engine.lists, prm.space, engine.calendar, sh):
                    return CALENDAR
        elif t_rescale == t_next:
            status = execute_rescale(c.time, engine.particles, engine.events, engine.lists, onlists, oncells,
                                     engine.calendar, c, prm, sh, stress)
        else:
            status = execute_kick(c.time, engine.particles, engine.events, engine.lists, onlists, oncells,
                                  engine.calendar, c, prm, engine.contacts, sh, stress,
                                  engine.spins)
        tick(probe, GLOBAL, clock)
        c.events += 1
        if status != DONE or c.time >= until:
            return status
        if c.events >= events_end:
            return BUDGET


@kernel
def synchronised(rec, img, period, t, flight, out_r, out_img, out_v):
    """Positions, images and velocities of all particles streamed to time t on their flight
    (no side effect).

    Positions land in [0, L) on periodic axes: one wrap suffices because no
    particle is more than shell/2 from its list centre, which lies in the box
    (cell-crossing mode: no particle is beyond its cell by more than round-off).
    Wall axes (period inf) are not wrapped. Straight flights keep the velocities.
    """
    for i in range(rec.shape[0]):
        dt = t - rec[i, 6]
        for a in range(3):
            if flight is None:
                x = rec[i, a] + rec[i, 3 + a] * dt
                out_v[i, a] = rec[i, 3 + a]
            else:
                w = rec[i, 3 + a] + flight[a] * dt
                x = rec[i, a] + 0.5 * (rec[i, 3 + a] + w) * dt
                out_v[i, a] = w
            k = img[i, a]
            if x >= period[a]:
                x -= period[a]
                k += 1
            elif x < 0.0:
                x += period[a]
                k -= 1
                if x >= period[a]:  # -tiny + L rounds to L
                    x = 0.0
                    k += 1
            out_r[i, a] = x
            out_img[i, a] = k
