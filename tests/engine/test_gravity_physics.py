"""Physics of gases under gravity against theory that needs no fit.

* An elastic gas on a thermal floor at T_w under a hard lid reaches equilibrium: T(z) = T_w in
  every layer, a Maxwellian in every layer (zero excess kurtosis), and the hydrostatic density
  profile dp/dz = -m g n with p = n T_w Z(n) from the project's equation of state
  (:func:`granulargas.theory.vibrated.hydrostatic_density`) -- within the statistical error
  (block means over snapshots). The layers within 1.5 diameters of the floor and the lid are
  left out: the local-density approximation does not describe the layering at a wall, whose
  excess of particles at contact also leaves the bulk a little short of the column's mean;
  the hydrostatic equation is local, so the profile is compared in shape, with its
  normalisation fitted over the inner layers (one parameter).
* A steady vibrated bed puts in what it dissipates.
"""

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from granulargas.analysis.vibrated import LayerAccumulator, energy_balance
from granulargas.engine import CollisionRule, Simulation, Wall, Walls
from granulargas.initial import random_state
from granulargas.theory import vibrated as V


def _equilibrium(d, n, packing, g, tw, t_relax, t_end, dt, seed, neighbours):
    """Snapshots of an elastic gas on a thermal floor under a hard lid after ``t_relax``: per
    snapshot, the counts and the sums of v^2 in 30 layers; the layer profile; the edges."""
    boundary = ("periodic",) * (d - 1) + ("wall",)
    st = random_state(n, packing, d, temperature=tw, seed=seed, boundary=boundary)
    gravity = [0.0] * (d - 1) + [-g]
    walls = Walls(**{"xyz"[d - 1] + "_low": Wall.thermal(tw)}, seed=seed)
    sim = Simulation(st, CollisionRule.elastic(), gravity=gravity, walls=walls, neighbours=neighbours)
    sim.run(t_relax)
    L = float(st.box[-1])
    edges = np.linspace(0.0, L, 31)
    acc = LayerAccumulator(d - 1, edges, st.box)
    counts, v2 = [], []
    t = t_relax
    while t < t_end:
        t += dt
        sim.run(t)
        pos, vel = sim.positions, sim.velocities
        acc.add(pos, vel, st.masses)
        counts.append(np.histogram(pos[:, -1], edges)[0])
        v2.append(np.histogram(pos[:, -1], edges, weights=(vel * vel).sum(axis=1))[0])
    return st, acc.profile(), np.array(counts, dtype=float), np.array(v2), edges


def _check_equilibrium(st, prof, counts, v2, edges, g, tw, d, blocks=40):
    """The checks of the module docstring. Errors are standard errors of block means over the
    snapshots; the density's also allows for the gradient corrections to the local-density
    approximation, of relative size (sigma / ell)^2 with ell = T_w / (m g)."""
    L = float(st.box[-1])
    section = float(np.prod(st.box[:-1]))
    width = np.diff(edges)
    cb = np.array([b.sum(axis=0) for b in np.array_split(counts, blocks)])
    vb = np.array([b.sum(axis=0) for b in np.array_split(v2, blocks)])
    per = len(counts) / blocks
    nb = cb / per / (width * section)
    n_mean, n_err = nb.mean(axis=0), nb.std(axis=0, ddof=1) / math.sqrt(blocks)
    with np.errstate(invalid="ignore", divide="ignore"):
        tb = vb / (d * cb)
    centres = 0.5 * (edges[1:] + edges[:-1])
    inner = (centres > 1.5) & (centres < L - 1.5) & (cb.min(axis=0) > 20)
    lda = (g / tw) ** 2  # (sigma / ell)^2

    def fitted(profile):
        """The profile (a function of the column) with the column that fits the inner layers best."""
        def chi2(c):
            p = profile(c)
            return float(np.sum(((n_mean - p) / np.hypot(n_err, lda * p))[inner] ** 2))
        c = minimize_scalar(chi2, bounds=(0.8 * st.n / section, 1.2 * st.n / section), method="bounded",
                            options={"xatol": 1e-9}).x
        return profile(c)

    theory = fitted(lambda c: V.hydrostatic_density(centres, c, tw, g, 1.0, 1.0, d, bottom=0.5, top=L - 0.5))
    baro = fitted(lambda c: V.barometric_density(centres, c, tw, g, 1.0, bottom=0.5, top=L - 0.5))
    z = (n_mean - theory) / np.hypot(n_err, lda * theory)
    assert np.mean(z[inner] ** 2) < 2.5 and np.max(np.abs(z[inner])) < 4.0, (z[inner], n_mean[inner], theory[inner])
    # the equation of state matters: the barometric law is refused near the floor
    zb = (n_mean - baro) / np.hypot(n_err, lda * baro)
    assert np.max(np.abs(zb[inner])) > 6.0
    # T = T_w and a Maxwellian in every layer with samples enough
    T_mean, T_err = np.nanmean(tb, axis=0), np.nanstd(tb, axis=0, ddof=1) / math.sqrt(blocks)
    ok = inner & (cb.min(axis=0) > 200)
    assert np.all(np.abs(T_mean[ok] - tw) < 4 * T_err[ok]), (T_mean[ok], T_err[ok])
    assert np.all(np.abs(prof.kurtosis[ok]) < 4 * prof.kurtosis_error[ok, None] * 3.0)


@pytest.mark.parametrize("neighbours", ["lists", "cells"])
def test_elastic_gas_on_a_thermal_floor_is_in_hydrostatic_equilibrium(neighbours):
    """2D, g = 0.15 (ell = 6.7 diameters, the floor at packing 0.25): the density within the
    statistical error and the local-density approximation's (sigma / ell)^2 = 2 %."""
    d, g, tw = 2, 0.15, 1.0
    st, prof, counts, v2, edges = _equilibrium(d, 150, 0.06, g, tw, 300.0, 3000.0, 1.0, 3, neighbours)
    _check_equilibrium(st, prof, counts, v2, edges, g, tw, d)


@pytest.mark.slow
@pytest.mark.parametrize("d, n, packing, g", [(2, 800, 0.16, 0.04), (3, 2000, 0.08, 0.05)])
def test_thermal_floor_equilibrium_long(d, n, packing, g):
    """Weak gravity (ell = 20-25 diameters: the local-density approximation good to 0.2-0.3 %)
    over a dense floor (packing 0.2-0.3): the hydrostatic profile within the statistical error."""
    st, prof, counts, v2, edges = _equilibrium(d, n, packing, g, 1.0, 1000.0, 12000.0, 2.0, 5, "lists")
    _check_equilibrium(st, prof, counts, v2, edges, g, 1.0, d)


@pytest.mark.parametrize("waveform", ["sine", "triangle", "biparabolic"])
def test_a_steady_vibrated_bed_puts_in_what_it_dissipates(waveform):
    """Power put in by the floor = power dissipated in collisions, to the statistical error of
    the second half of the run (the first half relaxes)."""
    st = random_state(300, 0.01, 3, seed=2, boundary=("periodic", "periodic", "wall"),
                      margins=[[0, 0], [0, 0], [0.1, 0]])
    walls = Walls(z_low=Wall.vibrating(0.05, 3.183, waveform))
    sim = Simulation(st, CollisionRule.constant(0.8, wall_restitution=0.9, elastic_below=1e-3),
                     gravity=[0.0, 0.0, -1.0], walls=walls, neighbours="cells")
    t, work, lost = [], [], []
    for k in range(1, 401):
        sim.run(k * 1.0)
        t.append(sim.time)
        work.append(sim.wall_work)
        lost.append(sim.dissipated_energy)
    b = energy_balance(t, work, lost)
    assert b.power_in > 0 and abs(b.ratio - 1.0) < 4 * b.ratio_error + 0.01, (b.ratio, b.ratio_error)
    assert b.ratio_error < 0.05
