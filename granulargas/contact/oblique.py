r"""Oblique contact of two frictionless viscoelastic spheres: the outcome of a contact that takes time.

Equations of motion
-------------------
Spheres i, j (radii R_i, R_j, masses m_i, m_j) touch at t = 0 with relative
position r_0 = x_i - x_j = D n_0, D = R_i + R_j, and relative velocity
v_0 = -g_n n_0 + g_t e_t (g_n > 0 approaching, e_t the unit tangential
direction, tan(theta) = g_t / g_n the impact angle). The viscoelastic force of
Schwager & Poeschel (1997), eq. (2), acts along the line of centres, so the
relative motion obeys m_eff r'' = F(xi, xi') r/|r| with |r| = D - xi: a central
force. The motion is planar (plane of n_0 and e_t), the angular momentum
|r x r'| = D g_t is conserved, and in polar coordinates (|r|, phi)

    (1)  xi'' + rho (xi^{3/2} + (3/2) A sqrt(xi) xi') + D^2 g_t^2 / (D - xi)^3 = 0,
    (2)  phi' = D g_t / (D - xi)^2,

rho = 2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2)): the head-on equation plus the
centrifugal term, while the normal turns by phi. With the head-on scales of the
normal impact speed, X = (g_n^2 / rho)^{2/5}, T = X / g_n, x = xi / X, tau = t / T:

    (3)  x'' + x^{3/2} + beta sqrt(x) x' + c (1 - delta x)^{-3} = 0,   x(0) = 0, x'(0) = 1,
    (4)  dphi/dtau = sqrt(c delta) (1 - delta x)^{-2},

    beta = (3/2) A rho^{2/5} g_n^{1/5},   delta = X / D,   c = delta tan^2(theta).

The outcome depends on THREE numbers: beta, the impact angle and delta, the
compression scale over the contact distance. The instantaneous collision is the
limit delta -> 0 at fixed beta and angle: then c -> 0, eq. (3) is the head-on
equation and phi stops turning. For equal spheres

    delta = (1/2) (sqrt(2) pi (1 - nu^2))^{2/5} (g_n / c_s)^{4/5},   c_s = sqrt(Y / density),

independent of size: the Mach number to the power 4/5. Real materials at real
speeds have delta ~ 1e-4 (steel, glass, ice at 0.1 m/s) to 1e-2 (nylon at
10 m/s, rubber at 1 m/s); the quasi-static force needs g_n / c_s < 0.1, i.e.
delta < 0.14 (:mod:`granulargas.contact.material`). A gas simulated with a soft
contact (contact time / mean free time = 0.01 - 0.1, as DEM runs are) has delta
~ 0.01 - 0.3 at thermal speeds, since t_c g_n / D = tau_c delta.

Why an exact three-parameter table, not an expansion in delta: the corrections
are powers of c = delta tan^2(theta), unbounded for grazing impacts at any
delta. In a gas (3D, impact angle flux weighted, density 2 cos(theta) sin(theta))
a fraction ~ delta_g^{5/3} of the collisions has c > 1 and is not perturbative
at all (delta_g: delta at the total relative speed g; c = delta_g sin^2(theta)
cos^{-6/5}(theta)), 2 % at delta_g = 0.1. And where it converges, a
first-order expansion leaves a second-order term (at theta = 56 deg, beta = 0.4
the outgoing velocity moves by 7.0 delta g_n + 0.75 delta^2 g_n), so the 1e-8
of the restitution table would need delta < 1e-4. The
variables below make all three directions smooth, including the grazing limit.

End of contact and separation
-----------------------------
* ``"overlap"``: the spheres separate when x returns to 0 (the force may be
  attractive just before, as for the head-on contact).
* ``"force"``: the contact ends when the repulsive force x + beta x' first
  vanishes (Schwager & Poeschel 2008). The spheres still overlap then, but no
  force acts any more: x' < 0 and x'' = -c (1 - delta x)^{-3} <= 0 make
  x + beta x' keep decreasing, so they fly apart on a straight line, which is
  eq. (3) without the contact terms, until x = 0.

Both ends are integrated to the geometric separation x = 0 (the engine needs
the pair apart), where the outcome is

    eps_s = -x'(tau_s),   tau_s,   M = int_0^{tau_s} x (2 - delta x) / (1 - delta x)^2 dtau,

and the normal has turned by Delta phi = sqrt(c delta) (tau_s + delta M)
(eq. (4), with 1/(1 - delta x)^2 = 1 + delta x (2 - delta x)/(1 - delta x)^2).
Angular momentum at |r| = D gives the tangential speed g_t exactly. So, with
n_s = cos(Delta phi) n_0 + sin(Delta phi) e_t and t_s = -sin(Delta phi) n_0 + cos(Delta phi) e_t:

    (5)  contact duration      t_c = tau_s T,
    (6)  relative velocity     v_s = eps_s g_n n_s + g_t t_s,
    (7)  relative position     r_s = D n_s,
    (8)  displacement          d = r_s - (D n_0 + (eps g_n n_0 + g_t e_t) t_c), eps = eps(beta) head-on,
         d . n_0 / X = -c J^2 sinc^2(Delta phi / 2) / 2 - eps tau_s,
         d . e_t / X = sqrt(c delta) M - (Delta phi - sin Delta phi) / delta,     J = tau_s + delta M.

(8) is where the pair is at the end of contact compared with an instantaneous
collision at first touch (the pair lags behind by about eps g_n t_c along n_0).
Head-on (c = 0) gives eps_s = eps(beta), and tau_s = tau_c(beta) for the
``overlap`` end, tau_c(beta) + x_f / eps for the ``force`` end (x_f the overlap
when the force vanishes), whatever delta.

Regularisation and integrators
------------------------------
sqrt(x) makes x(t) singular at both ends; w = sqrt(x), dt = w ds makes eq. (3)
polynomial (with u = 1/(1 - delta w^2) as an auxiliary series), integrated by
the compiled Taylor method of :mod:`granulargas.contact._oblique_taylor`
(~1e-14). :func:`solve_oblique_cartesian` is an independent reference: scipy's
DOP853 on the Cartesian relative motion in the plane (no polar reduction, no
angular momentum used), regularised by the same dt = w ds with w carried as a
state variable (d w/ds = xi'/2, which keeps w^2 = D - |r|).

The table (:mod:`granulargas.contact.oblique_grid`) holds eps_s,
tau_s (1 + c) and M (1 + c)^2 as smooth functions of (sqrt(beta),
zeta = sqrt(c) / (1 + sqrt(c)), delta) in [0, sqrt(beta_max)] x [0, 1] x [0, delta_max].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas.contact import _oblique_taylor as _k

ENDS = ("overlap", "force")

#: Largest delta a table may be requested for: the overlap reaches half the contact distance.
DELTA_MAX = 0.5
#: Largest delta the integrators accept (the last table cell reaches past DELTA_MAX).
SOLVE_DELTA_MAX = 0.8


def end_code(end: str) -> int:
    """Map an end-of-contact name to the compiled constant."""
    if end == "overlap":
        return _k.END_OVERLAP
    if end == "force":
        return _k.END_FORCE
    raise ValueError(f"end must be one of {ENDS}, got {end!r}")


# --------------------------------------------------------------------------- parameters


def compression_prefactor(young_modulus, poisson_ratio):
    """q = (2 Y / (3 (1 - nu^2)))^{-2/5}, the stiffness counterpart of the damping prefactor k.

    The compression scale of a pair is X = q (m_eff^2 g_n^4 / R_eff)^{1/5}
    (:func:`pair_compression_constant`), as beta = k (R_eff g_n / m_eff^2)^{1/5}.
    In reduced units (lengths sigma, masses m, speeds v_0) Y is Y sigma^3 / (m v_0^2).
    """
    young = np.asarray(young_modulus, dtype=float)
    nu = np.asarray(poisson_ratio, dtype=float)
    if not (np.all(young > 0) and np.all((nu > -1.0) & (nu < 0.5))):
        raise ValueError(f"need young_modulus > 0 and -1 < poisson_ratio < 0.5, got {young_modulus}, {poisson_ratio}")
    return (2.0 * young / (3.0 * (1.0 - nu * nu))) ** -0.4


def pair_compression_constant(prefactor, radius_i, radius_j, mass_i, mass_j):
    """rho^{-2/5} = q (m_eff^2 / R_eff)^{1/5} of a pair: X = this g_n^{4/5} (vectorised)."""
    r_eff = radius_i * radius_j / (radius_i + radius_j)
    m_eff = mass_i * mass_j / (mass_i + mass_j)
    return prefactor * (m_eff ** 2 / r_eff) ** 0.2


def parameters(normal_speed, tangential_speed, distance, rho, dissipation_time):
    """(beta, c, delta) of a collision, eq. (3).

    Parameters
    ----------
    normal_speed : float or array
        g_n > 0, approach speed along the line of centres at first touch.
    tangential_speed : float or array
        g_t >= 0.
    distance : float or array
        D = R_i + R_j.
    rho : float or array
        2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2)) (consistent units).
    dissipation_time : float or array
        A.

    Returns
    -------
    beta, c, delta : float or ndarray
    """
    g_n = np.asarray(normal_speed, dtype=float)
    g_t = np.asarray(tangential_speed, dtype=float)
    rho = np.asarray(rho, dtype=float)
    beta = 1.5 * np.asarray(dissipation_time, dtype=float) * rho ** 0.4 * g_n ** 0.2
    delta = rho ** -0.4 * g_n ** 0.8 / np.asarray(distance, dtype=float)
    c = delta * (g_t / g_n) ** 2
    return beta, c, delta


def zeta_of_c(c):
    """zeta = sqrt(c) / (1 + sqrt(c)) in [0, 1] (1 for c = inf)."""
    q = np.sqrt(np.asarray(c, dtype=float))
    with np.errstate(invalid="ignore"):
        return np.where(np.isinf(q), 1.0, q / (1.0 + q))


def c_of_zeta(zeta):
    """Inverse of :func:`zeta_of_c`."""
    z = np.asarray(zeta, dtype=float)
    with np.errstate(divide="ignore"):
        return (z / (1.0 - z)) ** 2


# --------------------------------------------------------------------------- Taylor solver


@dataclass(frozen=True)
class ObliqueSolution:
    """One integrated oblique contact (units g_n, X, T of eq. (3)).

    Attributes
    ----------
    beta, c, delta : float
    end : str
    restitution : float
        eps_s = -x' at separation.
    duration : float
        tau_s, touch to separation.
    turning : float
        M; the normal turns by sqrt(c delta) (tau_s + delta M).
    force_duration, force_restitution, force_overlap : float
        tau, -x' and x when the repulsive force vanished (``force`` end; for
        ``overlap`` the separation values and 0).
    max_compression : float
        Largest x.
    """

    beta: float
    c: float
    delta: float
    end: str
    restitution: float
    duration: float
    turning: float
    force_duration: float
    force_restitution: float
    force_overlap: float
    max_compression: float

    @property
    def rotation(self) -> float:
        """Delta phi, the angle the contact normal turns by (rad)."""
        return math.sqrt(self.c * self.delta) * (self.duration + self.delta * self.turning)


def solve_many(beta, c, delta, end="overlap", order=_k.ORDER, tol=_k.TOLERANCE):
    """Taylor-method solutions for arrays (broadcast) of beta, c, delta.

    Returns
    -------
    ndarray (..., N_COLUMNS)
        Columns :data:`granulargas.contact._oblique_taylor.COL_EPS` etc.
    """
    b, cc, d = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (beta, c, delta)))
    shape = b.shape
    b, cc, d = (np.ascontiguousarray(v.ravel()) for v in (b, cc, d))
    bad = ~((b >= 0) & (cc >= 0) & (d >= 0) & (d <= SOLVE_DELTA_MAX) & np.isfinite(b) & np.isfinite(cc))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"need beta >= 0, c >= 0 finite and 0 <= delta <= {SOLVE_DELTA_MAX}; got beta={b[i]}, "
                         f"c={cc[i]}, delta={d[i]}")
    out = np.empty((b.size, _k.N_COLUMNS))
    status = _k.oblique_solve_many(b, cc, d, end_code(end), int(order), float(tol), out)
    if status != _k.STATUS_OK:
        raise RuntimeError(f"oblique contact integrator failed (status {status})")
    return out.reshape(shape + (_k.N_COLUMNS,))


def solve_oblique(beta: float, c: float, delta: float, end: str = "overlap", **options) -> ObliqueSolution:
    """Integrate one oblique contact, eq. (3)-(4), to the separation (Taylor method).

    Parameters
    ----------
    beta : float
        Damping at the normal impact speed, >= 0.
    c : float
        delta tan^2(theta), >= 0.
    delta : float
        X / D, in [0, SOLVE_DELTA_MAX].
    end : {"overlap", "force"}
    **options
        ``order``, ``tol`` of the Taylor method.
    """
    row = solve_many(beta, c, delta, end, **options)
    return ObliqueSolution(float(beta), float(c), float(delta), end, *(float(row[j]) for j in (
        _k.COL_EPS, _k.COL_TAU, _k.COL_M, _k.COL_TAU_FORCE, _k.COL_EPS_FORCE, _k.COL_X_FORCE, _k.COL_X_MAX)))


# --------------------------------------------------------------------------- Cartesian reference


def solve_oblique_cartesian(beta: float, c: float, delta: float, end: str = "overlap",
                            rtol: float = 1e-13, atol: float = 1e-15) -> dict:
    """Independent reference: the relative motion in Cartesian coordinates with scipy's DOP853.

    Units D = 1, g_n = 1, so X = delta, T = delta, rho = delta^{-5/2},
    A = 2 beta delta / 3. State (w, r_x, r_y, v_x, v_y, t, M) in the fictitious
    time s with dt = w ds; w = sqrt(xi) is a state variable, dw/ds = xi'/2 with
    xi' = -v . r/|r|, so that w^2 = 1 - |r| holds along the solution (a check);
    M integrates x (2 - delta x) / (1 - delta x)^2 dtau with x = w^2 / delta.
    The force ends at w = 0 (``overlap``) or at w^2 + (3/2) A xi' = 0
    (``force``), after which the spheres fly freely until w = 0.

    Returns
    -------
    dict
        ``restitution`` (eps_s), ``duration`` (tau_s), ``turning`` (M), ``rotation`` (Delta phi),
        ``velocity`` (v_s in the frame (n_0, e_t), units g_n), ``position``
        (r_s, units D), ``force_duration``, ``drift`` (max |w^2 - (1 - |r|)| / delta).
    """
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    if not (delta > 0.0):
        raise ValueError("the Cartesian reference needs delta > 0")
    end_code(end)
    rho = delta ** -2.5
    a = 2.0 * beta * delta / 3.0
    tan_theta = math.sqrt(c / delta)

    def rhs(s, y, on):
        w, rx, ry, vx, vy, _, _ = y
        r = math.hypot(rx, ry)
        nx, ny = rx / r, ry / r
        xi_dot = -(vx * nx + vy * ny)
        f = on * rho * w * (w * w + 1.5 * a * xi_dot)  # repulsive, along +n
        xi = w * w  # = delta x
        return [0.5 * xi_dot, w * vx, w * vy, w * f * nx, w * f * ny, w,
                w / delta * (xi / delta) * (2.0 - xi) / (1.0 - xi) ** 2]

    def separation(s, y, on):
        return y[0]

    separation.terminal, separation.direction = True, -1
    y0 = [0.0, 1.0, 0.0, -1.0, tan_theta, 0.0, 0.0]
    s_max = 100.0 + 200.0 * beta ** 2
    opts = dict(method="DOP853", rtol=rtol, atol=atol)
    t_force = math.nan
    if end == "force" and beta > 0.0:
        def turning(s, y, on):
            r = math.hypot(y[1], y[2])
            return -(y[3] * y[1] + y[4] * y[2]) / r  # xi'

        turning.direction = -1
        sol = solve_ivp(rhs, (0.0, s_max), y0, events=[separation, turning], args=(1.0,), dense_output=True,
                        **opts)

        def g(s):
            y = sol.sol(s)
            r = math.hypot(y[1], y[2])
            return y[0] ** 2 + 1.5 * a * (-(y[3] * y[1] + y[4] * y[2]) / r)

        s_f = brentq(g, sol.t_events[1][0], sol.t_events[0][0], xtol=1e-15, rtol=1e-15)
        part = solve_ivp(rhs, (0.0, s_f), y0, args=(1.0,), **opts)
        y_f = part.y[:, -1]
        t_force = y_f[5] / delta
        sol = solve_ivp(rhs, (s_f, s_f + s_max), y_f, events=[separation], args=(0.0,), **opts)
        traj = np.hstack([part.y, sol.y])
    else:
        sol = solve_ivp(rhs, (0.0, s_max), y0, events=[separation], args=(1.0,), **opts)
        traj = sol.y
    if sol.status != 1:
        raise RuntimeError(f"no separation found (beta={beta}, c={c}, delta={delta})")
    w, rx, ry, vx, vy, t, m = sol.y_events[0][0]
    r = math.hypot(rx, ry)
    drift = float(np.max(np.abs(traj[0] ** 2 - (1.0 - np.hypot(traj[1], traj[2]))))) / delta
    return {
        "restitution": (vx * rx + vy * ry) / r,
        "duration": t / delta,
        "turning": m,
        "rotation": math.atan2(ry, rx),
        "velocity": np.array([vx, vy]),
        "position": np.array([rx, ry]),
        "force_duration": t / delta if math.isnan(t_force) else t_force,
        "drift": drift,
    }


# --------------------------------------------------------------------------- outcome in the collision frame


@dataclass(frozen=True)
class CollisionOutcome:
    """Resolved collision in the frame (n_0, e_t) of first touch, physical units.

    Attributes
    ----------
    duration : float
        t_c, touch to separation.
    velocity : ndarray (2,)
        Relative velocity v_s after the contact (components along n_0, e_t).
    position : ndarray (2,)
        Relative position r_s at separation.
    displacement : ndarray (2,)
        r_s minus where an instantaneous collision at first touch (eps(beta)
        head-on) would have put the pair at t_c, eq. (8).
    rotation : float
        Angle the contact normal turned by (rad).
    beta, c, delta : float
    """

    duration: float
    velocity: np.ndarray
    position: np.ndarray
    displacement: np.ndarray
    rotation: float
    beta: float
    c: float
    delta: float


def _sinc(x):
    return np.sinc(np.asarray(x) / np.pi)


def _one_minus_sinc_over_cube(x):
    """(x - sin x) / x^3, stable at small x."""
    x = float(x)
    if abs(x) < 1e-2:
        x2 = x * x
        return 1.0 / 6.0 - x2 / 120.0 + x2 * x2 / 5040.0
    return (x - math.sin(x)) / x ** 3


def frame_outcome(restitution, duration, turning, beta, c, delta, eps_head_on, normal_speed,
                  tangential_speed, distance) -> CollisionOutcome:
    """Eqs. (5)-(8): the physical outcome from the scaled separation values.

    Parameters
    ----------
    restitution, duration, turning : float
        eps_s, tau_s, M (from :func:`solve_oblique` or the table).
    beta, c, delta : float
    eps_head_on : float
        eps(beta) of the head-on contact (for the displacement only).
    normal_speed, tangential_speed, distance : float
        g_n, g_t, D.
    """
    g_n, g_t, dist = float(normal_speed), float(tangential_speed), float(distance)
    scale_x = delta * dist
    j = duration + delta * turning
    dphi = math.sqrt(c * delta) * j
    cs, sn = math.cos(dphi), math.sin(dphi)
    t_c = duration * scale_x / g_n
    velocity = np.array([restitution * g_n * cs - g_t * sn, restitution * g_n * sn + g_t * cs])
    position = dist * np.array([cs, sn])
    d_n = -0.5 * c * j * j * float(_sinc(0.5 * dphi)) ** 2 - eps_head_on * duration
    d_t = math.sqrt(c * delta) * turning - c ** 1.5 * math.sqrt(delta) * j ** 3 * _one_minus_sinc_over_cube(dphi)
    return CollisionOutcome(t_c, velocity, position, scale_x * np.array([d_n, d_t]), dphi, float(beta),
                            float(c), float(delta))
