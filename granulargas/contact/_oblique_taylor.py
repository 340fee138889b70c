"""Compiled Taylor integrator of the planar (oblique) viscoelastic contact.

The radial motion of an oblique frictionless contact in the rescaled units of
:mod:`granulargas.contact.oblique` (its eq. (3))

    x'' + x^{3/2} + beta sqrt(x) x' + c (1 - delta x)^{-3} = 0,   x(0) = 0, x'(0) = 1,

is regularised as the head-on one (:mod:`granulargas.contact._taylor`) by
w = sqrt(x), p = x', dt = w ds, plus u = 1 / (1 - delta w^2) so that the
right-hand side stays polynomial:

    dw/ds = p / 2,
    dp/ds = -on (w^4 + beta w^2 p) - c w u^3,
    dt/ds = w,
    dM/ds = w^3 (u^2 + u),                 M = int x (2 - delta x) / (1 - delta x)^2 dt,
    u (1 - delta w^2) = 1                  (Taylor coefficients by series division).

``on`` is 1 while the spheres press on each other and 0 after the ``force``
end (the repulsive force x + beta x' has vanished; it stays 0 while the pair
flies apart, see the module of the public API), so both contact ends integrate
to the geometric separation w = 0. The Taylor coefficients follow from the
Cauchy-product recurrences, steps from the size of the last coefficients
(Jorba & Zou 2005), the force end and the separation are roots of the step
polynomial (safeguarded Newton), as in the head-on kernel.

Everything here sees floats and arrays only (numba leaf module).
"""

import math

import numpy as np

from granulargas._numba import jit
from granulargas.contact._taylor import (  # noqa: F401  (constants shared by both kernels)
    END_FORCE,
    END_OVERLAP,
    MAX_STEPS,
    ORDER,
    STATUS_BAD_INPUT,
    STATUS_MAX_STEPS,
    STATUS_OK,
    TOLERANCE,
    end_root,
    horner,
    largest_compression,
)

#: Columns of the output row.
COL_EPS = 0  # -x' at separation
COL_TAU = 1  # time of separation
COL_M = 2  # M at separation
COL_TAU_FORCE = 3  # time the force vanished (= COL_TAU for the overlap end)
COL_EPS_FORCE = 4  # -x' then
COL_X_FORCE = 5  # x then
COL_M_FORCE = 6  # M then
COL_X_MAX = 7  # largest compression
COL_STEPS = 8
N_COLUMNS = 9


@jit
def _cauchy(a, b, k):
    s = 0.0
    for j in range(k + 1):
        s += a[j] * b[k - j]
    return s


@jit
def _coefficients(beta, c, delta, on, K, W, P, T, M, Q, U, U2, U3, F, R, WU3, W3, WP):
    """Taylor coefficients (orders 1..K) from the values in slot 0 of W, P, T, M."""
    q0 = W[0] * W[0]
    Q[0] = q0
    U[0] = 1.0 / (1.0 - delta * q0)
    for k in range(K):
        if k > 0:
            Q[k] = _cauchy(W, W, k)
            # u (1 - delta q) = 1  =>  U_k = delta sum_{j=1..k} Q_j U_{k-j} / (1 - delta Q_0)
            s = 0.0
            for j in range(1, k + 1):
                s += Q[j] * U[k - j]
            U[k] = delta * s * U[0]
        U2[k] = _cauchy(U, U, k)
        U3[k] = _cauchy(U2, U, k)
        F[k] = _cauchy(Q, Q, k)
        R[k] = _cauchy(Q, P, k)
        WU3[k] = _cauchy(W, U3, k)
        W3[k] = _cauchy(Q, W, k)
        m = 0.0
        for j in range(k + 1):
            m += W3[j] * (U2[k - j] + U[k - j])
        WP[k] = m
        inv = 1.0 / (k + 1)
        W[k + 1] = 0.5 * P[k] * inv
        P[k + 1] = -(on * (F[k] + beta * R[k]) + c * WU3[k]) * inv
        T[k + 1] = W[k] * inv
        M[k + 1] = m * inv


@jit
def oblique_solve(beta, c, delta, end, order, tol, out):
    """Integrate one oblique contact to the separation of the spheres.

    Parameters
    ----------
    beta : float
        Dimensionless damping at the normal impact speed, >= 0.
    c : float
        Centrifugal parameter delta tan^2(theta), >= 0.
    delta : float
        Compression scale / contact distance, 0 <= delta, delta x_max < 1.
    end : int
        END_OVERLAP or END_FORCE.
    order : int
        Taylor order K (>= 8).
    tol : float
        Target size of the truncated term relative to max(1, |state|).
    out : float64 array (N_COLUMNS,)
        Filled with the columns COL_*.

    Returns
    -------
    int
        STATUS_OK, STATUS_MAX_STEPS or STATUS_BAD_INPUT.
    """
    K = order
    if not (beta >= 0.0 and c >= 0.0 and delta >= 0.0) or K < 8 or not (delta < 0.9):
        return STATUS_BAD_INPUT
    W = np.zeros(K + 1)
    P = np.zeros(K + 1)
    T = np.zeros(K + 1)
    M = np.zeros(K + 1)
    Q = np.zeros(K + 1)
    U = np.zeros(K + 1)
    U2 = np.zeros(K + 1)
    U3 = np.zeros(K + 1)
    F = np.zeros(K + 1)
    R = np.zeros(K + 1)
    WU3 = np.zeros(K + 1)
    W3 = np.zeros(K + 1)
    WP = np.zeros(K + 1)
    w, p, t, m = 0.0, 1.0, 0.0, 0.0
    on = 1.0
    xmax = 0.0
    force_pending = end == END_FORCE and beta > 0.0
    for step in range(MAX_STEPS):
        W[0] = w
        P[0] = p
        T[0] = t
        M[0] = m
        _coefficients(beta, c, delta, on, K, W, P, T, M, Q, U, U2, U3, F, R, WU3, W3, WP)
        # step from the last coefficients of every series that must converge over it. p sees the poles
        # of u (delta w^2 = 1) only through c w u^3; with c = 0 or after the force end (w linear in s,
        # p constant for a head-on contact) M and u limit the step too
        watch_m = c == 0.0 or on == 0.0
        scale = max(1.0, abs(w), abs(p), abs(m)) if watch_m else max(1.0, abs(w), abs(p))
        h = 1e300
        for m_ in range(K - 5, K + 1):
            for a in (abs(W[m_]), abs(P[m_]), abs(M[m_]) if watch_m else 0.0, abs(U[m_ - 1]) if watch_m else 0.0):
                if a > 0.0:
                    hm = (tol * scale / a) ** (1.0 / m_)
                    if hm < h:
                        h = hm
        if h > 1e3:
            h = 1e3
        w1 = horner(W, K, h)
        p1 = horner(P, K, h)
        sig = h
        separated = False
        switched = False
        if w > 0.0 and w1 <= 0.0:
            sig = end_root(W, P, K, beta, END_OVERLAP, 0.0, h)
            separated = True
        if force_pending and p < 0.0 or force_pending and p1 < 0.0:
            g0 = w * w + beta * p
            ws = horner(W, K, sig)
            g1 = ws * ws + beta * horner(P, K, sig)
            if g0 > 0.0 and g1 <= 0.0:
                sig = end_root(W, P, K, beta, END_FORCE, 0.0, sig)
                switched = True
                separated = False
        if p > 0.0 and p1 <= 0.0:
            # turning point inside this step: largest compression
            xmax = largest_compression(W, P, K, h)
        w = horner(W, K, sig)
        p = horner(P, K, sig)
        t = horner(T, K, sig)
        m = horner(M, K, sig)
        if switched:
            out[COL_TAU_FORCE] = t
            out[COL_EPS_FORCE] = -p
            out[COL_X_FORCE] = w * w
            out[COL_M_FORCE] = m
            force_pending = False
            on = 0.0
        if separated:
            if end == END_OVERLAP or beta == 0.0:
                out[COL_TAU_FORCE] = t
                out[COL_EPS_FORCE] = -p
                out[COL_X_FORCE] = 0.0
                out[COL_M_FORCE] = m
            out[COL_EPS] = -p
            out[COL_TAU] = t
            out[COL_M] = m
            out[COL_X_MAX] = xmax
            out[COL_STEPS] = step + 1
            return STATUS_OK
    return STATUS_MAX_STEPS


@jit
def oblique_solve_many(beta, c, delta, end, order, tol, out):
    """Vectorised :func:`oblique_solve` over equal-length arrays; out (n, N_COLUMNS). Returns the worst status."""
    status = STATUS_OK
    for i in range(beta.shape[0]):
        st = oblique_solve(beta[i], c[i], delta[i], end, order, tol, out[i])
        if st != STATUS_OK:
            status = st
            for j in range(out.shape[1]):
                out[i, j] = math.nan
    return status
