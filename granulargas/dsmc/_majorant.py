"""The relative-speed bound of the majorant: a histogram of speed classes (numba leaf module).

The sequential majorant needs a number G with |v_i - v_j| <= G for every pair
at every moment. With w_i = |v_i - u| the speed of particle i relative to a
fixed frame velocity u (the mean velocity at construction; any u works),
|v_i - v_j| <= w_i + w_j <= w_(1) + w_(2), the two largest speeds. Speeds are
kept in classes: the class of w is the IEEE-754 bit pattern of w^2 shifted
right by 50 bits (exponent and the two leading mantissa bits), so classes are
ordered like w^2, four per octave of w^2 (eight per octave of w, a factor
2^(1/8) = 1.09 in speed). ``hist[k]`` counts the particles in class k (8192
classes cover every non-negative double). The bound

    G = edge(k1) + edge(k2)

uses the upper class edges of the two fastest particles (k1 the highest
occupied class, k2 = k1 if it holds two particles, else the next occupied one
below); edge(k) = sqrt(w^2 at the start of class k + 1) exceeds every speed
of class k. Every collision moves its two particles' counts, so G is a true
bound at all times, follows the cooling gas exactly, and is at most 9 %
above w_(1) + w_(2); no periodic recomputation is needed.
"""

import math

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from granulargas._numba import jit

N_CLASSES = 8192
_SHIFT = 50
_EDGE_MARGIN = 1.0 + 2.0**-40


@intrinsic
def _f64_bits(typingctx, x):
    """The IEEE-754 bit pattern of a float64 as int64."""
    if not isinstance(x, types.Float):
        return None
    sig = types.int64(types.float64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return sig, codegen


@intrinsic
def _bits_f64(typingctx, b):
    """The float64 with bit pattern b (int64)."""
    if not isinstance(b, types.Integer):
        return None
    sig = types.float64(types.int64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return sig, codegen


@jit(inline="always")
def speed_class(w2):
    """Class of a squared speed w2 >= 0 (finite): monotone in w2, 0 <= class < 8192."""
    return _f64_bits(w2) >> _SHIFT


@jit(inline="always")
def class_edge(k):
    """Upper speed edge of class k: every w with speed_class(w*w) <= k has w < class_edge(k)
    (the square root of the next class's first w^2, which lies above every w^2 of
    class k, raised by 2^-40 relative so that rounding in w^2 and in the pair's
    relative speed can never put a speed above it)."""
    return math.sqrt(_bits_f64((k + 1) << _SHIFT)) * _EDGE_MARGIN


@jit
def build_histogram(rec, dim, frame, hist):
    """Fill ``hist`` with the class counts of all particles; return the highest class."""
    hist[:] = 0
    top = 0
    for i in range(rec.shape[0]):
        w2 = 0.0
        for a in range(dim):
            c = rec[i, a] - frame[a]
            w2 += c * c
        k = speed_class(w2)
        hist[k] += 1
        if k > top:
            top = k
    return top


@jit(inline="always")
def top_classes(hist, top):
    """(k1, k2): the highest occupied class at or below ``top`` and the class of the
    second-fastest particle (k1 again if it holds two or more)."""
    while hist[top] == 0:
        top -= 1
    if hist[top] >= 2:
        return top, top
    second = top - 1
    while hist[second] == 0:
        second -= 1
    return top, second


def new_histogram() -> np.ndarray:
    """Zeroed class counts (int64, one per class)."""
    return np.zeros(N_CLASSES, dtype=np.int64)


# ---------------------------------------------------------------------------
# Fast particles: the second proposal process of the majorant.
#
# Particles of class > kf ("fast") are marked in a bitmap (bit i of word i // 64)
# with a Fenwick tree over the words' counts, so that the r-th fast particle in
# index order is found in O(log(N/64)) and membership flips cost the same. The
# bitmap is a pure function of the velocities and kf, whatever the history.

_ONE = np.uint64(1)
_SIX = np.uint64(63)


@jit(inline="always")
def _bit(i):
    return _ONE << np.uint64(i & 63)


@jit
def build_fast_set(rec, dim, frame, kf, bits, fen):
    """Mark the particles of class > kf in ``bits`` and fill the Fenwick tree ``fen``
    (size words + 1); return their number."""
    bits[:] = 0
    fen[:] = 0
    count = 0
    for i in range(rec.shape[0]):
        w2 = 0.0
        for a in range(dim):
            c = rec[i, a] - frame[a]
            w2 += c * c
        if speed_class(w2) > kf:
            bits[i >> 6] |= _bit(i)
            fen[(i >> 6) + 1] += 1
            count += 1
    size = fen.shape[0] - 1
    for w in range(1, size + 1):  # in-place O(W) Fenwick construction
        parent = w + (w & -w)
        if parent <= size:
            fen[parent] += fen[w]
    return count


@jit(inline="always")
def flip_fast(i, delta, bits, fen):
    """Particle i enters (delta = +1) or leaves (delta = -1) the fast set."""
    bits[i >> 6] ^= _bit(i)
    w = (i >> 6) + 1
    size = fen.shape[0] - 1
    while w <= size:
        fen[w] += delta
        w += w & -w


@jit(inline="always")
def select_fast(r, bits, fen):
    """Index of the fast particle of rank r (0-based, in index order)."""
    size = fen.shape[0] - 1
    step = 1
    while step * 2 <= size:
        step *= 2
    pos = 0
    rem = r + 1
    while step > 0:
        nxt = pos + step
        if nxt <= size and fen[nxt] < rem:
            pos = nxt
            rem -= fen[nxt]
        step >>= 1
    word = bits[pos]
    for _ in range(rem - 1):
        word &= word - _ONE
    low = word & (~word + _ONE)
    # the lowest set bit is a power of two: its exponent is its index
    return pos * 64 + ((_f64_bits(np.float64(low)) >> 52) - 1023)


@jit
def choose_fast_class(hist, k1, k2, n):
    """Fast-class threshold kf minimising the majorant rate (proportional to a N + 2 b F).

    a = edge(min(kf, k1)) + edge(min(kf, k2)) bounds the relative speed of two slow
    particles, b = edge(k1) - edge(kf) (0 if kf >= k1) is the extra allowance per
    fast end, F the number of fast particles (class > kf).
    """
    s1 = class_edge(k1)
    best = k1
    best_cost = (s1 + class_edge(k2)) * n
    above = 0
    k = k1
    while k > 0 and 2 * above < n:
        above += hist[k]
        k -= 1
        # kf = k: fast are the classes > k
        a = class_edge(min(k, k1)) + class_edge(min(k, k2))
        b = s1 - class_edge(k) if k < k1 else 0.0
        cost = a * n + 2.0 * b * above
        if cost < best_cost:
            best_cost = cost
            best = k
    return best


@jit(inline="always")
def majorant_parts(k1, k2, kf):
    """(a, b): pair bound a + b (f_i + f_j) with f = 1 for fast particles (class > kf)."""
    a = class_edge(min(kf, k1)) + class_edge(min(kf, k2))
    b = class_edge(k1) - class_edge(kf) if kf < k1 else 0.0
    return a, b


def fast_set_arrays(n: int):
    """Zeroed bitmap (uint64, one bit per particle) and Fenwick tree (int64)."""
    words = (n + 63) // 64
    return np.zeros(words, dtype=np.uint64), np.zeros(words + 1, dtype=np.int64)
