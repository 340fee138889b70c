"""The perturbation route of Schwager & Pöschel (1997) to C1, C2 and the first-order duration
(their eqs. (9)-(33)).

In the rescaled units used here (theirs with v = 1 and alpha v^{1/5} -> beta) the
compression is expanded in the damping (their eq. (14)),

    x(t) = x0(t) + beta x1(t) + beta^2 x2(t) + ...,

with x0 the elastic (Hertz) solution. Near t = 0 the x_k are Puiseux series in
sqrt(t) (their eq. (13)):

    x0 = t - (4/35) t^{7/2} + (1/175) t^6 + ...,
    x1 = -(4/15) t^{5/2} + (3/70) t^5 + ...,
    x2 = (1/15) t^4 + ...,   x3 = -(38/2475) t^{11/2} + ...

Away from 0 we integrate the perturbation hierarchy in t (expanding the ODE in beta)

    x0'' = -x0^{3/2},
    x1'' = -sqrt(x0) x0' - (3/2) sqrt(x0) x1,
    x2'' = -sqrt(x0) x1' - x1 x0' / (2 sqrt(x0)) - (3/2) sqrt(x0) x2 - (3/8) x1^2 / sqrt(x0),

started at a small t0 from the Puiseux values (the singular start is handled by
the series, as they suggest), up to the elastic turning point
Theta_c^0 / 2 (where x0' = 0; Theta_c^0 = Hertz duration). They then match
the direct collision with the time-reversed ("inverse") collision at maximum
compression (eqs. 16-29) and reads off (eq. 30)

    C1 = -(5/2) x1/x0,   C2 = (15/4) (x1/x0)^2 = (3/5) C1^2   at Theta_c^0 / 2,

and the duration to first order (eq. 33) tau_c = Theta_c^0 (1 + C1 beta / 10).
At second order the matching constant of eq. 26 cancels from eq. 29, which is why
C2 depends on x1 alone; we compute it anyway.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def puiseux_x(t, beta, order: int = 3):
    """Schwager & Pöschel (1997), eq. (13) (v = 1): x(t) through beta^order (order <= 3), and x'(t).

    Keeps the terms printed there: t, t^{5/2}, t^{7/2}, t^4, t^5, t^{11/2}, t^6.
    """
    t = np.asarray(t, dtype=float)
    terms = [  # (coefficient, power of beta, power of t)
        (1.0, 0, 1.0), (-4 / 35, 0, 3.5), (1 / 175, 0, 6.0),
        (-4 / 15, 1, 2.5), (3 / 70, 1, 5.0),
        (1 / 15, 2, 4.0),
        (-38 / 2475, 3, 5.5),
    ]
    x = np.zeros_like(t)
    v = np.zeros_like(t)
    for c, m, p in terms:
        if m <= order:
            x = x + c * beta ** m * t ** p
            v = v + c * beta ** m * p * t ** (p - 1)
    return x, v


def _rhs(t, y):
    x0, v0, x1, v1, x2, v2 = y
    r = math.sqrt(x0)
    return [v0, -x0 * r,
            v1, -r * v0 - 1.5 * r * x1,
            v2, -r * v1 - x1 * v0 / (2 * r) - 1.5 * r * x2 - 0.375 * x1 * x1 / r]


def perturbation_solution(t_end: float = None, t0: float = 1e-3, rtol: float = 1e-13):
    """Integrate (x0, x0', x1, x1', x2, x2') from t0 to t_end (default: the elastic turning point).

    Returns
    -------
    scipy OdeSolution-like object (``sol(t)`` -> (6,) or (6, n)) and the turning time t_m
    (x0' = 0), i.e. Theta_c^0 / 2.
    """
    from scipy.integrate import solve_ivp  # here, not at the top: importing the package loads no scipy

    y0 = []
    for m in range(3):
        terms = puiseux_x(t0, 1.0, order=m)
        lower = puiseux_x(t0, 1.0, order=m - 1) if m else (0.0, 0.0)
        y0 += [float(terms[0] - lower[0]), float(terms[1] - lower[1])]

    def turning(t, y):
        return y[1]
    turning.terminal = t_end is None
    turning.direction = -1
    sol = solve_ivp(_rhs, (t0, 10.0 if t_end is None else t_end), y0, method="DOP853", rtol=rtol,
                    atol=1e-16, dense_output=True, events=turning)
    t_m = float(sol.t_events[0][0]) if len(sol.t_events[0]) else math.nan
    return sol.sol, t_m


@dataclass(frozen=True)
class PerturbationConstants:
    """Quantities of the perturbation route at the elastic turning point Theta_c^0 / 2."""

    theta_c0: float        # elastic duration (Hertz), 2 x turning time
    x0: float              # x0(Theta_c^0 / 2) = (5/4)^{2/5}
    x1: float
    x2: float
    x1_dot: float
    x0_ddot: float
    delta1: float          # eq. 20: delta = beta * delta1 + O(beta^2)
    beta26: float          # eq. 26 (called beta there; cancels from C2)
    C1: float              # eq. 30
    C2: float              # eq. 30
    duration_slope: float  # eq. 33: d tau_c / d beta at 0 = Theta_c^0 C1 / 10


def perturbation_constants(t0: float = 1e-3, rtol: float = 1e-13) -> PerturbationConstants:
    """C1, C2 and the first-order duration by the route of Schwager & Pöschel (1997) (eqs. 13-33)."""
    sol, t_m = perturbation_solution(None, t0=t0, rtol=rtol)
    x0, v0, x1, v1, x2, v2 = sol(t_m)
    x0_ddot = -x0 ** 1.5
    ratio = x1 / x0
    # eq. 29 order by order with r = v'/v = 1 + beta r1 + beta^2 r2:
    #   beta^1: x1 = (4/5) r1 x0 - x1                       -> r1 = (5/2) x1/x0
    #   beta^2: B = x0 ((4/5) r2 - (2/25) r1^2) - r1 x1 + B  -> r2 = r1^2/10 + (5/4) r1 x1/x0
    r1 = 2.5 * ratio
    r2 = r1 ** 2 / 10 + 1.25 * r1 * ratio
    C1 = -r1
    theta = 2 * t_m
    return PerturbationConstants(
        theta_c0=theta, x0=x0, x1=x1, x2=x2, x1_dot=v1, x0_ddot=x0_ddot,
        delta1=-v1 / x0_ddot,
        beta26=x2 - 0.5 * v1 ** 2 / x0_ddot,
        C1=C1, C2=r2, duration_slope=theta * C1 / 10,
    )
