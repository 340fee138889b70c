"""Random numbers whose whole state lives in arrays (numba leaf module).

Two streams, both pure functions of a few 64-bit words, so that a run can be
stopped anywhere and continued bit for bit:

* the *sequential stream* is xoshiro256** (Blackman & Vigna 2021, "Scrambled
  linear pseudorandom number generators", ACM TOMS 47, 36), four ``uint64``
  words in ``state[0:4]``; it gives the acceptance draws, the waiting times and
  the collision normals;
* the *pair stream* is counter based: the candidate pair number ``k`` is the
  SplitMix64 output (Steele, Lea & Flood 2014, "Fast splittable pseudorandom
  number generators", OOPSLA) at position ``k`` of a Weyl sequence with key
  ``state[4]``. Any future pair can be computed without touching the state,
  which is what lets the loop prefetch the velocities of the pairs ahead.

Bounded integers use Lemire's multiply-shift with rejection (Lemire 2019,
"Fast random integer generation in an interval", ACM Trans. Model. Comput.
Simul. 29, 3): exactly uniform on 32-bit halves, the rejection taken with
probability n / 2^32.
Uniform doubles are 53-bit multiples of 2^-53.
"""

import numpy as np

from granulargas._numba import inlined

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_MASK32 = np.uint64(0xFFFFFFFF)
_TWO32 = np.uint64(1 << 32)
_U1 = np.uint64(1)
_S11 = np.uint64(11)
_S17 = np.uint64(17)
_S27 = np.uint64(27)
_S30 = np.uint64(30)
_S31 = np.uint64(31)
_S32 = np.uint64(32)
_S45 = np.uint64(45)
_S7 = np.uint64(7)
_S57 = np.uint64(57)
_FIVE = np.uint64(5)
_NINE = np.uint64(9)
_INV53 = 1.0 / 9007199254740992.0  # 2^-53

STATE_WORDS = 5  # xoshiro256** (4) + pair-stream key (1)


@inlined
def mix64(z):
    """SplitMix64 output function (a bijection of uint64)."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@inlined
def _rotl(x, k):
    return (x << k) | (x >> (np.uint64(64) - k))


@inlined
def next_u64(state):
    """Next xoshiro256** output; advances ``state[0:4]`` in place."""
    s0 = state[0]
    s1 = state[1]
    s2 = state[2]
    s3 = state[3]
    result = _rotl(s1 * _FIVE, _S7) * _NINE
    t = s1 << _S17
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, _S45)
    state[0] = s0
    state[1] = s1
    state[2] = s2
    state[3] = s3
    return result


@inlined
def uniform(state):
    """Uniform double in [0, 1) (53 bits) from the sequential stream."""
    return np.float64(next_u64(state) >> _S11) * _INV53


@inlined
def _bounded32(x, n, seed):
    """Uniform integer in [0, n) from the 32-bit value x (Lemire), re-drawing from
    ``mix64(seed + ...)`` in the rare rejected case; returns (value, seed)."""
    m = x * n
    low = m & _MASK32
    if low < n:
        threshold = (_TWO32 - n) % n
        while low < threshold:
            seed = seed + _GOLDEN
            x = mix64(seed) & _MASK32
            m = x * n
            low = m & _MASK32
    return np.int64(m >> _S32), seed


@inlined
def pair_of(key, k, n):
    """Candidate pair number ``k`` of the pair stream: (i, j), i != j, uniform over
    the n (n - 1) ordered pairs; a pure function of (key, k, n), n < 2^31."""
    seed = key + np.uint64(k) * _GOLDEN
    x = mix64(seed)
    i, seed = _bounded32(x & _MASK32, np.uint64(n), seed)
    j, seed = _bounded32(x >> _S32, np.uint64(n - 1), seed)
    if j >= i:
        j += 1
    return i, j


def seed_state(seed: int) -> np.ndarray:
    """The five state words for an integer seed (numpy ``SeedSequence``).

    Returns
    -------
    uint64 array (5,)
        xoshiro256** state (never all zero) and the pair-stream key.
    """
    words = np.random.SeedSequence(int(seed)).generate_state(STATE_WORDS, dtype=np.uint64)
    if not np.any(words[:4]):
        words[0] = 1
    return words
