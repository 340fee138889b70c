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
(at N = 10^6, ``scripts/profile_loop.py``: the peek at the next event from 515
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

Scalars: ``qi = [small size, B_cur, nb, live events in the ring, free chunk,
look-ahead chunk]``,
``qf = [w, t0, ovf_min]``.
"""

import math

import numpy as np

from granulargas._numba import jit
from granulargas.engine._prefetch import prefetch

PER_WINDOW = 48
CHUNK = 8  # int32 per chunk row: next chunk + 7 ids (32 bytes)
Q_SIZE, Q_CUR, Q_NB, Q_NRING, Q_FREE, Q_LOOK = 0, 1, 2, 3, 4, 5
Q_W, Q_T0, Q_OVF = 0, 1, 2


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


def allocate_calendar(n, capacity=None, pool=None):
    """Arrays of an empty calendar for n particles (fill ``qt``, then :func:`cal_build`).

    ``capacity`` of the small heap: default max(1024, n / 16), some 10^3 times
    what a window holds; when a window would overflow it, the calendar halves
    its width and places all events anew (O(N), self-correcting). ``pool``:
    number of chunks (default :func:`pool_size`; never below what n live
    entries need, so that placing all events anew always succeeds).
    """
    nb = ring_size(n)
    cap = max(1024, n // 16) if capacity is None else int(capacity)
    chunks = pool_size(n, nb) if pool is None else max(int(pool), pool_size(n, nb, stale=False))
    buf = np.zeros(chunks * CHUNK + 16, dtype=np.int32)
    offset = (-buf.ctypes.data % 32) // 4
    return dict(
        qt=np.full(n, np.inf),
        chunks=buf[offset : offset + chunks * CHUNK].reshape(chunks, CHUNK),
        qwhere=np.zeros(n, dtype=np.int32),
        small=np.zeros((min(n, cap), 2)),
        buckets=np.zeros((nb + 1, 2), dtype=np.int32),
        qi=np.array([0, 0, nb, 0, -1, -1], dtype=np.int64),
        qf=np.array([1.0, 0.0, np.inf]),
    )


# ----------------------------------------------------------------- small heap
@jit(inline="always")
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


@jit(inline="always")
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


@jit(inline="always")
def _small_push(i, t, small, where, qi):
    k = qi[Q_SIZE]
    if k >= small.shape[0]:
        return False
    qi[Q_SIZE] = k + 1
    small[k, 0] = t
    small[k, 1] = i
    _sift_up(small, where, k)
    return True


@jit(inline="always")
def _small_remove(k, small, where, qi):
    last = qi[Q_SIZE] - 1
    qi[Q_SIZE] = last
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
@jit(inline="always")
def _append(i, b, chunks, buckets, where, qi):
    """Put id i into bucket b; False if the chunk pool is empty."""
    c = buckets[b, 0]
    f = buckets[b, 1]
    if c < 0 or f == CHUNK - 1:
        nc = qi[Q_FREE]
        if nc < 0:
            return False
        qi[Q_FREE] = chunks[nc, 0]
        chunks[nc, 0] = c
        c = nc
        f = 0
        buckets[b, 0] = c
    chunks[c, 1 + f] = i
    buckets[b, 1] = f + 1
    where[i] = b
    return True


@jit(inline="always")
def _release(c, chunks, qi):
    chunks[c, 0] = qi[Q_FREE]
    qi[Q_FREE] = c


# insert status
_OK, _HEAP_FULL, _POOL_EMPTY = 0, 1, 2


def _insert_impl(i, t, qt, chunks, where, small, buckets, qi, qf):
    """Place the event of particle i at time t; returns _OK, _HEAP_FULL or _POOL_EMPTY."""
    qt[i] = t
    x = (t - qf[Q_T0]) / qf[Q_W]
    cur = qi[Q_CUR]
    if x < cur + 1:  # B(t) <= B_cur (also for round-off below t0)
        return _OK if _small_push(i, t, small, where, qi) else _HEAP_FULL
    nb = qi[Q_NB]
    if x < cur + nb:
        if not _append(i, int(x) & (nb - 1), chunks, buckets, where, qi):
            return _POOL_EMPTY
        qi[Q_NRING] += 1
    else:
        if not _append(i, nb, chunks, buckets, where, qi):
            return _POOL_EMPTY
        if t < qf[Q_OVF]:
            qf[Q_OVF] = t
    return _OK


# the hot path inlines it; the cold paths (rebuilds, overflow) share one compiled copy,
# which keeps the first compile short
_insert = jit(inline="always")(_insert_impl)
_insert_call = jit(_insert_impl)


@jit
def _place_all(t0, w, qt, chunks, where, small, buckets, qi, qf):
    """Empty the calendar and insert every event ``qt`` (windows from t0, width w).

    Returns False if the first window overflows the small heap (the pool
    always suffices for live entries alone).
    """
    qf[Q_W] = w
    qf[Q_T0] = t0
    qf[Q_OVF] = math.inf
    qi[Q_SIZE] = 0
    qi[Q_CUR] = 0
    qi[Q_NRING] = 0
    for b in range(qi[Q_NB] + 1):
        buckets[b, 0] = -1
        buckets[b, 1] = 0
    m = chunks.shape[0]
    for c in range(m):
        chunks[c, 0] = c + 1 if c + 1 < m else -1
    qi[Q_FREE] = 0
    qi[Q_LOOK] = -1
    for i in range(qt.shape[0]):
        if _insert_call(i, qt[i], qt, chunks, where, small, buckets, qi, qf) != _OK:
            return False
    return True


@jit
def _replace(narrow, qt, chunks, where, small, buckets, qi, qf):
    """Place all events anew from ``qt`` (which always holds every event time).

    With ``narrow`` (a window overflowed the small heap) the width is halved
    first, and again until the first window fits; otherwise (the chunk pool ran
    dry) the width stays and only live entries are kept. Returns False if even a
    tiny w cannot help (more simultaneous events than the small heap holds).
    """
    t0 = qf[Q_T0] + qi[Q_CUR] * qf[Q_W]
    w = qf[Q_W]
    if not narrow and _place_all(t0, w, qt, chunks, where, small, buckets, qi, qf):
        return True
    for _ in range(200):
        w *= 0.5
        if _place_all(t0, w, qt, chunks, where, small, buckets, qi, qf):
            return True
    return False


@jit
def cal_update(i, t, qt, chunks, where, small, buckets, qi, qf):
    """Set the event time of particle i to t. Returns False on failure (see :func:`_replace`)."""
    wi = where[i]
    if wi < 0:
        k = -wi - 1
        if small[k, 0] <= t and (t - qf[Q_T0]) / qf[Q_W] < qi[Q_CUR] + 1:
            # stays in the window, later: adjust in place
            small[k, 0] = t
            qt[i] = t
            _sift_down(small, where, k, qi[Q_SIZE])
            return True
        _small_remove(k, small, where, qi)
    elif wi < qi[Q_NB]:
        qi[Q_NRING] -= 1  # its old entry goes stale (lazy deletion)
    st = _insert(i, t, qt, chunks, where, small, buckets, qi, qf)
    if st != _OK:
        return _replace(st == _HEAP_FULL, qt, chunks, where, small, buckets, qi, qf)
    return True


@jit
def _redistribute_overflow(qt, chunks, where, small, buckets, qi, qf):
    """Place the live overflow events anew; returns an insert status (_OK or the failure)."""
    nb = qi[Q_NB]
    c = buckets[nb, 0]
    f = buckets[nb, 1]
    buckets[nb, 0] = -1
    buckets[nb, 1] = 0
    qf[Q_OVF] = math.inf
    while c >= 0:
        nx = chunks[c, 0]
        for q in range(1, f + 1):
            j = chunks[c, q]
            if where[j] == nb:
                # a second entry of j (it left the overflow and came back) is placed
                # again only if j went back to the overflow: one more entry there, no harm
                st = _insert_call(j, qt[j], qt, chunks, where, small, buckets, qi, qf)
                if st != _OK:
                    return st
        _release(c, chunks, qi)
        c = nx
        f = CHUNK - 1
    return _OK


@jit(inline="always")
def _open_bucket(slot, qt, chunks, where, small, buckets, qi):
    """Move the live events of ring bucket ``slot`` into the small heap; False if it fills."""
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
                qi[Q_NRING] -= 1
                if not _small_push(j, qt[j], small, where, qi):
                    return False
        _release(c, chunks, qi)
        c = nx
        f = CHUNK - 1
    return True


@jit(inline="always")
def cal_look_ahead(qt, chunks, where, qi):
    """Prefetch hints for one chunk of the next bucket (no effect on results).

    Called once per event: while the current window's ~PER_WINDOW events are
    processed, the next bucket's chain of chunks is walked one chunk at a time
    (each chunk prefetched one call before it is read) and the ``qt``/``where``
    rows of its ids are prefetched, so that opening that bucket finds them in
    cache instead of waiting on one miss per chunk. Stale or unused slots only
    prefetch lines in vain.
    """
    c = qi[Q_LOOK]
    if c >= 0:
        for q in range(1, CHUNK):
            j = chunks[c, q]
            prefetch(qt, j)
            prefetch(where, j)
        nx = chunks[c, 0]
        if nx >= 0:
            prefetch(chunks, nx)
        qi[Q_LOOK] = nx


@jit
def cal_peek(qt, chunks, where, small, buckets, qi, qf):
    """Particle with the earliest event (moving the window forward as needed).

    Its time is ``qt[result]``; every other event is at the same time or later.
    Returns -1 if there is no event (all times inf), -2 on failure (see
    :func:`_replace`).
    """
    nb = qi[Q_NB]
    while qi[Q_SIZE] == 0:
        st = _OK
        if qi[Q_NRING] == 0:
            if qf[Q_OVF] == math.inf:
                return -1
            # nothing live in the ring: jump to the window before the earliest overflow
            # event (stale entries left in the ring are skipped when their bucket opens)
            qi[Q_CUR] = int((qf[Q_OVF] - qf[Q_T0]) / qf[Q_W]) - 1
            st = _redistribute_overflow(qt, chunks, where, small, buckets, qi, qf)
        else:
            cur = qi[Q_CUR] + 1
            qi[Q_CUR] = cur
            if not _open_bucket(cur & (nb - 1), qt, chunks, where, small, buckets, qi):
                st = _HEAP_FULL
            elif cur & (nb // 2 - 1) == 0:
                # every half turn of the ring: overflow events were beyond cur + nb when
                # placed, so none is due before the next half turn
                st = _redistribute_overflow(qt, chunks, where, small, buckets, qi, qf)
            if st == _OK:
                # the look-ahead (cal_look_ahead) walks the next bucket meanwhile
                head = buckets[(cur + 1) & (nb - 1), 0]
                qi[Q_LOOK] = head
                if head >= 0:
                    prefetch(chunks, head)
        if st != _OK and not _replace(st == _HEAP_FULL, qt, chunks, where, small, buckets, qi,
                                      qf):
            return -2
    return int(small[0, 1])


@jit
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


@jit
def cal_build(now, qt, chunks, where, small, buckets, qi, qf):
    """Place every particle's event ``qt`` anew (window starts at ``now``; w from the mean delay).

    Returns False on failure (see :func:`_replace`).
    """
    w = cal_width(now, qt)
    if _place_all(now, w, qt, chunks, where, small, buckets, qi, qf):
        return True
    qi[Q_CUR] = 0
    qf[Q_T0] = now
    qf[Q_W] = w
    return _replace(True, qt, chunks, where, small, buckets, qi, qf)


@jit
def cal_check(qt, chunks, where, small, buckets, qi, qf):
    """Invariant checker: True if every event sits where its time says and no chunk is lost."""
    n = qt.shape[0]
    nb = qi[Q_NB]
    size = qi[Q_SIZE]
    cur = qi[Q_CUR]
    for k in range(size):
        i = int(small[k, 1])
        if where[i] != -k - 1 or small[k, 0] != qt[i]:
            return False
        if (qt[i] - qf[Q_T0]) / qf[Q_W] >= cur + 1:
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
    c = qi[Q_FREE]
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
        x = (qt[i] - qf[Q_T0]) / qf[Q_W]
        if x < cur + 1:
            return False
        if b < nb:
            if x >= cur + nb or (int(x) & (nb - 1)) != b:
                return False
            ring += 1
        elif qt[i] < qf[Q_OVF]:
            return False
    return ring == qi[Q_NRING]
