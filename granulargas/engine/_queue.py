"""Compiled event queue: an indexed binary min-heap (numba leaf module).

One scheduled event per particle, so the heap always holds all N particles.
Keys are stored inside the heap (``heap_t``) next to the particle id
(``heap_id``) so that sifting touches contiguous memory; ``hpos[i]`` is the heap
slot of particle i, which makes "change the key of particle i" O(log N).
Ties are broken by slot order, deterministically.
"""

from granulargas._numba import jit


@jit(inline="always")
def _sift_up(heap_t, heap_id, hpos, k):
    t = heap_t[k]
    p = heap_id[k]
    while k > 0:
        parent = (k - 1) >> 1
        tp = heap_t[parent]
        if tp <= t:
            break
        heap_t[k] = tp
        q = heap_id[parent]
        heap_id[k] = q
        hpos[q] = k
        k = parent
    heap_t[k] = t
    heap_id[k] = p
    hpos[p] = k


@jit(inline="always")
def _sift_down(heap_t, heap_id, hpos, k):
    n = heap_t.shape[0]
    t = heap_t[k]
    p = heap_id[k]
    while True:
        c = 2 * k + 1
        if c >= n:
            break
        tc = heap_t[c]
        if c + 1 < n:
            t2 = heap_t[c + 1]
            if t2 < tc:
                c += 1
                tc = t2
        if tc >= t:
            break
        heap_t[k] = tc
        q = heap_id[c]
        heap_id[k] = q
        hpos[q] = k
        k = c
    heap_t[k] = t
    heap_id[k] = p
    hpos[p] = k


@jit
def heap_update(heap_t, heap_id, hpos, i, t):
    """Set the event time of particle i to t and restore heap order."""
    k = hpos[i]
    old = heap_t[k]
    heap_t[k] = t
    if t < old:
        _sift_up(heap_t, heap_id, hpos, k)
    else:
        _sift_down(heap_t, heap_id, hpos, k)


@jit
def heap_build(heap_t, heap_id, hpos, times):
    """Heapify particles 0..N-1 with event times ``times`` (Floyd, O(N))."""
    n = times.shape[0]
    for i in range(n):
        heap_t[i] = times[i]
        heap_id[i] = i
        hpos[i] = i
    for k in range(n // 2 - 1, -1, -1):
        _sift_down(heap_t, heap_id, hpos, k)


@jit
def heap_check(heap_t, heap_id, hpos):
    """Invariant checker: True if heap order and the index are consistent."""
    n = heap_t.shape[0]
    for k in range(n):
        if hpos[heap_id[k]] != k:
            return False
        if k > 0 and heap_t[(k - 1) >> 1] > heap_t[k]:
            return False
    return True
