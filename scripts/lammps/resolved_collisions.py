"""Instantaneous EDMD, resolved EDMD and LAMMPS: a dilute soft cooling gas at several contact times.

``python scripts/lammps/resolved_collisions.py [--fractions 0.01 0.03 0.1 0.15 0.2] [--seeds 8] [--particles 2000]
[--packing 0.05] [--damping 0.1] [--end 20] [--steps-per-contact 10 20 40 80] [--workdir DIR]
[--figure PNG] [--reuse]``

For each contact-time ratio f = <t_c> omega at T0
(:func:`granulargas.run.validity.contact_time_ratio`: collision-averaged contact
duration over the mean free time) a 3D frictionless viscoelastic gas on the
material route (``[collision.material]`` in units where diameter, mass and
sqrt(T0/m) are 1: diameter 1, density 6/pi, speed_unit 1) with the Young modulus
Y that gives f, and the dissipation time A that keeps the damping (beta at g = 1
of two reference particles, ``--damping``) the same for all f, so all gases share
eps(g) and differ only in the contact's duration. From the same initial state
(seeds 1..``--seeds``) it runs

* the engine with ``[collision] duration = "instantaneous"``,
* the engine with ``duration = "resolved"`` (and its three-body count),
* LAMMPS (``pair_style granular``, hertz/material + damping viscoelastic,
  frictionless, :func:`granulargas.dem.export.export_lammps` with the material
  stiffness) at each of ``--steps-per-contact`` (timestep = elastic Hertz contact
  time at the thermal impact speed / n); the finest step is the reference.

Measured for each run: T(t) (LAMMPS: kinetic plus the elastic energy stored in
its contacts, the one the engine's jump leaves none of; also the kinetic T alone);
the collisions (LAMMPS: pairs in contact that were not at the step before,
:func:`granulargas.dem.lammps.read_contacts`); the
pressure (kinetic + pair virial, averaged over each sampling interval; the
engine's collisional virial of the resolved contact includes the kinetic term of
the virtual lines, docs/engine.md). Per seed, each run's deviation from the
LAMMPS reference run of the same initial state: T averaged over the second half
of the run, the collision count at the end, the pressure averaged over the run;
printed as mean +- standard error over the seeds; also P / (n T), the pressure
with the difference in T taken out. Costs are CPU times (the machine may be
shared): the engine's whole ``run_config`` (JIT compiled beforehand), LAMMPS's
loop time less its output time (the contact dump for the count) times the CPU
use it reports; medians over the seeds, one process at a time (wall times are
printed too).

Writes ``DIR/results.json`` (default ``runs/resolved_lammps``) and a figure
(default ``docs/figures/resolved_lammps.png``): error in T, collision count and
pressure and P / (n T) against CPU time, and T(t) / T_LAMMPS(t) - 1.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]

CONFIG = """
[system]
dimension = 3
particles = {n}
packing_fraction = {packing}
seed = {seed}

[collision]
model = "viscoelastic"
duration = "{duration}"

[collision.material]
young_modulus = {young!r}
poisson_ratio = {poisson!r}
dissipation_time = {dissipation!r}
diameter = 1.0
density = {density!r}
speed_unit = 1.0

[run]
end_time = {end!r}

[output]
file = "{out}"
observables_interval = {interval!r}
snapshot_interval = {end!r}
"""

POISSON = 0.3
SAMPLES = 40


def config_text(args, young, seed, duration, out):
    from granulargas.contact.material import dissipation_time_from_prefactor, prefactor_from_damping

    dissipation = dissipation_time_from_prefactor(prefactor_from_damping(args.damping), young, POISSON)
    return CONFIG.format(n=args.particles, packing=args.packing, seed=seed, duration=duration, young=young,
                         poisson=POISSON, dissipation=dissipation, density=6.0 / math.pi, end=args.end,
                         interval=args.end / SAMPLES, out=out)


def young_for_fraction(args, fraction, workdir):
    """Y whose contact-time ratio at T0 is ``fraction`` (damping held fixed)."""
    from scipy.optimize import brentq

    from granulargas.io.config import parse_config
    from granulargas.run.validity import contact_time_ratio

    def ratio(log_y):
        cfg = parse_config(config_text(args, math.exp(log_y), 1, "instantaneous", workdir / "x.h5"), source="probe")
        return math.log(contact_time_ratio(cfg) / fraction)

    return math.exp(brentq(ratio, math.log(1e-2), math.log(1e12), xtol=1e-10))


def run_engine(args, young, seed, duration, workdir, reuse):
    from granulargas.io.config import parse_config
    from granulargas.io.h5md import read_observables
    from granulargas.run.runner import run_config

    result = workdir / f"{duration}.json"
    if reuse and result.exists():
        return json.loads(result.read_text())
    out = workdir / f"{duration}.h5"
    cfg = parse_config(config_text(args, young, seed, duration, out), source=f"{duration} seed {seed}")
    cpu = time.process_time()
    summary = run_config(cfg, overwrite=True, quiet=True)
    cpu = time.process_time() - cpu
    obs = read_observables(out)
    res = {"t": obs["temperature"][1].tolist(), "T": obs["temperature"][2].tolist(),
           "collisions": obs["collisions"][2].astype(float).tolist(), "P": obs["pressure"][2].tolist(),
           "wall": summary.wall_time, "cpu": cpu, "total_collisions": summary.collisions,
           "three_body": summary.three_body_contacts}
    result.write_text(json.dumps(res))
    out.unlink()
    return res


def run_dem(args, young, seed, steps_per_contact, workdir, reuse):
    from granulargas.dem.export import export_lammps
    from granulargas.dem.lammps import loop_time, output_time, read_contacts, read_thermo, run_lammps
    from granulargas.io.config import parse_config
    from granulargas.run.prepare import initial_state

    d = workdir / f"lammps_n{steps_per_contact}"
    result = d / "result.json"
    if reuse and result.exists():
        res = json.loads(result.read_text())
        res["cpu"] = lammps_cpu((d / "log.lammps").read_text())
        return res
    cfg = parse_config(config_text(args, young, seed, "instantaneous", workdir / "unused.h5"), source=f"seed {seed}")
    ex = export_lammps(cfg, d, contact_fraction=None, steps_per_contact=steps_per_contact, pressure=True,
                       contact_pairs=True)
    t0 = time.perf_counter()
    text = run_lammps(ex.input_file)
    wall = time.perf_counter() - t0
    th = read_thermo(d / "log.lammps")
    state = initial_state(cfg)
    n = len(state.radii)
    steps, new, elastic = read_contacts(d / "contacts.granulargas", state.radii, ex.contact)
    cumulative = np.cumsum(new)
    coll = np.interp(th["Step"], steps, cumulative)
    # c_granT = m<c^2>/3 over N particles (temp/com with extra/dof 0), as the engine's T
    T_kin = th["c_granT"]
    T_energy = T_kin + 2.0 * np.interp(th["Step"], steps, elastic) / (3 * n)
    res = {"t": th["Time"].tolist(), "T": T_energy.tolist(), "T_kinetic": T_kin.tolist(),
           "collisions": coll.tolist(),
           "P": th["f_granP"].tolist(), "wall": loop_time(text) - output_time(text), "wall_process": wall,
           "cpu": lammps_cpu(text),
           "total_collisions": int(cumulative[-1]), "timestep": ex.timestep, "steps": ex.steps,
           "young_modulus": ex.contact.young_modulus, "hertz_fraction": ex.contact_fraction}
    result.write_text(json.dumps(res))
    (d / "contacts.granulargas").unlink()
    return res


QUANTITIES = ("T", "collisions", "pressure", "T_kinetic", "Z")


def lammps_cpu(text):
    """CPU time of a LAMMPS run without its output: (loop time - output time) x the CPU use it reports."""
    import re

    from granulargas.dem.lammps import loop_time, output_time

    use = float(re.search(r"([0-9.]+)% CPU use", text).group(1)) / 100
    return (loop_time(text) - output_time(text)) * use


def deviations(run, ref, end):
    """Relative deviations of ``run`` from ``ref`` (module doc), in the order of QUANTITIES."""
    t = np.asarray(run["t"])
    late = t >= 0.5 * end

    def temperature(key):
        T = np.asarray(run.get(key, run["T"]))
        T_ref = np.interp(t, ref["t"], ref[key])
        return float(np.mean(T[late] / T_ref[late] - 1.0))

    dC = run["collisions"][-1] / ref["collisions"][-1] - 1.0
    # pressure: mean over the sampling windows (the first sample has no window)
    dP = float(np.mean(np.asarray(run["P"])[1:]) / np.mean(np.asarray(ref["P"])[1:]) - 1.0)
    # compressibility factor P / (n T), T the kinetic temperature at the middle of each window
    # (n is the same for both): the pressure with the difference in T taken out

    def z(r):
        T = np.asarray(r.get("T_kinetic", r["T"]))
        T = np.interp(t, r["t"], T)
        return np.asarray(np.interp(t, r["t"], r["P"]))[1:] / (0.5 * (T[1:] + T[:-1]))

    dZ = float(np.mean(z(run) / z(ref) - 1.0))
    return temperature("T"), dC, dP, temperature("T_kinetic"), dZ


def mean_se(values):
    v = np.asarray(values, dtype=float)
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v))) if len(v) > 1 else math.nan


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fractions", type=float, nargs="+", default=[0.01, 0.03, 0.1, 0.15, 0.2])
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--particles", type=int, default=2000)
    ap.add_argument("--packing", type=float, default=0.05)
    ap.add_argument("--damping", type=float, default=0.1)
    ap.add_argument("--end", type=float, default=20.0)
    ap.add_argument("--steps-per-contact", type=int, nargs="+", default=[10, 20, 40, 80])
    ap.add_argument("--workdir", default=str(ROOT / "runs" / "resolved_lammps"))
    ap.add_argument("--figure", default=str(ROOT / "docs" / "figures" / "resolved_lammps.png"))
    ap.add_argument("--reuse", action="store_true", help="reuse finished runs found in the work directory")
    args = ap.parse_args(argv)

    from granulargas.dem.lammps import find_lmp
    from granulargas.errors import ConfigError

    if find_lmp() is None:
        sys.exit("LAMMPS (lmp) not found: this comparison needs it (apt-get install lammps)")
    workdir = Path(args.workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    steps_list = sorted(args.steps_per_contact)
    finest = steps_list[-1]

    # JIT compile both engine loops on a small copy before timing anything
    warm = workdir / "warmup"
    warm.mkdir(exist_ok=True)
    small = argparse.Namespace(**{**vars(args), "particles": 64, "end": 0.5})
    t0 = time.perf_counter()
    for duration in ("instantaneous", "resolved"):
        run_engine(small, 1e5, 1, duration, warm, False)
    print(f"JIT compile + warm-up of both engine loops: {time.perf_counter() - t0:.3g} s", flush=True)

    results = {"particles": args.particles, "packing_fraction": args.packing, "damping": args.damping,
               "end_time": args.end, "seeds": args.seeds, "steps_per_contact": steps_list, "fractions": {}}
    gas = f"N{args.particles}_packing{args.packing:g}_damping{args.damping:g}_end{args.end:g}"  # runs reused per gas
    for f in args.fractions:
        young = young_for_fraction(args, f, workdir)
        runs = {"instantaneous": [], "resolved": [], **{f"lammps_n{n}": [] for n in steps_list}}
        refused = None
        for seed in range(1, args.seeds + 1):
            d = workdir / gas / f"f{f:g}" / f"seed{seed}"
            d.mkdir(parents=True, exist_ok=True)
            runs["instantaneous"].append(run_engine(args, young, seed, "instantaneous", d, args.reuse))
            if refused is None:
                try:
                    runs["resolved"].append(run_engine(args, young, seed, "resolved", d, args.reuse))
                except ConfigError as exc:  # an impact beyond the oblique table's range
                    refused = f"seed {seed}: {exc}"
                    print(f"  resolved run refused, {refused}", flush=True)
            for n in steps_list:
                print(f"  f = {f:g}, seed {seed}: LAMMPS t_c/{n} ...", flush=True)
                runs[f"lammps_n{n}"].append(run_dem(args, young, seed, n, d, args.reuse))
        ref_key = f"lammps_n{finest}"
        block = {"young_modulus": young, "methods": {}, "resolved_refused": refused}
        if refused is None:
            share = [r["three_body"] / r["total_collisions"] for r in runs["resolved"]]
            block["three_body_share"] = mean_se(share)
            extra = f"three-body share of the resolved runs {100 * np.mean(share):.2f} %"
        else:
            del runs["resolved"]
            extra = "resolved runs refused"
        print(f"t_c/t_free = {f:g}: Y = {young:.4g}, LAMMPS dt = {runs[ref_key][0]['timestep']:.3g} (finest), {extra}")
        print(f"  {'method':16s} {'T, 2nd half [%]':>18s} {'collisions [%]':>18s} {'pressure [%]':>18s} "
              f"{'T kinetic [%]':>18s} {'P/(nT) [%]':>18s} {'CPU [s]':>9s} {'wall [s]':>9s} {'collisions':>10s}")
        for key, lst in runs.items():
            devs = np.array([deviations(r, ref, args.end) for r, ref in zip(lst, runs[ref_key])])
            m = {name: mean_se(100 * devs[:, k]) for k, name in enumerate(QUANTITIES)}
            m["wall_median"] = statistics.median(r["wall"] for r in lst)
            m["walls"] = [r["wall"] for r in lst]
            m["cpu_median"] = statistics.median(r["cpu"] for r in lst)
            m["cpus"] = [r["cpu"] for r in lst]
            m["collisions_mean"] = float(np.mean([r["total_collisions"] for r in lst]))
            # T(t) / T_ref(t) - 1 per seed, on the engine's sample times
            t = np.asarray(runs["instantaneous"][0]["t"])
            m["t"] = t.tolist()
            m["T_dev"] = [(100 * (np.interp(t, r["t"], r["T"]) / np.interp(t, ref["t"], ref["T"]) - 1.0)).tolist()
                          for r, ref in zip(lst, runs[ref_key])]
            block["methods"][key] = m
            cells = " ".join(f"{m[q][0]:+8.2f} +- {m[q][1]:5.2f}" for q in QUANTITIES)
            print(f"  {key:16s} {cells} {m['cpu_median']:9.3g} {m['wall_median']:9.3g} {m['collisions_mean']:10.0f}", flush=True)
        results["fractions"][f"{f:g}"] = block
        (workdir / "results.json").write_text(json.dumps(results, indent=1) + "\n")
    print_advise_rows(results)
    plot(args.figure, results)
    print(f"figure {args.figure}; results {workdir / 'results.json'}")
    return 0


def error_bound(m):
    """Largest |mean| + 2 standard errors over all QUANTITIES (fraction)."""
    return max(abs(m[q][0]) + 2 * m[q][1] for q in QUANTITIES) / 100


def print_advise_rows(results):
    """The rows of ``granulargas.run.advise.RESOLVED_LAMMPS_MEASURED`` these runs give."""
    rows = []
    for f, block in results["fractions"].items():
        meth = block["methods"]
        if "resolved" not in meth:
            print(f"t_c/t_free = {f}: resolved runs refused ({block['resolved_refused']})")
            continue
        coarsest = min(int(k.split("_n")[1]) for k in meth if k.startswith("lammps_n"))
        rows.append((float(f), round(error_bound(meth["instantaneous"]), 4), round(error_bound(meth["resolved"]), 4),
                     round(meth[f"lammps_n{coarsest}"]["cpu_median"] / meth["resolved"]["cpu_median"], 2)))
    print("(ratio, error bound instantaneous, resolved, CPU time of LAMMPS at its coarsest step / resolved): "
          "error bound = largest |mean| + 2 s.e. over " + ", ".join(QUANTITIES))
    print(tuple(rows))


def plot(path, results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fracs = list(results["fractions"])
    steps_list = results["steps_per_contact"]
    colors = {f: c for f, c in zip(fracs, ["C0", "C1", "C3", "C2", "C4"])}
    nf = len(fracs)
    fig = plt.figure(figsize=(max(16.0, 3.7 * nf), 8.6))
    top = fig.add_gridspec(1, 4, left=0.05, right=0.99, top=0.86, bottom=0.55, wspace=0.33)
    bottom = fig.add_gridspec(1, nf, left=0.05, right=0.99, top=0.44, bottom=0.07, wspace=0.3)
    axes = [[fig.add_subplot(top[0, k]) for k in range(4)], [fig.add_subplot(bottom[0, k]) for k in range(nf)]]
    labels = [("T", r"$\langle T/T_{\rm ref}-1\rangle$, second half [%]"),
              ("collisions", r"$N_{\rm coll}/N_{\rm coll,ref}-1$ at the end [%]"),
              ("pressure", r"$\langle P\rangle/\langle P\rangle_{\rm ref}-1$ [%]"),
              ("Z", r"$\langle Z/Z_{\rm ref}-1\rangle$, $Z = P/(nT)$ [%]")]
    markers = {"instantaneous": "o", "resolved": "s"}
    for ax, (q, lab) in zip(axes[0], labels):
        for f in fracs:
            meth = results["fractions"][f]["methods"]
            c = colors[f]
            for key, mk in markers.items():
                if key not in meth:
                    continue
                m = meth[key]
                ax.errorbar(m["cpu_median"], m[q][0], yerr=m[q][1], fmt=mk, color=c, ms=8,
                            mfc="none" if key == "instantaneous" else c, capsize=3)
            lw = [meth[f"lammps_n{n}"]["cpu_median"] for n in steps_list[:-1]]
            le = [meth[f"lammps_n{n}"][q][0] for n in steps_list[:-1]]
            ls = [meth[f"lammps_n{n}"][q][1] for n in steps_list[:-1]]
            ax.errorbar(lw, le, yerr=ls, fmt="^-", color=c, ms=7, capsize=3)
            ax.axvline(meth[f"lammps_n{steps_list[-1]}"]["cpu_median"], color=c, ls=":", lw=1)
        ax.set_xscale("log")
        ax.set_yscale("symlog", linthresh=1.0, linscale=1.5)  # linear within +-1 %, logarithmic beyond
        ticks = [-20, -10, -5, -2, -1, -0.5, 0, 0.5, 1, 2, 5, 10, 20]
        ax.yaxis.set_major_locator(matplotlib.ticker.FixedLocator(ticks))
        ax.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        ax.margins(y=0.08)
        ax.axhline(0, color="k", lw=0.6)
        ax.grid(True, which="major", axis="y", color="0.9")
        ax.set_xlabel("CPU time per run [s]")
        ax.set_ylabel(lab)
    # legend: fractions by colour, methods by marker
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=colors[f], lw=3, label=f"$t_c/t_{{free}}$ = {f}") for f in fracs]
    handles += [Line2D([], [], color="k", marker="o", mfc="none", ls="", label="EDMD, instantaneous"),
                Line2D([], [], color="k", marker="s", ls="", label="EDMD, resolved"),
                Line2D([], [], color="k", marker="^", ls="-",
                       label=f"LAMMPS, $t_c$/{', '.join(str(n) for n in steps_list[:-1])}"),
                Line2D([], [], color="k", ls=":", label=f"LAMMPS reference ($t_c$/{steps_list[-1]}): its CPU time")]
    fig.legend(handles=handles, fontsize=9, loc="upper center", ncol=len(handles), bbox_to_anchor=(0.5, 0.955),
               frameon=False)
    fig.suptitle(f"error against LAMMPS at $t_c$/{steps_list[-1]} vs cost; N = {results['particles']}, "
                         f"packing {results['packing_fraction']:g}, damping {results['damping']:g}, "
                         f"{results['seeds']} seeds (mean $\\pm$ s.e.)", fontsize=11)
    for ax, f in zip(axes[1], fracs):
        meth = results["fractions"][f]["methods"]
        for key, c, lab in (("instantaneous", "C7", "EDMD instantaneous"), ("resolved", "C3", "EDMD resolved"),
                            (f"lammps_n{steps_list[0]}", "C0", f"LAMMPS $t_c$/{steps_list[0]}")):
            if key not in meth:
                continue
            m = meth[key]
            dev = np.asarray(m["T_dev"])
            mean = dev.mean(axis=0)
            se = dev.std(axis=0, ddof=1) / math.sqrt(len(dev))
            ax.plot(m["t"], mean, color=c, label=lab)
            ax.fill_between(m["t"], mean - se, mean + se, color=c, alpha=0.25, lw=0)
        ax.axhline(0, color="k", lw=0.6)
        if "three_body_share" in results["fractions"][f]:
            share = results["fractions"][f]["three_body_share"][0]
            ax.set_title(f"$t_c/t_{{free}}$ = {f} (three-body {100 * share:.2g} %)", fontsize=10)
        else:
            ax.set_title(f"$t_c/t_{{free}}$ = {f} (resolved: refused)", fontsize=10)
        ax.set_xlabel(r"time $t$ [$\sigma\sqrt{m/T_0}$]")
        ax.set_ylabel(r"$T(t)/T_{\rm LAMMPS}(t) - 1$ [%]")
        ax.legend(fontsize=8)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
