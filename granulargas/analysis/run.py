"""File-level analysis of one run: the H5MD file -> histories, theory, fits.

Everything goes through the readers of :mod:`granulargas.io.h5md`
(``read_observables``, ``iter_snapshots``, ``load_snapshot``,
``read_parameters``) and reads snapshots one frame at a time, so files with
10^6 particles and many frames are fine.

A run is one of the kinds of :func:`run_kind`: ``"elastic"`` (energy conserved:
:mod:`granulargas.analysis.elastic`) or ``"cooling"`` (constant or viscoelastic
restitution, this module's :func:`analyze_cooling`);
:func:`granulargas.analysis.kinds.analyze_file` dispatches on it.

Cooling runs are compared with the kinetic theory of
:mod:`granulargas.theory.gas` (temperature and a2 together; :attr:`CoolingAnalysis.theory`),
started at the first sample's temperature: for a constant restitution the best
reference of the homogeneous cooling state (:func:`granulargas.theory.hcs.hcs_reference`:
the Enskog-Boltzmann DSMC table, first Sonine outside it), for the viscoelastic law the
moment equations with the exact eps(g) (first Sonine). Every report names the theory
it takes a ratio against. The closed-form laws (Haff's ``T0/(1+t/tau0)^2`` with the
reference's cooling rate, the leading-order viscoelastic ``T0 (1+t/tau0)^(-5/3)``)
stay as references (:class:`Prediction`) and give the exponents of the fits.
Both the run and the theory curve are fitted with the same law on the same
samples, so fitted tau0 and exponent compare like with like.

a2 is averaged over a window of snapshots where the comparison is like with like
(:attr:`CoolingAnalysis.a2_window`): for a constant restitution the snapshots after a2 has
relaxed from the start (:func:`granulargas.theory.gas.relaxation_collisions`, counted in the
run's own collisions per particle), compared with the reference's stationary a2; for the
viscoelastic law (no stationary a2) the later half of the snapshots, compared with the
theory's a2 averaged over the same snapshots. The error is the standard error of block means
(:func:`granulargas.analysis.cooling.block_mean`, the one error estimate of the analysis).

The theory is that of identical particles: for a polydisperse run the mean
diameter and the mass of a particle of that diameter are used and
:attr:`RunInfo.monodisperse` is False (the report says so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterator

import numpy as np

from granulargas import theory
from granulargas.analysis.cooling import (
    BLOCKS,
    CoolingFit,
    block_mean,
    collisions_per_particle,
    fit_cooling_law,
    sonine_coefficients,
)
from granulargas.contact.material import damping_from_prefactor
from granulargas.errors import InputFileError
from granulargas.io.h5md import iter_snapshots, load_snapshot, read_observables, read_parameters
from granulargas.io.scene import Scene
from granulargas.theory.gas import CoolingCurve, Gas, cooling_curve, hcs_of, pressure_factor, relaxation_collisions
from granulargas.theory.hcs import FIRST_SONINE

__all__ = [
    "RunInfo",
    "run_kind",
    "Prediction",
    "CoolingHistory",
    "cooling_history",
    "PressureSamples",
    "pressure_samples",
    "sonine_history",
    "snapshot_series",
    "CoolingAnalysis",
    "analyze_cooling",
    "theory_name",
    "FINAL_FRACTION",
    "RELAXED_FRACTION",
    "A2_ERROR_METHOD",
]

#: T_ratio_final averages T / T_theory over this last fraction of the observation time span
FINAL_FRACTION = 0.1
#: a2 counts as relaxed once it has come within this fraction of the way from its start to the HCS
RELAXED_FRACTION = 0.01
#: how the error of a mean over snapshots is estimated (reports, JSON)
A2_ERROR_METHOD = f"standard error of {BLOCKS} block means"


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
    name: str = ""  # what the law is, with its a2 and cooling rate (reports, legends)

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
    solid_fraction: float = math.nan  # sum of the particle volumes over the box volume
    boundary: tuple = ()  # "periodic" or "wall" per axis
    method: str = "edmd"  # "dsmc": a homogeneous gas without positions (velocities only)
    scene: Scene = field(default_factory=Scene)  # the kind of run: which comparisons apply

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
            mass=_mean_particle_mass(radii, masses, int(snap.box.shape[0])),
            monodisperse=bool(np.ptp(radii) == 0 and np.ptp(masses) == 0),
            model=model,
            restitution=_float_or_none(coll.get("restitution")),
            prefactor=_float_or_none(coll.get("prefactor")),
            contact_end=str(coll.get("contact_end", "overlap")),
            parameters=params,
            solid_fraction=float(np.sum(theory.particle_volume(2.0 * radii, int(snap.box.shape[0])))
                                 / float(np.prod(snap.box))),
            boundary=tuple(snap.boundary) or ("periodic",) * int(snap.box.shape[0]),
            method=str(params.get("method", "edmd")),
            scene=Scene.from_parameters(params, int(snap.box.shape[0]), tuple(snap.boundary), radii, masses,
                                        snap.contact_until is not None),
        )

    @property
    def damping(self) -> float | None:
        """The run's ``damping`` (a viscoelastic run): beta at unit impact speed for two
        reference particles, the one name every output gives the parameter (the
        ``[collision.material]`` route's equivalent); None for other models."""
        if self.model != "viscoelastic" or self.prefactor is None:
            return None
        return float(damping_from_prefactor(self.prefactor))

    @property
    def walls(self) -> bool:
        """Whether the run has walls on some axis."""
        return "wall" in self.boundary

    @property
    def volume(self) -> float:
        return float(np.prod(self.box))

    @property
    def number_density(self) -> float:
        return self.particles / self.volume

    @property
    def packing_fraction(self) -> float:
        """Packing fraction of the theory's gas: identical particles of the mean diameter at
        the run's number density (the run's own, :attr:`solid_fraction`, if monodisperse)."""
        return float(theory.packing_fraction(self.number_density, self.dimension, self.diameter))

    @property
    def kind(self) -> str:
        """:func:`run_kind` of this run."""
        return run_kind(self)

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
            gas = self.gas(T0)
            ref = hcs_of(gas)
            if eps < 1.0:
                # Haff's law with the reference's cooling rate zeta_M c_zeta (theory.hcs, (H1))
                tau0 = 2.0 / (float(theory.enskog_cooling_rate(eps, n, T0, d, s, m, a2=0.0)) * ref.zeta_factor)
            else:
                tau0 = math.inf
            return Prediction("haff", T0, tau0, 2.0, ref.a2, omega0 * ref.omega_factor, ell, gas.instability_length(),
                              name=f"Haff 1983 with the cooling rate of the {ref.name}")
        if self.model == "viscoelastic" and self.prefactor is not None:
            tau0 = float(theory.viscoelastic_tau0(self.prefactor, n, T0, d, s, m))
            # instability length at T0 (it grows as T falls)
            lc = self.gas(T0).instability_length()
            tau2 = float(theory.viscoelastic_tau0(self.prefactor, n, T0, d, s, m, order=2))
            return Prediction("viscoelastic", T0, tau0, 5.0 / 3.0, 0.0, omega0, ell, lc, tau2,
                              name="leading order in the damping (Schwager & Pöschel 1998), a2 = 0")
        return Prediction("elastic", T0, math.inf, 0.0, 0.0, omega0, ell, math.inf, name="elastic: constant T")


def _mean_particle_mass(radii, masses, dim) -> float:
    """Mass of a particle of the mean diameter, as :func:`granulargas.run.prepare.mean_particle`
    gives it for the config: the common mass, or (masses proportional to the particle volumes,
    a material density) the density times the volume of the mean diameter; else the mean mass."""
    if np.ptp(masses) == 0:
        return float(masses[0])
    vol = theory.particle_volume(2.0 * radii, dim)
    rho = masses / vol
    if np.ptp(rho) <= 1e-9 * rho.mean():
        return float(rho.mean() * theory.particle_volume(2.0 * radii.mean(), dim))
    return float(masses.mean())


def run_kind(info: RunInfo) -> str:
    """``"shear"`` (uniform shear flow), ``"vibrated"`` (gravity, thermal or vibrating walls;
    rough particles too), ``"rough"`` (rough particles, cooling or driven:
    :mod:`granulargas.analysis.rough`), ``"driven"`` (white-noise driving), ``"elastic"``
    (energy conserved: eps = 1 or damping 0), ``"cooling"``, or ``"unknown"`` (the file does
    not record its collision model, :class:`granulargas.io.scene.Scene`)."""
    if info.scene.rough and info.scene.model != "unknown" and info.scene.kind != "vibrated":
        return "rough"
    return info.scene.kind


def theory_name(info: RunInfo) -> str:
    """What the kinetic theory compared with a run is (reports, JSON, legends)."""
    d = info.dimension
    eos = theory.eos_name(d)
    if info.kind == "elastic":
        return f"Enskog, {eos} equation of state"
    if info.kind == "driven":
        return "Enskog, driven steady state (zeta(T) T = H)"
    if info.kind == "shear":
        return "Grad solution of uniform shear flow (theory.shear)"
    if info.model == "viscoelastic":
        return (f"moment equations of the Enskog-Boltzmann equation, first Sonine, exact eps(g) "
                f"(Brilliantov & Pöschel 2000); chi from {eos}")
    ref = hcs_of(info.gas(1.0))
    if ref.name == FIRST_SONINE:
        return f"Enskog-Boltzmann, constant eps: moment equations, {FIRST_SONINE}; chi from {eos}"
    return (f"Enskog-Boltzmann, constant eps: cooling rate and a2 of the {ref.name}, relaxed from the start; "
            f"chi from {eos}")


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
    pressure: np.ndarray | None = None  # mean over the interval since the previous non-NaN sample


def cooling_history(path, particles: int | None = None) -> CoolingHistory:
    """Temperature, collision count, kinetic energy and pressure against time from ``observables/``."""
    obs = read_observables(path)
    if "temperature" not in obs:
        raise InputFileError(f"{path}: no observables/temperature in the file")
    _, t, T = obs["temperature"]
    n = t.shape[0]

    def column(name, fill, dtype=float):
        value = obs.get(name, (None, t, np.full(n, fill)))[2]
        return np.asarray(value, dtype=dtype)[:n] if len(value) >= n else np.full(n, fill, dtype=dtype)

    coll, ke, p = column("collisions", -1, np.int64), column("kinetic_energy", np.nan), column("pressure", np.nan)
    t, idx = np.unique(np.asarray(t, dtype=float), return_index=True)
    T, coll, ke, p = np.asarray(T, float)[idx], coll[idx], ke[idx], p[idx]
    ok = np.isfinite(T)
    if particles is None:
        particles = load_snapshot(path, 0).radii.shape[0]
    cpp = collisions_per_particle(np.where(coll >= 0, coll, np.nan), particles)
    return CoolingHistory(t[ok], T[ok], coll[ok], cpp[ok], ke[ok], p[ok])


@dataclass(frozen=True)
class PressureSamples:
    """Pressure windows of a run: each the mean over ``[start, end]`` (arrays (P,)).

    ``temperature`` is the time average of T over the window (T log-linear between
    samples), so ``Z = P / (n temperature)`` is the compressibility factor of the window.
    """

    start: np.ndarray
    end: np.ndarray
    pressure: np.ndarray
    temperature: np.ndarray
    Z: np.ndarray


def _mean_temperature(t, T, a, b):
    """Time average of T over [a, b], T log-linear between the samples (t, T)."""
    inside = (t > a) & (t < b)
    tt = np.concatenate([[a], t[inside], [b]])
    lT = np.interp(tt, t, np.log(T))
    dt, T0, T1 = np.diff(tt), np.exp(lT[:-1]), np.exp(lT[1:])
    with np.errstate(divide="ignore", invalid="ignore"):
        seg = np.where(np.abs(T1 - T0) > 1e-12 * T0, (T1 - T0) / np.log(T1 / T0), 0.5 * (T0 + T1))
    return float((seg * dt).sum() / (b - a))


def pressure_samples(history: CoolingHistory, density: float) -> PressureSamples:
    """The run's pressure windows with their mean temperature and Z (number density ``density``)."""
    p = history.pressure if history.pressure is not None else np.full(history.time.shape, np.nan)
    idx = np.flatnonzero(np.isfinite(p))
    if idx.size == 0:
        e = np.empty(0)
        return PressureSamples(e, e, e, e, e)
    t, T = history.time, history.temperature
    # a window runs from the previous pressure sample (or the run's first sample) to this one
    starts = np.concatenate([[t[0]], t[idx[:-1]]])
    ends = t[idx]
    keep = ends > starts
    starts, ends, pres = starts[keep], ends[keep], p[idx][keep]
    Tm = np.array([_mean_temperature(t, T, a, b) for a, b in zip(starts, ends)])
    return PressureSamples(starts, ends, pres, Tm, pres / (density * Tm))


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
    """A run's cooling compared with kinetic theory (see :func:`analyze_cooling`).

    Times in the arrays are measured from the first observable sample
    (``t_offset``, non-zero for a restarted run's file); reports add it back.
    """

    info: RunInfo
    history: CoolingHistory
    prediction: Prediction  # closed-form reference law
    fit: CoolingFit | None  # exponent fixed to the closed-form law's
    fit_free: CoolingFit | None  # exponent fitted
    sonine: tuple  # (time, a2, a3)
    t_offset: float  # time of the first sample (restarts), subtracted from every time
    theory: CoolingCurve | None = None  # kinetic theory, T and a2 (theory.gas)
    theory_fit: CoolingFit | None = None  # the fixed-exponent law fitted to the theory curve
    theory_fit_free: CoolingFit | None = None
    pressure: PressureSamples | None = None
    kind: str = "cooling"

    @property
    def time(self) -> np.ndarray:
        """Sample times since the first sample, (S,)."""
        return self.history.time - self.t_offset

    @property
    def theory_name(self) -> str:
        return theory_name(self.info)

    @property
    def temperature_theory(self) -> np.ndarray:
        """Kinetic-theory T at the sample times (closed form if no curve), (S,)."""
        if self.theory is None:
            return self.prediction.temperature(self.time)
        return self.theory.temperature_at(self.time)

    @property
    def ratio(self) -> np.ndarray:
        """T / T_theory at the sample times, (S,)."""
        return self.history.temperature / self.temperature_theory

    def ratio_mean(self, t_from: float) -> float:
        """Mean of T / T_theory over the samples with (shifted) time >= t_from."""
        sel = self.time >= t_from
        return float(np.mean(self.ratio[sel])) if np.any(sel) else math.nan

    @property
    def T_ratio_final(self) -> float:
        """Mean T / T_theory over the last :data:`FINAL_FRACTION` of the observation time span."""
        t = self.time
        return self.ratio_mean(t[-1] - FINAL_FRACTION * (t[-1] - t[0]))

    @property
    def T_ratio_last_decade(self) -> float:
        """Mean T / T_theory over the last decade of time, t >= t_final / 10."""
        return self.ratio_mean(self.time[-1] / 10.0)

    @property
    def tau0_deviation(self) -> float:
        """Relative deviation of the fitted tau0 from the closed-form law's tau0."""
        if self.fit is None or not math.isfinite(self.prediction.tau0):
            return math.nan
        return self.fit.tau0 / self.prediction.tau0 - 1.0

    @property
    def hcs(self):
        """The HCS reference of a constant-restitution run (:func:`granulargas.theory.gas.hcs_of`), else None."""
        if self.kind != "cooling" or self.info.model != "constant":
            return None
        return hcs_of(self.info.gas(self.prediction.T0))

    @property
    def relaxation_collisions(self) -> float:
        """Collisions per particle a2 needs to relax from the start (:data:`RELAXED_FRACTION` of the way;
        :func:`granulargas.theory.gas.relaxation_collisions`); nan unless constant restitution."""
        if self.hcs is None:
            return math.nan
        return relaxation_collisions(self.info.gas(self.prediction.T0), RELAXED_FRACTION)

    @property
    def a2_window(self) -> np.ndarray:
        """Which snapshots the a2 mean uses (bool (F,), module doc): constant restitution: those at
        or after :attr:`relaxation_collisions` (the run's own collision count); otherwise the later
        half of the snapshots (in their order; log-spaced snapshots make that the later half in log
        time). Never the first snapshot of a fresh run (the initial state)."""
        ts = self.sonine[0]
        if self.hcs is not None:
            s = np.interp(ts, self.time, self.history.collisions_per_particle - self.history.collisions_per_particle[0])
            sel = s >= self.relaxation_collisions
        else:
            sel = np.arange(ts.size) >= ts.size // 2
        return sel & (ts > 0)

    @property
    def a2_late(self):
        """(mean, standard error, count) of a2 over :attr:`a2_window` (error: :data:`A2_ERROR_METHOD`)."""
        ts, a2, _ = self.sonine
        sel = self.a2_window
        if not np.any(sel):
            return math.nan, math.nan, 0
        mean, err = block_mean(a2[sel])
        return mean, err, int(sel.sum())

    @property
    def a2_reference(self):
        """(value, error, name) that the a2 mean is compared with: the HCS reference's a2 (constant
        restitution), else the theory's a2 averaged over the same snapshots (:attr:`a2_window`)."""
        ref = self.hcs
        if ref is not None:
            return ref.a2, ref.a2_error, ref.name
        ts = self.sonine[0]
        sel = self.a2_window
        if self.theory is None or not np.any(sel):
            return math.nan, math.nan, ""
        # the theory's own error is that of its approximation (first Sonine), not a number here
        return float(np.mean(self.theory.a2_at(ts[sel]))), math.nan, f"{self.theory.name}, mean over the same snapshots"

    @property
    def Z(self) -> float:
        """Mean measured compressibility factor over the pressure windows (nan if none)."""
        if self.pressure is None or self.pressure.Z.size == 0:
            return math.nan
        return float(np.mean(self.pressure.Z))

    @property
    def Z_theory(self) -> float:
        """Eq. (G4) of theory.gas averaged over the same windows (at the theory's a2)."""
        if self.pressure is None or self.pressure.Z.size == 0 or self.theory is None:
            return math.nan
        mid = 0.5 * (self.pressure.start + self.pressure.end) - self.t_offset
        from granulargas.theory.gas import compressibility_factor

        z = compressibility_factor(self.info.gas(self.prediction.T0), self.pressure.temperature,
                                   self.theory.a2_at(mid))
        return float(np.mean(z))

    def summary(self) -> dict:
        """The numbers of the analysis as a flat, JSON-ready dict (``granulargas analyze --json``)."""
        info, h, p = self.info, self.history, self.prediction
        a2_mean, a2_err, a2_count = self.a2_late if self.sonine[0].size else (math.nan, math.nan, 0)
        a2_ref, a2_ref_err, a2_ref_name = self.a2_reference if self.sonine[0].size else (math.nan, math.nan, "")
        if self.hcs is not None:
            a2_final = self.hcs.a2
        else:
            a2_final = float(self.theory.a2_at(self.time[-1])) if self.theory is not None else None
        window = self.sonine[0][self.a2_window] + self.t_offset if self.sonine[0].size else np.empty(0)
        T_th = self.temperature_theory
        return _clean({
            **run_identity(info, self.kind),
            "restitution": info.restitution,
            "damping": info.damping,
            **history_span(h),
            "theory": self.theory_name,
            "T_theory_final": float(T_th[-1]),
            "T_ratio_final": self.T_ratio_final,
            "T_ratio_last_decade": self.T_ratio_last_decade,
            "tau0_fit": self.fit.tau0 if self.fit else None,
            "tau0_fit_error": self.fit.tau0_err if self.fit else None,
            "tau0_fit_free": self.fit_free.tau0 if self.fit_free else None,
            "tau0_fit_free_error": self.fit_free.tau0_err if self.fit_free else None,
            "tau0_theory": self.theory_fit.tau0 if self.theory_fit else p.tau0,
            "tau0_closed_form": p.tau0,
            "exponent_fit": -self.fit_free.exponent if self.fit_free else None,
            "exponent_fit_error": self.fit_free.exponent_err if self.fit_free else None,
            "exponent_theory": -self.theory_fit_free.exponent if self.theory_fit_free else -p.exponent,
            "exponent_closed_form": -p.exponent,
            "a2_mean": a2_mean,
            "a2_error": a2_err,
            "a2_error_method": A2_ERROR_METHOD,
            "a2_snapshots": a2_count,
            "a2_from": float(window[0]) if window.size else None,
            "a2_to": float(window[-1]) if window.size else None,
            "a2_theory": a2_ref,
            "a2_theory_error": a2_ref_err,
            "a2_theory_name": a2_ref_name,
            "a2_theory_final": a2_final,
            "a2_first_sonine": float(theory.sonine_a2(info.restitution, info.dimension)) if self.hcs is not None else None,
            "relaxation_collisions": self.relaxation_collisions,
            "closed_form": p.name,
            "Z": self.Z,
            "Z_theory": self.Z_theory,
            "instability_length": p.instability_length,
            "box": float(info.box.max()) if info.scene.space else None,  # a DSMC's box only sets the density
        })


def run_identity(info: RunInfo, kind: str) -> dict:
    """The first keys of every ``analyze --json`` summary: the file and the gas it holds."""
    return {"file": info.path, "kind": kind, "model": info.model, "dimension": info.dimension,
            "particles": info.particles, "packing_fraction": info.packing_fraction,
            "monodisperse": info.monodisperse, "scene": {**info.scene.as_dict(), "text": info.scene.describe()}}


def history_span(h: CoolingHistory) -> dict:
    """Start and end of a run's observables (times, temperatures, collisions per particle)."""
    return {"t_start": float(h.time[0]), "t_final": float(h.time[-1]), "T_initial": float(h.temperature[0]),
            "T_final": float(h.temperature[-1]), "collisions_per_particle": float(h.collisions_per_particle[-1])}


def _clean(d: dict) -> dict:
    """Non-finite floats -> None (JSON null)."""
    out = {}
    for k, v in d.items():
        if isinstance(v, (float, np.floating)):
            v = float(v) if math.isfinite(v) else None
        elif isinstance(v, np.integer):
            v = int(v)
        elif isinstance(v, np.bool_):
            v = bool(v)
        out[k] = v
    return out


def _initial_a2(path, t0: float) -> float:
    """a2 the theory starts from: 0 for a fresh run (Maxwellian start), else the a2 of
    the snapshot at the first sample time (a restarted run)."""
    if t0 == 0.0:
        return 0.0
    snap = load_snapshot(path, 0)
    if abs(snap.time - t0) > 1e-9 * max(abs(t0), 1.0):
        return 0.0
    return sonine_coefficients(snap.velocities, snap.masses)[0]


def analyze_cooling(path, t_range=None, with_sonine: bool = True, sonine_every: int = 1,
                    with_theory: bool = True) -> CoolingAnalysis:
    """Fit the cooling law of a run and compare it with kinetic theory.

    The kinetic theory (:func:`granulargas.theory.gas.cooling_curve`) starts at the
    first sample's temperature. The fixed-exponent fit (2 for constant restitution,
    5/3 viscoelastic) gives tau0, the free fit the exponent; both fits are applied to
    the run and to the theory curve on the same samples. Times are measured from the
    first observable sample (restarted runs start later than 0).

    Parameters
    ----------
    t_range : (t_min, t_max), optional
        Fit window, in the shifted time.
    with_sonine : bool
        Also compute a2, a3 from the snapshots (reads every frame once).
    with_theory : bool
        Integrate the kinetic theory (a second or so); otherwise only the closed forms.
    """
    info = RunInfo.from_file(path)
    hist = cooling_history(path, info.particles)
    if hist.time.size == 0:
        raise InputFileError(f"{path}: no temperature samples")
    t0 = float(hist.time[0])
    t = hist.time - t0
    T0 = float(hist.temperature[0])
    pred = info.prediction(T0)
    curve = None
    if with_theory and info.kind == "cooling" and t[-1] > 0:
        curve = cooling_curve(info.gas(T0), t_end=float(t[-1]), t_min_ratio=None, a2_initial=_initial_a2(path, t0))
    fit = fit_free = tfit = tfit_free = None
    if pred.law != "elastic" and t.size >= 4:
        fit = fit_cooling_law(t, hist.temperature, exponent=pred.exponent, t_range=t_range, tau0_guess=pred.tau0)
        fit_free = fit_cooling_law(t, hist.temperature, exponent=None, t_range=t_range, tau0_guess=pred.tau0)
        if curve is not None:
            T_th = curve.temperature_at(t)
            tfit = fit_cooling_law(t, T_th, exponent=pred.exponent, t_range=t_range, tau0_guess=pred.tau0)
            tfit_free = fit_cooling_law(t, T_th, exponent=None, t_range=t_range, tau0_guess=pred.tau0)
    son = sonine_history(path, sonine_every) if with_sonine else (np.empty(0),) * 3
    son = (son[0] - t0, son[1], son[2])
    return CoolingAnalysis(info, hist, pred, fit, fit_free, son, t0, curve, tfit, tfit_free,
                           pressure_samples(hist, info.number_density))
