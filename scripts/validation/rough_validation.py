"""Rough grains against theory, EDMD against DSMC, and both against published simulations.

Three scenes, each run with the event-driven engine (EDMD) and the DSMC of the homogeneous
Enskog-Boltzmann equation, several seeds each (errors: standard error over the seeds):

* ``hcs``: the homogeneous cooling state at low density, spheres (kappa = 2/5) and disks
  (kappa = 1/2), several (eps, beta_t) and one Walton (Coulomb) case. Measured over the
  collisions per particle s in [S_FROM, S_TO]: theta = T_rot / T_tr and the cooling per
  collision -d ln T_tr / ds, against the Maxwellian theory (theory.rough: eq. (R7) and the
  energy balance (R2) at theta_HCS).
* ``driven``: white-noise driven rough disks (kappa = 1/2) with the splitting thermostat:
  theta_st against the Maxwellian theory and against the EDMD and DSMC of Megías & Santos
  (2022), their public data (repository amegiasf/MpembaSplitting, "Steady states").
* ``mpemba``: the rough-sphere Mpemba scene (translation driven, T_st = 1): a hot gas
  without spin (T_tr = 12, T_rot = 0) and a cold one with much spin (T_tr = 1.1, T_rot = 22);
  their T_tr(t) cross; the crossing time against the theory's.

    python scripts/validation/rough_validation.py [--scene hcs driven mpemba] [--seeds 4] [--scale 1]
        [--json docs/figures/rough_validation.json] [--outdir docs/figures]

``--scale`` multiplies the particle numbers (0.25 for a quick look). Prints one line per
case and writes a JSON of the numbers and the figures ``rough_hcs_validation.png``,
``rough_driven_validation.png``, ``rough_mpemba.png``.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from granulargas import theory
from granulargas.dsmc import DSMC
from granulargas.engine import CollisionRule, Simulation, TangentialRule, WhiteNoise
from granulargas.initial import maxwell_spins, random_state
from granulargas.state import State
from granulargas.theory import rough as R
from granulargas.theory.gas import Gas

S_FROM, S_TO = 10.0, 40.0
PACKING = {3: 0.01, 2: 0.01}
#: EDMD boxes below the shear-instability length: L / l = 3.4 (3D) and 10 (2D) mean free paths
N_EDMD = {3: 8000, 2: 1000}
#: the 2D EDMD's fewer particles are made up for by more seeds
SEEDS_2D = 3
N_DSMC = 20000

HCS_CASES = [  # (d, eps, beta_t or beta_0, mu or None)
    (3, 0.9, 0.0, None), (3, 0.9, 0.6, None), (3, 0.7, -0.4, None), (3, 0.9, 0.4, 0.3),
    (2, 0.9, 0.0, None), (2, 0.8, 0.5, None),
]
#: Megías & Santos (2022), theta_st of driven rough disks (kappa = 1/2), EDMD and DSMC:
#: (eps, beta_t, fraction of the noise power on the spins) -> (EDMD, DSMC)
PUBLISHED = {
    (0.9, 0.0, 0.0): (0.24242, 0.24244), (0.9, 0.0, 0.5): (1.03038, 1.02863),
    (0.9, -0.7, 0.5): (1.54461, 1.54392), (0.7, 0.0, 0.5): (1.59410, 1.59390),
    (0.7, -0.7, 0.1): (0.42418, 0.42362),
}


def _gas(d, eps, T=1.0):
    n = theory.number_density(PACKING[d], d)
    return Gas(dimension=d, packing_fraction=PACKING[d], density=n, sigma=1.0, mass=1.0, temperature=T,
               model="constant", restitution=eps)


def _tangential(beta, mu):
    return TangentialRule.constant(beta) if mu is None else TangentialRule.coulomb(beta, mu)


def _rough(d, eps, beta, mu, **kw):
    kappa = R.DEFAULT_INERTIA[d]
    return R.RoughGas(_gas(d, eps, kw.pop("T", 1.0)), kappa, tangential="constant" if mu is None else "coulomb",
                      tangential_restitution=beta, friction=0.0 if mu is None else mu, **kw)


def _state(method, d, n, seed, T_tr, T_rot):
    """Maxwell velocities at T_tr and spins at T_rot (kappa of a uniform sphere or disk)."""
    kappa = R.DEFAULT_INERTIA[d]
    if method == "edmd":
        st = random_state(n, PACKING[d], d, temperature=T_tr, seed=seed)
    else:
        rng = np.random.default_rng(seed)
        v = rng.normal(size=(n, d)) * math.sqrt(T_tr)
        box = np.full(d, (n * float(theory.particle_volume(1.0, d)) / PACKING[d]) ** (1.0 / d))
        st = State(None, v, 0.5, 1.0, box)
    rng = np.random.default_rng([seed, 1])
    spins = maxwell_spins(np.full(n, kappa * 0.25), d, T_rot, rng=rng)
    return st.replace(angular_velocities=spins, inertia=np.full(n, kappa))


def _simulation(method, state, eps, tangential, driving=None, seed=1):
    rule = CollisionRule.constant(eps)
    if method == "edmd":
        return Simulation(state, rule, tangential=tangential, driving=driving, neighbours="cells")
    return DSMC(state, rule, seed=seed, tangential=tangential, driving=driving)


# ---------------------------------------------------------------- homogeneous cooling state


def hcs_run(method, d, eps, beta, mu, seed, scale):
    """(theta, -d ln T_tr / ds) over s in [S_FROM, S_TO] of one run started at theta_HCS."""
    rough = _rough(d, eps, beta, mu)
    theta0 = R.hcs_ratio(rough)
    n = int((N_EDMD[d] if method == "edmd" else N_DSMC) * scale)
    sim = _simulation(method, _state(method, d, n, seed, 1.0, theta0), eps, _tangential(beta, mu), seed=seed)
    s_grid = np.arange(S_FROM, S_TO + 0.5, 1.0)
    rows = []
    for s in np.concatenate([[S_FROM / 2], s_grid]):
        target = int(round(s * n / 2))
        sim.run(math.inf, max_collisions=max(target - sim.collisions, 1))
        rows.append((2 * sim.collisions / n, sim.temperature, sim.rotational_temperature))
    a = np.array(rows[1:])
    theta = float(np.mean(a[:, 2] / a[:, 1]))
    slope = -float(np.polyfit(a[:, 0], np.log(a[:, 1]), 1)[0])
    return theta, slope


def hcs_theory(d, eps, beta, mu):
    rough = _rough(d, eps, beta, mu)
    theta = R.hcs_ratio(rough)
    de_tr, _ = R.energy_change_per_collision(rough, 1.0, theta)
    return theta, -de_tr / R.degrees_of_freedom(d)[0]


def _mean_err(x):
    x = np.asarray(x, dtype=float)
    return float(x.mean()), float(x.std(ddof=1) / math.sqrt(len(x))) if len(x) > 1 else math.nan


def scene_hcs(seeds, scale):
    out = []
    print(f"homogeneous cooling state: theta and -d ln T_tr/ds over s in [{S_FROM:g}, {S_TO:g}], {seeds} seeds")
    for d, eps, beta, mu in HCS_CASES:
        th_theta, th_slope = hcs_theory(d, eps, beta, mu)
        row = {"d": d, "eps": eps, "beta": beta, "mu": mu, "theta_theory": th_theta, "slope_theory": th_slope}
        for method in ("edmd", "dsmc"):
            t0 = time.perf_counter()
            k = seeds * (SEEDS_2D if d == 2 and method == "edmd" else 1)
            res = [hcs_run(method, d, eps, beta, mu, seed, scale) for seed in range(1, k + 1)]
            row[f"theta_{method}"], row[f"theta_{method}_error"] = _mean_err([r[0] for r in res])
            row[f"slope_{method}"], row[f"slope_{method}_error"] = _mean_err([r[1] for r in res])
            row[f"seconds_{method}"] = time.perf_counter() - t0
        diff = row["theta_edmd"] - row["theta_dsmc"]
        err = math.hypot(row["theta_edmd_error"], row["theta_dsmc_error"])
        row["edmd_minus_dsmc_sigmas"] = diff / err
        law = f"beta_0 = {beta:g}, mu = {mu:g}" if mu is not None else f"beta_t = {beta:g}"
        print(f"  {d}D eps = {eps:g}, {law}: theta EDMD {row['theta_edmd']:.4f}({1e4 * row['theta_edmd_error']:.0f}) "
              f"DSMC {row['theta_dsmc']:.4f}({1e4 * row['theta_dsmc_error']:.0f}) [{diff / err:+.1f} sigma], "
              f"Maxwellian {th_theta:.4f} (DSMC {100 * (row['theta_dsmc'] / th_theta - 1):+.1f} %); "
              f"-dlnT/ds EDMD {row['slope_edmd']:.4f} DSMC {row['slope_dsmc']:.4f} Maxwellian {th_slope:.4f}")
        out.append(row)
    return out


# ---------------------------------------------------------------- driven steady states


def driven_run(method, eps, beta, lam, seed, scale):
    """theta_st over s in [S_FROM, S_TO + 60] of a driven disk run started at the theory's state."""
    d = 2
    base = _rough(d, eps, beta, None, heating_rate=1.0, rotational_fraction=lam)
    T1, _ = R.driven_state(base)
    h = T1 ** -1.5  # T_st = 1 (T_st ~ H^(2/3) at fixed theta)
    rough = _rough(d, eps, beta, None, heating_rate=h, rotational_fraction=lam)
    T, Tr = R.driven_state(rough)
    zeta = h / T
    n = int((N_EDMD[d] if method == "edmd" else N_DSMC) * scale)
    drv = WhiteNoise(h, theory.driving_interval(zeta), seed=seed, rotational_fraction=lam)
    sim = _simulation(method, _state(method, d, n, seed, T, Tr), eps, TangentialRule.constant(beta), drv, seed)
    thetas = []
    for s in np.arange(S_FROM, S_TO + 60.5, 2.0):
        sim.run(math.inf, max_collisions=max(int(s * n / 2) - sim.collisions, 1))
        thetas.append(sim.rotational_temperature / sim.temperature)
    return float(np.mean(thetas)), Tr / T


def scene_driven(seeds, scale):
    out = []
    print(f"driven rough disks (kappa = 1/2): theta_st, {seeds} seeds; Megias & Santos (2022) EDMD, DSMC")
    for (eps, beta, lam), (pub_edmd, pub_dsmc) in PUBLISHED.items():
        row = {"eps": eps, "beta": beta, "fraction": lam, "published_edmd": pub_edmd, "published_dsmc": pub_dsmc}
        for method in ("edmd", "dsmc"):
            k = seeds * (SEEDS_2D if method == "edmd" else 1)
            res = [driven_run(method, eps, beta, lam, seed, scale) for seed in range(1, k + 1)]
            row[f"theta_{method}"], row[f"theta_{method}_error"] = _mean_err([r[0] for r in res])
            row["theta_theory"] = res[0][1]
        print(f"  eps = {eps:g}, beta_t = {beta:g}, fraction {lam:g}: EDMD {row['theta_edmd']:.4f}"
              f"({1e4 * row['theta_edmd_error']:.0f}) DSMC {row['theta_dsmc']:.4f}({1e4 * row['theta_dsmc_error']:.0f}); "
              f"published EDMD {pub_edmd:.4f} DSMC {pub_dsmc:.4f}; Maxwellian {row['theta_theory']:.4f}")
        out.append(row)
    return out


# ---------------------------------------------------------------- Mpemba


MPEMBA = {"d": 3, "eps": 0.9, "beta": 0.0, "hot": (12.0, 0.0), "cold": (1.1, 22.0), "t_end": 60.0}


def mpemba_curves():
    m = MPEMBA
    base = _rough(m["d"], m["eps"], m["beta"], None, heating_rate=1.0)
    h = R.driven_state(base)[0] ** -1.5
    curves = {}
    for name in ("hot", "cold"):
        T0, R0 = m[name]
        g = _rough(m["d"], m["eps"], m["beta"], None, heating_rate=h, T=T0, rotational_temperature=R0)
        curves[name] = R.two_temperature_curve(g, m["t_end"])
    return h, curves


def mpemba_run(method, seed, scale, h):
    m = MPEMBA
    d = m["d"]
    n = int((N_EDMD[d] if method == "edmd" else N_DSMC) * scale)
    hot_gas = _rough(d, m["eps"], m["beta"], None, heating_rate=h, T=m["hot"][0])
    zeta = max(R.cooling_rates(hot_gas, m["hot"][0], m["hot"][0])[0], h)
    drv = WhiteNoise(h, theory.driving_interval(zeta), seed=seed)
    times = np.arange(0.0, m["t_end"] + 1e-9, 0.25)
    out = {}
    for name in ("hot", "cold"):
        T0, R0 = m[name]
        sim = _simulation(method, _state(method, d, n, seed, T0, R0), m["eps"], TangentialRule.constant(m["beta"]),
                          drv, seed)
        T = []
        for t in times:
            sim.run(t)
            T.append(sim.temperature)
        out[name] = np.array(T)
    return times, out


def _crossing(times, a, b):
    diff = np.log(a) - np.log(b)
    k = np.flatnonzero(np.sign(diff[1:]) != np.sign(diff[:-1]))
    if not k.size:
        return math.nan
    i = int(k[0])
    return float(times[i] - diff[i] * (times[i + 1] - times[i]) / (diff[i + 1] - diff[i]))


def scene_mpemba(seeds, scale):
    h, curves = mpemba_curves()
    t_th = R.mpemba_crossing_time(curves["hot"], curves["cold"])
    row = {"heating_rate": h, "crossing_theory": t_th, **{k: v for k, v in MPEMBA.items()}}
    mean_curves = {}
    for method in ("edmd", "dsmc"):
        crossings, runs = [], []
        for seed in range(1, seeds + 1):
            times, T = mpemba_run(method, seed, scale, h)
            crossings.append(_crossing(times, T["hot"], T["cold"]))
            runs.append(T)
        row[f"crossing_{method}"], row[f"crossing_{method}_error"] = _mean_err(crossings)
        mean_curves[method] = (times, {k: np.mean([r[k] for r in runs], axis=0) for k in ("hot", "cold")})
    print(f"Mpemba (3D, eps = 0.9, beta_t = 0, T_st = 1): hot T_tr = 12, T_rot = 0; cold T_tr = 1.1, T_rot = 22: "
          f"crossing EDMD {row['crossing_edmd']:.3f}({1e3 * row['crossing_edmd_error']:.0f}) "
          f"DSMC {row['crossing_dsmc']:.3f}({1e3 * row['crossing_dsmc_error']:.0f}) Maxwellian {t_th:.3f}")
    return row, curves, mean_curves


# ---------------------------------------------------------------- figures


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_hcs(rows, path):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    x = np.arange(len(rows))
    for k, (method, marker) in enumerate((("edmd", "o"), ("dsmc", "s"))):
        y = [r[f"theta_{method}"] / r["theta_theory"] for r in rows]
        e = [r[f"theta_{method}_error"] / r["theta_theory"] for r in rows]
        ax.errorbar(x + 0.12 * (k - 0.5), y, yerr=e, fmt=marker, ms=5, capsize=3, label=method.upper())
    ax.axhline(1.0, color="k", lw=1, label="Maxwellian theory, eq. (R7)")
    labels = [f"{r['d']}D ε={r['eps']:g}\n" + (f"β₀={r['beta']:g}, μ={r['mu']:g}" if r["mu"] is not None
                                                 else f"β_t={r['beta']:g}") for r in rows]
    ax.set_xticks(x, labels, fontsize=8)
    ax.set_ylabel("θ_HCS / Maxwellian θ_HCS")
    ax.set_title("Homogeneous cooling state of rough particles: EDMD and DSMC against theory", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_driven(rows, path):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    x = np.arange(len(rows))
    for k, (key, marker, label) in enumerate((("theta_edmd", "o", "EDMD (granulargas)"), ("theta_dsmc", "s", "DSMC (granulargas)"),
                                              ("published_edmd", "^", "EDMD, Megías & Santos (2022)"),
                                              ("published_dsmc", "v", "DSMC, Megías & Santos (2022)"))):
        y = [r[key] / r["theta_theory"] for r in rows]
        e = [r.get(key + "_error", 0.0) / r["theta_theory"] for r in rows]
        ax.errorbar(x + 0.1 * (k - 1.5), y, yerr=e, fmt=marker, ms=5, capsize=3, label=label, mfc="none" if k > 1 else None)
    ax.axhline(1.0, color="k", lw=1, label="Maxwellian theory")
    ax.set_xticks(x, [f"ε={r['eps']:g}, β_t={r['beta']:g}\nfraction {r['fraction']:g}" for r in rows], fontsize=8)
    ax.set_ylabel("θ_st / Maxwellian θ_st")
    ax.set_title("Driven rough disks (κ = 1/2), splitting thermostat", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_mpemba(row, curves, mean_curves, path):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.0, 4.5))
    t = np.linspace(0.0, MPEMBA["t_end"], 600)
    for name, color in (("hot", "C3"), ("cold", "C0")):
        ax.plot(t, curves[name].translational_at(t), "-", color=color, lw=1.3,
                label=f"{name}: T_tr(0) = {MPEMBA[name][0]:g}, T_rot(0) = {MPEMBA[name][1]:g} (theory)")
        for method, ls in (("edmd", "--"), ("dsmc", ":")):
            times, T = mean_curves[method]
            ax.plot(times, T[name], ls, color=color, lw=1, label=f"{name}, {method.upper()}")
    ax.axvline(row["crossing_theory"], color="k", lw=0.8, label=f"theory crossing t = {row['crossing_theory']:.3g}")
    ax.set_yscale("log")
    ax.set_xlabel("time")
    ax.set_ylabel("translational temperature T_tr")
    ax.set_title("Mpemba effect of rough spheres (translation driven, T_st = 1)", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", nargs="+", default=["hcs", "driven", "mpemba"], choices=("hcs", "driven", "mpemba"))
    p.add_argument("--seeds", type=int, default=4)
    p.add_argument("--scale", type=float, default=1.0)
    p.add_argument("--json", default=None)
    p.add_argument("--outdir", default=None)
    args = p.parse_args(argv)
    results = {"seeds": args.seeds, "scale": args.scale}
    out = Path(args.outdir) if args.outdir else None
    if "hcs" in args.scene:
        results["hcs"] = scene_hcs(args.seeds, args.scale)
        if out:
            plot_hcs(results["hcs"], out / "rough_hcs_validation.png")
    if "driven" in args.scene:
        results["driven"] = scene_driven(args.seeds, args.scale)
        if out:
            plot_driven(results["driven"], out / "rough_driven_validation.png")
    if "mpemba" in args.scene:
        row, curves, mean_curves = scene_mpemba(args.seeds, args.scale)
        results["mpemba"] = row
        if out:
            plot_mpemba(row, curves, mean_curves, out / "rough_mpemba.png")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1, default=float))


if __name__ == "__main__":
    main()
