"""Compiled event calendar: time buckets plus a small heap (numba leaf module).

One scheduled event per particle (time ``qt[i]``). A heap over all N events
costs O(log N) dependent cache misses per update at large N; a calendar
(Paul, J. Comput. Phys. 221, 615 (2007); Smallenburg, Eur. Phys. J. E 45, 22
(2022)) costs O(1):

* time is cut into windows of width w, numbered B(t) = floor((t - t0) / w);
  the events of the *current window* (all with B(t) <= B_cur) sit in a small
  4-ary min-heap ``small`` of (time, id) nodes (a few dozen events, in cache);
* the next ``nb - 1`` windows are *buckets* in a ring (slot B mod nb);
* events beyond the ring wait in an *overflow* bucket (slot ``nb``), which is
  redistributed every half turn of the ring (an overflow event lies at least
  one full turn ahead when placed, so none falls due in between; the cost is
  O(overflow) per ~N events). ``ovf_min`` (a lower bound after removals) lets
  an empty ring jump straight to the earliest overflow event.

A bucket is an unsorted stack of *chunks*, rows of ``chunks`` (next chunk,
then up to CHUNK - 1 particle ids), taken from a free list; ``buckets[b]`` =
(newest chunk, ids in it). Placing an event appends its id (one store, into a
line that recent appends to the same bucket keep in cache); moving an event
does not touch the old bucket at all (*lazy deletion*): ``where[i]`` says where
the event of i lives now, and an id met in bucket b counts only if
``where[id] == b``. (A particle that left b and came back has two entries;
the first moves it to the heap, which sets ``where``, so the second is
skipped.) An entry can be stale only until its bucket is emptied, one turn
at most, when its chunks return to the free list. Compared with doubly
linked lists threaded through the particles, this avoids the three stores
into other particles' rows per update and, when a window opens, the chain
of dependent misses: its ids are read in sequence and their ``qt``/``where``
rows are prefetched together. While the current window's events are
processed, :func:`cal_look_ahead` walks the next bucket's chunks, one per
event, and prefetches its ids' rows, so that the opening finds them in cache
(at N = 10^6, ``scripts/profiling/profile_loop.py``: the peek at the next event from 515
to 395 cycles per event, the whole loop from 9835 to 8648 cycles per collision).

The small heap holds max(1024, N/16) nodes, at least ~20 windows' worth; if a
window would overflow it (a sudden burst of simultaneous events), the width
is halved and all events are placed anew from ``qt``, which always holds every
event time (O(N), rare, self-correcting); only more simultaneous events than
the small heap holds stop the run (status 31). If the chunk pool runs dry
(stale entries pile up), all events are placed anew at the same width, which
keeps only live entries; the pool (N/(CHUNK-1) chunks for live entries, one
partly filled chunk per bucket, and as many again for stale ones) always
suffices for that.

``where[i] >= 0`` is the ring slot (or ``nb`` for overflow) of particle i;
``where[i] < 0`` means it sits in the small heap at node ``-where[i] - 1``.
Taking the earliest event moves the window forward, emptying one bucket into
the small heap per step, until the small heap is non-empty. B(t) is monotone
in t even in floating point, so an event in a later window is never earlier
than one in the current window: the order of events is exact. The width w is
chosen at :func:`cal_build` so that a window holds about ``PER_WINDOW``
events, from the mean event delay (:func:`cal_width`); at the start of a
``Simulation.run`` call the driver places all events anew (O(N), ~80 ms at
N = 10^6) only when w is off from that by more than a factor 2, which keeps w
matched to a cooling gas. Ties are broken by heap node order, deterministically.

The loop inlines the common cases (:func:`cal_first`, :func:`cal_update_root`,
:func:`cal_update_ring`) and calls :func:`cal_peek` / :func:`cal_update` for the rest:
a call passes every array of the calendar as separate arguments, which costs more
than most updates do.

State: :class:`granulargas.engine._state.Calendar` -- ``qt`` (N,) event times,
``chunks`` (pool, CHUNK) i4, ``where`` (N,) i4, ``small`` (capacity, 2) f8 nodes
(time, id), ``buckets`` (nb + 1, 2) i4 (newest chunk, ids in it), and ``state``,
a one-element record (:data:`granulargas.engine._state.CALENDAR_STATE`): ``size``
of the small heap, ``cur`` = B_cur, ``nb`` ring slots, ``nring`` live events in
the ring, ``free`` head of the chunk free list, ``look`` the look-ahead chunk,
``width`` w, ``t0`` and ``ovf_min``.
"""

import math

import numpy as np

from granulargas._numba import inlined, inlined_ir, jit, kernel
from granulargas.engine._prefetch import prefetch
from granulargas.engine._state import CALENDAR_STATE, Calendar, event_rows

PER_WINDOW = 48
CHUNK = 8  # int32 per chunk row: next chunk + 7 ids (32 bytes)


def ring_size(n):
    """Number of ring slots for n particles (a power of two, ~4-8 mean delays)."""
    nb = 64
    while 2 * nb <= 8 * n // PER_WINDOW + 2:
        nb *= 2
    return nb


def pool_size(n, nb, stale=True):
    """Chunks for n live entries plus one partial chunk per bucket (the least that placing
    all events anew needs), and with ``stale`` as many again for stale entries."""
    live = -(-n // (CHUNK - 1))
    return live + nb + 1 + (live if stale else 0)


def allocate_calendar(n, capacity=None, pool=None, qt=None, where=None) -> Calendar:
    """An empty calendar for n particles (fill ``qt``, then :func:`cal_build`).

    ``capacity`` of the small heap: default max(1024, n / 16), some 10^3 times
    what a window holds; when a window would overflow it, the calendar halves
    its width and places all events anew (O(N), self-correcting). ``pool``:
    number of chunks (default :func:`pool_size`; never below what n live
    entries need, so that placing all events anew always succeeds). ``qt``, ``where``:
    arrays of n to use (views into the mode's per-particle rows), else those of new rows
    (:func:`granulargas.engine._state.event_rows`), so that the kernels see one array
    type in every use.
    """
    if qt is None or where is None:
        _, _, where, qt = event_rows(n)
    nb = ring_size(n)
    cap = max(1024, n // 16) if capacity is None else int(capacity)
    chunks = pool_size(n, nb) if pool is None else max(int(pool), pool_size(n, nb, stale=False))
    buf = np.zeros(chunks * CHUNK + 16, dtype=np.int32)
    offset = (-buf.ctypes.data % 32) // 4
    state = np.zeros(1, dtype=CALENDAR_STATE)
    state[0] = (0, 0, nb, 0, -1, -1, 1.0, 0.0, np.inf)
    return Calendar(
        qt=qt,
        chunks=buf[offset : offset + chunks * CHUNK].reshape(chunks, CHUNK),
        where=where,
        small=np.zeros((min(n, cap), 2)),
        buckets=np.zeros((nb + 1, 2), dtype=np.int32),
        state=state,
    )


# ----------------------------------------------------------------- small heap
@inlined
def _sift_up(small, where, k):
    t = small[k, 0]
    p = small[k, 1]
    while k > 0:
        parent = (k - 1) >> 2
        tp = small[parent, 0]
        if tp <= t:
            break
        q = small[parent, 1]
        small[k, 0] = tp
        small[k, 1] = q
        where[int(q)] = -k - 1
        k = parent
    small[k, 0] = t
    small[k, 1] = p
    where[int(p)] = -k - 1


@inlined
def _sift_down(small, where, k, n):
    t = small[k, 0]
    p = small[k, 1]
    while True:
        c = 4 * k + 1
        if c >= n:
            break
        best = c
        tb = small[c, 0]
        e = c + 4 if c + 4 <= n else n
        for q in range(c + 1, e):
            tq = small[q, 0]
            if tq < tb:
                tb = tq
                best = q
        if tb >= t:
            break
        q = small[best, 1]
        small[k, 0] = tb
        small[k, 1] = q
        where[int(q)] = -k - 1
        k = best
    small[k, 0] = t
    small[k, 1] = p
    where[int(p)] = -k - 1


@inlined
def _small_push(i, t, small, where, cs):
    k = cs.size
    if k >= small.shape[0]:
        return False
    cs.size = k + 1
    small[k, 0] = t
    small[k, 1] = i
    _sift_up(small, where, k)
    return True


@inlined_ir
def _small_remove(k, small, where, cs):
    last = cs.size - 1
    cs.size = last
    if k == last:
        return
    old = small[k, 0]
    small[k, 0] = small[last, 0]
    small[k, 1] = small[last, 1]
    if small[k, 0] < old:
        _sift_up(small, where, k)
    else:
        _sift_down(small, where, k, last)


# -------------------------------------------------------------------- buckets
@inlined
def _append(i, b, chunks, buckets, where, cs):
    """Put id i into bucket b; False if the chunk pool is empty."""
    c = buckets[b, 0]
    f = buckets[b, 1]
    if c < 0 or f == CHUNK - 1:
        nc = cs.free
        if nc < 0:
            return False
        cs.free = chunks[nc, 0]
        chunks[nc, 0] = c
        c = nc
        f = 0
        buckets[b, 0] = c
    chunks[c, 1 + f] = i
    buckets[b, 1] = f + 1
    where[i] = b
    return True


@inlined
def _release(c, chunks, cs):
    chunks[c, 0] = cs.free
    cs.free = c


# insert status
_OK, _HEAP_FULL, _POOL_EMPTY = 0, 1, 2


@inlined
def _insert(i, t, cal, cs):
    """Place the event of particle i at time t; returns _OK, _HEAP_FULL or _POOL_EMPTY."""
    cal.qt[i] = t
    x = (t - cs.t0) / cs.width
    cur = cs.cur
    if x < cur + 1:  # B(t) <= B_cur (also for round-off below t0)
        return _OK if _small_push(i, t, cal.small, cal.where, cs) else _HEAP_FULL
    nb = cs.nb
    if x < cur + nb:
        if not _append(i, int(x) & (nb - 1), cal.chunks, cal.buckets, cal.where, cs):
            return _POOL_EMPTY
        cs.nring += 1
    else:
        if not _append(i, nb, cal.chunks, cal.buckets, cal.where, cs):
            return _POOL_EMPTY
        if t < cs.ovf_min:
            cs.ovf_min = t
    return _OK


@kernel(python=False)
def _insert_call(i, t, cal, cs):
    """:func:`_insert` for the cold paths (rebuilds, overflow): one compiled copy that they
    share, which keeps the first compile short (the hot path inlines :func:`_insert`)."""
    return _insert(i, t, cal, cs)


@kernel(python=False)
def _place_all(t0, w, cal):
    """Empty the calendar and insert every event ``qt`` (windows from t0, width w).

    Returns False if the first window overflows the small heap (the pool
    always suffices for live entries alone).
    """
    cs = cal.state[0]
    cs.width = w
    cs.t0 = t0
    cs.ovf_min = math.inf
    cs.size = 0
    cs.cur = 0
    cs.nring = 0
    buckets = cal.buckets
    chunks = cal.chunks
    for b in range(cs.nb + 1):
        buckets[b, 0] = -1
        buckets[b, 1] = 0
    m = chunks.shape[0]
    for c in range(m):
        chunks[c, 0] = c + 1 if c + 1 < m else -1
    cs.free = 0
    cs.look = -1
    qt = cal.qt
    for i in range(qt.shape[0]):
        if _insert_call(i, qt[i], cal, cs) != _OK:
            return False
    return True


@kernel(python=False)
def _replace(failure, cal):
    """Place all events anew from ``qt`` (which always holds every event time).

    After ``failure`` _HEAP_FULL (a window overflowed the small heap) the width
    is halved first, and again until the first window fits; after _POOL_EMPTY
    (the chunk pool ran dry) the width stays and only live entries are kept.
    Returns False if even a tiny w cannot help (more simultaneous events than the
    small heap holds). (One compiled signature: ``failure`` is always an int64.)
    """
    narrow = failure == _HEAP_FULL
    cs = cal.state[0]
    t0 = cs.t0 + cs.cur * cs.width
    w = cs.width
    if not narrow and _place_all(t0, w, cal):
        return True
    for _ in range(200):
        w *= 0.5
        if _place_all(t0, w, cal):
            return True
    return False


@kernel(python=False)
def cal_update(i, t, cal):
    """Set the event time of particle i to t. Returns False on failure (see :func:`_replace`)."""
    cs = cal.state[0]
    where = cal.where
    small = cal.small
    wi = where[i]
    if wi < 0:
        k = -wi - 1
        if small[k, 0] <= t and (t - cs.t0) / cs.width < cs.cur + 1:
            # stays in the window, later: adjust in place
            small[k, 0] = t
            cal.qt[i] = t
            _sift_down(small, where, k, cs.size)
            return True
        _small_remove(k, small, where, cs)
    elif wi < cs.nb:
        cs.nring -= 1  # its old entry goes stale (lazy deletion)
    st = _insert(i, t, cal, cs)
    if st != _OK:
        return _replace(st, cal)
    return True


@inlined
def _ring_append(i, t, cal, cs):
    """The common case of an update: when t falls into the ring (beyond the window) and
    that bucket's newest chunk has room, append i there and return True; else change
    nothing and return False."""
    x = (t - cs.t0) / cs.width
    if not (x >= cs.cur + 1 and x < cs.cur + cs.nb):  # written so that a NaN fails too
        return False
    b = int(x) & (cs.nb - 1)
    c = cal.buckets[b, 0]
    f = cal.buckets[b, 1]
    if c < 0 or f >= CHUNK - 1:
        return False
    cal.qt[i] = t
    cal.chunks[c, 1 + f] = i
    cal.buckets[b, 1] = f + 1
    cal.where[i] = b
    return True


@inlined_ir
def cal_update_root(i, t, cal):
    """:func:`cal_update` of the particle whose event is the earliest (the root of the small
    heap), small enough for the loop to inline: the common case (:func:`_ring_append`,
    then the root node removed; :func:`_small_remove` less its sift-up, which the root
    never needs) here, the rest by the call. Same result as
    :func:`cal_update` in every case."""
    cs = cal.state[0]
    if cal.where[i] == -1 and _ring_append(i, t, cal, cs):
        small = cal.small
        last = cs.size - 1  # the root node removed: the last one sifted down from the top
        cs.size = last
        if last > 0:
            small[0, 0] = small[last, 0]
            small[0, 1] = small[last, 1]
            _sift_down(small, cal.where, 0, last)
        cs.nring += 1
        return True
    return cal_update(i, t, cal)


@inlined_ir
def cal_update_ring(i, t, cal):
    """:func:`cal_update` small enough for the loop to inline, for a particle whose event
    is in the ring (the partner of a collision, mostly): the common case
    (:func:`_ring_append`; the old entry goes stale) here, the rest by the call. Same
    result as :func:`cal_update` in every case."""
    cs = cal.state[0]
    wi = cal.where[i]
    if wi >= 0 and wi < cs.nb and _ring_append(i, t, cal, cs):
        return True
    return cal_update(i, t, cal)


@kernel(python=False)
def _redistribute_overflow(cal):
    """Place the live overflow events anew; returns an insert status (_OK or the failure)."""
    cs = cal.state[0]
    chunks = cal.chunks
    buckets = cal.buckets
    where = cal.where
    nb = cs.nb
    c = buckets[nb, 0]
    f = buckets[nb, 1]
    buckets[nb, 0] = -1
    buckets[nb, 1] = 0
    cs.ovf_min = math.inf
    while c >= 0:
        nx = chunks[c, 0]
        for q in range(1, f + 1):
            j = chunks[c, q]
            if where[j] == nb:
                # a second entry of j (it left the overflow and came back) is placed
                # again only if j went back to the overflow: one more entry there, no harm
                st = _insert_call(np.int64(j), cal.qt[j], cal, cs)
                if st != _OK:
                    return st
        _release(c, chunks, cs)
        c = nx
        f = CHUNK - 1
    return _OK


@inlined_ir
def _open_bucket(slot, cal, cs):
    """Move the live events of ring bucket ``slot`` into the small heap; False if it fills."""
    chunks = cal.chunks
    buckets = cal.buckets
    where = cal.where
    qt = cal.qt
    c = buckets[slot, 0]
    f = buckets[slot, 1]
    buckets[slot, 0] = -1
    buckets[slot, 1] = 0
    while c >= 0:
        nx = chunks[c, 0]
        for q in range(1, f + 1):
            j = chunks[c, q]
            prefetch(qt, j)
            prefetch(where, j)
        if nx >= 0:
            prefetch(chunks, nx)
        for q in range(1, f + 1):
            j = chunks[c, q]
            if where[j] == slot:
                cs.nring -= 1
                if not _small_push(j, qt[j], cal.small, where, cs):
                    return False
        _release(c, chunks, cs)
        c = nx
        f = CHUNK - 1
    return True


@inlined_ir
def cal_look_ahead(cal):
    """Prefetch hints for one chunk of the next bucket (no effect on results).

    Called once per event: while the current window's ~PER_WINDOW events are
    processed, the next bucket's chain of chunks is walked one chunk at a time
    (each chunk prefetched one call before it is read) and the ``qt``/``where``
    rows of its ids are prefetched, so that opening that bucket finds them in
    cache instead of waiting on one miss per chunk. Stale or unused slots only
    prefetch lines in vain.
    """
    cs = cal.state[0]
    c = cs.look
    if c >= 0:
        chunks = cal.chunks
        for q in range(1, CHUNK):
            j = chunks[c, q]
            prefetch(cal.qt, j)
            prefetch(cal.where, j)
        nx = chunks[c, 0]
        if nx >= 0:
            prefetch(chunks, nx)
        cs.look = nx


@inlined_ir
def cal_after_next(cal, skip):
    """Best guess of the particle whose event follows the earliest one, or -1.

    The earliest child of the small heap's root, passing over the event of
    particle ``skip`` (the next event's partner, which that event re-predicts:
    often its copy of the same collision, equal in time up to round-off); when
    ``skip``'s node is a child of the root, its children are candidates too.
    Only a hint for the prefetch: right for 97-98 % of events
    (``scripts/profiling/profile_loop.py``).
    """
    small = cal.small
    size = cal.state[0].size
    c2 = -1
    t2 = math.inf
    cp = -1
    for q in range(1, min(5, size)):
        if small[q, 1] == skip:
            cp = q
        elif small[q, 0] < t2:
            t2 = small[q, 0]
            c2 = q
    if cp > 0:
        for q in range(4 * cp + 1, min(4 * cp + 5, size)):
            if small[q, 0] < t2:
                t2 = small[q, 0]
                c2 = q
    return int(small[c2, 1]) if c2 > 0 else -1


@inlined_ir
def cal_first(cal):
    """:func:`cal_peek` inlined where the window is usually open: the root of the small heap,
    or the call when the heap is empty. (Inlined in IR: a library of its own would be
    compiled for nothing but the two call sites of each build of the loop.)"""
    return int(cal.small[0, 1]) if cal.state[0].size > 0 else cal_peek(cal)


@inlined
def cal_next_time(cal):
    """Time of the earliest event after :func:`cal_peek` returned its particle."""
    return cal.small[0, 0]


@kernel(python=False)
def cal_peek(cal):
    """Particle with the earliest event (moving the window forward as needed).

    Its time is ``qt[result]`` (= :func:`cal_next_time`); every other event is at
    the same time or later. Returns -1 if there is no event (all times inf), -2 on
    failure (see :func:`_replace`).
    """
    cs = cal.state[0]
    nb = cs.nb
    while cs.size == 0:
        st = _OK
        if cs.nring == 0:
            if cs.ovf_min == math.inf:
                return -1
            # nothing live in the ring: jump to the window before the earliest overflow
            # event (stale entries left in the ring are skipped when their bucket opens)
            cs.cur = int((cs.ovf_min - cs.t0) / cs.width) - 1
            st = _redistribute_overflow(cal)
        else:
            cur = cs.cur + 1
            cs.cur = cur
            if not _open_bucket(cur & (nb - 1), cal, cs):
                st = _HEAP_FULL
            elif cur & (nb // 2 - 1) == 0:
                # every half turn of the ring: overflow events were beyond cur + nb when
                # placed, so none is due before the next half turn
                st = _redistribute_overflow(cal)
            if st == _OK:
                # the look-ahead (cal_look_ahead) walks the next bucket meanwhile
                head = cal.buckets[(cur + 1) & (nb - 1), 0]
                cs.look = head
                if head >= 0:
                    prefetch(cal.chunks, head)
        if st != _OK and not _replace(st, cal):
            return -2
    return int(cal.small[0, 1])


@kernel
def cal_width(now, qt):
    """Window width for events ``qt`` at time ``now``: PER_WINDOW events per window on average."""
    n = qt.shape[0]
    total = 0.0
    finite = 0
    for i in range(n):
        if qt[i] < math.inf:
            total += qt[i] - now
            finite += 1
    w = 1.0
    if finite > 0 and total > 0.0:
        w = PER_WINDOW * (total / finite) / finite
    if not w > 0.0:
        w = 1.0
    return w


@kernel
def cal_build(now, cal):
    """Place every particle's event ``qt`` anew (window starts at ``now``; w from the mean delay).

    Returns False on failure (see :func:`_replace`).
    """
    w = cal_width(now, cal.qt)
    if _place_all(now, w, cal):
        return True
    cs = cal.state[0]
    cs.cur = 0
    cs.t0 = now
    cs.width = w
    return _replace(np.int64(_HEAP_FULL), cal)


@jit  # allocates: reference counting on
def cal_check(cal):
    """Invariant checker: True if every event sits where its time says and no chunk is lost."""
    qt = cal.qt
    chunks = cal.chunks
    where = cal.where
    small = cal.small
    buckets = cal.buckets
    cs = cal.state[0]
    n = qt.shape[0]
    nb = cs.nb
    size = cs.size
    cur = cs.cur
    for k in range(size):
        i = int(small[k, 1])
        if where[i] != -k - 1 or small[k, 0] != qt[i]:
            return False
        if (qt[i] - cs.t0) / cs.width >= cur + 1:
            return False
        if k > 0 and small[(k - 1) >> 2, 0] > small[k, 0]:
            return False
    found = np.zeros(n, dtype=np.bool_)
    used = 0
    for b in range(nb + 1):
        c = buckets[b, 0]
        f = buckets[b, 1]
        while c >= 0:
            used += 1
            for q in range(1, f + 1):
                j = chunks[c, q]
                if where[j] == b:
                    found[j] = True
            c = chunks[c, 0]
            f = CHUNK - 1
    free = 0
    c = cs.free
    while c >= 0 and free <= chunks.shape[0]:
        free += 1
        c = chunks[c, 0]
    if used + free != chunks.shape[0]:
        return False
    ring = 0
    for i in range(n):
        b = where[i]
        if b < 0:
            if b < -size:
                return False
            continue
        if b > nb or not found[i]:
            return False
        x = (qt[i] - cs.t0) / cs.width
        if x < cur + 1:
            return False
        if b < nb:
            if x >= cur + nb or (int(x) & (nb - 1)) != b:
                return False
            ring += 1
        elif qt[i] < cs.ovf_min:
            return False
    return ring == cs.nring
