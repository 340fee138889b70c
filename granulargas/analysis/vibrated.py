"""A gas under gravity or on vibrating walls: profiles along an axis, centre of mass, energy balance.

A vibrated bed is homogeneous along the floor and not across it: the number density, the
granular temperature and the shape of the velocity distribution depend on the height.
What a run shows:

* **layer profiles** along an axis (the axis of gravity, or the one a wall vibrates on),
  accumulated over snapshots (:class:`LayerAccumulator`): the number density n(z), the
  temperature T(z) = m <|c|^2> / d with c the velocity less the layer's mean (and its
  components along and across the axis), and the central moments of each velocity
  component, whose excess kurtosis <c^4>/<c^2>^2 - 3 is 0 for a Maxwellian (standard
  error sqrt(24 / n) from n samples);
* the **centre of mass** along the axis against time, and its mean in the steady state;
* the **energy balance** of the steady state: the power the walls put in (the slope of
  the cumulative ``wall_work``) against the power dissipated in collisions (the slope of
  ``dissipated_energy``), each the mean over blocks of the second half of the run with
  its standard error (:func:`energy_balance`);
* for an elastic gas on a thermal wall, the **hydrostatic profile** of the same column
  (:func:`granulargas.theory.vibrated.hydrostatic_density`) beside the measured n(z).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas.analysis.elastic import block_mean
from granulargas.analysis.run import run_identity

__all__ = ["LayerAccumulator", "LayerProfile", "centre_of_mass", "energy_balance", "EnergyBalance", "steady_mean",
           "VibratedAnalysis", "analyze_vibrated"]


@dataclass(frozen=True)
class LayerProfile:
    """Profiles along ``axis`` in the layers between ``edges`` (arrays (B,)), from ``frames`` snapshots.

    ``density``: particles per unit volume (area in 2D); ``temperature``: m <|c|^2> / d;
    ``t_along``, ``t_across``: m <c_a^2> along the axis and the mean over the other axes;
    ``kurtosis``: the excess kurtosis of each velocity component (B, d); ``counts``:
    samples per layer (particle-frames).
    """

    axis: int
    edges: np.ndarray
    density: np.ndarray
    temperature: np.ndarray
    t_along: np.ndarray
    t_across: np.ndarray
    kurtosis: np.ndarray
    counts: np.ndarray
    frames: int

    @property
    def centres(self) -> np.ndarray:
        return 0.5 * (self.edges[1:] + self.edges[:-1])

    @property
    def kurtosis_error(self) -> np.ndarray:
        """Standard error of the excess kurtosis of a Gaussian sample of the layer's size."""
        with np.errstate(divide="ignore"):
            return np.sqrt(24.0 / self.counts)


class LayerAccumulator:
    """Sums of the layers along ``axis`` over snapshots; :meth:`profile` gives the :class:`LayerProfile`.

    ``edges`` (B + 1,) bin edges along the axis; ``box`` (d,) the box sides (the layers'
    cross-section is the product of the other sides). Particles outside the edges are
    left out.
    """

    def __init__(self, axis: int, edges, box):
        self.axis = int(axis)
        self.edges = np.asarray(edges, dtype=float)
        self.box = np.asarray(box, dtype=float)
        d = self.box.shape[0]
        b = self.edges.shape[0] - 1
        self.frames = 0
        self.n = np.zeros(b)
        self.m = np.zeros(b)
        self.s1 = np.zeros((b, d))  # sum v
        self.s2 = np.zeros((b, d))  # sum v^2
        self.s3 = np.zeros((b, d))
        self.s4 = np.zeros((b, d))
        self.mv = np.zeros((b, d))  # sum m v
        self.mv2 = np.zeros((b, d))  # sum m v^2

    def add(self, positions, velocities, masses):
        """Add one snapshot (positions (N, d), velocities (N, d), masses (N,))."""
        z = np.asarray(positions, dtype=float)[:, self.axis]
        v = np.asarray(velocities, dtype=float)
        m = np.broadcast_to(np.asarray(masses, dtype=float), z.shape)
        k = np.searchsorted(self.edges, z, side="right") - 1
        ok = (k >= 0) & (k < self.n.shape[0])
        k, v, m = k[ok], v[ok], m[ok]
        np.add.at(self.n, k, 1.0)
        np.add.at(self.m, k, m)
        for p, arr in ((1, self.s1), (2, self.s2), (3, self.s3), (4, self.s4)):
            np.add.at(arr, k, v**p)
        np.add.at(self.mv, k, m[:, None] * v)
        np.add.at(self.mv2, k, m[:, None] * v * v)
        self.frames += 1
        return self

    def profile(self) -> LayerProfile:
        d = self.box.shape[0]
        width = np.diff(self.edges)
        section = float(np.prod(np.delete(self.box, self.axis)))
        frames = max(self.frames, 1)
        with np.errstate(invalid="ignore", divide="ignore"):
            density = self.n / (frames * width * section)
            # m <c_a^2> per component: (sum m v^2 - (sum m v)^2 / sum m) / n
            comp = (self.mv2 - self.mv**2 / self.m[:, None]) / self.n[:, None]
            mean = self.s1 / self.n[:, None]
            mu2 = self.s2 / self.n[:, None] - mean**2
            mu4 = (self.s4 / self.n[:, None] - 4 * mean * self.s3 / self.n[:, None]
                   + 6 * mean**2 * self.s2 / self.n[:, None] - 3 * mean**4)
            kurt = mu4 / mu2**2 - 3.0
        others = [a for a in range(d) if a != self.axis]
        return LayerProfile(self.axis, self.edges.copy(), density, comp.sum(axis=1) / d, comp[:, self.axis],
                            comp[:, others].mean(axis=1), kurt, self.n.copy(), self.frames)


def centre_of_mass(positions, masses, axis: int) -> float:
    """Height of the centre of mass along ``axis``."""
    z = np.asarray(positions, dtype=float)[:, axis]
    m = np.broadcast_to(np.asarray(masses, dtype=float), z.shape)
    return float(np.sum(m * z) / np.sum(m))


@dataclass(frozen=True)
class EnergyBalance:
    """Power put in by the walls and dissipated in collisions in the steady state (mean, standard
    error), from ``t_from`` on."""

    power_in: float
    power_in_error: float
    dissipation: float
    dissipation_error: float
    t_from: float

    @property
    def ratio(self) -> float:
        """Power dissipated / power put in (1 in a steady state)."""
        return self.dissipation / self.power_in if self.power_in else math.nan

    @property
    def ratio_error(self) -> float:
        r = self.ratio
        return abs(r) * math.hypot(self.power_in_error / self.power_in, self.dissipation_error / self.dissipation) \
            if self.power_in and self.dissipation else math.nan


def energy_balance(time, wall_work, dissipated, t_from: float | None = None, blocks: int = 10) -> EnergyBalance:
    """Mean powers from the cumulative ``wall_work`` and ``dissipated`` energy sampled at ``time``:
    the increments over ``blocks`` equal blocks of samples from ``t_from`` (default: the second
    half of the run) divided by their durations; the standard error from the spread of the
    blocks (the mean power is the total increment over the total time)."""
    t = np.asarray(time, dtype=float)
    w = np.asarray(wall_work, dtype=float)
    q = np.asarray(dissipated, dtype=float)
    t_from = 0.5 * (t[0] + t[-1]) if t_from is None else float(t_from)
    sel = np.flatnonzero(t >= t_from)
    if sel.size < 3:
        return EnergyBalance(math.nan, math.nan, math.nan, math.nan, t_from)
    k = min(blocks, sel.size - 1)
    cuts = np.linspace(sel[0], sel[-1], k + 1).round().astype(int)
    dt = np.diff(t[cuts])
    pin = np.diff(w[cuts]) / dt
    pout = np.diff(q[cuts]) / dt
    span = t[cuts[-1]] - t[cuts[0]]

    def mean_err(p, total):
        return total / span, (float(np.std(p, ddof=1) / math.sqrt(k)) if k > 1 else math.nan)

    a, ea = mean_err(pin, w[cuts[-1]] - w[cuts[0]])
    b, eb = mean_err(pout, q[cuts[-1]] - q[cuts[0]])
    return EnergyBalance(a, ea, b, eb, t_from)


def steady_mean(time, values, t_from: float | None = None):
    """(mean, standard error) of a sampled series from ``t_from`` on (default: the second half),
    by block means."""
    t = np.asarray(time, dtype=float)
    t_from = 0.5 * (t[0] + t[-1]) if t_from is None else float(t_from)
    return block_mean(np.asarray(values, dtype=float)[t >= t_from])


# ------------------------------------------------------------------ a run's file
#: layers of the profiles
LAYERS = 40


@dataclass(frozen=True)
class VibratedAnalysis:
    """A run under gravity or with thermal or vibrating walls (see :func:`analyze_vibrated`)."""

    info: object  # granulargas.analysis.run.RunInfo
    time: np.ndarray  # observables' times
    temperature: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    dissipated: np.ndarray
    wall_work: np.ndarray
    t_from: float  # the steady state (averages) from here on
    axis: int  # the axis of the profiles
    gravity: tuple | None
    walls: dict  # side -> wall parameters (the file's parameters/walls)
    profile: LayerProfile
    com_time: np.ndarray
    com: np.ndarray  # centre of mass along ``axis`` at the snapshots
    balance: EnergyBalance
    kind: str = "vibrated"

    @property
    def theory_name(self) -> str:
        if self.hydrostatic is not None:
            return "hydrostatic equilibrium dp/dz = -m g n, p = n T_w Z(n) (local density)"
        if self.bed is not None:
            return "dilute vibrated bed at leading order (Kumaran 1998; McNamara & Luding 1998)"
        return "energy balance of the steady state (power in = power dissipated)"

    @property
    def g_axis(self) -> float:
        """|g| along the axis of the profiles (0 without gravity)."""
        return 0.0 if self.gravity is None else abs(self.gravity[self.axis])

    @property
    def column(self) -> float:
        """Particles per unit floor area (length in 2D) across ``axis``."""
        return self.info.particles / float(np.prod(np.delete(self.info.box, self.axis)))

    @property
    def elastic(self) -> bool:
        return self.info.model == "elastic" or (self.info.model == "constant" and self.info.restitution == 1.0)

    @property
    def thermal_floor(self):
        """T_w of a thermal wall the gas rests on under gravity (None otherwise)."""
        if self.gravity is None or self.g_axis == 0:
            return None
        down = 0 if self.gravity[self.axis] < 0 else 1
        w = self.walls.get("xyz"[self.axis] + ("_low", "_high")[down])
        return float(w["temperature"]) if w and w.get("kind") == "thermal" else None

    @property
    def hydrostatic(self):
        """The hydrostatic n(z) at the layer centres for an elastic gas on a thermal floor (None otherwise)."""
        tw = self.thermal_floor
        if tw is None or not self.elastic or any(w.get("kind") == "vibrating" for w in self.walls.values()):
            return None
        from granulargas.theory import vibrated as V

        L = float(self.info.box[self.axis])
        R = 0.5 * self.info.diameter
        z = self.profile.centres
        if self.gravity[self.axis] > 0:
            z = L - z  # measured from the floor
        return V.hydrostatic_density(z, self.column, tw, self.g_axis, self.info.mass, self.info.diameter,
                                     self.info.dimension, bottom=R, top=L - R)

    @property
    def bed(self):
        """(leading-order T, its small parameters) of a vibrating floor under gravity with a constant e < 1."""
        if self.gravity is None or self.g_axis == 0 or self.info.model != "constant" or not (
                self.info.restitution is not None and self.info.restitution < 1.0):
            return None
        down = 0 if self.gravity[self.axis] < 0 else 1
        w = self.walls.get("xyz"[self.axis] + ("_low", "_high")[down])
        if not w or w.get("kind") != "vibrating":
            return None
        from granulargas.engine.walls import Wall
        from granulargas.theory import vibrated as V

        wall = Wall.vibrating(w["amplitude"], w["frequency"], w["waveform"], w["phase"])
        return V.bed_parameters(self.column, self.info.restitution, wall.amplitude, wall.mean_square_velocity,
                                self.g_axis, self.info.dimension, self.info.diameter, self.info.mass)

    @property
    def steady(self) -> np.ndarray:
        return self.time >= self.t_from

    def summary(self) -> dict:
        T, Te = block_mean(self.temperature[self.steady])
        com, come = block_mean(self.com[self.com_time >= self.t_from]) if self.com.size else (math.nan, math.nan)
        b = self.balance
        out = {
            **run_identity(self.info, self.kind), "t_final": float(self.time[-1]), "steady_from": self.t_from,
            "axis": "xyz"[self.axis], "gravity": list(self.gravity) if self.gravity else None,
            "T_steady": T, "T_steady_error": Te, "centre_of_mass": com, "centre_of_mass_error": come,
            "power_in": b.power_in, "power_in_error": b.power_in_error, "dissipation": b.dissipation,
            "dissipation_error": b.dissipation_error, "balance_ratio": b.ratio, "balance_ratio_error": b.ratio_error,
            "theory": self.theory_name,
        }
        bed = self.bed
        if bed is not None:
            out.update(T_bed_theory=bed["temperature"], bed_dissipation=bed["dissipation"],
                       bed_plate_speed=bed["plate_speed"], bed_amplitude=bed["amplitude"],
                       bed_floor_packing=bed["floor_packing"])
        if self.thermal_floor is not None:
            out["T_wall"] = self.thermal_floor
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in out.items()}


def _scene_axis(gravity, walls: dict, boundary) -> int:
    """The axis of the profiles: gravity's (its largest component), else the axis of a vibrating
    or thermal wall, else the first wall axis."""
    if gravity is not None and any(gravity):
        return int(np.argmax(np.abs(gravity)))
    for name, w in walls.items():
        if w.get("kind") in ("vibrating", "thermal"):
            return "xyz".index(name[0])
    return next((a for a, b in enumerate(boundary) if b == "wall"), len(boundary) - 1)


def analyze_vibrated(path, t_range=None, with_sonine: bool = True, **_) -> VibratedAnalysis:
    """Analyse a run under gravity or with thermal or vibrating walls: the steady state (the
    second half of the run, or ``t_range[0]`` on), its layer profiles along the axis of gravity
    (or of the vibrating wall), the centre of mass at the snapshots and the energy balance."""
    from granulargas.analysis.run import RunInfo
    from granulargas.io.h5md import iter_snapshots, read_observables

    info = RunInfo.from_file(path)
    obs = read_observables(path)
    t = obs["temperature"][1]

    def series(name):
        return obs[name][2] if name in obs else np.zeros_like(t)

    params = info.parameters
    g = params.get("gravity", {}).get("acceleration") if isinstance(params.get("gravity"), dict) else None
    gravity = tuple(float(x) for x in np.ravel(g)) if g is not None else None
    walls = params.get("walls", {}) if isinstance(params.get("walls"), dict) else {}
    t_from = float(t_range[0]) if t_range else 0.5 * (float(t[0]) + float(t[-1]))
    axis = _scene_axis(gravity, walls, info.boundary)
    L = float(info.box[axis])
    # the layers span the heights the gas reaches in the steady state (a bed fills a few
    # gravitational heights of a tall box): up to the highest 0.2 % of the particles
    com_t, com, top = [], [], 0.0
    for snap in iter_snapshots(path):
        com_t.append(snap.time)
        com.append(centre_of_mass(snap.positions, snap.masses, axis))
        if snap.time >= t_from:
            z = snap.positions[:, axis]
            top = max(top, float(np.quantile(z if gravity is None or gravity[axis] <= 0 else L - z, 0.998)))
    span = min(L, 1.05 * top) if top > 0 and gravity is not None and gravity[axis] != 0 else L
    edges = np.linspace(0.0, span, LAYERS + 1) if gravity is None or gravity[axis] <= 0 else \
        np.linspace(L - span, L, LAYERS + 1)
    acc = LayerAccumulator(axis, edges, info.box)
    if with_sonine:
        for snap in iter_snapshots(path):
            if snap.time >= t_from:
                acc.add(snap.positions, snap.velocities, snap.masses)
    balance = energy_balance(t, series("wall_work"), series("dissipated_energy"), t_from)
    return VibratedAnalysis(info, t, obs["temperature"][2], series("kinetic_energy"), series("potential_energy"),
                            series("dissipated_energy"), series("wall_work"), t_from, axis, gravity, walls,
                            acc.profile(), np.asarray(com_t), np.asarray(com), balance)
