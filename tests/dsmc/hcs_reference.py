"""The exact stationarity condition of the homogeneous cooling state, evaluated with numpy.

In the HCS every velocity scales with sqrt(T(t)), so d ln <v^p>/dt = (p/2) d ln <v^2>/dt
for every p. The collisional rates of change of <v^2> and <v^4> are integrals over pairs
and collision normals k weighted by Theta(g.k)(g.k) (the Enskog-Boltzmann collision
integral); for a velocity sample they are estimated here by plain Monte Carlo over random
pairs and uniformly drawn k, with the collision rule written out in numpy -- no DSMC code.
The ratio

    Q = (R4 / <v^4>) / (2 R2 / <v^2>)

is 1 for a sample of the HCS and differs from 1 for any other isotropic distribution
with the same eps (e.g. a Maxwellian): the first equation of the exact moment hierarchy,
which van Noije & Ernst (1998) solve in the first Sonine approximation for a2.
"""

import numpy as np


def collisional_moment_ratio(v, eps, pairs=2_000_000, seed=0, chunk=500_000):
    """(Q, standard error) for the peculiar velocities v (N, d) of identical particles."""
    rng = np.random.default_rng(seed)
    n, d = v.shape
    m2 = np.mean(np.sum(v * v, axis=1))
    m4 = np.mean(np.sum(v * v, axis=1) ** 2)
    r2_parts, r4_parts = [], []
    done = 0
    while done < pairs:
        k_count = min(chunk, pairs - done)
        i = rng.integers(0, n, k_count)
        j = (i + rng.integers(1, n, k_count)) % n
        k = rng.standard_normal((k_count, d))
        k /= np.linalg.norm(k, axis=1)[:, None]
        vi, vj = v[i], v[j]
        gk = np.sum((vi - vj) * k, axis=1)
        w = np.where(gk > 0, gk, 0.0)
        dv = (0.5 * (1 + eps) * gk)[:, None] * k
        vi2, vj2 = vi - dv, vj + dv
        s_old_i, s_old_j = np.sum(vi * vi, 1), np.sum(vj * vj, 1)
        s_new_i, s_new_j = np.sum(vi2 * vi2, 1), np.sum(vj2 * vj2, 1)
        r2_parts.append(w * (s_new_i + s_new_j - s_old_i - s_old_j))
        r4_parts.append(w * (s_new_i**2 + s_new_j**2 - s_old_i**2 - s_old_j**2))
        done += k_count
    r2 = np.concatenate(r2_parts)
    r4 = np.concatenate(r4_parts)
    # ratio of means, error by the delta method on the paired samples
    a, b = r4.mean() / m4, 2 * r2.mean() / m2
    q = a / b
    da, db = r4 / m4 - a, 2 * r2 / m2 - b
    var = np.mean((da / b - a * db / b**2) ** 2) / r2.size
    return float(q), float(np.sqrt(var))
