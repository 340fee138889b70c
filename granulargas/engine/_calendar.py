"""Compiled event calendar: time buckets plus a small heap (numba leaf module).

One scheduled event per particle (time ``qt[i]``). A heap over all N events
costs O(log N) dependent cache misses per update at large N; a calendar
(Paul, J. Comput. Phys. 221, 615 (2007); Smallenburg, Eur. Phys. J. E 45, 22
(2022)) costs O(1):

* time is cut into windows of width w, numbered B(t) = floor((t - t0) / w);
  the events of the *current window* (all with B(t) <= B_cur) sit in a small
  4-ary min-heap ``small`` of (time, id) nodes (a few dozen events, in cache);
* the next ``nb - 1`` windows are *buckets*: unsorted doubly linked lists
  (``qlink[i] = (next, prev)``, heads in ``heads``), in a ring (slot B mod nb);
* events beyond the ring wait in an *overflow* list (``heads[nb]``), which is
  redistributed every half turn of the ring (an overflow event lies at least
  one full turn ahead when placed, so none falls due in between; the cost is
  O(overflow) per ~N events). ``ovf_min`` (a lower bound after removals) lets
  an empty ring jump straight to the earliest overflow event.

The small heap holds max(1024, N/16) nodes, at least ~20 windows' worth; if a
window would overflow it (a sudden burst of simultaneous events), the width
is halved and all events are placed anew from ``qt``, which always holds every
event time (O(N), rare, self-correcting); only more simultaneous events than
the small heap holds stop the run (status 31).

``where[i] >= 0`` is the ring slot (or ``nb`` for overflow) of particle i;
``where[i] < 0`` means it sits in the small heap at node ``-where[i] - 1``.
Updating an event unlinks it (O(1)) and inserts it by its time (O(1), or
O(log m) in the small heap of m events). Taking the earliest event moves the
window forward, emptying one bucket into the small heap per step, until the
small heap is non-empty. B(t) is monotone in t even in floating point, so an
event in a later window is never earlier than one in the current window:
the order of events is exact. The width w is chosen at :func:`cal_build` so that a
window holds about ``PER_WINDOW`` events, from the mean event delay; the
calendar is rebuilt (O(N)) at the start of each ``Simulation.run`` call, which
keeps w matched to a cooling gas. Ties are broken by heap node order, deterministically.

Scalars: ``qi = [small size, B_cur, nb, events in the ring]``,
``qf = [w, t0, ovf_min]``.
"""

import math

import numpy as np

from granulargas._numba import jit

PER_WINDOW = 48
Q_SIZE, Q_CUR, Q_NB, Q_NRING = 0, 1, 2, 3
Q_W, Q_T0, Q_OVF = 0, 1, 2


def ring_size(n):
    """Number of ring slots for n particles (a power of two, ~8 mean delays)."""
    nb = 64
    while nb < 8 * n // PER_WINDOW + 2:
        nb *= 2
    return nb


def allocate_calendar(n, capacity=None):
    """Arrays of an empty calendar for n particles (fill ``qt``, then :func:`cal_build`).

    ``capacity`` of the small heap: default max(1024, n / 16), some 10^3 times
    what a window holds; when a window would overflow it, the calendar halves
    its width and places all events anew (O(N), self-correcting).
    """
    nb = ring_size(n)
    cap = max(1024, n // 16) if capacity is None else int(capacity)
    return dict(
        qt=np.full(n, np.inf),
        qlink=np.full((n, 2), -1, dtype=np.int32),
        qwhere=np.zeros(n, dtype=np.int32),
        small=np.zeros((min(n, cap), 2)),
        heads=np.full(nb + 1, -1, dtype=np.int32),
        qi=np.array([0, 0, nb, 0], dtype=np.int64),
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
def _link(i, b, qlink, heads, where):
    h = heads[b]
    qlink[i, 0] = h
    qlink[i, 1] = -1
    if h >= 0:
        qlink[h, 1] = i
    heads[b] = i
    where[i] = b


@jit(inline="always")
def _unlink(i, qlink, heads, where):
    nx = qlink[i, 0]
    pv = qlink[i, 1]
    if pv >= 0:
        qlink[pv, 0] = nx
    else:
        heads[where[i]] = nx
    if nx >= 0:
        qlink[nx, 1] = pv


def _insert_impl(i, t, qt, qlink, where, small, heads, qi, qf):
    """Place the event of particle i at time t; False if the small heap is full."""
    qt[i] = t
    x = (t - qf[Q_T0]) / qf[Q_W]
    cur = qi[Q_CUR]
    if x < cur + 1:  # B(t) <= B_cur (also for round-off below t0)
        return _small_push(i, t, small, where, qi)
    nb = qi[Q_NB]
    if x < cur + nb:
        _link(i, int(x) % nb, qlink, heads, where)
        qi[Q_NRING] += 1
    else:
        _link(i, nb, qlink, heads, where)
        if t < qf[Q_OVF]:
            qf[Q_OVF] = t
    return True


# the hot path inlines it; the cold paths (rebuilds, overflow) share one compiled copy,
# which keeps the first compile short
_insert = jit(inline="always")(_insert_impl)
_insert_call = jit(_insert_impl)


@jit
def _place_all(t0, w, qt, qlink, where, small, heads, qi, qf):
    """Empty the calendar and insert every event ``qt`` (windows from t0, width w).

    Returns False if the first window overflows the small heap.
    """
    qf[Q_W] = w
    qf[Q_T0] = t0
    qf[Q_OVF] = math.inf
    qi[Q_SIZE] = 0
    qi[Q_CUR] = 0
    qi[Q_NRING] = 0
    for b in range(qi[Q_NB] + 1):
        heads[b] = -1
    for i in range(qt.shape[0]):
        if not _insert_call(i, qt[i], qt, qlink, where, small, heads, qi, qf):
            return False
    return True


@jit
def _narrow(qt, qlink, where, small, heads, qi, qf):
    """A window overflowed the small heap: halve w and place all events again.

    ``qt`` holds every event time, so nothing is lost whatever state the lists
    were left in. Returns False if even a tiny w cannot help (more simultaneous
    events than the small heap holds).
    """
    t0 = qf[Q_T0] + qi[Q_CUR] * qf[Q_W]
    w = qf[Q_W]
    for _ in range(200):
        w *= 0.5
        if _place_all(t0, w, qt, qlink, where, small, heads, qi, qf):
            return True
    return False


@jit
def cal_update(i, t, qt, qlink, where, small, heads, qi, qf):
    """Set the event time of particle i to t. Returns False on failure (see :func:`_narrow`)."""
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
    else:
        _unlink(i, qlink, heads, where)
        if wi < qi[Q_NB]:
            qi[Q_NRING] -= 1
    if not _insert(i, t, qt, qlink, where, small, heads, qi, qf):
        return _narrow(qt, qlink, where, small, heads, qi, qf)
    return True


@jit
def _redistribute_overflow(qt, qlink, where, small, heads, qi, qf):
    nb = qi[Q_NB]
    j = heads[nb]
    heads[nb] = -1
    qf[Q_OVF] = math.inf
    while j >= 0:
        nx = qlink[j, 0]
        if not _insert_call(j, qt[j], qt, qlink, where, small, heads, qi, qf):
            return False
        j = nx
    return True


@jit
def cal_peek(qt, qlink, where, small, heads, qi, qf):
    """Particle with the earliest event (moving the window forward as needed).

    Its time is ``qt[result]``; every other event is at the same time or later.
    Returns -1 if there is no event (all times inf), -2 on failure (see
    :func:`_narrow`).
    """
    nb = qi[Q_NB]
    while qi[Q_SIZE] == 0:
        ok = True
        if qi[Q_NRING] == 0:
            if qf[Q_OVF] == math.inf:
                return -1
            # nothing in the ring: jump to the window before the earliest overflow event
            qi[Q_CUR] = int((qf[Q_OVF] - qf[Q_T0]) / qf[Q_W]) - 1
            ok = _redistribute_overflow(qt, qlink, where, small, heads, qi, qf)
        else:
            cur = qi[Q_CUR] + 1
            qi[Q_CUR] = cur
            slot = cur % nb
            j = heads[slot]
            heads[slot] = -1
            while j >= 0:
                nx = qlink[j, 0]
                qi[Q_NRING] -= 1
                if not _small_push(j, qt[j], small, where, qi):
                    ok = False
                    break
                j = nx
            if ok and cur % (nb // 2) == 0:
                # every half turn of the ring: overflow events were beyond cur + nb when
                # placed, so none is due before the next half turn
                ok = _redistribute_overflow(qt, qlink, where, small, heads, qi, qf)
        if not ok and not _narrow(qt, qlink, where, small, heads, qi, qf):
            return -2
    return int(small[0, 1])


@jit
def cal_build(now, qt, qlink, where, small, heads, qi, qf):
    """Place every particle's event ``qt`` anew (window starts at ``now``; w from the mean delay).

    Returns False on failure (see :func:`_narrow`).
    """
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
    if _place_all(now, w, qt, qlink, where, small, heads, qi, qf):
        return True
    qi[Q_CUR] = 0
    qf[Q_T0] = now
    qf[Q_W] = w
    return _narrow(qt, qlink, where, small, heads, qi, qf)


@jit
def cal_check(qt, qlink, where, small, heads, qi, qf):
    """Invariant checker: True if every event sits where its time says."""
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
    seen = 0
    ring = 0
    for b in range(nb + 1):
        j = heads[b]
        prev = -1
        while j >= 0:
            x = (qt[j] - qf[Q_T0]) / qf[Q_W]
            if where[j] != b or qlink[j, 1] != prev or x < cur + 1:
                return False
            if b < nb:
                if x >= cur + nb or int(x) % nb != b:
                    return False
                ring += 1
            elif qt[j] < qf[Q_OVF]:
                return False
            seen += 1
            prev = j
            j = qlink[j, 0]
    return seen + size == n and ring == qi[Q_NRING]
