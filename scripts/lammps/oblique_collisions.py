"""Oblique two-sphere collisions: the resolved-contact table against LAMMPS at several time steps.

``python scripts/lammps/oblique_collisions.py [--angles 0 30 60 80 88] [--betas 0.1 0.5 1.0] [--deltas 0.01 0.1]
[--steps 100 200 400 800 1600] [--ends overlap force] [--workdir DIR] [--figure PNG] [--json FILE]``

writes ``docs/figures/contact_oblique_lammps.png`` and ``runs/oblique_lammps/results.json`` by default.

For every impact angle theta (tan theta = g_t / g_n), damping beta (at the
normal speed g_n = 1) and compression scale delta = X / D (third parameter of
:mod:`granulargas.contact.oblique`; sets the stiffness through
:func:`granulargas.dem.lammps.stiffness_for_compression`), LAMMPS
(``pair_style granular``, hertz/material + damping viscoelastic, frictionless;
``limit_damping`` for the ``force`` end; mapping of
:class:`granulargas.dem.lammps.DemContact`) integrates the collision with
``--steps`` time steps per contact (dt = t_c / steps, t_c from the table).
From its relative motion x1 - x2 it takes

* the relative velocity after the contact,
* the contact duration (first touch to geometric separation, interpolated
  linearly between the steps around |r| = D),
* the line the pair leaves on, r(t) = a + v t, by its intercept a at the time
  of first touch (a = r_0 for an instantaneous collision),

and compares them with :meth:`granulargas.contact.ObliqueTable.outcome`:
velocity error / total speed g, relative duration error, intercept error / X.
The same numbers for the instantaneous collision (eps(beta), positions
unchanged) show what the table corrects. LAMMPS's error is first order in the
time step, so the errors must halve with each doubling of ``--steps``; the
Richardson extrapolation 2 q(2 dt) ... q(dt) of the finest pair is printed too.

Also one unequal pair (radii 0.3 / 0.7, masses 0.4 / 2.5) unless
``--no-unequal``. Writes a JSON of all numbers and a figure (errors against
steps per contact, and one trajectory in the collision plane).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def lammps_outcome(traj, distance):
    """Separation time, final velocity and intercept from a LAMMPS trajectory, in the frame (n_0, e_t).

    n_0 = -x (sphere 1 starts at -r1, sphere 2 at +r2), e_t = +y.
    """
    t, r, v = traj["t"], traj["r"], traj["v"]
    dist = np.linalg.norm(r, axis=1)
    inside = np.flatnonzero(dist < distance)
    if inside.size == 0:
        raise RuntimeError("LAMMPS spheres never overlapped")
    after = np.flatnonzero((dist >= distance) & (np.arange(dist.size) > inside[0]))
    if after.size == 0:
        raise RuntimeError("LAMMPS spheres did not separate within the run")
    k = after[0]
    f0, f1 = dist[k - 1] - distance, dist[k] - distance
    t_sep = t[k - 1] + (t[k] - t[k - 1]) * (-f0) / (f1 - f0)
    to_frame = np.array([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    v_end = to_frame @ v[-1]
    intercept = to_frame @ (r[-1] - v[-1] * t[-1])
    return t_sep, v_end, intercept, to_frame @ r.T


def run_case(case, steps_list, workdir, table_cache):
    from granulargas.contact import oblique_table, restitution
    from granulargas.dem.lammps import DemContact, oblique_trajectory, stiffness_for_compression

    theta, beta, delta, end = case["theta"], case["beta"], case["delta"], case["end"]
    (r1, r2), (m1, m2) = case["radii"], case["masses"]
    dist, r_eff, m_eff = r1 + r2, r1 * r2 / (r1 + r2), m1 * m2 / (m1 + m2)
    g_n, g_t = 1.0, math.tan(math.radians(theta))
    speed = math.hypot(g_n, g_t)
    young = stiffness_for_compression(delta, g_n, r_eff, m_eff, dist)
    contact = DemContact.from_beta(beta, g_n, young, r_eff, m_eff, end=end)
    key = (end,)
    if key not in table_cache:
        table_cache[key] = oblique_table(max(b for b in case["all_betas"]) * 1.001,
                                         max(d for d in case["all_deltas"]) * 1.001, end=end)
    table = table_cache[key]
    ours = table.outcome(g_n, g_t, dist, contact.rho(r_eff, m_eff), contact.dissipation_time)
    scale_x = delta * dist
    intercept = ours.position - ours.velocity * ours.duration
    eps = float(restitution(ours.beta, end=end))
    inst_velocity = np.array([eps * g_n, g_t])
    result = dict(case, steps={}, table={"duration": ours.duration, "velocity": ours.velocity.tolist(),
                                         "intercept": intercept.tolist(), "c": ours.c,
                                         "rotation": ours.rotation, "displacement": ours.displacement.tolist()},
                  instantaneous={"velocity_error": float(np.linalg.norm(inst_velocity - ours.velocity) / speed),
                                 "intercept_error": float(np.linalg.norm(np.array([dist, 0.0]) - intercept)
                                                          / scale_x)})
    result.pop("all_betas")
    result.pop("all_deltas")
    for n in steps_list:
        dt = ours.duration / n
        steps = int(math.ceil(1.5 * ours.duration / dt)) + 20
        traj = oblique_trajectory(contact, g_n, g_t, dt, steps, Path(workdir) / f"{case['name']}-{n}",
                                  radii=(r1, r2), masses=(m1, m2))
        t_sep, v_end, icpt, path = lammps_outcome(traj, dist)
        result["steps"][n] = {
            "duration": float(t_sep), "velocity": v_end.tolist(), "intercept": icpt.tolist(),
            "velocity_error": float(np.linalg.norm(v_end - ours.velocity) / speed),
            "duration_error": float(abs(t_sep / ours.duration - 1.0)),
            "intercept_error": float(np.linalg.norm(icpt - intercept) / scale_x),
        }
        if n == max(steps_list):
            result["path"] = path.tolist()
    # Richardson extrapolation of the two finest runs (first-order error)
    n1, n2 = sorted(steps_list)[-2:]
    a, b = result["steps"][n1], result["steps"][n2]
    v_x = 2 * np.array(b["velocity"]) - np.array(a["velocity"])
    i_x = 2 * np.array(b["intercept"]) - np.array(a["intercept"])
    t_x = 2 * b["duration"] - a["duration"]
    result["richardson"] = {
        "velocity_error": float(np.linalg.norm(v_x - ours.velocity) / speed),
        "duration_error": float(abs(t_x / ours.duration - 1.0)),
        "intercept_error": float(np.linalg.norm(i_x - intercept) / scale_x),
    }
    return result


def make_figure(results, path):
    """Top: LAMMPS error against steps per contact (velocity, duration, outgoing line). Bottom: one
    collision in the plane, and the instantaneous collision's error next to LAMMPS's, by angle."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from granulargas.contact import restitution

    fig = plt.figure(figsize=(16, 10))
    grid = fig.add_gridspec(2, 3)
    axes = [fig.add_subplot(grid[0, k]) for k in range(3)]
    names = [("velocity_error", "|v - v_table| / g", "velocity after the contact"),
             ("duration_error", "|t_c / t_table - 1|", "contact duration (touch to separation)"),
             ("intercept_error", "|a - a_table| / X", "outgoing line r = a + v t: intercept a")]
    cmap = plt.get_cmap("viridis")
    thetas = sorted({r["theta"] for r in results})

    def color(theta):
        return cmap(thetas.index(theta) / max(1, len(thetas) - 1))

    for ax, (key, label, title) in zip(axes, names):
        for r in results:
            n = np.array(sorted(int(k) for k in r["steps"]))
            err = np.array([r["steps"][k][key] for k in n])
            ax.loglog(n, err, "-" if r["end"] == "overlap" else "--", color=color(r["theta"]), alpha=0.7, lw=1)
        n = np.array([min(n), max(n)], dtype=float)
        top = max(r["steps"][min(r["steps"])][key] for r in results)
        ax.loglog(n, 2 * top * n[0] / n, "k-", lw=2, alpha=0.3)
        ax.set_xlabel("LAMMPS steps per contact (dt = t_c / steps)")
        ax.set_ylabel(label)
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    for th in thetas:
        axes[0].plot([], [], color=color(th), label=f"theta = {th:g} deg")
    axes[0].plot([], [], "k-", lw=2, alpha=0.3, label="slope -1")
    axes[0].plot([], [], "k--", lw=1, label="force end (solid: overlap)")
    axes[0].legend(fontsize=8, loc="lower left")

    # one collision in the collision plane
    ax = fig.add_subplot(grid[1, 0:2])
    show = max((r for r in results if r["end"] == "overlap" and r["radii"] == [0.5, 0.5]),
               key=lambda r: (r["delta"], -abs(r["theta"] - 60), r["beta"]))
    p = np.array(show["path"])
    dist = sum(show["radii"])
    tab = show["table"]
    t_end = 1.5 * tab["duration"]
    a, v = np.array(tab["intercept"]), np.array(tab["velocity"])
    ax.plot(p[1], p[0], "-", color="C0", lw=5, alpha=0.4,
            label=f"LAMMPS ({max(int(k) for k in show['steps'])} steps per contact)")
    ts = np.linspace(tab["duration"], t_end, 20)
    line = a[None, :] + ts[:, None] * v[None, :]
    ax.plot(line[:, 1], line[:, 0], "k--", lw=1.5, label="table: velocity after the contact, from the separation point")
    ax.plot([dist * math.sin(tab["rotation"])], [dist * math.cos(tab["rotation"])], "ko", ms=6,
            label="table: separation point (t = t_c)")
    eps = float(restitution(show["beta"], end="overlap"))
    g_t = math.tan(math.radians(show["theta"]))
    ts0 = np.linspace(0, t_end, 20)
    ax.plot(g_t * ts0, dist + eps * ts0, "r:", lw=2, label="instantaneous collision at first touch")
    phi = np.linspace(-0.15, 1.0, 200)
    ax.plot(dist * np.sin(phi), dist * np.cos(phi), color="0.5", lw=0.8, label="|r| = D (touching)")
    ax.set_xlabel("r . e_t (relative position x1 - x2, tangential)")
    ax.set_ylabel("r . n_0 (normal at first touch)")
    ax.set_aspect("equal")
    ax.set_xlim(-0.1, max(p[1].max(), line[:, 1].max()) + 0.05)
    ax.set_ylim(min(p[0].min(), 0.8) - 0.02, max(dist + eps * t_end, 1.05) + 0.02)
    ax.set_title(f"relative motion in the collision plane: theta = {show['theta']:g} deg, beta = {show['beta']:g}, "
                 f"delta = {show['delta']:g} (c = {tab['c']:.3g}); the normal turns by {tab['rotation']:.3f} rad")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(True, alpha=0.3)

    # what the table corrects: instantaneous error vs LAMMPS error, by angle
    ax = fig.add_subplot(grid[1, 2])
    for r in results:
        if r["radii"] != [0.5, 0.5]:
            continue
        fine = r["steps"][max(r["steps"], key=int)]
        mk = "o" if r["delta"] == max(x["delta"] for x in results) else "s"
        ax.semilogy(r["theta"], max(r["instantaneous"]["velocity_error"], 1e-16), mk, mfc="none", color="C3")
        ax.semilogy(r["theta"], fine["velocity_error"], mk, color="C0")
    ax.plot([], [], "o", mfc="none", color="C3", label="instantaneous collision, |v - v_table| / g")
    ax.plot([], [], "o", color="C0", label="LAMMPS at the finest step, |v - v_table| / g")
    ax.plot([], [], "ko", mfc="none", label=f"delta = {max(x['delta'] for x in results):g}; squares: smaller")
    ax.set_xlabel("impact angle theta (deg)")
    ax.set_ylabel("velocity error / g")
    ax.set_title("what the resolved contact corrects (all beta, both ends)")
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--angles", type=float, nargs="+", default=[0.0, 30.0, 60.0, 80.0, 88.0])
    parser.add_argument("--betas", type=float, nargs="+", default=[0.1, 0.5, 1.0])
    parser.add_argument("--deltas", type=float, nargs="+", default=[0.01, 0.1])
    parser.add_argument("--steps", type=int, nargs="+", default=[100, 200, 400, 800, 1600])
    parser.add_argument("--ends", nargs="+", default=["overlap", "force"], choices=["overlap", "force"])
    parser.add_argument("--no-unequal", action="store_true", help="skip the unequal pair")
    parser.add_argument("--workdir", type=Path, default=Path("runs/oblique_lammps"))
    parser.add_argument("--figure", type=Path, default=ROOT / "docs" / "figures" / "contact_oblique_lammps.png")
    parser.add_argument("--json", type=Path, default=None, help="default: WORKDIR/results.json")
    args = parser.parse_args(argv)

    from granulargas.dem.lammps import find_lmp

    bad = [a for a in args.angles if not 0.0 <= a < 90.0] + [b for b in args.betas if not 0.0 <= b <= 2.0] \
        + [d for d in args.deltas if not 0.0 < d <= 0.5] + [n for n in args.steps if n < 10]
    if bad or len(args.steps) < 2:
        print(f"scripts/lammps/oblique_collisions.py: need angles in [0, 90), betas in [0, 2], deltas in (0, 0.5], at least two "
              f"--steps >= 10; got {bad or args.steps}", file=sys.stderr)
        return 2
    if find_lmp() is None:
        print("scripts/lammps/oblique_collisions.py: LAMMPS executable `lmp` not found (apt-get install lammps)", file=sys.stderr)
        return 2
    cases = []
    for end in args.ends:
        for delta in args.deltas:
            for beta in args.betas:
                for theta in args.angles:
                    cases.append({"name": f"{end}-d{delta:g}-b{beta:g}-t{theta:g}", "end": end, "theta": theta,
                                  "beta": beta, "delta": delta, "radii": [0.5, 0.5], "masses": [1.0, 1.0]})
        if not args.no_unequal:
            cases.append({"name": f"{end}-unequal", "end": end, "theta": 45.0, "beta": max(args.betas),
                          "delta": max(args.deltas), "radii": [0.3, 0.7], "masses": [0.4, 2.5]})
    for c in cases:
        c["all_betas"], c["all_deltas"] = args.betas, args.deltas
    results, tables = [], {}
    t0 = time.perf_counter()
    for c in cases:
        r = run_case(c, sorted(args.steps), args.workdir, tables)
        results.append(r)
        fine = r["steps"][max(args.steps)]
        print(f"{r['name']:28s} c={r['table']['c']:9.3g}  finest: dv/g={fine['velocity_error']:.1e} "
              f"dt/t={fine['duration_error']:.1e} da/X={fine['intercept_error']:.1e} | Richardson: "
              f"{r['richardson']['velocity_error']:.1e} {r['richardson']['duration_error']:.1e} "
              f"{r['richardson']['intercept_error']:.1e} | instantaneous: "
              f"{r['instantaneous']['velocity_error']:.1e} {r['instantaneous']['intercept_error']:.1e}", flush=True)
    # convergence order over the whole set: median of log2(err(N)/err(2N))
    order = {}
    ns = sorted(args.steps)
    for key in ("velocity_error", "duration_error", "intercept_error"):
        ratios = [math.log2(r["steps"][a][key] / r["steps"][b][key]) for r in results for a, b in zip(ns, ns[1:])
                  if r["steps"][b][key] > 0 and r["steps"][a][key] > 1e-13]
        order[key] = float(np.median(ratios))
    worst = {key: max(r["steps"][max(ns)][key] for r in results) for key in order}
    worst_x = {key: max(r["richardson"][key] for r in results) for key in order}
    print(f"median observed order (log2 of error ratio per halving of dt): {order}")
    print(f"worst error at {max(ns)} steps per contact: {worst}")
    print(f"worst error of the Richardson extrapolation: {worst_x}")
    print(f"{len(cases)} cases, {len(cases) * len(ns)} LAMMPS runs, {time.perf_counter() - t0:.0f} s")
    args.figure.parent.mkdir(parents=True, exist_ok=True)
    make_figure(results, args.figure)
    out = args.json or args.workdir / "results.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    for r in results:
        r.pop("path", None)
    out.write_text(json.dumps({"order": order, "worst": worst, "worst_richardson": worst_x, "cases": results},
                              indent=1) + "\n")
    print(f"wrote {out} and {args.figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
