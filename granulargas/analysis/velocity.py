"""Velocity distribution of a homogeneous granular gas: f(c), Sonine forms, high-energy tail.

Works on velocity snapshots of either model (event-driven engine or DSMC), one
snapshot at a time, so arbitrarily many can be pooled.

Scaled velocity ``c = (v - V) / v_T`` with ``v_T = sqrt(2T/m)`` (V the mean
velocity, T the snapshot's temperature), and ``f(c)`` the d-dimensional density
of c normalised to ``integral f(c) d^d c = 1``. References:

* Maxwellian ``phi(c) = pi^(-d/2) exp(-c^2)``;
* Sonine forms ``phi(c) [1 + a2 S2(c^2) + a3 S3(c^2)]`` with the Sonine
  (associated Laguerre) polynomials of :func:`granulargas.analysis.cooling.sonine_polynomial`;
* the exponential high-energy tail of the homogeneous cooling state (HCS) of
  inelastic hard spheres, ``f(c) ~ exp(-A c)``, from the balance of the
  cooling drift and the loss term of the scaled Boltzmann equation
  (Esipov & Pöschel, J. Stat. Phys. 86, 1385 (1997); van Noije & Ernst,
  Granular Matter 1, 57 (1998)):

      (zeta*/2)(d + c . d/dc) f = J(f, f),   J ~ -B_d c f   (c >> 1),

  so ``A = 2 B_d / zeta*`` with ``B_d = pi^((d-1)/2) / Gamma((d+1)/2)`` (pi in
  3D, 2 in 2D) and ``zeta* = zeta / (chi n sigma^(d-1) v_T)`` the reduced
  cooling rate, constant in the HCS:
  ``zeta* = (1 - eps^2)/d Omega_d c_zeta``, ``Omega_d = sqrt(2) pi^((d-1)/2) / Gamma(d/2)``
  (the Enskog collision frequency in units of chi n sigma^(d-1) v_T), with the cooling-rate
  factor c_zeta of the HCS reference (:func:`granulargas.theory.hcs.hcs_reference`; in the
  first Sonine approximation c_zeta = 1 + 3 a2/16).
  The asymptotic form holds for c >> 1; at moderate c the local slope
  ``-d ln f / dc`` is still approaching A.

The tail is fitted by Poisson maximum likelihood on the binned counts of the
pooled speeds (:func:`fit_exponential_tail`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from granulargas import theory
from granulargas.theory.hcs import hcs_reference
from granulargas.analysis.cooling import block_mean, peculiar_velocities, sonine_coefficients, sonine_polynomial
from granulargas.io.h5md import iter_snapshots, load_snapshot, snapshot_count

__all__ = [
    "scaled_velocities",
    "SpeedHistogram",
    "maxwellian",
    "sonine_density",
    "omega_reduced",
    "sonine_cooling_rate",
    "reduced_cooling_rate",
    "tail_constant",
    "TailFit",
    "fit_exponential_tail",
    "local_slope",
    "plot_velocity_distribution",
]


def _masses(masses, n):
    if masses is None:
        return np.ones(n)
    m = np.asarray(masses, dtype=float)
    return np.full(n, float(m)) if m.ndim == 0 else m


def _sphere_area(dim):
    """Area of the unit sphere in d dimensions, 2 pi^(d/2) / Gamma(d/2)."""
    return 2.0 * math.pi ** (dim / 2.0) / math.gamma(dim / 2.0)


def scaled_velocities(velocities, masses=None):
    """Peculiar velocities in units of the thermal speed, ``c = (v - V) sqrt(m / (2T))``, (N, d)."""
    c = peculiar_velocities(velocities, masses)
    n, d = c.shape
    m = _masses(masses, n)
    temp = float((m * (c * c).sum(axis=1)).mean() / d)
    if not temp > 0:
        raise ValueError("velocity snapshot with zero temperature")
    return c * np.sqrt(m / (2.0 * temp))[:, None]


class SpeedHistogram:
    """Scaled speeds ``|c|`` pooled over snapshots, with their Sonine coefficients.

    Parameters
    ----------
    dim : {2, 3}
    c_max : float
        Upper edge of the histogram (speeds beyond are counted in ``overflow``).
    bins : int
        Number of equal-width bins on [0, c_max].
    """

    def __init__(self, dim: int, c_max: float = 8.0, bins: int = 160):
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self.dim = dim
        self.edges = np.linspace(0.0, float(c_max), int(bins) + 1)
        self.counts = np.zeros(int(bins), dtype=np.int64)
        self.samples = 0
        self.snapshots = 0
        self.overflow = 0
        self._a2 = []
        self._a3 = []

    def add(self, velocities, masses=None) -> "SpeedHistogram":
        """Pool one snapshot (N, d)."""
        v = np.asarray(velocities, dtype=float)
        if v.ndim != 2 or v.shape[1] != self.dim:
            raise ValueError(f"velocities: shape {v.shape}, expected (N, {self.dim})")
        speed = np.linalg.norm(scaled_velocities(v, masses), axis=1)
        counts, _ = np.histogram(speed, bins=self.edges)
        self.counts += counts
        self.overflow += int(np.count_nonzero(speed >= self.edges[-1]))
        self.samples += speed.size
        self.snapshots += 1
        a2, a3 = sonine_coefficients(v, masses)
        self._a2.append(a2)
        self._a3.append(a3)
        return self

    @property
    def centres(self):
        return 0.5 * (self.edges[1:] + self.edges[:-1])

    @property
    def shell_volumes(self):
        """Volume of each bin's spherical shell in c-space, S_d (c_hi^d - c_lo^d) / d."""
        d = self.dim
        return _sphere_area(d) * (self.edges[1:] ** d - self.edges[:-1] ** d) / d

    def density(self):
        """(c, f, f_err): f(c) per bin (shell average) with its Poisson error; empty bins give 0."""
        norm = self.samples * self.shell_volumes
        return self.centres, self.counts / norm, np.sqrt(self.counts) / norm

    def sonine(self):
        """(a2, a2_err, a3, a3_err): mean over the snapshots in the order added, with the standard
        error of block means (:func:`granulargas.analysis.cooling.block_mean`)."""
        a2, a2e = block_mean(self._a2)
        a3, a3e = block_mean(self._a3)
        return a2, a2e, a3, a3e


def maxwellian(c, dim):
    """Scaled Maxwellian ``pi^(-d/2) exp(-c^2)``."""
    c = np.asarray(c, dtype=float)
    return np.exp(-c * c) / math.pi ** (dim / 2.0)


def sonine_density(c, dim, a2, a3=0.0):
    """Sonine form ``phi(c) [1 + a2 S2(c^2) + a3 S3(c^2)]``."""
    c = np.asarray(c, dtype=float)
    x = c * c
    return maxwellian(c, dim) * (1.0 + a2 * sonine_polynomial(2, x, dim)
                                 + a3 * sonine_polynomial(3, x, dim))


def _b_d(dim):
    return math.pi ** ((dim - 1) / 2.0) / math.gamma((dim + 1) / 2.0)


def omega_reduced(dim):
    """Enskog collision frequency of a Maxwellian gas in units of chi n sigma^(d-1) v_T:
    ``sqrt(2) pi^((d-1)/2) / Gamma(d/2)`` (2 sqrt(2 pi) in 3D, sqrt(2 pi) in 2D)."""
    return math.sqrt(2.0) * math.pi ** ((dim - 1) / 2.0) / math.gamma(dim / 2.0)


def sonine_cooling_rate(eps, dim, a2=0.0, zeta_factor=None):
    """Reduced cooling rate ``zeta* = (1 - eps^2)/d Omega_d c_zeta``: with ``zeta_factor`` = c_zeta
    of an HCS reference (:mod:`granulargas.theory.hcs`), else first Sonine, c_zeta = 1 + 3 a2 / 16
    (van Noije & Ernst 1998)."""
    factor = 1.0 + 3.0 * a2 / 16.0 if zeta_factor is None else zeta_factor
    return (1.0 - eps * eps) / dim * omega_reduced(dim) * factor


def reduced_cooling_rate(times, temperatures, number_density, chi, dim, sigma=1.0, mass=1.0):
    """Measured reduced cooling rate ``zeta* = zeta / (chi n sigma^(d-1) v_T)`` of an HCS run.

    With zeta* constant, ``d T^(-1/2) / dt = (zeta*/2) chi n sigma^(d-1) sqrt(2/m)``
    exactly, so every interval between samples gives an estimate; returns their
    mean and the standard error of block means (:func:`granulargas.analysis.cooling.block_mean`).
    """
    t = np.asarray(times, dtype=float)
    y = np.asarray(temperatures, dtype=float) ** -0.5
    scale = 2.0 / (chi * number_density * sigma ** (dim - 1) * math.sqrt(2.0 / mass))
    return block_mean(np.diff(y) / np.diff(t) * scale)


def tail_constant(zeta_star, dim):
    """Decay constant of the HCS tail, ``A = 2 B_d / zeta*`` (module docstring)."""
    return 2.0 * _b_d(dim) / zeta_star


@dataclass(frozen=True)
class TailFit:
    """``f(c) = B exp(-A c)`` on ``c_min <= c < c_max`` fitted to ``counts`` pooled speeds."""

    A: float
    A_err: float
    B: float
    c_min: float
    c_max: float
    counts: int
    deviance_per_bin: float

    def __call__(self, c):
        return self.B * np.exp(-self.A * np.asarray(c, dtype=float))


def _tail_expected(hist, lo, hi, a, b):
    """Expected counts per bin for f = b exp(-a c): samples S_d b int c^(d-1) exp(-a c) dc."""
    d = hist.dim
    shell = _sphere_area(d) * math.gamma(d) / a**d
    integral = special.gammaincc(d, a * lo) - special.gammaincc(d, a * hi)
    return hist.samples * b * shell * integral


def fit_exponential_tail(hist: SpeedHistogram, c_min: float, c_max: float | None = None) -> TailFit:
    """Poisson maximum-likelihood fit of ``B exp(-A c)`` to the bins with c_min <= c < c_max.

    ``A_err`` is the one-sigma error from the inverse Fisher information;
    ``deviance_per_bin`` (Poisson deviance per degree of freedom, ~1 for a good fit)
    says whether the pure exponential describes the window.
    """
    c_max = hist.edges[-1] if c_max is None else float(c_max)
    sel = (hist.edges[:-1] >= c_min - 1e-12) & (hist.edges[1:] <= c_max + 1e-12)
    lo, hi, k = hist.edges[:-1][sel], hist.edges[1:][sel], hist.counts[sel]
    if k.sum() < 10 or k.size < 3:
        raise ValueError(f"tail window [{c_min}, {c_max}) holds {int(k.sum())} speeds in {k.size} bins: "
                         f"too few to fit")
    c_mid, f, _ = (x[sel] for x in hist.density())
    pos = f > 0
    slope, icpt = np.polyfit(c_mid[pos], np.log(f[pos]), 1, w=np.sqrt(k[pos]))
    a0 = max(-slope, 0.1)

    def nll(p):
        a, lb = p
        lam = _tail_expected(hist, lo, hi, a, math.exp(lb))
        return float(np.sum(lam - k * np.log(np.maximum(lam, 1e-300))))

    res = optimize.minimize(nll, [a0, icpt], method="Nelder-Mead",
                            options=dict(xatol=1e-10, fatol=1e-10, maxiter=20000))
    a, lb = res.x
    # Fisher information by central differences of the negative log likelihood
    h = np.array([1e-4 * max(abs(a), 1.0), 1e-4])
    hess = np.empty((2, 2))
    for i in range(2):
        for j in range(2):
            ei, ej = np.eye(2)[i] * h[i], np.eye(2)[j] * h[j]
            hess[i, j] = (nll(res.x + ei + ej) - nll(res.x + ei - ej) - nll(res.x - ei + ej)
                          + nll(res.x - ei - ej)) / (4 * h[i] * h[j])
    try:
        a_err = float(math.sqrt(np.linalg.inv(hess)[0, 0]))
    except (np.linalg.LinAlgError, ValueError):
        a_err = float("nan")
    lam = _tail_expected(hist, lo, hi, a, math.exp(lb))
    with np.errstate(divide="ignore", invalid="ignore"):
        term = np.where(k > 0, k * np.log(k / lam), 0.0)
    deviance = 2.0 * float(np.sum(term - (k - lam)))
    return TailFit(A=float(a), A_err=a_err, B=float(math.exp(lb)), c_min=float(c_min), c_max=float(c_max),
                   counts=int(k.sum()), deviance_per_bin=deviance / max(k.size - 2, 1))


def local_slope(hist: SpeedHistogram, min_counts: int = 25, merge: int = 4):
    """``-d ln f / dc`` from pairs of neighbouring groups of ``merge`` bins, where both groups
    hold at least ``min_counts`` speeds; returns (c, slope, slope_err)."""
    k = hist.counts[: hist.counts.size // merge * merge].reshape(-1, merge).sum(axis=1)
    vol = hist.shell_volumes[: k.size * merge].reshape(-1, merge).sum(axis=1)
    edges = hist.edges[: k.size * merge + 1 : merge]
    c = 0.5 * (edges[1:] + edges[:-1])
    ok = (k[1:] >= min_counts) & (k[:-1] >= min_counts)
    f = k / vol
    dc = np.diff(c)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = -np.log(f[1:] / f[:-1]) / dc
    err = np.sqrt(1.0 / np.maximum(k[1:], 1) + 1.0 / np.maximum(k[:-1], 1)) / dc
    cm = 0.5 * (c[1:] + c[:-1])
    return cm[ok], slope[ok], err[ok]


def plot_velocity_distribution(panels, path, title=None):
    """Figure: f(c) on a log scale with the Maxwellian, the Sonine forms and the tail fit
    (top), and the local slope -d ln f/dc against the tail constant A (bottom), one column
    per panel.

    Parameters
    ----------
    panels : list of dict
        Keys ``hist`` (SpeedHistogram), ``label`` (str), optional ``fit`` (TailFit),
        ``A_theory`` (dict: label -> A), ``a2_theory`` (float, drawn as a Sonine form) and
        ``a2_theory_name`` (what it is).
    path : str or Path
        PNG to write.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    cols = len(panels)
    fig, axes = plt.subplots(2, cols, figsize=(5.2 * cols, 7.6), squeeze=False,
                             gridspec_kw={"height_ratios": [3, 1.6]})
    for col, p in enumerate(panels):
        hist, ax, ax2 = p["hist"], axes[0, col], axes[1, col]
        c, f, err = hist.density()
        a2, a2e, a3, a3e = hist.sonine()
        ok = hist.counts > 0
        cmax = float(c[ok].max()) + 0.3 if ok.any() else hist.edges[-1]
        cs = np.linspace(0.0, cmax, 400)
        ax.errorbar(c[ok], f[ok], yerr=err[ok], fmt=".", ms=3, lw=0.8, color="C0",
                    label=f"simulation ({hist.samples:.3g} speeds)")
        ax.semilogy(cs, maxwellian(cs, hist.dim), "k-", lw=1, label="Maxwellian")
        ax.semilogy(cs, sonine_density(cs, hist.dim, a2), "C1--", lw=1,
                    label=f"first Sonine, measured $a_2$={a2:.4f}")
        ax.semilogy(cs, sonine_density(cs, hist.dim, a2, a3), "C2:", lw=1.2,
                    label=f"+ $a_3$={a3:.4f}")
        if p.get("a2_theory") is not None:
            ax.semilogy(cs, sonine_density(cs, hist.dim, p["a2_theory"]), "C4-.", lw=0.8,
                        label=f"Sonine form, $a_2$={p['a2_theory']:.4f} ({p.get('a2_theory_name', 'theory')})")
        fit = p.get("fit")
        if fit is not None:
            cf = np.linspace(fit.c_min, cmax, 100)
            ax.semilogy(cf, fit(cf), "r-", lw=1.4,
                        label=f"fit $e^{{-Ac}}$, c$\\geq${fit.c_min:g}: A={fit.A:.3f}$\\pm${fit.A_err:.3f}")
        pos = f[ok]
        ax.set_ylim(max(pos.min() / 3, 1e-300), pos.max() * 3)
        ax.set_xlim(0, cmax)
        ax.set_ylabel("$f(c)$")
        ax.set_title(p["label"], fontsize=10)
        ax.legend(fontsize=7, loc="lower left")
        cl, sl, se = local_slope(hist)
        ax2.errorbar(cl, sl, yerr=se, fmt=".", ms=3, lw=0.8, color="C0", label="$-d\\ln f/dc$")
        ax2.plot(cs, 2 * cs, "k-", lw=0.8, label="Maxwellian (2c)")
        for i, (name, value) in enumerate((p.get("A_theory") or {}).items()):
            ax2.axhline(value, color=f"C{3 + i}", ls="--", lw=1, label=f"A {name} = {value:.3f}")
        if fit is not None:
            ax2.axhline(fit.A, color="r", lw=1, label="A fitted")
        scale = [v for v in (p.get("A_theory") or {}).values()] + ([fit.A] if fit is not None else [])
        ax2.set_ylim(0, 1.6 * max(scale) if scale else 2 * cmax)
        ax2.set_xlim(0, cmax)
        ax2.set_xlabel("$c = |v - V| / \\sqrt{2T/m}$")
        ax2.set_ylabel("local slope")
        ax2.legend(fontsize=7, loc="upper left")
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


# ------------------------------------------------------------------ a run's file


@dataclass
class FileDistribution:
    """The scaled speed distribution of a run's snapshots (:func:`file_distribution`)."""

    hist: SpeedHistogram
    t_from: float
    a2_theory: float | None  # steady a2 of the run's kind (None: no steady value)
    a_theory: float | None  # tail constant 2 B_d / zeta* of the HCS (constant eps only)
    fit: TailFit | None
    a2_theory_name: str = ""  # what a2_theory is

    def lines(self) -> list[str]:
        a2, a2e, a3, a3e = self.hist.sonine()
        out = [f"  velocity distribution: {self.hist.snapshots} snapshots from t = {self.t_from:.4g}, "
               f"{self.hist.samples} speeds; a2 = {a2:.5f} +- {a2e:.2g}, a3 = {a3:.5f} +- {a3e:.2g} "
               f"(standard error of block means)"
               + ("" if self.a2_theory is None else f"; a2 of the {self.a2_theory_name}: {self.a2_theory:.5f}")]
        if self.a_theory is not None:
            fit = (f"fit exp(-A c) for c >= {self.fit.c_min:.2f}: A = {self.fit.A:.3f} +- {self.fit.A_err:.2g} "
                   f"({self.fit.counts} speeds)" if self.fit is not None else f"fewer than 10 speeds beyond c = {self.a_theory:.2f} to fit")
            out.append(f"  high-energy tail: {fit}; HCS theory A = 2 B_d / zeta* = {self.a_theory:.3f} "
                       f"(van Noije & Ernst 1998, zeta* of the {self.a2_theory_name})")
        return out


def file_distribution(info, kind: str, c_max: float = 8.0, t_from: float | None = None) -> FileDistribution:
    """Pool the scaled speeds of a run's snapshots from ``t_from`` on (default: the later half of
    the snapshots; never the initial one) for either method (a DSMC file has velocities only;
    that is all this needs). ``granulargas analyze --velocity`` passes the window of the report's
    a2 mean, so both give the same a2 with the same error.

    ``info``: :class:`granulargas.analysis.run.RunInfo`; ``kind``: ``"cooling"``,
    ``"elastic"`` or ``"driven"`` (:func:`granulargas.analysis.run.run_kind`). The theory:
    a2 = 0 (elastic), the HCS reference (constant eps, :func:`granulargas.theory.hcs.hcs_reference`)
    or the driven a2 (white noise, first Sonine), none for the viscoelastic HCS (its a2 changes
    with T); the tail constant for the HCS of constant eps, fitted from c = A on (the
    exponential overtakes the Gaussian there).
    """
    d = info.dimension
    count = snapshot_count(info.path)
    if count < 2:
        raise ValueError(f"{info.path}: no snapshot after the initial one")
    if t_from is None:
        t_from = load_snapshot(info.path, max(1, count // 2)).time
    hist = SpeedHistogram(d, c_max=c_max, bins=int(round(c_max / 0.05)))
    for snap in iter_snapshots(info.path):
        if snap.time >= t_from and snap.index > 0:
            hist.add(snap.velocities, snap.masses)
    eps = info.restitution if info.model == "constant" else (1.0 if info.model == "elastic" else None)
    if hist.snapshots == 0:
        raise ValueError(f"{info.path}: no snapshot from t = {t_from:.4g} on")
    a2_theory = a_theory = fit = None
    name = ""
    if kind == "elastic":
        a2_theory, name = 0.0, "Maxwellian"
    elif kind == "driven" and eps is not None:
        a2_theory, name = float(theory.driven_sonine_a2(eps, d)), "driven steady state, first Sonine"
    elif kind == "cooling" and eps is not None and eps < 1.0:
        ref = hcs_reference(eps, d)
        a2_theory, name = ref.a2, ref.name
        a_theory = tail_constant(sonine_cooling_rate(eps, d, zeta_factor=ref.zeta_factor), d)
        try:
            fit = fit_exponential_tail(hist, round(a_theory / 0.05) * 0.05)
        except ValueError:
            fit = None
    return FileDistribution(hist, t_from, a2_theory, a_theory, fit, name)


def plot_file_distribution(dist: FileDistribution, info, path):
    """:func:`plot_velocity_distribution` of a :class:`FileDistribution`."""
    method = "DSMC" if getattr(info, "method", "edmd") == "dsmc" else "EDMD"
    panel = {"hist": dist.hist, "fit": dist.fit, "a2_theory": dist.a2_theory, "a2_theory_name": dist.a2_theory_name,
             "label": f"{info.path.rsplit('/', 1)[-1]}: {method}, {info.model}, {info.dimension}D, "
                      f"N = {info.particles},\n{dist.hist.snapshots} snapshots from t = {dist.t_from:.4g}"}
    if dist.a_theory is not None:
        panel["A_theory"] = {f"HCS theory ({dist.a2_theory_name})": dist.a_theory}
    return plot_velocity_distribution([panel], path)
