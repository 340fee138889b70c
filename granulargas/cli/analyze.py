"""Report on a run's H5MD file, or on a sweep directory, against kinetic theory.

``granulargas analyze PATH [--plot [PNG]] [--json] [--fit-range TMIN TMAX] [--no-snapshots]``

PATH is a run's H5MD file (the analysis of its kind, :mod:`granulargas.analysis.kinds`:
cooling runs against the kinetic theory of :mod:`granulargas.theory.gas`, elastic runs
against the equation of state and Enskog's collision frequency, driven runs' steady
state against :mod:`granulargas.theory.driven`, runs of rough particles' two temperatures
against :mod:`granulargas.theory.rough`; a run with walls also gets the wall
pressure and the density across the walls, :mod:`granulargas.analysis.walls`, and
``--plot`` a second figure of the density profile; a mixture also gets the temperature of each
species against :mod:`granulargas.analysis.species` and a figure of T_i/T_j) or a sweep's output
directory (its ``index.json``: one row per parameter set, mean +- standard error over
the seeds). ``--json`` prints one JSON object instead of the text report.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from granulargas import theory
from granulargas.errors import InputFileError, UserError
from granulargas.io.paths import existing_directory
from granulargas.theory.hcs import FIRST_SONINE

INDEX_NAME = "index.json"
#: ``--plot`` given without a path: the figure goes beside the input (:func:`plot_path`)
DEFAULT_PLOT = "<beside the input>"
#: figure formats matplotlib writes (a path with another suffix is refused: no run file is overwritten)
FIGURE_SUFFIXES = ("png", "pdf", "svg", "jpg", "jpeg", "webp", "eps", "tif", "tiff")


def configure_parser(parser):
    parser.add_argument("file", metavar="PATH",
                        help="H5MD file written by 'granulargas run', or a sweep's output directory (index.json)")
    parser.add_argument("--plot", metavar="PNG", nargs="?", const=DEFAULT_PLOT,
                        help="write the figure of the analysis to PNG; without PNG beside the input: PATH with the "
                             "suffix .png (runs/x.h5 -> runs/x.png; a sweep directory DIR -> DIR/sweep.png)")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the report")
    parser.add_argument("--fit-range", nargs=2, type=float, metavar=("TMIN", "TMAX"),
                        help="fit window in time since the first sample (default: all samples)")
    parser.add_argument("--no-snapshots", action="store_true", help="skip a2/a3 (do not read the snapshots)")
    parser.add_argument("--velocity", metavar="PNG",
                        help="velocity distribution f(c) of the later snapshots (log scale, Maxwellian, first-Sonine "
                             "form, high-energy tail against theory) to this figure")
    parser.add_argument("--rows", type=int, default=10, help="rows of the T(t) table (default 10)")


def _fmt(x, spec=".4g"):
    if x is None or (isinstance(x, (float, np.floating)) and not math.isfinite(x)):
        return "-"
    return format(x, spec)


def _pm(value, error, spec=".5g"):
    return _fmt(value, spec) + ("" if error is None or not math.isfinite(error) else f" +- {_fmt(error, '.2g')}")


def _dev(value, ref):
    if value is None or ref is None or not (math.isfinite(value) and math.isfinite(ref)) or ref == 0:
        return ""
    return f" ({100 * (value / ref - 1):+.2f} %)"


def _header(info) -> list[str]:
    lines = [
        f"{info.path}",
        f"  {info.dimension}D, N = {info.particles}, "
        + (f"box = {' x '.join(_fmt(float(L)) for L in info.box)}, " if info.scene.space else
           f"number density = {info.number_density:.4g}, ")
        + f"packing fraction = {info.packing_fraction:.4g}, model = {info.model}"
        + (f" (restitution {info.restitution:g})" if info.restitution is not None and info.model == "constant" else "")
        + (f" (damping {info.damping:.4g})" if info.damping is not None else ""),
    ]
    if info.method == "dsmc":
        lines.append("  method = dsmc: the homogeneous Enskog-Boltzmann equation (no positions; "
                     + ("uniform shear flow in the Lagrangian frame)" if info.scene.kind == "shear"
                        else "the pressure is not sampled)"))
    if info.scene.shows("polydisperse_theory"):
        lines.append(f"  note: polydisperse run (solid fraction {info.solid_fraction:.4g}); the theory below is that of "
                     f"identical particles of the mean diameter {info.diameter:.4g} and its mass {info.mass:.4g} at the "
                     f"same number density (packing {info.packing_fraction:.4g})")
    if info.scene.shows("mixture_mean_particle"):
        lines.append(f"  note: a mixture; the T(t) theory below is that of identical particles of the mean diameter "
                     f"{info.diameter:.4g} and its mass {info.mass:.4g} with the mean law; the species section at the "
                     "end compares each species and T = sum x_i T_i with the mixture's own theory")
    return lines


def _table_rows(t, rows):
    if t.size > 1 and t[-1] > t[0]:
        targets = np.geomspace(max(t[1] - t[0], 1e-300), t[-1] - t[0], max(rows - 1, 1)) + t[0]
        return np.unique(np.concatenate([[0], np.searchsorted(t, targets).clip(0, t.size - 1)]))
    return np.array([0])


def cooling_report(a, rows: int = 10) -> str:
    """Text report of a :class:`granulargas.analysis.run.CoolingAnalysis`."""
    info, p, h = a.info, a.prediction, a.history
    lines = _header(info)
    lines.append(f"  theory: {a.theory_name}")
    space = info.scene.shows("instability")  # a DSMC run has no box to compare with L_c
    lines.append(f"  closed form ({p.name}): T0 = {p.T0:.4g}, tau0 = {_fmt(p.tau0)}, "
                 f"exponent = -{p.exponent:.4g}; mean free path = {p.mean_free_path:.4g}"
                 + (f", instability length L_c = {_fmt(p.instability_length)}" if space else ""))
    if space and math.isfinite(p.instability_length):
        L = float(info.box.max())
        side = "below" if L < p.instability_length else "ABOVE"
        lines.append(f"  box length {L:.4g} is {side} L_c ({p.instability_length:.4g})"
                     + ("" if L < p.instability_length else ": expect shear modes and clusters, not the homogeneous law"))
    t, T, Tth = a.time, h.temperature, a.temperature_theory
    lines += ["", f"  {'t':>12} {'coll/part':>10} {'T':>12} {'T_theory':>12} {'T/T_theory':>10}"]
    for i in _table_rows(t, rows):
        lines.append(f"  {h.time[i]:12.5g} {_fmt(float(h.collisions_per_particle[i]), '10.4g'):>10} {T[i]:12.5g} "
                     f"{Tth[i]:12.5g} {T[i] / Tth[i]:10.4f}")
    lines += ["", f"  T/T_theory: {a.T_ratio_final:.4f} over the last 10 % of the time, "
                  f"{a.T_ratio_last_decade:.4f} over the last decade (t >= {h.time[-1] / 10:.4g})"]
    if a.fit is not None:
        f, g = a.fit, a.fit_free
        tf, tg = a.theory_fit, a.theory_fit_free
        ref = tf.tau0 if tf is not None else p.tau0
        lines.append(f"  fit T0 (1 + t/tau0)^-{f.exponent:.4g}: tau0 = {f.tau0:.5g} +- {f.tau0_err:.2g}, theory "
                     f"{ref:.5g}{_dev(f.tau0, ref)}; closed form {p.tau0:.5g}{_dev(f.tau0, p.tau0)}")
        ref_e = tg.exponent if tg is not None else p.exponent
        lines.append(f"  fit T0 (1 + t/tau0)^-p with free exponent (the figure's fit): tau0 = {g.tau0:.5g} +- "
                     f"{g.tau0_err:.2g}, p = {g.exponent:.4f} +- {g.exponent_err:.2g}; theory p = {ref_e:.4f} "
                     f"(the same fit of the theory curve), closed form {p.exponent:.4g}")
    ts, a2, _ = a.sonine
    if ts.size:
        lines += _a2_lines(a)
    if math.isfinite(a.Z):
        lines.append(f"  Z = P/(nT) = {a.Z:.4f} (mean over {a.pressure.Z.size} windows), Enskog "
                     f"{_fmt(a.Z_theory, '.4f')}{_dev(a.Z, a.Z_theory)}")
    return "\n".join(lines)


def _sigmas(value, ref, error, ref_error=0.0, label="a2/reference") -> str:
    """'label = r, +x sigma' of a measured value against a reference with their errors."""
    if not all(x is not None and math.isfinite(x) for x in (value, ref)):
        return ""
    out = f"{label} = {value / ref:.4f}" if ref != 0 else ""
    sig = math.hypot(*(x if x is not None and math.isfinite(x) else 0.0 for x in (error, ref_error)))
    if math.isfinite(sig) and sig > 0:
        out += (", " if out else "") + f"{(value - ref) / sig:+.1f} sigma"
    return out


def _a2_lines(a) -> list[str]:
    """The a2 lines of a cooling report: snapshots against the theory curve, then the window mean
    against the best reference, named (:attr:`CoolingAnalysis.a2_window`, ``a2_reference``)."""
    from granulargas.analysis.run import A2_ERROR_METHOD

    ts, a2, _ = a.sonine
    k = np.unique(np.linspace(0, ts.size - 1, min(ts.size, 6)).astype(int))
    th = a.theory.a2_at(ts[k]) if a.theory is not None else np.full(k.size, np.nan)
    lines = ["  a2 of the snapshots (theory curve): " + ", ".join(
        f"t={ts[i] + a.t_offset:.3g}: {a2[i]:+.4f} ({th[j]:+.4f})" for j, i in enumerate(k))]
    mean, err, count = a.a2_late
    if not count:
        lines.append("  a2: no snapshot after the relaxation (" + _fmt(a.relaxation_collisions, ".3g")
                     + " collisions per particle); no mean")
        return lines
    sel = ts[a.a2_window] + a.t_offset
    where = (f"after the relaxation from the start ({a.relaxation_collisions:.3g} collisions per particle)"
             if a.hcs is not None else "the later half of the snapshots")
    lines.append(f"  a2 = {mean:+.5f} +- {_fmt(err, '.2g')}: mean of {count} snapshots, t = {sel[0]:.4g} .. "
                 f"{sel[-1]:.4g}, {where}; error: {A2_ERROR_METHOD}")
    ref, ref_err, name = a.a2_reference
    lines.append(f"  a2 reference ({name}): {_pm(ref, ref_err, '+.5f')}; {_sigmas(mean, ref, err, ref_err)}")
    if a.hcs is not None and a.hcs.name != FIRST_SONINE:
        fs = float(theory.sonine_a2(a.info.restitution, a.info.dimension))
        lines.append(f"  for comparison, {FIRST_SONINE}: {fs:+.5f}; {_sigmas(mean, fs, err, label='a2/first Sonine')}")
    return lines


def elastic_report(a, rows: int = 10) -> str:
    """Text report of a :class:`granulargas.analysis.elastic.ElasticAnalysis`."""
    s = a.summary()
    lines = _header(a.info)
    lines.append(f"  theory: {a.theory_name}; elastic collisions, no cooling")
    lines.append(f"  energy drift (E - E0)/E0: {s['energy_drift_final']:.3g} at t = {s['t_final']:.4g}, "
                 f"largest {s['energy_drift_max']:.3g}")
    lines.append(f"  averages from t = {a.t_equilibrated:.4g} (equilibration left out); errors from "
                 f"block means")
    if a.info.walls:
        lines.append("  (walls: Z and the collision frequency below use the mean density of the whole box, "
                     "depleted next to the walls; the wall pressure against the bulk density is the test)")
    if a.info.scene.shows("pressure"):  # DSMC samples no pressure
        lines.append(f"  Z = P/(nT) = {_pm(s['Z'], s['Z_error'])}; {s['Z_theory_name']} {s['Z_theory']:.5g}"
                     f"{_dev(s['Z'], s['Z_theory'])}; {s['Z_reference_name']} {s['Z_reference']:.5g}"
                     f"{_dev(s['Z'], s['Z_reference'])}")
    lines.append(f"  collision frequency per particle {_pm(s['collision_frequency'], s['collision_frequency_error'])}; "
                 f"Enskog {s['collision_frequency_theory']:.5g}"
                 f"{_dev(s['collision_frequency'], s['collision_frequency_theory'])}")
    if s.get("a2_mean") is not None:
        lines.append(f"  a2 = {_pm(s['a2_mean'], s.get('a2_error'), '+.5f')} (snapshots after the equilibration; "
                     f"error: standard error of block means); equilibrium of N = {a.info.particles} particles on "
                     f"their energy shell {s['a2_theory']:+.2g} (-2/(d(N-1)+2))")
    return "\n".join(lines)


def sweep_report(results, summaries) -> str:
    """Text table of :meth:`granulargas.analysis.ensemble.SweepResults.summaries`."""
    lines = [repr(results)]
    if not summaries:
        return "\n".join(lines + ["  no finished runs"])
    names = results.varied
    q = summaries[0].quantity
    lines.append(f"  theory: {summaries[0].theory_name}")
    lines.append(f"  {q}: " + ("fitted T0 (1 + t/tau0)^-p (p of the closed-form law), theory = the same fit of the "
                               "theory curve" if q == "tau0" else "P/(nT) after equilibration, theory = equation of state"))
    head = "  " + " ".join(f"{n:>22}" for n in names) + f" {'seeds':>5} {q + ' (+- s.e.)':>20} {'theory':>10} " \
        f"{'dev':>8} {'T_final (+- s.e.)':>22} {'T_theory':>11} {'T/T_theory':>16}"
    lines.append(head)
    for g in summaries:
        cells = " ".join(f"{_fmt(g.parameters.get(n), 'g') if not isinstance(g.parameters.get(n), str) else g.parameters.get(n):>22}"
                         for n in names)
        dev = _dev(g.value, g.theory).strip(" ()") or "-"
        lines.append(f"  {cells} {g.seeds:>5} {_pm(g.value, g.error):>20} {_fmt(g.theory, '.5g'):>10} {dev:>8} "
                     f"{_pm(g.T_final, g.T_final_error):>22} {_fmt(g.T_theory_final, '.5g'):>11} "
                     f"{_pm(g.T_ratio_final, g.T_ratio_final_error, '.4f'):>16}")
    return "\n".join(lines)


def driven_report(a, rows: int = 10) -> str:
    """Text report of a :class:`granulargas.analysis.driven.DrivenAnalysis`."""
    s = a.summary()
    lines = _header(a.info)
    lines.append(f"  driving: white noise, heating rate H = {a.heating_rate:.4g}, kicks every "
                 f"{a.interval:.4g} (zeta dt_k = {_fmt(s.get('zeta_dt_k'), '.3g')})")
    lines.append(f"  theory: {a.theory_name}")
    lines.append(f"  steady state from t = {a.t_relaxed:.4g} (relaxation left out); errors from block means")
    lines.append(f"  T_ss = {_pm(s.get('T_steady'), s.get('T_steady_error'))}; theory "
                 f"{_fmt(s.get('T_steady_theory'), '.5g')}{_dev(s.get('T_steady'), s.get('T_steady_theory'))}")
    if s.get("a2_mean") is not None:
        lines.append(f"  a2 = {_pm(s['a2_mean'], s.get('a2_error'), '+.4f')} (snapshots, bias -2/(dN) removed); "
                     f"theory {s['a2_theory']:+.4f}")
    t, T = a.time, a.history.temperature
    T_th = a.temperature_theory(t)
    lines += ["", f"  {'t':>12} {'T':>12} {'T_theory':>12} {'T/T_theory':>10}   (T_theory: dT/dt = H - zeta(T) T)"]
    for i in np.unique(np.linspace(0, t.size - 1, max(rows, 2)).astype(int)):
        lines.append(f"  {t[i]:12.5g} {T[i]:12.5g} {T_th[i]:12.5g} {T[i] / T_th[i]:10.4f}")
    return "\n".join(lines)


def shear_report(a, rows: int = 10) -> str:
    """Text report of a :class:`granulargas.analysis.shear.ShearAnalysis`."""
    s = a.summary()
    lines = _header(a.info)
    held = ("viscous heating balances the collisional loss" if a.thermostat is None
            else f"Gaussian thermostat at T = {a.thermostat:g}, rescaling the peculiar velocities")
    lines.append(f"  uniform shear flow: rate a = {a.rate:.5g} (flow along x, gradient along y); {held}")
    lines.append(f"  theory: {a.theory_name}")
    lines.append(f"  steady state from t = {a.t_relaxed:.4g} ({s['samples']} intervals; errors from block means)")
    lines.append(f"  {'quantity':<22} {'simulation':>22} {'theory':>10}")
    names = [("T", "T_steady"), ("a* = a / nu0", "a_star"), ("eta* = -P_xy/(a eta0)", "eta_star"),
             ("P_xx / p", "P_xx_over_p"), ("P_yy / p", "P_yy_over_p")]
    if a.info.dimension == 3:
        names.append(("P_zz / p", "P_zz_over_p"))
    names += [("P_xy / p", "P_xy_over_p"), ("(P_xx - P_yy) / p", "N1")]
    if a.info.dimension == 3:
        names.append(("(P_yy - P_zz) / p", "N2"))
    names.append(("p / (n T)", "Z"))
    for label, key in names:
        lines.append(f"  {label:<22} {_pm(s.get(key), s.get(key + '_error')):>22} {_fmt(s.get(key + '_theory'), '.5g'):>10}"
                     f"{_dev(s.get(key), s.get(key + '_theory'))}")
    lines.append(f"  Navier-Stokes eta* (first Sonine, a* -> 0): {_fmt(s.get('eta_star_navier_stokes'), '.5g')}")
    lines.append(f"  energy balance (per unit time): viscous heating -a P_xy V = {_fmt(s.get('viscous_heating'), '.6g')}, "
                 f"dissipation {_fmt(s.get('dissipation_rate'), '.6g')}, thermostat {_fmt(s.get('thermostat_removal'), '.6g')}")
    return "\n".join(lines)


def vibrated_report(a, rows: int = 10) -> str:
    """Text report of a :class:`granulargas.analysis.vibrated.VibratedAnalysis`."""
    from granulargas.analysis.vibrated import GAUSSIAN_TAIL_2

    s = a.summary()
    lines = _header(a.info)
    ax = "xyz"[a.axis]
    if a.gravity is not None:
        lines.append(f"  gravity g = {list(a.gravity)}; profiles along {ax}")
    for name, w in sorted(a.walls.items()):
        if w.get("kind") == "vibrating":
            lines.append(f"  {name}: vibrating ({w['waveform']}), A = {w['amplitude']:.4g}, nu = {w['frequency']:.4g}, "
                         f"A omega = {2 * np.pi * w['amplitude'] * w['frequency']:.4g}")
        elif w.get("kind") == "thermal":
            lines.append(f"  {name}: thermal, T_w = {w['temperature']:.4g}")
    lines.append(f"  theory: {a.theory_name}")
    lines.append(f"  steady state from t = {a.t_from:.4g}; errors from block means")
    lines.append(f"  T = {_pm(s.get('T_steady'), s.get('T_steady_error'))}, centre of mass {ax} = "
                 f"{_pm(s.get('centre_of_mass'), s.get('centre_of_mass_error'))}")
    if s.get("T_wall") is not None:
        lines.append(f"  thermal floor T_w = {s['T_wall']:.5g}{_dev(s.get('T_steady'), s['T_wall'])}")
    if s.get("T_bed_theory") is not None:
        lines.append(f"  leading-order bed T = {s['T_bed_theory']:.4g}{_dev(s.get('T_steady'), s['T_bed_theory'])}; "
                     f"its small parameters: (1-e^2) N = {s['bed_dissipation']:.2g}, m<U^2>/T = "
                     f"{s['bed_plate_speed']:.2g}, A m g/T = {s['bed_amplitude']:.2g}, floor packing "
                     f"{s['bed_floor_packing']:.2g}")
    if s.get("com_height") is not None:
        h = (f"  centre of mass above the floor h = {_pm(s.get('com_height'), s.get('com_height_error'))}")
        if s.get("plate_velocity") is not None:
            h += f" at plate velocity A omega = {s['plate_velocity']:.4g}"
        lines.append(h)
        if s.get("com_height_barometric") is not None:
            lines.append(f"  dilute barometric column sigma/2 + T/(m g): {s['com_height_barometric']:.5g} at the measured T"
                         f"{_dev(s.get('com_height'), s['com_height_barometric'])}" + (
                             f"; {s['com_height_bed_theory']:.5g} at the leading-order T (scales as (A omega)^2/N)"
                             f"{_dev(s.get('com_height'), s['com_height_bed_theory'])}"
                             if s.get("com_height_bed_theory") is not None else ""))
    lines.append(f"  energy: walls put in {_pm(s.get('power_in'), s.get('power_in_error'))} per unit time, collisions "
                 f"dissipate {_pm(s.get('dissipation'), s.get('dissipation_error'))}; ratio "
                 f"{_pm(s.get('balance_ratio'), s.get('balance_ratio_error'), '.4f')} (1 in a steady state)")
    p = a.profile
    hyd = a.hydrostatic
    head = f"  {ax:>8} {'n':>10} {'T':>10} {'T_along':>10} {'T_across':>10} {'kurt.':>8}"
    lines += ["", head + (f" {'n_hydro':>10}" if hyd is not None else "")]
    filled = np.flatnonzero(p.counts >= 30)  # layers with samples enough for a temperature
    for i in filled[np.unique(np.linspace(0, len(filled) - 1, max(rows, 2)).astype(int))] if filled.size else ():
        k = float(np.nanmean(p.kurtosis[i]))
        row = (f"  {p.centres[i]:8.4g} {p.density[i]:10.4g} {p.temperature[i]:10.4g} {p.t_along[i]:10.4g} "
               f"{p.t_across[i]:10.4g} {k:8.3f}")
        lines.append(row + (f" {hyd[i]:10.4g}" if hyd is not None else ""))
    dist = s.get("layer_distributions")
    if dist:
        lines += ["", f"  velocity distribution in layers: c_a sqrt(m/T_a) against the unit Gaussian (excess kurtosis 0, "
                      f"P(|c| > 2) = {GAUSSIAN_TAIL_2:.4f}); kurtosis errors from block means",
                  f"  {ax + ' from':>9} {'to':>8} {'samples':>8} {'kurt. along':>16} {'a2 along':>9} "
                  f"{'kurt. across':>16} {'a2 across':>9} {'P(|c|>2) al.':>12} {'ac.':>7}"]
        for row in dist:
            lines.append(f"  {row['from']:9.4g} {row['to']:8.4g} {row['samples_along']:8d} "
                         f"{_pm(row['kurtosis_along'], row['kurtosis_along_error'], '+.3f'):>16} "
                         f"{_fmt(row['a2_along'], '+.4f'):>9} "
                         f"{_pm(row['kurtosis_across'], row['kurtosis_across_error'], '+.3f'):>16} "
                         f"{_fmt(row['a2_across'], '+.4f'):>9} {_fmt(row['tail_along'], '.4f'):>12} "
                         f"{_fmt(row['tail_across'], '.4f'):>7}")
    return "\n".join(lines)


def rough_report(a, rows: int = 10) -> str:
    """Text report of a :class:`granulargas.analysis.rough.RoughAnalysis`."""
    from granulargas.analysis.rough import RELAXATION_COLLISIONS

    s = a.summary()
    g = a.gas
    lines = _header(a.info)
    law = (f"Walton's model, beta_0 = {g.tangential_restitution:g}, mu = {g.friction:g}" if g.tangential == "coulomb"
           else f"tangential restitution beta_t = {g.tangential_restitution:g}")
    lines.append(f"  rough particles: {law}, kappa = {g.inertia:g}")
    if a.driven:
        lines.append(f"  driving: white noise, H = {g.heating_rate:.4g}, fraction on the spins {g.rotational_fraction:g}")
    lines.append(f"  theory: {a.theory_name}")
    where = "steady state" if a.driven else "homogeneous cooling state"
    if math.isfinite(a.t_relaxed):
        lines.append(f"  relaxed from t = {a.t_relaxed:.4g}; errors from block means")
        lines.append(f"  theta = T_rot/T_tr = {_pm(s.get('theta'), s.get('theta_error'))}; theory over the same "
                     f"samples {_fmt(s.get('theta_theory_samples'), '.5g')}"
                     f"{_dev(s.get('theta'), s.get('theta_theory_samples'))}; {where} (Maxwellian) "
                     f"{_fmt(s.get('theta_theory'), '.5g')}{_dev(s.get('theta'), s.get('theta_theory'))}")
        if a.driven:
            lines.append(f"  T_tr = {_pm(s.get('T_steady'), s.get('T_steady_error'))}; theory "
                         f"{_fmt(s.get('T_steady_theory'), '.5g')}{_dev(s.get('T_steady'), s.get('T_steady_theory'))}")
        lines.append("  cumulants (relaxed): " + ", ".join(
            f"{k} = {_pm(s.get('cumulant_' + k), s.get('cumulant_' + k + '_error'), '+.4f')}" for k in ("a20", "a02", "a11")))
    else:
        lines.append(f"  the run is too short for theta to relax ({RELAXATION_COLLISIONS:g} collisions per particle): "
                     f"{where} theta (Maxwellian) {_fmt(s.get('theta_theory'), '.5g')}")
    h = a.history
    t = h.time
    Tt, Rt = a.curve.translational_at(t), a.curve.rotational_at(t)
    lines += ["", f"  {'t':>11} {'T_tr':>11} {'theory':>11} {'T_rot':>11} {'theory':>11} {'theta':>8} {'theory':>8}"]
    for i in np.unique(np.linspace(0, t.size - 1, max(rows, 2)).astype(int)):
        lines.append(f"  {t[i]:11.5g} {h.translational[i]:11.5g} {Tt[i]:11.5g} {h.rotational[i]:11.5g} "
                     f"{Rt[i]:11.5g} {h.ratio[i]:8.4f} {Rt[i] / Tt[i]:8.4f}")
    return "\n".join(lines)


#: kind -> text report ``f(analysis, rows) -> str``
REPORTS = {"cooling": cooling_report, "elastic": elastic_report, "driven": driven_report, "rough": rough_report,
           "shear": shear_report, "vibrated": vibrated_report}


def walls_report(w: dict) -> str:
    """Lines on the walls of a run (:func:`granulargas.analysis.walls.wall_summary`)."""
    lines = [f"  walls on {', '.join('xyz'[a] for a in w['axes'])}: wall pressure "
             f"{_pm(w['wall_pressure'], w['wall_pressure_error'])}; bulk (middle half) packing "
             f"{w['bulk_packing']:.4g}, density {w['bulk_density']:.4g} ({w['profile_frames']} snapshots)"]
    if w.get("eos_name"):
        lines.append(f"  equation of state ({w['eos_name']}) at the bulk density and T = {w['temperature']:.5g}: "
                     f"P = {w['eos_pressure']:.5g}; wall pressure{_dev(w['wall_pressure'], w['eos_pressure'])}")
    return "\n".join(lines)


def report(analysis, rows: int = 10) -> str:
    """The text report of an analysis of any kind (:data:`REPORTS`)."""
    return REPORTS[analysis.kind](analysis, rows=rows)


def _is_sweep(path: Path) -> bool:
    return path.is_dir() and (path / INDEX_NAME).exists()


def _run_sweep(args) -> int:
    from granulargas.analysis.ensemble import SweepResults

    path = Path(args.file)
    try:
        results = SweepResults(path)
        summaries = results.summaries(t_range=tuple(args.fit_range) if args.fit_range else None)
    except (ValueError, KeyError, json.JSONDecodeError) as exc:
        raise InputFileError(f"{path}: cannot analyse the sweep ({exc})") from None
    if args.json:
        print(json.dumps({"sweep": str(path), "varied": results.varied, "runs_done": len(results.runs),
                          "runs_not_done": len(results.failed), "groups": [g.as_dict() for g in summaries]},
                         indent=1, ensure_ascii=False))
    else:
        print(sweep_report(results, summaries))
    if args.plot:
        from granulargas.analysis.plots import plot_sweep

        plot_sweep(results, summaries, args.plot)
        if not args.json:
            print(f"  wrote {args.plot}")
    return 0


def _a2_window_start(a):
    """Time of the first snapshot of the report's a2 mean (the ``--velocity`` pool starts there too),
    or None to let the velocity distribution choose."""
    if a.kind == "cooling" and a.sonine[0].size and np.any(a.a2_window):
        return float(a.sonine[0][a.a2_window][0] + a.t_offset)
    for name in ("t_relaxed", "t_equilibrated"):
        if hasattr(a, name):
            return float(getattr(a, name))
    return None


def plot_path(path: Path) -> Path:
    """Where ``--plot`` without a value writes: beside a run's file with the suffix .png, inside a
    sweep's directory as sweep.png."""
    return path / "sweep.png" if path.is_dir() else path.with_suffix(".png")


def _check_figure_path(value: str, option: str):
    """A figure path: an image suffix (never a run's .h5 or a config), in a directory that exists."""
    if Path(value).suffix.lower().lstrip(".") not in FIGURE_SUFFIXES:
        raise UserError(f"{option} {value}: give a figure file ({', '.join('.' + s for s in FIGURE_SUFFIXES)})")
    existing_directory(value, f"{option} {value}")


def run(args) -> int:
    path = Path(args.file)
    if args.plot == DEFAULT_PLOT:
        args.plot = str(plot_path(path))
    if args.plot:  # before any work: a typo in the directory is refused, never created
        _check_figure_path(args.plot, "--plot")
    if args.velocity:
        _check_figure_path(args.velocity, "--velocity")
    if path.is_dir():
        if not _is_sweep(path):
            raise InputFileError(f"{path}: is a directory without {INDEX_NAME} (give a run's .h5 file or a "
                                 "sweep's output directory)")
        return _run_sweep(args)
    from granulargas.analysis.kinds import analyze_file

    try:
        a = analyze_file(args.file, t_range=tuple(args.fit_range) if args.fit_range else None,
                         with_sonine=not args.no_snapshots)
    except (ValueError, ArithmeticError) as exc:  # numbers no run of ours writes (a damaged file)
        raise InputFileError(f"{args.file}: cannot analyse ({exc or type(exc).__name__})") from None
    walls = None
    if a.info.walls and a.kind != "vibrated":  # (a vibrated gas: its own profiles)
        from granulargas.analysis.walls import wall_summary

        t_from = getattr(a, "t_equilibrated", getattr(a, "t_relaxed", float(a.time[0])))
        walls = wall_summary(a.info, t_from)
    from granulargas.analysis.species import analyze_species

    try:
        species = analyze_species(args.file, a.info.box, a.info.dimension)
    except (ValueError, ArithmeticError, KeyError) as exc:
        raise InputFileError(f"{args.file}: cannot analyse the species ({exc or type(exc).__name__})") from None
    if args.json:
        out = a.summary()
        out["method"] = a.info.method
        if walls is not None:
            out["walls"] = walls
        if species is not None:
            out["species"] = species.summary()
        print(json.dumps(out, indent=1, ensure_ascii=False, default=float))
    else:
        print(report(a, rows=args.rows) + ("\n" + walls_report(walls) if walls is not None else "")
              + ("\n" + "\n".join(species.lines()) if species is not None else ""))
    if args.plot:
        from granulargas.analysis.plots import plot_analysis, plot_density_profiles  # matplotlib only when asked

        plot_analysis(a, args.plot)
        extra = []
        if walls is not None:
            p = Path(args.plot)
            extra.append(plot_density_profiles(a.info, walls, p.with_name(p.stem + "_profile" + p.suffix)))
        if species is not None:
            from granulargas.analysis.species import plot_species

            p = Path(args.plot)
            extra.append(plot_species(species, p.with_name(p.stem + "_species" + p.suffix)))
        if not args.json:
            print("  wrote " + ", ".join(str(x) for x in [args.plot] + extra))
    if args.velocity:
        from granulargas.analysis.run import run_kind
        from granulargas.analysis.velocity import file_distribution, plot_file_distribution  # matplotlib when drawn

        try:
            dist = file_distribution(a.info, run_kind(a.info), t_from=_a2_window_start(a))
        except ValueError as exc:
            raise InputFileError(f"{args.file}: --velocity: {exc}") from None
        plot_file_distribution(dist, a.info, args.velocity)
        if not args.json:
            print("\n".join(dist.lines() + [f"  wrote {args.velocity}"]))
    return 0
