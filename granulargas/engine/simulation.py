"""The Python driver of the event-driven engine: :class:`Simulation`.

``Simulation`` owns the public state (in particle-id order) and, while a run is
under way, a compiled internal state in *memory order*: particles sorted along
a Morton (Z-order) curve of the cell grid so that neighbours sit close in
memory. The internal state (list centres, neighbour lists, cells, one event per
particle, event calendar) is built from the public state alone at the start of the first
``run`` after construction or :meth:`Simulation.synchronise`, which is what
makes a restart from a file written at a synchronised time bit-identical to
the uninterrupted run. The driver never loops over particles; between compiled
chunks it calls ``progress``, grows full neighbour lists and turns status codes
into :mod:`granulargas.errors` exceptions.
"""

from __future__ import annotations

import math

import numpy as np

from granulargas.engine import _loop
from granulargas.engine._cells import CELL_OVERFLOW, OVERFLOW, build_all_lists
from granulargas.engine._calendar import allocate_calendar, cal_build, cal_width
from granulargas.engine.rules import CollisionRule
from granulargas.errors import (
    ConfigError,
    InelasticCollapseError,
    SimulationError,
    TableRangeError,
)

_INT_MAX = np.iinfo(np.int64).max

#: Smallest box side in largest diameters: 3 cells per side (so that the 27
#: neighbour cells are distinct), each one diameter wide plus a neighbour-list
#: shell of at least 0.05 diameters: 3 x 1.05.
MIN_BOX_DIAMETERS = 3.15


def default_shell(packing: float) -> float:
    """Neighbour-list shell width in units of the largest diameter.

    A thin shell means short lists but frequent expiries; the optimum drops
    with density (tuned with ``scripts/bench_engine.py``).
    """
    if packing < 0.15:
        return 1.2
    if packing < 0.4:
        return 0.7
    return 0.45


def _part1by2(x):
    x = x.astype(np.uint64) & np.uint64(0x1FFFFF)
    x = (x | (x << np.uint64(32))) & np.uint64(0x1F00000000FFFF)
    x = (x | (x << np.uint64(16))) & np.uint64(0x1F0000FF0000FF)
    x = (x | (x << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    x = (x | (x << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    x = (x | (x << np.uint64(2))) & np.uint64(0x1249249249249249)
    return x


def _aligned_records(n):
    """Zeroed (n, 8) float64 array whose rows start on 64-byte boundaries (cache lines)."""
    buf = np.zeros(n * 8 + 8)
    offset = (-buf.ctypes.data % 64) // 8
    return buf[offset : offset + n * 8].reshape(n, 8)


def _aligned_int_rows(rows, width):
    """Uninitialised (rows, width) int32 array starting on a 64-byte boundary."""
    buf = np.empty(rows * width + 16, dtype=np.int32)
    offset = (-buf.ctypes.data % 64) // 4
    return buf[offset : offset + rows * width].reshape(rows, width)


def morton_order(positions3, box3, ncell):
    """Stable permutation sorting particles by the Z-order key of their cell."""
    key = np.zeros(positions3.shape[0], dtype=np.uint64)
    for a in range(3):
        c = np.minimum((positions3[:, a] * (ncell[a] / box3[a])).astype(np.int64), ncell[a] - 1)
        c = np.maximum(c, 0)
        key |= _part1by2(c) << np.uint64(a)
    return np.argsort(key, kind="stable")


class Simulation:
    """Event-driven hard spheres (d = 3) or disks (d = 2) in a periodic box.

    Parameters
    ----------
    positions : array (N, d)
        Positions in units of the reference diameter; wrapped into [0, L).
    velocities : array (N, d)
    radii, masses : array (N,)
    box : array (d,)
        Box side lengths L.
    rule : CollisionRule
    time : float
        Current time.
    collisions : int
        Pair collisions so far (a counter carried over on restart).
    images : int array (N, d), optional
        Periodic image counters (unwrapped position = position + images * L).
    last_collision : array (N,), optional
        Time of each particle's last collision (-inf: none); used by the TC model.
    shell : float, optional
        Neighbour-list shell in units of the largest diameter (default from the
        packing fraction, see :func:`default_shell`).
    collapse_count : int
        Inelastic-collapse detector: stop when one particle collides this many
        times in a row, each within ``1e-10`` thermal collision-length times
        of the previous one.
    events : int
        Events processed so far (counter carried over on restart).
    dissipated_energy : float
        Energy dissipated so far (carried over on restart).

    Notes
    -----
    ``run(until)`` processes every event with time <= ``until`` and sets
    ``time = until``. Observables are exact at ``time``; ``positions`` is a
    synchronised copy. ``synchronise()`` brings every particle clock to
    ``time`` and makes the next ``run`` rebuild all internal structures from
    the public state.
    """

    def __init__(self, positions, velocities, radii, masses, box, rule: CollisionRule,
                 time: float = 0.0, collisions: int = 0, images=None, last_collision=None,
                 *, events: int = 0, dissipated_energy: float = 0.0, shell: float | None = None,
                 collapse_count: int = 100):
        pos = np.array(positions, dtype=np.float64, order="C", copy=True)
        if pos.ndim != 2 or pos.shape[1] not in (2, 3):
            raise ConfigError(f"positions: shape {pos.shape}, expected (N, 2) or (N, 3)")
        n, d = pos.shape
        if n < 2:
            raise ConfigError(f"positions: N = {n}, need at least 2 particles")
        self.dimension = d
        vel = np.array(velocities, dtype=np.float64, order="C", copy=True)
        if vel.shape != (n, d):
            raise ConfigError(f"velocities: shape {vel.shape}, expected {(n, d)}")
        rad = np.array(np.broadcast_to(np.asarray(radii, dtype=np.float64), (n,)), order="C")
        mas = np.array(np.broadcast_to(np.asarray(masses, dtype=np.float64), (n,)), order="C")
        if not (np.all(rad > 0) and np.all(np.isfinite(rad))):
            raise ConfigError("radii: every radius must be finite and > 0")
        if not (np.all(mas > 0) and np.all(np.isfinite(mas))):
            raise ConfigError("masses: every mass must be finite and > 0")
        bx = np.array(np.broadcast_to(np.asarray(box, dtype=np.float64), (d,)), order="C")
        if not np.all(bx > 0):
            raise ConfigError(f"box = {bx.tolist()}: side lengths must be > 0")
        if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(vel))):
            raise ConfigError("positions/velocities: non-finite values")
        if not isinstance(rule, CollisionRule):
            raise TypeError("rule must be a granulargas.engine.CollisionRule")
        img = np.zeros((n, d), dtype=np.int64) if images is None else np.array(images, dtype=np.int64, order="C")
        if img.shape != (n, d):
            raise ConfigError(f"images: shape {img.shape}, expected {(n, d)}")
        shift = np.floor(pos / bx).astype(np.int64)
        pos -= shift * bx
        img += shift
        pos[pos >= bx] = 0.0  # guard against -tiny + L rounding to L
        lc = np.full(n, -np.inf) if last_collision is None else np.array(last_collision, dtype=np.float64, order="C")
        if lc.shape != (n,):
            raise ConfigError(f"last_collision: shape {lc.shape}, expected ({n},)")

        self._positions, self._velocities, self._images, self._last_collision = pos, vel, img, lc
        self._radii, self._masses, self._box = rad, mas, bx
        self.rule = rule
        self._time = float(time)
        self._collisions = int(collisions)
        self._events = int(events)
        self._dissipated = float(dissipated_energy)
        self._virial = 0.0
        self._kin_int = 0.0
        self._window_start = self._time
        self._rate = float("nan")
        self.collapse_count = int(collapse_count)

        volume = float(np.prod(bx))
        unit = math.pi / 6.0 * 8.0 if d == 3 else math.pi
        self.packing_fraction = float(unit * np.sum(rad**d) / volume)
        dmax = 2.0 * float(rad.max())
        want = default_shell(self.packing_fraction) if shell is None else float(shell)
        if want <= 0:
            raise ConfigError(f"shell = {want}: must be > 0")
        # at least 3 cells per side so that the 27 neighbour cells are distinct
        fit = float(bx.min()) / 3.0 - dmax
        if float(bx.min()) < MIN_BOX_DIAMETERS * dmax:
            raise ConfigError(f"box = {bx.tolist()}: too small for the cell grid, each side must be "
                              f">= {MIN_BOX_DIAMETERS * dmax:.4g} ({MIN_BOX_DIAMETERS:g} largest diameters)")
        self.shell = min(want * dmax, fit)
        cut = dmax + self.shell
        self._box3 = np.ones(3)
        self._box3[:d] = bx
        self._ncell = np.ones(3, dtype=np.int64)
        self._ncell[:d] = np.floor(bx / cut).astype(np.int64)
        self._built = False
        self._nb_width = self._initial_list_width(n, volume, cut)
        mean = n / float(np.prod(self._ncell))
        self._cell_width = 16 * max(1, math.ceil((mean + 5.0 * math.sqrt(mean) + 2) / 16))

    # ------------------------------------------------------------------ build
    def _initial_list_width(self, n, volume, cut):
        d = self.dimension
        vol = 4.0 / 3.0 * math.pi * cut**3 if d == 3 else math.pi * cut**2
        mean = n / volume * vol
        return int(min(n - 1, max(8, math.ceil(mean + 5.0 * math.sqrt(mean) + 4))))

    def _build(self):
        """Internal state from the public state (a pure function of it)."""
        n, d = self._positions.shape
        p3 = np.zeros((n, 3))
        p3[:, :d] = self._positions
        order = morton_order(p3, self._box3, self._ncell)
        self._order = order
        s = {}
        rec = _aligned_records(n)
        rec[:, :3] = p3[order]
        rec[:, 3:6] = 0.0
        rec[:, 3 : 3 + d] = self._velocities[order]
        rec[:, 6] = self._time
        rec[:, 7] = self._radii[order]
        s["rec"] = rec
        img = np.zeros((n, 3), dtype=np.int32)
        img[:, :d] = self._images[order]
        s["img"] = img
        s["centre"] = np.empty((n, 3), dtype=np.float32)  # list centres: see _cells
        s["mass"] = np.ascontiguousarray(self._masses[order])
        s["count"] = np.zeros(n, dtype=np.int32)
        s["partner"] = np.full(n, -1, dtype=np.int32)
        s["pcount"] = np.zeros(n, dtype=np.int32)
        s["lastcoll"] = np.ascontiguousarray(self._last_collision[order])
        s["rapid"] = np.zeros(n, dtype=np.int32)
        ncells = int(np.prod(self._ncell))
        s["cell_n"] = np.zeros(ncells, dtype=np.int32)
        s["cell_of"] = np.empty(n, dtype=np.int32)
        s["nbn"] = np.zeros(n, dtype=np.int32)
        pos = np.ascontiguousarray(rec[:, :3])
        while True:
            s["nbl"] = np.empty((n, self._nb_width), dtype=np.int32)
            s["cell_ids"] = _aligned_int_rows(ncells, self._cell_width)
            st = build_all_lists(pos, s["centre"], rec, self.shell, self._box3, self._ncell,
                                 s["cell_ids"], s["cell_n"], s["cell_of"],
                                 s["nbl"], s["nbn"])
            if st == OVERFLOW:
                self._nb_width = min(n - 1, max(self._nb_width + 4, int(self._nb_width * 1.5)))
            elif st == CELL_OVERFLOW:
                self._cell_width += 16
            else:
                break
        # compact the lists to what this state needs (+ a margin; they grow on demand)
        width = min(n - 1, int(s["nbn"].max()) + 6)
        if width < self._nb_width:
            s["nbl"] = np.ascontiguousarray(s["nbl"][:, :width])
            self._nb_width = width
        s["scratch"] = self._new_scratch()
        s["stencil"] = np.empty(27, dtype=np.int64)
        s.update(allocate_calendar(n))
        _loop.predict_all(self._time, rec, s["centre"], s["count"], s["nbl"], s["nbn"],
                          s["partner"], s["pcount"], self._box3, 0.5 * self.shell * (1.0 - 1e-9),
                          s["qt"])
        self._place_events(s, self._time)
        with np.errstate(over="ignore", under="ignore"):
            mv2 = float(np.sum(self._masses[:, None] * self._velocities**2))
        s["scal"] = np.array([self._time, self._dissipated, self._virial, self._kin_int, mv2])
        s["iscal"] = np.array([self._collisions, self._events, -1, -1, 0, 0], dtype=np.int64)
        self._s = s
        self._built = True

    def _place_events(self, s, now):
        """(Re)build the event calendar from the event times ``s["qt"]`` at time ``now``."""
        if not cal_build(now, s["qt"], s["chunks"], s["qwhere"], s["small"], s["buckets"], s["qi"],
                         s["qf"]):
            raise SimulationError(f"event calendar overflow at t = {now:.12g}: more simultaneous "
                                  f"events than its window holds ({s['small'].shape[0]})")
        self._calendar_time = now

    def _new_scratch(self):
        """Work space of a list rebuild: every candidate of the 27 cells, at least a full list."""
        return np.empty(max(self._nb_width, 27 * self._cell_width), dtype=np.int32)

    def _grow_cells(self):
        s = self._s
        old = s["cell_ids"]
        self._cell_width += 16
        new = _aligned_int_rows(old.shape[0], self._cell_width)
        new[:, : old.shape[1]] = old
        s["cell_ids"] = new
        s["scratch"] = self._new_scratch()

    def _grow_lists(self):
        s = self._s
        n = self.n
        new = min(n - 1, max(self._nb_width + 4, int(self._nb_width * 1.2)))
        if new <= self._nb_width:
            raise SimulationError("neighbour list cannot grow further (internal error)")
        nbl = np.empty((n, new), dtype=np.int32)
        nbl[:, : self._nb_width] = s["nbl"]
        s["nbl"] = nbl
        self._nb_width = new
        s["scratch"] = self._new_scratch()

    # -------------------------------------------------------------------- run
    def run(self, until: float, max_collisions: int | None = None, progress=None) -> "Simulation":
        """Process all events with time <= ``until``; then ``time = until``.

        Parameters
        ----------
        until : float
            End time (absolute). ``inf`` is allowed together with ``max_collisions``.
        max_collisions : int, optional
            Stop right after this many further pair collisions; ``time`` is then
            the time of the last one and ``run`` returns normally (check
            ``sim.time < until``).
        progress : callable, optional
            ``progress(sim)`` is called between compiled chunks and at the end.

        Raises
        ------
        InelasticCollapseError, TableRangeError, SimulationError
        """
        until = float(until)
        if until < self.time:
            raise ValueError(f"run(until={until}): the simulation is already at time {self.time}")
        if math.isinf(until) and max_collisions is None:
            raise ValueError("run(until=inf) needs max_collisions")
        if not self._built:
            self._build()
        s = self._s
        start_time, start_coll = self.time, self.collisions
        target = _INT_MAX if max_collisions is None else start_coll + int(max_collisions)
        vmax = float(np.max(np.abs(s["rec"][:, 3:6])))
        if not (vmax < 1e150) or (0.0 < vmax < 1e-150):
            raise SimulationError(f"velocities out of range at t = {self.time:.12g} (max |v_a| = "
                                  f"{vmax:.3g}): squared speeds must stay within float64; rescale "
                                  f"the units")
        kind, eps, tc, pref, inv_h, coeffs = self.rule.kernel_arguments()
        v2 = s["scal"][4] / float(np.sum(s["mass"]))
        scale = 2.0 * float(self._radii.min()) / math.sqrt(v2) if v2 > 0 else 1.0
        fpar = np.array([eps, tc, pref, inv_h, self.shell, 1e-10 * scale, float(self._radii.max())])
        chunk = max(1_000_000, 2 * self.n)
        if self._calendar_time != self.time:
            # the window width must stay matched to the event rate (a cooling gas slows
            # down): the events are placed anew when it is off by more than a factor 2
            ratio = cal_width(self.time, s["qt"]) / float(s["qf"][0])
            if not 0.5 <= ratio <= 2.0:
                self._place_events(s, self.time)
        while True:
            status = _loop.advance(
                s["rec"], s["img"], s["centre"], s["mass"], s["count"],
                s["partner"], s["pcount"], s["lastcoll"], s["rapid"], s["nbl"], s["nbn"], s["scratch"],
                s["stencil"],
                s["cell_ids"], s["cell_n"], s["cell_of"],
                s["qt"], s["chunks"], s["qwhere"], s["small"], s["buckets"], s["qi"], s["qf"], self._box3, self._ncell, kind, fpar, coeffs,
                self.collapse_count, until, chunk, target, s["scal"], s["iscal"])
            if status == _loop.BUDGET:
                if progress is not None:
                    progress(self)
                continue
            if status == OVERFLOW:
                self._grow_lists()
                continue
            if status == CELL_OVERFLOW:
                self._grow_cells()
                continue
            if status in (_loop.DONE, _loop.MAX_COLLISIONS):
                break
            self._raise(status)
        dt = self.time - start_time
        self._rate = 2.0 * (self.collisions - start_coll) / (self.n * dt) if dt > 0 else float("nan")
        if progress is not None:
            progress(self)
        return self

    def _raise(self, status):
        s = self._s
        i, j = int(s["iscal"][2]), int(s["iscal"][3])
        ids = [int(self._order[k]) for k in (i, j) if k >= 0]
        where = f"at t = {s['scal'][0]:.12g} after {int(s['iscal'][0])} collisions (particles {ids})"
        if status == _loop.COLLAPSE:
            if self.rule.kind == "constant":
                raise InelasticCollapseError(
                    f"inelastic collapse {where}: the collision rate diverges; use the TC model "
                    f"(CollisionRule.constant(eps, tc_time=...)) or a viscoelastic rule")
            raise SimulationError(f"endless rapid re-collisions {where} (round-off loop)")
        if status == _loop.TABLE_RANGE:
            raise TableRangeError(f"impact beyond the restitution table {where}: build the table "
                                  f"with a larger beta_max")
        if status == _loop.WATCHDOG:
            raise SimulationError(f"event-queue watchdog {where}: an event in the past or an endless "
                                  f"run of zero-time events")
        if status == _loop.CALENDAR:
            raise SimulationError(f"event calendar overflow {where}: more simultaneous events than "
                                  f"its window holds ({self._s['small'].shape[0]})")
        raise SimulationError(f"engine status {status} {where}")

    def synchronise(self) -> "Simulation":
        """Stream all particles to ``time`` and wrap; the next run rebuilds the queue."""
        if self._built:
            s = self._s
            self._positions, self._images = self._synchronised()
            n, d = self._positions.shape
            inv = self._order
            vel = np.empty((n, d))
            vel[inv] = s["rec"][:, 3 : 3 + d]
            self._velocities = vel
            lc = np.empty(n)
            lc[inv] = s["lastcoll"]
            self._last_collision = lc
            sc = s["scal"]
            self._time = float(sc[0])
            self._dissipated, self._virial, self._kin_int = float(sc[1]), float(sc[2]), float(sc[3])
            self._collisions, self._events = int(s["iscal"][0]), int(s["iscal"][1])
            self._built = False
            self._s = None
        return self

    def _synchronised(self):
        s = self._s
        n, d = self._positions.shape
        r = np.empty((n, 3))
        img = np.empty((n, 3), dtype=np.int32)
        _loop.synchronised(s["rec"], s["img"], self._box3, s["scal"][0], r, img)
        pos = np.empty((n, d))
        pos[self._order] = r[:, :d]
        im = np.empty((n, d), dtype=np.int64)
        im[self._order] = img[:, :d]
        return pos, im

    # ----------------------------------------------------------- public state
    @property
    def n(self) -> int:
        """Number of particles."""
        return self._positions.shape[0]

    @property
    def time(self) -> float:
        return float(self._s["scal"][0]) if self._built else self._time

    @property
    def collisions(self) -> int:
        return int(self._s["iscal"][0]) if self._built else self._collisions

    @property
    def events(self) -> int:
        return int(self._s["iscal"][1]) if self._built else self._events

    @property
    def positions(self) -> np.ndarray:
        """Positions (N, d) at ``time``, wrapped into [0, L) (a copy)."""
        return self._synchronised()[0] if self._built else self._positions.copy()

    @property
    def images(self) -> np.ndarray:
        return self._synchronised()[1] if self._built else self._images.copy()

    @property
    def unwrapped_positions(self) -> np.ndarray:
        pos, img = self._synchronised() if self._built else (self._positions, self._images)
        return pos + img * self._box

    @property
    def velocities(self) -> np.ndarray:
        if not self._built:
            return self._velocities.copy()
        out = np.empty_like(self._velocities)
        out[self._order] = self._s["rec"][:, 3 : 3 + self.dimension]
        return out

    @property
    def last_collision(self) -> np.ndarray:
        if not self._built:
            return self._last_collision.copy()
        out = np.empty(self.n)
        out[self._order] = self._s["lastcoll"]
        return out

    @property
    def radii(self) -> np.ndarray:
        return self._radii.copy()

    @property
    def masses(self) -> np.ndarray:
        return self._masses.copy()

    @property
    def box(self) -> np.ndarray:
        return self._box.copy()

    # ------------------------------------------------------------ observables
    def _vm(self):
        if self._built:
            return self._s["rec"][:, 3 : 3 + self.dimension], self._s["mass"]
        return self._velocities, self._masses

    @property
    def kinetic_energy(self) -> float:
        """Total kinetic energy sum m v^2 / 2."""
        v, m = self._vm()
        return float(0.5 * np.sum(m[:, None] * v * v))

    @property
    def momentum(self) -> np.ndarray:
        """Total momentum (d,)."""
        v, m = self._vm()
        return np.sum(m[:, None] * v, axis=0)

    @property
    def temperature(self) -> float:
        """Granular temperature m <c^2> / d with c the peculiar velocity (k_B = 1)."""
        v, m = self._vm()
        vcm = np.sum(m[:, None] * v, axis=0) / np.sum(m)
        c = v - vcm
        return float(np.sum(m[:, None] * c * c) / (self.dimension * len(m)))

    @property
    def dissipated_energy(self) -> float:
        """Kinetic energy dissipated in collisions since construction (cumulative)."""
        return float(self._s["scal"][1]) if self._built else self._dissipated

    @property
    def collision_rate(self) -> float:
        """Collisions per particle per unit time (2 x pair collisions / N / dt) during the last run."""
        return self._rate

    def pressure_window(self) -> float:
        """Mean pressure since the previous call (or construction), then reset.

        P = [ integral of sum_i m_i c_i^2 dt + sum_coll r_ij . Delta p_ij ] / (d V Delta t)
        (kinetic plus collisional virial; c is the peculiar velocity).
        """
        if self._built:
            sc = self._s["scal"]
            kin, vir = float(sc[3]), float(sc[2])
            sc[2] = 0.0
            sc[3] = 0.0
        else:
            kin, vir = self._kin_int, self._virial
        self._virial = 0.0
        self._kin_int = 0.0
        t = self.time
        dt = t - self._window_start
        self._window_start = t
        if dt <= 0:
            return float("nan")
        p = self.momentum
        kin -= float(p @ p) / float(np.sum(self._masses)) * dt
        return (kin + vir) / (self.dimension * float(np.prod(self._box)) * dt)

    def __repr__(self):
        return (f"Simulation(N={self.n}, d={self.dimension}, packing={self.packing_fraction:.4g}, "
                f"rule={self.rule.kind}, time={self.time:.6g}, collisions={self.collisions})")
