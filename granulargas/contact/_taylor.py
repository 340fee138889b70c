"""Compiled high-order Taylor integrator of the regularised contact equation.

The rescaled contact equation (Schwager & Pöschel (1997), eq. (2), rescaled)

    x'' + beta sqrt(x) x' + x^{3/2} = 0,   x(0) = 0, x'(0) = 1,

has sqrt(x) at the start (and, for the ``overlap`` end, at the end of contact):
derivatives of x(t) of order >= 3 diverge there (Schwager & Pöschel (1997), below eq. (8)). With

    w = sqrt(x),   p = x' = dx/dt,   dt = w ds

the system becomes polynomial and therefore analytic in s:

    dw/ds = p / 2,   dp/ds = -beta w^2 p - w^4,   dt/ds = w,
    w(0) = 0, p(0) = 1, t(0) = 0.

A polynomial right-hand side lets us compute the Taylor coefficients of the
solution in s to any order K by the usual recurrences (Cauchy products), and
integrate with steps chosen from the size of the last coefficients
(Jorba & Zou, Exp. Math. 14, 99 (2005)). Each step's polynomial is the local
solution itself, so the end of contact is located as a root of that polynomial
(safeguarded Newton) with no interpolation error:

* ``overlap`` (Schwager & Pöschel (1997), eq. (4)): w = 0 with p < 0,
* ``force`` (Schwager & Poeschel 2008): x + beta x' = 0, i.e. w^2 + beta p = 0.

The same recurrences carry the sensitivities d/dbeta of (w, p, t), which give
d eps/d beta and d tau/d beta by implicit differentiation of the end condition;
the restitution table uses them for cubic Hermite interpolation.

The step is the largest h on the ladder (j / 8) 2^k (j = 8, ..., 15; at most
2^``MAX_STEP_EXPONENT``) with |c_m| h^m <= tol max(1, |w|, |p|) for the last six
orders m of w and p (:func:`step_size`): the power of two from the binary
exponents alone (frexp and integer arithmetic, exact), then the largest j/8 whose
powers, made by repeated multiplication, keep every term within the limit. The
usual h = min_m (tol / |c_m|)^(1/m) needs ``pow``, whose last bit differs between
C libraries and between numpy's SIMD kernels (AVX-512 or not); the ladder's step
is at most 9/8 shorter. Every operation is then an IEEE addition, multiplication,
division or comparison (or the exact frexp, ldexp), so a contact's results are the
same bits on every machine, and so is the restitution table built from them.

Everything here sees floats and arrays only (numba leaf module).
"""

import math

import numpy as np

from granulargas._numba import jit

END_OVERLAP = 0
END_FORCE = 1

STATUS_OK = 0
STATUS_MAX_STEPS = 1
STATUS_BAD_INPUT = 2

ORDER = 28
TOLERANCE = 1e-17
MAX_STEPS = 200000
#: steps are at most 2^10 = 1024 (in s)
MAX_STEP_EXPONENT = 10


@jit
def horner(c, K, sigma):
    """sum_{k<=K} c_k sigma^k."""
    v = c[K]
    for k in range(K - 1, -1, -1):
        v = v * sigma + c[k]
    return v


@jit
def horner_d(c, K, sigma):
    """Value and derivative in sigma of sum_{k<=K} c_k sigma^k."""
    v = c[K]
    d = 0.0
    for k in range(K - 1, -1, -1):
        d = d * sigma + v
        v = v * sigma + c[k]
    return v, d


@jit
def _coefficients(beta, K, W, P, T, Wb, Pb, Tb, Q, R, F, Qb, Rb, Fb):
    """Taylor coefficients (orders 1..K) from the values in slot 0."""
    for k in range(K):
        q = 0.0
        qb = 0.0
        for j in range(k + 1):
            q += W[j] * W[k - j]
            qb += W[j] * Wb[k - j]
        Q[k] = q
        Qb[k] = 2.0 * qb
        r = 0.0
        rb = 0.0
        f = 0.0
        fb = 0.0
        for j in range(k + 1):
            r += Q[j] * P[k - j]
            rb += Qb[j] * P[k - j] + Q[j] * Pb[k - j]
            f += Q[j] * Q[k - j]
            fb += Q[j] * Qb[k - j]
        R[k] = r
        Rb[k] = rb
        F[k] = f
        Fb[k] = 2.0 * fb
        inv = 1.0 / (k + 1)
        W[k + 1] = 0.5 * P[k] * inv
        P[k + 1] = -(beta * r + f) * inv
        T[k + 1] = W[k] * inv
        Wb[k + 1] = 0.5 * Pb[k] * inv
        Pb[k + 1] = -(r + beta * rb + Fb[k]) * inv
        Tb[k + 1] = Wb[k] * inv


@jit
def step_exponent(a, fr, er, m):
    """The largest integer k with a 2^(k m) <= fr 2^er (a > 0, m >= 1; fr, er = frexp(limit)).

    With a = fa 2^ea (fa in [0.5, 1), frexp), a 2^(k m) <= fr 2^er holds iff
    k m <= er - ea - [fa > fr]: exact integer arithmetic, no pow."""
    fa, ea = math.frexp(a)
    d = er - ea
    if fa > fr:
        d -= 1
    return d // m


@jit
def mantissa_power(j, m):
    """(j / 8)^m by m - 1 multiplications, in this order."""
    mu = j / 8.0
    v = mu
    for _ in range(m - 1):
        v *= mu
    return v


@jit
def step_size(W, P, K, limit):
    """The largest h = (j / 8) 2^k (j = 8..15, k <= MAX_STEP_EXPONENT, h <= 2^MAX_STEP_EXPONENT)
    with |c_m| h^m <= limit for the last six orders m of W and P (module docstring)."""
    fr, er = math.frexp(limit)
    k = MAX_STEP_EXPONENT
    for c in (W, P):
        for m in range(K - 5, K + 1):
            a = abs(c[m])
            if a > 0.0:
                km = step_exponent(a, fr, er, m)
                if km < k:
                    k = km
    if k < MAX_STEP_EXPONENT:
        for j in range(15, 8, -1):
            fits = True
            for c in (W, P):
                for m in range(K - 5, K + 1):
                    if math.ldexp(abs(c[m]) * mantissa_power(j, m), k * m) > limit:
                        fits = False
            if fits:
                return math.ldexp(j / 8.0, k)
    return math.ldexp(1.0, k)


@jit
def _force_poly(W, P, K, beta, sigma):
    # g = w^2 + beta p and its derivative in s
    w, dw = horner_d(W, K, sigma)
    p, dp = horner_d(P, K, sigma)
    return w * w + beta * p, 2.0 * w * dw + beta * dp


@jit
def end_root(W, P, K, beta, end, a, b):
    """Safeguarded Newton for an end condition on [a, b] (f(a) > 0 >= f(b)).

    END_OVERLAP: w(sigma) = 0; END_FORCE: w^2 + beta p = 0 (the regularised
    system's series W, P of order K)."""
    x = 0.5 * (a + b)
    for _ in range(200):
        if end == END_OVERLAP:
            f, df = horner_d(W, K, x)
        else:
            f, df = _force_poly(W, P, K, beta, x)
        if f > 0.0:
            a = x
        else:
            b = x
        if df < 0.0:
            xn = x - f / df
        else:
            xn = 0.5 * (a + b)
        if not (a < xn < b):
            xn = 0.5 * (a + b)
        # quadratic convergence: once the step is ~1e-15 the error is far below it
        if abs(xn - x) <= 1e-15 * max(1.0, abs(x)) or b - a <= 4e-16 * max(1.0, abs(x)):
            x = xn
            break
        x = xn
    return x


@jit
def largest_compression(W, P, K, h):
    """x = w^2 at the root of p(sigma) on [0, h] (p(0) > 0 >= p(h)), by bisection."""
    a = 0.0
    b = h
    for _ in range(200):
        mid = 0.5 * (a + b)
        if horner(P, K, mid) > 0.0:
            a = mid
        else:
            b = mid
        if b - a < 1e-16:
            break
    wm = horner(W, K, 0.5 * (a + b))
    return wm * wm


@jit
def contact_solve(beta, end, order, tol, out):
    """Integrate one contact to its end.

    Parameters
    ----------
    beta : float
        Dimensionless damping, >= 0.
    end : int
        END_OVERLAP (x = 0) or END_FORCE (x + beta x' = 0).
    order : int
        Taylor order K (>= 8).
    tol : float
        Target size of the truncated term relative to max(1, |state|).
    out : float64 array (7,)
        Filled with eps, tau, d eps/d beta, d tau/d beta, s_end, steps, x_max.

    Returns
    -------
    int
        STATUS_OK, STATUS_MAX_STEPS or STATUS_BAD_INPUT.
    """
    K = order
    if not (beta >= 0.0) or K < 8:
        return STATUS_BAD_INPUT
    W = np.zeros(K + 1)
    P = np.zeros(K + 1)
    T = np.zeros(K + 1)
    Wb = np.zeros(K + 1)
    Pb = np.zeros(K + 1)
    Tb = np.zeros(K + 1)
    Q = np.zeros(K + 1)
    R = np.zeros(K + 1)
    F = np.zeros(K + 1)
    Qb = np.zeros(K + 1)
    Rb = np.zeros(K + 1)
    Fb = np.zeros(K + 1)
    w, p, t, wb, pb, tb = 0.0, 1.0, 0.0, 0.0, 0.0, 0.0
    s = 0.0
    xmax = 0.0
    for step in range(MAX_STEPS):
        W[0] = w
        P[0] = p
        T[0] = t
        Wb[0] = wb
        Pb[0] = pb
        Tb[0] = tb
        _coefficients(beta, K, W, P, T, Wb, Pb, Tb, Q, R, F, Qb, Rb, Fb)
        scale = max(1.0, abs(w), abs(p))
        # step from the last few coefficients (Jorba & Zou); several orders because
        # the first step's series is lacunary (w = s/2 + O(s^6)); found without pow
        h = step_size(W, P, K, tol * scale)
        w1 = horner(W, K, h)
        g0 = w * w + beta * p
        found = False
        sig = h
        if w > 0.0 and w1 <= 0.0:
            # x returns to zero within this step
            sig = end_root(W, P, K, beta, END_OVERLAP, 0.0, h)
            found = True
            if end == END_FORCE and beta > 0.0:
                # the force vanished before x = 0: g(sig) = beta p < 0
                sig = end_root(W, P, K, beta, END_FORCE, 0.0, sig)
        elif end == END_FORCE and p < 0.0 and g0 > 0.0:
            g1 = horner(W, K, h) ** 2 + beta * horner(P, K, h)
            if g1 <= 0.0:
                sig = end_root(W, P, K, beta, END_FORCE, 0.0, h)
                found = True
        if p > 0.0 and horner(P, K, h) <= 0.0:
            # the maximum compression lies where p = 0; track x_max on the fly
            xmax = largest_compression(W, P, K, h)
        w, dw = horner_d(W, K, sig)
        p, dp = horner_d(P, K, sig)
        t, dt = horner_d(T, K, sig)
        wb = horner(Wb, K, sig)
        pb = horner(Pb, K, sig)
        tb = horner(Tb, K, sig)
        s += sig
        if found:
            if end == END_OVERLAP or beta == 0.0:
                # w = 0 here, so dp/ds = -beta w^2 p - w^4 = 0 and dt/ds = w = 0: the shift of the
                # end time drops out exactly. (Multiplying the round-off residues of dp, dt by
                # ds/dbeta = -wb/(p/2) would not: at large beta p ~ eps is tiny.)
                out[2] = -pb
                out[3] = tb
            else:
                gs = 2.0 * w * dw + beta * dp
                ds_db = -(2.0 * w * wb + p + beta * pb) / gs
                out[2] = -(pb + dp * ds_db)
                out[3] = tb + dt * ds_db
            out[0] = -p
            out[1] = t
            out[4] = s
            out[5] = step + 1
            out[6] = xmax
            return STATUS_OK
    return STATUS_MAX_STEPS


@jit
def contact_solve_many(betas, end, order, tol, out):
    """Vectorised :func:`contact_solve`; out has shape (n, 7). Returns the worst status."""
    status = STATUS_OK
    for i in range(betas.shape[0]):
        st = contact_solve(betas[i], end, order, tol, out[i])
        if st != STATUS_OK:
            status = st
            for j in range(out.shape[1]):
                out[i, j] = math.nan
    return status
