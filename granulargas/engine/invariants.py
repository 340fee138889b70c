"""Invariant checks of the engine's internal state (debugging and tests; O(N^2)).

:func:`check` returns a list of violated invariants (empty when all hold):
event calendar order and index; every particle within shell/2 of its list centre; the
neighbour lists symmetric and complete (every pair with nearest-image centre
distance below R_i + R_j + shell listed both ways) -- or, with cell crossings,
every particle in the cell of its position (up to round-off) and listed once,
in that cell's linked list, cells at least 2 R_max wide; no two particles
overlapping beyond round-off (except a pair whose contact is under way with a
resolved rule: its extended outgoing lines overlap); no particle overlapping a wall beyond round-off
(a vibrating wall at its position at the current time), none with a nonzero image count on a wall
axis; each wall event scheduled for a particle moving into that wall (straight flights; under
gravity a particle moving away from a floor comes back). Particles are streamed on their flight.
"""

from __future__ import annotations

import numpy as np

from granulargas.engine._calendar import cal_check
from granulargas.engine._crossing import FLAT, NEXT, PREV


def _min_image(d, period):
    """Nearest image of coordinate differences d (..., 3); period inf leaves an axis alone."""
    finite = np.isfinite(period)
    p = np.where(finite, period, 1.0)
    return np.where(finite, d - p * np.round(d / p), d)


def check(sim, overlap_tol: float = 1e-9) -> list[str]:
    """Problems found in ``sim``'s internal state (it is built if needed)."""
    if not sim._built:
        sim._build()
    e = sim._engine
    period = sim._space.period
    t = float(e.counters[0]["time"])
    problems = []
    if not cal_check(e.calendar):
        problems.append("event calendar broken")
    rec = e.particles.rec
    dt = (t - rec[:, 6])[:, None]
    flight = sim._flight()
    r = rec[:, :3] + rec[:, 3:6] * dt + (0.0 if flight is None else 0.5 * flight * dt * dt)
    if sim.neighbours == "cells":
        problems += _check_grid(sim, e.lists, r)
    else:
        problems += _check_lists(sim, e.lists, r, period)
    n = len(r)
    rad = rec[:, 7]
    for i in range(n):
        dr = np.linalg.norm(_min_image(r[i] - r, period), axis=1)
        dr[i] = np.inf
        bad = np.flatnonzero(dr < (rad[i] + rad) * (1 - overlap_tol))
        if e.contacts is not None:
            cu, cp = e.contacts.until, e.contacts.partner
            bad = [int(j) for j in bad if not ((cp[i] == j and cu[i] > t) or (cp[j] == i and cu[j] > t))]
        else:
            bad = bad.tolist()
        if len(bad):
            problems.append(f"overlap of {i} with {bad[:5]}")
    for a in sim._space.wall_axes:
        a = int(a)
        box = sim._space.box[a]
        lo, hi = 0.0, box
        if sim.walls is not None:
            lo = float(sim.walls.side(a, 0).position(box, 0, t))
            hi = float(sim.walls.side(a, 1).position(box, 1, t))
        gap = np.minimum(r[:, a] - rad - lo, hi - rad - r[:, a])
        bad = np.flatnonzero(gap < -overlap_tol * rad)
        if len(bad):
            problems.append(f"overlap with a wall of axis {a}: particles {bad[:5].tolist()}")
        if np.any(e.particles.img[:, a] != 0):
            problems.append(f"nonzero image count on wall axis {a}")
    partner, tag = e.events.partner, e.events.tag
    for i in np.flatnonzero(partner == -2) if flight is None else ():
        a, side = int(tag[i]) >> 1, int(tag[i]) & 1
        v = rec[i, 3 + a]
        if not (v < 0 if side == 0 else v > 0):
            problems.append(f"wall event of {i} for a wall it moves away from")
    return problems


def _check_grid(sim, grid, r):
    """Cell-crossing mode: cells, their linked lists and every particle's place."""
    problems = []
    space = sim._space
    d = sim.dimension
    n = len(r)
    width = space.box / space.ncell
    if np.any(width[:d] < 2.0 * float(sim.radii.max())):
        problems.append(f"cells narrower than the largest diameter: {width[:d].tolist()}")
    seen = np.zeros(n, dtype=np.int64)
    for c in range(int(np.prod(space.ncell))):
        j, prev = int(grid.head[c]), -1
        while j >= 0:
            seen[j] += 1
            if grid.cell[j, FLAT] != c or grid.cell[j, PREV] != prev:
                problems.append(f"cell list of cell {c} broken at particle {j}")
                break
            prev, j = j, int(grid.cell[j, NEXT])
    if np.any(seen != 1):
        problems.append(f"particles not listed exactly once: {np.flatnonzero(seen != 1)[:5].tolist()}")
    flat = grid.cell[:, 0] + space.ncell[0] * (grid.cell[:, 1] + space.ncell[1] * grid.cell[:, 2])
    if np.any(flat != grid.cell[:, FLAT]):
        problems.append("cell coordinates and flat cell index disagree")
    tol = 1e-9 * float(np.max(space.box[:d]))
    for a in range(d):
        lo = grid.cell[:, a] * width[a]
        rel = r[:, a] - lo
        if np.isfinite(space.period[a]):
            rel -= space.period[a] * np.round(rel / space.period[a])
        bad = np.flatnonzero((rel < -tol) | (rel > width[a] + tol))
        if len(bad):
            problems.append(f"particles outside their cell on axis {a}: {bad[:5].tolist()}")
    return problems


def _check_lists(sim, lists_rec, r, period):
    """Neighbour-list mode: every particle near its list centre, lists symmetric and complete."""
    problems = []
    e = sim._engine
    rec = e.particles.rec
    centre = lists_rec.centre.astype(np.float64)
    off = np.linalg.norm(_min_image(r - centre, period), axis=1)
    if np.any(off > 0.5 * sim.shell * (1 + 1e-6)):
        problems.append(f"particle beyond shell/2 of its list centre: max {off.max():.6g}")
    n = len(r)
    rad = rec[:, 7]
    nbl, nbn = lists_rec.nbl, lists_rec.nbn
    lists = [set(nbl[i, : nbn[i]].tolist()) for i in range(n)]
    for i in range(n):
        dc = np.linalg.norm(_min_image(centre[i] - centre, period), axis=1)
        want = set(np.flatnonzero(dc < rad[i] + rad + sim.shell).tolist()) - {i}
        if not want <= lists[i]:
            problems.append(f"list of {i} misses {sorted(want - lists[i])[:5]}")
        for j in lists[i]:
            if i not in lists[j]:
                problems.append(f"list asymmetric: {j} in list of {i} but not vice versa")
    return problems
