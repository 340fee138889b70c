"""Compiled geometry of free flight between events (numba leaf module).

The geometry of straight flights; the flight itself (straight or under gravity) and the
pair prediction with a partner streamed on its flight are
:mod:`granulargas.engine._flight`. Internally every system is
three-dimensional: a 2D system has z = 0, v_z = 0 and one cell layer, so the
same kernels (one compiled signature) serve disks and spheres. Each axis is
periodic (period L: minimum image, wrap) or bounded by flat hard walls at 0 and
L; a wall axis has period inf, for which the minimum image and the wrap are the
identity, so the same code serves both at no cost.

Pair collision time (free flight, relative position dr, relative velocity dv,
contact distance sigma = R_i + R_j): the smallest s >= 0 with
|dr + dv s| = sigma,

    b = dr.dv < 0 (approaching),  disc = b^2 - dv^2 (dr^2 - sigma^2) >= 0,
    s = (dr^2 - sigma^2) / (-b + sqrt(disc))                           (1)

Form (1) is the cancellation-free root (the textbook (-b - sqrt(disc))/dv^2
loses all digits in grazing collisions). A pair found slightly overlapping
(dr^2 < sigma^2, round-off) and approaching collides at once (s = 0); a pair
that overlaps and recedes is left alone: it separates.
"""

import math

from granulargas._numba import inlined, inlined_ir


@inlined
def min_image(dx, length):
    """Nearest periodic image of a coordinate difference with |dx| < 1.5 L."""
    half = 0.5 * length
    if dx > half:
        return dx - length
    if dx < -half:
        return dx + length
    return dx


@inlined
def collision_delay(dx, dy, dz, ux, uy, uz, sigma):
    """Time until contact of a pair, or inf.

    Written without early returns (every quantity is computed and the answer
    selected at the end): whether a neighbour approaches is a coin toss for the
    branch predictor, and the square root and division pipeline across the
    neighbours of a prediction loop. 10-20 % faster per prediction than
    rejecting early. LLVM may still compile the final selects into one branch on
    ``hit`` (it does in the cell-crossing build, where hits are rare and the
    branch skips the square root and division); a form with 0/1 weights, free of
    branches in the machine code too, was 2-3 % slower there.

    Parameters
    ----------
    dx, dy, dz : float
        r_i - r_j (nearest image), in sigma units.
    ux, uy, uz : float
        v_i - v_j.
    sigma : float
        Contact distance R_i + R_j.

    Returns
    -------
    float
        Delay s >= 0 (0 for an approaching overlapping pair), or inf.
    """
    b = dx * ux + dy * uy + dz * uz
    gap = dx * dx + dy * dy + dz * dz - sigma * sigma
    u2 = ux * ux + uy * uy + uz * uz
    disc = b * b - u2 * gap
    hit = b < 0.0 and disc >= 0.0
    den = math.sqrt(disc if disc > 0.0 else 0.0) - b  # > 0 for a hit
    s = gap / (den if hit else 1.0)
    s = s if gap > 0.0 else 0.0
    return s if hit else math.inf


@inlined
def exit_delay(dx, dy, dz, vx, vy, vz, radius):
    """Time until a particle at offset d from its list centre is at distance ``radius``.

    Returns inf for a particle at rest; 0 if already outside.
    """
    v2 = vx * vx + vy * vy + vz * vz
    if v2 == 0.0:
        return math.inf
    b = dx * vx + dy * vy + dz * vz
    c = radius * radius - (dx * dx + dy * dy + dz * dz)
    if c <= 0.0:
        return 0.0
    # positive root of v2 s^2 + 2 b s - c = 0, cancellation-free
    q = math.sqrt(b * b + v2 * c)
    if b >= 0.0:
        return c / (b + q)
    return (q - b) / v2


@inlined_ir
def wall_delay(x, v, radius, length):
    """Time until a sphere at coordinate x, moving at v along a wall axis, touches a wall.

    The walls are the planes 0 and ``length``; contact at x = R (lower, v < 0) or
    x = L - R (upper, v > 0). Returns (delay, side) with side 0 (lower) or 1
    (upper); delay inf for v = 0, 0 for a sphere already touching (round-off)
    and moving into the wall.
    """
    if v < 0.0:
        gap = x - radius
        return (gap / -v if gap > 0.0 else 0.0), 0
    if v > 0.0:
        gap = length - radius - x
        return (gap / v if gap > 0.0 else 0.0), 1
    return math.inf, 0
