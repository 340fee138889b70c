"""Direct integration of the viscoelastic contact: eps(beta) and tau_c(beta).

The contact of two viscoelastic spheres (Schwager & Pöschel (1997), eq. (2)) in
rescaled units (time rho^{-2/5} g^{-1/5}, length g times that) reads

    x'' + beta sqrt(x) x' + x^{3/2} = 0,   x(0) = 0,  x'(0) = 1.

The coefficient of restitution is eps = -x'(tau_c) (Schwager & Pöschel (1997), eq. (4)) and tau_c the
dimensionless duration, for two definitions of the end of contact:

* ``"overlap"``: x returns to 0;
* ``"force"``: the repulsive force first vanishes, x + beta x' = 0
  (Schwager & Poeschel, PRE 78, 051304 (2008)).

The sqrt(x) singularity at x = 0 is removed by w = sqrt(x) and dt = w ds,

    dw/ds = p/2,   dp/ds = -beta w^2 p - w^4,   dt/ds = w      (p = x'),

a polynomial, hence analytic, system. Two independent integrators solve it:

* ``solver="taylor"`` (default): compiled Taylor-series method of order 28
  (:mod:`granulargas.contact._taylor`), end of contact as a root of the step
  polynomial; about 1e-14 absolute, some tens of microseconds per beta.
* ``solver="scipy"``: :func:`scipy.integrate.solve_ivp` (DOP853 by default),
  end of contact located by its event root finder, then the state at that root
  recomputed by a second integration that ends exactly there (the dense-output
  interpolant is one order less accurate than the steps).

:func:`solve_contact_naive` integrates x(t) itself from x = 0 with classical
RK4 at fixed step, which is what the singularity breaks (kept for the tests and
the speed/accuracy script to show it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas.contact import _taylor, _taylor_np

ENDS = ("overlap", "force")


def end_code(end: str) -> int:
    """Map an end-of-contact name to the compiled constant."""
    if end == "overlap":
        return _taylor.END_OVERLAP
    if end == "force":
        return _taylor.END_FORCE
    raise ValueError(f"end must be one of {ENDS}, got {end!r}")


@dataclass(frozen=True)
class ContactSolution:
    """Result of one contact integration (dimensionless units).

    Attributes
    ----------
    beta : float
    end : str
    restitution : float
        eps = -x'(tau_c).
    duration : float
        tau_c.
    restitution_derivative, duration_derivative : float
        d eps / d beta and d tau_c / d beta (nan when not computed).
    max_compression : float
        x at the turning point.
    """

    beta: float
    end: str
    restitution: float
    duration: float
    restitution_derivative: float = math.nan
    duration_derivative: float = math.nan
    max_compression: float = math.nan


def solve_many(beta, end="overlap", order=_taylor.ORDER, tol=_taylor.TOLERANCE, backend="numba"):
    """Taylor-method solutions for an array of beta.

    Parameters
    ----------
    backend : {"numba", "numpy"}
        The compiled kernel (fast per beta; ~3 s compile on a fresh numba cache)
        or the same algorithm vectorised in numpy (no compilation; used to build
        tables). They agree to round-off.

    Returns
    -------
    ndarray (n, 7)
        Columns eps, tau_c, d eps/d beta, d tau_c/d beta, s_end, steps, x_max.
    """
    betas = np.ascontiguousarray(np.atleast_1d(np.asarray(beta, dtype=np.float64)).ravel())
    if np.any(~(betas >= 0.0)):
        raise ValueError("beta must be >= 0 (and not nan)")
    code = end_code(end)
    if backend == "numpy":
        out = _taylor_np.solve_many(betas, code, int(order), float(tol))
        if np.isnan(out).any():
            raise RuntimeError(f"Taylor contact integrator (numpy) failed for some beta in {betas}")
        return out
    if backend != "numba":
        raise ValueError(f"backend must be 'numba' or 'numpy', got {backend!r}")
    out = np.empty((betas.shape[0], 7))
    status = _taylor.contact_solve_many(betas, code, int(order), float(tol), out)
    if status != _taylor.STATUS_OK:
        raise RuntimeError(f"Taylor contact integrator failed (status {status}) for some beta in {betas}")
    return out


def solve_contact(beta: float, end: str = "overlap", solver: str = "taylor", **options) -> ContactSolution:
    """Integrate one contact.

    Parameters
    ----------
    beta : float
        Dimensionless damping (3/2) A rho^{2/5} g^{1/5}, >= 0.
    end : {"overlap", "force"}
    solver : {"taylor", "scipy"}
    **options
        taylor: ``order``, ``tol``; scipy: ``method``, ``rtol``, ``atol``.
    """
    if solver == "taylor":
        row = solve_many(beta, end, **options)[0]
        return ContactSolution(float(beta), end, row[0], row[1], row[2], row[3], row[6])
    if solver == "scipy":
        eps, tau = solve_contact_scipy(beta, end, **options)
        return ContactSolution(float(beta), end, eps, tau)
    raise ValueError(f"solver must be 'taylor' or 'scipy', got {solver!r}")


def _rhs(s, y, beta):
    w, p, _ = y
    w2 = w * w
    return [0.5 * p, -beta * w2 * p - w2 * w2, w]


def solve_contact_scipy(beta: float, end: str = "overlap", method: str = "DOP853",
                        rtol: float = 1e-13, atol: float = 1e-15, refine: bool = True):
    """eps and tau_c from :func:`scipy.integrate.solve_ivp` on the (w, p, t) system.

    Parameters
    ----------
    refine : bool
        Recompute the state at the located end by integrating exactly to it
        (otherwise the dense-output interpolant is used).

    Returns
    -------
    (eps, tau_c) : tuple of float
    """
    from scipy.integrate import solve_ivp  # here, not at the top: a run's start-up loads no scipy
    from scipy.optimize import brentq

    beta = float(beta)
    end_code(end)

    def x_zero(s, y, beta):
        return y[0]

    def turning(s, y, beta):
        return y[1]

    x_zero.terminal = True
    x_zero.direction = -1
    turning.direction = -1
    s_max = 50.0 + 200.0 * beta ** 2
    sol = solve_ivp(_rhs, (0.0, s_max), [0.0, 1.0, 0.0], method=method, rtol=rtol, atol=atol,
                    events=[x_zero, turning], args=(beta,), dense_output=(end == "force"))
    if sol.status != 1 or len(sol.t_events[0]) == 0 or len(sol.t_events[1]) == 0:
        raise RuntimeError(f"no end of contact found for beta={beta} (s_max={s_max})")
    s_end = sol.t_events[0][0]
    y = sol.y_events[0][0]
    if end == "force" and beta > 0.0:
        # x + beta x' = w^2 + beta p is > 0 at the turning point (p = 0) and beta p < 0 where
        # x = 0, so the force end is bracketed; an event function on it can be stepped over
        # when beta is tiny (its two roots w = +-sqrt(-beta p) are then close together)
        def g(s):
            w, p, _ = sol.sol(s)
            return w * w + beta * p
        s_end = brentq(g, sol.t_events[1][0], s_end, xtol=1e-15, rtol=1e-15)
        y = sol.sol(s_end)
    if refine:
        again = solve_ivp(_rhs, (0.0, s_end), [0.0, 1.0, 0.0], method=method, rtol=rtol, atol=atol,
                          args=(beta,))
        y = again.y[:, -1]
    return -float(y[1]), float(y[2])


def trajectory(beta: float, end: str = "overlap", n: int = 400, rtol: float = 1e-11):
    """Compression history of one contact.

    Returns
    -------
    t, x, v : ndarray (n,)
        Dimensionless time, compression and compression rate from impact to the end.
    """
    from scipy.integrate import solve_ivp

    s_end = solve_many(beta, end)[0, 4]
    s = np.linspace(0.0, s_end, n)
    sol = solve_ivp(_rhs, (0.0, s_end), [0.0, 1.0, 0.0], method="DOP853", rtol=rtol, atol=1e-14,
                    t_eval=s, args=(float(beta),))
    w, p, t = sol.y
    return t, w * w, p


def solve_contact_naive(beta: float, end: str = "overlap", dt: float = 1e-3):
    """Classical RK4 at fixed step on x(t) itself, started at x = 0.

    The right-hand side contains sqrt(x): its third and higher derivatives diverge
    at the start and (``overlap``) at the end, so RK4 loses its fourth order
    (about dt^{3/2} for beta > 0, tests/contact). Kept to show that, not for use. The end is located
    inside the last step on the cubic Hermite interpolant of x (values and
    slopes at both ends, fourth-order accurate for a smooth solution), so that
    any loss of order is the singularity's, not the end detection's.

    Returns
    -------
    (eps, tau_c) : tuple of float
    """
    beta = float(beta)

    def f(x, v):
        r = math.sqrt(max(x, 0.0))
        return v, -beta * r * v - r * x

    def g(x, v):
        return x if end == "overlap" else x + beta * v

    x, v, t = 0.0, 1.0, 0.0
    for _ in range(int(1e8)):
        k1 = f(x, v)
        k2 = f(x + 0.5 * dt * k1[0], v + 0.5 * dt * k1[1])
        k3 = f(x + 0.5 * dt * k2[0], v + 0.5 * dt * k2[1])
        k4 = f(x + dt * k3[0], v + dt * k3[1])
        xn = x + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        vn = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        if vn < 0.0 and g(xn, vn) <= 0.0:
            # cubic Hermite x(theta), theta in [0, 1]; x' = dx/dtheta / dt
            c0, c1 = x, v * dt
            c2 = 3 * (xn - x) - 2 * v * dt - vn * dt
            c3 = 2 * (x - xn) + v * dt + vn * dt

            def gh(th):
                xh = c0 + th * (c1 + th * (c2 + th * c3))
                vh = (c1 + th * (2 * c2 + 3 * th * c3)) / dt
                return g(xh, vh), vh

            a, b = 0.0, 1.0
            for _ in range(100):
                m = 0.5 * (a + b)
                if gh(m)[0] > 0.0:
                    a = m
                else:
                    b = m
            th = 0.5 * (a + b)
            return -gh(th)[1], t + th * dt
        x, v, t = xn, vn, t + dt
    raise RuntimeError("naive integrator did not finish")
