"""How a particle moves between events: the flight (numba leaf module).

Between events a particle flies freely: on a straight line, or under a uniform
acceleration g (gravity) on a parabola,

    r(t_i + s) = r + v s + g s^2 / 2,    v(t_i + s) = v + g s,                  (1)

from its position r and velocity v at its own clock t_i. Every kernel that moves a
particle or asks when it reaches a surface asks this module, with the flight as an
argument ``flight``: None for straight flights, or the float64 (3,) vector g. Numba
removes the branches on ``flight is None`` when it compiles a kernel for a None
argument, so that a run without gravity compiles to straight-line code only.

Uniform gravity accelerates every particle alike: the relative motion of two
particles stays straight, and a pair's collision time is the root of the same
quadratic as without gravity, from the two particles' positions and velocities at
a common time (:func:`partner_at`). Only the one-particle events change:

* a plane at fixed height (a static wall, a cell face): the first root of a
  quadratic, :func:`descend_root`, which takes the root at which the gap closes
  (the gap's derivative there is -sqrt(discriminant) <= 0) in a form free of
  cancellation;
* the list expiry, |r(s) - c| = shell/2, a quartic in s: :func:`expiry_delay`
  returns a lower bound of its first root, refined by safe steps that keep the
  straight part of the motion exact and bound the rest, eq. (2).
  An expiry a little early rebuilds the list a little early, which is always
  correct (the list is valid while the particle stays within shell/2 of its
  centre); a late one could miss a collision, and the bound is never late.
"""

import math

import numpy as np

from granulargas._numba import inlined, inlined_ir
from granulargas.engine._geometry import collision_delay, exit_delay, min_image

#: safe steps of :func:`expiry_delay` at most
EXPIRY_STEPS = 4
#: :func:`expiry_delay` stops refining once the particle is this fraction of the radius
#: from the sphere (the expiry comes then at most about this fraction of a shell early)
EXPIRY_SLACK = 1e-3


@inlined
def stream(i, t, rec, img, period, flight):
    """Move particle i to time t on its flight, eq. (1), wrapping on periodic axes.

    ``rec[i] = (x, y, z, vx, vy, vz, t_i, R_i)``; ``img`` the image counters; ``period``
    (3,) (inf on wall axes: no wrap)."""
    dt = t - rec[i, 6]
    if flight is None:
        for a in range(3):
            x = rec[i, a] + rec[i, 3 + a] * dt
            if x >= period[a]:
                x -= period[a]
                img[i, a] += 1
            elif x < 0.0:
                x += period[a]
                img[i, a] -= 1
            rec[i, a] = x
    else:
        for a in range(3):
            v = rec[i, 3 + a]
            w = v + flight[a] * dt
            x = rec[i, a] + 0.5 * (v + w) * dt
            if x >= period[a]:
                x -= period[a]
                img[i, a] += 1
            elif x < 0.0:
                x += period[a]
                img[i, a] -= 1
            rec[i, a] = x
            rec[i, 3 + a] = w
    rec[i, 6] = t


@inlined
def partner_at(j, dt, rec, flight):
    """Position and velocity of particle j a time dt after its own clock, eq. (1), without
    moving it (no wrap): (x, y, z, vx, vy, vz)."""
    if flight is None:
        return (rec[j, 0] + rec[j, 3] * dt, rec[j, 1] + rec[j, 4] * dt, rec[j, 2] + rec[j, 5] * dt,
                rec[j, 3], rec[j, 4], rec[j, 5])
    h = 0.5 * dt * dt
    return (rec[j, 0] + rec[j, 3] * dt + flight[0] * h, rec[j, 1] + rec[j, 4] * dt + flight[1] * h,
            rec[j, 2] + rec[j, 5] * dt + flight[2] * h, rec[j, 3] + flight[0] * dt, rec[j, 4] + flight[1] * dt,
            rec[j, 5] + flight[2] * dt)


@inlined
def pair_delay(j, t, xi, yi, zi, vx, vy, vz, ri, rec, period, flight):
    """Time from t until particle i (centre (xi, yi, zi) at t, velocity v, radius ri)
    touches particle j, streamed from its own clock ``rec[j, 6]`` on its flight
    (:func:`partner_at`): the root of :func:`granulargas.engine._geometry.collision_delay`
    (the relative motion is straight under uniform gravity)."""
    xj, yj, zj, wx, wy, wz = partner_at(j, t - rec[j, 6], rec, flight)
    return collision_delay(min_image(xi - xj, period[0]), min_image(yi - yj, period[1]),
                           min_image(zi - zj, period[2]), vx - wx, vy - wy, vz - wz, ri + rec[j, 7])


@inlined
def descend_root(h, u, a):
    """First s >= 0 at which the gap h + u s + a s^2 / 2 reaches 0 while closing, or inf.

    ``h`` is the gap now (>= 0; a round-off overlap h <= 0 counts as touching), ``u``
    its rate of change, ``a`` its (constant) second derivative. Of the two roots
    (-u -+ sqrt(D)) / a, D = u^2 - 2 a h, the gap closes at the one where its
    derivative u + a s = -sqrt(D) <= 0; for h > 0 that is the first root it reaches.
    Written without cancellation: 2 h / (sqrt(D) - u) when u <= 0, (u + sqrt(D)) / (-a)
    when u > 0 (then only a < 0 brings the gap back). A touching gap (h <= 0) that
    closes (u < 0, or u = 0 and a < 0) gives 0; one that opens gives the later root.
    """
    if a == 0.0:  # a straight gap (no acceleration along the axis): no square root
        if u < 0.0:
            return h / -u if h > 0.0 else 0.0
        return math.inf
    if h <= 0.0:
        if u < 0.0 or (u == 0.0 and a < 0.0):
            return 0.0
        if a < 0.0:
            disc = u * u - 2.0 * a * h
            return (u + math.sqrt(disc if disc > 0.0 else 0.0)) / -a
        return math.inf
    disc = u * u - 2.0 * a * h
    if disc < 0.0:
        return math.inf  # a > 0: the gap turns round before it closes
    q = math.sqrt(disc)
    if u <= 0.0:
        den = q - u
        return 2.0 * h / den if den > 0.0 else math.inf
    if a < 0.0:
        return (u + q) / -a
    return math.inf


@inlined
def expiry_delay(dx, dy, dz, vx, vy, vz, radius, flight):
    """Time until a particle at offset d from its list centre, moving with v, is at distance
    ``radius`` (inf for a particle at rest, 0 if already outside). Straight flights: the
    exact root (:func:`granulargas.engine._geometry.exit_delay`). Under gravity a lower
    bound of the first root of the quartic q(s) = |d + v s + g s^2 / 2|^2 = radius^2,
    refined in safe steps. From s_k (offset d_k, velocity w_k) the quartic is exactly

        q(s_k + u) - radius^2 = c0 + c1 u + c2 u^2 + c3 u^3 + c4 u^4,                (2)

    c0 = |d_k|^2 - radius^2 < 0, c1 = 2 d_k.w_k, c2 = |w_k|^2 + d_k.g, c3 = w_k.g,
    c4 = |g|^2 / 4; for 0 <= u <= H it is at most the quadratic c0 + c1 u + (c2 + |c3| H +
    c4 H^2) u^2, whose first root (or H, if it has none below H) is a safe step: the
    particle is inside until then. H is the straight exit time from (d_k, w_k), so that
    the step keeps the straight part of the motion exact and bounds only the cubic and
    quartic terms of gravity; :data:`EXPIRY_STEPS` steps at most, fewer once the particle
    is within :data:`EXPIRY_SLACK` of the radius.
    """
    if flight is None:
        return exit_delay(dx, dy, dz, vx, vy, vz, radius)
    gx = flight[0]
    gy = flight[1]
    gz = flight[2]
    g2 = gx * gx + gy * gy + gz * gz
    r2 = radius * radius
    s = 0.0
    for _ in range(EXPIRY_STEPS):
        hs = 0.5 * s * s
        ex = dx + vx * s + gx * hs
        ey = dy + vy * s + gy * hs
        ez = dz + vz * s + gz * hs
        c0 = ex * ex + ey * ey + ez * ez - r2
        if c0 >= 0.0:
            return s
        wx = vx + gx * s
        wy = vy + gy * s
        wz = vz + gz * s
        w2 = wx * wx + wy * wy + wz * wz
        window = exit_delay(ex, ey, ez, wx, wy, wz, radius)
        if window == math.inf:  # at rest for an instant: the time gravity alone needs
            window = 2.0 * math.sqrt(2.0 * radius / math.sqrt(g2)) if g2 > 0.0 else math.inf
            if window == math.inf:
                return math.inf
        slack = abs(wx * gx + wy * gy + wz * gz) * window + 0.25 * g2 * window * window
        c2 = w2 + ex * gx + ey * gy + ez * gz + slack
        u = descend_root(-c0, -2.0 * (ex * wx + ey * wy + ez * wz), -2.0 * c2)
        if u > window:
            u = window
        s += u
        if -c0 < EXPIRY_SLACK * r2 or slack < EXPIRY_SLACK * w2:  # close, or the bound nearly exact
            break
    return s


@inlined_ir
def face_delay(rel, v, g, width, lower, upper):
    """Time until a coordinate ``rel`` from the lower face of its cell (width ``width``),
    moving at v with acceleration g, reaches a face it may cross: (delay, side 0 lower
    or 1 upper), delay inf if none. ``lower``, ``upper``: whether each face may be
    crossed (False at a wall)."""
    s_up = descend_root(width - rel, -v, -g) if upper else math.inf
    s_lo = descend_root(rel, v, g) if lower else math.inf
    if s_up < s_lo:
        return s_up, np.int64(1)
    return s_lo, np.int64(0)


@inlined
def plane_delay(x, v, g, radius, low, high):
    """Time until a sphere of radius ``radius`` at coordinate x, moving at v with
    acceleration g along the axis, touches the plane ``low`` from above or the plane
    ``high`` from below: (delay, side 0 or 1), delay inf if neither."""
    s_lo = descend_root(x - radius - low, v, g)
    s_up = descend_root(high - radius - x, -v, -g)
    if s_up < s_lo:
        return s_up, np.int64(1)
    return s_lo, np.int64(0)
