"""The relative-speed bound of the majorant: a histogram of speed classes (numba leaf module).

The sequential majorant needs a number G with |v_i - v_j| <= G for every pair
at every moment. With w_i = |v_i| the speeds (the DSMC works with peculiar
velocities, so these are speeds about the centre of mass),
|v_i - v_j| <= w_i + w_j <= w_(1) + w_(2), the two largest speeds. Speeds are
kept in classes: the class of w is the IEEE-754 bit pattern of w^2 shifted
right by 50 bits (exponent and the two leading mantissa bits), so classes are
ordered like w^2, four per octave of w^2 (mantissa 1, 5/4, 3/2, 7/4: at most a
factor sqrt(5/4) = 1.118 in speed). ``hist[k]`` counts the particles in class k (8192
classes cover every non-negative double). The bound

    G = edge(k1) + edge(k2)

uses the upper class edges of the two fastest particles (k1 the highest
occupied class, k2 = k1 if it holds two particles, else the next occupied one
below); edge(k) = sqrt(w^2 at the start of class k + 1) exceeds every speed
of class k. Every collision moves its two particles' counts, so G is a true
bound at all times, follows the cooling gas exactly, and is at most 12 %
above w_(1) + w_(2); no periodic recomputation is needed.
"""

import math

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from granulargas._numba import inlined, jit

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


@inlined(python=True)
def speed_class(w2):
    """Class of a squared speed w2 >= 0 (finite): monotone in w2, 0 <= class < 8192."""
    return _f64_bits(w2) >> _SHIFT


@inlined(python=True)
def class_edge(k):
    """Upper speed edge of class k: every w with speed_class(w*w) <= k has w < class_edge(k)
    (the square root of the next class's first w^2, which lies above every w^2 of
    class k, raised by 2^-40 relative so that rounding in w^2 and in the pair's
    relative speed can never put a speed above it)."""
    return math.sqrt(_bits_f64((k + 1) << _SHIFT)) * _EDGE_MARGIN


@jit
def build_histogram(rec, dim, hist):
    """Fill ``hist`` with the class counts of the speeds |rec[i, :dim]|; return the highest class."""
    hist[:] = 0
    top = 0
    for i in range(rec.shape[0]):
        w2 = 0.0
        for a in range(dim):
            w2 += rec[i, a] * rec[i, a]
        k = speed_class(w2)
        hist[k] += 1
        if k > top:
            top = k
    return top


@inlined(python=True)
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



@jit
def largest_component(rec, dim):
    """max |rec[i, a]| over the particles and the first ``dim`` columns (no temporaries)."""
    out = 0.0
    for i in range(rec.shape[0]):
        for a in range(dim):
            x = abs(rec[i, a])
            if x > out:
                out = x
    return out
