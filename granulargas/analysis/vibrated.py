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
* the **velocity distribution in layers** (:class:`LayerDistributionAccumulator`): a few
  thick layers, each holding an equal share of the samples, in which the component along the
  axis and the components across it (pooled) are scaled by their own temperature,
  c_a sqrt(m / T_a), and histogrammed against the unit Gaussian, with the excess kurtosis
  k = <c^4>/<c^2>^2 - 3 of each (a_2 = k / 3 for one component, 0 for a Maxwellian) and its
  error from block means over the snapshots;
* the **centre of mass** along the axis against time, its height above the floor (the
  wall the gas rests on, at its rest position) in the steady state (time mean, block-mean
  error), against that of a dilute barometric column, sigma/2 + T / (m g), which for a dilute
  bed on a vibrating floor scales as T, i.e. as (A omega)^2 / N_L at leading order
  (:func:`centre_of_mass_height`, :func:`barometric_height`);
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

__all__ = ["LayerAccumulator", "LayerProfile", "LayerDistributionAccumulator", "LayerDistributions",
           "distribution_edges", "centre_of_mass", "centre_of_mass_height", "barometric_height", "energy_balance",
           "EnergyBalance", "steady_mean", "VibratedAnalysis", "analyze_vibrated"]


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

    def moments(self, groups):
        """Mean velocity (G, d), m <c_a^2> along the axis and across it (G,) of the groups of
        layers ``groups`` (list of index arrays into the layers)."""
        d = self.box.shape[0]
        others = [a for a in range(d) if a != self.axis]
        n = np.array([self.n[g].sum() for g in groups])
        m = np.array([self.m[g].sum() for g in groups])
        s1 = np.array([self.s1[g].sum(axis=0) for g in groups]).reshape(len(groups), d)
        mv = np.array([self.mv[g].sum(axis=0) for g in groups]).reshape(len(groups), d)
        mv2 = np.array([self.mv2[g].sum(axis=0) for g in groups]).reshape(len(groups), d)
        with np.errstate(invalid="ignore", divide="ignore"):
            comp = (mv2 - mv**2 / m[:, None]) / n[:, None]
            return s1 / n[:, None], comp[:, self.axis], comp[:, others].mean(axis=1)

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


#: the scaled velocity histograms: bins of width 0.2 over [-4.8, 4.8] (|c| = 2 is a bin edge)
HISTOGRAM_BINS = np.linspace(-4.8, 4.8, 49)
#: the tail weight P(|c| > 2) of the unit Gaussian
GAUSSIAN_TAIL_2 = math.erfc(2.0 / math.sqrt(2.0))


def distribution_edges(profile: LayerProfile, layers: int) -> np.ndarray:
    """Edges of ``layers`` thick layers from the fine layers of ``profile``, each holding about
    an equal share of the samples (cut at the fine edges; fewer if the samples are too few)."""
    c = np.concatenate([[0.0], np.cumsum(profile.counts)])
    if c[-1] <= 0:
        return profile.edges[[0, -1]].copy()
    cuts = np.searchsorted(c, c[-1] * np.arange(1, layers) / layers)
    inner = np.unique(np.clip(cuts, 1, profile.edges.size - 2))
    lo = int(np.argmax(c > 0)) - 1  # the first filled fine layer
    hi = int(np.searchsorted(c, c[-1]))  # the edge after the last filled one
    inner = inner[(inner > lo) & (inner < hi)]
    return profile.edges[np.concatenate([[lo], inner, [hi]])]


@dataclass(frozen=True)
class LayerDistributions:
    """The velocity distribution in the layers between ``edges`` (L + 1,) along ``axis``.

    ``along``, ``across``: histograms (L, K) of the scaled components c_a sqrt(m / T_a) over
    ``bins`` (K + 1,) as probability densities (normalised by all samples of the layer, those
    beyond the bins too); ``counts`` (L, 2): samples along and across; ``kurtosis``,
    ``kurtosis_error`` (L, 2): excess kurtosis along and across, and its standard error from
    block means over the snapshots (sqrt(24 / n), that of n independent Gaussian samples, with
    fewer than 4 snapshots); ``tail`` (L, 2): P(|c| > 2) (Gaussian: :data:`GAUSSIAN_TAIL_2`);
    ``temperature`` (L, 2): T along and across by which the components were scaled.
    """

    axis: int
    edges: np.ndarray
    bins: np.ndarray
    along: np.ndarray
    across: np.ndarray
    counts: np.ndarray
    kurtosis: np.ndarray
    kurtosis_error: np.ndarray
    tail: np.ndarray
    temperature: np.ndarray

    @property
    def centres(self) -> np.ndarray:
        """Centres of the histogram bins."""
        return 0.5 * (self.bins[1:] + self.bins[:-1])

    @property
    def gaussian(self) -> np.ndarray:
        """The unit Gaussian density at the bin centres."""
        return np.exp(-0.5 * self.centres**2) / math.sqrt(2.0 * math.pi)

    @property
    def a2(self) -> np.ndarray:
        """Sonine a_2 of one component, k / 3 (L, 2)."""
        return self.kurtosis / 3.0

    def summary(self) -> list:
        """One dict per layer (JSON-ready)."""
        def f(x):
            return float(x) if math.isfinite(x) else None

        out = []
        for i in range(self.edges.size - 1):
            out.append({"from": float(self.edges[i]), "to": float(self.edges[i + 1]),
                        "samples_along": int(self.counts[i, 0]), "samples_across": int(self.counts[i, 1]),
                        "T_along": f(self.temperature[i, 0]), "T_across": f(self.temperature[i, 1]),
                        "kurtosis_along": f(self.kurtosis[i, 0]), "kurtosis_along_error": f(self.kurtosis_error[i, 0]),
                        "kurtosis_across": f(self.kurtosis[i, 1]),
                        "kurtosis_across_error": f(self.kurtosis_error[i, 1]),
                        "a2_along": f(self.a2[i, 0]), "a2_across": f(self.a2[i, 1]),
                        "tail_along": f(self.tail[i, 0]), "tail_across": f(self.tail[i, 1]),
                        "bins": self.bins.tolist(), "density_along": self.along[i].tolist(),
                        "density_across": self.across[i].tolist(), "gaussian": self.gaussian.tolist()})
        return out


class LayerDistributionAccumulator:
    """Histograms of the scaled velocity components in the layers between ``edges`` along ``axis``.

    ``mean`` (L, d): each layer's mean velocity; ``t_along``, ``t_across`` (L,): its m <c_a^2>
    along the axis and across it (from a first pass, :meth:`LayerAccumulator.moments`), by which
    c_a = v_a - mean_a is scaled to c_a sqrt(m / T_a). Each snapshot's sums of c^2 and c^4 are
    kept apart, for the block error of the kurtosis.
    """

    def __init__(self, axis: int, edges, mean, t_along, t_across, bins=HISTOGRAM_BINS):
        self.axis = int(axis)
        self.edges = np.asarray(edges, dtype=float)
        self.mean = np.asarray(mean, dtype=float)
        self.t = np.stack([np.asarray(t_along, dtype=float), np.asarray(t_across, dtype=float)], axis=1)
        self.bins = np.asarray(bins, dtype=float)
        n_layers, k = self.edges.size - 1, self.bins.size - 1
        self.hist = np.zeros((2, n_layers, k))
        self.frame_sums = []  # per snapshot: (3, 2, L) sums of 1, c^2, c^4

    def add(self, positions, velocities, masses):
        """Add one snapshot (positions (N, d), velocities (N, d), masses (N,))."""
        z = np.asarray(positions, dtype=float)[:, self.axis]
        v = np.asarray(velocities, dtype=float)
        d = v.shape[1]
        m = np.broadcast_to(np.asarray(masses, dtype=float), z.shape)
        n_layers, k = self.edges.size - 1, self.bins.size - 1
        lay = np.searchsorted(self.edges, z, side="right") - 1
        ok = (lay >= 0) & (lay < n_layers)
        lay, v, m = lay[ok], v[ok], m[ok]
        across = [a for a in range(d) if a != self.axis]
        scale = np.empty_like(v)
        scale[:, self.axis] = self.t[lay, 0]
        scale[:, across] = self.t[lay, 1][:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            c = (v - self.mean[lay]) * np.sqrt(m[:, None] / scale)
        sums = np.zeros((3, 2, n_layers))
        for j, (cs, ls) in enumerate(((c[:, self.axis], lay), (c[:, across].ravel(), np.repeat(lay, d - 1)))):
            good = np.isfinite(cs)
            cs, ls = cs[good], ls[good]
            b = np.searchsorted(self.bins, cs, side="right") - 1
            inside = (b >= 0) & (b < k)
            self.hist[j] += np.bincount(ls[inside] * k + b[inside], minlength=n_layers * k).reshape(n_layers, k)
            for p, w in enumerate((np.ones_like(cs), cs**2, cs**4)):
                sums[p, j] = np.bincount(ls, weights=w, minlength=n_layers)
        self.frame_sums.append(sums)
        return self

    def distributions(self, blocks: int = 10) -> LayerDistributions:
        f = np.array(self.frame_sums) if self.frame_sums else np.zeros((0, 3, 2, self.edges.size - 1))
        tot = f.sum(axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            n = tot[0]
            kurt = tot[2] * n / tot[1] ** 2 - 3.0
            err = np.sqrt(24.0 / n)
            k = min(blocks, f.shape[0])
            if k >= 4:
                parts = np.array([p.sum(axis=0) for p in np.array_split(f, k)])
                kb = parts[:, 2] * parts[:, 0] / parts[:, 1] ** 2 - 3.0
                err = np.std(kb, axis=0, ddof=1) / math.sqrt(k)
            width = np.diff(self.bins)
            dens = self.hist / (n[:, :, None] * width)
            inner = (self.bins[:-1] >= -2.0) & (self.bins[1:] <= 2.0)
            tail = 1.0 - self.hist[:, :, inner].sum(axis=2) / n
        return LayerDistributions(self.axis, self.edges.copy(), self.bins.copy(), dens[0], dens[1], n.T.copy(),
                                  kurt.T.copy(), err.T.copy(), tail.T.copy(), self.t.copy())


def centre_of_mass_height(time, com, floor: float, t_from: float | None = None, up: int = 1):
    """(mean, standard error) of the height of the centre of mass above ``floor`` in the steady
    state (from ``t_from`` on, default the second half): the time mean of ``com`` - ``floor``
    (``up`` = -1: a floor above the gas, the height ``floor`` - ``com``), block-mean error."""
    return steady_mean(time, up * (np.asarray(com, dtype=float) - float(floor)), t_from)


def barometric_height(temperature: float, g: float, mass: float = 1.0, diameter: float = 1.0) -> float:
    """Height of the centre of mass of a dilute barometric column above its floor:
    sigma/2 + T / (m g) (the centres reach down to sigma/2, their density falls as
    exp(-m g z / T))."""
    return 0.5 * diameter + temperature / (mass * g)


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
#: thick layers of the velocity distributions (equal shares of the samples)
DISTRIBUTION_LAYERS = 4


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
    distributions: LayerDistributions | None = None  # the velocity distribution in layers

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
    def floor(self):
        """(position, direction) of the floor along the axis: the wall gravity points into, at
        its rest position (a vibrating wall's is A inside the box), and +1 if the gas lies
        above it, -1 below; without gravity along the axis, the low wall, +1."""
        down = 1 if self.gravity is not None and self.gravity[self.axis] > 0 else 0
        w = self.walls.get("xyz"[self.axis] + ("_low", "_high")[down]) or {}
        inside = float(w.get("amplitude", 0.0)) if w.get("kind") == "vibrating" else 0.0
        L = float(self.info.box[self.axis])
        return (L - inside, -1) if down else (inside, 1)

    @property
    def plate_velocity(self) -> float:
        """A omega of the vibrating floor (nan without one)."""
        down = 1 if self.gravity is not None and self.gravity[self.axis] > 0 else 0
        w = self.walls.get("xyz"[self.axis] + ("_low", "_high")[down]) or {}
        if w.get("kind") != "vibrating":
            return math.nan
        return 2.0 * math.pi * float(w["amplitude"]) * float(w["frequency"])

    def com_height(self):
        """(mean, error) of the centre of mass's height above the floor in the steady state."""
        floor, up = self.floor
        if not self.com.size:
            return math.nan, math.nan
        return centre_of_mass_height(self.com_time, self.com, floor, self.t_from, up)

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
        h, he = self.com_height()
        out.update(com_height=h, com_height_error=he, plate_velocity=self.plate_velocity)
        if self.g_axis > 0:
            # against the dilute barometric column at the measured T and at the leading-order T
            out["com_height_barometric"] = barometric_height(T, self.g_axis, self.info.mass, self.info.diameter)
            if bed is not None:
                out["com_height_bed_theory"] = barometric_height(bed["temperature"], self.g_axis, self.info.mass,
                                                                 self.info.diameter)
        out = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in out.items()}
        if self.distributions is not None:
            out["layer_distributions"] = self.distributions.summary()
        return out


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
    dists = None
    if with_sonine:
        for snap in iter_snapshots(path):
            if snap.time >= t_from:
                acc.add(snap.positions, snap.velocities, snap.masses)
        # the velocity distribution in thick layers, scaled by their temperatures (a second pass)
        fine = acc.profile()
        if fine.counts.sum() > 0:
            thick = distribution_edges(fine, DISTRIBUTION_LAYERS)
            idx = np.searchsorted(fine.edges, thick)
            mean, t_al, t_ac = acc.moments([np.arange(a, b) for a, b in zip(idx[:-1], idx[1:])])
            dacc = LayerDistributionAccumulator(axis, thick, mean, t_al, t_ac)
            for snap in iter_snapshots(path):
                if snap.time >= t_from:
                    dacc.add(snap.positions, snap.velocities, snap.masses)
            dists = dacc.distributions()
    balance = energy_balance(t, series("wall_work"), series("dissipated_energy"), t_from)
    return VibratedAnalysis(info, t, obs["temperature"][2], series("kinetic_energy"), series("potential_energy"),
                            series("dissipated_energy"), series("wall_work"), t_from, axis, gravity, walls,
                            acc.profile(), np.asarray(com_t), np.asarray(com), balance, distributions=dists)
