"""When does a constant restitution give the viscoelastic T(t)? Advice against real runs.

For a cooling 3D gas (packing 0.1) and several dampings, runs the viscoelastic
rule and the constant eps that ``granulargas advise`` recommends (same config,
same seeds, through :func:`granulargas.run.runner.run_config`), and compares the
measured largest relative error of the seed-averaged T(t) with the advice's
prediction, and the cost (wall time) of both.

    python scripts/validation/rule_choice.py [--quick] [--seeds 3] [--particles 1000] [--end-time 100]

Writes ``docs/figures/choice_rule.png`` and prints a table. The machine is
shared: wall times are medians over seeds, indicative only.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from granulargas.run.advise import advise, DEFAULT_TOLERANCE
from granulargas.io.config import parse_config
from granulargas.io.h5md import read_observables
from granulargas.run.runner import run_config
from granulargas.run import validity as V

BASE = """
[system]
dimension = 3
particles = {n}
packing_fraction = 0.1
seed = {seed}
[collision]
{collision}
[run]
end_time = {t_end}
[output]
file = "{file}"
snapshots = 2
observables_interval = {dt}
"""


def one_run(collision, n, seed, t_end, workdir):
    path = Path(workdir) / f"run_{abs(hash((collision, seed))) % 10**8}.h5"
    cfg = parse_config(BASE.format(n=n, seed=seed, collision=collision, t_end=t_end, file=path, dt=t_end / 100),
                       source="rule_choice")
    summary = run_config(cfg, overwrite=True, quiet=True)
    _, t, T = read_observables(path)["temperature"]
    path.unlink()
    return np.asarray(t), np.asarray(T), summary.wall_time, summary.collisions


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, to check the script")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--particles", type=int, default=2000)
    ap.add_argument("--end-time", type=float, default=100.0)
    ap.add_argument("--out", default="docs/figures/choice_rule.png")
    args = ap.parse_args(argv)
    dampings = [0.003, 0.01, 0.03, 0.1, 0.3]
    n, seeds, t_end = args.particles, args.seeds, args.end_time
    if args.quick:
        dampings, n, seeds, t_end = [0.01, 0.1], 300, 2, 20.0
    wall0 = time.perf_counter()
    rows = []
    with tempfile.TemporaryDirectory() as work:
        one_run('model = "elastic"', max(n, 300), 1, 0.1, work)  # JIT compile/load, not timed
        for b in dampings:
            visco = f'model = "viscoelastic"\ndamping = {b}'
            cfg = parse_config(BASE.format(n=n, seed=1, collision=visco, t_end=t_end, file="x.h5", dt=1.0))
            adv = advise(cfg)
            const = f'model = "constant"\nrestitution = {adv.eps_best!r}'
            ratios, wall_v, wall_c, coll_v = [], [], [], []
            for seed in range(1, seeds + 1):
                t, Tv, wv, cv = one_run(visco, n, seed, t_end, work)
                _, Tc, wc, _ = one_run(const, n, seed, t_end, work)
                ratios.append(Tc / Tv)
                wall_v.append(wv)
                wall_c.append(wc)
                coll_v.append(cv)
            ratios = np.array(ratios)
            mean = ratios.mean(axis=0) - 1.0
            sem = ratios.std(axis=0, ddof=1) / np.sqrt(seeds) if seeds > 1 else np.zeros_like(mean)
            k = int(np.argmax(np.abs(mean)))
            gas = V.gas_from_config(cfg)
            curve = V.viscoelastic_cooling(gas)
            from granulargas.run.advise import _haff
            predicted = _haff(gas, adv.eps_best, t) / curve.temperature_at(t) - 1.0
            rows.append(dict(b=b, eps=adv.eps_best, pred=adv.error, meas=abs(mean[k]), sem=sem[k], t=t,
                             curve=mean, curve_sem=sem, curve_pred=predicted,
                             wall_v=float(np.median(wall_v)), wall_c=float(np.median(wall_c)),
                             coll=float(np.median(coll_v)), spread=adv.spread))
            r = rows[-1]
            print(f"damping {b:6.3g}: eps spread {r['spread']['eps_min']:.3f}..{r['spread']['eps_max']:.3f}, "
                  f"best const eps {r['eps']:.4f}; max |T_c/T_v - 1| predicted {100 * r['pred']:.2f} %, "
                  f"measured {100 * r['meas']:.2f} +- {100 * r['sem']:.2f} %; wall/run visco {r['wall_v']:.2f} s, "
                  f"const {r['wall_c']:.2f} s ({r['coll']:.3g} collisions)", flush=True)
    print(f"total wall time {time.perf_counter() - wall0:.0f} s (N = {n}, {seeds} seeds, t_end = {t_end:g})")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.8))
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(rows)))
    for r, c in zip(rows, colors):
        ax1.plot(r["t"], 100 * r["curve"], color=c, lw=1.8, label=f"damping {r['b']:g} (eps = {r['eps']:.3f})")
        ax1.fill_between(r["t"], 100 * (r["curve"] - r["curve_sem"]), 100 * (r["curve"] + r["curve_sem"]),
                         color=c, alpha=0.2, lw=0)
        ax1.plot(r["t"], 100 * r["curve_pred"], color=c, ls="--", lw=1)
    ax1.axhspan(-100 * DEFAULT_TOLERANCE, 100 * DEFAULT_TOLERANCE, color="0.9", zorder=0)
    ax1.set_xlabel("time t  [sigma sqrt(m/T0)]")
    ax1.set_ylabel("T_const(t) / T_visco(t) - 1  [%]")
    ax1.set_title("best constant eps vs viscoelastic rule\n(solid: runs, mean of seeds; dashed: advice; grey: 2 %)",
                  fontsize=10)
    ax1.legend(fontsize=8)
    bs = np.array([r["b"] for r in rows])
    for r, c in zip(rows, colors):
        ax2.errorbar(r["wall_c"], 100 * r["meas"], yerr=100 * r["sem"], fmt="s", color=c, ms=7, capsize=3)
        ax2.plot(r["wall_c"], 100 * r["pred"], "x", color=c, ms=9)
        ax2.plot(r["wall_v"], 100 * 2 * r["sem"] + 1e-3, "o", mfc="none", color=c, ms=8)
    ax2.axhline(100 * DEFAULT_TOLERANCE, color="0.5", ls=":")
    ax2.set_yscale("log")
    ax2.set_xlabel("wall time per run [s] (shared machine)")
    ax2.set_ylabel("largest error of T(t) over the run [%]")
    ax2.plot([], [], "ks", label="constant eps, measured (+- s.e.)")
    ax2.plot([], [], "kx", label="constant eps, predicted by advise")
    ax2.plot([], [], "ko", mfc="none", label="viscoelastic: 2 x s.e. (reference)")
    ax2.legend(fontsize=8, loc="lower right")
    ax2.set_title(f"error against cost (N = {n}, packing 0.1, t_end = {t_end:g})", fontsize=10)
    fig.tight_layout()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")
    _ = bs


if __name__ == "__main__":
    main()
