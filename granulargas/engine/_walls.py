"""Wall kinds: hard, thermal and vibrating walls; contact times and collisions (numba leaf module).

Each side of a wall axis a (lower side 0, upper side 1) is a flat, infinitely heavy wall
of one kind
(:class:`~granulargas.engine._state.WallSpec`, arrays (3, 2) indexed [axis, side]):

* ``HARD`` -- at rest; the normal velocity becomes -eps v_n by the run's rule
  (eps of the sphere-plane contact, R_eff = R_i, m_eff = m_i);
* ``THERMAL`` -- at rest, diffuse: the outgoing velocity is drawn from the flux
  distribution of a Maxwellian at the wall temperature T_w,
  P(v_n) ~ v_n exp(-m v_n^2 / (2 T_w)) away from the wall and independent
  Gaussians of variance T_w / m along the wall (Cercignani 1988, ch. 3; the
  "thermal wall" of Tehver, Toigo, Koplik & Banavar 1998): v_n = sqrt(-2 (T_w / m)
  ln(1 - u)) with u uniform, the tangential components by Box-Muller. The draws are
  counter based, a pure function of (seed, the run's wall-collision count, component),
  so that the engine stays deterministic and a restart continues the same stream
  (SplitMix64 as in :mod:`granulargas.engine._drive`);
* ``VIBRATING`` -- moves along its normal by a prescribed law, W(t) = A f(2 pi nu t
  + phi) about its rest position, whatever the gas does (infinitely heavy). The rest
  position is A inside the box (A for the lower wall, L_a - A for the upper one), so that
  the wall sweeps [0, 2A] (or [L_a - 2A, L_a]) and the gas never leaves the box. The
  collision reverses the normal velocity relative to the wall and scales it by eps of
  the rule at that relative speed: v_n' = W' - eps (v_n - W'). The energy the wall
  gives the gas is the kinetic energy gained plus the energy dissipated in the
  collision, (1 - eps^2) m (v_n - W')^2 / 2; both are booked (``Walls.work``,
  ``counters.dissipated``).

Waveforms f (amplitude 1, period 1 in the cycle fraction u = nu t + phi / 2 pi mod 1):

* ``SINE`` -- sin(2 pi u);
* ``TRIANGLE`` -- the symmetric sawtooth: 4u on [0, 1/4], 2 - 4u on [1/4, 3/4],
  4u - 4 on [3/4, 1): the wall moves at the constant speed 4 A nu = (2 / pi) A omega
  and turns round at +-A;
* ``BIPARABOLIC`` -- parabolic arcs through the zeros and extremes of the sine,
  16 u (1/2 - u) on [0, 1/2) and its negative on [1/2, 1): continuous velocity, the
  acceleration -+32 A nu^2 = -+(8 / pi^2) A omega^2 constant on each half cycle (the
  plate motion of the event-driven simulations of Luding, Clément, Blumen,
  Rajchenbach & Duran 1994, which keeps contact times roots of quadratics).

Contact time with a vibrating wall
----------------------------------
Let p(s) be the particle's distance from the wall's rest plane minus its radius, s
after the prediction time t (a quadratic, :mod:`granulargas.engine._flight`:
p'' = +-g_a), and h(s) = p(s) - W(t + s) (lower wall; upper: p + W) the gap. The
contact is the first root of h. The search starts at s = 0 with h(0) >= 0 and never
steps over a root:

(a) Reach. |W| <= A, so h(s) >= p(s) - A: while p > A there is no contact. From a
    point with p(s) > A the search jumps to the first root of p - A (a quadratic,
    :func:`~granulargas.engine._flight.descend_root`; none: no contact ever).
(b) Piecewise-polynomial waveforms (triangle, bi-parabolic). Between the wall's turning
    points (triangle) or acceleration jumps (bi-parabolic) W is a polynomial of degree
    <= 2 in s, and so is h: its first root on the piece is exact
    (:func:`~granulargas.engine._flight.descend_root`). The pieces are visited in order,
    so the first root found is the first root.
(c) Sine: safe steps. |h''| <= M = |g_a| + A omega^2 everywhere, so by Taylor's theorem
    h(s_k + u) >= h(s_k) + h'(s_k) u - M u^2 / 2 for u >= 0. The first positive root
    u_k of that quadratic lower bound is a step over which h stays positive: no root
    of h lies in [s_k, s_k + u_k). The steps converge to the first root s* (if the
    steps accumulate at some s, u_k -> 0 forces h(s_k) -> 0 and h(s) = 0; near a root
    where h' != 0 the convergence is quadratic, as Newton's method from the safe side),
    and stop when a step is below the resolution of the clock. A root where the gap only
    touches zero without closing (h' >= 0 there: a grazing contact with no normal speed)
    is stepped over.

The search stops at a horizon (the particle's earliest other event, after which it is
predicted again) or after :data:`MAX_STEPS` steps; the latter returns a time before the
contact, a re-check: the event is scheduled with the tag bit :data:`RECHECK`, changes
nothing, and the particle is predicted again from there. Neither can make the search
miss a root.
"""

import math

import numpy as np

from granulargas._numba import inlined
from granulargas.engine._drive import _uniform, mix64
from granulargas.engine._flight import descend_root

HARD = 0
THERMAL = 1
VIBRATING = 2
#: wall kinds by name (the config's ``kind``)
KINDS = {"hard": HARD, "thermal": THERMAL, "vibrating": VIBRATING}

SINE = 0
TRIANGLE = 1
BIPARABOLIC = 2
#: waveforms by name (the config's ``waveform``)
WAVEFORMS = {"sine": SINE, "triangle": TRIANGLE, "biparabolic": BIPARABOLIC}

#: tag bit of a wall event that is a re-check, not a contact
RECHECK = 8
#: largest number of steps (sine) or pieces (piecewise waveforms) of one contact search
MAX_STEPS = 200
#: a step below this many units of the clock's last place is a converged search
CLOCK_ULPS = 4.0 * 2.0**-52

_TWO_PI = 2.0 * math.pi
_SALT = np.uint64(0x5851F42D4C957F2D)
_S2 = np.uint64(2)


def reach(kind: str, amplitude: float, waveform: str = "sine") -> float:
    """How far a wall of this kind moves from its rest position: A for a vibrating wall."""
    return float(amplitude) if kind == "vibrating" else 0.0


def acceleration_bound(waveform: str, amplitude: float, frequency: float) -> float:
    """sup |W''| of a waveform: A omega^2 (sine), 0 (triangle, between its turning
    points), (8 / pi^2) A omega^2 (bi-parabolic)."""
    omega = _TWO_PI * frequency
    return {"sine": 1.0, "triangle": 0.0, "biparabolic": 8.0 / math.pi**2}[waveform] * amplitude * omega**2


def velocity_bound(waveform: str, amplitude: float, frequency: float) -> float:
    """sup |W'|: A omega (sine), (2 / pi) A omega (triangle), (4 / pi) A omega (bi-parabolic)."""
    omega = _TWO_PI * frequency
    return {"sine": 1.0, "triangle": 2.0 / math.pi, "biparabolic": 4.0 / math.pi}[waveform] * amplitude * omega


def mean_square_velocity(waveform: str, amplitude: float, frequency: float) -> float:
    """<W'^2> over a period: (A omega)^2 / 2 (sine), 4 (A omega)^2 / pi^2 (triangle),
    16 (A omega)^2 / (3 pi^2) (bi-parabolic)."""
    a_omega2 = (amplitude * _TWO_PI * frequency) ** 2
    return {"sine": 0.5, "triangle": 4.0 / math.pi**2, "biparabolic": 16.0 / (3.0 * math.pi**2)}[waveform] * a_omega2


# ------------------------------------------------------------------ wall motion
@inlined
def cycle(nu, phase, t):
    """Fraction u in [0, 1) of the wall's cycle at time t (``phase`` in cycles)."""
    u = nu * t + phase
    return u - math.floor(u)


@inlined
def wave(waveform, u, amp, nu):
    """W, W', W'' of a waveform at cycle fraction u (amplitude ``amp``, frequency ``nu``)."""
    if waveform == SINE:
        om = _TWO_PI * nu
        th = _TWO_PI * u
        sn = math.sin(th)
        return amp * sn, amp * om * math.cos(th), -amp * om * om * sn
    if waveform == TRIANGLE:
        if u < 0.25:
            return 4.0 * amp * u, 4.0 * amp * nu, 0.0
        if u < 0.75:
            return amp * (2.0 - 4.0 * u), -4.0 * amp * nu, 0.0
        return amp * (4.0 * u - 4.0), 4.0 * amp * nu, 0.0
    # BIPARABOLIC
    if u < 0.5:
        return amp * u * (8.0 - 16.0 * u), amp * nu * (8.0 - 32.0 * u), -32.0 * amp * nu * nu
    w = u - 0.5
    return -amp * w * (8.0 - 16.0 * w), -amp * nu * (8.0 - 32.0 * w), 32.0 * amp * nu * nu


@inlined
def piece_end(waveform, u):
    """End (cycle fraction) of the polynomial piece of a waveform that holds u."""
    if waveform == TRIANGLE:
        if u < 0.25:
            return 0.25
        if u < 0.75:
            return 0.75
        return 1.0
    return 0.5 if u < 0.5 else 1.0


@inlined
def wall_motion(spec, a, side, t):
    """Displacement W, velocity W' and acceleration W'' of wall (a, side) at time t
    (zeros for a wall at rest)."""
    if spec.kind[a, side] != VIBRATING:
        return 0.0, 0.0, 0.0
    nu = spec.frequency[a, side]
    return wave(spec.waveform[a, side], cycle(nu, spec.phase[a, side], t), spec.amplitude[a, side], nu)


# ------------------------------------------------------------------ contact times
@inlined
def _piecewise_delay(p0, dp0, ddp, sgn, amp, nu, phase, waveform, t, horizon):
    """First root of h(s) = p(s) + sgn W(t + s) for a piecewise-polynomial waveform:
    (delay, re-check flag); delay inf if none before ``horizon`` (module doc (a), (b))."""
    s = 0.0
    for _ in range(MAX_STEPS):
        ps = p0 + (dp0 + 0.5 * ddp * s) * s
        dps = dp0 + ddp * s
        if ps > amp:
            d = descend_root(ps - amp, dps, ddp)
            if d == math.inf:
                return math.inf, False
            if d > CLOCK_ULPS * (abs(t) + s):  # (a step the clock cannot resolve is no skip)
                s += d
                if s > horizon:
                    return math.inf, False
                continue
        u = cycle(nu, phase, t + s)
        end = piece_end(waveform, u)
        if (end - u) * 1e13 < 1.0:  # at a piece boundary up to round-off: the next piece
            u = end if end < 1.0 else 0.0
            end = piece_end(waveform, u)
        w0, w1, w2 = wave(waveform, u, amp, nu)
        r = descend_root(ps + sgn * w0, dps + sgn * w1, ddp + sgn * w2)
        span = (end - u) / nu
        if r <= span:
            s += r
            return (s, False) if s <= horizon else (math.inf, False)
        s += span
        if s > horizon:
            return math.inf, False
    return s, True


@inlined
def _sine_delay(p0, dp0, ddp, sgn, amp, nu, phase, t, horizon):
    """First root of h(s) = p(s) + sgn A sin(2 pi (nu (t + s) + phase)) by safe steps:
    (delay, re-check flag); delay inf if none before ``horizon`` (module doc (a), (c))."""
    om = _TWO_PI * nu
    bound = abs(ddp) + amp * om * om
    s = 0.0
    for _ in range(MAX_STEPS):
        ps = p0 + (dp0 + 0.5 * ddp * s) * s
        dps = dp0 + ddp * s
        if ps > amp:
            d = descend_root(ps - amp, dps, ddp)
            if d == math.inf:
                return math.inf, False
            if d > CLOCK_ULPS * (abs(t) + s):  # (a step the clock cannot resolve is no skip)
                s += d
                if s > horizon:
                    return math.inf, False
                continue
        th = _TWO_PI * cycle(nu, phase, t + s)
        h = ps + sgn * amp * math.sin(th)
        dh = dps + sgn * amp * om * math.cos(th)
        hp = h if h > 0.0 else 0.0
        q = math.sqrt(dh * dh + 2.0 * bound * hp)
        if dh > 0.0:
            step = (dh + q) / bound
        else:
            den = q - dh
            step = 2.0 * hp / den if den > 0.0 else 0.0
        tol = CLOCK_ULPS * (abs(t) + s)
        if step <= tol:
            if dh < 0.0:
                return (s, False) if s <= horizon else (math.inf, False)
            step = tol if tol > 0.0 else 1e-300  # touching without closing: step over
        s += step
        if s > horizon:
            return math.inf, False
    return s, True


@inlined
def contact_delay(x, v, g, radius, rest, side, t, horizon, spec, a):
    """Time from t until a sphere (coordinate x, velocity v, acceleration g along axis a)
    touches wall (a, side) at rest position ``rest``: (delay, re-check flag), delay inf if
    none (for a vibrating wall: none before ``horizon``). ``spec`` None: walls at rest."""
    if side == 0:
        p0 = x - radius - rest
        dp0 = v
        ddp = g
        sgn = -1.0
    else:
        p0 = rest - radius - x
        dp0 = -v
        ddp = -g
        sgn = 1.0
    if spec is None:
        return descend_root(p0, dp0, ddp), False
    if spec.kind[a, side] != VIBRATING:
        return descend_root(p0, dp0, ddp), False
    wf = spec.waveform[a, side]
    amp = spec.amplitude[a, side]
    nu = spec.frequency[a, side]
    phase = spec.phase[a, side]
    if wf == SINE:
        return _sine_delay(p0, dp0, ddp, sgn, amp, nu, phase, t, horizon)
    return _piecewise_delay(p0, dp0, ddp, sgn, amp, nu, phase, wf, t, horizon)


@inlined
def predict_walls(i, t, before, rec, space, flight, spec):
    """Earliest wall event of particle i (streamed to t) for walls of any kind (``spec`` a
    :class:`~granulargas.engine._state.WallSpec`, or None: hard walls at rest), under any
    flight (None or the gravity vector): (time, tag), tag = 2 a + side, plus
    :data:`RECHECK` for a re-check; (inf, 0) if none before ``before``."""
    best = math.inf
    tag = 0
    horizon = before - t
    axes = space.wall_axes
    for k in range(axes.shape[0]):
        a = axes[k]
        g = 0.0 if flight is None else flight[a]
        for side in range(2):
            rest = 0.0 if side == 0 else space.box[a]
            if spec is not None:  # a vibrating wall rests A inside the box (amplitude 0 for the others)
                rest = spec.amplitude[a, 0] if side == 0 else space.box[a] - spec.amplitude[a, 1]
            s, again = contact_delay(rec[i, a], rec[i, 3 + a], g, rec[i, 7], rest, side, t,
                                     horizon, spec, a)
            if s < best:
                best = s
                tag = 2 * a + side + (RECHECK if again else 0)
    return t + best, tag


# ------------------------------------------------------------------ collisions
@inlined
def wall_uniforms(seed, k):
    """Four uniform numbers in (0, 1] for the k-th wall collision of a run: counter based,
    SplitMix64 of the counters 4 k + r, r = 0..3, under a key from ``seed``
    (:func:`granulargas.engine._drive.mix64`)."""
    key = mix64(np.uint64(seed) ^ _SALT)
    base = np.uint64(k) << _S2
    return (1.0 - _uniform(key, base), 1.0 - _uniform(key, base | np.uint64(1)),
            1.0 - _uniform(key, base | np.uint64(2)), 1.0 - _uniform(key, base | np.uint64(3)))


@inlined
def thermal_velocity(seed, k, scale):
    """Outgoing speed away from a thermal wall and two tangential components for the k-th
    wall collision: sqrt(-2 ln u1) scale and Box-Muller normals times ``scale`` = sqrt(T_w/m)."""
    u1, u2, u3, u4 = wall_uniforms(seed, k)
    r = math.sqrt(-2.0 * math.log(u3))
    return (scale * math.sqrt(-2.0 * math.log(u1)), scale * r * math.cos(_TWO_PI * u4),
            scale * r * math.sin(_TWO_PI * u4))


@inlined
def moving_wall_collision(vn, wv, eps, mi, side):
    """Collision with a wall moving at ``wv`` along its normal axis: the particle's new
    normal velocity W' - eps (v_n - W'), the energy dissipated, the energy the wall gives
    the gas (kinetic energy gained + dissipated) and the momentum delivered to the wall
    (>= 0), or a new velocity equal to ``vn`` if the particle does not approach the wall.
    ``side`` 0: the wall is below (approach: v_n < W'), 1: above."""
    u = vn - wv
    if (u >= 0.0) if side == 0 else (u <= 0.0):
        return vn, 0.0, 0.0, 0.0
    v_new = wv - eps * u
    loss = 0.5 * (1.0 - eps * eps) * mi * u * u
    gain = 0.5 * mi * (v_new * v_new - vn * vn)
    return v_new, loss, gain + loss, (1.0 + eps) * mi * abs(u)
