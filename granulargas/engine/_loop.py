"""The compiled event loop (numba): pop, validate, execute, re-predict.

One event per particle (Smallenburg 2022; Paul 2007): particle i stores the
earliest of (a) its predicted collision with a particle of its neighbour list
and (b) the moment it leaves the sphere of radius shell/2 around its list
centre ("list expiry"). The event records the partner's collision counter at
prediction time; a popped event whose partner has collided since is stale and
is simply re-predicted. A pair collision needs to be scheduled by only one of
the two: whichever changes its velocity first re-predicts against all its
neighbours, the other included.

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
the loop issues prefetch hints (:mod:`granulargas.engine._prefetch`, no effect
on results) for every per-particle row of the next event's particle and its
partner, the records of its neighbours, and the rows of the likely event after
it (the earliest child of the small heap's root, passing over the event of the
next particle's partner, which the next collision re-predicts: that guess is
right for 97-98 % of events, ``scripts/profile_loop.py``), so that
these misses overlap with the current work; before a list expiry it also
prefetches the cell rows around the particle and its neighbours' list rows.
Where the time goes per part of the loop: ``python scripts/profile_loop.py 1e4
1e6`` (cycle counters); two source trees compared by alternated runs:
``python scripts/bench_ab.py OTHER_TREE . --sizes 1e4 1e6``; the numbers are in
docs/performance.md.

Status codes (the Python driver raises ``granulargas.errors`` exceptions):
0 reached ``until``; 1 event budget of this chunk used (call again);
2 ``max_collisions`` reached; 10 a neighbour list is full, 11 a cell is full
(enlarge, call again: nothing was lost); 20 inelastic collapse (a particle collided
``collapse_count`` times in a row less than ``collapse_dt`` after its previous
collision); 21 impact beyond the restitution table; 30 watchdog (an event in
the past or an endless run of zero-time events: round-off trouble); 31 more
simultaneous events than the event calendar's window holds.
"""

import math

import numpy as np

from granulargas._numba import jit
from granulargas.engine._cells import prefetch_cells, rebuild_list
from granulargas.engine._collide import restitution
from granulargas.engine._geometry import collision_delay, exit_delay, min_image
from granulargas.engine._prefetch import prefetch
from granulargas.engine._calendar import cal_look_ahead, cal_peek, cal_update

DONE = 0
BUDGET = 1
MAX_COLLISIONS = 2
COLLAPSE = 20
TABLE_RANGE = 21
WATCHDOG = 30
CALENDAR = 31

# indices into the float and int scalar arrays
S_TIME, S_DISSIPATED, S_VIRIAL, S_KIN_INT, S_SUM_MV2 = 0, 1, 2, 3, 4
I_COLLISIONS, I_EVENTS, I_ERR_I, I_ERR_J, I_EXPIRIES, I_STALE = 0, 1, 2, 3, 4, 5
# indices into the float parameter array
P_EPS, P_TC, P_PREFACTOR, P_INV_H, P_SHELL, P_COLLAPSE_DT, P_RMAX = 0, 1, 2, 3, 4, 5, 6
# columns of a particle record
T_COL, R_COL = 6, 7


@jit(inline="always")
def stream(i, t, rec, img, box):
    """Move particle i on its straight line to time t, wrapping into the box."""
    dt = t - rec[i, 6]
    for a in range(3):
        x = rec[i, a] + rec[i, 3 + a] * dt
        if x >= box[a]:
            x -= box[a]
            img[i, a] += 1
        elif x < 0.0:
            x += box[a]
            img[i, a] -= 1
        rec[i, a] = x
    rec[i, 6] = t


@jit(inline="always")
def _prefetch_particle(i, rec, img, centre, mass, count, pcount, lastcoll, rapid, nbl, nbn,
                       partner, qt, qwhere):
    """Prefetch hints for the per-particle rows an event of particle i touches (not
    ``img``, which only a wrap through the box writes)."""
    prefetch(rec, i)
    prefetch(centre, i)
    prefetch(mass, i)
    prefetch(count, i)
    prefetch(pcount, i)
    prefetch(lastcoll, i)
    prefetch(rapid, i)
    prefetch(nbl, i)
    prefetch(nbn, i)
    prefetch(partner, i)
    prefetch(qt, i)
    prefetch(qwhere, i)


@jit
def predict(i, t, rec, centre, count, nbl, nbn, partner, pcount, box, half_shell):
    """Earliest event of particle i (streamed to t): collision or list expiry.

    Sets ``partner[i]`` (-1 for expiry) and ``pcount[i]``; returns the time.
    """
    xi = rec[i, 0]
    yi = rec[i, 1]
    zi = rec[i, 2]
    vx = rec[i, 3]
    vy = rec[i, 4]
    vz = rec[i, 5]
    ri = rec[i, 7]
    best = t + exit_delay(min_image(xi - centre[i, 0], box[0]),
                          min_image(yi - centre[i, 1], box[1]),
                          min_image(zi - centre[i, 2], box[2]), vx, vy, vz, half_shell)
    p = -1
    for k in range(nbn[i]):
        j = nbl[i, k]
        dtj = t - rec[j, 6]
        s = collision_delay(min_image(xi - (rec[j, 0] + rec[j, 3] * dtj), box[0]),
                            min_image(yi - (rec[j, 1] + rec[j, 4] * dtj), box[1]),
                            min_image(zi - (rec[j, 2] + rec[j, 5] * dtj), box[2]),
                            vx - rec[j, 3], vy - rec[j, 4], vz - rec[j, 5], ri + rec[j, 7])
        tc = t + s
        better = tc < best
        best = tc if better else best
        p = j if better else p
    partner[i] = p
    pcount[i] = count[p] if p >= 0 else 0
    return best


@jit
def predict_all(t, rec, centre, count, nbl, nbn, partner, pcount, box, half_shell, times):
    """Predict the event of every particle (all clocks at t) into ``times``."""
    for i in range(rec.shape[0]):
        times[i] = predict(i, t, rec, centre, count, nbl, nbn, partner, pcount, box, half_shell)


@jit
def advance(rec, img, centre, mass, count, partner, pcount, lastcoll, rapid,
            nbl, nbn, scratch, stencil, cell_ids, cell_n, cell_of,
            qt, chunks, qwhere, small, buckets, qi, qf,
            box, ncell, kind, fpar, coeffs, collapse_count, until, max_events, max_collisions,
            scal, iscal):
    """Process events in time order until ``until`` (or a budget); see module doc.

    ``scal`` = [time, dissipated energy, collisional virial sum, integral of
    sum m v^2 dt, sum m v^2]; ``iscal`` = [collisions, events, i, j of an
    error, list expiries, stale events]. Returns a status code.
    """
    eps_const = fpar[P_EPS]
    tc_time = fpar[P_TC]
    prefactor = fpar[P_PREFACTOR]
    inv_h = fpar[P_INV_H]
    shell = fpar[P_SHELL]
    half_shell = 0.5 * shell * (1.0 - 1e-9)  # margin against round-off in |r - c|
    collapse_dt = fpar[P_COLLAPSE_DT]
    rmax = fpar[P_RMAX]
    time = scal[S_TIME]
    zero_advance = 0
    zero_limit = 1000 + rec.shape[0]
    events_end = iscal[I_EVENTS] + max_events
    status = DONE
    while True:
        if iscal[I_EVENTS] >= events_end:
            status = BUDGET
            break
        i = cal_peek(qt, chunks, qwhere, small, buckets, qi, qf)
        if i < 0:
            if i == -2:
                status = CALENDAR
            break
        te = small[0, 0]  # = qt[i]: the heap root's copy, in cache
        if te > until or te == math.inf:
            break
        if te <= time:
            if te < time:
                iscal[I_ERR_I] = i
                iscal[I_ERR_J] = partner[i]
                status = WATCHDOG
                break
            zero_advance += 1
            if zero_advance > zero_limit:
                iscal[I_ERR_I] = i
                iscal[I_ERR_J] = partner[i]
                status = WATCHDOG
                break
        else:
            zero_advance = 0
        scal[S_KIN_INT] += scal[S_SUM_MV2] * (te - time)
        time = te
        j = np.int64(partner[i])  # one signature for the callees (partner is int32)
        if j >= 0 and count[j] == pcount[i]:
            # ---- pair collision: validate, execute, re-predict both
            for k in range(nbn[j]):  # j's list row is in cache: start the misses of predict(j)
                prefetch(rec, nbl[j, k])
            stream(i, te, rec, img, box)
            stream(j, te, rec, img, box)
            dx = min_image(rec[i, 0] - rec[j, 0], box[0])
            dy = min_image(rec[i, 1] - rec[j, 1], box[1])
            dz = min_image(rec[i, 2] - rec[j, 2], box[2])
            ux = rec[i, 3] - rec[j, 3]
            uy = rec[i, 4] - rec[j, 4]
            uz = rec[i, 5] - rec[j, 5]
            b = dx * ux + dy * uy + dz * uz
            if b < 0.0:
                dist = math.sqrt(dx * dx + dy * dy + dz * dz)
                inv = 1.0 / dist
                nx = dx * inv
                ny = dy * inv
                nz = dz * inv
                un = b * inv  # normal relative velocity, < 0
                mi = mass[i]
                mj = mass[j]
                msum = mi + mj
                m_eff = mi * mj / msum
                if tc_time > 0.0 and (te - lastcoll[i] < tc_time or te - lastcoll[j] < tc_time):
                    eps = 1.0
                else:
                    r_eff = rec[i, 7] * rec[j, 7] / (rec[i, 7] + rec[j, 7])
                    eps = restitution(kind, eps_const, prefactor, inv_h, coeffs, -un, r_eff,
                                      m_eff)
                    if eps < 0.0:
                        iscal[I_ERR_I] = i
                        iscal[I_ERR_J] = j
                        status = TABLE_RANGE
                        break
                f = (1.0 + eps) * un / msum
                fi = f * mj
                fj = f * mi
                rec[i, 3] -= fi * nx
                rec[i, 4] -= fi * ny
                rec[i, 5] -= fi * nz
                rec[j, 3] += fj * nx
                rec[j, 4] += fj * ny
                rec[j, 5] += fj * nz
                de = 0.5 * (1.0 - eps * eps) * m_eff * un * un
                scal[S_DISSIPATED] += de
                scal[S_SUM_MV2] -= 2.0 * de
                scal[S_VIRIAL] -= (1.0 + eps) * m_eff * un * dist
                count[i] += 1
                count[j] += 1
                iscal[I_COLLISIONS] += 1
                # inelastic collapse watch: runs of ever faster re-collisions
                if te - lastcoll[i] < collapse_dt:
                    rapid[i] += 1
                else:
                    rapid[i] = 0
                if te - lastcoll[j] < collapse_dt:
                    rapid[j] += 1
                else:
                    rapid[j] = 0
                lastcoll[i] = te
                lastcoll[j] = te
                tj = predict(j, te, rec, centre, count, nbl, nbn, partner, pcount, box,
                             half_shell)
                if not cal_update(j, tj, qt, chunks, qwhere, small, buckets, qi, qf):
                    status = CALENDAR
                    break
                if rapid[i] >= collapse_count or rapid[j] >= collapse_count:
                    ti = predict(i, te, rec, centre, count, nbl, nbn, partner, pcount, box,
                                 half_shell)
                    if not cal_update(i, ti, qt, chunks, qwhere, small, buckets, qi, qf):
                        status = CALENDAR
                    iscal[I_EVENTS] += 1
                    iscal[I_ERR_I] = i
                    iscal[I_ERR_J] = j
                    status = COLLAPSE
                    break
        elif j < 0:
            # ---- list expiry: new centre and list for i
            stream(i, te, rec, img, box)
            st = rebuild_list(i, rec, centre, rmax, shell, box, ncell, cell_ids, cell_n, cell_of,
                              nbl, nbn, scratch, stencil)
            if st != 0:
                iscal[I_ERR_I] = i
                iscal[I_ERR_J] = -1
                status = st
                break
            iscal[I_EXPIRIES] += 1
        else:
            # ---- stale event: the partner changed course; just re-predict
            stream(i, te, rec, img, box)
            iscal[I_STALE] += 1
        ti = predict(i, te, rec, centre, count, nbl, nbn, partner, pcount, box, half_shell)
        if not cal_update(i, ti, qt, chunks, qwhere, small, buckets, qi, qf):
            status = CALENDAR
            break
        iscal[I_EVENTS] += 1
        # ---- prefetch hints (no effect on results): the next event's partner and
        # neighbour records, and the rows of the likely event after it (the earliest
        # child of the root), so that their cache misses overlap with work
        i1 = cal_peek(qt, chunks, qwhere, small, buckets, qi, qf)
        if i1 == -2:
            status = CALENDAR
            break
        cal_look_ahead(qt, chunks, qwhere, qi)
        if i1 >= 0:
            p1 = partner[i1]
            if p1 >= 0:
                _prefetch_particle(p1, rec, img, centre, mass, count, pcount, lastcoll, rapid,
                                   nbl, nbn, partner, qt, qwhere)
                prefetch(mass, i1)  # the rows only a collision of i1 touches
                prefetch(lastcoll, i1)
                prefetch(rapid, i1)
                prefetch(count, i1)
            else:
                dt1 = small[0, 0] - rec[i1, 6]  # small[0, 0] = qt[i1]
                prefetch_cells(rec[i1, 0] + rec[i1, 3] * dt1, rec[i1, 1] + rec[i1, 4] * dt1,
                               rec[i1, 2] + rec[i1, 5] * dt1,
                               rec[i1, 7] + rmax + shell, box, ncell, cell_ids, cell_n, stencil)
                # the rebuild rewrites the lists of neighbours that leave or join, mostly
                # among the present ones, and moves i1's cell slot
                for k in range(nbn[i1]):
                    prefetch(nbl, nbl[i1, k])
                    prefetch(nbn, nbl[i1, k])
                prefetch(cell_of, i1)
            for k in range(nbn[i1]):
                prefetch(rec, nbl[i1, k])
            prefetch(qwhere, i1)
            # the event after i1: the earliest child of the root, except the event of
            # i1's partner, which i1's collision re-predicts (often the partner's copy of
            # the same collision, equal in time up to round-off); then that node's
            # children are candidates too
            size = qi[0]
            c2 = -1
            t2 = math.inf
            cp = -1
            for q in range(1, min(5, size)):
                if small[q, 1] == p1:
                    cp = q
                elif small[q, 0] < t2:
                    t2 = small[q, 0]
                    c2 = q
            if cp > 0:
                for q in range(4 * cp + 1, min(4 * cp + 5, size)):
                    if small[q, 0] < t2:
                        t2 = small[q, 0]
                        c2 = q
            if c2 > 0:
                i2 = int(small[c2, 1])
                prefetch(rec, i2)
                prefetch(nbl, i2)
                prefetch(nbn, i2)
                prefetch(partner, i2)
                prefetch(pcount, i2)
                prefetch(centre, i2)
        if iscal[I_COLLISIONS] >= max_collisions:
            status = MAX_COLLISIONS
            break
    scal[S_TIME] = time
    if status == DONE and until < math.inf:
        scal[S_KIN_INT] += scal[S_SUM_MV2] * (until - time)
        scal[S_TIME] = until
    return status


@jit
def synchronised(rec, img, box, t, out_r, out_img):
    """Positions and images of all particles streamed to time t (no side effect).

    Positions land in [0, L): one wrap suffices because no particle is more than
    shell/2 from its list centre, which lies in the box.
    """
    for i in range(rec.shape[0]):
        dt = t - rec[i, 6]
        for a in range(3):
            x = rec[i, a] + rec[i, 3 + a] * dt
            k = img[i, a]
            if x >= box[a]:
                x -= box[a]
                k += 1
            elif x < 0.0:
                x += box[a]
                k -= 1
                if x >= box[a]:  # -tiny + L rounds to L
                    x = 0.0
                    k += 1
            out_r[i, a] = x
            out_img[i, a] = k
