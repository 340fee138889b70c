"""Runs with walls: density profile across the walls and the pressure on them.

A gas between flat hard walls (``[system] boundary`` with "wall" entries) is
homogeneous along the periodic axes but not across the walls: next to a wall the
density rises above its bulk value (contact-value theorem for hard walls,
P = n(R) T), further out it oscillates and settles within a few diameters.

* :func:`density_profile` -- number density and packing fraction against the
  coordinate across a wall axis, averaged over snapshots (histogram of the
  centres, bins of equal width over [0, L]);
* :func:`wall_summary` -- the measured wall pressure (observable ``wall_pressure``:
  momentum delivered per wall area and time) averaged over the run, the bulk
  density (the middle half of the slab) and, for an elastic gas, the pressure the
  equation of state gives at that bulk density and the run's temperature: in
  mechanical equilibrium they are equal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas import theory
from granulargas.analysis.elastic import block_mean
from granulargas.io.h5md import iter_snapshots, read_observables

__all__ = ["DensityProfile", "density_profile", "wall_summary", "wall_axes"]


def wall_axes(boundary) -> list[int]:
    """Indices of the axes with walls."""
    return [a for a, b in enumerate(boundary) if b == "wall"]


@dataclass(frozen=True)
class DensityProfile:
    """Number density n(x) across one axis (arrays (B,)), averaged over ``frames`` snapshots."""

    axis: int
    edges: np.ndarray
    density: np.ndarray  # number per unit volume
    packing: np.ndarray  # particle volume per unit volume (monodisperse: n v)
    frames: int
    t_from: float

    @property
    def centres(self) -> np.ndarray:
        return 0.5 * (self.edges[1:] + self.edges[:-1])

    def bulk(self, fraction: float = 0.5):
        """(mean density, mean packing) over the middle ``fraction`` of the axis."""
        L = self.edges[-1]
        c = self.centres
        sel = np.abs(c - 0.5 * L) <= 0.5 * fraction * L
        return float(self.density[sel].mean()), float(self.packing[sel].mean())


def density_profile(path, axis: int, bins: int | None = None, t_from: float = 0.0) -> DensityProfile:
    """Histogram of the particle centres across ``axis``, averaged over the snapshots at t >= t_from.

    ``bins`` defaults to 5 per largest diameter.
    """
    counts = vol = None
    frames = 0
    for snap in iter_snapshots(path):
        if snap.time < t_from:
            continue
        if counts is None:
            L = float(snap.box[axis])
            d = snap.box.shape[0]
            nb = bins or max(10, int(round(5.0 * L / (2.0 * float(snap.radii.max())))))
            edges = np.linspace(0.0, L, nb + 1)
            counts = np.zeros(nb)
            vol = np.zeros(nb)
            slab = float(np.prod(snap.box)) / L * (L / nb)
            pv = theory.particle_volume(2.0 * snap.radii, d)
        idx = np.clip((snap.positions[:, axis] / L * nb).astype(int), 0, nb - 1)
        counts += np.bincount(idx, minlength=nb)
        vol += np.bincount(idx, weights=pv, minlength=nb)
        frames += 1
    if frames == 0:
        raise ValueError(f"no snapshot at t >= {t_from:g}")
    return DensityProfile(axis, edges, counts / (frames * slab), vol / (frames * slab), frames, t_from)


def wall_summary(info, t_from: float, temperature: float | None = None) -> dict:
    """Wall pressure (block mean over the observables windows after ``t_from``), bulk density,
    and for an elastic gas the equation-of-state pressure at the bulk density.

    ``info`` is a :class:`granulargas.analysis.run.RunInfo` with walls; ``temperature``
    the run's mean temperature over the same times (default: from the observables).
    """
    obs = read_observables(info.path)
    _, t, pw = obs["wall_pressure"]
    keep = (t > t_from) & np.isfinite(pw)
    p, p_err = block_mean(pw[keep])
    if temperature is None:
        _, tt, T = obs["temperature"]
        temperature = float(np.mean(T[tt >= t_from]))
    out = {"wall_pressure": p, "wall_pressure_error": p_err, "axes": wall_axes(info.boundary), "t_from": t_from}
    profiles = [density_profile(info.path, a, t_from=t_from) for a in out["axes"]]
    n_bulk, eta_bulk = profiles[0].bulk()
    out.update(bulk_density=n_bulk, bulk_packing=eta_bulk, profile_frames=profiles[0].frames)
    if info.model == "elastic" or (info.model == "constant" and info.restitution == 1.0):
        eta = float(theory.packing_fraction(n_bulk, info.dimension, info.diameter))
        z = float(theory.compressibility_factor(eta, info.dimension))
        out.update(eos_pressure=n_bulk * temperature * z, eos_name=theory.eos_name(info.dimension),
                   temperature=temperature)
    else:
        out.update(eos_pressure=math.nan, eos_name=None, temperature=temperature)
    return out
