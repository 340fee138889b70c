"""Speed against accuracy of every way to get eps(beta): one chart, three beta ranges.

For small (1e-4..1e-2), moderate (0.05..0.5) and large (1..3) beta, plots the
maximum absolute error of eps over a sample of beta against the cost of one
evaluation, for

* the regularised ODE by our compiled Taylor method at several (order, tolerance),
* the same ODE by scipy's DOP853 at several tolerances (Python callbacks),
* a naive fixed-step RK4 on x(t) started at x = 0 (what the sqrt singularity breaks),
* the truncated series of orders 1..20 (compiled Horner),
* the Mueller-Poeschel Pade approximant (compiled; force end),
* restitution tables of several sizes (the engine's compiled lookup).

Reference: Taylor method, order 28, tolerance 1e-17 (agrees with DOP853 at
rtol 1e-13 to ~1e-14, tests/contact). Costs are medians of several runs; compiled
kernels are warmed up first and their compile time printed separately. Costs of
compiled evaluators are per element of a loop over 2e5 random beta (throughput).

    python scripts/contact/epsilon_speed_accuracy.py [--end overlap|force] [--out docs/figures/contact_speed_accuracy.png]
"""

from __future__ import annotations

import argparse
import time
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from granulargas._numba import jit
from granulargas.contact import ode, series
from granulargas.contact.lookup import table_lookup
from granulargas.contact.pade import A_PADE, C1
from granulargas.contact.table import _build

RANGES = {"small": (1e-4, 1e-2), "moderate": (0.05, 0.5), "large": (1.0, 3.0)}


@jit
def horner_loop(x, c, out):
    for i in range(x.shape[0]):
        v = c[c.shape[0] - 1]
        for k in range(c.shape[0] - 2, -1, -1):
            v = v * x[i] + c[k]
        out[i] = v


@jit
def series_loop(beta, c, sqrt_variable, out):
    for i in range(beta.shape[0]):
        x = np.sqrt(beta[i]) if sqrt_variable else beta[i]
        v = c[c.shape[0] - 1]
        for k in range(c.shape[0] - 2, -1, -1):
            v = v * x + c[k]
        out[i] = v


@jit
def pade_loop(beta, a, c1, out):
    for i in range(beta.shape[0]):
        u = np.sqrt(beta[i])
        out[i] = (1 + a * u) / (1 + a * u + c1 * u * u + a * c1 * u ** 3 + 0.4 * c1 * c1 * u ** 4)


@jit
def table_loop(beta, inv_h, coeffs, out):
    for i in range(beta.shape[0]):
        out[i] = table_lookup(beta[i], inv_h, coeffs)


def median_time(f, repeats=5):
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--end", default="overlap", choices=["overlap", "force"])
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    end = args.end
    out_png = args.out or f"docs/figures/contact_speed_accuracy{'' if end == 'overlap' else '_force'}.png"
    rng = np.random.default_rng(1)
    sqrt_var = end == "force"

    # compile (or load) the kernels once, report the time separately
    t0 = time.perf_counter()
    dummy = np.full(4, 0.1)
    o4 = np.empty(4)
    horner_loop(dummy, np.ones(3), o4)
    series_loop(dummy, np.ones(3), sqrt_var, o4)
    pade_loop(dummy, A_PADE, C1, o4)
    tab = _build(4, 1 / 8, end)
    table_loop(dummy, 8.0, tab[0], o4)
    ode.solve_many(dummy, end)
    print(f"compile/load of compiled kernels: {time.perf_counter() - t0:.2f} s (not included below)")

    results = {}  # range -> list of (family, label, cost_s, err)
    for rname, (lo, hi) in RANGES.items():
        acc_b = np.sort(rng.uniform(lo, hi, 400))
        ref = ode.solve_many(acc_b, end, order=28, tol=1e-17)[:, 0]
        cost_b = rng.uniform(lo, hi, 200_000)
        buf = np.empty_like(cost_b)
        rows = []

        def record(family, label, values, cost):
            err = float(np.max(np.abs(values - ref)))
            rows.append((family, label, cost, max(err, 1e-17)))
            print(f"{rname:9s} {family:10s} {label:22s} cost {cost * 1e9:12.1f} ns   max|err| {err:.2e}")

        # ODE, compiled Taylor method
        for order, tol in [(8, 1e-5), (12, 1e-8), (16, 1e-11), (20, 1e-14), (24, 1e-16)]:
            b_small = cost_b[:300]
            cost = median_time(lambda: ode.solve_many(b_small, end, order=order, tol=tol), 3) / b_small.size
            record("ode-taylor", f"K={order}, tol={tol:g}", ode.solve_many(acc_b, end, order=order, tol=tol)[:, 0],
                   cost)
        # ODE, scipy DOP853 (a few points: Python callbacks)
        sub = acc_b[::40]
        ref_sub = ref[::40]
        for rtol in [1e-6, 1e-9, 1e-12]:
            t0 = time.perf_counter()
            vals = np.array([ode.solve_contact_scipy(b, end, rtol=rtol, atol=rtol * 1e-3)[0] for b in sub])
            cost = (time.perf_counter() - t0) / sub.size
            err = float(np.max(np.abs(vals - ref_sub)))
            rows.append(("ode-scipy", f"DOP853 rtol={rtol:g}", cost, max(err, 1e-17)))
            print(f"{rname:9s} ode-scipy  rtol={rtol:<17g} cost {cost * 1e9:12.1f} ns   max|err| {err:.2e}")
        # naive RK4 from x = 0
        for dt in [1e-2, 1e-3]:
            t0 = time.perf_counter()
            vals = np.array([ode.solve_contact_naive(b, end, dt)[0] for b in sub[:3]])
            cost = (time.perf_counter() - t0) / 3
            err = float(np.max(np.abs(vals - ref_sub[:3])))
            rows.append(("naive-rk4", f"dt={dt:g}", cost, max(err, 1e-17)))
            print(f"{rname:9s} naive-rk4  dt={dt:<19g} cost {cost * 1e9:12.1f} ns   max|err| {err:.2e}")
        # series, orders 1..20 (in u for the force end: orders 2..40 step 2)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for n in range(1, 21):
                order = n if end == "overlap" else 2 * n
                c = series.restitution_coefficients(order, end)
                cost = median_time(lambda: series_loop(cost_b, c, sqrt_var, buf)) / cost_b.size
                vals = np.empty_like(acc_b)
                series_loop(acc_b, c, sqrt_var, vals)
                record("series", f"order {order}", vals, cost)
        # Pade
        cost = median_time(lambda: pade_loop(cost_b, A_PADE, C1, buf)) / cost_b.size
        vals = np.empty_like(acc_b)
        pade_loop(acc_b, A_PADE, C1, vals)
        record("pade", "Mueller-Poeschel", vals, cost)
        # tables of several sizes
        for ipu in [8, 16, 32, 64, 128, 256]:
            n = int(np.sqrt(hi) * ipu) + 1
            coeffs = _build(n, 1.0 / ipu, end)[0]
            cost = median_time(lambda: table_loop(cost_b, float(ipu), coeffs, buf)) / cost_b.size
            vals = np.empty_like(acc_b)
            table_loop(acc_b, float(ipu), coeffs, vals)
            record("table", f"{ipu}/unit sqrt(beta)", vals, cost)
        results[rname] = rows

    style = {"ode-taylor": ("o", "C0"), "ode-scipy": ("s", "C1"), "naive-rk4": ("x", "C3"),
             "series": ("^", "C2"), "pade": ("*", "C4"), "table": ("D", "C5")}
    fig, axes = plt.subplots(1, 3, figsize=(15, 5), sharey=True, sharex=True)
    for ax, (rname, rows) in zip(axes, results.items()):
        for fam, (mk, col) in style.items():
            pts = [(c, e) for f, _, c, e in rows if f == fam]
            if pts:
                c, e = np.array(pts).T
                ax.loglog(c * 1e9, np.minimum(e, 10.0), mk, color=col, label=fam, ms=8 if fam == "pade" else 6,
                          ls="-" if fam in ("series", "table", "ode-taylor") else "none", lw=0.8)
        for f, lab, c, e in rows:
            if f == "series" and lab in ("order 1", "order 2", "order 20", "order 40"):
                ax.annotate(lab.replace("order ", "n="), (c * 1e9, min(e, 10.0)), fontsize=7, xytext=(3, 3),
                            textcoords="offset points")
            if f == "ode-taylor" and lab.startswith(("K=8,", "K=24")):
                ax.annotate(lab.split(",")[0], (c * 1e9, e), fontsize=7, xytext=(4, 0), textcoords="offset points")
            if f == "table" and lab.split("/")[0] in ("8", "256"):
                ax.annotate(lab.split(" ")[0], (c * 1e9, e), fontsize=7, xytext=(3, -9), textcoords="offset points")
        lo, hi = RANGES[rname]
        ax.axhline(1e-8, color="gray", ls=":", lw=0.8)
        ax.set_title(f"{rname} beta: {lo:g} - {hi:g}  ({end} end)")
        ax.set_xlabel("cost per evaluation [ns]")
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("max |eps - eps_ref| over the range")
    axes[0].legend(loc="center", fontsize=8)
    fig.suptitle(f"eps(beta), {end} end: error against cost per evaluation (reference: Taylor K=28, tol 1e-17; "
                 "series errors clipped at 10; dotted: table target 1e-8)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out_png, dpi=120)
    print(f"wrote {out_png}")


if __name__ == "__main__":
    main()
