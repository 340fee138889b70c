"""Figures of the two-temperature theory of rough grains (granulargas.theory.rough).

``rough_steady_states.png``: theta_st = T_rot / T_tr of white-noise driven rough disks
(kappa = 1/2) against the fraction of the noise power that goes to the spins (the splitting
thermostat), Maxwellian theory (eq. (R5) = 0) against the EDMD and DSMC values that
Megías & Santos (2022) published with their paper (public repository amegiasf/MpembaSplitting,
"Steady states"); their error bars are smaller than the markers.

``rough_hcs_ratio.png``: theta of the homogeneous cooling state against beta_t for spheres
(kappa = 2/5) and disks (kappa = 1/2), eq. (R7); and for Walton's Coulomb model
(spheres, beta_0 = 0.4) against mu: the exact Maxwellian balances (R4) beside the constant
model at the mean beta_t over the impact angles of its own state (the effective beta_t of
Luding et al. 1998). Where no curve is drawn, no ratio balances the energy exchange: theta grows
without bound (Herbst, Huthmann & Zippelius 2000).

    python scripts/validation/rough_theory_figures.py [--outdir docs/figures]

The script prints the published and the theoretical theta_st side by side.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from granulargas import theory
from granulargas.theory import rough as R
from granulargas.theory.gas import Gas

#: Megías & Santos (2022), theta_st of driven rough disks (kappa = 1/2) against the fraction of the
#: noise power on the spins, EDMD and DSMC ("Steady states/theta_st_<method>_<eps>_<beta>.txt")
FRACTIONS = (0.0, 0.1, 0.25, 0.5, 0.8, 0.9, 1.0)
PUBLISHED = {
    (0.9, 0.0): {"EDMD": (0.24242, 0.34889, 0.54436, 1.03038, 2.21659, 2.99169, 4.25174),
                 "DSMC": (0.24244, 0.34894, 0.54466, 1.02863, 2.21418, 2.98640, 4.25754)},
    (0.9, -0.7): {"EDMD": (0.054959, 0.22864, 0.56817, 1.54461, 5.18753, 9.44497, 28.6256),
                  "DSMC": (0.054326, 0.22772, 0.56783, 1.54392, 5.17694, 9.44376, 28.4110)},
    (0.7, 0.0): {"EDMD": (0.24414, 0.42704, 0.76318, 1.59410, 3.64744, 4.99130, 7.32520),
                 "DSMC": (0.24419, 0.42647, 0.76324, 1.59390, 3.63625, 4.99097, 7.30916)},
    (0.7, -0.7): {"EDMD": (0.054709, 0.42418, 1.14734, 3.22344, 10.9738, 20.0233, 61.0518),
                  "DSMC": (0.054627, 0.42362, 1.14770, 3.21272, 10.9239, 19.9075, 60.7161)},
}


def _gas(d, eps, packing=0.01):
    n = theory.number_density(packing, d)
    return Gas(dimension=d, packing_fraction=packing, density=n, sigma=1.0, mass=1.0, temperature=1.0,
               model="constant", restitution=eps)


def steady_theta(eps, beta, fraction, kappa=0.5):
    r = R.RoughGas(_gas(2, eps), kappa, tangential_restitution=beta, heating_rate=1.0, rotational_fraction=fraction)
    T, Tr = R.driven_state(r)
    return Tr / T


def steady_states(out):
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    lam = np.linspace(0.0, 1.0, 81)
    print("eps  beta_t  fraction  EDMD      DSMC      Maxwellian  (theory/EDMD - 1)")
    for (eps, beta), color in zip(PUBLISHED, ("C0", "C1", "C2", "C3")):
        theta = [steady_theta(eps, beta, x) for x in lam]
        ax.plot(lam, theta, color=color, label=f"ε = {eps}, β_t = {beta}")
        pub = PUBLISHED[(eps, beta)]
        ax.plot(FRACTIONS, pub["EDMD"], "o", mfc="none", color=color)
        ax.plot(FRACTIONS, pub["DSMC"], "x", color=color)
        for x, e, s in zip(FRACTIONS, pub["EDMD"], pub["DSMC"]):
            th = steady_theta(eps, beta, x)
            print(f"{eps:.1f}  {beta:5.1f}   {x:5.2f}   {e:8.5g}  {s:8.5g}  {th:9.5g}   {th / e - 1:+.3f}")
    ax.plot([], [], "ko", mfc="none", label="EDMD, Megías & Santos (2022)")
    ax.plot([], [], "kx", label="DSMC, Megías & Santos (2022)")
    ax.set_yscale("log")
    ax.set_xlabel("fraction of the noise power on the spins")
    ax.set_ylabel("θ_st = T_rot / T_tr")
    ax.set_title("Driven rough disks (κ = 1/2): Maxwellian theory (lines)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def self_consistent_mean(r, eps):
    """theta of the constant model whose beta_t is the mean over the impacts of its own state:
    theta = theta_HCS(mean beta_t(theta)), the smallest root on a log grid (nan if none)."""
    grid = np.logspace(-3, 4, 141)

    def f(theta):
        return np.log(theta) - np.log(R.hcs_temperature_ratio(eps, R.coulomb_mean_restitution(r, 1.0, theta), 0.4, 3))

    values = [f(x) for x in grid]
    for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:]):
        if fa < 0.0 <= fb:
            from scipy.optimize import brentq

            return brentq(f, a, b, rtol=1e-10)
    return np.nan


def hcs_ratio(out):
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.2))
    beta = np.linspace(-0.98, 1.0, 200)
    for eps, ls in ((1.0, "-"), (0.9, "--"), (0.7, ":")):
        a.plot(beta, R.hcs_temperature_ratio(eps, beta, 0.4, 3), "C0" + ls, label=f"spheres κ = 2/5, ε = {eps}")
        a.plot(beta, R.hcs_temperature_ratio(eps, beta, 0.5, 2), "C1" + ls, label=f"disks κ = 1/2, ε = {eps}")
    a.set_yscale("log")
    a.set_xlabel("tangential restitution β_t")
    a.set_ylabel("θ_HCS = T_rot / T_tr")
    a.set_title("Homogeneous cooling state, eq. (R7)")
    a.legend(fontsize=7)
    mus = np.logspace(-1.3, 1.0, 40)
    for eps, color in ((0.9, "C0"), (0.7, "C2")):
        g = _gas(3, eps)
        exact, mean = [], []
        for mu in mus:
            r = R.RoughGas(g, 0.4, tangential="coulomb", tangential_restitution=0.4, friction=mu)
            exact.append(R.hcs_ratio(r))
            mean.append(self_consistent_mean(r, eps))
        b.plot(mus, exact, color=color, label=f"Walton, exact balances, ε = {eps}")
        b.plot(mus, mean, "--", color=color, label=f"constant β_t = its mean over impacts, ε = {eps}")
        b.axhline(R.hcs_temperature_ratio(eps, 0.4, 0.4, 3), color=color, lw=0.6, ls=":")
    b.set_xscale("log")
    b.set_yscale("log")
    b.set_xlabel("friction coefficient μ")
    b.set_ylabel("θ_HCS")
    b.set_title("Spheres, Walton's model, β_0 = 0.4 (dotted: μ → ∞)", fontsize=10)
    b.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--outdir", default="docs/figures")
    p.add_argument("--only", choices=("steady", "hcs"))
    args = p.parse_args(argv)
    out = Path(args.outdir)
    if args.only != "hcs":
        steady_states(out / "rough_steady_states.png")
    if args.only != "steady":
        hcs_ratio(out / "rough_hcs_ratio.png")


if __name__ == "__main__":
    main()
