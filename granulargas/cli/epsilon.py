"""Coefficient of restitution and contact duration of two viscoelastic spheres, by each method.

Examples::

    granulargas epsilon --beta 0.1
    granulargas epsilon --beta 0.1 0.5 --end force
    granulargas epsilon --young 1e7 --poisson 0.3 --dissipation-time 1e-5 \\
        --radius 0.01 --density 1000 --speed 1.0

Each contact end starts with the value to use, eps and tau_c from the restitution
table the engine looks up, then compares the methods (ODE, table, series, Padé).
The material form computes rho (Schwager & Pöschel (1997), eq. (3)) and beta = (3/2) A rho^{2/5} g^{1/5}
for two identical spheres (or give --radius2/--mass2), prints physical
durations in seconds, and warns when the model leaves its validity range.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from granulargas.contact import duration, material, restitution, restitution_table
from granulargas.contact.series import MAX_RELIABLE_ORDER, SeriesDivergenceWarning, radius_of_convergence
from granulargas.contact.table import TABLE_BETA_MAX
from granulargas.errors import UserError
from granulargas.theory import particle_volume


def configure_parser(parser):
    parser.add_argument("--beta", type=float, nargs="+", metavar="B",
                        help="dimensionless damping (3/2) A rho^{2/5} g^{1/5} (one or more)")
    parser.add_argument("--end", choices=["overlap", "force", "both"], default="both",
                        help="end of contact: x = 0 (the engine's default), vanishing force, or both (default)")
    parser.add_argument("--order", type=int, default=None,
                        help="extra series order to show (default: 10 overlap / 20 force)")
    m = parser.add_argument_group("material form (SI units)")
    m.add_argument("--young", type=float, metavar="Y", help="Young modulus [Pa]")
    m.add_argument("--poisson", type=float, metavar="NU", help="Poisson ratio")
    m.add_argument("--dissipation-time", "-A", type=float, metavar="A", help="dissipative time A [s]")
    m.add_argument("--radius", type=float, metavar="R", help="sphere radius [m]")
    m.add_argument("--radius2", type=float, metavar="R2", help="second sphere radius [m] (default: --radius)")
    m.add_argument("--density", type=float, help="material density [kg/m^3] (gives masses and speed of sound)")
    m.add_argument("--mass", type=float, help="sphere mass [kg] (instead of --density)")
    m.add_argument("--mass2", type=float, help="second sphere mass [kg] (default: --mass)")
    m.add_argument("--speed", type=float, nargs="+", metavar="G", help="normal impact speed(s) [m/s]")


def _material(args):
    needed = {"--young": args.young, "--poisson": args.poisson, "--dissipation-time": args.dissipation_time,
              "--radius": args.radius, "--speed": args.speed}
    missing = [k for k, v in needed.items() if v is None]
    if missing:
        raise UserError(f"material form needs {', '.join(missing)} (or give --beta)")
    if (args.density is None) == (args.mass is None):
        raise UserError("material form needs exactly one of --density or --mass")
    for name, value in (("--young", args.young), ("--radius", args.radius), ("--density", args.density),
                        ("--mass", args.mass), ("--radius2", args.radius2), ("--mass2", args.mass2)):
        if value is not None and not (value > 0 and math.isfinite(value)):
            raise UserError(f"{name} {value}: must be positive")
    if not (-1.0 < args.poisson < 0.5):
        raise UserError(f"--poisson {args.poisson}: must lie in (-1, 0.5)")
    if not (args.dissipation_time >= 0):
        raise UserError(f"--dissipation-time {args.dissipation_time}: must be >= 0")
    if any(not (g > 0) for g in args.speed):
        raise UserError(f"--speed {args.speed}: impact speeds must be positive")
    r1 = args.radius
    r2 = args.radius2 or r1
    if args.mass is not None:
        m1 = args.mass
        m2 = args.mass2 or m1
    else:
        m1 = args.density * float(particle_volume(2.0 * r1, 3))
        m2 = args.density * float(particle_volume(2.0 * r2, 3))
    r_eff, m_eff = material.effective(r1, r2), material.effective(m1, m2)
    g = np.asarray(args.speed, dtype=float)
    beta = material.beta_from_material(args.young, args.poisson, args.dissipation_time, r_eff, m_eff, g)
    unit = material.time_unit(args.young, args.poisson, r_eff, m_eff, g)
    rho = material.rho_from_material(args.young, args.poisson, r_eff, m_eff)
    k = material.prefactor_from_material(args.young, args.poisson, args.dissipation_time)
    print(f"R_eff = {r_eff:.6g} m, m_eff = {m_eff:.6g} kg, rho = {rho:.6g} m^-1/2 s^-2 (Schwager & Pöschel (1997), eq. (3)), "
          f"k = {k:.6g} (SI), b_ij = {material.pair_constant(k, r1, r2, m1, m2):.6g}")
    c = material.sound_speed(args.young, args.density) if args.density is not None else None
    for problem in material.validity_problems(beta=beta, impact_speed=g, speed_of_sound=c):
        print(f"warning: {problem}")
    return beta, g, unit


def _rows(beta, end, order):
    rows = [("ode", restitution(beta, end=end), duration(beta, end=end))]
    rows.append(("table", restitution(beta, method="table", end=end), duration(beta, method="table", end=end)))
    radius = radius_of_convergence(end)
    default = 2 if end == "overlap" else 4
    high = order or {"overlap": 10, "force": 20}[end]
    high = min(high, MAX_RELIABLE_ORDER[end])
    for n in (default, high):
        name = f"series({n})"
        if beta >= radius:
            rows.append((name + " diverges", math.nan, math.nan))
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SeriesDivergenceWarning)
            rows.append((name, restitution(beta, method="series", end=end, order=n),
                         duration(beta, method="series", end=end, order=n)))
    if end == "force":
        rows.append(("pade", restitution(beta, method="pade", end=end), math.nan))
    return rows, radius


def _use_line(beta: float, end: str, unit) -> str:
    """The value to use: the restitution table the engine looks up (and its interpolation error)."""
    table = restitution_table(max(beta, 1e-6), end=end)
    eps, tau = float(table.restitution(beta)), float(table.duration(beta))
    err = table.parameters.get("max_error_restitution")
    phys = f", t_c = {tau * unit:.8g} s" if unit is not None else ""
    return (f"    use: eps = {eps:.14f}, tau_c = {tau:.14f}{phys}  (the engine's restitution table"
            + (f", interpolation error < {float(err):.1g}" if err is not None else "") + ")")


def run(args) -> int:
    if args.beta is None and args.young is None:
        raise UserError("give --beta B, or the material form (--young ... --speed G); see --help")
    if args.beta is not None:
        if any(not (b >= 0 and math.isfinite(b)) for b in args.beta):
            raise UserError(f"--beta {args.beta}: must be finite and >= 0")
        if any(b > TABLE_BETA_MAX for b in args.beta):
            raise UserError(f"--beta {args.beta}: the engine's restitution table covers beta <= {TABLE_BETA_MAX:g} "
                            "(the viscoelastic model holds for beta well below ~3)")
        betas, speeds, units = np.asarray(args.beta, dtype=float), None, None
        for problem in material.validity_problems(beta=betas):
            print(f"warning: {problem}")
    else:
        betas, speeds, units = _material(args)
    ends = ["overlap", "force"] if args.end == "both" else [args.end]
    for i, beta in enumerate(betas):
        head = f"beta = {beta:.6g}"
        if speeds is not None:
            head += f"  (impact speed {speeds[i]:.6g} m/s, time unit rho^-2/5 g^-1/5 = {units[i]:.6g} s)"
        print(head)
        for end in ends:
            rows, radius = _rows(float(beta), end, args.order)
            default = " (the engine's default)" if end == "overlap" else ""
            print(f"  end = {end}{default}")
            print(_use_line(float(beta), end, None if units is None else units[i]))
            print(f"    comparison of the methods (series radius of convergence: beta < {radius:.4g}):")
            tunit = "t_c [s]" if units is not None else ""
            print(f"    {'method':<22}{'eps':>20}{'tau_c':>20}{tunit:>16}")
            for name, e, tau in rows:
                phys = f"{tau * units[i]:16.8g}" if units is not None and not math.isnan(tau) else ""
                es = f"{e:20.14f}" if not math.isnan(e) else f"{'-':>20}"
                ts = f"{tau:20.14f}" if not math.isnan(tau) else f"{'-':>20}"
                print(f"    {name:<22}{es}{ts}{phys}")
    return 0
