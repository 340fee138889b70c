"""The homogeneous-cooling-state reference table: a2, a3 and the cooling-rate factors by DSMC.

Builds ``granulargas/theory/hcs_dsmc_table.csv``, the table behind
:mod:`granulargas.theory.hcs` (the reference that ``granulargas analyze`` compares a
constant-restitution run with). The DSMC of :mod:`granulargas.dsmc` solves the
homogeneous Enskog-Boltzmann equation up to statistics; in the homogeneous cooling
state (HCS) every velocity scales with sqrt(T(t)), so a2, a3 and the ratios of the
cooling rate zeta and of the collision frequency omega to their Maxwellian values,

    c_zeta = zeta / zeta_M,    zeta_M = (1 - eps^2) omega_M / d,
    c_omega = omega / omega_M, omega_M = Omega_d chi n sigma^(d-1) sqrt(T/m),

are numbers of eps and d alone (first Sonine, van Noije & Ernst 1998:
c_zeta = 1 + 3 a2/16, c_omega = 1 - a2/16).

For each (d, eps) the script runs ``--seeds`` independent DSMC gases of ``--n``
particles from Maxwellian velocities; each relaxes for ``--relax`` collisions per
particle, then ``--samples`` snapshots follow one collision per particle apart
(exactly N/2 collisions). Per snapshot interval k: a2, a3 at its end, the energy ratio
(the cooling per collision, -d ln T/ds = zeta/omega, telescopes over the run) and its
duration dt_k. With T log-linear in s inside an interval (exact in the HCS),
omega_M integrated over it is ``(2/(r K sqrt(T_k))) (exp(r/2) - 1)`` (r = ln(T_k/T_(k+1)),
K = omega_M/sqrt(T)), so ``c_omega = mean_k of that / dt_k`` and
``c_zeta = c_omega r d / (1 - eps^2)``. Velocities are rescaled to T = 1 every
``--block`` collisions per particle (a fresh DSMC with a new seed: the velocity-only
Markov process has no other state), which keeps <v^6> far from underflow. Each seed
gives one mean of each quantity; the table's errors are the standard errors of the
seed means (their scatter over sqrt(seeds)), so correlations between successive
snapshots need no model.

The transient from the Maxwellian start (the table's ``relaxation_rate``): ``--relax-seeds``
further gases run ``--relax`` collisions per particle from Maxwellian velocities; once
relaxed, ln T(s) = -k q s + delta (k = (1 - eps^2)/d, q = c_zeta/c_omega of the table, 1 at
the start), and a factor relaxing as exp(-rate s) gives delta = k (q - 1)/rate. delta is
the mean of ln T(s) + k q s over the last third of the ``--relax`` collisions per particle;
the rate is stored where it is resolved (3 standard errors), else nan.

Printed with the table: the first-Sonine values, the stationarity check (a2 over
the first and the second half of the samples), the lag-1 autocorrelation of a2, the
transient's rate with its error, the rate of an exponential fitted to the seed-mean a2(s)
of the transient (s >= 2; where |a2| > 0.02) and the relaxation rate of a2 in the first
Sonine moment equations; then the leave-one-out check of the interpolation.

    python scripts/validation/hcs_reference_table.py                 # 7e9 collisions: 10-15 min on one idle core; writes the table
    python scripts/validation/hcs_reference_table.py --quick --out /tmp/t.csv   # checks the script (~1 min)
    python scripts/validation/hcs_reference_table.py --update-relaxation        # only the transient (~5 min)
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from granulargas import theory  # noqa: E402
from granulargas.dsmc import DSMC  # noqa: E402
from granulargas.engine import CollisionRule  # noqa: E402
from granulargas.state import State  # noqa: E402
from granulargas.theory import hcs  # noqa: E402

DENSITY = 0.01  # number density of the DSMC gas; with chi = 1 it only sets the time unit


def make_dsmc(velocities, eps, seed):
    """A DSMC of identical unit particles (diameter 1, mass 1) at ``DENSITY``, Boltzmann (chi = 1)."""
    return DSMC(State(None, velocities, 0.5, 1.0, None), CollisionRule.constant(eps), number_density=DENSITY, chi=1.0,
                seed=seed)


def rescaled(sim):
    """The DSMC's peculiar velocities scaled to T = 1."""
    return sim.velocities / math.sqrt(sim.temperature)


def run_seed(dim, eps, n, relax, samples, block, seed):
    """One independent gas: per-interval samples after the relaxation (module doc)."""
    k_max = theory.collision_frequency(DENSITY, 1.0, dim, 1.0, 1.0, chi=1.0)  # omega_M at T = 1
    v = np.random.default_rng(seed).standard_normal((n, dim))
    sub = 0
    sim = make_dsmc(v, eps, seed * 100_003 + sub)
    for s in range(relax):
        if s and s % block == 0:
            sub += 1
            sim = make_dsmc(rescaled(sim), eps, seed * 100_003 + sub)
        sim.run(np.inf, max_collisions=n // 2)
    a2, a3, log_ratio, c_omega = (np.empty(samples) for _ in range(4))
    for k in range(samples):
        if k % block == 0:
            sub += 1
            sim = make_dsmc(rescaled(sim), eps, seed * 100_003 + sub)
        T0, t0 = sim.temperature, sim.time
        sim.run(np.inf, max_collisions=n // 2)
        r = math.log(T0 / sim.temperature)
        dt = sim.time - t0
        omega_m = 2.0 / (r * k_max * math.sqrt(T0)) * math.expm1(0.5 * r) if r > 0 else 1.0 / (k_max * math.sqrt(T0))
        a2[k], a3[k], log_ratio[k], c_omega[k] = sim.sonine_a2, sim.sonine_a3, r, omega_m / dt
    return a2, a3, log_ratio, c_omega


def relaxation(dim, eps, n, collisions, seeds, q_hcs):
    """The transient from a Maxwellian start: (rate, its error, a2 trace), module doc.

    In collisions per particle s, ln T(s) = -k q_HCS s + delta once relaxed (k = (1 - eps^2)/d,
    q = c_zeta/c_omega, 1 at the Maxwellian start); a factor relaxing as exp(-rate s) gives
    delta = k (q_HCS - 1) / rate. delta is the mean of ln T(s) + k q_HCS s over the last third
    of ``collisions`` and over ``seeds`` gases.
    """
    k = (1.0 - eps * eps) / dim
    offsets, traces = [], []
    for seed in range(1001, 1001 + seeds):
        sim = make_dsmc(np.random.default_rng(seed).standard_normal((n, dim)), eps, seed)
        T0 = sim.temperature
        ln_t, trace = [], []
        for s in range(1, collisions + 1):
            sim.run(np.inf, max_collisions=n // 2)
            ln_t.append(math.log(sim.temperature / T0) + k * q_hcs * s)
            trace.append(sim.sonine_a2)
        offsets.append(np.mean(ln_t[2 * collisions // 3:]))
        traces.append(trace)
    delta, delta_err = float(np.mean(offsets)), float(np.std(offsets, ddof=1) / math.sqrt(seeds))
    rate = k * (q_hcs - 1.0) / delta if delta != 0 else math.nan
    rate_err = abs(rate) * delta_err / abs(delta) if delta != 0 else math.nan
    return rate, rate_err, np.mean(traces, axis=0)


def lag1(x):
    return float(np.corrcoef(x[:-1], x[1:])[0, 1])


def measure(dim, eps, args):
    """Seed means, their standard errors, and the diagnostics of one (d, eps)."""
    per_seed, half, lags = [], [], []
    for seed in range(1, args.seeds + 1):
        a2, a3, r, c_om = run_seed(dim, eps, args.n, args.relax, args.samples, args.block, seed)
        ratio = r.mean()  # -d ln T / ds per collision per particle (ds = 1 per interval)
        c_omega = c_om.mean()
        c_zeta = c_omega * ratio * dim / (1.0 - eps * eps)
        per_seed.append((a2.mean(), a3.mean(), c_zeta, c_omega))
        m = a2.size // 2
        half.append((a2[:m].mean(), a2[m:].mean()))
        lags.append(lag1(a2))
    x = np.array(per_seed)
    mean = x.mean(axis=0)
    err = x.std(axis=0, ddof=1) / math.sqrt(len(x))
    half = np.array(half)
    return mean, err, {"first_half": half[:, 0].mean(), "second_half": half[:, 1].mean(),
                       "half_error": half.std(axis=0, ddof=1).max() / math.sqrt(len(half)),
                       "lag1": float(np.mean(lags))}


def transient(dim, eps, a2_hcs, c_zeta, c_omega, args):
    """(rate for the table, printed text): the rate from the temperature offset where it is resolved
    (3 standard errors), else nan (theory.hcs then uses the first-Sonine rate)."""
    rate, rate_err, trace = relaxation(dim, eps, args.n, args.relax, args.relax_seeds, c_zeta / c_omega)
    fit = relaxation_rate(trace, a2_hcs) if abs(a2_hcs) > 0.02 else math.nan
    resolved = math.isfinite(rate) and rate > 0 and rate_err < rate / 3
    text = f"{rate:>5.2f}+-{rate_err:<4.2f} {fit:>5.2f} {first_sonine_rate(dim, eps):>5.2f}"
    return (rate if resolved else math.nan), text


def relaxation_rate(trace, a2_hcs):
    """Rate (per collision per particle) of a2(s) = a2_hcs + c exp(-rate s), fitted to the seed-mean
    trace from s = 2 on (the first collision grows a2 from 0 more slowly than the exponential)."""
    from scipy.optimize import curve_fit

    s = np.arange(1, trace.size + 1, dtype=float)
    keep = s >= 2
    (c, rate), _ = curve_fit(lambda x, c, r: a2_hcs + c * np.exp(-r * x), s[keep], trace[keep],
                             p0=(-a2_hcs if a2_hcs else -0.01, 0.5), maxfev=10000)
    return float(rate)


def first_sonine_rate(dim, eps):
    """Relaxation rate of a2 per collision per particle in the first Sonine moment equations
    (theory.gas.cooling_rates: da2/dt is linear in a2)."""
    from granulargas.theory.gas import Gas, cooling_rates

    g = Gas(dimension=dim, packing_fraction=0.01, density=float(theory.number_density(0.01, dim)), sigma=1.0,
            mass=1.0, temperature=1.0, model="constant", restitution=eps)
    _, d0, omega = cooling_rates(g, 1.0, 0.0)
    _, d1, _ = cooling_rates(g, 1.0, 1.0)
    return float(-(d1 - d0) / omega)


def leave_one_out(eps, values):
    """Deviation at each interior node of the cubic spline through the other nodes."""
    from scipy.interpolate import CubicSpline

    out = np.full(eps.size, np.nan)
    for k in range(1, eps.size - 1):
        keep = np.arange(eps.size) != k
        out[k] = CubicSpline(eps[keep], values[keep])(eps[k]) - values[k]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--eps", type=float, nargs="+", default=[round(0.1 + 0.05 * k, 2) for k in range(18)])
    ap.add_argument("--dims", type=int, nargs="+", choices=(2, 3), default=[2, 3])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--relax", type=int, default=20, help="collisions per particle before sampling")
    ap.add_argument("--samples", type=int, default=400, help="snapshots per seed, one collision per particle apart")
    ap.add_argument("--block", type=int, default=25, help="rescale T to 1 every this many collisions per particle")
    ap.add_argument("--relax-seeds", type=int, default=32, help="gases for the transient from the Maxwellian start")
    ap.add_argument("--out", default=str(hcs.TABLE_PATH))
    ap.add_argument("--update-relaxation", action="store_true",
                    help="keep the table's other columns (read from --out) and measure the transient again")
    ap.add_argument("--quick", action="store_true", help="small and short (checks the script, not the physics)")
    args = ap.parse_args(argv)
    if args.quick:
        args.n, args.seeds, args.samples, args.relax_seeds, args.eps = 20_000, 3, 20, 4, [0.3, 0.9]
    previous = []
    if args.update_relaxation:
        table = hcs.read_table(args.out)
        previous = [(d, *row) for d in (2, 3) for row in zip(*(table[d][c] for c in hcs._COLUMNS[1:]))]
    args.n -= args.n % 2
    print(f"HCS reference by DSMC: N = {args.n}, {args.seeds} seeds, {args.relax} collisions per particle to "
          f"relax, {args.samples} snapshots per seed one collision per particle apart; errors: seed scatter / "
          f"sqrt({args.seeds})")
    print(f"{'d':>2} {'eps':>5} {'a2':>9} {'+-':>7} {'a2 vNE':>8} {'a3':>9} {'+-':>7} {'c_zeta':>8} {'+-':>7} "
          f"{'1+3a2/16':>8} {'c_omega':>8} {'+-':>7} {'1-a2/16':>8} {'a2 1st/2nd half':>17} {'lag1':>5} "
          f"{'rate (T)':>10} {'a2 fit':>6} {'1st S':>5} {'s':>5}", flush=True)
    rows = []
    for dim in args.dims:
        for eps in args.eps:
            t0 = time.perf_counter()
            if args.update_relaxation:
                old = [r for r in previous if r[0] == dim and abs(r[1] - eps) < 1e-9]
                if not old:
                    continue
                mean, err = np.array(old[0][2:10:2]), np.array(old[0][3:10:2])
                diag = {"first_half": math.nan, "second_half": math.nan, "lag1": math.nan}
            else:
                mean, err, diag = measure(dim, eps, args)
            rate, text = transient(dim, eps, mean[0], mean[2], mean[3], args)
            vne = float(theory.sonine_a2(eps, dim))
            rows.append((dim, eps, mean[0], err[0], mean[1], err[1], mean[2], err[2], mean[3], err[3], rate))
            print(f"{dim:>2} {eps:>5.2f} {mean[0]:>+9.5f} {err[0]:>7.5f} {vne:>+8.5f} {mean[1]:>+9.5f} {err[1]:>7.5f} "
                  f"{mean[2]:>8.5f} {err[2]:>7.5f} {1 + 3 * vne / 16:>8.5f} {mean[3]:>8.5f} {err[3]:>7.5f} "
                  f"{1 - vne / 16:>8.5f} {diag['first_half']:>+8.5f}/{diag['second_half']:>+8.5f} "
                  f"{diag['lag1']:>5.2f} {text} {time.perf_counter() - t0:>5.0f}", flush=True)
    rows = np.array(rows)
    # leave-one-out check of the interpolation, on the differences from first Sonine (module doc of theory.hcs)
    print("\ninterpolation (cubic spline of the difference from first Sonine, through eps = 1 where it is 0): "
          "leave-one-out deviation / combined error at interior nodes")
    for dim in args.dims:
        sel = rows[:, 0] == dim
        if sel.sum() < 3:
            continue
        e = np.append(rows[sel, 1], 1.0)
        vne = theory.sonine_a2(e, dim)
        for name, col, first in (("a2", 2, vne), ("c_zeta", 6, 1 + 3 * vne / 16), ("c_omega", 8, 1 - vne / 16)):
            diff = np.append(rows[sel, col], first[-1]) - first
            err = np.append(rows[sel, col + 1], 0.0)
            loo = leave_one_out(e, diff)
            inner = slice(1, e.size - 1)
            # the spline through every node has spacing h, the leave-one-out one 2h: a cubic's error
            # ~ h^4, so 1/16 of the deviation bounds the table's interpolation error (noise included)
            z = loo[inner] / np.sqrt(err[inner] ** 2 + 0.25 * (err[:-2] ** 2 + err[2:] ** 2))
            print(f"  {dim}D {name:>7}: max |deviation| {np.nanmax(np.abs(loo)):.2g} (/16 = "
                  f"{np.nanmax(np.abs(loo)) / 16:.2g}); rms deviation/error {np.sqrt(np.mean(z ** 2)):.2f}")
    hcs.write_table(args.out, rows, header=(
        f"HCS of smooth inelastic hard {{disks, spheres}} by DSMC (homogeneous Enskog-Boltzmann equation): "
        f"scripts/validation/hcs_reference_table.py, N = {args.n}, {args.seeds} seeds x {args.samples} snapshots one "
        f"collision per particle apart after {args.relax} to relax; errors: standard error of the seed means; "
        f"relaxation_rate: {args.relax_seeds} gases over {args.relax} collisions per particle from a Maxwellian "
        f"start, nan where not resolved"))
    print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
