"""Cooling of granular gases against kinetic theory, several seeds per case.

Runs (or, with --reuse, reads) three kinds of cooling runs and compares them with
:mod:`granulargas.theory`:

1. constant restitution eps = 0.9, 3D, packing 0.05, box below the shear-instability
   length: Haff's law T = T0 / (1 + t/tau0)^2; the theory drawn is the one
   ``granulargas analyze`` uses (``theory.gas.cooling_curve``: the cooling rate and a2 of the
   homogeneous cooling state from ``theory.hcs``, relaxed from the Maxwellian start);
2. viscoelastic particles, 3D, packing 0.1, small damping: against the same theory as
   ``granulargas analyze`` (``theory.gas.cooling_curve``: the moment equations with the exact
   eps(g)); the leading-order law T = T0 (1 + t/tau0)^(-5/3) (``theory.viscoelastic_tau0``)
   gives the exponent and the time axis;
3. the same constant-restitution gas in 2D (packing 0.1, eps = 0.9) in a box below
   and in a box three times above the instability length L_c: the large box leaves
   Haff's law once shear modes and clusters grow.

Writes ``docs/figures/cooling_haff.png`` (cases 1-2: T/T0 vs t/tau0 with the theory,
T/T_theory with seed-spread bands, local exponent, a2(t)) and
``docs/figures/cooling_instability.png`` (case 3), and prints measured against
predicted tau0 and exponents.

    python scripts/validation/haff_comparison.py                # ~10 min on 2 cores
    python scripts/validation/haff_comparison.py --quick        # smaller, to check the script
    python scripts/validation/haff_comparison.py --reuse        # re-analyse existing runs
    python scripts/validation/haff_comparison.py --no-instability   # only cases 1-2 (cooling_haff.png)
    python scripts/validation/haff_comparison.py --a2-scan      # only: HCS a2 against the references, eps 0.3-0.9 (~3 min)
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

from granulargas import theory as th
from granulargas.analysis.cooling import local_exponent
from granulargas.analysis.run import analyze_cooling
from granulargas.theory.hcs import FIRST_SONINE, hcs_reference

TEMPLATE = """
[system]
dimension = {dim}
particles = {n}
packing_fraction = {eta}
seed = {seed}

[collision]
{collision}

[run]
end_time = {end}

[output]
file = "{file}"
snapshots = {snapshots}
first_snapshot = {first}
observables_interval = {dt}
"""


def run_case(outdir, name, dim, n, eta, seed, collision, end, dt, snapshots, first, reuse):
    from granulargas.io.config import parse_config
    from granulargas.run.runner import run_config

    path = Path(outdir) / f"{name}_seed{seed}.h5"
    if reuse and path.exists():
        return path
    path.parent.mkdir(parents=True, exist_ok=True)
    text = TEMPLATE.format(dim=dim, n=n, eta=eta, seed=seed, collision=collision, end=end, dt=dt,
                           snapshots=snapshots, first=first, file=path)
    t = time.perf_counter()
    s = run_config(parse_config(text, source=name), overwrite=True)
    print(f"  ran {path.name}: {s.collisions} collisions, {time.perf_counter() - t:.1f} s", flush=True)
    return path


def seed_band(analyses, grid):
    """T/T_theory (the theory of ``granulargas analyze``, ``CoolingAnalysis.ratio``) of each seed
    interpolated on ``grid`` (in t/tau0 of the closed form): mean, std."""
    rows = []
    for a in analyses:
        x = a.time / a.prediction.tau0
        rows.append(np.interp(grid, x, a.ratio, left=np.nan, right=np.nan))
    rows = np.array(rows)
    return np.nanmean(rows, axis=0), np.nanstd(rows, axis=0, ddof=1) if len(rows) > 1 else np.zeros(len(grid))


def summarize(label, analyses):
    p = analyses[0].prediction
    tau = np.array([a.fit.tau0 for a in analyses])
    expo = np.array([a.fit_free.exponent for a in analyses])
    ns = len(analyses)
    sem = lambda v: v.std(ddof=1) / math.sqrt(ns) if ns > 1 else float("nan")  # noqa: E731
    print(f"\n{label}  ({ns} seeds, N = {analyses[0].info.particles}, packing {analyses[0].info.packing_fraction:.3g}, "
          f"L = {analyses[0].info.box[0]:.3g}, L_c = {p.instability_length:.3g})")
    print(f"  theory: {analyses[0].theory_name}\n  T/T_theory over the last 10 % of the time: "
          + ", ".join(f"{a.T_ratio_final:.4f}" for a in analyses))
    print(f"  tau0 closed form ({p.name}) {p.tau0:.5g}   measured {tau.mean():.5g} +- {sem(tau):.2g} (seed s.e.m.)"
          f"   deviation {100 * (tau.mean() / p.tau0 - 1):+.2f} %  (per seed: "
          + ", ".join(f"{100 * (x / p.tau0 - 1):+.2f}" for x in tau) + ")")
    if math.isfinite(p.tau0_second_order):
        print(f"  tau0 with the beta^2 term {p.tau0_second_order:.5g}: deviation {100 * (tau.mean() / p.tau0_second_order - 1):+.2f} %")
    print(f"  exponent predicted -{p.exponent:.4f}   measured -{expo.mean():.4f} +- {sem(expo):.2g}"
          f"   (per seed: " + ", ".join(f"-{x:.4f}" for x in expo) + ")")
    return tau.mean(), expo.mean()


def figure_cooling(cases, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 2, figsize=(11, 8))
    colors = {"const": "C0", "visco": "C3"}
    for key, (label, analyses) in cases.items():
        c = colors[key]
        p = analyses[0].prediction
        xmax = min((a.history.time[-1] - a.t_offset) / p.tau0 for a in analyses)
        grid = np.geomspace(1e-2, xmax, 300)
        for i, a in enumerate(analyses):
            t = a.history.time - a.t_offset
            m = t > 0
            ax[0, 0].loglog(t[m] / p.tau0, a.history.temperature[m] / p.T0, color=c, lw=0.6, alpha=0.6,
                            label=f"{label} ({len(analyses)} seeds)" if i == 0 else None)
            ts, a2, _ = a.sonine
            ms = ts > 0
            ax[1, 1].semilogx(ts[ms] / p.tau0, a2[ms], "o", color=c, ms=2.5, alpha=0.5,
                              label=f"{label}: $a_2$ per snapshot" if i == 0 else None)
        a0 = analyses[0]
        name = ("Enskog-Boltzmann, DSMC-table cooling rate" if a0.hcs is not None
                else "moment equations, exact $\\varepsilon(g)$")
        ax[0, 0].loglog(grid, a0.theory.temperature_at(grid * p.tau0) / p.T0, "k--", lw=1)
        ax[0, 0].plot([], [], ls="none", label=f"  theory: {name}")
        mean, std = seed_band(analyses, grid)
        ax[0, 1].semilogx(grid, mean, color=c, label=label)
        ax[0, 1].fill_between(grid, mean - std, mean + std, color=c, alpha=0.25, lw=0)
        # local exponent of the seed-averaged curve, against ln(1 + t/tau0)
        tt = analyses[0].history.time - analyses[0].t_offset
        TT = np.mean([np.interp(tt, a.history.time - a.t_offset, a.history.temperature) for a in analyses], axis=0)
        sel = np.unique(np.searchsorted(tt, np.geomspace(0.05 * p.tau0, tt[-1], 25)).clip(0, tt.size - 1))
        tm, slope = local_exponent(tt[sel], TT[sel], p.tau0)
        ax[1, 0].semilogx(tm / p.tau0, slope, "o-", color=c, ms=3, label=label)
        ax[1, 0].axhline(-p.exponent, color=c, ls="--", lw=0.8)
        # a2 seed average per snapshot time
        ts0 = analyses[0].sonine[0]
        a2m = np.mean([a.sonine[1][: ts0.size] for a in analyses], axis=0)
        ms = ts0 > 0
        ax[1, 1].semilogx(ts0[ms] / p.tau0, a2m[ms], "-", color=c, lw=1.5, label=f"{label}: seed mean")
        tg = np.geomspace(1e-2, xmax, 200) * p.tau0
        ax[1, 1].semilogx(tg / p.tau0, a0.theory.a2_at(tg), "--", color=c, lw=0.9, label=f"{label}: theory")
    ax[0, 0].plot([], [], "k--", label="theory, as granulargas analyze")
    ax[0, 0].set(xlabel="$t/\\tau_0$ (closed form)", ylabel="$T/T_0$", title="temperature")
    ax[0, 0].legend(fontsize=8)
    ax[0, 1].axhline(1, color="k", lw=0.8)
    ax[0, 1].set(xlabel="$t/\\tau_0$ (closed form)", ylabel="$T/T_{theory}$",
                 title="ratio to the theory of granulargas analyze\n(band: $\\pm 1\\sigma$ seed-to-seed)")
    ax[0, 1].legend(fontsize=8)
    ax[1, 0].set(xlabel="$t/\\tau_0$ (closed form)", ylabel="$d\\ln T/d\\ln(1+t/\\tau_0)$",
                 title="local exponent (dashed: -2 and -5/3)")
    ax[1, 0].legend(fontsize=8)
    ax[1, 1].axhline(0, color="0.6", lw=0.5)
    ax[1, 1].set(xlabel="$t/\\tau_0$ (closed form)", ylabel="$a_2$", title="second Sonine coefficient")
    ax[1, 1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")


def figure_instability(small, large, path):
    """small, large: lists of CoolingAnalysis (seeds) below and above L_c."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from granulargas.io.h5md import load_snapshot

    fig = plt.figure(figsize=(12, 4.2))
    ax0 = fig.add_subplot(1, 3, 1)
    for g, c in ((small, "C0"), (large, "C3")):
        a = g[0]
        p = a.prediction
        t = a.history.time - a.t_offset
        m = t > 0
        L = a.info.box[0]
        r = np.array([np.interp(t, b.history.time - b.t_offset, b.history.temperature) for b in g]) / p.temperature(t)
        lab = f"L = {L:.0f} = {L / p.instability_length:.2f} $L_c$ (N = {a.info.particles}"
        lab += f", mean of {len(g)} seeds)" if len(g) > 1 else ")"
        ax0.semilogx(t[m] / p.tau0, r.mean(axis=0)[m], color=c, label=lab)
        if len(g) > 1:
            sd = r.std(axis=0, ddof=1)
            ax0.fill_between(t[m] / p.tau0, (r.mean(axis=0) - sd)[m], (r.mean(axis=0) + sd)[m], color=c, alpha=0.25, lw=0)
    ax0.axhline(1, color="k", lw=0.8)
    a = small[0]
    ax0.set(xlabel="$t/\\tau_0$ (Haff)", ylabel="$T/T_{Haff}$",
            title=f"2D, $\\epsilon$ = {a.info.restitution}, packing {a.info.packing_fraction:.2g}, "
                  f"$L_c$ = {a.prediction.instability_length:.1f}")
    ax0.legend(fontsize=8)
    for k, a in enumerate((small[0], large[0])):
        s = load_snapshot(a.info.path, -1)
        ax = fig.add_subplot(1, 3, 2 + k)
        ax.scatter(s.positions[:, 0], s.positions[:, 1], s=0.3 if a.info.particles > 2000 else 2, c="k", lw=0)
        ax.set_aspect("equal")
        ax.set(xlim=(0, s.box[0]), ylim=(0, s.box[1]), xticks=[], yticks=[])
        ax.set_title(f"L = {a.info.box[0]:.0f} ({a.info.box[0] / a.prediction.instability_length:.2f} $L_c$), "
                     f"t = {s.time / a.prediction.tau0:.0f} $\\tau_0$", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")


def a2_scan(outdir, seeds, reuse, eps_values=(0.3, 0.5, 0.7, 0.9)):
    """HCS a2 (3D, packing 0.05, box 0.5 L_c, snapshots every 30/39 tau0 after 2 tau0)."""
    from granulargas.analysis.run import sonine_history
    from granulargas.io.config import parse_config
    from granulargas.run.runner import run_config

    eta = 0.05
    n = th.number_density(eta, 3)
    print(f"\nHCS a2, 3D, packing {eta}, L = 0.5 L_c, {len(seeds)} seeds (error: seed-to-seed scatter of the "
          f"seed means / sqrt(seeds))")
    for eps in eps_values:
        N = int(n * (0.5 * th.instability_length(eps, n)) ** 3)
        tau0 = th.haff_tau0(eps, n)
        vals = []
        for seed in seeds:
            path = Path(outdir) / f"a2_eps{eps}_N{N}_seed{seed}.h5"
            if not (reuse and path.exists()):
                path.parent.mkdir(parents=True, exist_ok=True)
                text = TEMPLATE.format(dim=3, n=N, eta=eta, seed=seed,
                                       collision=f'model = "constant"\nrestitution = {eps}\ntc_time = 1e-4',
                                       end=30 * tau0, dt=tau0, snapshots=1, first=1.0, file=path)
                text = text.replace("snapshots = 1\nfirst_snapshot = 1.0", f"snapshot_interval = {30 * tau0 / 39}")
                run_config(parse_config(text, source="a2"), overwrite=True)
            t, a2, _ = sonine_history(path)
            vals.append(a2[t > 2 * tau0])
        means = np.array([x.mean() for x in vals])
        ref = hcs_reference(eps, 3)
        print(f"  eps {eps}: N = {N}, a2 = {means.mean():+.4f} +- {means.std(ddof=1) / math.sqrt(means.size):.4f}"
              f" ({sum(x.size for x in vals)} snapshots)   {ref.name} {ref.a2:+.4f} +- {ref.a2_error:.4f}"
              f"   {FIRST_SONINE} {th.sonine_a2(eps, 3):+.4f}", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--outdir", default="runs/haff_comparison")
    ap.add_argument("--figdir", default="docs/figures")
    ap.add_argument("--reuse", action="store_true", help="analyse existing run files instead of re-running")
    ap.add_argument("--quick", action="store_true", help="small, short runs (checks the script, not the physics)")
    ap.add_argument("--a2-scan", action="store_true", help="only the HCS a2 scan over eps (20 seeds)")
    ap.add_argument("--no-instability", action="store_true", help="only cases 1-2 (cooling_haff.png)")
    args = ap.parse_args(argv)
    if args.a2_scan:
        a2_scan(args.outdir, list(range(1, (3 if args.quick else 20) + 1)), args.reuse)
        return 0

    q = args.quick
    seeds = list(range(1, (2 if q else args.seeds) + 1))
    Path(args.figdir).mkdir(parents=True, exist_ok=True)

    # 1. Haff, 3D, eps = 0.9, packing 0.05: L/L_c = 0.49 for N = 2000
    eps, eta, n = 0.9, 0.05, (500 if q else 2000)
    tau_h = th.haff_tau0(eps, th.number_density(eta, 3))
    span = 20 if q else 100
    const = [analyze_cooling(run_case(args.outdir, f"haff3d_N{n}", 3, n, eta, s, f'model = "constant"\nrestitution = {eps}',
                                      span * tau_h, tau_h / 20, 30, 0.02 * tau_h, args.reuse)) for s in seeds]
    # 2. viscoelastic, 3D, damping 0.02, packing 0.1
    k, eta_v, n_v = 0.02, 0.1, (500 if q else 2000)
    tau_v = th.viscoelastic_tau0(k, th.number_density(eta_v, 3))
    visco = [analyze_cooling(run_case(args.outdir, f"visco3d_N{n_v}", 3, n_v, eta_v, s, f'model = "viscoelastic"\ndamping = {k}',
                                      span * tau_v, tau_v / 20, 30, 0.02 * tau_v, args.reuse)) for s in seeds]
    summarize(f"constant restitution {eps}, 3D (Haff)", const)
    summarize(f"viscoelastic, damping {k}, 3D", visco)
    figure_cooling({"const": (f"$\\epsilon$ = {eps}", const), "visco": (f"viscoelastic, damping {k}", visco)},
                   Path(args.figdir) / "cooling_haff.png")

    if args.no_instability:
        return 0
    # 3. 2D below / above the instability length (same eps and density). Late-time T of a
    # small system random-walks with its collision count (a 1.5 % spread in collisions
    # per particle is a 10 % spread in T after 70 collisions), so the small box gets
    # several seeds. The TC model (tc_time = 1e-4, far below the mean free time) guards
    # the large box against inelastic collapse inside clusters.
    eta2 = 0.1
    n2 = th.number_density(eta2, 2)
    lc = th.instability_length(eps, n2, 2)
    tau2 = th.haff_tau0(eps, n2, dim=2)
    span2 = 30 if q else 300
    coll2 = f'model = "constant"\nrestitution = {eps}\ntc_time = 1e-4'
    groups = []
    for ratio, seeds2 in ((0.6, seeds), (1.5 if q else 3.0, [1])):
        N = int(round(n2 * (ratio * lc) ** 2))
        groups.append([analyze_cooling(run_case(args.outdir, f"haff2d_L{ratio:g}Lc_N{N}", 2, N, eta2, s, coll2,
                                                span2 * tau2, tau2 / 10, 20, 0.1 * tau2, args.reuse), with_sonine=False)
                       for s in seeds2])
    for g in groups:
        a = g[0]
        t = a.history.time - a.t_offset
        r = np.array([np.interp(t, b.history.time - b.t_offset, b.history.temperature) for b in g]) / a.prediction.temperature(t)
        print(f"\n2D eps = {eps}, packing {eta2}: L = {a.info.box[0]:.1f} = {a.info.box[0] / lc:.2f} L_c (N = {a.info.particles},"
              f" {len(g)} seeds): T/T_Haff at t = {t[-1] / tau2:.0f} tau0: {r[:, -1].mean():.3f}"
              f" (seeds {', '.join(f'{x:.3f}' for x in r[:, -1])}), largest seed-mean {r.mean(axis=0).max():.3f}")
    figure_instability(groups[0], groups[1], Path(args.figdir) / "cooling_instability.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
