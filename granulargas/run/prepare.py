"""Config -> collision rule, restitution table and initial state (what a run starts from).

Units are converted here, once (ARCHITECTURE.md "Units"):

* ``damping``: beta at normal impact speed g = 1 for two reference particles
  (diameter 1, mass 1), so k = damping / (R_eff_ref / m_eff_ref^2)^(1/5)
  (:func:`granulargas.contact.material.prefactor_from_damping`).
* ``[collision.material]``: k_SI from Y, nu, A (Schwager & Pöschel (1997), eq. (3), folded into
  beta = (3/2) A rho^(2/5) g^(1/5)), then to reduced units with the reference
  diameter sigma (m), mass M = density pi sigma^3/6 (kg) and velocity unit u
  (m/s): beta = k_SI (R g / m^2)^(1/5) in SI equals
  k_SI (sigma u / M^2)^(1/5) (R' g' / m'^2)^(1/5) in reduced units, so
  k = k_SI (sigma u / M^2)^(1/5).

The restitution table must cover every beta the run can meet. Collisions
never raise the total kinetic energy E (lab frame, conserved momentum), so
|v_i| <= sqrt(2E/m_i), g_n <= 2 sqrt(2E/m_min), and with
R_eff <= R_max/2, m_eff >= m_min/2 every pair has
beta <= k (2 R_max / m_min^2)^(1/5) g_max^(1/5): a rigorous bound, so the
engine can never leave the table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from granulargas import __version__
from granulargas.contact import material, restitution_table
from granulargas.engine import CollisionRule
from granulargas.engine.simulation import MIN_BOX_DIAMETERS
from granulargas.errors import ConfigError, InputFileError
from granulargas.initial import InitialState, box_for_packing, random_state
from granulargas.io.config import RunConfig
from granulargas.io.h5md import load_snapshot, open_run, snapshot_count
from granulargas.theory import particle_volume


@dataclass
class Setup:
    """Everything :func:`granulargas.run.runner.run_config` needs."""

    rule: object
    rule_name: str
    state: InitialState
    prefactor: float | None = None
    table: object = None
    parameters: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)


# ------------------------------------------------------------------- particles


def mean_particle(config: RunConfig) -> tuple[float, float]:
    """(sigma, m): the config's mean diameter and the mass of a particle of that diameter
    (``particles.mass``, or ``particles.density`` times its volume); what kinetic theory
    of identical particles uses for the config."""
    s, p = config.system, config.particles
    sigma = p.diameter
    mass = p.mass if p.mass is not None else p.density * float(particle_volume(sigma, s.dimension))
    return sigma, mass


def make_particles(config: RunConfig, rng: np.random.Generator):
    """Radii and masses of the config's particles (polydisperse radii drawn from ``rng``)."""
    s, p = config.system, config.particles
    n = s.particles
    if p.polydisperse:
        diam = rng.uniform(p.diameter_min, p.diameter_max, n)
    else:
        diam = np.full(n, p.diameter)
    radii = np.ascontiguousarray(0.5 * diam)
    masses = np.full(n, p.mass) if p.mass is not None else p.density * particle_volume(diam, s.dimension)
    return radii, np.ascontiguousarray(masses, dtype=np.float64)


def fresh_state(config: RunConfig) -> InitialState:
    """Random non-overlapping positions and Maxwell-Boltzmann velocities with zero
    total momentum and temperature exactly ``initial.temperature``; all drawn from
    ``numpy.random.default_rng(system.seed)`` (radii, then positions, then velocities)
    by :func:`granulargas.initial.random_state`."""
    s = config.system
    rng = np.random.default_rng(s.seed)
    radii, masses = make_particles(config, rng)
    box = box_for_packing(radii, s.packing_fraction, s.dimension)
    dmax = 2.0 * float(radii.max())
    if float(box.min()) < MIN_BOX_DIAMETERS * dmax:  # the engine's cell grid (engine.simulation)
        raise ConfigError(
            f"{config.source}: system.particles = {s.particles}: box edge {box.min():.3g} is below "
            f"{MIN_BOX_DIAMETERS:g} largest diameters (= {MIN_BOX_DIAMETERS * dmax:.4g}); use more particles "
            "or a higher packing_fraction"
        )
    try:
        return random_state(s.particles, s.packing_fraction, s.dimension, config.initial.temperature,
                            radii=radii, masses=masses, rng=rng)
    except ConfigError as exc:
        raise ConfigError(f"{config.source}: system.packing_fraction = {s.packing_fraction:g}: {exc}") from None


def restart_state(config: RunConfig) -> InitialState:
    """The last snapshot of one of our files, with its time and counters."""
    path = Path(config.initial.from_file)
    where = f'{config.source}: initial.from = "{path}"'
    try:
        count = snapshot_count(path)
    except InputFileError as exc:
        raise InputFileError(f"{where}: {str(exc).split(': ', 1)[-1]}") from None
    if count == 0:
        raise InputFileError(f"{where}: holds no snapshot")
    snap = load_snapshot(path, -1)
    with open_run(path) as f:
        g = f["observables/collisions"]
        steps = g["step"][()]
        times = g["time"][()]
        hits = np.nonzero((steps == snap.step) & (times == snap.time))[0]
        if len(hits) == 0:
            raise InputFileError(f"{where}: no observables sample at its last snapshot (t = {snap.time:g})")
        k = int(hits[-1])
        collisions = int(g["value"][k])
        dissipated = float(f["observables/dissipated_energy/value"][k])
    n, dim = snap.positions.shape
    if dim != config.system.dimension:
        raise ConfigError(f"{config.source}: system.dimension = {config.system.dimension}: restart file {path} is {dim}D")
    if n != config.system.particles:
        raise ConfigError(
            f"{config.source}: system.particles = {config.system.particles}: restart file {path} has {n} particles"
        )
    return InitialState(
        positions=np.ascontiguousarray(snap.positions, dtype=np.float64),
        velocities=np.ascontiguousarray(snap.velocities, dtype=np.float64),
        radii=np.ascontiguousarray(snap.radii, dtype=np.float64),
        masses=np.ascontiguousarray(snap.masses, dtype=np.float64),
        box=np.ascontiguousarray(snap.box, dtype=np.float64),
        species=np.asarray(snap.species, dtype=np.int32),
        images=np.ascontiguousarray(snap.images, dtype=np.int64),
        time=snap.time,
        collisions=collisions,
        events=snap.step,
        dissipated_energy=dissipated,
        last_collision=None if snap.last_collision is None else np.ascontiguousarray(snap.last_collision),
        source=str(path),
    )


# ------------------------------------------------------------------- collisions


def reduced_prefactor(config: RunConfig) -> float:
    """The viscoelastic pair prefactor k in reduced units (see module docstring)."""
    c = config.collision
    if c.material is None:
        return float(material.prefactor_from_damping(c.damping, radius=0.5, mass=1.0))
    m = c.material
    k_si = float(material.prefactor_from_material(m.young_modulus, m.poisson_ratio, m.dissipation_time))
    return k_si * (m.diameter * m.speed_unit / reference_mass_si(m) ** 2) ** 0.2


def reference_mass_si(material) -> float:
    """SI mass (kg) of the reference sphere of ``[collision.material]``: density x pi diameter^3 / 6
    (the reduced mass unit of the material route)."""
    return material.density * float(particle_volume(material.diameter, 3))


def beta_bound(prefactor: float, state: InitialState) -> float:
    """Largest beta any pair can reach in the run (rigorous; module docstring)."""
    m = state.masses
    energy = 0.5 * float((m[:, None] * state.velocities**2).sum())
    m_min = float(m.min())
    g_max = 2.0 * math.sqrt(2.0 * energy / m_min)
    r_max = float(state.radii.max())
    # R_eff <= R_max / 2 and m_eff >= m_min / 2: the pair constant of two (R_max, m_min) particles bounds all
    return float(material.pair_constant(prefactor, r_max, r_max, m_min, m_min)) * g_max**0.2


def expected_beta(prefactor: float, state: InitialState) -> tuple[float, float]:
    """(beta_typical, beta_high): beta of two mean particles at the mean normal
    impact speed sqrt(pi T / (2 m_eff)) of a Maxwellian gas, and of the pair with
    the largest b_ij at the fast impact speed 3 sqrt(T / m_eff) (the upper end of
    the range a cooling run meets; both at the initial temperature). Also returns
    nothing larger than the rigorous :func:`beta_bound`."""
    m, r = state.masses, state.radii
    d = state.velocities.shape[1]
    temp = float((m[:, None] * state.velocities**2).sum()) / (d * len(m))
    r_mean, m_mean = float(np.mean(r)), float(np.mean(m))
    g_typical = math.sqrt(math.pi * temp / m_mean)  # sqrt(pi T / (2 m_eff)), m_eff = m / 2
    typical = float(material.pair_constant(prefactor, r_mean, r_mean, m_mean, m_mean)) * g_typical**0.2
    r_max, m_min = float(r.max()), float(m.min())
    g_fast = 3.0 * math.sqrt(2.0 * temp / m_min)  # 3 sqrt(T / m_eff), m_eff = m_min / 2
    high = float(material.pair_constant(prefactor, r_max, r_max, m_min, m_min)) * g_fast**0.2
    return typical, min(high, beta_bound(prefactor, state))


def validity_warnings(config: RunConfig, prefactor: float, state: InitialState) -> list[str]:
    """One-line warnings when the run's expected beta range (or, on the material
    route, its impact speeds) leaves the viscoelastic model's range
    (:func:`granulargas.contact.material.validity_problems`)."""
    _, high = expected_beta(prefactor, state)
    speed = sound = None
    mat = config.collision.material
    if mat is not None:
        m, d = state.masses, state.velocities.shape[1]
        temp = float((m[:, None] * state.velocities**2).sum()) / (d * len(m))
        speed = 3.0 * math.sqrt(2.0 * temp / float(m.min())) * mat.speed_unit  # m/s
        sound = material.sound_speed(mat.young_modulus, mat.density)
    return [f"warning: {config.source}: {p}" for p in material.validity_problems(beta=high, impact_speed=speed,
                                                                          speed_of_sound=sound)]


def make_rule(config: RunConfig, state: InitialState):
    """(rule, name, prefactor, table, warnings, parameters) for the config."""
    c = config.collision
    params = {"model": c.model}
    if c.model == "elastic":
        return CollisionRule.elastic(), "elastic", None, None, [], params
    if c.model == "constant":
        params.update(restitution=c.restitution, tc_time=c.tc_time)
        return CollisionRule.constant(c.restitution, tc_time=c.tc_time), "constant", None, None, [], params
    k = reduced_prefactor(config)
    bmax = beta_bound(k, state)
    table = restitution_table(max(bmax, 1e-6), end=c.contact_end)
    warns = validity_warnings(config, k, state)
    params.update(prefactor=k, contact_end=c.contact_end, damping=c.damping,
                  beta_expected=list(expected_beta(k, state)), beta_bound=bmax)
    params["restitution_table"] = {
        "inv_h": table.inv_h, "coeffs": np.asarray(table.coeffs), "duration_coeffs": np.asarray(table.duration_coeffs),
        "beta_max": table.beta_max, "end": table.end, **{k2: v for k2, v in table.parameters.items()},
    }
    return CollisionRule.viscoelastic(prefactor=k, table=table), "viscoelastic", k, table, warns, params


def initial_state(config: RunConfig) -> InitialState:
    """The state a run of ``config`` starts from: the restart file's last snapshot
    (``initial.from``) or a fresh random state."""
    return restart_state(config) if config.initial.from_file else fresh_state(config)


def prepare(config: RunConfig) -> Setup:
    """Build rule, table and initial state; raise before any file is written."""
    state = initial_state(config)
    rule, name, k, table, warns, rule_params = make_rule(config, state)
    s = config.system
    vol = particle_volume(2.0 * state.radii, s.dimension).sum()
    parameters = {
        "config": config.to_toml(),
        "config_source": config.text,
        "config_file": config.source,
        "version": __version__,
        "seed": s.seed,
        "dimension": s.dimension,
        "particles": int(len(state.radii)),
        "packing_fraction": float(vol / np.prod(state.box)),
        "units": "length: reference particle diameter; mass: reference particle mass; "
                 "energy: initial temperature T0 (k_B = 1) unless [collision.material] sets speed_unit; "
                 "time: diameter * sqrt(mass / T0)",
        "collision": rule_params,
    }
    if config.collision.material is not None:
        m = config.collision.material
        parameters["units_si"] = {"length_m": m.diameter, "mass_kg": reference_mass_si(m),
                                  "speed_m_per_s": m.speed_unit, "time_s": m.diameter / m.speed_unit}
    if state.source:
        parameters["restart"] = {"file": state.source, "time": state.time, "step": state.events,
                                 "collisions": state.collisions}
    return Setup(rule, name, state, k, table, parameters, warns)
