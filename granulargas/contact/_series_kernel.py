"""Compiled bivariate Taylor coefficients of the regularised contact system.

Each of w, p, t is a truncated power series in beta whose coefficients are
functions of s; around a point s_n they are expanded in sigma = s - s_n, so a
variable is an array c[k, m] (sigma^k beta^m). The system

    w' = p/2,   p' = -beta w^2 p - w^4,   t' = w

is polynomial, so the s-Taylor coefficients follow from Cauchy products in both
variables; "beta times" shifts the beta index by one. Numba leaf module.
"""

import numpy as np

from granulargas._numba import jit


@jit
def _conv_add(a, b, out, M):
    # out[0..M] += (a * b)[0..M] (truncated 1-D Cauchy product)
    for i in range(M + 1):
        ai = a[i]
        if ai != 0.0:
            for j in range(M + 1 - i):
                out[i + j] += ai * b[j]


@jit
def bivariate_coefficients(W, P, T, K, M):
    """Fill rows 1..K of W, P, T (shape (K+1, M+1)) from row 0."""
    Q = np.zeros((K + 1, M + 1))
    R = np.zeros((K + 1, M + 1))
    F = np.zeros((K + 1, M + 1))
    for k in range(K):
        for j in range(k + 1):
            _conv_add(W[j], W[k - j], Q[k], M)
        for j in range(k + 1):
            _conv_add(Q[j], P[k - j], R[k], M)
            _conv_add(Q[j], Q[k - j], F[k], M)
        inv = 1.0 / (k + 1)
        for m in range(M + 1):
            W[k + 1, m] = 0.5 * P[k, m] * inv
            T[k + 1, m] = W[k, m] * inv
            shifted = R[k, m - 1] if m > 0 else 0.0
            P[k + 1, m] = -(shifted + F[k, m]) * inv
