"""Python entry points for engine kernels that the event loop calls only from compiled code.

The engine compiles those kernels without numba's CPython wrappers (which unbox every
array of a record and cost first-compile time); the tests call them through these
thin compiled functions instead.
"""

from granulargas._numba import jit
from granulargas.engine import _calendar, _cells, _collide, _drive, _rough


@jit
def cal_peek(cal):
    return _calendar.cal_peek(cal)


@jit
def cal_update(i, t, cal):
    return _calendar.cal_update(i, t, cal)


@jit
def rebuild_list(i, rec, lists, cells, space, rmax, shell):
    return _cells.rebuild_list(i, rec, lists, cells, space, rmax, shell)


@jit
def reach(x, y, z, cut, space, stencil):
    return _cells._reach(x, y, z, cut, space, stencil)


@jit
def cell_coord(x, length, n):
    return _cells.cell_coord(x, length, n)


@jit
def kick_normals(seed, step, ident):
    return _drive.kick_normals(seed, step, ident)


# ---- the flight and the wall kinds (granulargas.engine._flight, _walls)
from granulargas.engine import _flight, _walls  # noqa: E402


@jit
def descend_root(h, u, a):
    return _flight.descend_root(h, u, a)


@jit
def expiry_delay(dx, dy, dz, vx, vy, vz, radius, flight):
    return _flight.expiry_delay(dx, dy, dz, vx, vy, vz, radius, flight)


@jit
def face_delay(rel, v, g, width, lower, upper):
    return _flight.face_delay(rel, v, g, width, lower, upper)


@jit
def plane_delay(x, v, g, radius, low, high):
    return _flight.plane_delay(x, v, g, radius, low, high)


@jit
def stream(i, t, rec, img, period, flight):
    _flight.stream(i, t, rec, img, period, flight)


@jit
def pair_delay(j, t, xi, yi, zi, vx, vy, vz, ri, rec, period, flight):
    return _flight.pair_delay(j, t, xi, yi, zi, vx, vy, vz, ri, rec, period, flight)


@jit
def contact_delay(x, v, g, radius, rest, side, t, horizon, spec, a):
    return _walls.contact_delay(x, v, g, radius, rest, side, t, horizon, spec, a)


@jit
def wall_motion(spec, a, side, t):
    return _walls.wall_motion(spec, a, side, t)


@jit
def thermal_velocity(seed, k, scale):
    return _walls.thermal_velocity(seed, k, scale)


@jit
def wall_uniforms(seed, k):
    return _walls.wall_uniforms(seed, k)


@jit
def moving_wall_collision(vn, wv, eps, mi, side):
    return _walls.moving_wall_collision(vn, wv, eps, mi, side)


@jit
def rough_pair(vi, vj, wi, wj, n, mi, mj, ki, kj, ri, rj, eps, model, beta, mu):
    """One rough pair collision on 3-vectors (v, w, the unit normal n from j to i), in place,
    by the engine's law (:mod:`granulargas.engine._rough`). Returns (loss, impulse)."""
    sx = ri * wi[0] + rj * wj[0]
    sy = ri * wi[1] + rj * wj[1]
    sz = ri * wi[2] + rj * wj[2]
    un, gx, gy, gz = _rough.contact_slip(vi[0] - vj[0], vi[1] - vj[1], vi[2] - vj[2], n[0], n[1], n[2],
                                         sx, sy, sz)
    fi, fj, ti, tj, si, sj, loss, impulse = _rough.rough_pair_collision(
        un, gx * gx + gy * gy + gz * gz, mi, mj, ki, kj, ri, rj, eps, model, beta, mu)
    cx = n[1] * gz - n[2] * gy
    cy = n[2] * gx - n[0] * gz
    cz = n[0] * gy - n[1] * gx
    vi[0] -= fi * n[0] + ti * gx
    vi[1] -= fi * n[1] + ti * gy
    vi[2] -= fi * n[2] + ti * gz
    vj[0] += fj * n[0] + tj * gx
    vj[1] += fj * n[1] + tj * gy
    vj[2] += fj * n[2] + tj * gz
    wi[0] += si * cx
    wi[1] += si * cy
    wi[2] += si * cz
    wj[0] += sj * cx
    wj[1] += sj * cy
    wj[2] += sj * cz
    return loss, impulse


@jit
def smooth_pair(vi, vj, n, mi, mj, eps):
    """The smooth law (:func:`granulargas.engine._collide.pair_collision`) applied as the engine
    applies it, in place. Returns (loss, impulse)."""
    un = (vi[0] - vj[0]) * n[0] + (vi[1] - vj[1]) * n[1] + (vi[2] - vj[2]) * n[2]
    fi, fj, loss, impulse = _collide.pair_collision(un, mi, mj, eps)
    for a in range(3):
        vi[a] -= fi * n[a]
        vj[a] += fj * n[a]
    return loss, impulse


@jit
def rough_wall(v, w, n, mi, ki, ri, eps, model, beta, mu):
    """A rough particle against a wall at rest with normal n (into the gas), in place, by
    :func:`granulargas.engine._rough.rough_wall_collision`. Returns (loss, momentum)."""
    un, gx, gy, gz = _rough.contact_slip(v[0], v[1], v[2], n[0], n[1], n[2], ri * w[0], ri * w[1], ri * w[2])
    vn_new, ti, si, loss, momentum = _rough.rough_wall_collision(
        un, gx * gx + gy * gy + gz * gz, mi, ki, ri, eps, model, beta, mu)
    cx = n[1] * gz - n[2] * gy
    cy = n[2] * gx - n[0] * gz
    cz = n[0] * gy - n[1] * gx
    v[0] += (vn_new - un) * n[0] - ti * gx
    v[1] += (vn_new - un) * n[1] - ti * gy
    v[2] += (vn_new - un) * n[2] - ti * gz
    w[0] += si * cx
    w[1] += si * cy
    w[2] += si * cz
    return loss, momentum


# ---- the Lees-Edwards list rebuild (granulargas.engine._shear)
from granulargas.engine import _shear  # noqa: E402


@jit
def rebuild_list_le_now(i, t, rec, img, lists, cells, space, flight, rmax, shell, sh):
    """Particle i streamed to t, back inside the box through the sheared boundary, and its list
    rebuilt there (what a list expiry does)."""
    _flight.stream(i, t, rec, img, space.period, flight)
    _shear.le_wrap(i, t, rec, img, sh)
    return _shear.rebuild_list_le(i, t, rec, lists, cells, space, rmax, shell, sh)
