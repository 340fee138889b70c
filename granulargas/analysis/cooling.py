"""Cooling of a homogeneous granular gas: temperature, Sonine coefficients, fits.

Plain functions on arrays (the style of the whole :mod:`granulargas.analysis`
package): a snapshot's velocities in, numbers out; file-level helpers live in
:mod:`granulargas.analysis.run`.

Temperature: ``T = <m c^2> / d`` with the peculiar velocity ``c = v - V`` (``V``
the centre-of-mass velocity). Sonine expansion of the scaled distribution, with
``x = m c^2 / (2T)`` (so ``<x> = d/2``):

    f(c) = phi(c) [1 + a2 S2(x) + a3 S3(x) + ...],
    <x^2> = d(d+2)/4 (1 + a2),   <x^3> = d(d+2)(d+4)/8 (1 + 3 a2 - a3)

(Brilliantov & Pöschel, EPL 74, 424 (2006); van Noije & Ernst 1998),
so ``a2 = 4 <x^2> / (d(d+2)) - 1`` and ``a3 = 1 + 3 a2 - 8 <x^3> / (d(d+2)(d+4))``.

Fits: the cooling laws ``T = T0 (1 + t/tau0)^(-p)`` (Haff ``p = 2``, viscoelastic
``p = 5/3``) are fitted by least squares on ``ln T`` (equal relative weights at
all times), with ``T0`` fixed to the first sample unless asked otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from granulargas import observables

#: blocks for the standard errors of :func:`block_mean`
BLOCKS = 10


def block_mean(x, blocks: int = BLOCKS):
    """(mean, standard error) of a correlated series from the means of ``blocks`` consecutive blocks.

    The one error estimate of the analysis (every mean over a run's samples or snapshots):
    the series is cut into ``blocks`` consecutive blocks of (nearly) equal length, and the
    error is the standard deviation of the block means over sqrt(blocks). Blocks longer than
    the correlation time are independent, so no model of the correlations is needed; fewer
    than 2 finite values give an error of nan.
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return math.nan, math.nan
    k = min(blocks, x.size)
    if k < 2:
        return float(x.mean()), math.nan
    means = np.array([b.mean() for b in np.array_split(x, k)])
    return float(x.mean()), float(means.std(ddof=1) / math.sqrt(k))

__all__ = [
    "temperature",
    "peculiar_velocities",
    "sonine_coefficients",
    "sonine_polynomial",
    "velocity_distribution",
    "maxwell_sonine_pdf",
    "collisions_per_particle",
    "BLOCKS",
    "block_mean",
    "CoolingFit",
    "fit_cooling_law",
    "local_exponent",
]


def _masses(masses, n):
    if masses is None:
        return np.ones(n)
    m = np.asarray(masses, dtype=float)
    return np.full(n, float(m)) if m.ndim == 0 else m


def peculiar_velocities(velocities, masses=None):
    """Velocities relative to the centre-of-mass velocity, shape (N, d)."""
    v = np.asarray(velocities, dtype=float)
    m = _masses(masses, v.shape[0])
    return v - (m[:, None] * v).sum(axis=0) / m.sum()


def temperature(velocities, masses=None):
    """Granular temperature ``T = <m c^2> / d`` (k_B = 1) of one snapshot.

    Parameters
    ----------
    velocities : array (N, d)
    masses : array (N,) or float, optional (default 1)
    """
    c = peculiar_velocities(velocities, masses)
    m = _masses(masses, c.shape[0])
    return float((m * (c * c).sum(axis=1)).mean() / c.shape[1])


def sonine_polynomial(p, x, dim):
    """Sonine polynomial ``S_p(x)`` = associated Laguerre ``L_p^(d/2 - 1)(x)``
    with the sign convention of the granular literature (S2 = x^2/2 - (d+2)x/2 + d(d+2)/8)."""
    return special.eval_genlaguerre(p, dim / 2.0 - 1.0, x)


def sonine_coefficients(velocities, masses=None):
    """Second and third Sonine coefficients of the velocity distribution
    (the estimator of :mod:`granulargas.observables`, which the simulations' observables use).

    Returns
    -------
    a2, a3 : float
        For a Maxwellian both are 0 within sampling error
        (standard error of a2 ~ sqrt(8 / (d (d + 2) N))).
    """
    v = np.asarray(velocities, dtype=float)
    m = None if masses is None else np.broadcast_to(np.asarray(masses, dtype=float), (v.shape[0],))
    return observables.sonine_coefficients(v, m)


def maxwell_sonine_pdf(u, dim, a2=0.0, a3=0.0, kind="component"):
    """Reference densities in the scaled velocity ``u = c / v_T``, ``v_T = sqrt(2T/m)``.

    ``kind="speed"``: density of ``|u|`` for ``phi (1 + a2 S2 + a3 S3)``;
    ``kind="component"``: Maxwellian density of one component,
    ``exp(-u^2)/sqrt(pi)`` (the Sonine terms are only plotted for the speed).
    """
    u = np.asarray(u, dtype=float)
    if kind == "component":
        return np.exp(-u * u) / np.sqrt(np.pi)
    x = u * u
    base = 2.0 * u ** (dim - 1) * np.exp(-x) / special.gamma(dim / 2.0)
    return base * (1.0 + a2 * sonine_polynomial(2, x, dim) + a3 * sonine_polynomial(3, x, dim))


def velocity_distribution(velocities, masses=None, bins=60, kind="speed", u_max=4.0):
    """Histogram of the scaled peculiar velocity ``u = c / v_T``, ``v_T = sqrt(2T/m)``.

    Parameters
    ----------
    kind : {"speed", "component"}
        Density of ``|u|`` or of every Cartesian component pooled.

    Returns
    -------
    centers, density : arrays (bins,)
    """
    c = peculiar_velocities(velocities, masses)
    n, d = c.shape
    m = _masses(masses, n)
    T = (m * (c * c).sum(axis=1)).mean() / d
    u = c * np.sqrt(m / (2.0 * T))[:, None]
    if kind == "speed":
        data, rng = np.linalg.norm(u, axis=1), (0.0, u_max)
    elif kind == "component":
        data, rng = u.ravel(), (-u_max, u_max)
    else:
        raise ValueError(f"kind must be 'speed' or 'component', got {kind!r}")
    hist, edges = np.histogram(data, bins=bins, range=rng)
    density = hist / (data.size * np.diff(edges))
    return 0.5 * (edges[1:] + edges[:-1]), density


def collisions_per_particle(collisions, n_particles):
    """Time axis in collisions per particle, ``s = 2 C / N`` (each pair collision
    counts for both partners)."""
    return 2.0 * np.asarray(collisions, dtype=float) / n_particles


@dataclass(frozen=True)
class CoolingFit:
    """Result of :func:`fit_cooling_law`: ``T = T0 (1 + t/tau0)^(-exponent)``.

    ``tau0_err`` and ``exponent_err`` are one-sigma errors from the fit's
    covariance (residual-scaled); they do not include seed-to-seed scatter.
    ``rms`` is the root-mean-square residual of ``ln T``.
    """

    T0: float
    tau0: float
    exponent: float
    tau0_err: float
    exponent_err: float
    rms: float

    def __call__(self, t):
        return self.T0 * (1.0 + np.asarray(t, dtype=float) / self.tau0) ** (-self.exponent)


def fit_cooling_law(t, T, exponent=2.0, T0=None, t_range=None, tau0_guess=None):
    """Fit ``T(t) = T0 (1 + t/tau0)^(-p)`` by least squares in ``ln T``.

    Parameters
    ----------
    t, T : arrays (S,)
        Times (first sample normally at t = 0) and temperatures.
    exponent : float or None
        Fixed ``p`` (2 for Haff, 5/3 viscoelastic), or None to fit it too.
    T0 : float or None
        Fixed initial temperature; default ``T[0]`` if ``t[0] == 0``, else fitted.
    t_range : (t_min, t_max), optional
        Use only samples in this window.
    tau0_guess : float, optional

    Returns
    -------
    CoolingFit
    """
    t = np.asarray(t, dtype=float)
    T = np.asarray(T, dtype=float)
    ok = np.isfinite(T) & (T > 0) & np.isfinite(t)
    fixed_T0 = T0
    if fixed_T0 is None and t.size and t[0] == 0.0 and T[0] > 0:
        fixed_T0 = float(T[0])
    if t_range is not None:
        ok &= (t >= t_range[0]) & (t <= t_range[1])
    t, T = t[ok], T[ok]
    if t.size < 3:
        raise ValueError("need at least 3 samples to fit a cooling law")
    y = np.log(T)
    p_guess = 2.0 if exponent is None else float(exponent)
    if tau0_guess is None:
        # from the last sample: T_end/T0 = (1 + t/tau0)^-p
        T0g = fixed_T0 if fixed_T0 is not None else float(T[0])
        ratio = (T0g / T[-1]) ** (1.0 / p_guess) - 1.0
        tau0_guess = t[-1] / ratio if ratio > 0 else max(t[-1], 1.0)

    names = ["log_tau0"]
    x0 = [np.log(tau0_guess)]
    if exponent is None:
        names.append("p")
        x0.append(p_guess)
    if fixed_T0 is None:
        names.append("log_T0")
        x0.append(float(y[0]))

    def unpack(params):
        d = dict(zip(names, params))
        tau0 = np.exp(d["log_tau0"])
        p = d.get("p", exponent)
        lT0 = d.get("log_T0", np.log(fixed_T0) if fixed_T0 is not None else 0.0)
        return tau0, p, lT0

    def resid(params):
        tau0, p, lT0 = unpack(params)
        return lT0 - p * np.log1p(t / tau0) - y

    res = optimize.least_squares(resid, x0, method="lm", xtol=1e-14, ftol=1e-14)
    tau0, p, lT0 = unpack(res.x)
    dof = max(t.size - len(names), 1)
    s2 = float(np.sum(res.fun**2)) / dof
    try:
        cov = np.linalg.inv(res.jac.T @ res.jac) * s2
        errs = dict(zip(names, np.sqrt(np.clip(np.diag(cov), 0, None))))
    except np.linalg.LinAlgError:
        errs = {k: np.nan for k in names}
    return CoolingFit(
        T0=float(np.exp(lT0)),
        tau0=float(tau0),
        exponent=float(p),
        tau0_err=float(tau0 * errs["log_tau0"]),
        exponent_err=float(errs.get("p", 0.0)),
        rms=float(np.sqrt(np.mean(res.fun**2))),
    )


def local_exponent(t, T, tau0=0.0):
    """Logarithmic derivative ``d ln T / d ln(t + tau0)`` by centred differences.

    With ``tau0`` from a fit this tends to ``-p`` at all times if
    ``T ~ (1 + t/tau0)^(-p)``; with ``tau0 = 0`` it is the plain log-log slope,
    which reaches ``-p`` only for ``t >> tau0``.

    Returns
    -------
    t_mid, slope : arrays (S-1,)
    """
    t = np.asarray(t, dtype=float)
    T = np.asarray(T, dtype=float)
    ok = (t + tau0 > 0) & (T > 0)
    lx, ly = np.log(t[ok] + tau0), np.log(T[ok])
    return np.exp(0.5 * (lx[1:] + lx[:-1])) - tau0, np.diff(ly) / np.diff(lx)
