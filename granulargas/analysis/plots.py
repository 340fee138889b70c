"""Figures for one run (matplotlib, Agg backend; imported lazily by the CLI)."""

from __future__ import annotations

import numpy as np


def _plt():
    # matplotlib is imported when a figure is drawn: `import granulargas.analysis.plots` stays cheap
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def plot_cooling(analysis, path):
    """T/T0 against t/tau0 (log-log) with theory, ratio to theory, and a2(t).

    Parameters
    ----------
    analysis : granulargas.analysis.run.CoolingAnalysis
    path : str or Path
        PNG to write.
    """
    plt = _plt()
    h, p = analysis.history, analysis.prediction
    t = h.time - analysis.t_offset
    tau = p.tau0 if np.isfinite(p.tau0) else 1.0
    fig, axes = plt.subplots(3, 1, figsize=(6.4, 8.0), sharex=True, gridspec_kw={"height_ratios": [3, 1.3, 1.3]})
    x = t / tau
    pos = x > 0
    ax = axes[0]
    ax.loglog(x[pos], h.temperature[pos] / p.T0, ".", ms=3, label="simulation")
    xs = np.geomspace(max(x[pos].min(), 1e-3), x.max(), 200)
    ax.loglog(xs, p.temperature(xs * tau) / p.T0, "k-", lw=1, label=f"theory ({p.law}, $\\tau_0$={p.tau0:.4g})")
    if analysis.fit_free is not None:
        f = analysis.fit_free
        ax.loglog(xs, f(xs * tau) / p.T0, "r--", lw=1, label=f"fit: $\\tau_0$={f.tau0:.4g}, exponent {-f.exponent:.3f}")
    ax.set_ylabel("$T/T_0$")
    ax.legend(fontsize=8)
    ax.set_title(f"{analysis.info.path}: {analysis.info.model}, d={analysis.info.dimension}, "
                 f"N={analysis.info.particles}, $\\eta$={analysis.info.packing_fraction:.3g}", fontsize=8)
    ax = axes[1]
    ax.semilogx(x[pos], h.temperature[pos] / p.temperature(t[pos]), ".", ms=3)
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_ylabel("$T/T_{theory}$")
    ax = axes[2]
    ts, a2, a3 = analysis.sonine
    if ts.size:
        m = ts > 0
        ax.semilogx(ts[m] / tau, a2[m], "o-", ms=3, label="$a_2$")
        ax.semilogx(ts[m] / tau, a3[m], "s-", ms=3, label="$a_3$")
        if p.law == "haff":
            ax.axhline(p.a2, color="k", lw=0.8, ls="--", label="$a_2$ van Noije-Ernst")
        ax.legend(fontsize=8)
    ax.axhline(0.0, color="0.7", lw=0.5)
    ax.set_ylabel("Sonine coefficients")
    ax.set_xlabel("$t/\\tau_0$ (theory)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
