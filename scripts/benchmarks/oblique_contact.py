"""Cost of a resolved collision: the oblique-contact lookup against the head-on restitution lookup.

``python scripts/benchmarks/oblique_contact.py [--n 200000] [--repeats 7] [--end overlap]``

Times, per call inside a compiled loop (median of ``--repeats`` runs; the
first-call JIT compile and the table build are reported separately):

* ``table_lookup`` of eps(beta) (what an instantaneous viscoelastic collision needs),
* ``resolve_collision`` (oblique table lookup plus the frame algebra), for
  impacts drawn like a thermal gas (Maxwellian relative velocity, flux-weighted
  impact angle) at two stiffnesses, and for parameters spread over the whole
  table (every call in another cell: the memory-bound worst case).

Also the direct Taylor integration per contact, for scale.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np

from granulargas._numba import jit
from granulargas.contact import oblique as ob
from granulargas.contact import oblique_table, restitution_table
from granulargas.contact.lookup import table_lookup
from granulargas.contact.oblique_lookup import resolve_collision


@jit
def _loop_resolve(g_n, g_t, dist, bconst, xconst, inv_hs, inv_hd, coeffs):
    work = np.empty(3)
    out = np.empty(5)
    acc = 0.0
    bad = 0
    for i in range(g_n.shape[0]):
        if resolve_collision(g_n[i], g_t[i], dist, bconst, xconst, inv_hs, inv_hd, coeffs, work, out) != 0:
            bad += 1
        acc += out[0] + out[1]
    return acc, bad


@jit
def _loop_eps(beta, inv_h, coeffs):
    acc = 0.0
    for i in range(beta.shape[0]):
        acc += table_lookup(beta[i], inv_h, coeffs)
    return acc


def thermal_impacts(rng, n, temperature=1.0, mass_eff=0.5):
    """g_n, g_t of colliding pairs in a Maxwellian gas (3D): |g| ~ g^3 exp(-m_eff g^2 / 2T), cos(theta) ~ 2 x."""
    g = np.sqrt(2 * temperature / mass_eff * rng.gamma(2.0, 1.0, n))
    cos = np.sqrt(rng.uniform(0, 1, n))
    return g * cos, g * np.sqrt(1 - cos * cos)


def timed(fn, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=200_000)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--end", default="overlap", choices=ob.ENDS)
    args = parser.parse_args(argv)
    if args.n < 1000 or args.repeats < 1:
        print(f"scripts/benchmarks/oblique_contact.py: --n must be >= 1000 and --repeats >= 1, got {args.n}, {args.repeats}",
              file=sys.stderr)
        return 2
    rng = np.random.default_rng(1)
    n = args.n
    dist, r_eff, m_eff, damping = 1.0, 0.25, 0.5, 0.1
    bconst = damping  # beta at g_n = 1 for two reference particles
    t0 = time.perf_counter()
    table_e = restitution_table(2.0, end=args.end)
    t_build_e = time.perf_counter() - t0
    t0 = time.perf_counter()
    table_o = oblique_table(2.0, 0.5, end=args.end)
    t_build_o = time.perf_counter() - t0
    t0 = time.perf_counter()
    _loop_eps(np.array([0.1, 0.2]), table_e.inv_h, table_e.coeffs)
    _loop_resolve(np.array([1.0]), np.array([0.5]), dist, bconst, 0.01, table_o.inv_hs, table_o.inv_hd,
                  table_o.coeffs)
    t_jit = time.perf_counter() - t0
    print(f"tables (cached after the first build): restitution {t_build_e:.2f} s, oblique {t_build_o:.2f} s; "
          f"JIT compile + load of both loops {t_jit:.2f} s")
    g_n, g_t = thermal_impacts(rng, n, mass_eff=m_eff)
    beta = bconst * g_n ** 0.2
    per = timed(lambda: _loop_eps(beta, table_e.inv_h, table_e.coeffs), args.repeats) / n
    print(f"eps(beta) table_lookup (instantaneous collision): {per * 1e9:7.0f} ns per collision")
    for delta_thermal in (0.001, 0.05):
        # compression constant rho^{-2/5} such that delta = delta_thermal at g_n = sqrt(2 T / m_eff)
        xconst = delta_thermal * dist / (2.0 / m_eff) ** 0.4
        per = timed(lambda: _loop_resolve(g_n, g_t, dist, bconst, xconst, table_o.inv_hs, table_o.inv_hd,
                                          table_o.coeffs), args.repeats) / n
        _, bad = _loop_resolve(g_n, g_t, dist, bconst, xconst, table_o.inv_hs, table_o.inv_hd, table_o.coeffs)
        print(f"resolve_collision, thermal gas, delta = {delta_thermal:g} at the thermal speed: "
              f"{per * 1e9:7.0f} ns per collision ({bad} outside the table)")
    # spread over the whole table: beta and delta uniform, every call in another cell
    beta_s = rng.uniform(0, 1.4, n) ** 2
    delta_s = rng.uniform(0, 0.5, n)
    g_n_s = (beta_s / bconst) ** 5
    ok = g_n_s > 1e-6
    xconst_s = delta_s[ok] * dist / g_n_s[ok] ** 0.8  # differs per call: loop over the pairs instead

    @jit
    def loop_spread(g_n, g_t, xconst, inv_hs, inv_hd, coeffs):
        work = np.empty(3)
        out = np.empty(5)
        acc = 0.0
        for i in range(g_n.shape[0]):
            resolve_collision(g_n[i], g_t[i], 1.0, 0.1, xconst[i], inv_hs, inv_hd, coeffs, work, out)
            acc += out[0]
        return acc

    gn, gt = g_n_s[ok], g_n_s[ok] * np.tan(rng.uniform(0, np.pi / 2, ok.sum()))
    loop_spread(gn[:2], gt[:2], xconst_s[:2], table_o.inv_hs, table_o.inv_hd, table_o.coeffs)
    per = timed(lambda: loop_spread(gn, gt, xconst_s, table_o.inv_hs, table_o.inv_hd, table_o.coeffs),
                args.repeats) / gn.size
    print(f"resolve_collision, parameters spread over the whole table (15 MB): {per * 1e9:7.0f} ns per collision")
    m = 2000
    b, c, d = rng.uniform(0, 1, m), ob.c_of_zeta(rng.uniform(0, 1, m)), rng.uniform(0, 0.3, m)
    ob.solve_many(b[:2], c[:2], d[:2], args.end)
    per = timed(lambda: ob.solve_many(b, c, d, args.end), max(1, args.repeats // 2)) / m
    print(f"direct Taylor integration of one contact: {per * 1e6:7.1f} us")
    return 0


if __name__ == "__main__":
    sys.exit(main())
