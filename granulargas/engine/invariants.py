"""Invariant checks of the engine's internal state (debugging and tests; O(N^2)).

:func:`check` returns a list of violated invariants (empty when all hold):
event calendar order and index; every particle within shell/2 of its list centre; the
neighbour lists symmetric and complete (every pair with nearest-image centre
distance below R_i + R_j + shell listed both ways); no two particles
overlapping beyond round-off; each particle's scheduled event not later than
its true next collision with any neighbour.
"""

from __future__ import annotations

import numpy as np

from granulargas.engine._calendar import cal_check


def _min_image(d, box):
    return d - box * np.round(d / box)


def check(sim, overlap_tol: float = 1e-9) -> list[str]:
    """Problems found in ``sim``'s internal state (it is built if needed)."""
    if not sim._built:
        sim._build()
    s = sim._s
    box = sim._box3
    t = float(s["scal"][0])
    problems = []
    if not cal_check(s["qt"], s["chunks"], s["qwhere"], s["small"], s["buckets"], s["qi"], s["qf"]):
        problems.append("event calendar broken")
    rec = s["rec"]
    r = rec[:, :3] + rec[:, 3:6] * (t - rec[:, 6])[:, None]
    centre = s["centre"].astype(np.float64)
    off = np.linalg.norm(_min_image(r - centre, box), axis=1)
    if np.any(off > 0.5 * sim.shell * (1 + 1e-6)):
        problems.append(f"particle beyond shell/2 of its list centre: max {off.max():.6g}")
    n = len(r)
    rad = rec[:, 7]
    lists = [set(s["nbl"][i, : s["nbn"][i]].tolist()) for i in range(n)]
    for i in range(n):
        dc = np.linalg.norm(_min_image(centre[i] - centre, box), axis=1)
        want = set(np.flatnonzero(dc < rad[i] + rad + sim.shell).tolist()) - {i}
        if not want <= lists[i]:
            problems.append(f"list of {i} misses {sorted(want - lists[i])[:5]}")
        for j in lists[i]:
            if i not in lists[j]:
                problems.append(f"list asymmetric: {j} in list of {i} but not vice versa")
        dr = np.linalg.norm(_min_image(r[i] - r, box), axis=1)
        dr[i] = np.inf
        bad = np.flatnonzero(dr < (rad[i] + rad) * (1 - overlap_tol))
        if len(bad):
            problems.append(f"overlap of {i} with {bad[:5].tolist()}")
    return problems
