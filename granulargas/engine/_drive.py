"""White-noise driving: Gaussian velocity kicks from a counter-based generator (numba).

A white-noise thermostat (Williams & MacKintosh 1996; van Noije, Ernst, Trizac
& Pagonabarraga 1999) adds to every particle's velocity an independent
Gaussian random force, dv_i = xi_i(t) dt with <xi_ia(t) xi_jb(t')> =
(H / m_i) delta_ij delta_ab delta(t - t'). Integrated over steps of length
dt_k, each particle receives at the times t_k = (k + 1/2) dt_k the kick

    Delta v_i = s_i g_i - (sum_j m_j s_j g_j) / M,   s_i^2 = H dt_k N / ((N - 1) m_i)      (1)

with g_i a vector of independent standard normal numbers and M the total mass:
the kicks of a step carry no momentum, and, since removing the centre-of-mass
part takes 1/N of the injected energy, the factor N/(N-1) makes the driving
alone raise the granular temperature T = sum m c^2 / (d N) at the rate
dT/dt = H exactly on average. Between kicks the gas moves and collides freely.
The half step puts the multiples of dt_k half-way between kicks: there T equals
its average over a kick interval to second order in zeta dt_k, whereas right
after a kick it is higher by H dt_k / 2, so output at multiples of dt_k samples
the steady state without bias.
The kick interval must be short compared with the time over which the gas
cools, zeta dt_k << 1 (zeta the cooling rate); the steady state is then
independent of dt_k (see ``scripts/validation/driven_steady_state.py`` for the measured
dependence).

Random numbers: g for particle id ``ident`` at step k, component a, is a
pure function of (seed, k, ident, a): SplitMix64 (Steele, Lea & Flood 2014)
applied to the counter ``(k << 34) | (ident << 2) | r`` added to the hashed
seed gives four 64-bit words r = 0..3, whose top 53 bits are uniform numbers
u in [0, 1); two Box-Muller pairs turn them into four normal numbers (the
first d are used). No generator state is carried from one step to the next,
so the stream is reproduced from the step index alone: a restart only needs k
(steps < 2^30 and ids < 2^32 keep the counters distinct).
"""

import math

import numpy as np

from granulargas._numba import inlined, kernel

_GAMMA = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30 = np.uint64(30)
_S27 = np.uint64(27)
_S31 = np.uint64(31)
_S11 = np.uint64(11)
_S34 = np.uint64(34)
_S2 = np.uint64(2)
_TWO53 = 1.0 / 9007199254740992.0


@inlined
def mix64(z):
    """SplitMix64 finaliser of a 64-bit word (a bijection with full avalanche)."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@inlined
def _uniform(key, counter):
    """Uniform number in [0, 1) for a counter under a key (53 random bits)."""
    return np.float64(mix64(key + counter * _GAMMA) >> _S11) * _TWO53


@inlined
def kick_normals(seed, step, ident):
    """Three independent standard normal numbers for (seed, step k, particle id).

    ``seed`` is a uint64; ``step`` and ``ident`` non-negative integers.
    """
    key = mix64(np.uint64(seed))
    base = (np.uint64(step) << _S34) | (np.uint64(ident) << _S2)
    u1 = _uniform(key, base)
    u2 = _uniform(key, base | np.uint64(1))
    u3 = _uniform(key, base | np.uint64(2))
    u4 = _uniform(key, base | np.uint64(3))
    r1 = math.sqrt(-2.0 * math.log(1.0 - u1))
    r2 = math.sqrt(-2.0 * math.log(1.0 - u3))
    return r1 * math.cos(2.0 * math.pi * u2), r1 * math.sin(2.0 * math.pi * u2), \
        r2 * math.cos(2.0 * math.pi * u4)


def kick_scale(heating_rate: float, interval: float, n: int) -> float:
    """s of eq. (1) for unit mass: sqrt(H dt_k N / (N - 1))."""
    return math.sqrt(heating_rate * interval * n / (n - 1.0))


@kernel
def kick_velocities(v, col, mass, ident, dims, seed, step, scale):
    """Apply one driving step, eq. (1), to the velocities in ``v`` in place.

    Row i holds particle ``ident[i]``'s velocity in columns ``col`` .. ``col + dims - 1``
    (the random numbers follow the id, not the row); ``mass`` (N,); ``scale`` is
    :func:`kick_scale`. Returns the kinetic energy the step adds. The momentum of
    the kicks is summed over the rows in order.
    """
    n = v.shape[0]
    px = 0.0
    py = 0.0
    pz = 0.0
    mtot = 0.0
    for i in range(n):
        g1, g2, g3 = kick_normals(seed, step, ident[i])
        s = scale * math.sqrt(mass[i])  # m_i s_i
        px += s * g1
        py += s * g2
        pz += s * g3
        mtot += mass[i]
    px /= mtot
    py /= mtot
    pz /= mtot
    gained = 0.0
    for i in range(n):
        g1, g2, g3 = kick_normals(seed, step, ident[i])
        s = scale / math.sqrt(mass[i])
        e_old = 0.0
        e_new = 0.0
        for a in range(dims):
            dv = s * (g1 if a == 0 else g2 if a == 1 else g3) - (px if a == 0 else py if a == 1
                                                                 else pz)
            old = v[i, col + a]
            new = old + dv
            e_old += old * old
            e_new += new * new
            v[i, col + a] = new
        gained += 0.5 * mass[i] * (e_new - e_old)
    return gained
