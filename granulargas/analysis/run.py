"""File-level analysis of one run: the H5MD file -> cooling history, theory, fits.

Everything goes through the readers of :mod:`granulargas.io.h5md`
(``read_observables``, ``iter_snapshots``, ``load_snapshot``,
``read_parameters``) and reads snapshots one frame at a time, so files with
10^6 particles and many frames are fine.

The theory for a run (:meth:`RunInfo.prediction`) uses the run's number density
``N / V``, dimension, and collision model from ``parameters/collision``; it is the
theory of identical particles, so for a polydisperse run the mean diameter and
mass are used and :attr:`RunInfo.monodisperse` is False.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterator

import numpy as np

from granulargas import theory
from granulargas.analysis.cooling import (
    CoolingFit,
    collisions_per_particle,
    fit_cooling_law,
    sonine_coefficients,
)
from granulargas.errors import InputFileError
from granulargas.io.h5md import iter_snapshots, load_snapshot, read_observables, read_parameters
from granulargas.theory.gas import Gas

__all__ = [
    "RunInfo",
    "Prediction",
    "CoolingHistory",
    "cooling_history",
    "sonine_history",
    "snapshot_series",
    "CoolingAnalysis",
    "analyze_cooling",
]


@dataclass(frozen=True)
class Prediction:
    """Kinetic-theory prediction for a run's cooling (reduced units).

    ``law`` is ``"haff"`` (``T0/(1+t/tau0)^2``), ``"viscoelastic"``
    (``T0 (1+t/tau0)^(-5/3)``) or ``"elastic"`` (constant T).
    """

    law: str
    T0: float
    tau0: float
    exponent: float
    a2: float
    omega0: float
    mean_free_path: float
    instability_length: float
    tau0_second_order: float = math.nan  # viscoelastic: 1/((3/5) zeta(T0)) with the beta^2 term

    def temperature(self, t):
        t = np.asarray(t, dtype=float)
        if self.law == "elastic":
            return np.full_like(t, self.T0)
        return self.T0 * (1.0 + t / self.tau0) ** (-self.exponent)

    def collisions(self, t):
        """Collisions per particle by time t."""
        t = np.asarray(t, dtype=float)
        if self.law == "haff":
            return theory.haff_collisions(t, self.tau0, self.omega0)
        if self.law == "viscoelastic":
            return theory.viscoelastic_collisions(t, self.tau0, self.omega0)
        return self.omega0 * t


@dataclass(frozen=True)
class RunInfo:
    """What the analysis needs to know about a run, read once from its file."""

    path: str
    dimension: int
    particles: int
    box: np.ndarray
    diameter: float
    mass: float
    monodisperse: bool
    model: str
    restitution: float | None
    prefactor: float | None
    contact_end: str = "overlap"
    parameters: dict = field(repr=False, default_factory=dict)

    @classmethod
    def from_file(cls, path) -> "RunInfo":
        params = read_parameters(path)
        snap = load_snapshot(path, 0)
        coll = params.get("collision", {}) or {}
        model = str(coll.get("model", "unknown"))
        radii, masses = np.asarray(snap.radii), np.asarray(snap.masses)
        return cls(
            path=str(path),
            dimension=int(snap.box.shape[0]),
            particles=int(radii.shape[0]),
            box=np.asarray(snap.box, dtype=float),
            diameter=float(2.0 * radii.mean()),
            mass=float(masses.mean()),
            monodisperse=bool(np.ptp(radii) == 0 and np.ptp(masses) == 0),
            model=model,
            restitution=_float_or_none(coll.get("restitution")),
            prefactor=_float_or_none(coll.get("prefactor")),
            contact_end=str(coll.get("contact_end", "overlap")),
            parameters=params,
        )

    @property
    def volume(self) -> float:
        return float(np.prod(self.box))

    @property
    def number_density(self) -> float:
        return self.particles / self.volume

    @property
    def packing_fraction(self) -> float:
        return float(theory.packing_fraction(self.number_density, self.dimension, self.diameter))

    def gas(self, T0: float) -> Gas:
        """The run as a homogeneous gas of identical particles at temperature ``T0``."""
        model = self.model if self.model in ("elastic", "constant", "viscoelastic") else "elastic"
        return Gas(dimension=self.dimension, packing_fraction=self.packing_fraction, density=self.number_density,
                   sigma=self.diameter, mass=self.mass, temperature=float(T0), model=model,
                   restitution=self.restitution, prefactor=self.prefactor, end=self.contact_end)

    def prediction(self, T0: float) -> Prediction:
        """Kinetic theory for this run starting at temperature ``T0`` (at t = 0)."""
        d, n, s, m = self.dimension, self.number_density, self.diameter, self.mass
        omega0 = float(theory.collision_frequency(n, T0, d, s, m))
        ell = float(theory.mean_free_path(n, d, s))
        if self.model == "constant" and self.restitution is not None:
            eps = self.restitution
            a2 = float(theory.sonine_a2(eps, d))
            tau0 = float(theory.haff_tau0(eps, n, T0, d, s, m, a2=a2))
            lc = self.gas(T0).instability_length()
            return Prediction("haff", T0, tau0, 2.0, a2, omega0, ell, lc)
        if self.model == "viscoelastic" and self.prefactor is not None:
            tau0 = float(theory.viscoelastic_tau0(self.prefactor, n, T0, d, s, m))
            # instability length at T0 (it grows as T falls)
            lc = self.gas(T0).instability_length()
            tau2 = float(theory.viscoelastic_tau0(self.prefactor, n, T0, d, s, m, order=2))
            return Prediction("viscoelastic", T0, tau0, 5.0 / 3.0, 0.0, omega0, ell, lc, tau2)
        return Prediction("elastic", T0, math.inf, 0.0, 0.0, omega0, ell, math.inf)


def _float_or_none(v):
    try:
        return None if v is None else float(v)
    except (TypeError, ValueError):
        return None


@dataclass(frozen=True)
class CoolingHistory:
    """Observables of a run, sorted by time, duplicates removed (arrays (S,))."""

    time: np.ndarray
    temperature: np.ndarray
    collisions: np.ndarray
    collisions_per_particle: np.ndarray
    kinetic_energy: np.ndarray


def cooling_history(path, particles: int | None = None) -> CoolingHistory:
    """Temperature and collision count against time from ``observables/``."""
    obs = read_observables(path)
    if "temperature" not in obs:
        raise InputFileError(f"{path}: no observables/temperature in the file")
    _, t, T = obs["temperature"]
    coll = obs.get("collisions", (None, t, np.full(t.shape, -1)))[2]
    ke = obs.get("kinetic_energy", (None, t, np.full(t.shape, np.nan)))[2]
    t, idx = np.unique(np.asarray(t, dtype=float), return_index=True)
    T, coll, ke = np.asarray(T, float)[idx], np.asarray(coll)[idx], np.asarray(ke, float)[idx]
    ok = np.isfinite(T)
    if particles is None:
        particles = load_snapshot(path, 0).radii.shape[0]
    cpp = collisions_per_particle(np.where(coll >= 0, coll, np.nan), particles)
    return CoolingHistory(t[ok], T[ok], coll[ok], cpp[ok], ke[ok])


def snapshot_series(path, func: Callable, every: int = 1, indices=None) -> Iterator:
    """Apply ``func(snapshot)`` frame by frame; yields ``(snapshot.time, result)``.

    Parameters
    ----------
    every : int
        Use every ``every``-th frame.
    indices : sequence of int, optional
        Only these frame indices (overrides ``every``).
    """
    if indices is not None:
        for k in indices:
            snap = load_snapshot(path, int(k))
            yield snap.time, func(snap)
        return
    for snap in iter_snapshots(path):
        if snap.index % every == 0:
            yield snap.time, func(snap)


def sonine_history(path, every: int = 1):
    """Sonine coefficients a2, a3 of every (``every``-th) snapshot.

    Returns
    -------
    time, a2, a3 : arrays (F,)
    """
    rows = [(t, *r) for t, r in snapshot_series(path, lambda s: sonine_coefficients(s.velocities, s.masses), every)]
    if not rows:
        return np.empty(0), np.empty(0), np.empty(0)
    t, a2, a3 = (np.asarray(c) for c in zip(*rows))
    return t, a2, a3


@dataclass(frozen=True)
class CoolingAnalysis:
    """A run's cooling compared with theory (see :func:`analyze_cooling`)."""

    info: RunInfo
    history: CoolingHistory
    prediction: Prediction
    fit: CoolingFit | None  # exponent fixed to the theory's
    fit_free: CoolingFit | None  # exponent fitted
    sonine: tuple  # (time, a2, a3)
    t_offset: float  # time of the first sample (restarts), subtracted from every time

    @property
    def tau0_deviation(self) -> float:
        """Relative deviation of the fitted tau0 from the prediction."""
        if self.fit is None or not math.isfinite(self.prediction.tau0):
            return math.nan
        return self.fit.tau0 / self.prediction.tau0 - 1.0


def analyze_cooling(path, t_range=None, with_sonine: bool = True, sonine_every: int = 1) -> CoolingAnalysis:
    """Fit the cooling law of a run and compare it with kinetic theory.

    The fixed-exponent fit (2 for constant restitution, 5/3 viscoelastic) gives
    tau0; the free fit gives the exponent. Times are measured from the first
    observable sample (restarted runs start later than 0).

    Parameters
    ----------
    t_range : (t_min, t_max), optional
        Fit window, in the shifted time.
    with_sonine : bool
        Also compute a2, a3 from the snapshots (reads every frame once).
    """
    info = RunInfo.from_file(path)
    hist = cooling_history(path, info.particles)
    if hist.time.size == 0:
        raise InputFileError(f"{path}: no temperature samples")
    t0 = float(hist.time[0])
    t = hist.time - t0
    pred = info.prediction(float(hist.temperature[0]))
    fit = fit_free = None
    if pred.law != "elastic" and t.size >= 4:
        fit = fit_cooling_law(t, hist.temperature, exponent=pred.exponent, t_range=t_range, tau0_guess=pred.tau0)
        fit_free = fit_cooling_law(t, hist.temperature, exponent=None, t_range=t_range, tau0_guess=pred.tau0)
    son = sonine_history(path, sonine_every) if with_sonine else (np.empty(0),) * 3
    son = (son[0] - t0, son[1], son[2])
    return CoolingAnalysis(info, hist, pred, fit, fit_free, son, t0)
