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
