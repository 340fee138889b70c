"""Initial states: random non-overlapping placement and Maxwell-Boltzmann velocities.

Placement (fast for 10^6 particles, packing fractions up to ~0.55 in 3D and
~0.80 in 2D, polydisperse too):

1. a lattice with at least N sites and the largest nearest-neighbour distance
   that fits the box (FCC in 3D, triangular in 2D, per-axis cell counts chosen
   to fit any box shape);
2. N sites chosen at random, radii assigned at random; if the lattice distance
   is below the largest diameter (polydisperse or very dense systems), all radii
   start scaled down and grow between Monte Carlo sweeps to the largest size
   without overlap until they reach full size;
3. hard-sphere Monte Carlo sweeps (random displacements rejected on overlap,
   step adapted to ~40 % acceptance) destroy the lattice order.

Velocities: Gaussian components with variance T/m_i, total momentum removed,
then rescaled so that the granular temperature m<c^2>/d is exactly T.
Everything is drawn from ``numpy.random.default_rng(seed)``: a seed gives
the same state on every machine.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from granulargas.engine import _montecarlo as mc
from granulargas.errors import ConfigError


@dataclass
class InitialState:
    """Arrays for :class:`granulargas.engine.Simulation` (particle-id order)."""

    positions: np.ndarray  # (N, d)
    velocities: np.ndarray  # (N, d)
    radii: np.ndarray  # (N,)
    masses: np.ndarray  # (N,)
    box: np.ndarray  # (d,)

    def as_kwargs(self) -> dict:
        return dict(positions=self.positions, velocities=self.velocities, radii=self.radii,
                    masses=self.masses, box=self.box)


def particle_volume(radii, dimension):
    """Volume (3D) or area (2D) of each particle."""
    radii = np.asarray(radii, dtype=np.float64)
    return 4.0 / 3.0 * math.pi * radii**3 if dimension == 3 else math.pi * radii**2


def box_for_packing(radii, packing, dimension, aspect=None):
    """Box sides (d,) giving packing fraction ``packing`` (aspect: relative side lengths)."""
    volume = float(np.sum(particle_volume(radii, dimension))) / packing
    aspect = np.ones(dimension) if aspect is None else np.asarray(aspect, dtype=np.float64)
    return aspect * (volume / float(np.prod(aspect))) ** (1.0 / dimension)


def _lattice(n, box):
    """Sites (M >= n, d) of an FCC (3D) / triangular (2D) lattice filling ``box``."""
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
    return sites, best


def random_positions(radii, box, seed=0, sweeps=None, rng=None):
    """Random non-overlapping positions (N, d) in [0, L) for spheres/disks of ``radii``.

    Parameters
    ----------
    radii : array (N,)
    box : array (d,)
    seed : int
    sweeps : int, optional
        Monte Carlo sweeps after lattice placement (default 20, 6 beyond 10^5 particles).

    Raises
    ------
    ConfigError
        If the packing is too high for the lattice to hold the largest particles.
    """
    rng = np.random.default_rng(seed) if rng is None else rng
    radii = np.asarray(radii, dtype=np.float64)
    box = np.asarray(box, dtype=np.float64)
    n, d = len(radii), len(box)
    sites, dist = _lattice(n, box)
    dmax = 2.0 * float(radii.max())
    # random sites, kept in lattice (memory ~ space) order for fast sweeps;
    # particle ids are shuffled at the end
    chosen = np.sort(rng.permutation(len(sites))[:n])
    pos = sites[chosen]
    ids = rng.permutation(n)
    radii = radii[ids]  # radii[k] belongs to the particle placed at site k
    r3 = np.zeros((n, 3))
    r3[:, :d] = pos
    box3 = np.ones(3)
    box3[:d] = box
    ncell = np.ones(3, dtype=np.int64)
    ncell[:d] = np.maximum(1, np.floor(box / dmax)).astype(np.int64)
    head = np.empty(int(np.prod(ncell)), dtype=np.int32)
    nxt = np.empty(n, dtype=np.int32)
    prv = np.empty(n, dtype=np.int32)
    cof = np.empty(n, dtype=np.int32)
    mc.fill_cells(r3, box3, ncell, head, nxt, prv, cof)
    if sweeps is None:
        sweeps = 20 if n <= 100_000 else 6
    disp = np.zeros((n, 3))
    state = {"step": 0.1 * dmax}

    def do_sweep(rad):
        disp[:, :d] = rng.uniform(-1.0, 1.0, size=(n, d))
        acc = mc.sweep(r3, rad, box3, ncell, head, nxt, prv, cof, state["step"], disp) / n
        state["step"] = min(0.5 * float(box.min()), state["step"] * min(2.0, max(0.5, acc / 0.4)))

    # Dense systems (and lattices too tight for the largest particles) start
    # diluted, radii scaled by lam so that the packing is <= 0.25 and the sweeps
    # melt the lattice; then the radii grow in steps of a few per cent, the
    # overlaps each step creates are pushed apart (Gauss-Seidel descent on the
    # overlaps, :func:`_montecarlo.push_some`), and a hard-sphere sweep follows.
    eta = float(np.sum(particle_volume(radii, d))) / float(np.prod(box))
    lam = min(1.0, dist / dmax * (1.0 - 1e-9), (0.25 / eta) ** (1.0 / d))
    if lam < 1.0:
        for _ in range(int(sweeps)):
            do_sweep(radii * lam)
    buf = np.empty(max(64, 40 * n), dtype=np.int64)
    uniq = np.empty(n, dtype=np.int64)
    seen = np.zeros(n, dtype=np.bool_)
    grow = 0.05
    while lam < 1.0:
        if grow < 1e-4:
            raise ConfigError(f"packing fraction {eta:.4g}: too dense for random placement of these "
                              f"radii (reached {lam:.4f} of the target size)")
        saved = r3.copy()
        trial = min(1.0, lam * (1.0 + grow))
        rad = radii * trial
        idx = buf[: mc.overlapping(r3, rad, box3, ncell, head, nxt, buf)].copy()
        for it in range(600):
            if len(idx) == 0:
                break
            if it % 100 == 99:  # jammed spots: let the hard-sphere surroundings make room
                disp[:, :d] = rng.uniform(-1.0, 1.0, size=(n, d))
                mc.relax_sweep(r3, rad, box3, ncell, head, nxt, prv, cof, 0.5 * grow * dmax, disp)
                idx = buf[: mc.overlapping(r3, rad, box3, ncell, head, nxt, buf)].copy()
                continue
            kick = rng.uniform(0.5, 1.5, size=len(idx))
            m = mc.push_some(idx, r3, rad, box3, ncell, head, nxt, prv, cof, kick, buf)
            idx = np.sort(uniq[: mc.distinct(buf, m, seen, uniq)])  # = np.unique(buf[:m])
        if len(idx):  # stuck: undo, grow more gently
            r3[:] = saved
            mc.fill_cells(r3, box3, ncell, head, nxt, prv, cof)
            grow *= 0.5
            continue
        grow = min(0.05, grow * 1.5)
        lam = trial
        rad = radii * lam
        do_sweep(rad)
    for _ in range(int(sweeps)):
        do_sweep(radii)
    out = np.empty((n, d))
    out[ids] = r3[:, :d]
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


def random_state(n, packing, dimension=3, temperature=1.0, seed=0, radii=0.5, masses=None,
                 aspect=None, sweeps=None) -> InitialState:
    """A random homogeneous initial state.

    Parameters
    ----------
    n : int
        Number of particles.
    packing : float
        Packing fraction (3D: sum of sphere volumes / V; 2D: disk areas / A).
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
    """
    if dimension not in (2, 3):
        raise ConfigError(f"dimension = {dimension}: allowed values are 2 and 3")
    n = int(n)
    if n < 2:
        raise ConfigError(f"number of particles = {n}: need at least 2")
    if not 0.0 < packing < (0.74 if dimension == 3 else 0.9):
        raise ConfigError(f"packing fraction = {packing}: allowed range is (0, {0.74 if dimension == 3 else 0.9})")
    rng = np.random.default_rng(seed)
    radii = np.array(np.broadcast_to(np.asarray(radii, dtype=np.float64), (n,)))
    if np.any(radii <= 0):
        raise ConfigError("radii: must be > 0")
    masses = (2.0 * radii) ** dimension if masses is None else np.array(
        np.broadcast_to(np.asarray(masses, dtype=np.float64), (n,)))
    box = box_for_packing(radii, packing, dimension, aspect)
    pos = random_positions(radii, box, sweeps=sweeps, rng=rng)
    vel = maxwell_velocities(masses, dimension, temperature, rng=rng)
    return InitialState(pos, vel, radii, masses, box)
