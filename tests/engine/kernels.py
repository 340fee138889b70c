"""Python entry points for engine kernels that the event loop calls only from compiled code.

The engine compiles those kernels without numba's CPython wrappers (which unbox every
array of a record and cost first-compile time); the tests call them through these
thin compiled functions instead.
"""

from granulargas._numba import jit
from granulargas.engine import _calendar, _cells, _drive


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
