"""Is a constant restitution good enough for this config? (``granulargas advise CONFIG``)

A viscoelastic gas sees a whole range of eps: fast impacts at the start of a
cooling run are more inelastic than slow ones at the end (eps -> 1 as g -> 0).
From the config alone (T0, damping or material, density, run length) the
advice predicts, with kinetic theory and no simulation
(:mod:`granulargas.run.validity` explains each step):

1. the temperature range of the run, from the viscoelastic cooling law solved
   with the exact eps(beta) (:func:`granulargas.theory.gas.cooling_curve`);
2. the spread of eps over the thermal impact speeds (central 90 % of collisions)
   from the hottest to the coldest moment of the run;
3. the best constant eps: the one whose Haff law ``T0 / (1 + t/tau0)^2``
   (Enskog rate with the van Noije-Ernst a2 of that eps) stays closest to the
   viscoelastic T(t) over the run, in the minimax sense, and that largest
   relative deviation ``max_t |T_const(t) / T_visco(t) - 1|``;
4. the verdict: a constant eps will do if that deviation is within the
   tolerance (default 2 %, ``--tolerance``);
5. whether the box is longer than the shear-instability length of the gas at
   T0 (:meth:`granulargas.theory.gas.Gas.instability_length`; a viscoelastic
   gas's grows as it cools, so clusters seeded early dissolve later; the
   homogeneous prediction then fails for both rules).

6. the model of the scene (:func:`choose_method`): DSMC (``run.method = "dsmc"``) for a
   homogeneous dilute gas, where it solves the same Enskog-Boltzmann equation much
   faster: no walls or TC model, a box below the instability length and a
   packing fraction up to :data:`DSMC_MAX_PACKING`; EDMD otherwise. The predicted
   speed-up is the ratio of collision rates measured by ``scripts/benchmarks/dsmc.py``
   (docs/performance.md, DSMC section), interpolated in the packing fraction.

7. the duration of the contacts (:func:`choose_duration`, material route only, where the
   stiffness fixes the contact time): from the contact-time ratio ``<t_c> omega`` at T0
   (:func:`granulargas.run.validity.contact_time_ratio`) and the errors of instantaneous
   and resolved EDMD against LAMMPS measured at a few ratios by
   ``scripts/lammps/resolved_collisions.py`` (:data:`RESOLVED_LAMMPS_MEASURED`; docs/validation.md,
   "Against LAMMPS"), interpolated as a power law in the ratio: instantaneous
   collisions where their predicted error is within the tolerance; else
   ``[collision] duration = "resolved"`` where its error is and a DEM at t_c/10 (whose error
   stayed within 1 %) would take longer (measured CPU-time ratio, :func:`dem_cost`;
   the resolved rule itself runs at about :data:`RESOLVED_COST` the collisions per CPU
   second of the instantaneous one, ``scripts/benchmarks/resolved.py``); else a time-stepped
   DEM (``granulargas export lammps --material-stiffness``). Above the largest measured
   ratio the resolved scheme is not vouched for, nor where the fastest impact expected
   among the config's particles (:func:`fastest_impact_bounds`) is beyond its table,
   which the run would refuse.

Every line applies to the config's scene (:class:`granulargas.io.scene.Scene`,
:data:`granulargas.io.scene.STATEMENTS`): steps 2-4 compare cooling curves and are
made for cooling gases only; a driven gas is predicted by its relaxation towards the
steady temperature of the driving (:func:`granulargas.run.validity.driven_end`, the
theory ``granulargas analyze`` compares with) and told how many relaxation times the
run lasts; an elastic gas keeps T0; step 5 needs space, so a DSMC config (whose box
only sets the density) is told instead how long a box of its gas could be. The
predicted temperature at the end is the run summary's (:func:`granulargas.run.validity.check_run`).

For a constant-eps config the advice reports the config ``damping`` (beta at
g = 1 for two reference particles) whose viscoelastic gas cools at the same
initial rate and how far its T(t) would drift from Haff's law
over the run, plus the inelastic-collapse risk.

8. A mixture (``[[species]]``, :func:`species_advice`): the temperature of each species,
   which equipartition does not fix -- in the homogeneous cooling state (constant eps) or
   at the run's end (viscoelastic: the species' balance equations integrated over the run)
   or in the driven steady state, from the Maxwellian theory of Garzó & Dufty (1999) with
   the Enskog chi_ij (:mod:`granulargas.theory.mixture`). The run's temperature range, the
   clustering and the method are those of the one-component gas of the mixture's mean
   particle and mean law (:func:`granulargas.run.validity.gas_from_config`); the
   constant-versus-viscoelastic comparison of items 2-4 is one of one kind of particle and
   is not made for a mixture.

The prediction is the kinetic theory of :mod:`granulargas.theory.gas`: a homogeneous
gas whose temperature and second Sonine coefficient a2 evolve together (moment
equations with the exact eps(g)); it is checked against real runs in
``scripts/validation/rule_choice.py`` (docs/choosing-a-model.md).

Runner API: :func:`summary_line` ``(config, tolerance=DEFAULT_TOLERANCE) -> str | None``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from granulargas import theory
from granulargas.contact.material import damping_from_prefactor
from granulargas.errors import ConfigError
from granulargas.io.scene import Scene
from granulargas.run import validity as V
from granulargas.run.prepare import (DELTA_MAX, OBLIQUE_BETA_MAX, mean_particle, mean_restitution, mixture_of_config,
                                     oblique_bounds, reduced_compression, reduced_prefactor)
from granulargas.run import vibrated as vibrated_scene
from granulargas.theory.driven import RELAXATION_TIMES
from granulargas.theory import rough as rough_theory
from granulargas.theory.gas import cooling_curve
from granulargas.theory.rough import smooth_deviation

__all__ = ["DEFAULT_TOLERANCE", "Advice", "advise", "summary_line", "constant_error", "best_constant",
           "choose_method", "dsmc_speedup", "DSMC_MAX_PACKING", "method_line", "choose_duration",
           "duration_error", "dem_cost", "fastest_impact_bounds", "RESOLVED_LAMMPS_MEASURED", "RESOLVED_COST",
           "RESOLVED_THREE_BODY_CHECKED", "shear_prediction"]

#: default tolerance on the relative error of T(t)
DEFAULT_TOLERANCE = 0.02

#: T / T_theory at the end of ``granulargas run configs/polydisperse_3d.toml`` (diameters uniform in
#: [0.7, 1.3], t = 100; ``granulargas analyze``, over the last 10 % of the time): the theory of
#: identical particles of the mean diameter misses the mix's cooling by this much
POLYDISPERSE_MEASURED = 0.917

#: largest packing fraction for which advise recommends DSMC. Enskog's equation neglects the
#: velocity correlations of a dense gas; at packing 0.02 the engine's T(t) and a2(t) agree
#: with DSMC within 0.33 % and 0.005 (scripts/validation/dsmc_vs_engine.py), and the engine's energy
#: loss per collision falls below DSMC's by about 1 % at packing 0.1 and 5 % at 0.4 for
#: eps = 0.8 (scripts/validation/dsmc_packing_gap.py; docs/dsmc.md, "denser packings").
DSMC_MAX_PACKING = 0.1

#: (packing fraction, DSMC / engine collision rate): CPU-time medians at N = 10^5, 3D,
#: constant eps = 0.9 (``scripts/benchmarks/dsmc.py``; docs/performance.md, DSMC section)
DSMC_SPEEDUP_MEASURED = ((0.02, 252.0), (0.3, 26.0))


#: (contact-time ratio <t_c> omega at T0, error of instantaneous EDMD, error of resolved EDMD, CPU time
#: of LAMMPS at t_c/10 over that of resolved EDMD). Errors as fractions: the largest, over T averaged
#: over the second half of the run (LAMMPS's with and without the elastic energy of its contacts), the
#: collision count, the mean pressure and the mean P / (n T), of |mean| + 2 standard errors over 8 seeds
#: of the relative deviation from LAMMPS at t_c/80 (LAMMPS at t_c/10 stays within 1 % of it). 3D,
#: N = 2000, packing 0.05, damping 0.1, t = 0..20 (about 12 collisions per particle), one core each
#: (``scripts/lammps/resolved_collisions.py``; docs/validation.md, "Against LAMMPS"). At t_c/t_free = 0.2 the
#: resolved scheme refuses some initial states of this gas: the fastest impact is beyond its table.
RESOLVED_LAMMPS_MEASURED = ((0.01, 0.0168, 0.0098, 7.16), (0.03, 0.0255, 0.0089, 2.98), (0.1, 0.0756, 0.0182, 1.42),
                            (0.15, 0.1101, 0.0166, 1.15))

#: share of the resolved collisions that met a pair still in contact at the largest contact-time
#: ratio of :data:`RESOLVED_LAMMPS_MEASURED` (same runs)
RESOLVED_THREE_BODY_CHECKED = 0.166

#: resolved / instantaneous collisions per CPU second, 3D N = 10^4 packing 0.1
#: (``scripts/benchmarks/resolved.py``; docs/performance.md)
RESOLVED_COST = 0.80


def _measured(ratio: float, column: int) -> float:
    """Column ``column`` of :data:`RESOLVED_LAMMPS_MEASURED` at ``ratio``: a power law between
    neighbouring measured ratios, the outer segments' power laws beyond them."""
    r = np.log([row[0] for row in RESOLVED_LAMMPS_MEASURED])
    y = np.log([row[column] for row in RESOLVED_LAMMPS_MEASURED])
    x = math.log(ratio)
    k = int(np.clip(np.searchsorted(r, x) - 1, 0, len(r) - 2))
    slope = (y[k + 1] - y[k]) / (r[k + 1] - r[k])
    return float(math.exp(y[k] + slope * (x - r[k])))


def duration_error(ratio: float, method: str) -> float:
    """Predicted largest relative error against DEM of ``method`` ("instantaneous" or "resolved")
    at the contact-time ratio ``ratio``: :data:`RESOLVED_LAMMPS_MEASURED` interpolated linearly in
    log(error) against log(ratio); below the smallest measured ratio the error falls in proportion
    to the ratio (the share of collisions that overlap a third contact, :mod:`granulargas.run.validity`);
    above the largest the instantaneous error follows the power law of the last two points and the
    resolved one is not known (``nan``)."""
    col = {"instantaneous": 1, "resolved": 2}[method]
    r0, e0 = RESOLVED_LAMMPS_MEASURED[0][0], RESOLVED_LAMMPS_MEASURED[0][col]
    if ratio <= r0:
        return float(e0 * ratio / r0)
    if ratio > RESOLVED_LAMMPS_MEASURED[-1][0] and method == "resolved":
        return math.nan
    return _measured(ratio, col)


def dem_cost(ratio: float) -> float:
    """Predicted CPU time of a DEM run at t_c/10 over that of resolved EDMD at the contact-time
    ratio ``ratio`` (:data:`RESOLVED_LAMMPS_MEASURED`, a power law in the ratio; the DEM's steps per
    mean free time fall as 1 / ratio)."""
    return _measured(ratio, 3)


def fastest_impact_bounds(config) -> tuple[float, float]:
    """(beta, delta) the resolved rule's table must hold for the fastest impact of a fresh
    Maxwellian state of the config, predicted without building it: the largest of N thermal
    speeds stays below v with probability 0.9 (the chi distribution with d degrees of freedom,
    F(v)^N = 0.9; 8 states of 2000 particles had their fastest at 0.94 to 1.06 of the median), as
    :func:`granulargas.run.prepare.oblique_bounds` takes it (relative speed twice that), for
    particles of the mean diameter and mass."""
    from types import SimpleNamespace

    from scipy.stats import chi

    s = config.system
    sigma, mass = mean_particle(config)
    v_max = float(chi(s.dimension, scale=math.sqrt(config.initial.temperature / mass)).ppf(0.9 ** (1.0 / s.particles)))
    state = SimpleNamespace(masses=np.array([mass]), radii=np.array([sigma / 2]), velocities=np.array([[v_max]]))
    return oblique_bounds(reduced_prefactor(config), reduced_compression(config), state)


def choose_duration(config, tolerance: float = DEFAULT_TOLERANCE) -> tuple[str, str] | None:
    """("instantaneous", "resolved" or "dem", the reason in words) for a viscoelastic config on
    the material route (module docstring, 7.); None where the contact time is unknown (damping
    route) or the rule is not viscoelastic."""
    c = config.collision
    if c.model != "viscoelastic" or c.material is None:
        return None
    ratio = V.contact_time_ratio(config)
    if ratio is None:
        return None
    largest = RESOLVED_LAMMPS_MEASURED[-1][0]
    e_inst = duration_error(ratio, "instantaneous")
    dem = "use a time-stepped DEM (granulargas export lammps --material-stiffness)"
    measured = (f"t_c/t_free = {ratio:.3g} at T0: against LAMMPS (scripts/lammps/resolved_collisions.py, measured at "
                f"{', '.join(f'{row[0]:g}' for row in RESOLVED_LAMMPS_MEASURED)}) instantaneous collisions are off "
                f"by about {100 * e_inst:.2g} %")
    if e_inst <= tolerance:
        return "instantaneous", f"{measured} (tolerance {100 * tolerance:g} %): the contact's duration does not matter"
    if ratio > largest:
        return "dem", f"{measured}; the resolved scheme was measured up to t_c/t_free = {largest:g} only: {dem}"
    e_res = duration_error(ratio, "resolved")
    cost = dem_cost(ratio)
    if e_res > tolerance:
        return "dem", f"{measured}, resolved collisions by about {100 * e_res:.2g} % (tolerance {100 * tolerance:g} %): {dem}"
    beta, delta = fastest_impact_bounds(config)
    if not (beta < OBLIQUE_BETA_MAX and delta < DELTA_MAX):
        return "dem", (f"{measured}, resolved collisions by about {100 * e_res:.2g} %, but the fastest impact "
                       f"expected among {config.system.particles} particles (beta = {beta:.3g}, delta = {delta:.3g}) "
                       f"is beyond the resolved scheme's table (beta < {OBLIQUE_BETA_MAX:g}, delta < {DELTA_MAX:g}): "
                       f"{dem}")
    if cost < 1.0:
        return "dem", (f"{measured}, resolved collisions by about {100 * e_res:.2g} %, but a DEM at t_c/10 costs "
                       f"about x{cost:.2g} the CPU time of the resolved run: {dem}")
    return "resolved", (f"{measured}, resolved collisions by about {100 * e_res:.2g} % (tolerance "
                        f"{100 * tolerance:g} %): use [collision] duration = \"resolved\" (about x{RESOLVED_COST:g} "
                        f"the collisions per CPU second of instantaneous ones, scripts/benchmarks/resolved.py; a DEM at "
                        f"t_c/10 about x{cost:.2g} its CPU time)")


def dsmc_speedup(packing: float) -> float:
    """Predicted DSMC / EDMD collision rate at ``packing``: the measured ratios
    (:data:`DSMC_SPEEDUP_MEASURED`) interpolated as a power law in the packing fraction
    (the engine's cost per collision grows as the gas gets more dilute), held constant
    outside the measured range."""
    (p0, r0), (p1, r1) = DSMC_SPEEDUP_MEASURED
    p = min(max(packing, p0), p1)
    return float(r0 * math.exp(math.log(r1 / r0) * math.log(p / p0) / math.log(p1 / p0)))


def choose_method(config, instability_length: float = math.inf, duration: str | None = None) -> tuple[str, str]:
    """("dsmc" or "edmd", the reason in words) for a config's scene (module docstring, 6.);
    ``instability_length``: L_c of a cooling gas, compared with the config's box (inf: no
    such test, as for a driven or elastic gas, and for a DSMC config, whose box only sets
    the sample size); ``duration``: the advised collision duration (:func:`choose_duration`),
    "resolved" or "dem" rule DSMC out."""
    s, c = config.system, config.collision
    eta = s.packing_fraction
    if getattr(config, "gravity", None) is not None:
        return "edmd", "gravity needs positions (DSMC simulates a homogeneous gas)"
    if "wall" in s.boundary:
        return "edmd", "walls need positions (DSMC simulates a homogeneous gas)"
    if c.tc_time is not None:
        return "edmd", "the TC model needs pair histories of a spatial gas"
    if c.duration == "resolved":
        return "edmd", "collisions that take time need positions (DSMC's collisions are instantaneous)"
    if duration in ("resolved", "dem"):
        return "edmd", "the contacts last long enough to matter (duration below; DSMC's collisions are instantaneous)"
    box = V.box_length(config)
    if box > instability_length:
        return "edmd", (f"the box {box:.4g} exceeds the instability length {instability_length:.4g}: "
                        "clusters and shear modes grow, which DSMC (no space) cannot show")
    if eta > DSMC_MAX_PACKING:
        return "edmd", (f"packing fraction {eta:g} > {DSMC_MAX_PACKING:g}: velocity correlations of a dense gas, "
                        "which the Enskog-Boltzmann equation of DSMC neglects, matter")
    below = ", box below the instability length" if math.isfinite(instability_length) else ""
    return "dsmc", (f"homogeneous and dilute (packing {eta:g} <= {DSMC_MAX_PACKING:g}{below}): DSMC solves the same "
                    "Enskog-Boltzmann equation with the same collision rule")


@dataclass
class Advice:
    """The advice for one config (numbers; :meth:`lines` formats them, :meth:`summary` gives JSON).

    Attributes
    ----------
    model : str
    tolerance : float
    t_end, T_end : float
        Predicted run end time and the temperature then, in units of T0: the run summary's
        prediction (:func:`granulargas.run.validity.check_run`).
    scene : Scene
        The kind of run (:class:`granulargas.io.scene.Scene`); every line applies to it.
    T0 : float
        The initial temperature (``initial.temperature``).
    T_steady, relaxation_time : float
        Driven runs: the steady temperature of the driving (units of T0) and the cooling time
        1/zeta(T_ss) in which the gas relaxes to it; nan otherwise.
    spread : dict or None
        :func:`granulargas.run.validity.restitution_spread` over the run.
    eps_best : float or None
        Best constant eps (viscoelastic config) or the config's eps.
    error : float or None
        Predicted largest relative error of T(t) of the constant eps vs the
        viscoelastic law over the run.
    damping_equivalent : float or None
        Constant config: the config ``damping`` (reference particles) whose viscoelastic
        gas has the same initial cooling rate.
    constant_ok : bool or None
    box, instability_length : float
        Box edge and the shear-instability length at T0 (cooling gases).
    T_stable_instability : float
        Viscoelastic gas in a box above L_c: the temperature (units of T0) at which the growing
        L_c passes the box (:func:`granulargas.run.validity.stable_temperature`); nan otherwise.
    method, method_reason : str
        The model the scene needs (:func:`choose_method`) and why.
    speedup : float
        Predicted DSMC / EDMD collision rate at the config's packing (:func:`dsmc_speedup`).
    configured_method : str
        The config's ``run.method``.
    duration, duration_reason : str or None
        The collision duration the contact time needs (:func:`choose_duration`) and why;
        None off the material route.
    validity : list of str
        The run summary's checks that the lines above do not state (t_c/t_free, warnings).
    species : list of str
        A mixture: the lines of :func:`species_advice`.
    notes : list of str
    """

    model: str
    tolerance: float
    t_end: float
    T_end: float
    scene: Scene = field(default_factory=Scene)
    T0: float = 1.0
    T_steady: float = math.nan
    relaxation_time: float = math.nan
    spread: dict | None = None
    eps_best: float | None = None
    error: float | None = None
    damping_equivalent: float | None = None
    constant_ok: bool | None = None
    box: float = math.nan
    instability_length: float = math.nan
    T_stable_instability: float = math.nan
    method: str = "edmd"
    method_reason: str = ""
    speedup: float = math.nan
    configured_method: str = "edmd"
    duration: str | None = None
    duration_reason: str = ""
    validity: tuple = ()
    species: tuple = ()
    notes: tuple = ()
    steady: str = ""
    shear: dict | None = None
    #: a vibrated scene's lines (:func:`granulargas.run.vibrated.scene_lines`), in place of the cooling advice
    vibrated: tuple = ()
    #: a vibrated scene's numbers (:func:`granulargas.run.vibrated.scene`), for JSON
    vibrated_numbers: dict = field(default_factory=dict)
    #: rough particles: the largest relative change of T_tr(t) over the run if the particles
    #: were smooth (beta_t = -1; :func:`granulargas.theory.rough.smooth_deviation`), and whether
    #: that is within the tolerance
    rough_deviation: float | None = None
    smooth_ok: bool | None = None

    def _run_line(self) -> str:
        sc = self.scene
        head = f"run          T 1 -> {self.T_end:.3g} T0 by t = {self.t_end:.4g}"
        if sc.rough and sc.kind == "driven" and math.isfinite(self.T_steady):
            return (f"{head}, relaxing to the steady state T_tr = {self.T_steady:.4g} T0 of the driving "
                    "(two-temperature theory)")
        if sc.rough:
            return f"{head} (translational temperature, two-temperature theory)"
        if sc.kind == "driven" and math.isfinite(self.T_steady):
            return (f"{head}, relaxing to the steady state T_ss = {self.T_steady:.4g} T0 of the driving "
                    "(Enskog theory, first Sonine)")
        if sc.kind == "driven":
            return f"{head} (elastic collisions heated by the driving: T0 + H t, no steady state)"
        if sc.kind == "shear":
            return (f"{head}, uniform shear flow: steady T_s = {self.T_steady:.4g} T0 ({self.steady}); T is the "
                    "peculiar temperature")
        if sc.kind == "elastic":
            return f"{head} (elastic collisions conserve the energy)"
        return f"{head} (homogeneous cooling, kinetic theory)"

    def lines(self) -> list[str]:
        sc = self.scene
        # a vibrated scene has no free cooling to predict: its own numbers instead
        out = (list(self.vibrated) if sc.kind == "vibrated" else [self._run_line()]) + list(self.species)
        if self.rough_deviation is not None:
            verdict = "a smooth model will do" if self.smooth_ok else "keep the rough particles"
            out.append(f"rough        smooth particles (beta_t = -1) would move T_tr(t) by up to "
                       f"{100 * self.rough_deviation:.3g} % over this run (tolerance {100 * self.tolerance:g} %) "
                       f"-> {verdict}")
        if self.model == "elastic":
            out.append("advice       elastic collisions: nothing to choose")
        if sc.kind == "driven" and math.isfinite(self.relaxation_time):
            n = self.t_end / self.relaxation_time if math.isfinite(self.t_end) else math.nan
            relaxed = RELAXATION_TIMES * self.relaxation_time
            enough = ("" if not math.isfinite(n) or relaxed < self.t_end else
                      f"; too short: granulargas analyze averages the steady state after {RELAXATION_TIMES:g} of "
                      f"them (t = {relaxed:.4g})")
            out.append(f"steady state relaxation time 1/zeta(T_ss) = {self.relaxation_time:.4g}; the run lasts "
                       f"{n:.3g} of them{enough}")
        if sc.shows("shear_state") and self.shear is not None:
            g = self.shear
            ns = "; eta*_NS = {:.4g} (Navier-Stokes, Garzó & Dufty 1999)".format(g["eta_navier_stokes"]) \
                if g.get("eta_navier_stokes") is not None else ""
            out.append(f"shear flow   a* = a/nu0 = {g['a_star']:.4g} at T_s, Grad solution eta* = {g['eta_star']:.4g}, "
                       f"P_xx/p = {g['pxx']:.4g}, P_yy/p = {g['pyy']:.4g}{ns}; granulargas analyze compares the steady "
                       "state with these")
        if self.spread is not None and sc.shows("eps_spread"):
            sp = self.spread
            span = "from T0 to the steady state" if sc.kind in ("driven", "shear") else "start to end"
            out.append(f"eps spread   {sp['eps_min']:.4f} .. {sp['eps_max']:.4f} (beta {sp['beta_max']:.3g} .. "
                       f"{sp['beta_min']:.3g}) over thermal impacts, {span}")
        if sc.shows("constant_or_viscoelastic"):
            if self.model == "viscoelastic" and self.eps_best is not None and self.spread is not None:
                verdict = "a constant eps will do" if self.constant_ok else "keep the viscoelastic rule"
                out.append(f"best const.  eps = {self.eps_best:.4f}: T(t) off by up to {100 * self.error:.2g} % "
                           f"(tolerance {100 * self.tolerance:g} %) -> {verdict}")
            if self.model == "constant" and self.damping_equivalent is not None:
                out.append(f"equivalent   damping = {self.damping_equivalent:.4g} cools at the same initial rate; "
                           f"its T(t) departs from Haff's by up to {100 * self.error:.2g} % over this run")
        if sc.shows("instability") and math.isfinite(self.instability_length):
            rel = "above" if self.box > self.instability_length else "below"
            until = (f" until T = {self.T_stable_instability:.3g} T0, where the growing L_c passes the box"
                     if math.isfinite(self.T_stable_instability) else "")
            out.append(f"clustering   box {self.box:.4g} is {rel} the shear-instability length "
                       f"{self.instability_length:.4g} at T0 (homogeneous cooling {'un' if rel == 'above' else ''}stable"
                       f"{until})")
        if sc.shows("homogeneous_by_construction") and math.isfinite(self.instability_length):
            out.append(f"homogeneous  DSMC has no space: it simulates the homogeneous gas, whatever the sample size; "
                       f"a box of this gas in space clusters if longer than L_c = {self.instability_length:.4g} "
                       "(at T0)")
        if self.method_reason:
            name = {"dsmc": "DSMC", "edmd": "EDMD"}[self.method]
            speed = (f"; about x{self.speedup:.3g} the collisions per CPU second of EDMD (scripts/benchmarks/dsmc.py, "
                     "interpolated in the packing fraction)" if self.method == "dsmc" else "")
            out.append(f"method       {name} (run.method = \"{self.method}\"): {self.method_reason}{speed}")
            if self.configured_method != self.method:
                out.append(f"             the config has run.method = \"{self.configured_method}\"")
        if self.duration is not None:
            out.append(f"duration     {self.duration}: {self.duration_reason}")
        out += [f"note         {n}" for n in self.notes]
        out += list(self.validity)
        return out

    def summary(self) -> dict:
        """The advice as a flat, JSON-ready dict (``granulargas advise --json``): the scene, the
        predicted end (``temperature_end`` in the config's units, ``temperature_end_ratio`` = T/T0)
        and every number of the lines."""
        sp = self.spread or {}
        out = {
            "scene": {**self.scene.as_dict(), "text": self.scene.describe()},
            "model": self.model,
            "t_end": self.t_end,
            "temperature_start": self.T0,
            "temperature_end": self.T_end * self.T0,
            "temperature_end_ratio": self.T_end,
            "temperature_steady": self.T_steady * self.T0,
            "relaxation_time": self.relaxation_time,
            "shear": self.shear,
            "eps_min": sp.get("eps_min"),
            "eps_max": sp.get("eps_max"),
            "eps_best": self.eps_best if self.scene.shows("constant_or_viscoelastic") else None,
            "constant_error": self.error if self.scene.shows("constant_or_viscoelastic") else None,
            "constant_ok": self.constant_ok if self.scene.shows("constant_or_viscoelastic") else None,
            "damping_equivalent": self.damping_equivalent,
            "tolerance": self.tolerance,
            "box": self.box if self.scene.space else None,
            "instability_length": self.instability_length,
            "method": self.method,
            "method_reason": self.method_reason,
            "configured_method": self.configured_method,
            "dsmc_speedup": self.speedup if self.method == "dsmc" else None,
            "duration": self.duration,
            "notes": list(self.notes),
            "validity": list(self.validity),
            "vibrated": self.vibrated_numbers or None,
        }
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in out.items()}


def shear_prediction(config, gas: V.Gas, T_s: float) -> dict:
    """The Grad solution of a sheared config at its steady (or thermostat) temperature ``T_s``
    (:func:`granulargas.theory.shear.grad_usf`): a* = a/nu0(T_s), eta*, P_xx/p, P_yy/p, and the
    Navier-Stokes eta* (:func:`granulargas.theory.shear.navier_stokes_viscosity_reduced`) of a
    constant or elastic rule."""
    from granulargas.theory import shear as usf

    d, n, sigma, m = gas.dimension, gas.density, gas.sigma, gas.mass
    sh = config.shear
    a_star = sh.rate / float(usf.reference_frequency(n, T_s, d, sigma, m))
    if gas.model == "elastic":
        eps = 1.0
    elif gas.model == "constant":
        eps = gas.restitution
    else:
        eps = float(theory.effective_restitution(gas.prefactor, T_s, d, sigma, m, gas.end))
    thermostat = sh.thermostat_temperature is not None
    st = usf.grad_usf(eps, d, gas.packing_fraction, a_star=a_star if thermostat or eps >= 1.0 else None)
    return {"a_star": float(st.a_star), "eta_star": float(st.eta_star), "pxx": float(st.pressure[0, 0]),
            "pyy": float(st.pressure[1, 1]), "eps": float(eps), "thermostat": thermostat,
            "eta_navier_stokes": float(usf.navier_stokes_viscosity_reduced(eps, d, gas.packing_fraction))}


def _haff(gas: V.Gas, eps: float, t):
    """Haff's law for constant eps (Enskog rate, van Noije-Ernst a2)."""
    tau0 = theory.haff_tau0(eps, gas.density, gas.temperature, gas.dimension, gas.sigma, gas.mass)
    return theory.haff_temperature(t, gas.temperature, tau0)


def constant_error(gas: V.Gas, eps: float, curve: V.CoolingCurve, t_end: float) -> float:
    """``max_t |T_const(t) / T_visco(t) - 1|`` over ``0 <= t <= t_end``."""
    return _max_error(gas, eps, *_error_grid(curve, t_end))


def _error_grid(curve: V.CoolingCurve, t_end: float):
    """The times of :func:`constant_error` and the curve's T there."""
    t = curve.time[curve.time <= t_end]
    t = np.append(t, t_end)
    return t, curve.temperature_at(t)


def _max_error(gas: V.Gas, eps: float, t, temperature) -> float:
    """:func:`constant_error` on the grid of :func:`_error_grid`."""
    return float(np.max(np.abs(_haff(gas, eps, t) / temperature - 1.0)))


def best_constant(gas: V.Gas, curve: V.CoolingCurve, t_end: float):
    """(eps, error): the constant eps minimising :func:`constant_error`."""
    from scipy.optimize import minimize_scalar  # here, not at the top: a run's start-up loads no scipy

    # search in q = 1 - eps^2 on a log grid, then refine
    q_ref = float(V.effective_inelasticity(gas, gas.temperature))
    qs = q_ref * np.geomspace(0.05, 1.5, 80)
    qs = qs[qs < 1.0]
    grid = _error_grid(curve, t_end)
    errs = [_max_error(gas, math.sqrt(1 - q), *grid) for q in qs]
    k = int(np.argmin(errs))
    lo, hi = qs[max(k - 1, 0)], qs[min(k + 1, len(qs) - 1)]
    res = minimize_scalar(lambda q: _max_error(gas, math.sqrt(1 - q), *grid), bounds=(lo, hi),
                          method="bounded", options={"xatol": 1e-7 * q_ref})
    q = float(res.x) if res.fun <= errs[k] else float(qs[k])
    return math.sqrt(1.0 - q), min(float(res.fun), float(errs[k]))


def _equivalent_prefactor(gas: V.Gas, eps: float) -> float | None:
    """Prefactor k whose viscoelastic gas has (1 - eps^2)_eff(T0) = 1 - eps^2; None if no beta
    at the thermal impact speed up to 20 gives it (eps below what the table's range reaches)."""
    from scipy.optimize import brentq

    target = 1.0 - eps**2

    def f(log_k):
        g = replace(gas, model="viscoelastic", prefactor=math.exp(log_k))
        return V.effective_inelasticity(g, gas.temperature) - target

    # bracket in beta = b g^(1/5) at the thermal impact speed g ~ sqrt(2 T / m) of the gas's
    # particles, b = k (R_eff / m_eff^2)^(1/5) their pair constant. The upper end grows from
    # beta = 0.25 (eps_eff ~ 0.77) to 20 until it brackets the root (f grows with k): each f
    # needs the restitution table up to the largest beta of the quadrature nodes, and building
    # it up to beta ~ 30 for a mildly inelastic gas would cost more than the rest of the advice.
    g_thermal = math.sqrt(2.0 * gas.temperature / gas.mass)
    scale = replace(gas, model="viscoelastic", prefactor=1.0).pair_constant * g_thermal**0.2
    lo = math.log(1e-8 / scale)
    if not math.isfinite(lo):
        return None
    f_lo = f(lo)
    for beta_hi in (0.25, 2.0, 20.0):
        hi = math.log(beta_hi / scale)
        if not math.isfinite(hi):
            return None
        if f_lo * f(hi) <= 0:
            return math.exp(brentq(f, lo, hi, xtol=1e-10))
    return None


def _curve_through(gas: V.Gas, curve: V.CoolingCurve, t_end: float) -> V.CoolingCurve:
    """``curve``, or one integrated up to ``t_end`` if the run ends after ``curve`` does
    (its T then falls below the default 1e-12 T0)."""
    if t_end <= curve.time[-1]:
        return curve
    return cooling_curve(gas, t_end=t_end, t_min_ratio=None)


def species_advice(config, t_end: float) -> list[str]:
    """The temperature of each species of a mixture (module docstring, item 8), as lines: the
    homogeneous cooling state's T_i / T (constant eps), T_i / T at the predicted end ``t_end``
    of a viscoelastic run from equal temperatures at the start, or the driven steady state's
    (granulargas's driving: the same heating rate dT_i/dt for every species)."""
    mix = mixture_of_config(config)
    c = config.collision
    names = mix.names
    driving = config.driving
    t0 = config.initial.temperature

    def listed(ratios):
        return ", ".join(f"{n} {r:.4g}" for n, r in zip(names, ratios))

    out = []
    if c.model == "elastic":
        return ["species      elastic collisions: every species keeps the temperature T (equipartition)"]
    if driving is not None and driving.heating_rate > 0.0:
        t_ss = float(theory.driven_temperature(driving.heating_rate, mean_restitution(config), mix.number_density,
                                               mix.dimension, *mean_particle(config))) if c.model == "constant" else t0
        ratios = mix.driven_ratios("equal_heating", t_ss)
        return [f"species      driven steady state T_i / T: {listed(ratios)} (Garzó & Dufty 1999 Maxwellian, Enskog "
                "chi_ij; the driving heats every species at the same dT_i/dt)"]
    if c.model == "constant":
        ratios = mix.hcs_ratios()
        out.append(f"species      homogeneous cooling state T_i / T: {listed(ratios)} (Garzó & Dufty 1999 Maxwellian, "
                   "Enskog chi_ij), reached from equal temperatures within a few collisions per particle")
        return out
    temps = mix.temperature_history(np.array([0.0, t_end]), np.full(len(names), t0))[-1]
    ratios = temps / float(np.sum(mix.fractions * temps))
    out.append(f"species      T_i / T at t = {t_end:.4g}: {listed(ratios)} (from equal temperatures; Maxwellian "
               "balance of each species with eps_ij(g) per pair, Garzó & Dufty 1999)")
    return out


def advise(config, tolerance: float = DEFAULT_TOLERANCE) -> Advice:
    """Advice on the collision rule for a config (module doc); every line applies to the
    config's scene (:class:`granulargas.io.scene.Scene`)."""
    gas = V.gas_from_config(config)
    table = V.table_range_error(gas)
    if table:
        raise ConfigError(table)
    scene = Scene.from_config(config)
    rv = V.check_run(config)  # the run summary's prediction: one predicted end for both
    if rv.errors and not math.isfinite(rv.t_end) and V.rough_gas_from_config(config) is not None:
        raise ConfigError(rv.errors[0])  # the two-temperature theory cannot be solved for this gas
    T0 = gas.temperature
    t_end = rv.t_end
    adv = Advice(gas.model, tolerance, t_end, rv.T_end / T0, scene=scene, T0=T0, box=V.box_length(config),
                 spread=rv.spread)
    if scene.kind == "vibrated":  # the scene's lines lead; the checks after them
        adv.vibrated = tuple(rv.vibrated)
        adv.vibrated_numbers = vibrated_scene.scene(config)
        checks = [ln for ln in rv.lines() if ln not in rv.vibrated]
    else:
        checks = rv.lines()[1:]
    adv.validity = tuple(ln for ln in checks
                         if not ln.startswith("validity     beta") and ln != f"warning: {rv.instability_warning}")
    notes = []
    if scene.kind == "driven":
        adv.T_steady = rv.T_steady / T0
        if math.isfinite(rv.T_steady):
            adv.relaxation_time = rv.T_steady / config.driving.heating_rate  # 1/zeta(T_ss) = T_ss / H
    if scene.kind == "shear":
        adv.T_steady = rv.T_steady / T0
        adv.steady = rv.steady or ""
        if math.isfinite(rv.T_steady) and not rv.errors:
            adv.shear = shear_prediction(config, gas, rv.T_steady)
    if scene.shows("instability") or scene.shows("homogeneous_by_construction"):
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            adv.instability_length = gas.instability_length()
        adv.T_stable_instability = rv.T_stable / T0
    if gas.model == "viscoelastic" and gas.pair_constant > 0:
        chosen = choose_duration(config, tolerance)
        if chosen is not None:
            adv.duration, adv.duration_reason = chosen
    if scene.shows("constant_or_viscoelastic") and gas.model == "viscoelastic":
        curve = V.cooling_of(gas)
        curve = _curve_through(gas, curve, t_end)
        adv.eps_best, adv.error = best_constant(gas, curve, t_end)
        adv.constant_ok = adv.error <= tolerance
        if config.collision.duration == "resolved" or adv.duration in ("resolved", "dem"):
            ratio = V.contact_time_ratio(config)
            share = "" if ratio is None else (f"; of the order of {100 * (1 - math.exp(-2 * ratio)):.2g} % of the collisions "
                                              "will meet a pair still in contact (three_body_contacts)")
            notes.append("the constant-eps comparison above is one of instantaneous collisions, which leave out "
                         "the contact's duration and the turn of the normal" + share)
        elif adv.constant_ok:
            notes.append(f'use [collision] model = "constant", restitution = {adv.eps_best:.4f} '
                         "(cost per collision is nearly the same; the gain is a closed-form reference, Haff's law)")
    elif gas.model == "viscoelastic" and not gas.pair_constant > 0:
        adv.constant_ok = True
        adv.eps_best, adv.error = 1.0, 0.0
        notes.append("damping = 0: the collisions are elastic; use model = \"elastic\"")
    elif scene.shows("constant_or_viscoelastic") and gas.model == "constant":
        eps = gas.restitution
        adv.eps_best = eps
        k = _equivalent_prefactor(gas, eps)
        if k is None:
            notes.append(f"eps = {eps:g}: no viscoelastic damping within the restitution table's range cools "
                         "at this rate")
        else:
            ve = replace(gas, model="viscoelastic", prefactor=k)
            curve = _curve_through(ve, V.cooling_of(ve), t_end)
            adv.damping_equivalent = damping_from_prefactor(k)
            adv.error = constant_error(ve, eps, curve, t_end)
            adv.constant_ok = adv.error <= tolerance
    if scene.shows("collapse") and (gas.restitution <= 0.7 or (gas.dimension == 2 and gas.packing_fraction >= 0.3)):
        notes.append(f"eps = {gas.restitution:g} without tc_time: dense or strongly inelastic regions can collapse "
                     "(InelasticCollapseError); set [collision] tc_time (TC model) or use the viscoelastic "
                     "rule (scripts/validation/collapse_demo.py)")
    if scene.shows("species_temperatures"):
        adv.species = tuple(species_advice(config, t_end))
    if scene.shows("mixture_mean_particle"):
        notes.append(f"a mixture: T(t), the clustering and the method above are those of its mean particle (diameter "
                     f"{gas.sigma:.4g}, mass {gas.mass:.4g}) and mean law; the constant-versus-viscoelastic comparison "
                     "is one of one kind of particle and is not made")
    if scene.shows("polydisperse_theory"):
        notes.append(f"polydisperse: the predictions are those of identical particles of the mean diameter "
                     f"{gas.sigma:.4g} (mass {gas.mass:.4g}) at the config's number density (packing "
                     f"{gas.packing_fraction:.4g}), as granulargas analyze compares; the mix cools at a rate of "
                     f"its own (configs/polydisperse_3d.toml ends at {POLYDISPERSE_MEASURED:g} of them)")
    if scene.shows("rough"):
        _set_rough(adv, config, tolerance, notes)
    adv.notes = tuple(notes)
    _set_method(adv, config)
    return adv


def _set_rough(adv: Advice, config, tolerance: float, notes: list):
    """Rough particles: how far smooth particles would take T_tr(t) over the run
    (:func:`granulargas.theory.rough.smooth_deviation`); the run's end as the run checks predict."""
    rough = V.rough_gas_from_config(config)
    t_end = adv.t_end if math.isfinite(adv.t_end) else V.rough_end(rough, None, config.run.collisions_per_particle)[0]
    adv.rough_deviation = smooth_deviation(rough, t_end)["max_deviation"]
    adv.smooth_ok = adv.rough_deviation <= tolerance
    if adv.smooth_ok:
        notes.append("leave out [collision.tangential]: the spins change T_tr(t) by less than the tolerance")
    if adv.scene.kind == "driven":
        adv.T_steady = float(rough_theory.driven_state(rough)[0]) / rough.translational_temperature


def _set_method(adv: Advice, config):
    length = adv.instability_length if adv.scene.shows("instability") else math.inf
    adv.method, adv.method_reason = choose_method(config, length, adv.duration)
    adv.speedup = dsmc_speedup(config.system.packing_fraction)
    adv.configured_method = config.run.method


def method_line(config) -> str | None:
    """One line for the run summary of a DSMC config whose scene needs positions (a dense
    gas): the DSMC answer is that of a homogeneous Enskog gas. None otherwise (walls and the
    TC model are refused by the config rules; the box of a DSMC config only sets its sample
    size, so it is not compared with the instability length)."""
    if config.run.method != "dsmc":
        return None
    method, reason = choose_method(config)
    if method == "dsmc":
        return None
    return (f"warning      run.method = \"dsmc\": {reason}; this run shows the homogeneous Enskog-Boltzmann gas "
            "(method = \"edmd\" for the real one)")


def summary_line(config, tolerance: float = DEFAULT_TOLERANCE) -> str | None:
    """One line for the run summary: the eps spread and whether a constant eps would do; for
    rough particles, whether smooth ones would.

    Returns None where the scene has no such comparison (elastic and driven runs: the advice
    compares cooling curves).
    """
    scene = Scene.from_config(config)
    if scene.shows("rough"):
        adv = advise(config, tolerance)
        verdict = "would do" if adv.smooth_ok else "would not do"
        return (f"advice       smooth particles (beta_t = -1) {verdict}: T_tr(t) off by up to "
                f"{100 * adv.rough_deviation:.3g} % over the run (tolerance {100 * tolerance:g} %)")
    if scene.shows("species_temperatures"):  # a mixture: the temperatures of its species
        return "advice       " + advise(config, tolerance).species[0].split(None, 1)[1]
    if not scene.shows("constant_or_viscoelastic"):
        return None
    adv = advise(config, tolerance)
    if adv.model == "viscoelastic" and adv.spread is not None and adv.eps_best is not None:
        sp = adv.spread
        verdict = "would do" if adv.constant_ok else "would not do"
        return (f"advice       eps {sp['eps_min']:.3f}..{sp['eps_max']:.3f} over the run; best constant "
                f"eps = {adv.eps_best:.4f} {verdict} (T(t) off by {100 * adv.error:.2g} %, "
                f"tolerance {100 * tolerance:g} %)")
    if adv.model == "constant" and adv.damping_equivalent is not None:
        return (f"advice       constant eps = {adv.eps_best:g} ~ damping {adv.damping_equivalent:.3g}; a viscoelastic "
                f"gas would differ by up to {100 * adv.error:.2g} % in T(t) over this run")
    return None
