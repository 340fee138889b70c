"""Figures 1 and 3 of Schwager & Pöschel (1997) from granulargas.contact.

``contact_collision_dynamics.png`` (their Fig. 1): compression against time for
the damped and the undamped (elastic) contact in rescaled units
(x'' + beta sqrt(x) x' + x^{3/2} = 0, impact speed 1), with their second-order
expansion x0 + beta x1 + beta^2 x2 (Schwager & Pöschel (1997), eq. (14)) on
[0, Theta_c^0/2], where they use it, and the times Theta_m < Theta_c^0/2
(earlier maximum) and Theta_c > Theta_c^0 (longer contact).

``contact_restitution_vs_speed.png`` (their Fig. 3): eps against the impact speed g
for one material, the second-order formula 1 - C1 beta + C2 beta^2 with
beta = (3/2) A rho^{2/5} g^{1/5} (Schwager & Pöschel (1997), eq. (32)) against the
numerical integration (ODE, both ends of contact).

    python scripts/contact/schwager_poschel_figures.py [--beta 0.4] [--outdir docs/figures]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from granulargas.contact import material, ode, perturbation, restitution
from granulargas.contact.pade import C1, C2

# Fig. 3 material: soft (rubber-like) spheres; g <= 5 m/s keeps the Mach number (c = 95 m/s) below 0.1
YOUNG, POISSON, A, RADIUS, DENSITY = 1.0e7, 0.45, 3.0e-5, 0.01, 1100.0


def fig1(beta, out):
    t_d, x_d, _ = ode.trajectory(beta, "overlap", n=600)
    t_e, x_e, _ = ode.trajectory(0.0, "overlap", n=600)
    sol, t_half = perturbation.perturbation_solution(None)
    tt = np.linspace(1e-3, t_half, 300)
    x0, _, x1, _, x2, _ = sol(tt)
    x_force = ode.trajectory(beta, "force", n=600)
    theta_m = t_d[np.argmax(x_d)]
    fig, ax = plt.subplots(figsize=(7, 5.4))
    ax.plot(t_e, x_e, "k--", label=r"undamped, $\beta=0$ (Hertz)")
    ax.plot(t_d, x_d, "C0-", lw=2, label=rf"damped, $\beta={beta:g}$ (ODE, overlap end)")
    ax.plot(x_force[0], x_force[1], "C1:", lw=2, label=r"damped, force end ($x+\beta x'=0$)")
    ax.plot(tt, x0 + beta * x1 + beta ** 2 * x2, "C3-", lw=1, alpha=0.8,
            label=r"Schwager & Pöschel (1997), eq. (14): $x_0+\beta x_1+\beta^2 x_2$ on $[0,\Theta_c^0/2]$")
    ax.plot(x_force[0][-1], x_force[1][-1], "o", color="C1", ms=6)
    ax.annotate("force end: repulsion vanishes\n(surfaces separate, x > 0)", (x_force[0][-1], x_force[1][-1]),
                xytext=(-135, -25), textcoords="offset points", fontsize=8, color="C1",
                arrowprops=dict(arrowstyle="->", color="C1"))
    for t, lab, col, ha in [(theta_m, r"$\Theta_m$", "C0", "right"), (t_half, r"$\Theta_c^0/2$", "k", "left"),
                            (t_e[-1], r"$\Theta_c^0$", "k", "right"), (t_d[-1], r"$\Theta_c$", "C0", "left")]:
        ax.axvline(t, color=col, lw=0.6, ls=":")
        ax.text(t, 1.16, " " + lab + " ", ha=ha, fontsize=9, color=col)
    ax.set_xlabel(r"time $t\ [\rho^{-2/5} g^{-1/5}]$")
    ax.set_ylabel(r"compression $x\ [g^{4/5}\rho^{-2/5}]$")
    ax.set_ylim(0, 1.22)
    ax.set_xlim(0, max(t_d[-1], t_e[-1]) * 1.02)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    ax.set_title("the dynamics of the collision (after Schwager & Pöschel (1997), Fig. 1)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}: Theta_m = {theta_m:.4f} < Theta_c0/2 = {t_half:.4f}; "
          f"Theta_c = {t_d[-1]:.4f} > Theta_c0 = {t_e[-1]:.4f}")


def fig3(out):
    r_eff = RADIUS / 2
    m_eff = DENSITY * 4 / 3 * np.pi * RADIUS ** 3 / 2
    g = np.linspace(0.0, 5.0, 201)
    beta = material.beta_from_material(YOUNG, POISSON, A, r_eff, m_eff, g)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(g, 1 - C1 * beta + C2 * beta ** 2, "C3-", lw=2.5, alpha=0.6, label="Schwager & Pöschel (1997), eq. (32) (second order)")
    ax.plot(g, restitution(beta, end="overlap"), "k--", lw=1.2, label="numerical integration, overlap end")
    ax.plot(g, restitution(beta, end="force"), "C0:", lw=1.5, label="numerical integration, force end")
    ax.plot(g, 1 - C1 * beta, "C2-.", lw=1, label="first order, 1 - C1 beta")
    ax.set_xlabel("impact velocity g [m/s]")
    ax.set_ylabel(r"coefficient of restitution $\epsilon$")
    ax.set_title(f"after Schwager & Pöschel (1997), Fig. 3 (beta = {beta[-1]:.3f} at g = {g[-1]:g} m/s)\n"
                 f"Y = {YOUNG:g} Pa, nu = {POISSON}, A = {A:g} s, R = {RADIUS} m, density {DENSITY:g} kg/m3", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    gap = np.max(np.abs(1 - C1 * beta + C2 * beta ** 2 - restitution(beta, end="overlap")))
    print(f"wrote {out}: max |eq. 32 - ODE| = {gap:.2e} over g in [0, {g[-1]:g}] m/s (beta <= {beta[-1]:.3f})")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--beta", type=float, default=0.4, help="damping for Fig. 1")
    ap.add_argument("--outdir", default="docs/figures")
    args = ap.parse_args(argv)
    outdir = Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    fig1(args.beta, outdir / "contact_collision_dynamics.png")
    fig3(outdir / "contact_restitution_vs_speed.png")


if __name__ == "__main__":
    main()
