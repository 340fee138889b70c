"""Two runs of rough particles and the crossing of their translational temperatures (Mpemba).

Reads two granulargas H5MD files of rough particles (e.g. ``configs/rough_mpemba_hot.toml`` and
``configs/rough_mpemba_cold.toml`` run), integrates the two-temperature theory of each from its
first sample (:func:`granulargas.analysis.rough.rough_gas`, :mod:`granulargas.theory.rough`),
and prints the first time their T_tr cross in the runs (linear interpolation of ln T_tr between
observables samples) and in the theory (:func:`granulargas.theory.rough.mpemba_crossing_time`).

    python scripts/validation/rough_mpemba.py runs/rough_mpemba_hot.h5 runs/rough_mpemba_cold.h5 [--plot runs/mpemba.png]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from granulargas.analysis.rough import rough_gas, rough_history
from granulargas.analysis.run import RunInfo
from granulargas.theory import rough as R


def crossing(times, a, b):
    """First time ln a - ln b changes sign (linear interpolation); nan if never."""
    diff = np.log(a) - np.log(b)
    k = np.flatnonzero(np.sign(diff[1:]) * np.sign(diff[:-1]) < 0)
    if not k.size:
        return math.nan
    i = int(k[0])
    return float(times[i] - diff[i] * (times[i + 1] - times[i]) / (diff[i + 1] - diff[i]))


def load(path):
    info = RunInfo.from_file(path)
    h = rough_history(path, info.particles)
    gas = rough_gas(info, float(h.translational[0]), float(h.rotational[0]))
    return h, R.two_temperature_curve(gas, float(h.time[-1] - h.time[0]))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("first")
    p.add_argument("second")
    p.add_argument("--plot", default=None)
    args = p.parse_args(argv)
    (ha, ca), (hb, cb) = load(args.first), load(args.second)
    t = np.intersect1d(ha.time, hb.time)
    run = crossing(t, np.interp(t, ha.time, ha.translational), np.interp(t, hb.time, hb.translational))
    th = R.mpemba_crossing_time(ca, cb)
    print(f"{args.first}: T_tr {ha.translational[0]:.4g} -> {ha.translational[-1]:.4g}, T_rot {ha.rotational[0]:.4g} -> "
          f"{ha.rotational[-1]:.4g}")
    print(f"{args.second}: T_tr {hb.translational[0]:.4g} -> {hb.translational[-1]:.4g}, T_rot {hb.rotational[0]:.4g} -> "
          f"{hb.rotational[-1]:.4g}")
    print(f"T_tr cross at t = {run:.4g} in the runs, {th if th is None else f'{th:.4g}'} in the theory "
          f"({'no crossing' if th is None else f'{100 * (run / th - 1):+.1f} %'})")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7.0, 4.5))
        tt = np.linspace(0.0, float(t[-1]), 600)
        for h, c, color, name in ((ha, ca, "C3", args.first), (hb, cb, "C0", args.second)):
            label = f"{name.rsplit('/', 1)[-1]}: T_tr(0) = {h.translational[0]:.3g}, T_rot(0) = {h.rotational[0]:.3g}"
            ax.plot(h.time, h.translational, "-", color=color, lw=1.2, label=label)
            ax.plot(tt, c.translational_at(tt), "--", color=color, lw=1, label="theory")
        if th is not None:
            ax.axvline(th, color="k", lw=0.8, label=f"theory: cross at t = {th:.3g}")
        if math.isfinite(run):
            ax.axvline(run, color="k", lw=0.8, ls=":", label=f"runs: cross at t = {run:.3g}")
        ax.set_yscale("log")
        ax.set_xlabel("time")
        ax.set_ylabel("translational temperature $T_{tr}$")
        ax.set_title("Mpemba effect of rough particles: the translational temperatures cross", fontsize=10)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
