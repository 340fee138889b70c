"""Where the truncated series of eps(beta) stops converging: figure and numbers.

Left/middle: |partial sum of order N - eps_ODE| against N at beta = f R for
several fractions f of the radius of convergence R, for both ends of contact
(overlap: powers of beta; force: powers of u = sqrt(beta)). Inside the radius
the error falls geometrically like f^N, outside it grows.
Right: Domb-Sykes plot of the overlap coefficients, c_k / c_{k-1} against 1/k,
extrapolated to k -> infinity, against -1/B* with B* = max_beta beta eps^{1/5}
from the ODE (the branch point at beta = -B* from time reversal).

    python scripts/contact/series_convergence.py [--out docs/figures/contact_series_convergence.png]
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from granulargas.contact import ode, series


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/figures/contact_series_convergence.png")
    args = ap.parse_args(argv)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    fractions = [0.3, 0.6, 0.9, 1.1, 1.4]
    for ax, end in zip(axes[:2], ["overlap", "force"]):
        R = series.radius_of_convergence(end)
        N = series.MAX_RELIABLE_ORDER[end]
        c = series.restitution_coefficients(N, end)
        k = np.arange(N + 1)
        print(f"{end}: radius of convergence in beta R = {R:.6f}")
        for f in fractions:
            b = f * R
            x = b if end == "overlap" else np.sqrt(b)
            err = np.abs(np.cumsum(c * x ** k) - ode.solve_many(b, end)[0, 0])
            ax.semilogy(k[1:], np.maximum(err[1:], 1e-17), "o-", ms=3,
                        label=f"beta = {f:g} R = {b:.3f}" + ("  (outside)" if f > 1 else ""))
            print(f"  beta = {b:.4f} ({f:g} R): error at order {N // 2}: {err[N // 2]:.2e}, at order {N}: {err[N]:.2e}")
        var = "beta" if end == "overlap" else "u = sqrt(beta)"
        ax.set_xlabel(f"series order N (highest power of {var})")
        ax.set_ylabel("|partial sum - eps_ODE|")
        ax.set_title(f"{end} end: R = {R:.4f} (in beta)", fontsize=10)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    # Domb-Sykes for the overlap series
    ax = axes[2]
    R = series.radius_of_convergence("overlap")
    c = series.restitution_coefficients(22, "overlap")
    d = series.duration_coefficients(22, "overlap")
    k = np.arange(2, 23)
    ax.plot(1 / k, c[k] / c[k - 1], "o", label=r"$c_k/c_{k-1}$ of $\epsilon$")
    ax.plot(1 / k[4:], d[k[4:]] / d[k[4:] - 1], "s", mfc="none", label=r"same for $\tau_c$")
    fit_k = np.arange(10, 23)
    A = np.vstack([np.ones(fit_k.size), 1 / fit_k, 1 / fit_k ** 2]).T
    a = np.linalg.lstsq(A, c[fit_k] / c[fit_k - 1], rcond=None)[0]
    xx = np.linspace(0, 0.11, 50)
    ax.plot(xx, a[0] + a[1] * xx + a[2] * xx ** 2, "C0-", lw=0.8,
            label=f"fit k = 10..22 -> R = {1 / abs(a[0]):.4f}")
    ax.axhline(-1 / R, color="k", ls="--", lw=0.8, label=f"-1/B*, B* = {R:.5f} (ODE)")
    ax.set_xlim(0, 0.11)
    ax.set_ylim(-0.9, -0.5)
    ax.set_xlabel("1/k")
    ax.set_ylabel("coefficient ratio")
    ax.set_title("Domb-Sykes plot, overlap series: singularity at beta = -B*", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    print(f"Domb-Sykes (eps, k = 10..22): R = {series.domb_sykes_radius(c):.5f}; "
          f"(tau_c): R = {series.domb_sykes_radius(d):.5f}; B* from the ODE = {R:.6f}")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
