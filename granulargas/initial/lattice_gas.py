"""Initial states: random non-overlapping placement and Maxwell-Boltzmann velocities.

Placement (fast for 10^6 particles, packing fractions up to ~0.54 in 3D and
~0.76 in 2D, polydisperse too; at 0.55 / 0.78-0.80 the growth of step 2 gets
stuck for some seeds and raises ConfigError):

1. a lattice (FCC in 3D, triangular in 2D, per-axis cell counts chosen to fit
   any box shape) with at least M = round(N / (1 - S0)) sites and the largest
   nearest-neighbour distance, S0 = :func:`fluid_s0` (see below); the few sites
   beyond M that the cell counts give are dropped evenly in space (one at
   random in each of equal runs of a Z-order (Morton) numbering of the cells,
   so that they add almost no long-wavelength fluctuation of their own);
2. N of the M sites chosen at random, radii assigned at random; if the lattice
   distance is below the largest diameter (polydisperse or very dense systems),
   all radii start scaled down and grow between Monte Carlo sweeps to the
   largest size without overlap until they reach full size (each growth step's
   overlaps pushed apart, every push overshooting by ``PUSH_MARGIN`` times the
   step, so that a dense step settles in tens of passes rather than hundreds);
3. hard-sphere Monte Carlo sweeps (random displacements rejected on overlap,
   step adapted to ~40 % acceptance) destroy the lattice order.

Large systems (N >= :data:`SORTED_MIN_PARTICLES`) run the sweeps over
particles sorted by cell, slab by slab (:mod:`._montecarlo`): the slabs of one
parity run in parallel threads, with the same result for any number of threads
(``NUMBA_NUM_THREADS``). From packing ``COMPRESSION_MIN_PACKING`` (0.4 in 3D,
0.6 in 2D) on, their growth of step 2 is one compression instead of steps and
pushes (:mod:`._compression`): all radii are set to full size at once and the
overlaps are removed by the energy minimiser FIRE (Bitzek et al. 2006) on
harmonic overlaps of contact distances swollen by ``SWELL`` (4 %; less where the
swollen packing would exceed ``SWELL_PACKING_MAX``, well below soft-sphere
jamming), until no pair is closer than contact. All particles relax at once, so
that the ~60 minimiser steps cost less than the pushes' dozens of passes over the
last growth steps (where nearly every particle overlaps and each push opens one
gap by closing another), and the swelling leaves gaps around the contacts: the
contact value of g(r) after the final sweeps is closer to the equilibrium
fluid's (N = 2e5 at packing 0.5: ~7.5 with Carnahan-Starling 6.0, the growth
steps ~10.9). Where the box is too small for the compression's scans, the growth
steps with pushes serve; small systems use cell lists and the generator's random
numbers throughout.

Melting before the compression. Sweeps move each particle by a fraction of a
diameter: the bond order falls to the fluid's, but the density stays modulated
at the lattice's wavevectors G (N = 2e5 at packing 0.5: S(G) ~ 2000 at the
nearest ones after 25 melting sweeps and the compression, ~4000 after 20 and the
growth steps; N for a perfect lattice, ~2 in the fluid at the same |k|). In 3D
the compression therefore starts from one random displacement of each particle,
uniform over the FCC cell (sides a_i) centred on its site, and no sweeps: the
expected density of such a particle is uniform, so that every Fourier
component of the lattice averages out (the characteristic function of the
displacement, the product over the axes of sin(G_i a_i / 2) / (G_i a_i / 2),
vanishes at every G); at long wavelengths it changes S(k) by O((k a)^2) only.
The compression then brings S(G) back to ~5-25 only: a displaced particle sees
the hole its own site leaves in the others' expected density and is pulled back
a little (displacements of less than half a cell let the compression rebuild
the lattice). Disks (2D, packing >= 0.6, near the end of the hard-disk fluid at
0.70; Bernard & Krauth 2011) are pulled back more (mean S(G) 14-26 at N = 5000
and 0.7, against 1-4 after sweeps): 2D states keep ``COMPRESSION_MELT_SWEEPS`` (25) sweeps at packing
0.25 before the compression.

Long-wavelength density fluctuations. The sweeps move each particle by a
fraction of a diameter: they relax the structure at short range, but a density
mode of wavevector k relaxes only at the rate of collective diffusion, ~D k^2,
so the modes of the largest wavelengths keep the amplitude the placement gave
them. N particles on N of M sites chosen at random are a lattice gas with
(hypergeometric) random occupation; its static structure factor
``S(k) = |sum_j exp(i k.r_j)|^2 / N`` is, for every k that is not a
reciprocal-lattice vector (every k of the box below the Bragg peaks),

    S(k) = 1 - (N - 1)/(M - 1) = 1 - N/M + O(1/N).

M = N / (1 - S0) makes this S0 = S_eq(k -> 0) = n T kappa_T, the value of the
equilibrium hard-sphere (hard-disk) fluid at the same packing fraction eta,
from the compressibility equation ``S0 = 1 / d(eta Z)/d eta`` with

* 3D, Carnahan-Starling ``Z = (1 + eta + eta^2 - eta^3)/(1 - eta)^3``:
  ``S0 = (1 - eta)^4 / (1 + 4 eta + 4 eta^2 - 4 eta^3 + eta^4)``;
* 2D, Henderson ``Z = (1 + eta^2/8)/(1 - eta)^2``:
  ``S0 = (1 - eta)^3 / (1 + eta + 3 eta^2/8 - eta^3/8)``

(3D eta = 0.1: 0.457, 0.3: 0.098, 0.45: 0.028; 2D eta = 0.25: 0.332,
0.7: 0.015; both 1 - 2^d eta + O(eta^2)). A lattice filled to the last site
(M = N) would give S(k) ~ 0.005-0.01 at k = 2 pi/L for 10^5 particles instead
of ~0.3: a nearly hyperuniform start, seeding a clustering instability with
far too little initial amplitude.

Approximations and limits: polydisperse radii use this monodisperse S0 at the
total packing fraction; the equilibrium S(k) rises above S0 as k^2 (Percus-
Yevick, 3D: +1 % at k sigma = 0.33, +3 % at 0.6); below eta = 0.017 (3D) /
0.033 (2D) M is capped at 8 N (memory), so S = 7/8 instead of S0 in (7/8, 1).
In small boxes (a few thousand particles) S at k = 2 pi/L comes out above S0 by
~0.01-0.03, from two effects that fall off with the box size: the dropped extra
sites (up to 10-20 % of M when the cell counts are small), and the sweeps at
reduced radii of the growth route (eta > 0.25), which relax towards the larger
S0 of that lower packing at the rate D k^2.

Velocities: Gaussian components with variance T/m_i, total momentum removed,
then rescaled so that the granular temperature m<c^2>/d is exactly T.
Everything is drawn from ``numpy.random.default_rng(seed)``: a seed gives
the same state on every machine.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from granulargas import theory
from granulargas.errors import ConfigError
from granulargas.initial import _compression as fire
from granulargas.initial import _montecarlo as mc
from granulargas.state import State


def box_for_packing(radii, packing, dimension, aspect=None):
    """Box sides (d,) giving packing fraction ``packing`` (aspect: relative side lengths)."""
    diameters = 2.0 * np.asarray(radii, dtype=np.float64)
    volume = float(np.sum(theory.particle_volume(diameters, dimension))) / packing
    aspect = np.ones(dimension) if aspect is None else np.asarray(aspect, dtype=np.float64)
    return aspect * (volume / float(np.prod(aspect))) ** (1.0 / dimension)


#: packing fractions up to which random placement works for every seed (module docstring)
RANDOM_PLACEMENT_MAX = {3: 0.54, 2: 0.76}

#: Monte Carlo sweeps that melt the lattice (at packing <= 0.25), whatever N: the bond order
#: Q6 of a 3D lattice falls to the fluid's after about 20 (N = 2e4 at packing 0.5,
#: ~1400-particle subvolumes: 0.16 after 6 sweeps, 0.09 after 10, 0.02 after 20). The final
#: relaxation sweeps at full size do not change Q6 (N = 2e5: the same after 6 as after 20).
MELT_SWEEPS = 20

#: packing fraction (3D, 2D) from which large systems grow by the compression; below it
#: by growth steps, which are cheaper there (one thread, CPU time, compression against
#: growth steps: 10^7 spheres at 0.3 94 s and 3.7 GB against 84 s and 3.1 GB, 10^6 at
#: 0.45 13.2 against 17.7 s; 10^6 disks at 0.5 21.4 against 12.1 s, at 0.6 8.8 against
#: 15.3 s, at 0.7 12.1 against 33.7 s)
COMPRESSION_MIN_PACKING = {3: 0.4, 2: 0.6}

#: melting sweeps of large 2D systems grown by the compression (3D ones are melted by one
#: displacement within a lattice cell instead; module docstring): it keeps more of the
#: lattice's order than growth steps with sweeps in between
COMPRESSION_MELT_SWEEPS = 25

# final Monte Carlo sweeps of systems beyond 10^5 particles (default of random_positions)
FINAL_SWEEPS_LARGE = 6

# pushes overshoot by this fraction of the growth step (of the contact distance): a
# growth step's overlaps are resolved in few passes; a failed step halves both
PUSH_MARGIN = 0.4

#: particle count from which the sweeps (and the overlap census of the growth steps) run
#: over cell-sorted particles, slab by slab in parallel threads, with random numbers from
#: a per-sweep key (:mod:`._montecarlo`); below it over cell lists, with random numbers
#: drawn from the generator. The sorted sweep is ~25 % faster at any N (one thread), but
#: its parallel kernels take ~8 s to compile once: below 10^5 particles (a state in well
#: under a second) the saving would not repay the compile.
SORTED_MIN_PARTICLES = 100_000

# pushes over sorted particles (large systems) stay within this fraction of a diameter of
# their cell: the scans reach (1 + PUSH_CAP) diameters
PUSH_CAP = 0.1

# passes over fewer particles push on one thread (same order, same result): starting the
# threads would cost more than they save
PARALLEL_MIN_PUSHES = 20_000

#: large systems grow to full size in one compression (:mod:`._compression`): contact
#: distances swollen by this fraction, so that every gap ends >= SWELL/2 of a contact distance
SWELL = 0.04

# the swollen packing stays below this (3D, 2D; jamming of soft spheres: ~0.64, ~0.84),
# where the compression converges in ~100 steps
SWELL_PACKING_MAX = {3: 0.58, 2: 0.80}

# neighbour lists of the compression: pairs within the swollen contact distance + this
# fraction of the largest diameter (rebuilt when two particles have together moved as far)
FIRE_SKIN = 0.25

# FIRE: initial time step (unit masses, unit stiffness), its largest value, steps before giving up
FIRE_DT = 0.2
FIRE_DT_MAX = 0.5
FIRE_MAX_STEPS = 5000

# FIRE moves each particle by at most this fraction of the largest diameter per step: the
# first steps, from deep overlaps, would otherwise overshoot and need a new neighbour list
# every step (N = 1e6 at packing 0.5: 70 steps and 22 lists uncapped, 58 and 10 capped)
FIRE_MAX_MOVE = 0.025

# particles per block of the compression's parallel moves
FIRE_BLOCK = 4096

# at most max(SEPARATE_MAX_PAIRS, N / SEPARATE_PER_PAIR) overlapping pairs left: these are
# pushed apart directly (FIRE spends ~10 steps on the last few)
SEPARATE_MAX_PAIRS = 16
SEPARATE_PER_PAIR = 20_000

# room for this many more pairs than a particle had in the last neighbour list
NEIGHBOUR_SLACK = 12

# lowest occupancy N/M of the lattice: M <= 8 N (memory at very low packing)
_MIN_OCCUPANCY = 1.0 / 8.0


def fluid_s0(packing, dimension):
    """Structure factor S(k -> 0) of the equilibrium hard-sphere (3D) / hard-disk (2D) fluid.

    Compressibility route ``S0 = 1 / d(eta Z)/d eta`` with the Carnahan-Starling
    (3D) and Henderson (2D) compressibility factors Z (module docstring).
    """
    eta = float(packing)
    if dimension == 3:
        return (1.0 - eta) ** 4 / (1.0 + 4.0 * eta + 4.0 * eta**2 - 4.0 * eta**3 + eta**4)
    return (1.0 - eta) ** 3 / (1.0 + eta + 3.0 * eta**2 / 8.0 - eta**3 / 8.0)


def _morton(cells):
    """Z-order (Morton) codes of integer cell coordinates (M, d), < 2^21 per axis."""
    code = np.zeros(len(cells), dtype=np.int64)
    d = cells.shape[1]
    for bit in range(int(cells.max()).bit_length()):
        for axis in range(d):
            code |= ((cells[:, axis] >> bit) & 1) << (bit * d + axis)
    return code


def _lattice(n, box):
    """Sites (M >= n, d) of an FCC (3D) / triangular (2D) lattice filling ``box``, the
    nearest-neighbour distance, the site indices in Z-order of their cells (runs
    of consecutive entries are compact in space), and the sides (d,) of the cells
    (cubic cells of 4 sites in 3D, rectangular ones of 2 in 2D)."""
    d = len(box)
    basis = (np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) if d == 3
             else np.array([[0, 0], [0.5, 0.5]]))
    per_cell = len(basis)
    volume = float(np.prod(box))
    shape = np.array([1.0, math.sqrt(3.0)]) if d == 2 else np.ones(3)
    a_ideal = (volume * per_cell / n / float(np.prod(shape))) ** (1.0 / d)
    best, best_counts = -1.0, None
    base = np.floor(box / (a_ideal * shape)).astype(int)
    for offs in itertools.product(range(-1, 3), repeat=d):
        counts = np.maximum(1, base + np.array(offs))
        if per_cell * int(np.prod(counts)) < n:
            continue
        a = box / counts
        if d == 3:
            dist = min(a.min(), *(math.hypot(a[p], a[q]) / 2 for p, q in ((0, 1), (0, 2), (1, 2))))
        else:
            dist = min(a.min(), math.hypot(a[0], a[1]) / 2)
        if dist > best:
            best, best_counts = dist, counts
    counts = best_counts
    a = box / counts
    grids = np.meshgrid(*[np.arange(c) for c in counts], indexing="ij")
    cells = np.stack([g.ravel() for g in grids], axis=1)
    sites = (cells[:, None, :] + basis[None, :, :]).reshape(-1, d) * a
    z_order = (np.argsort(_morton(cells))[:, None] * per_cell + np.arange(per_cell)).ravel()
    return sites, best, z_order, a


def _spread_out(m_keep, order, rng):
    """Sorted ``m_keep`` entries of ``order``: of len(order) - m_keep equal runs of
    consecutive entries, one entry each (at random) is dropped."""
    m = len(order)
    r = m - m_keep
    keep = np.ones(m, dtype=np.bool_)
    if r > 0:
        edges = np.arange(r + 1, dtype=np.int64) * m // r
        keep[edges[:-1] + (rng.random(r) * np.diff(edges)).astype(np.int64)] = False
    return np.sort(order[keep])


def _sorted_grid(box, dmax, step):
    """Cell counts (3,) for a sweep over cell-sorted particles (:func:`_montecarlo.sorted_sweep`):
    cells ~dmax wide along x, >= 2 (dmax + step) along y and z; None where that
    needs fewer than two cells on an axis (small boxes) or the step is longer than a
    diameter (dilute: a wide reach would scan many particles), where cell lists serve better."""
    reach = dmax + step
    if step > dmax or float(box.min()) < 4.0 * reach:
        return None
    grid = np.ones(3, dtype=np.int64)
    grid[0] = max(1, int(box[0] / dmax))
    grid[1 : len(box)] = (box[1:] / (2.0 * reach) * (1.0 - 1e-9)).astype(np.int64)
    grid[len(box) - 1] -= grid[len(box) - 1] % 2  # an even number of slabs
    return grid


def random_positions(radii, box, seed=0, sweeps=None, rng=None):
    """Random non-overlapping positions (N, d) in [0, L) for spheres/disks of ``radii``,
    with the long-wavelength density fluctuations of the equilibrium fluid (module docstring).

    Parameters
    ----------
    radii : array (N,)
    box : array (d,)
    seed : int
    sweeps : int, optional
        Monte Carlo sweeps of the melt (at packing <= 0.25) and of the final relaxation
        (default: :data:`MELT_SWEEPS` for the melt, :data:`COMPRESSION_MELT_SWEEPS`
        before the compression of large 2D systems, none before that of large 3D
        ones, whose melt is the displacement within a lattice cell; for the
        relaxation the same up to 10^5 particles, 6 beyond). Without growth (packing
        <= 0.25, lattice wide enough) the final sweeps are the melt: the default is
        :data:`MELT_SWEEPS` for every N.

    Raises
    ------
    ConfigError
        If the packing is too high for the lattice to hold the largest particles.
    """
    rng = np.random.default_rng(seed) if rng is None else rng
    radii = np.asarray(radii, dtype=np.float64)
    box = np.asarray(box, dtype=np.float64)
    n, d = len(radii), len(box)
    eta = float(np.sum(theory.particle_volume(2.0 * radii, d))) / float(np.prod(box))
    p = _Placement(radii, box, eta, rng)
    melt = MELT_SWEEPS if sweeps is None else sweeps
    default_melt = sweeps is None
    if sweeps is None:
        sweeps = MELT_SWEEPS if n <= 100_000 else FINAL_SWEEPS_LARGE

    # Dense systems (and lattices too tight for the largest particles) start
    # diluted, radii scaled by lam so that the packing is <= 0.25 and the sweeps
    # melt the lattice; then the radii grow to full size: large systems in one
    # compression (_Placement.compress), the others in steps of a few per cent, the
    # overlaps each step creates pushed apart (Gauss-Seidel descent on the
    # overlaps, :func:`_montecarlo.push_some`), each step followed by a sweep.
    lam = min(1.0, p.dist / p.dmax * (1.0 - 1e-9), (0.25 / eta) ** (1.0 / d))
    if lam == 1.0:  # no growth: the final sweeps melt the lattice, at least MELT_SWEEPS of them
        sweeps = max(int(melt), int(sweeps))
    # large systems: growth by one compression (below) where the box holds its grid
    swell = min(SWELL, (SWELL_PACKING_MAX[d] / eta) ** (1.0 / d) - 1.0)
    squeeze = (fire.compression_grid(box, p.dmax * (1.0 + swell + FIRE_SKIN))
               if p.large and lam < 1.0 and eta >= COMPRESSION_MIN_PACKING[d] else None)
    if squeeze is not None and d == 3:  # melt: each particle displaced uniformly over a lattice cell
        p.displace_within_cells()
        if default_melt:
            melt = 0
    elif squeeze is not None and default_melt:
        melt = COMPRESSION_MELT_SWEEPS
    if lam < 1.0:
        for _ in range(int(melt)):
            p.sweep(lam)
    if squeeze is not None:
        p.compress(squeeze, swell)
        lam = 1.0
        # the melt's step at packing <= 0.25 would be rejected almost always at full size
        p.step = min(p.step, 0.1 * p.dmax)
    p.grow(lam)
    for _ in range(int(sweeps)):
        p.sweep(1.0)
    return p.positions()


class _Placement:
    """One random placement under way (:func:`random_positions`): positions (N, 3) in lattice
    (memory ~ space) order, the radii and particle ids in the same order, the cell lists, the
    sort of large systems, and the Monte Carlo step. Large systems (N >=
    :data:`SORTED_MIN_PARTICLES`) sweep and push over cell-sorted particles (parallel), their
    random numbers from a per-sweep key; small ones over cell lists, their random numbers from
    the generator."""

    def __init__(self, radii, box, eta, rng):
        n, d = len(radii), len(box)
        self.n, self.d, self.box, self.eta, self.rng = n, d, box, eta, rng
        # M sites for N particles: S(k) = 1 - N/M = S0 at long wavelengths (docstring)
        m_sites = max(n, round(n / max(_MIN_OCCUPANCY, 1.0 - fluid_s0(eta, d))))
        sites, self.dist, z_order, self.cell = _lattice(m_sites, box)
        self.dmax = 2.0 * float(radii.max())
        # M sites kept, the extra ones dropped evenly in space; N of them at random,
        # in lattice (memory ~ space) order for fast sweeps; particle ids are
        # shuffled at the end
        kept = _spread_out(m_sites, z_order, rng)
        chosen = np.sort(kept[rng.permutation(m_sites)[:n]])
        pos = sites[chosen]
        self.ids = rng.permutation(n)
        self.radii = radii[self.ids]  # radii[k] belongs to the particle placed at site k
        self.r3 = np.zeros((n, 3))
        self.r3[:, :d] = pos
        self.box3 = np.ones(3)
        self.box3[:d] = box
        self.ncell = np.ones(3, dtype=np.int64)
        self.ncell[:d] = np.maximum(1, np.floor(box / self.dmax)).astype(np.int64)
        self.head = np.empty(int(np.prod(self.ncell)), dtype=np.int32)
        self.nxt = np.empty(n, dtype=np.int32)
        self.prv = np.empty(n, dtype=np.int32)
        self.cof = np.empty(n, dtype=np.int32)
        mc.fill_cells(self.r3, self.box3, self.ncell, self.head, self.nxt, self.prv, self.cof)
        self.step = 0.1 * self.dmax
        self.stale = False  # the cell lists lag behind the positions
        self.large = n >= SORTED_MIN_PARTICLES
        self.u = np.empty((0 if self.large else n, d))  # uniform random numbers of a sweep (small systems)
        self.sorting = {}  # the sort's offsets and scratch arrays (large systems)
        # pushed particles' partners (pushes over cell lists: small systems, and large ones in
        # boxes too small for the sorted scans); buf allocated on first use
        self.buf = np.empty(0, dtype=np.int64)
        self.near = np.empty(256, dtype=np.int64)
        self.uniq = np.empty(n, dtype=np.int64)
        self.seen = np.zeros(n, dtype=np.bool_)

    def _cells(self):
        return self.ncell, self.head, self.nxt, self.prv, self.cof

    def sweep_key(self):
        """A sweep's random numbers: a 64-bit key, or u filled (_montecarlo docstring)."""
        if self.large:
            return np.uint64(self.rng.integers(0, 2**63, dtype=np.int64))
        self.rng.random(out=self.u)
        return np.uint64(0)

    def lists(self):
        """The cell lists brought up to date, after sweeps or pushes over sorted particles."""
        if self.stale:
            mc.wrap_positions(self.r3, self.box3)
            mc.fill_cells(self.r3, self.box3, *self._cells())
            self.stale = False

    def sort(self, grid):
        """Particles (and their radii and ids) sorted by the cells of ``grid``."""
        n, sorting = self.n, self.sorting
        if not sorting:
            sorting.update(start=np.empty(0, dtype=np.int32), cell_of=np.empty(n, dtype=np.int32),
                           r=np.empty_like(self.r3), f=np.empty(n), i=np.empty(n, dtype=self.ids.dtype),
                           dest=np.empty(n, dtype=np.int32))
        if len(sorting["start"]) <= int(np.prod(grid)):
            sorting["start"] = np.empty(int(np.prod(grid)) + 1, dtype=np.int32)
        mc.sort_by_cell(self.r3, self.radii, self.ids, self.box3, grid, sorting["start"], sorting["cell_of"],
                        sorting["r"], sorting["f"], sorting["i"], sorting["dest"])
        self.stale = True

    def sweep(self, scale):
        """One hard-sphere Monte Carlo sweep at radii * scale; the step adapts to 40 % acceptance."""
        step = self.step
        grid = _sorted_grid(self.box, self.dmax * scale, step) if self.large else None
        if grid is None:  # small system, small box or long moves: cell lists
            self.lists()
            acc = mc.sweep(self.r3, self.radii * scale, self.box3, *self._cells(), step, self.sweep_key(), self.u,
                           self.d)
        else:
            self.sort(grid)
            acc = mc.sorted_sweep(self.r3, self.radii * scale, self.box3, grid, self.sorting["start"], step,
                                  self.sweep_key(), self.d)
        acc /= self.n
        self.step = min(0.5 * float(self.box.min()), step * min(2.0, max(0.5, acc / 0.4)))

    def displace_within_cells(self):
        """The melt of large 3D systems: each particle displaced uniformly over its lattice cell."""
        self.r3[:, : self.d] += (self.rng.random((self.n, self.d)) - 0.5) * self.cell
        self.stale = True

    def grow(self, lam):
        """Radii from lam of full size to full size in steps of a few per cent (at most 5 %), the
        overlaps of each step pushed apart, each step followed by a sweep; a step that stays stuck
        is undone and retried at half the growth."""
        r3, radii, ids, box3, seen = self.r3, self.radii, self.ids, self.box3, self.seen
        grow = 0.05
        while lam < 1.0:
            if grow < 1e-4:
                raise ConfigError(f"packing fraction {self.eta:.4g}: too dense for random placement of these "
                                  f"radii (reached {lam:.4f} of the target size)")
            trial = min(1.0, lam * (1.0 + grow))
            cap = PUSH_CAP * self.dmax * trial
            grid = _sorted_grid(self.box, self.dmax * trial, cap) if self.large else None
            if grid is not None:  # large systems: census and pushes over sorted particles
                self.sort(grid)
                mc.sorted_overlapping(r3, radii * trial, box3, grid, self.sorting["start"], seen)
                idx = np.flatnonzero(seen)
                seen[:] = False
                saved = (r3.copy(), radii.copy(), ids.copy())
                idx = self.sorted_pushes(idx, grid, trial, grow, cap)
                if len(idx):
                    r3[:], radii[:], ids[:] = saved
                    self.stale = True
            else:
                self.lists()
                saved = r3.copy()
                idx = self.pushes(radii * trial, grow)
                if len(idx):
                    r3[:] = saved
                    mc.fill_cells(r3, box3, *self._cells())
            if len(idx):  # stuck: undone, grow more gently
                grow *= 0.5
                continue
            grow = min(0.05, grow * 1.5)
            lam = trial
            self.sweep(lam)

    def pushes(self, rad, grow):
        """A growth step's pushes over cell lists; returns the particles still overlapping."""
        n, d, r3, box3, rng = self.n, self.d, self.r3, self.box3, self.rng
        ncell, head, nxt, prv, cof = self._cells()
        if len(self.buf) == 0:
            self.buf = np.empty(max(64, 40 * n), dtype=np.int64)
        buf, near, uniq, seen = self.buf, self.near, self.uniq, self.seen
        idx = buf[: mc.overlapping(r3, rad, box3, ncell, head, nxt, buf)].copy()
        for it in range(600):
            if len(idx) == 0:
                break
            if it % 100 == 99:  # jammed spots: let the hard-sphere surroundings make room
                key = self.sweep_key()
                mc.relax_sweep(r3, rad, box3, ncell, head, nxt, prv, cof, 0.5 * grow * self.dmax, key, self.u, d)
                idx = buf[: mc.overlapping(r3, rad, box3, ncell, head, nxt, buf)].copy()
                continue
            kick = rng.uniform(0.5, 1.5, size=len(idx))
            m = mc.push_some(idx, r3, rad, box3, ncell, head, nxt, prv, cof, kick, PUSH_MARGIN * grow,
                             near, buf)
            # in order of first appearance (a pushed particle's new partners, then itself)
            idx = uniq[: mc.distinct(buf, m, seen, uniq)].copy()
        return idx

    def sorted_pushes(self, idx, grid, scale, grow, cap):
        """The same over sorted particles (large systems)."""
        d, r3, box3, rng, sorting = self.d, self.r3, self.box3, self.rng, self.sorting
        uniq, seen = self.uniq, self.seen
        start = sorting["start"]
        slabs = int(grid[2] if d == 3 else grid[1])
        slab_start = np.empty(slabs + 1, dtype=np.int64)
        out_n = np.empty(slabs, dtype=np.int64)
        rad = self.radii * scale
        for it in range(600):
            if len(idx) == 0:
                break
            if it % 100 == 99:  # jammed spots: as in pushes(), then sorted again
                self.lists()
                key = self.sweep_key()
                mc.relax_sweep(r3, rad, box3, *self._cells(), 0.5 * grow * self.dmax, key, self.u, d)
                self.sort(grid)
                rad = self.radii * scale
                mc.sorted_overlapping(r3, rad, box3, grid, start, seen)
                idx = np.flatnonzero(seen)
                seen[:] = False
                continue
            mc.group_by_slab(idx, sorting["cell_of"], grid, uniq[: len(idx)], slab_start)
            idx = uniq[: len(idx)].copy()
            kick = rng.uniform(0.5, 1.5, size=len(idx))
            out = np.empty(40 * len(idx), dtype=np.int64)  # slab h writes from 40 slab_start[h] on
            push = mc.sorted_push if len(idx) >= PARALLEL_MIN_PUSHES else mc.sorted_push_serial
            clamped = push(idx, slab_start, r3, rad, box3, grid, start, sorting["cell_of"], cap, kick,
                           PUSH_MARGIN * grow, out, out_n)
            self.stale = True
            # in order of first appearance (a pushed particle's new partners, then itself)
            idx = uniq[: mc.distinct_runs(out, 40 * slab_start[:-1], out_n, seen, uniq)].copy()
            del out  # (a buffer per pass: its untouched pages are never mapped)
            if clamped:  # pushes held back at the cap: sort again
                self.sort(grid)
                rad = self.radii * scale
                idx = sorting["dest"][idx].astype(np.int64)
        return idx

    def compress(self, grid, swell):
        """Growth to full size in one FIRE minimisation (large systems)."""
        n, d, r3, radii, box3, dmax, sorting = self.n, self.d, self.r3, self.radii, self.box3, self.dmax, self.sorting
        skin = FIRE_SKIN * dmax
        v = np.zeros((n, 3))
        f = np.empty((n, 3))
        r0 = np.empty((n, 3))
        moved = np.empty((-(-n // FIRE_BLOCK), 2))
        counts = np.empty(n, dtype=np.int64)
        offsets = np.zeros(n + 1, dtype=np.int64)

        def rebuild(pairs):  # sorted again (v with the particles), neighbour lists from the sort
            self.sort(grid)
            start = sorting["start"]
            # v and the last counts (room for as many pairs as the particle had neighbours,
            # + NEIGHBOUR_SLACK) to the particles' new places
            fire.follow_sort(sorting["dest"], v, counts, f, room)
            if len(pairs) == 0:
                fire.neighbour_counts(r3, radii, box3, grid, start, swell, skin, counts)
            while True:
                np.cumsum(counts + NEIGHBOUR_SLACK, out=offsets[1:])
                if len(pairs) < offsets[-1]:
                    pairs = np.empty(int(1.1 * offsets[-1]), dtype=np.int32)
                if fire.neighbour_rows(r3, radii, box3, grid, start, swell, skin, offsets, pairs, counts) == 0:
                    break
            r0[:] = r3
            slab_start[:] = start[np.arange(slabs + 1) * (int(np.prod(grid)) // slabs)]
            return pairs

        room = np.empty(n, dtype=np.int64)
        slabs = int(grid[2] if d == 3 else grid[1])
        slab_start = np.empty(slabs + 1, dtype=np.int64)
        sums = np.empty((slabs, 6))
        pairs = rebuild(np.empty(0, dtype=np.int32))
        dt, alpha, downhill, separated = FIRE_DT, 0.1, 0, -5
        for it in range(FIRE_MAX_STEPS):
            power, vv, ff, hard, _worst, stray = fire.fire_forces(r3, radii, box3, offsets, counts, pairs, swell,
                                                                  v, f, slab_start, sums)
            if stray:
                raise RuntimeError(f"compression: {stray} listed pairs reach beyond the next slab")
            if hard == 0:  # no pair closer than contact
                self.stale = True
                return
            if hard <= max(SEPARATE_MAX_PAIRS, n // SEPARATE_PER_PAIR) and it >= separated + 5:
                # the last few overlaps: pushed apart directly, the lists built afresh
                for _ in range(8):  # (then checked over lists built afresh)
                    if fire.separate_pairs(r3, radii, box3, offsets, counts, pairs, swell) == 0:
                        break
                pairs = rebuild(pairs)
                separated = it
                continue
            if power >= 0.0:  # FIRE (Bitzek et al. 2006): N_min 5, f_inc 1.1, f_alpha 0.99, f_dec 0.5
                downhill += 1
                if downhill > 5:
                    dt, alpha = min(1.1 * dt, FIRE_DT_MAX), 0.99 * alpha
                keep, mix = 1.0 - alpha, alpha * math.sqrt(vv / ff) if ff > 0.0 else 0.0
            else:
                downhill, dt, alpha, keep, mix = 0, 0.5 * dt, 0.1, 0.0, 0.0
            fire.fire_move(r3, v, f, r0, keep, mix, dt, FIRE_MAX_MOVE * dmax, FIRE_BLOCK, moved)
            self.stale = True
            far = np.sort(moved.ravel())[-2:]  # the two largest distances moved since the build
            if far[0] + far[1] > skin:
                pairs = rebuild(pairs)
        raise ConfigError(f"packing fraction {self.eta:.4g}: too dense for random placement of these radii "
                          f"(the compression to full size did not converge in {FIRE_MAX_STEPS} steps)")

    def positions(self):
        """The positions (N, d) in [0, L), in the particles' (shuffled) id order."""
        mc.wrap_positions(self.r3, self.box3)
        out = np.empty((self.n, self.d))
        out[self.ids] = self.r3[:, : self.d]
        return out


def maxwell_velocities(masses, dimension, temperature=1.0, seed=0, rng=None):
    """Maxwell-Boltzmann velocities (N, d): zero total momentum, temperature exactly T."""
    rng = np.random.default_rng(seed) if rng is None else rng
    masses = np.asarray(masses, dtype=np.float64)
    n = len(masses)
    v = rng.standard_normal((n, dimension)) * np.sqrt(temperature / masses)[:, None]
    v -= np.sum(masses[:, None] * v, axis=0) / np.sum(masses)
    t_now = float(np.sum(masses[:, None] * v * v)) / (dimension * n)
    if temperature > 0 and t_now > 0:
        v *= math.sqrt(temperature / t_now)
    else:
        v[:] = 0.0
    return v


def maxwell_spins(moments, dimension, temperature=1.0, rng=None):
    """Maxwell-Boltzmann angular velocities of rough particles with moments of inertia
    ``moments`` (N,): (N, 3) in 3D, (N, 1) (about z) in 2D, zero total spin angular momentum
    sum I w = 0 and rotational temperature sum I |w|^2 / (d_r N) exactly ``temperature``
    (d_r = 3 or 1; :func:`maxwell_velocities` with the moments in place of the masses)."""
    return maxwell_velocities(moments, 3 if dimension == 3 else 1, temperature, rng=rng)


#: smallest wall axis in largest diameters: the placement box is one diameter shorter
#: than the wall axis and needs the engine's 3.15 (three cells) itself
MIN_WALL_AXIS_DIAMETERS = 4.15


def random_state(n, packing, dimension=3, temperature=1.0, seed=0, radii=0.5, masses=None,
                 aspect=None, sweeps=None, rng=None, boundary=None, shear=None, margins=None) -> State:
    """A random homogeneous initial state: box, positions, velocities (in this order from one generator).

    Parameters
    ----------
    n : int
        Number of particles.
    packing : float
        Packing fraction (3D: sum of sphere volumes / V; 2D: disk areas / A), V the
        whole box also between walls.
    dimension : {2, 3}
    temperature : float
        Granular temperature T (k_B = 1).
    seed : int
    radii : float or array (N,)
        Radii in units of the reference diameter (default 0.5: monodisperse).
    masses : float or array (N,), optional
        Default: (2 R)^d, i.e. the density of the reference particle (mass 1, diameter 1).
    aspect : sequence of d floats, optional
        Relative box side lengths (default cubic/square).
    sweeps : int, optional
        Monte Carlo sweeps (see :func:`random_positions`).
    rng : numpy.random.Generator, optional
        Generator to draw from instead of ``default_rng(seed)`` (a config run draws
        its polydisperse radii from it first).
    boundary : sequence of d str, optional
        "periodic" or "wall" per axis (default all periodic). On a wall axis of length
        L the positions are placed as on a periodic axis of length L - 2 R_max and
        shifted by R_max: no sphere overlaps a wall (every centre lies within
        [R_max, L - R_max]); the density next to the walls relaxes to its steady
        profile within a few collision times. A wall axis must be at least
        ``MIN_WALL_AXIS_DIAMETERS`` largest diameters long. "lees-edwards" (the sheared
        y axis) is placed as a periodic one.
    shear : float, optional
        Shear rate a: the velocities get the flow a (y - L_y/2) along x on top of the
        Maxwellian (uniform shear flow, :class:`granulargas.engine.shear.Shear`).
    margins : array (d, 2), optional
        Room kept free at the lower and upper wall of each wall axis besides R_max (e.g.
        the sweep 2A of a vibrating wall, :attr:`granulargas.engine.walls.Wall.reach`):
        the positions are placed on L - 2 R_max - margins there, which must still be at
        least ``MIN_WALL_AXIS_DIAMETERS`` largest diameters less 2 R_max.
    """
    if dimension not in (2, 3):
        raise ConfigError(f"dimension = {dimension}: allowed values are 2 and 3")
    n = int(n)
    if n < 2:
        raise ConfigError(f"number of particles = {n}: need at least 2")
    if not 0.0 < packing < (0.74 if dimension == 3 else 0.9):
        raise ConfigError(f"packing fraction = {packing}: allowed range is (0, {0.74 if dimension == 3 else 0.9})")
    walls = [] if boundary is None else [a for a in range(dimension) if boundary[a] == "wall"]
    rng = np.random.default_rng(seed) if rng is None else rng
    radii = np.array(np.broadcast_to(np.asarray(radii, dtype=np.float64), (n,)))
    if np.any(radii <= 0):
        raise ConfigError("radii: must be > 0")
    masses = (2.0 * radii) ** dimension if masses is None else np.array(
        np.broadcast_to(np.asarray(masses, dtype=np.float64), (n,)))
    box = box_for_packing(radii, packing, dimension, aspect)
    placement = box.copy()
    rmax = float(radii.max())
    margins = np.zeros((dimension, 2)) if margins is None else np.asarray(margins, dtype=np.float64)
    for a in walls:
        free = box[a] - margins[a].sum()
        if free < MIN_WALL_AXIS_DIAMETERS * 2.0 * rmax:
            room = "" if not margins[a].any() else f" less {margins[a].sum():.4g} kept clear of the walls"
            raise ConfigError(f"wall axis {'xyz'[a]}: length {box[a]:.4g}{room} is too short for the particles: "
                              f"it must be >= {MIN_WALL_AXIS_DIAMETERS:g} largest diameters "
                              f"(= {MIN_WALL_AXIS_DIAMETERS * 2.0 * rmax:.4g}); use more particles or a "
                              f"lower packing fraction")
        placement[a] = free - 2.0 * rmax
    pos = random_positions(radii, placement, sweeps=sweeps, rng=rng)
    for a in walls:
        pos[:, a] += rmax + margins[a, 0]
    vel = maxwell_velocities(masses, dimension, temperature, rng=rng)
    if shear is not None:  # the flow a (y - L_y/2) along x on top of the peculiar velocities
        vel[:, 0] += float(shear) * (pos[:, 1] - 0.5 * box[1])
    bnd = None if boundary is None else tuple(boundary)
    return State(pos, vel, radii, masses, box, boundary=bnd)
