"""The Python driver of the event-driven engine: :class:`Simulation`.

``Simulation`` owns the public state (in particle-id order) and, while a run is
under way, a compiled internal state in *memory order*: particles sorted along
a Morton (Z-order) curve of the cell grid so that neighbours sit close in
memory. The internal state (list centres, neighbour lists, cells, one event per
particle, event calendar) is built from the public state alone at the start of the first
``run`` after construction or :meth:`Simulation.synchronise`, which is what
makes a restart from a file written at a synchronised time bit-identical to
the uninterrupted run. The compiled state is a set of named records
(:mod:`granulargas.engine._state`). The driver never loops over particles;
between compiled chunks it calls ``progress``, grows full neighbour lists,
removes the centre-of-mass drift that round-off leaves and turns status codes
into :mod:`granulargas.errors` exceptions.
"""

from __future__ import annotations

import math

import numpy as np

from granulargas.contact.material import pair_constant
from granulargas.contact.oblique import pair_compression_constant
from granulargas.engine import _loop, _shear, _state
from granulargas.engine._resolved import OBLIQUE_BETA_RANGE, OBLIQUE_DELTA_RANGE
from granulargas.engine._calendar import PER_WINDOW, allocate_calendar, cal_build, cal_width
from granulargas.engine._cells import CELL_OVERFLOW, OVERFLOW
from granulargas.engine._crossing import FRESH_SIZE, MARGIN, build_grid, particle_rows
from granulargas.engine._drive import kick_scale
from granulargas.engine.driving import WhiteNoise
from granulargas.engine.pairs import pair_count_matrix, species_of_state
from granulargas.engine.rules import CollisionRule
from granulargas.engine.shear import Shear
from granulargas.engine.walls import Walls
from granulargas.engine.tangential import (
    TangentialRule,
    public_spins,
    rotational_temperature,
    spin_kick_scale,
    spins_of,
)
from granulargas.errors import (
    ConfigError,
    InelasticCollapseError,
    SimulationError,
    TableRangeError,
)
from granulargas.state import PARTICLE_FIELDS, State

_INT_MAX = np.iinfo(np.int64).max
#: per-particle fields of granulargas.state.PARTICLE_FIELDS that the engine moves or uses; it keeps
#: the others as it was given them
OWN_FIELDS = ("positions", "velocities", "images", "radii", "masses", "last_collision", "contact_until",
              "contact_partner")
#: and, with a tangential rule (rough particles), these too
ROUGH_FIELDS = ("angular_velocities", "inertia")
#: boundary conditions of an axis ("lees-edwards": the sheared y axis, with ``shear``)
BOUNDARIES = ("periodic", "wall", "lees-edwards")
#: scratch of a cell scan under shear: the heads of 3 + 4 + 4 columns times 3 layers, and one
SHEAR_FRESH_SIZE = 34
#: neighbour search: neighbour lists with a shell, cell crossings (no lists), or the
#: faster of the two for the packing fraction (:func:`neighbour_mode`)
NEIGHBOURS = ("lists", "cells", "auto")
#: "auto" uses cell crossings below this packing fraction, where they were measured faster than
#: the lists at both N = 10^4 and 10^5 (``scripts/benchmarks/neighbours.py``, elastic gases): in
#: 3D up to 0.2 (at 0.25 the lists are faster at 10^5), in 2D up to 0.3 (at 0.4 the lists are
#: as fast or faster at 10^5)
CELLS_BELOW = {3: 0.2, 2: 0.35}
#: cell-crossing mode: at most this many cells per particle (wider cells in very dilute gases)
CELLS_PER_PARTICLE = 8

#: Smallest box side in largest diameters: 3 cells per side (so that the 27
#: neighbour cells are distinct), each one diameter wide plus a neighbour-list
#: shell of at least 0.05 diameters: 3 x 1.05.
MIN_BOX_DIAMETERS = 3.15

#: Neighbour-list table ``nbl`` (N, width): a build cuts the width to the fullest list
#: plus ``LIST_SLACK``; a list that outgrows it widens the table by ``max(1, width //
#: LIST_GROWTH)`` columns (a few reallocations per run: the fullest list drifts up slowly
#: as the run samples the tail of the list-length distribution). The table's memory
#: follows the longest list, which in a dilute gas is some 2-2.5 times the mean (about
#: 12, :func:`default_shell`), hence the small margin and steps. The width is the row
#: stride only: the lists and their order do not depend on it.
LIST_SLACK = 2
LIST_GROWTH = 16
#: The same rule for the cell table ``cells.ids`` (C, K) of the list centres: a build
#: cuts K to the fullest cell plus ``CELL_SLACK``, growth by ``max(1, K // LIST_GROWTH)``.
CELL_SLACK = 2


def _wider(width: int) -> int:
    """Width of the list or cell table after one growth step: ``width // LIST_GROWTH``
    more columns, at least one."""
    return width + max(1, width // LIST_GROWTH)


def default_shell(packing: float, dimension: int = 3) -> float:
    """Neighbour-list shell width in units of the largest diameter.

    A thin shell means short lists but frequent expiries (a particle leaves its
    shell every shell/2 of travel), a wide one long lists that every prediction
    scans. The fastest shells measured (``scripts/benchmarks/neighbours.py``, 3D packing 0.05
    to 0.45, 2D 0.05 to 0.55) keep about 12 list centres within the cut-off
    1 + shell of a particle, whatever the packing:

    * 3D (number density 6 eta / pi): ``(1 + shell)^3 = 1.5 / eta``, between 0.4
      and 3.5;
    * 2D (number density 4 eta / pi): ``(1 + shell)^2 = 3 / eta``, at most 8, below
      packing 0.5; 0.7 from 0.5 on, where the disks' near-crystalline order makes
      longer lists cost more than the expiries they save.

    A fixed shell would let the expiries per collision grow as the mean free path,
    1 / eta.
    """
    if not packing > 0.0:
        return 3.5 if dimension == 3 else 8.0
    if dimension == 3:
        return min(3.5, max(0.4, (1.5 / packing) ** (1.0 / 3.0) - 1.0))
    if packing >= 0.5:
        return 0.7
    return min(8.0, math.sqrt(3.0 / packing) - 1.0)


def sheared_shell(packing: float, dimension: int = 3) -> float:
    """Neighbour-list shell under Lees-Edwards boundaries, in units of the largest diameter.

    The rule of :func:`default_shell` (as many list centres within reach as the periodic
    lists hold) with the sliding margin counted: a list also holds the centres of the
    adjacent rows that the rows' sliding, by up to the margin D = ``MARGIN`` shells,
    brings within the cut-off c = 1 + shell (:mod:`granulargas.engine._shear`, eq. 3). A
    centre at height dy above the list's own is in the next row with probability
    |dy| / w_y (rows w_y >= c high), and there the reach stretches by D along x: the
    listed volume grows by D |dy| / w_y integrated over the ball's cross-section,
    4 c^3 D / (3 w_y) of the ball's 4 pi c^3 / 3 in 3D and c^2 D / w_y of the disk's
    pi c^2 in 2D, the factor 1 + D / (pi w_y) in both. With w_y = c this gives

        c^d + (MARGIN / pi) c^(d - 1) (c - 1) = the periodic c^d of :func:`default_shell`,

    solved for c (Newton's method from the periodic c, from above), within the same
    bounds. At packing 0.1 in 3D: 1.33 against the periodic 1.47, with lists as long
    as the periodic ones (about 11.5 centres).
    """
    periodic = default_shell(packing, dimension)
    if dimension == 2 and packing >= 0.5:
        return periodic
    target = (1.0 + periodic) ** dimension
    k = _shear.MARGIN / math.pi
    c = 1.0 + periodic
    for _ in range(50):
        f = c ** dimension + k * c ** (dimension - 1) * (c - 1.0) - target
        df = (dimension * c ** (dimension - 1)
              + k * (dimension * c ** (dimension - 1) - (dimension - 1) * c ** (dimension - 2)))
        step = f / df
        c -= step
        if abs(step) < 1e-14 * c:
            break
    low = 0.4 if dimension == 3 else 0.0
    return min(periodic, max(low, c - 1.0))


def neighbour_mode(neighbours: str, packing: float, dimension: int = 3) -> str:
    """The neighbour search a run uses: "lists" or "cells" ("auto": cells below
    :data:`CELLS_BELOW` of the dimension, where they were measured faster,
    ``scripts/benchmarks/neighbours.py``)."""
    if neighbours not in NEIGHBOURS:
        raise ConfigError(f"neighbours = {neighbours!r}: must be one of {', '.join(NEIGHBOURS)}")
    if neighbours == "auto":
        return "cells" if packing < CELLS_BELOW[dimension] else "lists"
    return neighbours


def crossing_grid(box, dmax: float, n: int, extra: float = 0.0) -> np.ndarray:
    """Cells per axis (d,) of the cell-crossing mode: sides at least (1 + extra) dmax
    (times 1 + MARGIN), at least 3 per axis, at most ``CELLS_PER_PARTICLE`` n cells."""
    bx = np.asarray(box, dtype=np.float64)
    width = dmax * (1.0 + extra) * (1.0 + MARGIN)
    while True:
        ncell = np.maximum(3, np.floor(bx / width).astype(np.int64))
        if np.prod(ncell) <= CELLS_PER_PARTICLE * n or np.all(ncell == 3):
            return ncell
        width *= 1.05


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
    """Event-driven hard spheres (d = 3) or disks (d = 2) in a box, periodic or walled per axis.

    Parameters
    ----------
    state : granulargas.state.State
        The state to start from: positions (wrapped into [0, L) on periodic axes; on a
        wall axis every sphere must lie within [R_i, L - R_i], no overlap with a wall),
        velocities, radii, masses, box, boundary (flat hard walls at 0 and L on "wall"
        axes), periodic images (zero on wall axes), the clock and every counter
        (carried over on restart), each particle's last collision (the TC model) and,
        for collisions that take time, the contacts under way.
    rule : CollisionRule
        Collision rule of sphere-sphere and sphere-wall collisions.
    driving : WhiteNoise, optional
        White-noise driving (:class:`granulargas.engine.driving.WhiteNoise`):
        kicks at the times (k + 1/2) * interval, from the state's ``kick_step`` on
        (None: the first k with (k + 1/2) * interval > time).
    neighbours : {"lists", "cells", "auto"}
        Neighbour search: neighbour lists with a shell (list expiries as events),
        cell crossings (no lists; each particle is predicted against the
        particles of its own and the neighbouring cells, and a cell crossing is
        an event; :mod:`granulargas.engine._crossing`), or "auto" (cells below
        :data:`CELLS_BELOW`, lists otherwise and for collisions that take time).
        The two modes process different
        events, so their event sequences agree only up to round-off. Cell
        crossings do not take collisions that take time (ConfigError).
    shell : float, optional
        Neighbour-list shell in units of the largest diameter (default from the
        packing fraction, see :func:`default_shell`).
    collapse_count : int
        Inelastic-collapse detector: stop when one particle collides this many
        times in a row, each within ``1e-10`` thermal collision-length times
        of the previous one.
    remove_drift : bool
        Remove the centre-of-mass velocity that round-off accumulates on the
        periodic axes (see :meth:`run`). False keeps any centre-of-mass motion,
        e.g. a mean flow given on purpose.
    shear : Shear, optional
        Uniform shear flow (:class:`granulargas.engine.shear.Shear`): Lees-Edwards
        boundaries on y (the state's ``boundary`` marks y "lees-edwards"; x periodic, z
        periodic or walls), the flow along x at the rate ``shear.rate``, optionally a
        thermostat (:mod:`granulargas.engine._shear`). Velocities are those of the
        laboratory frame (the flow a (y - L_y/2) included); ``temperature`` and
        ``kinetic_energy`` are peculiar; ``images`` count the image shifts (module doc
        there).
    stress : bool
        Accumulate the pressure tensor for :meth:`pressure_tensor_window` (always on
        with ``shear``; off by default, when the loop carries none of it).
    gravity : sequence of d floats, optional
        A uniform acceleration g (on wall and periodic axes alike; a periodic axis
        falls freely): particles fly on parabolas between events
        (:mod:`granulargas.engine._flight`).
    walls : Walls, optional
        The kind of each side of the wall axes (:class:`granulargas.engine.walls.Walls`:
        hard, thermal or vibrating; a side not given is a hard wall at rest). A vibrating
        wall rests its amplitude inside the box; every sphere must start clear of every
        wall's position at the state's time.
    tangential : TangentialRule, optional
        Rough particles (:class:`granulargas.engine.TangentialRule`): the particles spin, with
        the state's ``angular_velocities`` (default 0) and ``inertia`` kappa = I / (m R^2)
        (default 2/5 for spheres, 1/2 for disks), and collisions (pairs and walls) change the
        tangential velocity of the contact points by that rule (:mod:`granulargas.engine._rough`).
        None: smooth particles (the loop is compiled without spins). The driving's
        ``rotational_fraction`` of the power goes to the spins.

    Notes
    -----
    ``run(until)`` processes every event with time <= ``until`` and sets
    ``time = until``. Observables are exact at ``time``; ``positions`` is a
    synchronised copy. ``synchronise()`` brings every particle clock to
    ``time`` and makes the next ``run`` rebuild all internal structures from
    the public state; :attr:`state` is that public state as a record, and
    ``Simulation(sim.state, rule, ...)`` continues where ``sim.synchronise()``
    would, bit for bit.
    """

    #: the centre-of-mass velocity is removed once V^2 exceeds this fraction of <c^2> ...
    DRIFT_LIMIT = 1e-8
    #: ... if its kinetic energy is below this fraction of the energy that has passed
    #: through the gas (kinetic + dissipated + injected), as round-off drift always is
    ROUND_OFF = 1e-20

    def __init__(self, state: State, rule: CollisionRule, *, driving: WhiteNoise | None = None,
                 neighbours: str = "lists", shell: float | None = None, collapse_count: int = 100,
                 remove_drift: bool = True, shear: Shear | None = None, stress: bool = False, gravity=None,
                 walls: Walls | None = None,
                 tangential: TangentialRule | None = None):
        if not isinstance(state, State):
            raise TypeError("state must be a granulargas.state.State")
        if state.positions is None:
            raise ConfigError("positions: the state has none (a DSMC state); the engine needs positions (N, d)")
        state.check_shapes()
        pos = np.array(state.positions, dtype=np.float64, order="C", copy=True)
        n, d = pos.shape
        if n < 2:
            raise ConfigError(f"positions: N = {n}, need at least 2 particles")
        self.dimension = d
        vel = state.velocities.copy()
        rad, mas = state.radii.copy(), state.masses.copy()
        if not (np.all(rad > 0) and np.all(np.isfinite(rad))):
            raise ConfigError("radii: every radius must be finite and > 0")
        if not (np.all(mas > 0) and np.all(np.isfinite(mas))):
            raise ConfigError("masses: every mass must be finite and > 0")
        if state.box is None:
            raise ConfigError("box: the state has none; the engine needs the box sides (d,)")
        bx = state.box.copy()
        if not np.all(bx > 0):
            raise ConfigError(f"box = {bx.tolist()}: side lengths must be > 0")
        if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(vel))):
            raise ConfigError("positions/velocities: non-finite values")
        if not isinstance(rule, CollisionRule):
            raise TypeError("rule must be a granulargas.engine.CollisionRule")
        self.boundary = _boundary(state.boundary, d)
        if shear is not None and not isinstance(shear, Shear):
            raise TypeError("shear must be a granulargas.engine.shear.Shear or None")
        _check_shear(self.boundary, shear, rule)
        self.shear = shear
        self.stress = bool(stress) or shear is not None
        wall = np.array([b == "wall" for b in self.boundary])
        img = state.array("images")
        if np.any(img[:, wall] != 0):
            raise ConfigError("images: must be 0 on wall axes")
        #: the uniform acceleration (d,) as a tuple, or None
        self.gravity = _gravity(gravity, d)
        #: the wall kinds (None: hard walls at rest)
        self.walls = _walls(walls, self.boundary, bx, 2.0 * float(rad.max()))
        for a in np.flatnonzero(wall):
            lo = 0.0 if self.walls is None else float(self.walls.side(a, 0).position(bx[a], 0, state.time))
            hi = bx[a] if self.walls is None else float(self.walls.side(a, 1).position(bx[a], 1, state.time))
            low = pos[:, a] - rad - lo
            high = hi - rad - pos[:, a]
            tol = 1e-9 * rad
            bad = np.flatnonzero((low < -tol) | (high < -tol))
            if len(bad):
                k = int(bad[0])
                raise ConfigError(f"positions: particle {k} at {'xyz'[a]} = {pos[k, a]:.6g} overlaps a "
                                  f"wall (radius {rad[k]:.6g}, walls at {lo:.6g} and {hi:.6g} at t = "
                                  f"{state.time:.6g}); every sphere must lie within [R, L - R] on a wall "
                                  f"axis, clear of a vibrating wall's position")
        if shear is not None and (self.gravity is not None or self.walls is not None and self.walls.moving):
            raise ConfigError("shear: gravity and thermal or vibrating walls are not available with Lees-Edwards "
                              "boundaries (hard walls at rest only)")
        if self.stress and (self.gravity is not None or self.walls is not None and self.walls.moving):
            raise ConfigError("stress: the pressure tensor under gravity or with thermal or vibrating walls is "
                              "not available (stress=False)")
        if shear is not None:
            # y into [0, L_y) through the sheared images: x shifted by the unreduced image offset
            ky = np.floor(pos[:, 1] / bx[1]).astype(np.int64)
            pos[:, 1] -= ky * bx[1]
            pos[:, 0] -= ky * (shear.rate * bx[1] * float(state.time))
            vel[:, 0] -= ky * (shear.rate * bx[1])
            img[:, 1] += ky
        shift = np.floor(pos / bx).astype(np.int64)
        shift[:, wall] = 0
        pos -= shift * bx
        img += shift
        wrapped = pos >= bx
        wrapped[:, wall] = False
        pos[wrapped] = 0.0  # guard against -tiny + L rounding to L
        lc = state.array("last_collision")
        if driving is not None and not isinstance(driving, WhiteNoise):
            raise TypeError("driving must be a granulargas.engine.driving.WhiteNoise or None")
        if rule.resolved and np.any(wall):
            raise ConfigError('boundary: walls are not available with collisions that take time '
                              '(duration = "resolved"); use periodic axes')
        cu, cp = state.array("contact_until"), state.array("contact_partner")
        if np.any((cp < -1) | (cp >= n)) or np.any(np.isnan(cu)):
            raise ConfigError("contact_partner: particle ids in [0, N) or -1; contact_until: no NaN")
        self._contact_until, self._contact_partner = cu, cp
        self._three_body = state.three_body_contacts
        # rough particles: spins (N, 3) and kappa in id order (engine.tangential)
        if tangential is not None and not isinstance(tangential, TangentialRule):
            raise TypeError("tangential must be a granulargas.engine.TangentialRule or None")
        if tangential is not None and rule.resolved:
            raise ConfigError('tangential: rough particles need instantaneous collisions (the resolved '
                              'contact, duration = "resolved", is frictionless)')
        if driving is not None and driving.rotational_fraction > 0.0 and tangential is None:
            raise ConfigError(f"driving: rotational_fraction = {driving.rotational_fraction}: smooth particles "
                              "have no spins to drive (give a tangential rule)")
        if tangential is not None and shear is not None:
            raise ConfigError("shear: rough particles (a tangential rule) are not available with Lees-Edwards "
                              "boundaries")
        if tangential is not None and self.stress:
            raise ConfigError("stress: the pressure tensor of rough particles is not available (stress=False)")
        if tangential is not None and self.walls is not None and self.walls.moving:
            raise ConfigError("tangential: rough particles take hard walls at rest only (thermal and vibrating "
                              "walls act on smooth particles)")
        self.tangential = tangential
        self._spins, self._kappa = spins_of(state) if tangential is not None else (None, None)
        # a mixture: the species of every particle index the rule's pair table
        self._species_of = self._pair_counts = None
        if rule.pairs is not None:
            self._species_of, self._pair_counts = species_of_state(state, rule)
        # per-particle fields the engine does not use: kept as they are, returned by ``state``
        own = OWN_FIELDS + (ROUGH_FIELDS if tangential is not None else ())
        self._carried = {f.name: getattr(state, f.name).copy() for f in PARTICLE_FIELDS
                         if f.name not in own and getattr(state, f.name) is not None}

        self._positions, self._velocities, self._images, self._last_collision = pos, vel, img, lc
        self._radii, self._masses, self._box = rad, mas, bx
        self.rule = rule
        self.driving = driving
        self.remove_drift = bool(remove_drift)
        self._time = state.time
        self._collisions = state.collisions
        self._events = state.events
        self._wall_collisions = state.wall_collisions
        self._wall_work = state.wall_work
        self._dissipated = state.dissipated_energy
        self._injected = state.injected_energy
        kick_step = state.kick_step
        if driving is None:
            self._kick_step = 0
        elif kick_step is None:
            self._kick_step = max(0, int(math.floor(self._time / driving.interval - 0.5)))
            while (self._kick_step + 0.5) * driving.interval <= self._time:  # round-off in the floor
                self._kick_step += 1
        else:
            self._kick_step = kick_step
            if not (self._kick_step + 0.5) * driving.interval > self._time:
                raise ConfigError(f"kick_step = {kick_step}: the next driving step k must come after the "
                                  f"current time ((k + 1/2) interval > {self._time:.17g})")
        self._virial = 0.0
        self._kin_int = 0.0
        self._stress_window = np.zeros(12)  # kinetic integrals and collisional sums when not built
        self._rescale_step = shear.first_step(self._time) if shear is not None else 0
        self._wall_impulse = np.zeros((3, 2))
        self._window_start = self._time
        self._wall_window_start = self._time
        self._rate = float("nan")
        self.collapse_count = int(collapse_count)

        volume = float(np.prod(bx))
        unit = math.pi / 6.0 * 8.0 if d == 3 else math.pi
        self.packing_fraction = float(unit * np.sum(rad**d) / volume)
        dmax = 2.0 * float(rad.max())
        #: the neighbour search in use, "lists" or "cells"
        self.neighbours = neighbour_mode(neighbours, self.packing_fraction, d)
        if neighbours == "auto" and rule.resolved:
            self.neighbours = "lists"
        if self.neighbours == "cells" and rule.resolved:
            raise ConfigError('neighbours = "cells": collisions that take time (duration = "resolved") '
                             'need neighbour lists; use neighbours = "lists"')
        if self.neighbours == "cells":
            want = 0.0 if shell is None else float(shell)
            if want < 0:
                raise ConfigError(f"shell = {want}: must be >= 0")
        else:
            rule_shell = default_shell if shear is None else sheared_shell
            want = rule_shell(self.packing_fraction, d) if shell is None else float(shell)
        if want <= 0 and self.neighbours == "lists":
            raise ConfigError(f"shell = {want}: must be > 0")
        # at least 3 cells per side so that the 27 neighbour cells are distinct
        fit = float(bx.min()) / 3.0 - dmax
        if float(bx.min()) < MIN_BOX_DIAMETERS * dmax:
            short = [f"{'xyz'[a]} ({self.boundary[a]})" for a in range(d)
                     if bx[a] < MIN_BOX_DIAMETERS * dmax]
            raise ConfigError(f"box = {bx.tolist()}: too small for the cell grid, each side must be "
                              f">= {MIN_BOX_DIAMETERS * dmax:.4g} ({MIN_BOX_DIAMETERS:g} largest "
                              f"diameters); too short: {', '.join(short)}")
        self.shell = min(want * dmax, fit)
        # a shell cut to fit: L / (L/3 - dmax + dmax) can round to just below 3 cells, so the
        # shell steps down by units in the last place until floor(L / cut) is 3
        for _ in range(64):
            if self.shell <= 0 or math.floor(float(bx.min()) / (dmax + self.shell)) >= 3:
                break
            self.shell = float(np.nextafter(self.shell, 0.0))
        cut = dmax + self.shell
        box3 = np.ones(3)
        box3[:d] = bx
        period3 = box3.copy()
        period3[:d][wall] = np.inf
        if shear is not None:
            period3[1] = np.inf  # the sheared axis: wrapped by engine._shear
        ncell = np.ones(3, dtype=np.int64)
        if self.neighbours == "cells":
            # the shell is the cells' width beyond the largest diameter
            ncell[:d] = crossing_grid(bx, dmax, n, want)
            self.shell = float(np.min(bx / ncell[:d])) - dmax
        else:
            ncell[:d] = np.floor(bx / cut).astype(np.int64)
        self._space = _state.space(box3, period3, ncell, np.flatnonzero(wall), d)
        self._built = False
        self._engine = None
        self._nb_width = self._initial_list_width(n, volume, cut)
        mean = n / float(np.prod(ncell))
        self._cell_width = 16 * max(1, math.ceil((mean + 5.0 * math.sqrt(mean) + 2) / 16))

    # ------------------------------------------------------------------ build
    def _initial_list_width(self, n, volume, cut):
        d = self.dimension
        vol = 4.0 / 3.0 * math.pi * cut**3 if d == 3 else math.pi * cut**2
        mean = n / volume * vol
        return int(min(n - 1, max(8, math.ceil(mean + 5.0 * math.sqrt(mean) + 4))))

    def _build(self, target=_INT_MAX):
        """Internal state from the public state (a pure function of it). ``target``: the
        collision count at which the present run stops (the lists mode's build runs the loop,
        :meth:`_first_events_by_the_loop`)."""
        n, d = self._positions.shape
        spc = self._space
        p3 = np.zeros((n, 3))
        p3[:, :d] = self._positions
        order = morton_order(p3, spc.box, spc.ncell)
        self._order = order
        rec = _aligned_records(n)
        rec[:, :3] = p3[order]
        rec[:, 3:6] = 0.0
        rec[:, 3 : 3 + d] = self._velocities[order]
        rec[:, 6] = self._time
        rec[:, 7] = self._radii[order]
        img = np.zeros((n, 3), dtype=np.int32)
        img[:, :d] = self._images[order]
        particles = _state.Particles(
            rec=rec, img=img, mass=np.ascontiguousarray(self._masses[order]),
            count=np.zeros(n, dtype=np.int32),
            lastcoll=np.ascontiguousarray(self._last_collision[order]),
            rapid=np.zeros(n, dtype=np.int32), ident=order.astype(np.int32))
        ncells = int(np.prod(spc.ncell))
        sh = None
        if self.shear is not None:
            sh = _shear.shear_geometry(
                self.shear.rate, spc.box, spc.ncell, n,
                math.inf if self.shear.interval is None else self.shear.interval,
                self.shear.temperature or 1.0, rescales=self._rescale_step, lists=self.neighbours == "lists",
                shell=self.shell, cut=2.0 * float(self._radii.max()) + self.shell)
            sh.slide[0] = int(math.floor(self._time / sh.slide_time))
            sh.slide[1] = sh.slide[0] % sh.nx
            spc = spc._replace(shear=sh)
            self._space = spc
            rec[:, 1] += sh.ly  # the compiled state keeps y + L_y (engine._shear)
        if self.neighbours == "cells":
            cell, partner, tag, where, qt, pair_t = particle_rows(n)
            events = _state.Events(partner=partner, tag=tag)
            lists = _state.Grid(head=np.empty(ncells, dtype=np.int32), cell=cell,
                                width=spc.box / spc.ncell, pair_t=pair_t,
                                fresh=np.full(FRESH_SIZE if sh is None else SHEAR_FRESH_SIZE, -1, dtype=np.int64))
            if sh is not None:
                _shear.build_grid_le(self._time, rec, lists, spc, sh)
                self._finish_build(particles, events, lists, None, order, qt=qt, where=where)
                return
            build_grid(rec, lists, spc)
            partner[:] = _loop.STALE  # every particle re-predicted now, by the loop
            tag[:] = 0
            qt[:] = self._time
            self._finish_build(particles, events, lists, None, order, qt=qt, where=where, expired=True)
            self._first_events_by_the_loop(target)
            return
        partner, tag, where, qt = _state.event_rows(n)
        events = _state.Events(partner=partner, tag=tag)
        centre = np.empty((n, 3), dtype=np.float32)  # list centres: see _cells
        stencil = np.empty(27 if sh is None else 36, dtype=np.int64)  # (sheared: 3 + 4 + 4 columns x 3)
        if sh is None:
            centre[:] = rec[:, :3]
            cells = self._centre_cells(centre, ncells)
            lists = _state.Lists(centre=centre, nbl=np.empty((n, self._nb_width), dtype=np.int32),
                                 nbn=np.zeros(n, dtype=np.int32), scratch=self._new_scratch(),
                                 stencil=stencil, mark=np.zeros(n, dtype=np.uint8))
            partner[:] = _loop.EXPIRY
            tag[:] = 0
            qt[:] = self._time
            self._finish_build(particles, events, lists, cells, order, qt=qt, where=where, expired=True)
            self._first_events_by_the_loop(target)
            return
        while True:
            lists = _state.Lists(centre=centre, nbl=np.empty((n, self._nb_width), dtype=np.int32),
                                 nbn=np.zeros(n, dtype=np.int32), scratch=np.empty(1, np.int32),
                                 stencil=stencil, mark=np.zeros(n, dtype=np.uint8))
            cells = _state.Cells(ids=_aligned_int_rows(ncells, self._cell_width),
                                 n=np.zeros(ncells, dtype=np.int32))
            st = _shear.build_all_lists_le(self._time, rec, lists, cells, spc, self.shell, sh)
            if st == OVERFLOW:
                self._nb_width = min(n - 1, max(self._nb_width + 4, int(self._nb_width * 1.5)))
            elif st == CELL_OVERFLOW:
                self._cell_width += 16
            else:
                break
        lists = lists._replace(nbl=self._compact_lists(lists.nbl, lists.nbn))
        cells = self._compact_cells(cells)
        lists = lists._replace(scratch=self._new_scratch())
        self._finish_build(particles, events, lists, cells, order, qt=qt, where=where)

    def _centre_cells(self, centre, ncells):
        """The cells of the list centres (as :func:`granulargas.engine._cells.cell_index` assigns
        them, slots in particle order), rows as wide as the fullest cell plus a margin."""
        spc = self._space
        box, ncell = spc.box, spc.ncell
        flat = np.zeros(len(centre), dtype=np.int64)
        for a in (2, 1, 0):
            ca = (centre[:, a].astype(np.float64) * (ncell[a] / box[a])).astype(np.int64)
            flat = flat * ncell[a] + np.clip(ca, 0, ncell[a] - 1)
        fill = np.bincount(flat, minlength=ncells).astype(np.int32)
        while self._cell_width < fill.max():
            self._cell_width += 16
        self._cell_width = min(self._cell_width, int(fill.max()) + CELL_SLACK)
        ids = _aligned_int_rows(ncells, self._cell_width)
        by_cell = np.argsort(flat, kind="stable")
        start = np.cumsum(fill) - fill
        ids[flat[by_cell], np.arange(len(flat)) - start[flat[by_cell]]] = by_cell
        return _state.Cells(ids=ids, n=fill)

    def _compact_lists(self, nbl, nbn):
        """The list table cut to what this state needs (+ a margin; the lists grow on demand)."""
        width = min(self.n - 1, int(nbn.max()) + LIST_SLACK)
        if width < self._nb_width:
            nbl = np.ascontiguousarray(nbl[:, :width])
            self._nb_width = width
        return nbl

    def _compact_cells(self, cells):
        """The cells' rows cut to the fullest cell (+ a margin)."""
        slots = int(cells.n.max()) + CELL_SLACK
        if slots < self._cell_width:
            ids = _aligned_int_rows(cells.ids.shape[0], slots)
            ids[:] = cells.ids[:, :slots]
            cells = cells._replace(ids=ids)
            self._cell_width = slots
        return cells

    def _first_events_by_the_loop(self, target=_INT_MAX):
        """Every particle's first event, by the event loop itself (no kernel of its own to compile).

        Neighbour lists: every list expires at the present time (``_build`` sets the centres, the
        cells, empty lists and these expiries), and the loop rebuilds each list and predicts its
        particle's event as at any expiry. A particle's prediction follows its own rebuild, so it
        sees its whole list (the lists of the particles not yet rebuilt are partial, but every
        pair is predicted by its later-rebuilt particle). Cell crossings: every particle has a
        stale event at the present time, and the loop predicts it as after any stale event (each
        prediction scans the cells around its particle and stores only its own best pair, so the
        order does not matter). The build's events are not counted as events of the run; the
        calendar is then placed anew, its width matched to the predicted events.

        A pair that overlaps and approaches collides at once, during the build; if that
        collision is the run's last (``target``), the build's remaining events stay in the
        calendar as ordinary events at this time (and count as events when they are executed).
        """
        c = self._counters
        kind = "stale" if self.neighbours == "cells" else "expiries"
        before = int(c[kind])
        # every build event is in the calendar's first window; the predictions to come need
        # windows of the width the events will have: 48 events per window among N, each some
        # half shell's (cell's) flight away (far smaller or larger widths put the next events
        # beyond the window count's integer range, or all of them into the first window)
        rec = self._engine.particles.rec
        spc = self._space
        d = self.dimension
        reach = float(np.min(spc.box[:d] / spc.ncell[:d])) if self.neighbours == "cells" else self.shell
        v2 = float(np.mean(np.sum(rec[:, 3:6] ** 2, axis=1)))
        g = 0.0 if self.gravity is None else float(np.sqrt(np.sum(np.square(self.gravity))))
        flight = 0.5 * reach / math.sqrt(v2) if v2 > 0 else (math.sqrt(reach / g) if g > 0 else 1.0)
        self._engine.calendar.state["width"][0] = PER_WINDOW * flight / self.n
        prm = self._params()
        # the loop stops right after any event once the count has reached its target: the build
        # stops early only for a collision of its own that reaches the run's target
        target = max(target, int(c["collisions"]) + 1)
        while True:
            e = self._engine
            status = _loop.advance(e, *_loop.mode_flags(e.cells), prm, self._time, 4 * self.n + 1000, target,
                                   None, None, e.stress, self._walls_arg(e))
            if self._served(status):
                prm = self._params()
            elif status in (_loop.DONE, _loop.MAX_COLLISIONS):
                break
            elif status != _loop.BUDGET:
                self._raise(status)
        c = self._counters
        built = int(c[kind]) - before
        c["events"] = int(c["events"]) - built
        c[kind] = before
        if status == _loop.MAX_COLLISIONS:
            return
        e = self._engine
        cal = allocate_calendar(self.n, qt=e.calendar.qt, where=e.calendar.where)
        if e.cells is not None:
            e = e._replace(lists=e.lists._replace(nbl=self._compact_lists(e.lists.nbl, e.lists.nbn),
                                                  scratch=self._new_scratch()))
        self._engine = e._replace(calendar=cal)
        self._place_events(self._time)

    def _finish_build(self, particles, events, lists, cells, order, qt=None, where=None, expired=False):
        """Contacts, every particle's event, counters and the calendar (after the neighbour search;
        ``qt``, ``where``: the calendar's per-particle arrays, views into the mode's per-particle
        rows). ``expired``: the events are set already, every list expiring now or every event
        stale (:meth:`_first_events_by_the_loop`); the calendar's window holds them all."""
        n = self.n
        spc = self._space
        rec = particles.rec
        calendar = allocate_calendar(n, capacity=n if expired else None, qt=qt, where=where)
        slot = np.empty(n, dtype=np.int64)
        slot[order] = np.arange(n)
        cp = self._contact_partner[order]
        # the instantaneous rules' loop is compiled without the contacts (None)
        contacts = _state.contacts(n, self._contact_until[order],
                                   np.where(cp >= 0, slot[np.maximum(cp, 0)], -1).astype(np.int32)
                                   ) if self.rule.resolved else None
        if not expired:
            _loop.predict_all(self._time, rec, particles.count, events, lists, *_loop.mode_flags(cells), spc,
                              0.5 * self.shell * (1.0 - 1e-9), contacts, self._flight(), self._wallkinds(),
                              spc.shear, calendar.qt)
        counters = np.zeros(1, dtype=_state.COUNTERS)
        c = counters[0]
        with np.errstate(over="ignore", under="ignore"):
            c["sum_mv2"] = float(np.sum(self._masses[:, None] * self._velocities**2))
        c["time"] = self._time
        c["dissipated"] = self._dissipated
        c["virial"] = self._virial
        c["kin_int"] = self._kin_int
        c["injected"] = self._injected
        c["collisions"] = self._collisions
        c["events"] = self._events
        c["wall_collisions"] = self._wall_collisions
        c["kick_step"] = self._kick_step
        c["three_body"] = self._three_body
        c["err_i"] = c["err_j"] = -1
        walls = _state.walls(impulse=self._wall_impulse)  # work: since this build (added to _wall_work)
        stress = None
        if self.stress:
            stress = np.zeros(1, dtype=_shear.STRESS)
            _shear.stress_sums_of(rec, particles.mass, spc.shear, stress[0]["s"])
            stress[0]["k"] = self._stress_window[:6]
            stress[0]["w"] = self._stress_window[6:]
        tg = self.tangential  # rough particles; None: the loop compiles without spins
        spins = None if tg is None else _state.spins(
            self._spins[order], self._kappa[order], tg.code, tg.restitution, tg.friction, tg.wall_beta, tg.wall_mu,
            spin_kick_scale(self.driving, self.dimension))
        # a rule without a pair table compiles the loop without the species (None)
        species = None if self._species_of is None else _state.species_record(
            self._species_of[order], self.rule.pairs, self._pair_counts)
        self._engine = _state.Engine(particles, events, lists, cells, calendar, counters, walls, contacts,
                                     stress, spins, species)
        self._place_events(self._time)
        self._built = True

    def _walls_arg(self, engine):
        """The loop's ``walls`` argument: the walls' record in a box with wall axes, else None (the
        loop is then compiled without the walls' code)."""
        return engine.walls if self._space.wall_axes.size else None

    @property
    def _counters(self):
        return self._engine.counters[0]

    def _place_events(self, now):
        """(Re)build the event calendar from the event times ``qt`` at time ``now``."""
        cal = self._engine.calendar
        if not cal_build(now, cal):
            raise SimulationError(f"event calendar overflow at t = {now:.12g}: more simultaneous "
                                  f"events than its window holds ({cal.small.shape[0]})")
        self._calendar_time = now

    def _new_scratch(self):
        """Work space of a list rebuild: every candidate of the 27 cells, at least a full list."""
        return np.empty(max(self._nb_width, 27 * self._cell_width), dtype=np.int32)

    def _grow_cells(self):
        e = self._engine
        old = e.cells.ids
        self._cell_width = _wider(self._cell_width)
        new = _aligned_int_rows(old.shape[0], self._cell_width)
        new[:, : old.shape[1]] = old
        self._engine = e._replace(cells=e.cells._replace(ids=new),
                                  lists=e.lists._replace(scratch=self._new_scratch()))

    def _grow_lists(self):
        e = self._engine
        n = self.n
        new = min(n - 1, _wider(self._nb_width))
        if new <= self._nb_width:
            raise SimulationError("neighbour list cannot grow further (internal error)")
        nbl = np.empty((n, new), dtype=np.int32)
        nbl[:, : self._nb_width] = e.lists.nbl
        self._nb_width = new
        self._engine = e._replace(lists=e.lists._replace(nbl=nbl, scratch=self._new_scratch()))

    def _params(self):
        """The read-only parameters of the compiled loop for the coming run."""
        c = self._counters
        v2 = float(c["sum_mv2"]) / float(np.sum(self._masses))
        scale = 2.0 * float(self._radii.min()) / math.sqrt(v2) if v2 > 0 else 1.0
        drv = self.driving
        kick = {} if drv is None else dict(
            kick_interval=drv.interval, kick_scale=kick_scale(drv.translational_rate, drv.interval, self.n),
            kick_seed=drv.seed)
        return _state.params(self.rule.compiled(), self._space, self.shell, float(self._radii.max()),
                             1e-10 * scale, self.collapse_count, **kick, gravity=self._flight(),
                             wallkinds=self._wallkinds())

    def _flight(self):
        """The flight the kernels take: None (straight) or the (3,) gravity vector."""
        if self.gravity is None:
            return None
        g = np.zeros(3)
        g[: self.dimension] = self.gravity
        return g

    def _wallkinds(self):
        """The wall kinds the kernels take: None for hard walls at rest, else the compiled
        :class:`~granulargas.engine._state.WallSpec`."""
        return self.walls.compiled() if self.walls is not None and self.walls.moving else None

    # -------------------------------------------------------------------- run
    def run(self, until: float, max_collisions: int | None = None, progress=None) -> "Simulation":
        """Process all events with time <= ``until``; then ``time = until``.

        With ``remove_drift`` (default), at the start of the call and between
        compiled chunks the centre-of-mass velocity V on the periodic axes is
        compared with the thermal speed. Collisions conserve momentum and driving
        kicks sum to zero, but round-off leaves a drift of ~1e-16 of the initial
        speeds, which a cooling gas keeps while its thermal speeds fall; below
        T/T0 ~ 1e-30 it dominates, and list expiries would outnumber collisions by
        orders of magnitude. Once V^2 > ``DRIFT_LIMIT`` <c^2> and the drift's
        kinetic energy M V^2 / 2 is below ``ROUND_OFF`` times the energy that has
        passed through the gas (kinetic + dissipated + injected: a drift round-off
        can explain, not a mean flow given on purpose), the state is synchronised, V
        (an exactly rounded mass-weighted sum, in particle-id order) is subtracted
        from every velocity and the internal state rebuilt. The decision depends on
        the state alone, so that restarts stay bit-identical.

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
        self._remove_drift()
        # before a build, whose first events the loop predicts
        velocities = self._engine.particles.rec[:, 3:6] if self._built else self._velocities
        vmax = float(np.max(np.abs(velocities)))
        if not (vmax < 1e150) or (0.0 < vmax < 1e-150):
            raise SimulationError(f"velocities out of range at t = {self.time:.12g} (max |v_a| = "
                                  f"{vmax:.3g}): squared speeds must stay within float64; rescale "
                                  f"the units")
        start_time, start_coll = self.time, self.collisions
        target = _INT_MAX if max_collisions is None else start_coll + int(max_collisions)
        if not self._built:
            self._build(target)
        prm = self._params()
        chunk = max(1_000_000, 2 * self.n)
        if self._calendar_time != self.time:
            # the window width must stay matched to the event rate (a cooling gas slows
            # down): the events are placed anew when it is off by more than a factor 2
            cal = self._engine.calendar
            ratio = cal_width(self.time, cal.qt) / float(cal.state[0]["width"])
            if not 0.5 <= ratio <= 2.0:
                self._place_events(self.time)
        advance = _loop.advance if self.driving is None else _loop.advance_driven
        if self.shear is not None:
            advance = _loop.advance_sheared
        while self.collisions < target:  # (a build's collisions at its own time count)
            e = self._engine
            status = advance(e, *_loop.mode_flags(e.cells), prm, until, chunk, target, None, prm.space.shear, e.stress,
                             self._walls_arg(e))
            if status == _loop.BUDGET:
                if progress is not None:
                    progress(self)
                if self._remove_drift() or not self._built:
                    self._build(target)
                    prm = self._params()
                continue
            if self._served(status):
                prm = self._params()
                continue
            if status in (_loop.DONE, _loop.MAX_COLLISIONS):
                break
            self._raise(status)
        dt = self.time - start_time
        self._rate = 2.0 * (self.collisions - start_coll) / (self.n * dt) if dt > 0 else float("nan")
        if progress is not None:
            progress(self)
        return self

    def _served(self, status) -> bool:
        """Serve a status by which the loop asks for more room: a wider list or cell table, an
        oblique-contact table that reaches further. True if served (call the loop again)."""
        if status == OVERFLOW:
            self._grow_lists()
        elif status == CELL_OVERFLOW:
            self._grow_cells()
        elif status in (OBLIQUE_BETA_RANGE, OBLIQUE_DELTA_RANGE):
            self._extend_oblique_table()
        else:
            return False
        return True

    def _remove_drift(self) -> bool:
        """Subtract the centre-of-mass velocity on periodic axes once it exceeds
        ``DRIFT_LIMIT`` of the thermal speed (see :meth:`run`); True if it did."""
        axes = [a for a in range(self.dimension) if self.boundary[a] == "periodic"
                and not (a == 0 and self.shear is not None)  # the flow's axis keeps its momentum
                and (self.gravity is None or self.gravity[a] == 0.0)]  # a falling axis is no drift
        if not self.remove_drift or not axes:
            return False
        v, m = self._vm_unordered()
        mtot = float(np.sum(self._masses))
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            vcm = (m @ v) / mtot
            mv2 = float(np.einsum("i,ij,ij->", m, v, v))  # not the running sum: it loses digits
            passed = 0.5 * mv2 + self.dissipated_energy + self.injected_energy
            drift2 = float(np.sum(vcm[axes] ** 2))
            c2 = mv2 / mtot - float(vcm @ vcm)
        if not (self.DRIFT_LIMIT * c2 < drift2 and 0.5 * mtot * drift2 < self.ROUND_OFF * passed):
            return False
        self.synchronise()
        vel = self._velocities
        mtot = math.fsum(self._masses)
        for a in axes:
            va = math.fsum((self._masses * vel[:, a]).tolist()) / mtot
            vel[:, a] -= va
        return True

    def _extend_oblique_table(self):
        """The pair ``err_i``, ``err_j`` met an impact beyond the oblique-contact table:
        replace the rule by one with a table covering it (its shared part is
        bit-identical, so results do not depend on when this happens)."""
        from dataclasses import replace

        from granulargas.contact.oblique import DELTA_MAX
        from granulargas.contact.oblique_grid import BETA_MAX

        c = self._counters
        i, j = int(c["err_i"]), int(c["err_j"])
        rec, m = self._engine.particles.rec, self._engine.particles.mass
        d = rec[i, :3] - rec[j, :3]
        period = self._space.period
        d = np.where(np.isfinite(period), d - period * np.round(d / np.where(np.isfinite(period), period, 1.0)), d)
        g_n = -float(np.dot(d, rec[i, 3:6] - rec[j, 3:6])) / float(np.linalg.norm(d))
        rule = self.rule
        ri, rj = float(rec[i, 7]), float(rec[j, 7])
        beta = float(pair_constant(rule.prefactor, ri, rj, m[i], m[j])) * g_n**0.2
        delta = float(pair_compression_constant(rule.compression, ri, rj, m[i], m[j])) * g_n**0.8 / (ri + rj)
        ids = [int(self._order[k]) for k in (i, j)]
        if not (beta < BETA_MAX and delta < DELTA_MAX):
            raise TableRangeError(
                f"impact of particles {ids} at t = {float(c['time']):.12g} (normal speed {g_n:.6g}) has "
                f"beta = {beta:.4g}, delta = {delta:.4g}: collisions that take time need beta < {BETA_MAX:g} "
                f"and delta < {DELTA_MAX:g} (delta is the compression over the contact distance: the "
                f"contact is too soft or the impact too fast)")
        table = rule.oblique.extended(min(BETA_MAX, max(beta * 1.2, rule.oblique.beta_max)),
                                      min(DELTA_MAX, max(delta * 1.2, rule.oblique.delta_max)))
        self.rule = replace(rule, oblique=table)
        c["err_i"] = c["err_j"] = -1

    def _raise(self, status):
        c = self._counters
        i, j = int(c["err_i"]), int(c["err_j"])
        ids = [int(self._order[k]) for k in (i, j) if k >= 0]
        where = f"at t = {float(c['time']):.12g} after {int(c['collisions'])} collisions (particles {ids})"
        zeno = (f"inelastic collapse {where}: ever faster collisions (a grain coming to rest on a wall, or a "
                f"cluster on a shaken plate, bounces infinitely often in a finite time); set a restitution floor "
                f"(collision.elastic_below: collisions below that normal speed are elastic; "
                f"CollisionRule.constant(eps, elastic_below=v)) or the TC model (collision.tc_time)")
        trap = self.gravity is not None or "wall" in self.boundary
        if status == _loop.COLLAPSE:
            if trap:
                raise InelasticCollapseError(zeno, where=where)
            if self.rule.kind == "constant":
                raise InelasticCollapseError(
                    f"inelastic collapse {where}: the collision rate diverges; use the TC model "
                    f"(CollisionRule.constant(eps, tc_time=...)) or a viscoelastic rule", where=where)
            raise SimulationError(f"endless rapid re-collisions {where} (round-off loop)")
        if status == _loop.TABLE_RANGE:
            raise TableRangeError(f"impact beyond the restitution table {where}: build the table "
                                  f"with a larger beta_max")
        if status == _loop.WATCHDOG and trap and i >= 0 and self._engine.particles.lastcoll[i] == float(c["time"]):
            # a particle that keeps colliding at one instant of the clock: bounces faster than it resolves
            raise InelasticCollapseError(zeno, where=where)
        if status == _loop.WATCHDOG:
            raise SimulationError(f"event-queue watchdog {where}: an event in the past or an endless "
                                  f"run of zero-time events")
        if status == _loop.CALENDAR:
            raise SimulationError(f"event calendar overflow {where}: more simultaneous events than "
                                  f"its window holds ({self._engine.calendar.small.shape[0]})")
        raise SimulationError(f"engine status {status} {where}")

    def synchronise(self) -> "Simulation":
        """Stream all particles to ``time`` and wrap; the next run rebuilds the queue."""
        if self._built:
            e = self._engine
            self._positions, self._images, self._velocities = self._synchronised()
            n, d = self._positions.shape
            inv = self._order
            lc = np.empty(n)
            lc[inv] = e.particles.lastcoll
            self._last_collision = lc
            c = self._counters
            self._time = float(c["time"])
            self._dissipated, self._virial, self._kin_int = (float(c["dissipated"]), float(c["virial"]),
                                                             float(c["kin_int"]))
            self._injected = float(c["injected"])
            self._collisions, self._events = int(c["collisions"]), int(c["events"])
            self._wall_collisions = int(c["wall_collisions"])
            self._wall_work += float(np.sum(e.walls.work))
            self._kick_step = int(c["kick_step"])
            self._three_body = int(c["three_body"])
            self._wall_impulse = e.walls.impulse.copy()
            if e.stress is not None:
                self._stress_window = np.concatenate([e.stress[0]["k"], e.stress[0]["w"]])
            if self.shear is not None:
                self._rescale_step = int(self._space.shear.rescales[0])
            if e.spins is not None:
                self._spins = np.empty((n, 3))
                self._spins[inv] = e.spins.w
            if e.species is not None:
                self._pair_counts = e.species.pairs.copy()
            if e.contacts is not None:
                self._contact_until = np.empty(n)
                self._contact_until[inv] = e.contacts.until
                cp = e.contacts.partner.astype(np.int64)
                self._contact_partner = np.empty(n, dtype=np.int64)
                self._contact_partner[inv] = np.where(cp >= 0, inv[np.maximum(cp, 0)], -1)
            self._built = False
            self._engine = None
        return self

    def _streamed(self):
        """Positions, images and velocities at ``time``, wrapped, each (N, 3), in the engine's
        (memory) order."""
        e = self._engine
        n = self.n
        r = np.empty((n, 3))
        img = np.empty((n, 3), dtype=np.int32)
        v = np.empty((n, 3))
        if self.shear is None:
            _loop.synchronised(e.particles.rec, e.particles.img, self._space.period, self.time, self._flight(), r,
                               img, v)
        else:
            _shear.synchronised_le(e.particles.rec, e.particles.img, self._space.period, self.time,
                                   self._space.shear, r, img, v)
        return r, img, v

    def _synchronised(self):
        """Positions, images and velocities at ``time``, wrapped (particle-id order)."""
        r, img, v = self._streamed()
        n, d = self._positions.shape
        vel = np.empty((n, d))
        vel[self._order] = v[:, :d]
        pos = np.empty((n, d))
        pos[self._order] = r[:, :d]
        im = np.empty((n, d), dtype=np.int64)
        im[self._order] = img[:, :d]
        return pos, im, vel

    # ----------------------------------------------------------- public state
    @property
    def n(self) -> int:
        """Number of particles."""
        return self._positions.shape[0]

    @property
    def time(self) -> float:
        return float(self._counters["time"]) if self._built else self._time

    @property
    def collisions(self) -> int:
        """Pair collisions so far."""
        return int(self._counters["collisions"]) if self._built else self._collisions

    @property
    def events(self) -> int:
        """Events processed so far (every kind, a driving step counting as one)."""
        return int(self._counters["events"]) if self._built else self._events

    @property
    def wall_collisions(self) -> int:
        """Sphere-wall collisions so far."""
        return int(self._counters["wall_collisions"]) if self._built else self._wall_collisions

    @property
    def three_body_contacts(self) -> int:
        """Resolved rule: collisions of a particle still in contact with another partner so far."""
        return int(self._counters["three_body"]) if self._built else self._three_body

    @property
    def contact_until(self) -> np.ndarray:
        """Resolved rule: when each particle's contact under way ends (-inf: none), (N,)."""
        if not self._built or self._engine.contacts is None:
            return self._contact_until.copy()
        out = np.empty(self.n)
        out[self._order] = self._engine.contacts.until
        return out

    @property
    def contact_partner(self) -> np.ndarray:
        """Resolved rule: the particle id of each particle's last contact partner (-1: none), (N,)."""
        if not self._built or self._engine.contacts is None:
            return self._contact_partner.copy()
        cp = self._engine.contacts.partner.astype(np.int64)
        out = np.empty(self.n, dtype=np.int64)
        out[self._order] = np.where(cp >= 0, self._order[np.maximum(cp, 0)], -1)
        return out

    @property
    def kick_step(self) -> int:
        """Index k of the next driving step (at time (k + 1/2) * interval); 0 without driving."""
        return int(self._counters["kick_step"]) if self._built else self._kick_step

    @property
    def positions(self) -> np.ndarray:
        """Positions (N, d) at ``time``, wrapped into [0, L) on periodic axes (a copy)."""
        return self._synchronised()[0] if self._built else self._positions.copy()

    @property
    def images(self) -> np.ndarray:
        return self._synchronised()[1] if self._built else self._images.copy()

    @property
    def unwrapped_positions(self) -> np.ndarray:
        """Positions + images times the box (with shear, x also + images_y a L_y t)."""
        pos, img = self._synchronised()[:2] if self._built else (self._positions, self._images)
        out = pos + img * self._box
        if self.shear is not None:
            out[:, 0] += img[:, 1] * (self.shear.rate * self._box[1] * self.time)
        return out

    @property
    def velocities(self) -> np.ndarray:
        """Velocities (N, d) at ``time`` (a copy; laboratory frame; with shear those of the wrapped
        positions; under gravity each streamed from its clock)."""
        if not self._built:
            return self._velocities.copy()
        if self.shear is not None or self._flight() is not None:
            return self._synchronised()[2]
        out = np.empty_like(self._velocities)
        out[self._order] = self._engine.particles.rec[:, 3 : 3 + self.dimension]
        return out

    def peculiar_velocities(self) -> np.ndarray:
        """Velocities relative to the flow, c = v - a (y - L_y/2) x (v without shear), (N, d)."""
        if self.shear is None:
            return self.velocities
        pos, _, vel = self._synchronised() if self._built else (self._positions, None, self._velocities)
        out = vel.copy()
        out[:, 0] -= self.shear.rate * (pos[:, 1] - 0.5 * self._box[1])
        return out

    @property
    def last_collision(self) -> np.ndarray:
        if not self._built:
            return self._last_collision.copy()
        out = np.empty(self.n)
        out[self._order] = self._engine.particles.lastcoll
        return out

    def _spin_rows(self) -> np.ndarray:
        """The spins (N, 3) in id order (2D: the last column)."""
        if not self._built:
            return self._spins
        out = np.empty((self.n, 3))
        out[self._order] = self._engine.spins.w
        return out

    @property
    def angular_velocities(self) -> np.ndarray | None:
        """Rough particles: angular velocities, (N, 3) in 3D and (N, 1) (about z) in 2D (None: smooth)."""
        return None if self.tangential is None else public_spins(self._spin_rows(), self.dimension)

    @property
    def inertia(self) -> np.ndarray | None:
        """Rough particles: kappa = I / (m R^2) of each particle (None: smooth)."""
        return None if self._kappa is None else self._kappa.copy()

    @property
    def rotational_temperature(self) -> float:
        """Rough particles: T_rot = sum I |w|^2 / (d_r N) (nan for smooth particles)."""
        if self.tangential is None:
            return math.nan
        return rotational_temperature(self._spin_rows(), self._kappa, self._masses, self._radii, self.dimension)

    @property
    def rotational_energy(self) -> float:
        """Rough particles: sum I |w|^2 / 2 (0 for smooth particles)."""
        if self.tangential is None:
            return 0.0
        return 0.5 * self.rotational_temperature * (3 if self.dimension == 3 else 1) * self.n

    @property
    def radii(self) -> np.ndarray:
        return self._radii.copy()

    @property
    def masses(self) -> np.ndarray:
        return self._masses.copy()

    @property
    def box(self) -> np.ndarray:
        return self._box.copy()

    @property
    def species(self) -> np.ndarray | None:
        """Species index of each particle (N,), as given (None: all 0)."""
        return self._carried["species"].copy() if "species" in self._carried else None

    @property
    def species_collisions(self) -> np.ndarray | None:
        """Pair collisions so far per pair of species (S, S), symmetric: entry (a, b) counts the
        collisions between a particle of species a and one of species b (None without a pair
        table in the rule)."""
        if self._species_of is None:
            return None
        raw = self._engine.species.pairs if self._built else self._pair_counts
        return pair_count_matrix(raw, self.rule.pairs.count)

    @property
    def state(self) -> State:
        """The public state as a record (:class:`granulargas.state.State`): a synchronised copy at
        ``time``, particles in id order, every counter; ``Simulation(sim.state, rule, ...)``
        continues bit for bit where :meth:`synchronise` would. ``contact_until`` and
        ``contact_partner`` are None unless collisions take time, ``kick_step`` without driving;
        the per-particle fields the engine does not use are those it was given."""
        if self._built:
            pos, img, vel = self._synchronised()
        else:
            pos, img, vel = self._positions.copy(), self._images.copy(), self._velocities.copy()
        resolved = self.rule.resolved
        return State(
            positions=pos, velocities=vel, radii=self.radii, masses=self.masses, box=self.box,
            boundary=self.boundary, images=img, last_collision=self.last_collision,
            contact_until=self.contact_until if resolved else None,
            contact_partner=self.contact_partner if resolved else None,
            time=self.time, collisions=self.collisions, events=self.events,
            dissipated_energy=self.dissipated_energy, wall_collisions=self.wall_collisions,
            wall_work=self.wall_work,
            injected_energy=self.injected_energy, kick_step=None if self.driving is None else self.kick_step,
            three_body_contacts=self.three_body_contacts, species_collisions=self.species_collisions,
            **({} if self.tangential is None else {"angular_velocities": self.angular_velocities,
                                                   "inertia": self._kappa.copy()}),
            **{name: value.copy() for name, value in self._carried.items()})

    # ------------------------------------------------------------ observables
    def _vm_unordered(self):
        """:meth:`_vm` in the engine's particle order (for sums only): without the reordering
        of a synchronisation into particle-id order, which costs the drift check of every
        chunk of a sheared or gravity run more than the streaming itself."""
        if not self._built or (self.shear is None and self._flight() is None):
            return self._vm()
        r, _, v = self._streamed()
        if self.shear is not None:
            v[:, 0] -= self.shear.rate * (r[:, 1] - 0.5 * self._box[1])
        return v[:, : self.dimension], self._engine.particles.mass

    def _vm(self):
        if self.shear is not None:
            return self.peculiar_velocities(), self._masses
        if self._built:
            if self._flight() is not None:  # velocities at time (the order of masses matches)
                return self._synchronised()[2], self._masses
            return self._engine.particles.rec[:, 3 : 3 + self.dimension], self._engine.particles.mass
        return self._velocities, self._masses

    @property
    def potential_energy(self) -> float:
        """Potential energy in the uniform field, -sum m g . r (unwrapped positions; 0 without
        gravity)."""
        if self.gravity is None:
            return 0.0
        r = self.unwrapped_positions
        return float(-np.sum(self._masses * (r @ np.asarray(self.gravity))))

    @property
    def wall_work(self) -> float:
        """Energy the thermal and vibrating walls have given the gas so far (net, cumulative)."""
        if self._built:
            return self._wall_work + float(np.sum(self._engine.walls.work))
        return self._wall_work

    @property
    def wall_rechecks(self) -> int:
        """Re-check events of the vibrating walls' contact search in the current build."""
        return int(self._engine.walls.rechecks[0]) if self._built else 0

    @property
    def kinetic_energy(self) -> float:
        """Total kinetic energy sum m v^2 / 2 (with shear: of the peculiar velocities)."""
        v, m = self._vm()
        return float(0.5 * np.sum(m[:, None] * v * v))

    @property
    def momentum(self) -> np.ndarray:
        """Total momentum (d,) (with shear: of the peculiar velocities)."""
        v, m = self._vm()
        return np.sum(m[:, None] * v, axis=0)

    @property
    def temperature(self) -> float:
        """Granular temperature m <c^2> / d with c the peculiar velocity (k_B = 1; with shear
        relative to the flow, :meth:`peculiar_velocities`, less their mean)."""
        v, m = self._vm()
        vcm = np.sum(m[:, None] * v, axis=0) / np.sum(m)
        c = v - vcm
        return float(np.sum(m[:, None] * c * c) / (self.dimension * len(m)))

    @property
    def dissipated_energy(self) -> float:
        """Kinetic energy dissipated in collisions (pairs and walls) since construction (cumulative)."""
        return float(self._counters["dissipated"]) if self._built else self._dissipated

    @property
    def injected_energy(self) -> float:
        """Kinetic energy put in by the driving (cumulative)."""
        return float(self._counters["injected"]) if self._built else self._injected

    @property
    def collision_rate(self) -> float:
        """Collisions per particle per unit time (2 x pair collisions / N / dt) during the last run."""
        return self._rate

    def pressure_window(self) -> float:
        """Mean pressure since the previous call (or construction), then reset.

        P = [ integral of sum_i m_i c_i^2 dt + sum_coll r_ij . Delta p_ij ] / (d V Delta t)
        (kinetic plus collisional virial; c is the peculiar velocity). With walls
        the sphere-wall forces are not included: this is then the volume average of
        the trace of the kinetic and collisional stress, and
        :meth:`wall_pressure_window` is the pressure on the walls. With shear the trace
        of :meth:`pressure_tensor_window` over d. Shares its window with
        :meth:`pressure_tensor_window` (:meth:`pressure_windows` gives both). Under gravity
        NaN (the kinetic integral is not kept for velocities that change between events).
        """
        return self.pressure_windows()[0]

    def pressure_tensor_window(self) -> np.ndarray:
        """Mean pressure tensor (d, d) since the previous call (or construction), then reset.

        P_ab = [ integral of sum_i m_i c_ia c_ib dt + sum_coll r_ij,a Delta p_i,b ] / (V Delta t),
        c the peculiar velocity (with shear relative to the flow a (y - L_y/2) x; without,
        relative to the centre of mass at the end of the window); the collisional part
        r_ij (x) Delta p_i through the pair's (sheared) image. Needs ``stress=True`` or
        ``shear``. Shares its window with :meth:`pressure_window`."""
        if not self.stress:
            raise ConfigError("pressure_tensor_window: construct the Simulation with stress=True")
        return self.pressure_windows()[1]

    def pressure_windows(self):
        """(pressure, pressure tensor or None) of the window since the previous call, then reset."""
        if self.gravity is not None:
            self._window_start = self.time
            if self._built:
                self._counters["virial"] = self._counters["kin_int"] = 0.0
            self._virial = self._kin_int = 0.0
            return float("nan"), None
        if self._built:
            c = self._counters
            kin, vir = float(c["kin_int"]), float(c["virial"])
            c["virial"] = 0.0
            c["kin_int"] = 0.0
        else:
            kin, vir = self._kin_int, self._virial
        self._virial = 0.0
        self._kin_int = 0.0
        t = self.time
        dt = t - self._window_start
        self._window_start = t
        d = self.dimension
        if not self.stress:
            if dt <= 0:
                return float("nan"), None
            p = self.momentum
            kin -= float(p @ p) / float(np.sum(self._masses)) * dt
            return (kin + vir) / (d * float(np.prod(self._box)) * dt), None
        k, w = self._stress_sums()
        if dt <= 0:
            return float("nan"), np.full((d, d), np.nan)
        full = np.empty((3, 3))
        for q, (a, b) in enumerate(((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))):
            full[a, b] = full[b, a] = k[q] + w[q]
        tensor = full[:d, :d].copy()
        p = self.momentum
        if self.shear is None:
            tensor -= np.outer(p, p) / float(np.sum(self._masses)) * dt
            kin -= float(p @ p) / float(np.sum(self._masses)) * dt
            scalar = (kin + vir) / (d * float(np.prod(self._box)) * dt)
        tensor /= float(np.prod(self._box)) * dt
        if self.shear is not None:
            scalar = float(np.trace(tensor)) / d
        return scalar, tensor

    def _stress_sums(self):
        """(kinetic integrals, collisional sums) of the pressure tensor since the last reset, each
        (6,) in the order xx, yy, zz, xy, xz, yz; reset them."""
        if self._built:
            st = self._engine.stress[0]
            k, w = st["k"].copy(), st["w"].copy()
            st["k"] = 0.0
            st["w"] = 0.0
        else:
            k, w = self._stress_window[:6].copy(), self._stress_window[6:].copy()
        self._stress_window[:] = 0.0
        return k, w

    def wall_impulse(self) -> np.ndarray:
        """Normal momentum (d, 2) delivered to the lower / upper wall of each axis since the
        last :meth:`wall_pressure_window` (zero on periodic axes)."""
        imp = self._engine.walls.impulse if self._built else self._wall_impulse
        return imp[: self.dimension].copy()

    def wall_pressure_window(self) -> float:
        """Mean pressure on the walls since the previous call (or construction), then reset.

        Normal momentum delivered to all walls / (their total area x elapsed time);
        NaN without walls or for an empty interval.
        """
        imp = self._engine.walls.impulse if self._built else self._wall_impulse
        total = float(np.sum(imp))
        imp[:] = 0.0
        t = self.time
        dt = t - self._wall_window_start
        self._wall_window_start = t
        axes = [a for a in range(self.dimension) if self.boundary[a] == "wall"]
        if dt <= 0 or not axes:
            return float("nan")
        volume = float(np.prod(self._box))
        area = sum(2.0 * volume / float(self._box[a]) for a in axes)
        return total / (area * dt)

    def __repr__(self):
        walls = "" if "wall" not in self.boundary else f", boundary={self.boundary}"
        if self.walls is not None and self.walls.moving:
            walls += ", walls=" + ", ".join(f"{'xyz'[a]}_{('low', 'high')[s]}: {w.kind}" for a, s, w in self.walls.given())
        if self.gravity is not None:
            walls += f", gravity={list(self.gravity)}"
        return (f"Simulation(N={self.n}, d={self.dimension}, packing={self.packing_fraction:.4g}, "
                f"rule={self.rule.kind}{walls}, time={self.time:.6g}, collisions={self.collisions})")


def _boundary(boundary, d):
    """The boundary tuple (one of "periodic", "wall" per axis) or ConfigError."""
    if boundary is None:
        return ("periodic",) * d
    if isinstance(boundary, str):
        raise ConfigError(f"boundary = {boundary!r}: give one entry per axis, e.g. "
                          f"{('periodic',) * (d - 1) + ('wall',)}")
    b = tuple(str(x) for x in boundary)
    if len(b) != d:
        raise ConfigError(f"boundary = {list(b)}: {len(b)} entries for a {d}D system, need {d} "
                          f"(one per axis)")
    for x in b:
        if x not in BOUNDARIES:
            raise ConfigError(f"boundary = {list(b)}: {x!r} is not one of {', '.join(BOUNDARIES)}")
    return b


def _check_shear(boundary, shear, rule):
    """Lees-Edwards boundaries: y (axis 1) marked "lees-edwards" exactly when there is a shear,
    x periodic (the flow's axis); ConfigError otherwise."""
    marked = [a for a, b in enumerate(boundary) if b == "lees-edwards"]
    if shear is None:
        if marked:
            raise ConfigError(f"boundary = {list(boundary)}: \"lees-edwards\" needs a shear "
                              f"(Simulation(..., shear=Shear(rate)))")
        return
    if marked != [1]:
        raise ConfigError(f"boundary = {list(boundary)}: a shear flow needs \"lees-edwards\" on y (the "
                          f"gradient axis) and on no other axis")
    if boundary[0] != "periodic":
        raise ConfigError(f"boundary = {list(boundary)}: the flow's axis x must be periodic under shear")
    if rule.resolved:
        raise ConfigError('shear: collisions that take time (duration = "resolved") are not available '
                          'with Lees-Edwards boundaries')
    if getattr(rule, "pairs", None) is not None:
        raise ConfigError("shear: mixtures (a collision rule with a species table) are not available with "
                          "Lees-Edwards boundaries")
def _gravity(gravity, d):
    """The acceleration as a tuple of d finite floats, or None (ConfigError otherwise)."""
    if gravity is None:
        return None
    g = np.asarray(gravity, dtype=np.float64).ravel()
    if g.shape != (d,) or not np.all(np.isfinite(g)):
        raise ConfigError(f"gravity = {np.asarray(gravity).tolist()}: give {d} finite components (one per axis)")
    return tuple(float(x) for x in g)


def _walls(walls, boundary, box, dmax):
    """The wall kinds, checked against the boundary and the box (None: hard walls at rest)."""
    if walls is None:
        return None
    if not isinstance(walls, Walls):
        raise TypeError("walls must be a granulargas.engine.walls.Walls or None")
    for a, side, w in walls.given():
        name = "xyz"[a] + ("_low" if side == 0 else "_high")
        if a >= len(boundary):
            raise ConfigError(f"walls: {name}: a {len(boundary)}D system has no {'xyz'[a]} axis")
        if boundary[a] != "wall":
            raise ConfigError(f"walls: {name} is a {w.kind} wall on the {'xyz'[a]} axis, which is "
                              f"\"{boundary[a]}\": a wall of any kind needs a \"wall\" axis")
    for a in range(len(boundary)):
        if boundary[a] != "wall":
            continue
        room = float(box[a]) - walls.side(a, 0).reach - walls.side(a, 1).reach
        if not room > dmax:
            raise ConfigError(f"walls: the {'xyz'[a]} axis is {float(box[a]):.6g} long and its walls reach "
                              f"{walls.side(a, 0).reach:.6g} and {walls.side(a, 1).reach:.6g} into it (twice "
                              f"their amplitudes): at their closest they leave {room:.6g}, no room for a "
                              f"particle of diameter {dmax:.6g}")
    return walls
