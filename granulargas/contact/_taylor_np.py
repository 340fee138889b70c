"""The Taylor integrator of :mod:`granulargas.contact._taylor`, vectorised over beta in numpy.

Same algorithm, same regularised system (w = sqrt(x), dt = w ds), same step rule
and end-of-contact roots, but every operation acts on all beta at once, so it
needs no compilation. The restitution table is built with it: a fresh numba
cache (as in CI) would otherwise pay ~3 s of compile time for the compiled
kernel before the first table. For a single beta the compiled kernel is ~1000
times faster; both agree to ~1e-14 (tests/contact).

The same bits on every machine. Each beta's result is a fixed sequence of IEEE
additions, multiplications, divisions and comparisons (plus the exact frexp and
ldexp), so it does not depend on the platform or on the other betas of the call:

* steps are chosen on a ladder without ``pow`` (:func:`_step_size`; numpy's
  AVX-512 ``power`` and the C library's differ in the last bit);
* Cauchy products are summed in the order j = 0, 1, ..., k by
  ``np.add.accumulate``, whose result is defined element by element, not by
  ``einsum``, whose kernels may use fused multiply-adds or another order;
* the safeguarded Newton iteration stops each beta where its own test is met,
  as the scalar kernel does, whatever the other betas still need.
"""

from __future__ import annotations

import numpy as np

from granulargas.contact._taylor import END_FORCE, MAX_STEP_EXPONENT, MAX_STEPS, ORDER, TOLERANCE


def _horner(C, x):
    v = C[-1].copy()
    for k in range(C.shape[0] - 2, -1, -1):
        v = v * x + C[k]
    return v


def _horner_d(C, x):
    v = C[-1].copy()
    d = np.zeros_like(v)
    for k in range(C.shape[0] - 2, -1, -1):
        d = d * x + v
        v = v * x + C[k]
    return v, d


def _cauchy(A, B, k):
    """sum_{j<=k} A_j B_{k-j}, added in the order j = 0, 1, ..., k."""
    return np.add.accumulate(A[: k + 1] * B[k::-1], axis=0)[k]


def _mantissa_power(j, m):
    """(j / 8)^m by m - 1 multiplications, in the order of :func:`granulargas.contact._taylor.mantissa_power`."""
    mu = j / 8.0
    v = mu
    for _ in range(m - 1):
        v *= mu
    return v


def _step_size(W, P, order, limit):
    """:func:`granulargas.contact._taylor.step_size` for every column at once."""
    fr, er = np.frexp(limit)
    terms = [(np.abs(C[m]), m) for C in (W, P) for m in range(order - 5, order + 1)]
    k = np.full(limit.shape, MAX_STEP_EXPONENT, dtype=er.dtype)
    for a, m in terms:
        fa, ea = np.frexp(a)
        d = er - ea - (fa > fr).astype(er.dtype)
        k = np.where(fa > 0.0, np.minimum(k, d // m), k)
    h = np.ldexp(1.0, k)
    open_ = k < MAX_STEP_EXPONENT
    for j in range(15, 8, -1):
        if not np.any(open_):
            break
        fits = open_.copy()
        for a, m in terms:
            fits &= ~(np.ldexp(a * _mantissa_power(j, m), k * m) > limit)
        h = np.where(fits, np.ldexp(j / 8.0, k), h)
        open_ &= ~fits
    return h


def _root(f, a, b, iterations=100):
    """Safeguarded Newton, vectorised: f(x) -> (value, slope); f(a) > 0 >= f(b)."""
    x = 0.5 * (a + b)
    a = a.copy()
    b = b.copy()
    active = np.ones(x.shape, dtype=bool)  # a converged root stays as it is (as in the scalar kernel)
    for _ in range(iterations):
        v, d = f(x)
        pos = v > 0.0
        a = np.where(pos, x, a)
        b = np.where(pos, b, x)
        with np.errstate(divide="ignore", invalid="ignore"):
            xn = np.where(d < 0.0, x - v / d, 0.5 * (a + b))
        bad = ~((a < xn) & (xn < b))
        xn = np.where(bad, 0.5 * (a + b), xn)
        done = (np.abs(xn - x) <= 1e-15 * np.maximum(1.0, np.abs(x))) | (b - a <= 4e-16 * np.maximum(1.0, np.abs(x)))
        x = np.where(active, xn, x)
        active &= ~done
        if not np.any(active):
            break
    return x


def solve_many(betas, end_code, order=ORDER, tol=TOLERANCE):
    """Columns eps, tau_c, d eps/d beta, d tau_c/d beta, s_end, steps, x_max for each beta (n, 7)."""
    beta_all = np.asarray(betas, dtype=np.float64)
    n = beta_all.shape[0]
    K = int(order)
    out = np.full((n, 7), np.nan)
    idx = np.arange(n)
    w = np.zeros(n)
    p = np.ones(n)
    t = np.zeros(n)
    wb = np.zeros(n)
    pb = np.zeros(n)
    tb = np.zeros(n)
    s = np.zeros(n)
    xmax = np.zeros(n)
    force = end_code == END_FORCE
    for step in range(MAX_STEPS):
        if idx.size == 0:
            break
        b = beta_all[idx]
        m = idx.size
        W, P, T, Wb, Pb, Tb, Q, R, F, Qb, Rb, Fb = (np.zeros((K + 1, m)) for _ in range(12))
        W[0], P[0], T[0], Wb[0], Pb[0], Tb[0] = w, p, t, wb, pb, tb
        for k in range(K):
            Q[k] = _cauchy(W, W, k)
            Qb[k] = 2.0 * _cauchy(W, Wb, k)
            R[k] = _cauchy(Q, P, k)
            Rb[k] = _cauchy(Qb, P, k) + _cauchy(Q, Pb, k)
            F[k] = _cauchy(Q, Q, k)
            Fb[k] = 2.0 * _cauchy(Q, Qb, k)
            inv = 1.0 / (k + 1)
            W[k + 1] = 0.5 * P[k] * inv
            P[k + 1] = -(b * R[k] + F[k]) * inv
            T[k + 1] = W[k] * inv
            Wb[k + 1] = 0.5 * Pb[k] * inv
            Pb[k + 1] = -(R[k] + b * Rb[k] + Fb[k]) * inv
            Tb[k + 1] = Wb[k] * inv
        scale = np.maximum(1.0, np.maximum(np.abs(w), np.abs(p)))
        h = _step_size(W, P, K, tol * scale)
        w1 = _horner(W, h)
        p1 = _horner(P, h)
        cross_w = (w > 0.0) & (w1 <= 0.0)
        sig = h.copy()
        if np.any(cross_w):
            c = np.flatnonzero(cross_w)
            Wc = W[:, c]
            sig[c] = _root(lambda x: _horner_d(Wc, x), np.zeros(c.size), h[c])
        found = cross_w.copy()
        if force:
            g0 = w * w + b * p
            g1 = w1 * w1 + b * p1
            cross_g = (~cross_w) & (p < 0.0) & (g0 > 0.0) & (g1 <= 0.0)
            need = (cross_w & (b > 0.0)) | cross_g
            if np.any(need):
                c = np.flatnonzero(need)
                Wc, Pc, bc = W[:, c], P[:, c], b[c]

                def g(x):
                    wv, dw = _horner_d(Wc, x)
                    pv, dp = _horner_d(Pc, x)
                    return wv * wv + bc * pv, 2.0 * wv * dw + bc * dp
                sig[c] = _root(g, np.zeros(c.size), sig[c])
            found |= cross_g
        turn = (p > 0.0) & (p1 <= 0.0)
        if np.any(turn):
            c = np.flatnonzero(turn)
            Wc, Pc = W[:, c], P[:, c]
            sm = _root(lambda x: _horner_d(Pc, x), np.zeros(c.size), h[c])
            wm = _horner(Wc, sm)
            xmax[idx[c]] = wm * wm
        w, dw = _horner_d(W, sig)
        p, dp = _horner_d(P, sig)
        t, dt = _horner_d(T, sig)
        wb = _horner(Wb, sig)
        pb = _horner(Pb, sig)
        tb = _horner(Tb, sig)
        s[idx] += sig
        if np.any(found):
            f = found
            # overlap end (and beta = 0): w = 0, so dp/ds = dt/ds = 0 and the end-time shift drops out
            # exactly (see _taylor.contact_solve)
            d_eps = -pb
            d_tau = tb.copy()
            if force:
                gs = 2.0 * w * dw + b * dp
                with np.errstate(divide="ignore", invalid="ignore"):
                    ds_db = -(2.0 * w * wb + p + b * pb) / gs
                    d_eps = np.where(b > 0.0, -(pb + dp * ds_db), d_eps)
                    d_tau = np.where(b > 0.0, tb + dt * ds_db, d_tau)
            rows = idx[f]
            out[rows, 0] = -p[f]
            out[rows, 1] = t[f]
            out[rows, 2] = d_eps[f]
            out[rows, 3] = d_tau[f]
            out[rows, 4] = s[rows]
            out[rows, 5] = step + 1
            out[rows, 6] = xmax[rows]
            keep = ~f
            idx = idx[keep]
            w, p, t, wb, pb, tb = w[keep], p[keep], t[keep], wb[keep], pb[keep], tb[keep]
    return out
