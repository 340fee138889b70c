"""Compiled event queue: an indexed 4-ary min-heap (numba leaf module).

One scheduled event per particle, so the heap always holds all N particles.
Each heap node is a pair ``heap[k] = (time, particle id)`` (16 bytes; the id is
stored as a float, exact below 2^53) so that a node is one memory access, and
the four children 4k+1..4k+4 of node k share one 64-byte cache line (the
array is allocated so that node 1 starts a cache line). ``hpos[i]`` is the
node of particle i, which makes "change the event time of particle i"
O(log_4 N). A 4-ary heap has half the depth of a binary one; most updates sift
the just-popped particle down from the root, so depth is what costs.
Ties are broken by node order, deterministically.
"""

import numpy as np

from granulargas._numba import jit


def allocate_heap(n):
    """(n, 2) float64 array whose node 1 starts on a 64-byte boundary."""
    buf = np.zeros(2 * n + 8)
    # want address of element (1, 0) = base + 16 to be a multiple of 64
    offset = ((-(buf.ctypes.data + 16)) % 64) // 8
    return buf[offset : offset + 2 * n].reshape(n, 2)


@jit(inline="always")
def _sift_up(heap, hpos, k):
    t = heap[k, 0]
    p = heap[k, 1]
    while k > 0:
        parent = (k - 1) >> 2
        tp = heap[parent, 0]
        if tp <= t:
            break
        q = heap[parent, 1]
        heap[k, 0] = tp
        heap[k, 1] = q
        hpos[int(q)] = k
        k = parent
    heap[k, 0] = t
    heap[k, 1] = p
    hpos[int(p)] = k


@jit(inline="always")
def _sift_down(heap, hpos, k):
    n = heap.shape[0]
    t = heap[k, 0]
    p = heap[k, 1]
    while True:
        c = 4 * k + 1
        if c >= n:
            break
        best = c
        tb = heap[c, 0]
        e = c + 4 if c + 4 <= n else n
        for q in range(c + 1, e):
            tq = heap[q, 0]
            if tq < tb:
                tb = tq
                best = q
        if tb >= t:
            break
        q = heap[best, 1]
        heap[k, 0] = tb
        heap[k, 1] = q
        hpos[int(q)] = k
        k = best
    heap[k, 0] = t
    heap[k, 1] = p
    hpos[int(p)] = k


@jit
def heap_update(heap, hpos, i, t):
    """Set the event time of particle i to t and restore heap order."""
    k = hpos[i]
    old = heap[k, 0]
    heap[k, 0] = t
    if t < old:
        _sift_up(heap, hpos, k)
    else:
        _sift_down(heap, hpos, k)


@jit
def heap_build(heap, hpos, times):
    """Heapify particles 0..N-1 with event times ``times`` (Floyd, O(N))."""
    n = times.shape[0]
    for i in range(n):
        heap[i, 0] = times[i]
        heap[i, 1] = i
        hpos[i] = i
    for k in range((n - 2) // 4, -1, -1):
        _sift_down(heap, hpos, k)


@jit
def heap_check(heap, hpos):
    """Invariant checker: True if heap order and the index are consistent."""
    n = heap.shape[0]
    for k in range(n):
        if hpos[int(heap[k, 1])] != k:
            return False
        if k > 0 and heap[(k - 1) >> 2, 0] > heap[k, 0]:
            return False
    return True
