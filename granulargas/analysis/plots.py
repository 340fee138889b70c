"""Figures of ``granulargas analyze --plot`` (matplotlib, Agg backend; imported lazily by the CLI).

One figure per kind of run (:data:`PLOTS`, dispatched by :func:`plot_analysis`) and
one for a sweep (:func:`plot_sweep`). Each says in its title what it shows and
names the theory in the legend; axes never use an offset (small drifts are drawn
in units of a stated power of ten).
"""

from __future__ import annotations

import math

import numpy as np

from granulargas import theory
from granulargas.analysis.run import A2_ERROR_METHOD
from granulargas.theory.hcs import FIRST_SONINE

__all__ = ["PLOTS", "plot_analysis", "ratio_limits", "plot_cooling", "plot_density_profiles", "plot_driven", "plot_elastic",
           "plot_rough", "plot_shear", "plot_sweep", "plot_vibrated"]


def _plt():
    # matplotlib is imported when a figure is drawn: `import granulargas.analysis.plots` stays cheap
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _no_offset(ax):
    fmt = ax.yaxis.get_major_formatter()
    if hasattr(fmt, "set_useOffset"):
        fmt.set_useOffset(False)
    if hasattr(fmt, "set_scientific"):
        fmt.set_scientific(False)


def _title(info, what):
    name = info.path.rsplit("/", 1)[-1]
    extra = ""
    if info.model == "constant" and info.restitution is not None:
        extra = f", $\\varepsilon$ = {info.restitution:g}"
    elif info.damping is not None:
        extra = f", damping {info.damping:.3g}"
    eta = info.solid_fraction if math.isfinite(info.solid_fraction) else info.packing_fraction
    method = "DSMC, " if getattr(info, "method", "edmd") == "dsmc" else ""
    return (f"{what}\n{name}: {method}{info.model}{extra}, {info.dimension}D, N = {info.particles}, $\\eta$ = {eta:.3g}"
            + ("" if info.monodisperse else "; polydisperse, theory for particles of the mean diameter"))


def _curve_label(a) -> str:
    """Short name of a cooling analysis's theory curve for a legend."""
    if a.hcs is not None:
        return f"{a.hcs.name}" + (", relaxed from the start" if a.hcs.name != FIRST_SONINE else ", moment equations")
    return "moment equations, first Sonine, exact $\\varepsilon(g)$"


def ratio_limits(ratio) -> tuple[str, float, float]:
    """(scale, low, high) of a T/T_theory axis: linear and symmetric about 1 (at least +-3 %)
    while the ratio stays within a factor 1.5 of 1; beyond, logarithmic from below the
    smallest to above the largest ratio. A ratio is positive: the axis never goes below 0."""
    r = np.asarray(ratio, dtype=float)
    r = r[np.isfinite(r) & (r > 0)]
    lo, hi = (float(r.min()), float(r.max())) if r.size else (1.0, 1.0)
    if hi <= 1.5 and lo >= 1 / 1.5:
        span = max(hi - 1.0, 1.0 - lo, 0.03) * 1.15
        return "linear", 1.0 - span, 1.0 + span
    return "log", min(lo, 1.0) / 1.15, max(hi, 1.0) * 1.15


def plot_cooling(analysis, path):
    """T/T0 against t (log-log) with the kinetic theory, T/T_theory, and a2(t).

    Parameters
    ----------
    analysis : granulargas.analysis.run.CoolingAnalysis
    path : str or Path
        PNG to write.
    """
    plt = _plt()
    a, h, p = analysis, analysis.history, analysis.prediction
    t = a.time
    pos = t > 0
    fig, axes = plt.subplots(3, 1, figsize=(7.0, 9.0), sharex=True, gridspec_kw={"height_ratios": [3, 1.4, 1.4]})
    ax = axes[0]
    ax.loglog(t[pos], h.temperature[pos] / p.T0, ".", ms=3, color="C0", label="simulation")
    ts = np.geomspace(t[pos].min(), t.max(), 300) if np.any(pos) else t
    if a.theory is not None:
        ax.loglog(ts, a.theory.temperature_at(ts) / p.T0, "k-", lw=1.2, label="theory: " + _curve_label(a))
    law = ("$(1+t/\\tau_0)^{-2}$" if p.law == "haff" else "$(1+t/\\tau_0)^{-5/3}$")
    ax.loglog(ts, p.temperature(ts) / p.T0, "--", color="0.55", lw=1,
              label=f"closed form {law}: {p.name}, $\\tau_0$ = {p.tau0:.4g}")
    if a.fit_free is not None:
        f = a.fit_free
        ax.loglog(ts, f(ts) / p.T0, ":", color="C3", lw=1.2,
                  label=f"fit $T_0(1+t/\\tau_0)^{{-p}}$: $\\tau_0$ = {f.tau0:.4g}, p = {f.exponent:.3f}")
    ax.set_ylabel("$T/T_0$")
    ax.legend(fontsize=7.5, loc="lower left")
    ax.set_title(_title(a.info, "Cooling: temperature against time, simulation and kinetic theory"), fontsize=9)

    ax = axes[1]
    r = a.ratio
    ax.axhspan(0.98, 1.02, color="0.9", label="$\\pm$2 %")
    ax.semilogx(t[pos], r[pos], ".", ms=3, color="C0")
    ax.axhline(1.0, color="k", lw=0.8)
    scale, low, high = ratio_limits(r[pos])
    ax.set_yscale(scale)
    ax.set_ylim(low, high)
    if scale == "log":  # plain numbers (0.9, 1, 2, 5) on a ratio axis, not powers of ten
        from matplotlib.ticker import FuncFormatter

        plain = FuncFormatter(lambda v, _: f"{v:g}")
        ax.yaxis.set_major_formatter(plain)
        ax.yaxis.set_minor_formatter(plain)
    _no_offset(ax)
    ax.set_ylabel("$T/T_\\mathrm{theory}$")
    ax.text(0.01, 0.95, f"last 10 % of t: {a.T_ratio_final:.4f};  last decade: {a.T_ratio_last_decade:.4f}",
            transform=ax.transAxes, fontsize=8, va="top")
    ax.legend(fontsize=7.5, loc="upper right")

    ax = axes[2]
    ts_, a2, a3 = a.sonine
    if ts_.size:
        m = ts_ > 0
        ax.plot(ts_[m], a2[m], "o", ms=3, color="C0", label=f"$a_2$ of the snapshots (N = {a.info.particles})")
        ax.plot(ts_[m], a3[m], "s", ms=3, color="C2", alpha=0.6, label="$a_3$ of the snapshots")
        mean, err, count = a.a2_late
        if count:
            w = ts_[a.a2_window]
            ax.fill_between([w[0], w[-1]], mean - err, mean + err, color="C0", alpha=0.3, lw=0,
                            label=f"mean {mean:+.4f} $\\pm$ {err:.1g} ({A2_ERROR_METHOD})")
    if a.theory is not None and np.any(pos):
        ax.plot(ts, a.theory.a2_at(ts), "k-", lw=1.2, label="$a_2(t)$, theory")
    if a.hcs is not None:
        ax.axhline(a.hcs.a2, color="k", lw=0.8, ls=":", label=f"$a_2$ = {a.hcs.a2:+.4f}, {a.hcs.name}")
        if a.hcs.name != FIRST_SONINE:
            fs = float(theory.sonine_a2(a.info.restitution, a.info.dimension))
            ax.axhline(fs, color="0.55", lw=1, ls="--", label=f"$a_2$ = {fs:+.4f}, {FIRST_SONINE}")
    ax.axhline(0.0, color="0.7", lw=0.5)
    ax.set_xscale("log")
    _no_offset(ax)
    ax.set_ylabel("Sonine coefficients")
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 1.2 * (hi - lo))  # room above the points for the legend
    ax.legend(fontsize=7, loc="upper center", ncol=2, framealpha=0.85)
    ax.set_xlabel("time t  [$\\sigma\\,(m/T_0)^{1/2}$]" + (f", since the first sample at {a.t_offset:.4g}"
                                                          if a.t_offset else ""))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _scaled(values):
    """(values / 10^k, k) with k the exponent of the largest magnitude (k = 0 if all zero)."""
    v = np.asarray(values, dtype=float)
    top = np.nanmax(np.abs(v)) if v.size else 0.0
    if not np.isfinite(top) or top == 0.0:
        return v, 0
    k = int(math.floor(math.log10(top)))
    return v / 10.0**k, k


def plot_elastic(analysis, path):
    """Energy drift, Z against the equation of state, collision frequency against Enskog.

    Parameters
    ----------
    analysis : granulargas.analysis.elastic.ElasticAnalysis
    path : str or Path
    """
    plt = _plt()
    a, info = analysis, analysis.info
    s = a.summary()
    fig, axes = plt.subplots(3, 1, figsize=(7.0, 8.5), sharex=True)
    t = a.time

    ax = axes[0]
    drift, k = _scaled(a.energy_drift)
    ax.plot(t, drift, "-", color="C0", lw=1)
    ax.axhline(0.0, color="0.7", lw=0.5)
    top = max(float(np.nanmax(np.abs(drift))), 1.0) if drift.size else 1.0
    ax.set_ylim(-1.2 * top, 1.2 * top)
    _no_offset(ax)
    unit = f"  [$10^{{{k}}}$]" if k else ""
    ax.set_ylabel(f"$(E-E_0)/E_0${unit}", fontsize=9)
    ax.text(0.01, 0.95, "kinetic energy drift (round-off only)" if s["energy_drift_max"] < 1e-9 else
            "kinetic energy drift", transform=ax.transAxes, fontsize=8, va="top")
    ax.set_title(_title(info, "Elastic gas: energy conservation, pressure and collision frequency"), fontsize=9)

    ax = axes[1]
    tz, z = a.Z_windows
    if tz.size:
        ax.plot(tz, z, "o", ms=3, color="C0", label=f"simulation, windows (mean {s['Z']:.4f} $\\pm$ {s['Z_error']:.2g})")
        if s["Z"] is not None and s["Z_error"] is not None:
            ax.axhspan(s["Z"] - s["Z_error"], s["Z"] + s["Z_error"], color="C0", alpha=0.2, lw=0)
    ax.axhline(s["Z_theory"], color="k", lw=1.2, label=f"{s['Z_theory_name']}: {s['Z_theory']:.4f}")
    ax.axhline(s["Z_reference"], color="0.55", lw=1, ls="--", label=f"{s['Z_reference_name']}: {s['Z_reference']:.4f}")
    vals = np.concatenate([z, [s["Z_theory"], s["Z_reference"]]]) if tz.size else np.array([s["Z_theory"]])
    pad = max(0.01 * s["Z_theory"], 1.2 * float(np.max(np.abs(vals - s["Z_theory"]))))
    ax.set_ylim(s["Z_theory"] - pad, s["Z_theory"] + pad)
    _no_offset(ax)
    ax.set_ylabel("$Z = P/(nT)$")
    ax.legend(fontsize=7.5, loc="lower right", framealpha=0.7)

    ax = axes[2]
    tw, om = a.collision_windows
    th = s["collision_frequency_theory"]
    if tw.size:
        ax.plot(tw, om, "o", ms=3, color="C0",
                label=f"simulation (mean {s['collision_frequency']:.5g} $\\pm$ {s['collision_frequency_error']:.2g})")
        if s["collision_frequency_error"] is not None:
            ax.axhspan(s["collision_frequency"] - s["collision_frequency_error"],
                       s["collision_frequency"] + s["collision_frequency_error"], color="C0", alpha=0.2, lw=0)
    ax.axhline(th, color="k", lw=1.2, label=f"Enskog ($\\chi$ of {s['Z_theory_name']}): {th:.5g}")
    vals = np.concatenate([om, [th]]) if tw.size else np.array([th])
    pad = max(0.01 * th, 1.2 * float(np.max(np.abs(vals - th))))
    ax.set_ylim(th - pad, th + pad)
    _no_offset(ax)
    ax.set_ylabel("collisions per particle\nper unit time", fontsize=9)
    ax.legend(fontsize=7.5, loc="lower right", framealpha=0.7)
    ax.set_xlabel(f"time t  [$\\sigma\\,(m/T_0)^{{1/2}}$]; averages from t = {a.t_equilibrated:.3g}")
    for ax in axes[1:]:
        ax.axvline(a.t_equilibrated, color="0.8", lw=0.8, ls=":")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


#: kind -> figure function ``f(analysis, path)``
PLOTS = {"cooling": plot_cooling, "elastic": plot_elastic}


def plot_analysis(analysis, path):
    """The figure of an analysis' kind (:data:`PLOTS`)."""
    return PLOTS[analysis.kind](analysis, path)


def _numeric(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def plot_sweep(results, summaries, path):
    """The fitted quantity against the swept parameter (mean +- standard error over seeds,
    theory beside it) and, for cooling sweeps, T/T_theory against time with its seed band.

    Parameters
    ----------
    results : granulargas.analysis.ensemble.SweepResults
    summaries : list of granulargas.analysis.ensemble.GroupSummary
    path : str or Path
    """
    plt = _plt()
    if not summaries:
        raise ValueError("no finished runs to plot")
    q = summaries[0].quantity
    cooling = summaries[0].kind == "cooling"
    numeric = [k for k in results.varied if all(_numeric(g.parameters.get(k)) for g in summaries)]
    x_key = numeric[0] if numeric else None
    others = [k for k in results.varied if k != x_key]
    fig, axes = plt.subplots(2 if cooling else 1, 1, figsize=(7.0, 8.0 if cooling else 4.8), squeeze=False)
    ax = axes[0, 0]
    series: dict = {}
    for i, g in enumerate(summaries):
        label = ", ".join(f"{k} = {g.parameters.get(k)}" for k in others)
        series.setdefault(label, []).append((g.parameters.get(x_key, i) if x_key else i, g))
    for j, (label, pts) in enumerate(series.items()):
        pts.sort(key=lambda p: p[0])
        x = np.array([p[0] for p in pts], dtype=float)
        y = np.array([p[1].value for p in pts])
        e = np.array([p[1].error if math.isfinite(p[1].error) else 0.0 for p in pts])
        th = np.array([p[1].theory for p in pts])
        seeds = pts[0][1].seeds
        ax.errorbar(x, y, yerr=e, fmt="o", color=f"C{j}", capsize=3,
                    label=f"simulation, mean $\\pm$ s.e. over {seeds} seed{'s' if seeds != 1 else ''}"
                    + (f" ({label})" if label else ""))
        ax.plot(x, th, "-", color=f"C{j}" if label else "k", lw=1, marker="x", ms=5,
                label="kinetic theory" + (f" ({label})" if label else ""))
        for xi, p in zip(x, pts):
            g = p[1]
            if math.isfinite(g.value) and math.isfinite(g.theory) and g.theory:
                ax.annotate(f"{100 * (g.value / g.theory - 1):+.1f} %", (xi, g.value), textcoords="offset points",
                            xytext=(6, -10), fontsize=7, color=f"C{j}")
    ax.set_xlabel(x_key or "parameter set")
    ax.set_ylabel("$\\tau_0$ of $T_0(1+t/\\tau_0)^{-p}$" if q == "tau0" else "$Z = P/(nT)$")
    _no_offset(ax)
    ax.legend(fontsize=7.5, title="percentages: simulation vs theory", title_fontsize=7)
    what = "fitted cooling time $\\tau_0$" if q == "tau0" else "compressibility factor Z"
    ax.set_title(f"Sweep {results.path.name}: {what} against {x_key or 'parameter set'}\n"
                 f"theory: {summaries[0].theory_name}", fontsize=8.5)
    if cooling:
        ax = axes[1, 0]
        ax.axhspan(0.98, 1.02, color="0.92", label="$\\pm$2 %")
        for j, g in enumerate(summaries):
            if g.ratio_time.size == 0:
                continue
            m = g.ratio_time > 0
            t, r, e = g.ratio_time[m], g.ratio_mean[m], g.ratio_error[m]
            label = ", ".join(f"{k} = {v}" for k, v in g.parameters.items()) or f"set {j}"
            ax.plot(t, r, "-", color=f"C{j}", lw=1, label=label)
            if np.all(np.isfinite(e)):
                ax.fill_between(t, r - e, r + e, color=f"C{j}", alpha=0.25, lw=0)
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set_xscale("log")
        _no_offset(ax)
        ax.set_xlabel("time since the first sample  [$\\sigma\\,(m/T_0)^{1/2}$]")
        ax.set_ylabel("$T/T_\\mathrm{theory}$ (mean $\\pm$ s.e. over seeds)")
        ax.set_title("temperature over kinetic theory, seeds averaged (band: standard error)", fontsize=8.5)
        ax.legend(fontsize=7.5)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_driven(analysis, path):
    """T(t) against the relaxation to the theoretical steady state, and the snapshots' a2.

    Parameters
    ----------
    analysis : granulargas.analysis.driven.DrivenAnalysis
    path : str or Path
    """
    plt = _plt()
    a, info = analysis, analysis.info
    s = a.summary()
    fig, axes = plt.subplots(2, 1, figsize=(7.0, 6.5), sharex=True)
    t, T = a.time, a.history.temperature
    ax = axes[0]
    ax.plot(t, T, "-", color="C0", lw=1, label="simulation")
    ax.plot(t, a.temperature_theory(t), "-", color="k", lw=1.2,
            label="theory: $dT/dt = H - \\zeta(T)\\,T$")
    if s.get("T_steady") is not None and math.isfinite(a.theory.temperature):
        ax.axhline(a.theory.temperature, color="k", lw=0.8, ls="--",
                   label=f"theory $T_{{ss}}$ = {a.theory.temperature:.4g}")
        ax.axhspan(s["T_steady"] - (s.get("T_steady_error") or 0), s["T_steady"] + (s.get("T_steady_error") or 0),
                   color="C0", alpha=0.25, lw=0,
                   label=f"simulation $T_{{ss}}$ = {s['T_steady']:.4g} $\\pm$ {s.get('T_steady_error') or 0:.2g}")
    _no_offset(ax)
    ax.set_ylabel("temperature T")
    ax.legend(fontsize=7.5, loc="lower right", framealpha=0.7)
    ax.set_title(_title(info, f"White-noise driven gas, H = {a.heating_rate:.3g}: steady state against "
                              "kinetic theory"), fontsize=9)
    ax = axes[1]
    ts, a2, _ = a.sonine
    if ts.size:
        ax.plot(ts, a2, "o", ms=3, color="C0", label="snapshots")
    if s.get("a2_mean") is not None:
        ax.axhline(s["a2_mean"], color="C0", lw=1, label=f"mean after relaxation {s['a2_mean']:+.4f} (bias removed)")
    ax.axhline(a.theory.a2, color="k", lw=1.2, label=f"van Noije & Ernst (driven) {a.theory.a2:+.4f}")
    ax.axhline(0.0, color="0.7", lw=0.5)
    _no_offset(ax)
    ax.set_ylabel("$a_2$")
    ax.legend(fontsize=7.5, loc="lower right", framealpha=0.7)
    ax.set_xlabel(f"time t  [$\\sigma\\,(m/T_0)^{{1/2}}$]; steady state from t = {a.t_relaxed:.3g}")
    for ax in axes:
        ax.axvline(a.t_relaxed, color="0.8", lw=0.8, ls=":")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


PLOTS["driven"] = plot_driven


def plot_shear(analysis, path):
    """T(t) of a sheared run with the steady part marked, and the steady reduced quantities
    (a*, eta*, P_ii/p) against the Grad solution.

    Parameters
    ----------
    analysis : granulargas.analysis.shear.ShearAnalysis
    path : str or Path
    """
    plt = _plt()
    a, info = analysis, analysis.info
    s = a.summary()
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.2), gridspec_kw={"width_ratios": [1.2, 1.0]})
    ax = axes[0]
    ax.plot(a.time, a.temperature, "-", color="C0", lw=1, label="simulation")
    T_th = a.theory.temperature
    if math.isfinite(T_th):
        ax.axhline(T_th, color="k", lw=1.0, ls="--", label=f"Grad steady T = {T_th:.4g}")
    if s.get("T_steady") is not None:
        e = s.get("T_steady_error") or 0.0
        ax.axhspan(s["T_steady"] - e, s["T_steady"] + e, color="C0", alpha=0.25, lw=0,
                   label=f"steady mean {s['T_steady']:.4g} $\\pm$ {e:.2g}")
    ax.axvline(a.t_relaxed, color="0.7", lw=0.8, ls=":")
    _no_offset(ax)
    ax.set_xlabel(f"time t; steady from t = {a.t_relaxed:.3g}")
    ax.set_ylabel("temperature T (peculiar)")
    ax.legend(fontsize=7.5, framealpha=0.7)
    ax = axes[1]
    keys = [("a_star", "$a^*$"), ("eta_star", "$\\eta^*$"), ("P_xx_over_p", "$P_{xx}/p$"), ("P_yy_over_p", "$P_{yy}/p$")]
    if info.dimension == 3:
        keys.append(("P_zz_over_p", "$P_{zz}/p$"))
    keys.append(("P_xy_over_p", "$P_{xy}/p$"))
    x = np.arange(len(keys))
    sim = np.array([s.get(k) if s.get(k) is not None else np.nan for k, _ in keys], dtype=float)
    err = np.array([s.get(k + "_error") or 0.0 for k, _ in keys], dtype=float)
    th = np.array([s.get(k + "_theory") if s.get(k + "_theory") is not None else np.nan for k, _ in keys],
                  dtype=float)
    ax.errorbar(x - 0.1, sim, yerr=err, fmt="o", color="C0", ms=5, capsize=3, label="simulation (steady)")
    ax.plot(x + 0.1, th, "s", color="k", ms=5, mfc="none", label="Grad solution")
    ax.axhline(0.0, color="0.8", lw=0.5)
    ax.set_xticks(x)
    ax.set_xticklabels([lab for _, lab in keys])
    ax.legend(fontsize=7.5, framealpha=0.7)
    held = "viscous heating = loss" if a.thermostat is None else f"thermostat T = {a.thermostat:g}"
    fig.suptitle(_title(info, f"Uniform shear flow, a = {a.rate:.3g} ({held}) against the Grad solution"), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_vibrated(analysis, path):
    """Figure of a :class:`granulargas.analysis.vibrated.VibratedAnalysis`: the density profile
    (with the hydrostatic one for an elastic gas on a thermal floor), the temperature profile
    along and across the axis, the cumulative energy put in and dissipated, and the centre of
    mass against time."""
    plt = _plt()
    a = analysis
    p = a.profile
    ax_name = "xyz"[a.axis]
    ok = p.counts >= 30
    dist = a.distributions
    fig, axes = plt.subplots(3 if dist is not None else 2, 2, figsize=(10, 11 if dist is not None else 7.5))
    ax = axes[0, 0]
    ax.plot(p.centres, p.density, "o", ms=3, label="measured")
    hyd = a.hydrostatic
    if hyd is not None:
        ax.plot(p.centres, hyd, "k-", lw=1.2, label="hydrostatic, p = n T_w Z(n)")
    ax.set_yscale("log")
    ax.set_xlabel(ax_name)
    ax.set_ylabel("number density n")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    ax.plot(p.centres[ok], p.temperature[ok], "o-", ms=3, label="T")
    ax.plot(p.centres[ok], p.t_along[ok], "^", ms=3, label=f"m<c_{ax_name}^2>")
    ax.plot(p.centres[ok], p.t_across[ok], "v", ms=3, label="across")
    if a.thermal_floor is not None:
        ax.axhline(a.thermal_floor, color="k", lw=1, label="T_w")
    bed = a.bed
    if bed is not None:
        ax.axhline(bed["temperature"], color="k", ls="--", lw=1, label="leading-order bed")
    ax.set_xlabel(ax_name)
    ax.set_ylabel("temperature")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    ax.plot(a.time, a.wall_work - a.wall_work[0], label="put in by the walls")
    ax.plot(a.time, a.dissipated - a.dissipated[0], label="dissipated")
    ax.axvline(a.t_from, color="0.6", lw=0.8)
    ax.set_xlabel("t")
    ax.set_ylabel("energy (cumulative)")
    b = a.balance
    ax.set_title(f"steady state: dissipated / put in = {b.ratio:.4f} ± {b.ratio_error:.2g}", fontsize=9)
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    ax.plot(a.com_time, a.com, "o-", ms=2)
    ax.axvline(a.t_from, color="0.6", lw=0.8)
    ax.set_xlabel("t")
    ax.set_ylabel(f"centre of mass {ax_name}")
    h, he = a.com_height()
    if math.isfinite(h):
        title = f"steady: height above the floor {h:.4g} ± {he:.2g}"
        if math.isfinite(a.plate_velocity):
            title += f" at A omega = {a.plate_velocity:.3g}"
        ax.set_title(title, fontsize=9)
    if dist is not None:
        # the velocity distribution in layers, each component scaled by its layer's temperature
        c = dist.centres
        for j, (ax, hist, label) in enumerate(((axes[2, 0], dist.along, f"c_{ax_name} (m / T_{ax_name})^1/2"),
                                                (axes[2, 1], dist.across, "c across (m / T_across)^1/2"))):
            for i in range(dist.edges.size - 1):
                good = hist[i] > 0
                ax.plot(c[good], hist[i][good], "o", ms=2.5,
                        label=f"{ax_name} {dist.edges[i]:.3g}–{dist.edges[i + 1]:.3g}: "
                              f"a2 = {dist.a2[i, j]:+.3f} ± {dist.kurtosis_error[i, j] / 3:.2g}")
            ax.plot(c, dist.gaussian, "k-", lw=1, label="Gaussian")
            ax.set_yscale("log")
            ax.set_ylim(bottom=max(1e-5, 0.3 / max(float(dist.counts[:, j].max()), 1.0)))
            ax.set_xlabel(f"{label} in layers")
            ax.set_ylabel("probability density")
            ax.legend(fontsize=7)
    fig.suptitle(_title(a.info, "Vibrated gas: profiles, energy balance, centre of mass"
                        + (", velocity distribution in layers" if dist is not None else "")), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_rough(analysis, path):
    """T_tr(t), T_rot(t), theta(t) against the two-temperature theory, and the cumulants.

    Parameters
    ----------
    analysis : granulargas.analysis.rough.RoughAnalysis
    path : str or Path
    """
    plt = _plt()
    a, info = analysis, analysis.info
    h = a.history
    t = h.time
    s = a.summary()
    fig, axes = plt.subplots(3, 1, figsize=(7.0, 9.0), sharex=True)
    tt = np.linspace(t[0], t[-1], 400) if a.driven else np.geomspace(max(t[0], t[1] * 1e-3) if t[0] == 0 else t[0],
                                                                      t[-1], 400)
    ax = axes[0]
    ax.plot(t, h.translational, "-", color="C0", lw=1.2, label="$T_{tr}$")
    ax.plot(t, h.rotational, "-", color="C3", lw=1.2, label="$T_{rot}$")
    ax.plot(tt, a.curve.translational_at(tt), "--", color="k", lw=1, label="theory (Maxwellian energy balances)")
    ax.plot(tt, a.curve.rotational_at(tt), ":", color="k", lw=1)
    ax.set_ylabel("temperature")
    if not a.driven:
        ax.set_xscale("symlog", linthresh=max(t[1] - t[0], 1e-12) if t.size > 1 else 1.0)
        ax.set_yscale("log")
    ax.legend(fontsize=7.5, framealpha=0.7)
    kind = "driven" if a.driven else "freely cooling"
    ax.set_title(_title(info, f"Rough particles ({kind}): two temperatures against theory"), fontsize=9)
    ax = axes[1]
    ax.plot(t, h.ratio, "-", color="C2", lw=1.2, label="$\\theta = T_{rot}/T_{tr}$")
    ax.plot(tt, a.curve.ratio_at(tt), "--", color="k", lw=1, label="theory")
    name = "steady state" if a.driven else "homogeneous cooling state"
    if math.isfinite(a.theta_theory):
        ax.axhline(a.theta_theory, color="0.5", lw=0.8, ls=":", label=f"{name} {a.theta_theory:.4g}")
    if s.get("theta") is not None and math.isfinite(a.t_relaxed):
        err = s.get("theta_error") or 0.0
        ax.fill_between([a.t_relaxed, t[-1]], s["theta"] - err, s["theta"] + err, color="C2", alpha=0.3, lw=0,
                        label=f"simulation, relaxed part: {s['theta']:.4g} $\\pm$ {err:.2g}")
        ax.axvline(a.t_relaxed, color="0.8", lw=0.8, ls=":")
    ax.set_ylabel("$\\theta$")
    ax.legend(fontsize=7.5, framealpha=0.7)
    ax = axes[2]
    for name, color in (("a20", "C0"), ("a02", "C3"), ("a11", "C4")):
        ax.plot(t, getattr(h, name), "-", color=color, lw=1, label=f"$a_{{{name[1:]}}}$")
    ax.axhline(0.0, color="0.7", lw=0.5)
    ax.set_ylabel("cumulants")
    ax.legend(fontsize=7.5, framealpha=0.7)
    ax.set_xlabel("time t  [$\\sigma\\,(m/T_0)^{1/2}$]")
    if not a.driven:
        for ax in axes[1:]:
            ax.set_xscale("symlog", linthresh=max(t[1] - t[0], 1e-12) if t.size > 1 else 1.0)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


PLOTS["vibrated"] = plot_vibrated
PLOTS["rough"] = plot_rough
PLOTS["shear"] = plot_shear


def plot_density_profiles(info, walls: dict, path):
    """Density (packing fraction) across each wall axis, with the bulk value.

    Parameters
    ----------
    info : granulargas.analysis.run.RunInfo
    walls : dict
        :func:`granulargas.analysis.walls.wall_summary`.
    path : str or Path
    """
    from granulargas.analysis.walls import density_profile

    plt = _plt()
    axes_list = walls["axes"]
    fig, axes = plt.subplots(len(axes_list), 1, figsize=(7.0, 3.0 * len(axes_list) + 0.5), squeeze=False)
    t_from = walls.get("t_from", 0.0)
    for ax, a in zip(axes[:, 0], axes_list):
        prof = density_profile(info.path, a, t_from=t_from)
        ax.step(prof.centres, prof.packing, where="mid", color="C0", lw=1,
                label=f"simulation ({prof.frames} snapshots)")
        n_b, eta_b = prof.bulk()
        ax.axhline(eta_b, color="k", lw=1, ls="--", label=f"bulk (middle half): {eta_b:.4g}")
        ax.set_xlim(0.0, float(info.box[a]))
        ax.set_xlabel(f"{'xyz'[a]} across the walls at 0 and {float(info.box[a]):.4g}  [$\\sigma$]")
        ax.set_ylabel("local packing fraction")
        ax.legend(fontsize=7.5, loc="upper center", framealpha=0.7)
    axes[0, 0].set_title(_title(info, "Density across the walls (particle centres, time average)"), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
