"""Cell grid: the pruned stencil of a list rebuild against a brute-force geometric reference."""

import itertools

import numpy as np
import pytest

from granulargas.engine._state import space
from tests.engine.kernels import cell_coord, reach


def _expected(p, cut, box, ncell, walls=()):
    """{(cell index, offset code): distance from p to that cell} for the 27 (9) cells around p
    (none beyond the walls of the axes in ``walls``)."""
    d3 = ncell[2] >= 3
    c = [cell_coord(float(p[a]), float(box[a]), int(ncell[a])) for a in range(3)]
    w = box / ncell
    out = {}
    for o in itertools.product((-1, 0, 1), (-1, 0, 1), (-1, 0, 1) if d3 else (0,)):
        if any(not 0 <= c[a] + o[a] < ncell[a] for a in walls):
            continue
        gap = 0.0
        for a in range(3):
            if a == 2 and not d3:
                continue
            lo, hi = (c[a] + o[a]) * w[a], (c[a] + o[a] + 1) * w[a]
            gap += max(lo - p[a], 0.0, p[a] - hi) ** 2
        k = [(c[a] + o[a]) % ncell[a] for a in range(3)]
        code = (o[0] + 1) + 3 * (o[1] + 1) + 9 * (o[2] + 1)
        out[(k[0] + ncell[0] * (k[1] + ncell[1] * k[2]), code)] = np.sqrt(gap)
    return out


@pytest.mark.parametrize("dim, walls", [(2, ()), (3, ()), (2, (1,)), (3, (0, 2))])
def test_pruned_stencil_keeps_every_cell_the_cutoff_sphere_reaches(dim, walls):
    """On a wall axis the cells beyond the walls do not exist (no wrap)."""
    rng = np.random.default_rng(7)
    box = np.array([7.3, 6.1, 9.2]) if dim == 3 else np.array([7.3, 6.1, 1.0])
    ncell = np.array([5, 4, 6] if dim == 3 else [5, 4, 1], dtype=np.int64)
    w = box / ncell
    period = box.copy()
    period[list(walls)] = np.inf
    spc = space(box, period, ncell, np.array(walls, np.int64), dim)
    stencil = np.empty(27, dtype=np.int64)
    reached = []
    for trial in range(3000):
        cut = rng.uniform(0.3, 1.0) * w[:dim].min()
        p = rng.uniform(-0.3, box + 0.3)  # list centres may lie shell/2 outside the box
        if trial % 3 == 0:  # on cell faces and edges exactly
            for a in rng.choice(dim, size=rng.integers(1, dim + 1), replace=False):
                p[a] = rng.integers(0, ncell[a] + 1) * w[a]
        if dim == 2:
            p[2] = 0.5
        inside = bool(np.all((p[:dim] >= 0) & (p[:dim] < box[:dim])))
        ns = reach(p[0], p[1], p[2], cut, spc, stencil)
        got = {(int(e) >> 5, int(e) & 31) for e in stencil[:ns]}
        assert len(got) == ns
        want = _expected(p, cut, box, ncell, walls)
        assert got <= set(want), "a stencil entry that is not one of the neighbour cells"
        for key, dist in want.items():
            if dist < cut:
                assert key in got, f"cell {key} at distance {dist} < cut {cut} dropped (p = {p})"
            elif dist > cut * 1.000001 and inside:  # outside the box it may keep more
                assert key not in got, f"cell {key} at distance {dist} > cut {cut} kept"
        reached.append(ns)
    # the geometry: on average 1 + 6 + 12 pi/4 + 8 pi/6 = 20.6 of 27 cells for cut = side
    # (3D), 1 + 4 + 4 pi/4 = 8.1 of 9 (2D); fewer here since cut < side
    assert np.mean(reached) < (20.7 if dim == 3 else 8.2)
    if walls:  # a point in the first cell of a wall axis reaches nothing beyond it
        p = np.array([0.5 * w[0], 0.5 * w[1], 0.5 * w[2] if dim == 3 else 0.5])
        ns = reach(p[0], p[1], p[2], 0.9 * w[:dim].min(), spc, stencil)
        for e in stencil[:ns]:
            code = int(e) & 31
            offs = (code % 3 - 1, (code // 3) % 3 - 1, code // 9 - 1)
            assert all(offs[a] >= 0 for a in walls)
