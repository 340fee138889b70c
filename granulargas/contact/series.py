"""Power series of eps(beta) and tau_c(beta) to high order, and their radius of convergence.

Method (the second-order perturbation route of Schwager & Pöschel (1997) is in
:mod:`granulargas.contact.perturbation`). In the regularised variables of
:mod:`granulargas.contact.ode` (w = sqrt(x), dt = w ds) the contact is the
polynomial system w' = p/2, p' = -beta w^2 p - w^4, t' = w, analytic in s and
beta. We

1. integrate it with every variable a truncated power series in beta
   (sensitivity equations of all orders at once; Taylor method in s whose
   coefficients are beta-series, :mod:`granulargas.contact._series_kernel`)
   from s = 0 to the elastic end s0 (w(s0, 0) = 0);
2. expand around s0 in both sigma = s - s0 and beta;
3. solve the end condition for sigma as a series by fixed-point iteration:
   ``overlap``: w(s0 + sigma, beta) = 0, sigma a series in beta;
   ``force``: w = u sqrt(-p) with u = sqrt(beta) (the positive root of
   w^2 + beta p = 0), sigma a series in u -- the force-end series runs in
   powers of sqrt(beta);
4. compose: eps = -p(s0 + sigma, beta), tau_c = t(s0 + sigma, beta).

At s = s0 the elastic solution has w_s = -1/2 != 0, so the implicit function
theorem makes eps analytic in beta (overlap) or sqrt(beta) (force) near 0: the
series converge in a disc whose radius is set by the nearest complex
singularity. :func:`radius_of_convergence` estimates it from the coefficients
(root test on the tail); beyond it the truncated sums diverge, and
:func:`restitution_series` warns (``SeriesDivergenceWarning``) or raises.

The coefficients are float64: relative accuracy ~1e-13 for the first ones,
checked in the tests against the closed forms C1, C2 and against the ODE.
"""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np

from granulargas.contact import _series_kernel
from granulargas.contact.ode import end_code, solve_many

DEFAULT_ORDER = {"overlap": 2, "force": 4}
# float64 round-off grows like ~1.9^k in the overlap coefficients (the beta-columns of p(s0) have a
# smaller radius, ~0.8, than eps and cancel in the composition): relative error ~1e-7 at k = 20,
# 1e-5 at 25. The force series (in u, half as many beta-columns) reaches 1e-8 at k = 30.
MAX_RELIABLE_ORDER = {"overlap": 22, "force": 34}


class SeriesDivergenceWarning(UserWarning):
    """A truncated series is evaluated beyond (or near) its radius of convergence."""


def _conv(a, b, n):
    return np.convolve(a, b)[:n]


def _compose(C, sigma):
    """sum_k C[k] sigma^k for series C[k] (rows) and sigma (same length)."""
    n = sigma.shape[0]
    acc = C[-1].copy()
    for k in range(C.shape[0] - 2, -1, -1):
        acc = _conv(acc, sigma, n) + C[k]
    return acc


def _sqrt_series(a):
    y = np.zeros_like(a)
    y[0] = math.sqrt(a[0])
    for n in range(1, a.shape[0]):
        y[n] = (a[n] - np.dot(y[1:n], y[n - 1:0:-1])) / (2.0 * y[0])
    return y


@functools.lru_cache(maxsize=8)
def _expansion_at_elastic_end(M: int, K_end: int, order: int = 28, tol: float = 1e-17):
    """Bivariate coefficients (K_end+1, M+1) of w, p, t around s0, and s0."""
    s0 = float(solve_many(0.0, "overlap")[0, 4])
    state = np.zeros((3, M + 1))
    state[1, 0] = 1.0
    s = 0.0
    for _ in range(10000):
        W = np.zeros((order + 1, M + 1))
        P = np.zeros((order + 1, M + 1))
        T = np.zeros((order + 1, M + 1))
        W[0], P[0], T[0] = state
        _series_kernel.bivariate_coefficients(W, P, T, order, M)
        h = math.inf
        for C in (W, P):
            scale = np.maximum(np.abs(C).max(axis=0), 1e-300)
            for m in range(order - 5, order + 1):
                a = np.abs(C[m]) / scale
                a = a[a > 0]
                if a.size:
                    h = min(h, float(np.min((tol / a) ** (1.0 / m))))
        last = s + h >= s0
        if last:
            h = s0 - s
        powers = h ** np.arange(order + 1)
        state = np.stack([powers @ W, powers @ P, powers @ T])
        s += h
        if last:
            break
    W = np.zeros((K_end + 1, M + 1))
    P = np.zeros((K_end + 1, M + 1))
    T = np.zeros((K_end + 1, M + 1))
    W[0], P[0], T[0] = state
    _series_kernel.bivariate_coefficients(W, P, T, K_end, M)
    return W, P, T, s0


@functools.lru_cache(maxsize=16)
def _coefficients(order: int, end: str):
    """(eps coefficients, tau_c coefficients), each of length order+1, in beta or u."""
    end_code(end)
    if order < 0:
        raise ValueError(f"order must be >= 0, got {order}")
    n = order + 1
    if end == "overlap":
        W, P, T, _ = _expansion_at_elastic_end(order, order + 4)
    else:
        M = (order + 1) // 2
        W2, P2, T2, _ = _expansion_at_elastic_end(M, order + 4)
        # beta^m -> u^{2m}
        W = np.zeros((W2.shape[0], 2 * M + 1))
        P = np.zeros_like(W)
        T = np.zeros_like(W)
        W[:, ::2], P[:, ::2], T[:, ::2] = W2, P2, T2
        W, P, T = W[:, :n], P[:, :n], T[:, :n]
    if W.shape[1] < n:  # order 0
        W, P, T = (np.pad(C, ((0, 0), (0, n - C.shape[1]))) for C in (W, P, T))
    sigma = np.zeros(n)
    slope = W[1, 0]  # d w / d s at s0 for beta = 0 (= -1/2)
    for _ in range(n + 5):
        G = _compose(W, sigma)
        if end == "force":
            G = G - np.concatenate([[0.0], _sqrt_series(-_compose(P, sigma))[:-1]])
        sigma = sigma - G / slope
    eps = -_compose(P, sigma)
    tau = _compose(T, sigma)
    return eps, tau


def _check_order(order, end):
    end_code(end)
    if order > MAX_RELIABLE_ORDER[end]:
        warnings.warn(f"series coefficients beyond order {MAX_RELIABLE_ORDER[end]} ({end} end) are dominated by "
                      f"float64 round-off (relative error > 1e-6)", SeriesDivergenceWarning, stacklevel=3)


def restitution_coefficients(order: int, end: str = "overlap") -> np.ndarray:
    """c_0..c_order with eps = sum c_k beta^k (overlap) or sum c_k u^k, u = sqrt(beta) (force).

    For "force" the odd coefficients c_1 = c_3 = 0 (returned as exact zeros); c_5 = 4/15.
    Orders beyond ``MAX_RELIABLE_ORDER[end]`` warn (round-off).
    """
    _check_order(int(order), end)
    c = _coefficients(int(order), end)[0].copy()
    if end == "force":
        c[[k for k in (1, 3) if k < c.shape[0]]] = 0.0
    return c


def duration_coefficients(order: int, end: str = "overlap") -> np.ndarray:
    """d_0..d_order with tau_c = sum d_k beta^k (overlap) or sum d_k u^k (force); d_0 = Hertz."""
    _check_order(int(order), end)
    d = _coefficients(int(order), end)[1].copy()
    if end == "force":
        d[[k for k in (1, 3, 5) if k < d.shape[0]]] = 0.0
    return d


@functools.lru_cache(maxsize=4)
def radius_of_convergence(end: str = "overlap") -> float:
    """Radius of convergence of the eps series, expressed in beta.

    ``overlap``: the nearest singularity is on the negative axis. Time reversal
    maps a damped collision (beta, eps) onto an anti-damped one with impact speed
    eps and damping -beta eps^{1/5}, restitution 1/eps; the map
    beta -> beta eps(beta)^{1/5} has a maximum B* (at beta ~ 7.03), so eps(beta)
    has a square-root branch point at beta = -B*. We return
    B* = max_beta beta eps(beta)^{1/5} = 1.38836..., computed from the ODE; the
    ratio test on the coefficients (Domb-Sykes, orders 10..22) agrees to 1 % (tests).

    ``force``: no such symmetry (the force end is not time-reversal invariant);
    the singularities are complex (coefficient ratios oscillate). Root test
    min_k |c_k|^{-1/k} over the reliable orders 20..34 of the series in
    u = sqrt(beta), squared: about 1.19, good to a few per cent.
    """
    end_code(end)
    if end == "overlap":
        from scipy.optimize import minimize_scalar  # here, not at the top: a run's start-up loads no scipy

        res = minimize_scalar(lambda b: -b * solve_many(b, "overlap")[0, 0] ** 0.2, bounds=(1.0, 20.0),
                              method="bounded", options={"xatol": 1e-10})
        return float(-res.fun)
    c = np.abs(restitution_coefficients(MAX_RELIABLE_ORDER["force"], "force"))
    k = np.arange(c.shape[0])
    window = (k >= 20) & (c > 0)
    return float(np.min(c[window] ** (-1.0 / k[window])) ** 2)


def domb_sykes_radius(coeffs, kmin: int = 10, kmax: int = 22) -> float:
    """Ratio-test radius: fit c_k/c_{k-1} = a0 + a1/k + a2/k^2 on [kmin, kmax]; R = 1/|a0|."""
    c = np.asarray(coeffs, dtype=float)
    k = np.arange(kmin, kmax + 1)
    ratio = c[k] / c[k - 1]
    A = np.vstack([np.ones_like(k, dtype=float), 1.0 / k, 1.0 / k ** 2]).T
    a0 = np.linalg.lstsq(A, ratio, rcond=None)[0][0]
    return float(1.0 / abs(a0))


def _variable(beta, end):
    b = np.asarray(beta, dtype=float)
    return b if end == "overlap" else np.sqrt(b)


def _check_radius(beta, end, on_divergence):
    radius = radius_of_convergence(end)
    bmax = float(np.max(beta)) if np.size(beta) else 0.0
    if bmax >= radius:
        msg = (f"beta = {bmax:.4g} is beyond the radius of convergence {radius:.4g} of the {end}-end series: "
               f"the truncated series diverges there; use method='ode', 'table' or 'pade'")
        if on_divergence == "raise":
            raise ValueError(msg)
        if on_divergence == "warn":
            warnings.warn(msg, SeriesDivergenceWarning, stacklevel=3)


def _evaluate(coeffs, beta, end):
    x = _variable(beta, end)
    return np.polynomial.polynomial.polyval(x, coeffs)


def restitution_series(beta, end: str = "overlap", order: int | None = None, on_divergence: str = "warn"):
    """Truncated series of eps (vectorised).

    Parameters
    ----------
    order : int, optional
        Highest power kept, of beta ("overlap") or sqrt(beta) ("force");
        default 2 / 4 (Schwager & Pöschel (1997), eq. (31)).
    on_divergence : {"warn", "raise", "ignore"}
        What to do when some beta lies beyond the radius of convergence.
    """
    end_code(end)
    order = DEFAULT_ORDER[end] if order is None else int(order)
    _check_radius(beta, end, on_divergence)
    return _evaluate(restitution_coefficients(order, end), beta, end)


def duration_series(beta, end: str = "overlap", order: int | None = None, on_divergence: str = "warn"):
    """Truncated series of tau_c (vectorised); order as in :func:`restitution_series` (default 1 / 2: Schwager & Pöschel (1997), eq. (33))."""
    end_code(end)
    order = {"overlap": 1, "force": 2}[end] if order is None else int(order)
    _check_radius(beta, end, on_divergence)
    return _evaluate(duration_coefficients(order, end), beta, end)
