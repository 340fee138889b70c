"""granulargas vs LAMMPS (time-stepped DEM with the same contact law).

Two studies:

``python scripts/lammps/cooling_gas.py CONFIG [--end-time T] [--fractions 0.01 0.002]``
    Runs the config with granulargas (median wall time of ``--repeats`` runs,
    JIT compile timed separately) and, when ``lmp`` is installed, the exported
    LAMMPS run at each contact-time fraction (contact time / mean free time;
    the stiffness follows). Draws T(t) of all runs with the kinetic-theory
    curve (:func:`granulargas.theory.viscoelastic_temperature`) and the
    relative deviation from the event-driven run; prints the wall times and
    their ratio; writes ``results.json`` in the work directory.

``python scripts/lammps/cooling_gas.py CONFIG --ensemble 8 [--set system.particles=2000] [--end-time 30]``
    The same comparison over seeds 1..8 at the first contact-time fraction: the
    mean and standard error over seeds of T_LAMMPS / T_granulargas - 1 at a few
    times and averaged over the second half of the run (single runs from one
    initial state decorrelate, so only the mean tests for a systematic difference).

``python scripts/lammps/cooling_gas.py --head-on``
    eps(beta) of LAMMPS head-on collisions (limit_damping on / off) against
    :func:`granulargas.contact.restitution` (``force`` / ``overlap`` end),
    and the error against the timestep.

The LAMMPS runs use one core (OMP_NUM_THREADS=1) and run one at a time.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


# --------------------------------------------------------------------------- cooling gas


def run_granulargas(config, overrides: dict, workdir: Path, repeats: int):
    """Run the config ``repeats`` times; return (observables, wall times, compile time, summary)."""
    from granulargas.io.config import parse_config
    from granulargas.io.h5md import read_observables
    from granulargas.run.runner import run_config

    # compile (and load the numba cache) on a tiny copy of the config
    t0 = time.perf_counter()
    tiny = parse_config(config.text, source=config.source, overrides={
        "system.particles": 64, "system.packing_fraction": 0.05, "run.end_time": 0.2,
        "output.file": str(workdir / "warmup.h5"), "output.observables_interval": 0.1, "output.snapshots": 2})
    run_config(tiny, overwrite=True, quiet=True)
    compile_time = time.perf_counter() - t0

    # same output as the LAMMPS thermo: T(t) at 200 times, no intermediate snapshots
    walls = []
    out = workdir / "granulargas.h5"
    cfg = parse_config(config.text, source=config.source, overrides={
        **overrides, "output.file": str(out), "output.snapshots": 2,
        "output.observables_interval": config.run.end_time / 200})
    for _ in range(repeats):
        summary = run_config(cfg, overwrite=True, quiet=True)
        walls.append(summary.wall_time)
    obs = read_observables(out)
    return obs, walls, compile_time, summary


def seed_spread(config, overrides: dict, workdir: Path, seeds: int, t_ref, T_ref):
    """T_seed / T_ref - 1 of granulargas runs from other initial states (seed + 1, ...).

    Two runs from the same initial state decorrelate after a few collisions
    (molecular chaos), so this is the size of the difference expected between
    LAMMPS and granulargas from fluctuations alone."""
    from granulargas.io.config import parse_config
    from granulargas.io.h5md import read_observables
    from granulargas.run.runner import run_config

    devs = []
    for k in range(1, seeds + 1):
        out = workdir / f"granulargas_seed{k}.h5"
        cfg = parse_config(config.text, source=config.source, overrides={
            **overrides, "output.file": str(out), "output.snapshots": 2,
            "output.observables_interval": config.run.end_time / 200, "system.seed": config.system.seed + k})
        run_config(cfg, overwrite=True, quiet=True)
        _, t, T = read_observables(out)["temperature"]
        devs.append(np.interp(t_ref, t, T) / T_ref - 1.0)
    return np.array(devs)


def run_dem(config, workdir: Path, fraction: float, steps_per_contact: int, end_time: float, reuse: bool):
    from granulargas.dem.export import export_lammps
    from granulargas.dem.lammps import loop_time, read_thermo, run_lammps

    d = workdir / f"lammps_f{fraction:g}"
    ex = export_lammps(config, d, contact_fraction=fraction, steps_per_contact=steps_per_contact, end_time=end_time)
    log = d / "log.lammps"
    result_file = d / "wall.json"
    if reuse and result_file.exists() and log.exists():
        wall = json.loads(result_file.read_text())["wall_time"]
        text = log.read_text()
    else:
        print(f"  LAMMPS f = {fraction:g}: {ex.steps} steps of {ex.timestep:.3g} ...", flush=True)
        t0 = time.perf_counter()
        text = run_lammps(ex.input_file)
        wall = time.perf_counter() - t0
        result_file.write_text(json.dumps({"wall_time": wall}))
    return ex, read_thermo(log), wall, loop_time(text)


def cooling(args):
    from granulargas import theory
    from granulargas.io.config import load_config
    from granulargas.dem.lammps import find_lmp
    from granulargas.cli._args import parse_override

    overrides = dict(parse_override(t) for t in args.set)
    if args.end_time is not None:
        overrides["run.end_time"] = args.end_time
    config = load_config(args.config, overrides)
    workdir = Path(args.workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    s = config.system
    print(f"config {args.config}: N = {s.particles}, {s.dimension}D, packing {s.packing_fraction}, "
          f"damping {config.collision.damping}, end '{config.collision.contact_end}', t_end = {config.run.end_time}")

    obs, walls, compile_time, summary = run_granulargas(config, overrides, workdir, args.repeats)
    _, t_ed, T_ed = obs["temperature"]
    ed_wall = statistics.median(walls)
    print(f"granulargas: wall {ed_wall:.3g} s (median of {len(walls)}: {', '.join(f'{w:.3g}' for w in walls)}), "
          f"JIT compile + warm-up {compile_time:.3g} s, {summary.collisions} collisions, T_end = {T_ed[-1]:.5g}")

    results = {"config": str(args.config), "particles": s.particles, "dimension": s.dimension,
               "packing_fraction": s.packing_fraction, "end_time": config.run.end_time,
               "granulargas": {"wall_time_median": ed_wall, "wall_times": walls, "compile_time": compile_time,
                               "collisions": summary.collisions, "T_end": float(T_ed[-1])},
               "lammps": []}
    dem = []
    if find_lmp() is None:
        print("LAMMPS (lmp) not found: granulargas only (install: apt-get install lammps)")
    else:
        for f in args.fractions:
            ex, th, wall, loop = run_dem(config, workdir, f, args.steps_per_contact, config.run.end_time, args.reuse)
            T_l = th["c_granT"]
            dev = float(np.max(np.abs(np.interp(t_ed, th["Time"], T_l) / T_ed - 1.0)))
            print(f"LAMMPS f = {f:g}: Y = {ex.contact.young_modulus:.4g}, dt = {ex.timestep:.3g}, {ex.steps} steps, "
                  f"wall {wall:.4g} s (loop {loop:.4g} s), T_end = {T_l[-1]:.5g}, max |T/T_ED - 1| = {dev:.3g}, "
                  f"wall ratio LAMMPS/granulargas = {wall / ed_wall:.3g}")
            dem.append((f, ex, th, wall))
            results["lammps"].append({"contact_fraction": f, "young_modulus": ex.contact.young_modulus,
                                      "timestep": ex.timestep, "steps": ex.steps, "wall_time": wall,
                                      "loop_time": loop, "T_end": float(T_l[-1]), "max_rel_dev": dev,
                                      "wall_ratio": wall / ed_wall})

    spread = seed_spread(config, overrides, workdir, args.seeds, t_ed, T_ed) if args.seeds > 1 else None
    if spread is not None:
        band = spread.std(axis=0, ddof=1)
        results["granulargas"]["seed_spread_rms"] = float(np.sqrt(np.mean(band**2)))
        print(f"granulargas, {args.seeds} other seeds: rms over time of std(T/T_ED - 1) = "
              f"{results['granulargas']['seed_spread_rms']:.3g}")
    n = theory.number_density(s.packing_fraction, s.dimension)
    k = _prefactor(config)
    tau0 = theory.viscoelastic_tau0(k, n, config.initial.temperature, s.dimension)
    results["theory_tau0"] = tau0
    (workdir / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    plot_cooling(args.figure, config, t_ed, T_ed, ed_wall, dem, tau0, spread)
    print(f"figure {args.figure}; results {workdir / 'results.json'}")


def ensemble(args):
    from granulargas.io.config import load_config
    from granulargas.dem.lammps import find_lmp
    from granulargas.cli._args import parse_override

    if find_lmp() is None:
        sys.exit("LAMMPS (lmp) not found: the ensemble needs it (apt-get install lammps)")
    base = dict(parse_override(t) for t in args.set)
    if args.end_time is not None:
        base["run.end_time"] = args.end_time
    f = args.fractions[0]
    devs = []
    for seed in range(1, args.ensemble + 1):
        overrides = {**base, "system.seed": seed}
        config = load_config(args.config, overrides)
        workdir = Path(args.workdir) / "ensemble" / f"seed{seed}"
        workdir.mkdir(parents=True, exist_ok=True)
        obs, _, _, _ = run_granulargas(config, overrides, workdir, 1)
        _, t, T = obs["temperature"]
        _, th, _, _ = run_dem(config, workdir, f, args.steps_per_contact, config.run.end_time, args.reuse)
        devs.append(np.interp(t, th["Time"], th["c_granT"]) / T - 1.0)
        print(f"seed {seed}: T_LAMMPS/T_granulargas - 1 at t_end = {100 * devs[-1][-1]:+.2f} %", flush=True)
    d = 100 * np.array(devs)
    n = len(d)
    s = config.system
    print(f"N = {s.particles}, {s.dimension}D, packing {s.packing_fraction:g}, t_c = {f:g} t_free, "
          f"{args.steps_per_contact} steps per contact, {n} seeds: mean +- standard error of T_LAMMPS/T_ED - 1 [%]")
    t_end = float(t[-1])
    for x in (0.1, 0.2, 0.5, 1.0):
        v = np.array([np.interp(x * t_end, t, row) for row in d])
        print(f"  t = {x * t_end:8.4g}: {v.mean():+.2f} +- {v.std(ddof=1) / np.sqrt(n):.2f}  (single seeds: sd {v.std(ddof=1):.2f})")
    late = t >= 0.5 * t_end
    v = d[:, late].mean(axis=1)
    print(f"  mean over t >= {0.5 * t_end:g}: {v.mean():+.2f} +- {v.std(ddof=1) / np.sqrt(n):.2f}")


def _prefactor(config):
    from granulargas.run.prepare import reduced_prefactor

    return reduced_prefactor(config)


def plot_cooling(path, config, t_ed, T_ed, ed_wall, dem, tau0, spread=None):
    from granulargas import theory

    plt = _plt()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.3))
    s = config.system
    ax.loglog(t_ed[1:], T_ed[1:], "-", color="C0", lw=2.5, label="granulargas (event-driven)")
    styles = ["--", ":", "-."]
    for (f, ex, th, wall), ls, c in zip(dem, styles, ["C3", "C2", "C4"]):
        lab = f"LAMMPS, $t_c$ = {f:g} $t_{{free}}$ (Y = {ex.contact.young_modulus:.2g})"
        ax.loglog(th["Time"][1:], th["c_granT"][1:], ls, color=c, lw=1.8, label=lab)
        T_l = np.interp(t_ed, th["Time"], th["c_granT"])
        ax2.plot(t_ed, (T_l / T_ed - 1.0) * 100, ls, color=c,
                 label=f"LAMMPS $t_c$ = {f:g} $t_{{free}}$")
    tt = np.geomspace(max(t_ed[1], 1e-3), t_ed[-1], 200)
    ax.loglog(tt, theory.viscoelastic_temperature(tt, config.initial.temperature, tau0), "k-", lw=0.8,
              label=r"kinetic theory $T_0(1+t/\tau_0)^{-5/3}$")
    ax.set_xlabel(r"time $t$ [$\sigma\sqrt{m/T_0}$]")
    ax.set_ylabel(r"granular temperature $T/T_0$")
    ax.set_title(f"viscoelastic cooling, N = {s.particles}, {s.dimension}D, packing {s.packing_fraction:g}, "
                 f"damping {config.collision.damping:g}", fontsize=10)
    ax.legend(fontsize=8, loc="lower left")
    ax2.axhline(0, color="C0", lw=2.5)
    if spread is not None:
        band = 100 * spread.std(axis=0, ddof=1)
        ax2.fill_between(t_ed, -band, band, color="0.8", zorder=0,
                         label=f"granulargas, {len(spread)} other seeds: $\\pm$1 std")
    ax2.set_xlabel(r"time $t$ [$\sigma\sqrt{m/T_0}$]")
    ax2.set_ylabel(r"$T_{\rm LAMMPS}/T_{\rm granulargas} - 1$ [%]")
    ax2.set_title("difference from the event-driven run (same initial state)", fontsize=10)
    if dem or spread is not None:
        ax2.legend(fontsize=8)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)


# --------------------------------------------------------------------------- head-on


def head_on(args):
    from granulargas.contact import restitution
    from granulargas.dem.lammps import DemContact, find_lmp, head_on_restitution

    if find_lmp() is None:
        sys.exit("LAMMPS (lmp) not found: the head-on study needs it (apt-get install lammps)")
    workdir = Path(args.workdir) / "head_on"
    betas = np.geomspace(0.01, 3.0, 12)
    fine = np.geomspace(0.005, 4.0, 200)
    n_fine = 2000
    rows = {}
    for end in ("force", "overlap"):
        eps = [head_on_restitution(DemContact.from_beta(b, 1.0, 1e4, end=end), 1.0, n_fine, workdir)
               for b in betas]
        rows[end] = np.array(eps)
        err = np.abs(rows[end] - restitution(betas, method="ode", end=end))
        print(f"{end:8s} (limit_damping {'on' if end == 'force' else 'off'}): t_c/{n_fine}: "
              f"max |eps_LAMMPS - eps_ODE| = {err.max():.2g} over beta in [{betas[0]:g}, {betas[-1]:g}]")
    steps = np.array([50, 100, 200, 400, 800, 1600, 3200])
    conv = {}
    for beta in (0.1, 1.0):
        for end in ("force", "overlap"):
            ref = float(restitution(beta, method="ode", end=end))
            e = [head_on_restitution(DemContact.from_beta(beta, 1.0, 1e4, end=end), 1.0, int(n), workdir)
                 for n in steps]
            conv[(beta, end)] = np.abs(np.array(e) - ref)
            print(f"beta = {beta:g}, {end}: |error| at t_c/n, n = {steps.tolist()}: "
                  + ", ".join(f"{x:.2g}" for x in conv[(beta, end)]))

    plt = _plt()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.3))
    for end, c in (("force", "C3"), ("overlap", "C0")):
        ax.semilogx(fine, restitution(fine, method="ode", end=end), "-", color=c,
                    label=f"granulargas.contact, '{end}' end")
        mk = "o" if end == "force" else "s"
        lab = "LAMMPS limit_damping" if end == "force" else "LAMMPS without limit_damping"
        ax.semilogx(betas, rows[end], mk, color=c, mfc="none", ms=7, label=f"{lab} ($t_c$/{n_fine})")
    ax.set_xlabel(r"dimensionless damping $\beta = \frac{3}{2}A\rho^{2/5}g^{1/5}$")
    ax.set_ylabel(r"coefficient of restitution $\varepsilon$")
    ax.set_title("two spheres head-on: LAMMPS hertz/material + viscoelastic", fontsize=10)
    ax.legend(fontsize=8)
    # colour = end of contact, as in the left panel; line style and marker = beta
    # (markers other than the left panel's, which mark the end there)
    colour = {"force": "C3", "overlap": "C0"}
    style = {0.1: ("--", "^", "none"), 1.0: ("-", "D", None)}
    for (beta, end), err in conv.items():
        ls, mk, mfc = style[beta]
        ax2.loglog(steps, np.maximum(err, 1e-12), ls, marker=mk, ms=5, color=colour[end], mfc=mfc,
                   label=fr"$\beta$ = {beta:g}, '{end}' end")
    ax2.loglog(steps, 0.05 / steps, "k:", lw=1, label="first order ($\\propto \\Delta t$)")
    ax2.set_xlabel(r"steps per contact $t_c/\Delta t$")
    ax2.set_ylabel(r"$|\varepsilon_{\rm LAMMPS} - \varepsilon_{\rm ODE}|$")
    ax2.set_title("convergence in the LAMMPS timestep", fontsize=10)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.figure_head_on, dpi=130)
    plt.close(fig)
    print(f"figure {args.figure_head_on}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("config", nargs="?", default=str(ROOT / "configs" / "viscoelastic_3d.toml"),
                   help="run configuration (default configs/viscoelastic_3d.toml)")
    p.add_argument("--end-time", type=float, default=None, help="override run.end_time")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="config override (repeatable)")
    p.add_argument("--fractions", type=float, nargs="+", default=[0.01, 0.002],
                   help="LAMMPS contact time / mean free time, one run each (default 0.01 0.002)")
    p.add_argument("--steps-per-contact", type=int, default=50)
    p.add_argument("--repeats", type=int, default=3, help="granulargas runs (median wall time)")
    p.add_argument("--seeds", type=int, default=4,
                   help="granulargas runs from other seeds for the fluctuation band (default 4; 0: none)")
    p.add_argument("--workdir", default="runs/compare_lammps")
    p.add_argument("--reuse", action="store_true", help="reuse finished LAMMPS runs in the work directory")
    p.add_argument("--figure", default=str(ROOT / "docs" / "figures" / "lammps_cooling.png"))
    p.add_argument("--ensemble", type=int, default=0, metavar="SEEDS",
                   help="mean LAMMPS/granulargas difference over seeds 1..SEEDS (first fraction) instead")
    p.add_argument("--head-on", action="store_true", help="the two-particle study instead")
    p.add_argument("--figure-head-on", default=str(ROOT / "docs" / "figures" / "lammps_restitution.png"))
    args = p.parse_args(argv)
    if args.head_on:
        head_on(args)
    elif args.ensemble:
        ensemble(args)
    else:
        cooling(args)


if __name__ == "__main__":
    main()
