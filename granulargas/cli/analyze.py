"""Report on a run's H5MD file: T(t) table, fitted cooling law against theory, a2.

``granulargas analyze FILE [--plot PNG] [--fit-range TMIN TMAX] [--no-snapshots]``
"""

from __future__ import annotations

import math

import numpy as np

from granulargas.analysis.run import analyze_cooling
from granulargas.errors import InputFileError


def configure_parser(parser):
    parser.add_argument("file", help="H5MD file written by 'granulargas run'")
    parser.add_argument("--plot", metavar="PNG", help="write the cooling figure (T/T0, ratio to theory, a2) here")
    parser.add_argument("--fit-range", nargs=2, type=float, metavar=("TMIN", "TMAX"),
                        help="fit window in time since the first sample (default: all samples)")
    parser.add_argument("--no-snapshots", action="store_true", help="skip a2/a3 (do not read the snapshots)")
    parser.add_argument("--rows", type=int, default=10, help="rows of the T(t) table (default 10)")


def _fmt(x, spec=".4g"):
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def report(analysis, rows: int = 10) -> str:
    """The text report of :func:`granulargas.analysis.run.analyze_cooling`'s result."""
    a, info, p, h = analysis, analysis.info, analysis.prediction, analysis.history
    lines = [
        f"{info.path}",
        f"  {info.dimension}D, N = {info.particles}, box = {' x '.join(_fmt(float(L)) for L in info.box)}, "
        f"packing fraction = {info.packing_fraction:.4g}, model = {info.model}"
        + (f" (restitution {info.restitution:g})" if info.restitution is not None and info.model == "constant" else "")
        + (f" (prefactor k = {info.prefactor:.4g})" if info.prefactor is not None and info.model == "viscoelastic" else ""),
    ]
    if not info.monodisperse:
        lines.append("  note: polydisperse run; theory below uses the mean diameter and mass")
    lines.append(
        f"  theory: law = {p.law}, T0 = {p.T0:.4g}, tau0 = {_fmt(p.tau0)}, exponent = -{p.exponent:.4g}, "
        f"a2 = {p.a2:.4g}, mean free path = {p.mean_free_path:.4g}, instability length L_c = {_fmt(p.instability_length)}"
    )
    if math.isfinite(p.instability_length):
        L = float(info.box.max())
        side = "below" if L < p.instability_length else "ABOVE"
        lines.append(f"  box length {L:.4g} is {side} L_c ({p.instability_length:.4g})"
                     + ("" if L < p.instability_length else ": expect shear modes and clusters, not the homogeneous law"))
    t = h.time - a.t_offset
    if t.size > 1:
        targets = np.geomspace(t[1], t[-1], max(rows - 1, 1))
        idx = np.unique(np.concatenate([[0], np.searchsorted(t, targets).clip(0, t.size - 1)]))
    else:
        idx = np.array([0])
    lines.append("")
    lines.append(f"  {'t':>12} {'coll/part':>10} {'T':>12} {'T_theory':>12} {'T/T_theory':>10}")
    for i in idx:
        Tth = float(p.temperature(t[i]))
        lines.append(f"  {t[i]:12.5g} {_fmt(float(h.collisions_per_particle[i]), '10.4g'):>10} {h.temperature[i]:12.5g} "
                     f"{Tth:12.5g} {h.temperature[i] / Tth:10.4f}")
    lines.append("")
    if a.fit is not None:
        f, g = a.fit, a.fit_free
        lines.append(f"  fit (exponent fixed at -{f.exponent:.4g}): tau0 = {f.tau0:.5g} +- {f.tau0_err:.2g}"
                     f"  vs theory {p.tau0:.5g}  ({100 * a.tau0_deviation:+.2f} %)"
                     + (f"; with the beta^2 term {p.tau0_second_order:.5g} ({100 * (f.tau0 / p.tau0_second_order - 1):+.2f} %)"
                        if math.isfinite(p.tau0_second_order) else ""))
        lines.append(f"  fit (exponent free): exponent = -{g.exponent:.4f} +- {g.exponent_err:.2g}, tau0 = {g.tau0:.5g}"
                     f"  vs theory -{p.exponent:.4g}")
    ts, a2, a3 = a.sonine
    if ts.size:
        k = np.unique(np.linspace(0, ts.size - 1, min(ts.size, 6)).astype(int))
        lines.append("  Sonine coefficients (snapshots): " + ", ".join(f"t={ts[i]:.3g}: a2={a2[i]:+.4f}" for i in k))
        if p.law == "haff":
            late = a2[ts.size // 2:]  # the later half of the snapshots (log-spaced in time)
            se = math.sqrt(8.0 / (info.dimension * (info.dimension + 2) * info.particles))
            lines.append(f"  a2 mean over the later half of the snapshots ({late.size}) {np.mean(late):+.4f}"
                         f" +- {se / math.sqrt(max(late.size, 1)):.2g} (sampling error of N = {info.particles})"
                         f" vs van Noije-Ernst {p.a2:+.4f}")
    return "\n".join(lines)


def run(args) -> int:
    try:
        a = analyze_cooling(args.file, t_range=tuple(args.fit_range) if args.fit_range else None,
                            with_sonine=not args.no_snapshots)
    except ValueError as exc:
        raise InputFileError(f"{args.file}: cannot analyse ({exc})") from None
    print(report(a, rows=args.rows))
    if args.plot:
        from granulargas.analysis.plots import plot_cooling  # matplotlib only when a plot is asked for

        plot_cooling(a, args.plot)
        print(f"  wrote {args.plot}")
    return 0
