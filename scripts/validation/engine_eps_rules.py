"""Evaluating eps inside the engine: cost per collision and error of the cooling curve.

Candidates for the engine's viscoelastic rule:

* the ODE tabulated on grids of 2..128 intervals per unit of s = sqrt(beta)
  (cubic Hermite in s, the layout of :func:`granulargas.contact.restitution_table`;
  values and derivatives from the Taylor ODE solver);
* truncated series of eps, ``overlap`` end in powers of beta (orders 1..8) and
  ``force`` end in powers of sqrt(beta) (orders 2..8);
* the Mueller-Poeschel Pade approximant (``force`` end).

The engine evaluates eps through a table. To run a series or the Pade as the
rule, the function is tabulated finely (512 intervals per unit, Hermite error
~1e-13, far below the functions' own errors): the cooling-curve error measured
is the function's. Its cost per collision is the cost of the engine with the
reference table plus the difference between one evaluation of the function
(numba-compiled Horner / rational) and one table lookup, both measured in
isolation (loops over 1e6 beta drawn from the run's range).

Cooling-curve error = largest relative deviation of T(t) from the reference
(the 128-interval table of the same contact end) over the run:
predicted by kinetic theory (:func:`granulargas.run.validity.viscoelastic_cooling`
with the candidate eps) and measured with engine runs (mean over seeds of the
per-seed ratio, same initial states; +- standard error).

    python scripts/validation/engine_eps_rules.py [--quick] [--seeds 4] [--particles 2000] [--damping 0.3]

Writes ``docs/figures/choice_eps_rule.png``. Timings on a shared machine.
"""

from __future__ import annotations

from dataclasses import replace
import argparse
import math
import time
from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from granulargas import theory
from granulargas.run import validity as V
from granulargas._numba import jit
from granulargas.contact import restitution_table
from granulargas.contact.lookup import table_lookup, table_lookup_many
from granulargas.contact.ode import solve_many
from granulargas.contact.pade import A_PADE, C1
from granulargas.contact.series import restitution_coefficients
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state


@dataclass(frozen=True)
class Table:
    """What CollisionRule.viscoelastic needs: inv_h and coeffs (lookup layout)."""

    inv_h: float
    coeffs: np.ndarray


def hermite_table(value_and_ds, beta_max, intervals_per_unit):
    """Cubic Hermite table in s = sqrt(beta) of a function given with its s-derivative."""
    h = 1.0 / intervals_per_unit
    n = int(math.floor(math.sqrt(beta_max) * intervals_per_unit)) + 1
    s = np.arange(n + 1) * h
    f, dfds = value_and_ds(s)
    d0, d1 = dfds[:-1] * h, dfds[1:] * h
    f0, f1 = f[:-1], f[1:]
    c = np.empty((n, 4))
    c[:, 0], c[:, 1] = f0, d0
    c[:, 2] = 3.0 * (f1 - f0) - 2.0 * d0 - d1
    c[:, 3] = 2.0 * (f0 - f1) + d0 + d1
    return Table(float(intervals_per_unit), np.ascontiguousarray(c))


def ode_function(end):
    def f(s):
        rows = solve_many(s * s, end)
        return rows[:, 0], 2.0 * s * rows[:, 2]
    return f


def series_function(order, end):
    c = restitution_coefficients(order, end)
    k = np.arange(len(c))

    def f(s):
        x = s * s if end == "overlap" else s
        val = np.polynomial.polynomial.polyval(x, c)
        dx = np.polynomial.polynomial.polyval(x, (k * c)[1:]) if len(c) > 1 else 0 * x
        return val, dx * (2.0 * s if end == "overlap" else 1.0)
    return f


def pade_function():
    a = A_PADE
    num = np.array([1.0, a])
    den = np.array([1.0, a, C1, a * C1, 0.4 * C1**2])
    P = np.polynomial.polynomial

    def f(u):
        n_, d_ = P.polyval(u, num), P.polyval(u, den)
        dn, dd = P.polyval(u, P.polyder(num)), P.polyval(u, P.polyder(den))
        return n_ / d_, (dn * d_ - n_ * dd) / d_**2
    return f


def tabulated(table):
    def eps(beta):
        b = np.ascontiguousarray(np.asarray(beta, dtype=float).ravel())
        out = np.empty_like(b)
        table_lookup_many(b, table.inv_h, table.coeffs, out)
        return out.reshape(np.shape(beta))
    return eps


# ------------------------------------------------- per-evaluation costs (isolation)


@jit
def _loop_table(beta, inv_h, coeffs):
    acc = 0.0
    for i in range(beta.shape[0]):
        acc += table_lookup(beta[i], inv_h, coeffs)
    return acc


@jit
def _loop_series(beta, c, sqrt_variable):
    acc = 0.0
    for i in range(beta.shape[0]):
        x = math.sqrt(beta[i]) if sqrt_variable else beta[i]
        v = c[c.shape[0] - 1]
        for k in range(c.shape[0] - 2, -1, -1):
            v = v * x + c[k]
        acc += v
    return acc


@jit
def _loop_pade(beta, a, c1):
    acc = 0.0
    for i in range(beta.shape[0]):
        u = math.sqrt(beta[i])
        acc += (1.0 + a * u) / (1.0 + a * u + c1 * u * u + a * c1 * u * u * u + 0.4 * c1 * c1 * u * u * u * u)
    return acc


@jit
def _loop_empty(beta):
    acc = 0.0
    for i in range(beta.shape[0]):
        acc += beta[i]
    return acc


def per_eval_ns(fn, *a, repeats=7):
    fn(*a)
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(*a)
        ts.append(time.perf_counter() - t0)
    return 1e9 * float(np.median(ts)) / a[0].shape[0]


# ------------------------------------------------------------------- engine runs


def engine_runs(n, damping, table, seeds, t_end, times):
    """T(times) per seed and the median wall time per collision."""
    out, cost = [], []
    for seed in range(1, seeds + 1):
        st = random_state(n=n, packing=0.1, dimension=3, temperature=1.0, seed=seed)
        sim = Simulation(st, CollisionRule.viscoelastic(prefactor=damping, table=table))
        T = []
        t0 = time.perf_counter()
        for t in times:
            sim.run(until=float(t))
            T.append(sim.temperature)
        wall = time.perf_counter() - t0
        out.append(T)
        cost.append(wall / max(sim.collisions, 1))
    return np.array(out), 1e9 * float(np.median(cost))


def time_engine(table, damping, n=4000, collisions=200_000, repeats=3):
    """Median wall time per collision [ns] of a viscoelastic run (3D, packing 0.1, T0 = 1)."""
    st = random_state(n=n, packing=0.1, dimension=3, temperature=1.0, seed=11)
    out = []
    for _ in range(repeats):
        sim = Simulation(st, CollisionRule.viscoelastic(prefactor=damping, table=table))
        sim.run(until=1e-6)  # build outside the timing
        t0 = time.perf_counter()
        sim.run(until=math.inf, max_collisions=collisions)
        out.append((time.perf_counter() - t0) / collisions)
    return 1e9 * float(np.median(out))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--seeds", type=int, default=32)
    ap.add_argument("--particles", type=int, default=500,
                    help="keep the box below the shear-instability length (~14 diameters here)")
    ap.add_argument("--damping", type=float, default=0.3)
    ap.add_argument("--end-time", type=float, default=100.0)
    ap.add_argument("--out", default="docs/figures/choice_eps_rule.png")
    args = ap.parse_args(argv)
    n, seeds, b, t_end = args.particles, args.seeds, args.damping, args.end_time
    sizes = [2, 4, 8, 16, 32, 128]
    orders = {"overlap": [1, 2, 3, 4, 6, 8], "force": [2, 4, 5, 6, 8]}
    if args.quick:
        n, seeds, t_end, sizes, orders = 300, 2, 10.0, [4, 128], {"overlap": [1, 2], "force": [4]}
    timing = dict(n=500, collisions=20_000, repeats=1) if args.quick else {}
    wall0 = time.perf_counter()
    # rigorous beta bound of the runs (run.prepare): g_n <= 2 sqrt(2 E / m), R_eff <= 1/2, m_eff >= 1/2
    g_max = 2.0 * math.sqrt(2.0 * 1.5 * n * 1.05)
    beta_max = b * (2 * 0.5 / 1.0) ** 0.2 * g_max**0.2
    times = np.linspace(0, t_end, 41)[1:]

    # reference tables (contact module, 128 per unit) and candidates
    ref = {end: restitution_table(beta_max * 1.01, end=end) for end in ("overlap", "force")}
    cands = []  # (label, family, end, table, isolated-cost key)
    for m in sizes:
        t = ref["overlap"] if m == 128 else hermite_table(ode_function("overlap"), beta_max * 1.01, m)
        cands.append((f"table {m}/unit", "table", "overlap", t, ("table", t)))
    for end, ords in orders.items():
        for k in ords:
            c = restitution_coefficients(k, end)
            t = hermite_table(series_function(k, end), beta_max * 1.01, 512)
            cands.append((f"series {end} order {k}", f"series {end}", end, t, ("series", c, end == "force")))
    cands.append(("Pade (force)", "pade", "force", hermite_table(pade_function(), beta_max * 1.01, 512), ("pade",)))
    cands.append(("table 128/unit (force)", "table force", "force", ref["force"], ("table", ref["force"])))

    # isolated per-evaluation costs over beta met in the run (T from 1 to 0.01)
    rng = np.random.default_rng(0)
    temps = 10 ** rng.uniform(-2, 0, 1_000_000)
    g = np.sqrt(2 * temps) * np.sqrt(-2 * np.log1p(-rng.uniform(0, 1, temps.size)))
    betas = np.ascontiguousarray(np.minimum(b * g**0.2, beta_max))
    empty = per_eval_ns(_loop_empty, betas)

    def one(key):
        if key[0] == "table":
            return per_eval_ns(_loop_table, betas, key[1].inv_h, key[1].coeffs, repeats=1)
        if key[0] == "series":
            return per_eval_ns(_loop_series, betas, key[1], key[2], repeats=1)
        return per_eval_ns(_loop_pade, betas, A_PADE, C1, repeats=1)

    def iso(key, repeats=9):
        """(median cost of one evaluation, median of its difference to an interleaved lookup) in ns."""
        own, diff = [], []
        for _ in range(repeats):
            lk = one(("table", ref["overlap"]))
            c = one(key)
            own.append(c)
            diff.append(c - lk)
        return float(np.median(own)), float(np.median(diff))

    iso_ref = iso(("table", ref["overlap"]))[0]
    print(f"isolated cost: empty loop {empty:.2f} ns, table lookup {iso_ref:.2f} ns per evaluation "
          "(medians; compile excluded)")

    # engine: compile once (not timed), then references
    engine_runs(max(n, 300), b, ref["overlap"], 1, 0.5, np.array([0.5]))
    gas = V.Gas(dimension=3, packing_fraction=0.1, density=theory.number_density(0.1, 3), sigma=1.0, mass=1.0,
                temperature=1.0, model="viscoelastic", prefactor=b)
    T_ref, cost_ref, pred_ref = {}, {}, {}
    for end in ("overlap", "force"):
        T_ref[end], _ = engine_runs(n, b, ref[end], seeds, t_end, times)
        cost_ref[end] = time_engine(ref[end], b, **timing)
        pred_ref[end] = V.viscoelastic_cooling(replace(gas, end=end), restitution=tabulated(ref[end]))
    rows = []
    for label, family, end, table, key in cands:
        if table is ref[end]:
            T_runs, cost = T_ref[end], cost_ref[end]
        else:
            T_runs, _ = engine_runs(n, b, table, seeds, t_end, times)
            cost = time_engine(table, b, **timing) if family.startswith("table") else math.nan
        ratio = T_runs / T_ref[end]
        mean = ratio.mean(axis=0) - 1
        sem = ratio.std(axis=0, ddof=1) / math.sqrt(seeds)
        k = int(np.argmax(np.abs(mean)))
        curve = V.viscoelastic_cooling(replace(gas, end=end), restitution=tabulated(table))
        pred = float(np.max(np.abs(curve.temperature_at(times) / pred_ref[end].temperature_at(times) - 1)))
        c_iso, c_diff = iso(key)
        if family.startswith("table"):
            per_coll = cost  # measured in the engine
        else:
            per_coll = cost_ref[end] + c_diff
        bb = np.linspace(0, beta_max, 2001)
        f_err = float(np.max(np.abs(tabulated(table)(bb) - solve_many(bb, end)[:, 0])))
        rows.append(dict(label=label, family=family, end=end, cost=per_coll, iso=c_iso, pred=pred,
                         meas=abs(mean[k]), sem=sem[k], ferr=f_err, engine=cost))
        print(f"{label:26s} eps error {f_err:8.1e} | eval {c_iso:6.2f} ns | per collision {per_coll:7.0f} ns "
              f"(engine {cost:6.0f} ns) | T(t) error predicted {pred:8.1e}, measured {mean[k]:+.1e} "
              f"+- {sem[k]:.1e}", flush=True)
    print(f"beta up to {beta_max:.3g} (bound), damping {b:g}, N = {n}, {seeds} seeds, t_end = {t_end:g}; "
          f"total wall {time.perf_counter() - wall0:.0f} s")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2), gridspec_kw={"width_ratios": [1.35, 1]})
    styles = {"table": ("C0", "o"), "series overlap": ("C1", "s"), "series force": ("C2", "D"),
              "pade": ("C3", "*"), "table force": ("C0", "P")}
    noise = float(np.median([r["sem"] for r in rows if r["sem"] > 0]))
    shown = [r for r in rows if r["pred"] > 0]  # the references are the zero of the scale
    x = np.arange(len(shown))
    for i, r in enumerate(shown):
        col, mk = styles[r["family"]]
        ax1.plot(i, r["pred"], mk, color=col, mfc="none", ms=10)
        m_ = max(r["meas"], 1e-9)
        ax1.errorbar(i, m_, yerr=[[min(r["sem"], 0.7 * m_)], [r["sem"]]], fmt=mk, color=col, ms=5, capsize=2)
    ax1.axhspan(1e-9, 2 * noise, color="0.92", zorder=0)
    ax1.axhline(0.02, color="0.4", ls=":", lw=1)
    ax1.text(len(shown) - 0.5, 0.022, "2 %", fontsize=7, ha="right", va="bottom", color="0.3")
    ax1.text(0, 1.2 * noise, "measured runs cannot resolve this band (2 x s.e.)", fontsize=7, color="0.35")
    ax1.set_xticks(x)
    ax1.set_xticklabels([r["label"].replace("series ", "").replace(" order ", " k=").replace("/unit", "/u")
                         for r in shown], rotation=60, ha="right", fontsize=7)
    ax1.set_yscale("log")
    ax1.set_ylim(1e-9, 1)
    ax1.set_ylabel("largest relative error of T(t) vs the 128/unit table")
    ax1.plot([], [], "ko", mfc="none", ms=9, label="predicted (kinetic theory with that eps)")
    ax1.plot([], [], "ko", ms=5, label="measured (engine runs, +- s.e.)")
    ax1.legend(fontsize=8, loc="lower center")
    ax1.set_title(f"cooling-curve error of each rule (3D, N = {n}, damping {b:g}, t <= {t_end:g})", fontsize=10)
    for fam, (col, mk) in styles.items():
        rs = [r for r in rows if r["family"] == fam]
        if not rs:
            continue
        ax2.plot([r["iso"] for r in rs], [max(r["ferr"], 1e-16) for r in rs], mk, color=col, ms=7, label=fam)
        for r in rs:
            lab = r["label"].split(" order ")[-1] if "order" in r["label"] else r["label"].split()[1] \
                if r["family"].startswith("table") else ""
            ax2.annotate(lab, (r["iso"], max(r["ferr"], 1e-16)), fontsize=6, xytext=(3, 2),
                         textcoords="offset points")
    base = float(np.nanmedian([r["engine"] for r in rows]))
    ax2.text(0.97, 0.55, f"engine: ~{base / 1000:.0f} us per collision\n(median of table runs, shared machine);\n"
             f"one evaluation costs a few ns", transform=ax2.transAxes, fontsize=8, ha="right",
             bbox=dict(fc="white", ec="0.7"))
    ax2.set_yscale("log")
    ax2.set_xlabel("one evaluation in a numba loop [ns] (isolated, median)")
    ax2.set_ylabel(f"max |eps - eps_ODE| for beta <= {beta_max:.2f}")
    ax2.set_title("accuracy of eps itself vs evaluation cost", fontsize=10)
    ax2.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
