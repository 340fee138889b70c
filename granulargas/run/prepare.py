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

Collisions that take time (``duration = "resolved"``) also need the contact
stiffness: the compression prefactor q = (2 Y / (3 (1 - nu^2)))^(-2/5)
(:func:`granulargas.contact.oblique.compression_prefactor`) in reduced units,
q = (2 Y sigma^3 / (3 (1 - nu^2) M u^2))^(-2/5), so that X = q (m_eff^2 g_n^4 / R_eff)^(1/5).
Its oblique-contact table is built for the fastest impact of the initial state
(twice the largest speed): no rigorous bound fits the table's range, so the
engine extends the table when an impact leaves it
(:meth:`granulargas.engine.Simulation.run`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from granulargas import __version__
from granulargas.contact import material, oblique_table, restitution_table
from granulargas.contact.oblique import DELTA_MAX, compression_prefactor
from granulargas.contact.oblique_grid import BETA_MAX as OBLIQUE_BETA_MAX
from granulargas import theory
from granulargas.engine import CollisionRule, TangentialRule, Wall, Walls, WhiteNoise
from granulargas.engine.shear import Shear
from granulargas.engine.simulation import MIN_BOX_DIAMETERS
from granulargas.errors import ConfigError, InputFileError
from granulargas.initial import box_for_packing, maxwell_spins, random_state
from granulargas.initial.lattice_gas import MIN_WALL_AXIS_DIAMETERS, RANDOM_PLACEMENT_MAX, maxwell_velocities
from granulargas.io.config import TABLE_BETA_MAX, WALL_SIDES, RunConfig
from granulargas.io.h5md import has_positions, open_run, read_state
from granulargas.run.resources import check_dsmc_memory, check_memory
from granulargas.state import State
from granulargas.theory import particle_volume

#: observables samples of a run without [output] observables_interval (run.schedule uses it)
DEFAULT_OBSERVABLE_SAMPLES = 200


@dataclass
class Setup:
    """Everything :func:`granulargas.run.runner.run_config` needs."""

    rule: object
    rule_name: str
    #: the state the run starts from (a DSMC restart: with the file's DSMC continuation)
    state: State
    prefactor: float | None = None
    table: object = None
    parameters: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    driving: object = None
    #: the restart file the state was read from (None: a fresh state)
    source: str | None = None
    #: the uniform acceleration (tuple) or None; the wall kinds (engine.walls.Walls) or None
    gravity: tuple | None = None
    walls: object = None
    #: uniform shear flow (``[shear]``: :class:`granulargas.engine.shear.Shear`), or None
    shear: object = None
    #: rough particles: the tangential rule (None: smooth)
    tangential: object = None


# ------------------------------------------------------------------- particles


def mean_particle(config: RunConfig) -> tuple[float, float]:
    """(sigma, m): the config's mean diameter and the mass of a particle of that diameter
    (``particles.mass``, or ``particles.density`` times its volume); what kinetic theory
    of identical particles uses for the config. A mixture: the number-weighted mean diameter
    and mean mass of its species."""
    s, p = config.system, config.particles
    if config.species:
        x = species_fractions(config)
        sigma = float(np.dot(x, [sp.diameter for sp in config.species]))
        return sigma, float(np.dot(x, [sp.particle_mass(s.dimension) for sp in config.species]))
    sigma = p.diameter
    mass = p.mass if p.mass is not None else p.density * float(particle_volume(sigma, s.dimension))
    return sigma, mass


def species_fractions(config: RunConfig) -> np.ndarray:
    """Number fractions x_i of a mixture's species (S,), from their counts."""
    counts = np.array([sp.count for sp in config.species], dtype=float)
    return counts / counts.sum()


def make_particles(config: RunConfig, rng: np.random.Generator):
    """Radii and masses of the config's particles (polydisperse radii drawn from ``rng``); a
    mixture: the particles of each species in the order of ``[[species]]``, ids 0 .. n_1 - 1 the
    first (positions are random: the order places nothing), nothing drawn from ``rng``."""
    s, p = config.system, config.particles
    n = s.particles
    if config.species:
        of = species_indices(config)
        diam = np.array([sp.diameter for sp in config.species])[of]
        masses = np.array([sp.particle_mass(s.dimension) for sp in config.species])[of]
        return np.ascontiguousarray(0.5 * diam), np.ascontiguousarray(masses, dtype=np.float64)
    if p.polydisperse:
        diam = rng.uniform(p.diameter_min, p.diameter_max, n)
    else:
        diam = np.full(n, p.diameter)
    radii = np.ascontiguousarray(0.5 * diam)
    masses = np.full(n, p.mass) if p.mass is not None else p.density * particle_volume(diam, s.dimension)
    return radii, np.ascontiguousarray(masses, dtype=np.float64)


def species_indices(config: RunConfig) -> np.ndarray | None:
    """The species index of every particle (int32 (N,), in the order of ``[[species]]``; None
    without species)."""
    if not config.species:
        return None
    return np.repeat(np.arange(len(config.species), dtype=np.int32), [sp.count for sp in config.species])


def fresh_state(config: RunConfig) -> State:
    """Random non-overlapping positions and Maxwell-Boltzmann velocities with zero
    total momentum and temperature exactly ``initial.temperature``; all drawn from
    ``numpy.random.default_rng(system.seed)`` (radii, then positions, then velocities)
    by :func:`granulargas.initial.random_state`."""
    s = config.system
    check_memory(config)  # before anything is allocated
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
    for a, kind in enumerate(s.boundary):
        if kind == "wall" and box[a] < MIN_WALL_AXIS_DIAMETERS * dmax:
            raise ConfigError(
                f"{config.source}: system.boundary = [{', '.join(repr(b) for b in s.boundary)}]: the wall "
                f"axis {'xyz'[a]} is {box[a]:.4g} long, too short for the particles: it must be >= "
                f"{MIN_WALL_AXIS_DIAMETERS:g} largest diameters (= {MIN_WALL_AXIS_DIAMETERS * dmax:.4g}); "
                "use more particles or a higher packing_fraction"
            )
    walls = make_walls(config)
    margins = None
    if walls is not None:  # keep the sweep of the vibrating walls clear
        margins = np.array([[walls.side(a, 0).reach, walls.side(a, 1).reach] for a in range(s.dimension)])
        check_wall_room(config, walls, box, dmax)
    try:
        state = random_state(s.particles, s.packing_fraction, s.dimension, config.initial.temperature,
                             radii=radii, masses=masses, rng=rng, boundary=s.boundary, margins=margins,
                             shear=None if config.shear is None else config.shear.rate)
        return state if not config.species else state.replace(species=species_indices(config))
    except ConfigError as exc:
        limit = RANDOM_PLACEMENT_MAX[s.dimension]
        raise ConfigError(f"{config.source}: system.packing_fraction = {s.packing_fraction:g}: {exc}; random "
                          f"placement works up to about {limit:g} in {s.dimension}D") from None


def fresh_velocities(config: RunConfig) -> State:
    """A fresh state without positions (``run.method = "dsmc"``): radii and masses as
    :func:`fresh_state` draws them, the box of the packing fraction (its volume sets the
    density), Maxwell-Boltzmann velocities with zero total momentum and temperature exactly
    ``initial.temperature``, all from ``numpy.random.default_rng(system.seed)``; no
    hard-sphere placement (the costly part of a large engine state)."""
    s = config.system
    check_dsmc_memory(config)
    rng = np.random.default_rng(s.seed)
    radii, masses = make_particles(config, rng)
    box = box_for_packing(radii, s.packing_fraction, s.dimension)
    velocities = maxwell_velocities(masses, s.dimension, config.initial.temperature, rng=rng)
    return State(None, velocities, radii, masses, box, boundary=tuple(s.boundary), species=species_indices(config))


def restart_state(config: RunConfig) -> State:
    """The last snapshot of one of our files, with its time and counters
    (:func:`granulargas.io.h5md.read_state`), checked against the config."""
    path = Path(config.initial.from_file)
    where = f'{config.source}: initial.from = "{path}"'
    try:
        state = read_state(path, -1)
        with open_run(path) as f:
            file_method = "edmd" if has_positions(f) else "dsmc"
    except InputFileError as exc:
        raise InputFileError(f"{where}: {str(exc).split(': ', 1)[-1]}") from None
    if file_method != config.run.method:
        raise ConfigError(f'{config.source}: run.method = "{config.run.method}": restart file {path} is a '
                          f'{"DSMC run (no positions)" if file_method == "dsmc" else "EDMD run"}; continue it '
                          f'with method = "{file_method}"')
    n, dim = state.velocities.shape
    if dim != config.system.dimension:
        raise ConfigError(f"{config.source}: system.dimension = {config.system.dimension}: restart file {path} is {dim}D")
    if n != config.system.particles:
        raise ConfigError(
            f"{config.source}: system.particles = {config.system.particles}: restart file {path} has {n} particles"
        )
    arrays = ("positions", "velocities", "radii", "masses", "box") if file_method == "edmd" else (
        "velocities", "radii", "masses", "box")
    bad = [name for name in arrays if not np.all(np.isfinite(getattr(state, name)))]
    if bad or not (np.all(state.radii > 0) and np.all(state.masses > 0) and np.all(state.box > 0)):
        raise InputFileError(f"{where}: damaged H5MD file: the last snapshot holds non-finite or non-positive "
                             f"{', '.join(bad) or 'radii, masses or box'}")
    packing = float(particle_volume(2.0 * state.radii, dim).sum() / np.prod(state.box))
    if file_method == "dsmc":
        check_dsmc_memory(config, n=n)
    else:
        check_memory(config, n=n, packing=packing, fresh=False)
    if state.boundary != tuple(config.system.boundary):
        raise ConfigError(
            f"{config.source}: system.boundary = [{', '.join(repr(b) for b in config.system.boundary)}]: "
            f"restart file {path} has [{', '.join(repr(b) for b in state.boundary)}]"
        )
    want, have = species_indices(config), state.species
    if want is None and have is not None and np.any(have != 0):
        raise ConfigError(f"{config.source}: [[species]]: restart file {path} is a mixture of "
                          f"{int(have.max()) + 1} species; continue it with the [[species]] tables of its run")
    if want is not None:
        counts = [sp.count for sp in config.species]
        found = np.bincount(np.zeros(n, dtype=np.int64) if have is None else np.maximum(have, 0),
                            minlength=len(counts))
        if have is None or np.any(have < 0) or len(found) != len(counts) or np.any(found != counts):
            listed = ", ".join(f"{sp.name} {sp.count}" for sp in config.species)
            raise ConfigError(f"{config.source}: [[species]]: restart file {path} has species counts "
                              f"{found.tolist()}, the config {listed}")
    return state


# ------------------------------------------------------------------- collisions


def reduced_prefactor(config: RunConfig) -> float:
    """The viscoelastic pair prefactor k in reduced units (see module docstring). A mixture: the
    mean of its pair prefactors (:func:`pair_prefactors`) weighted by how often the pairs
    collide (:func:`pair_weights`), what the kinetic theory of one kind of particle uses for it."""
    c = config.collision
    if config.species:
        return float(np.sum(pair_weights(config) * pair_prefactors(config)))
    if c.material is None:
        return float(material.prefactor_from_damping(c.damping, radius=0.5, mass=1.0))
    m = c.material
    k_si = float(material.prefactor_from_material(m.young_modulus, m.poisson_ratio, m.dissipation_time))
    return k_si * (m.diameter * m.speed_unit / reference_mass_si(m) ** 2) ** 0.2


def pair_prefactors(config: RunConfig) -> np.ndarray:
    """The viscoelastic prefactors k_ij (S, S) of a mixture in reduced units: from ``damping``
    (a number or one per pair) as :func:`granulargas.contact.material.prefactor_from_damping`, or
    from each pair's materials (:func:`granulargas.contact.material.pair_prefactor_from_materials`,
    the species' constants or those of ``[collision.material]``) converted like one material's."""
    c, names = config.collision, config.species_names
    if c.material is None:
        table = c.pair_table(c.damping, names)
        return np.array([[material.prefactor_from_damping(x, radius=0.5, mass=1.0) for x in row] for row in table])
    m = c.material
    consts = [tuple(getattr(sp, k) if getattr(sp, k) is not None else getattr(m, k)
                    for k in ("young_modulus", "poisson_ratio", "dissipation_time")) for sp in config.species]
    unit = (m.diameter * m.speed_unit / reference_mass_si(m) ** 2) ** 0.2
    return np.array([[float(material.pair_prefactor_from_materials(*a, *b)) * unit for b in consts] for a in consts])


def pair_weights(config: RunConfig) -> np.ndarray:
    """How often each pair of species collides, relative: x_i x_j sigma_ij^(d-1) (S, S), summing to 1
    (the dilute collision rates at one temperature and one mass; for the averages of one-component
    kinetic theory)."""
    x = species_fractions(config)
    sig = np.array([sp.diameter for sp in config.species])
    w = np.outer(x, x) * (0.5 * (sig[:, None] + sig[None, :])) ** (config.system.dimension - 1)
    return w / w.sum()


def pair_restitutions(config: RunConfig) -> np.ndarray:
    """The constant eps_ij (S, S) of a mixture (``restitution`` a number or one per pair)."""
    return np.array(config.collision.pair_table(config.collision.restitution, config.species_names))


def mean_restitution(config: RunConfig) -> float:
    """The constant eps of a config; a mixture: the mean of eps_ij weighted by :func:`pair_weights`
    (what the kinetic theory of one kind of particle uses for it)."""
    if not config.species:
        return config.collision.restitution
    return float(np.sum(pair_weights(config) * pair_restitutions(config)))


def reduced_young_modulus(config: RunConfig) -> float:
    """The Young modulus of ``[collision.material]`` in reduced units (energy / length^3):
    Y diameter^3 / (m_ref speed_unit^2)."""
    m = config.collision.material
    return float(m.young_modulus * m.diameter**3 / (reference_mass_si(m) * m.speed_unit**2))


def reduced_compression(config: RunConfig) -> float:
    """The compression prefactor q of ``[collision.material]`` in reduced units (module docstring)."""
    m = config.collision.material
    return float(compression_prefactor(reduced_young_modulus(config), m.poisson_ratio))


def oblique_bounds(prefactor: float, compression: float, state: State) -> tuple[float, float]:
    """(beta, delta) of the fastest impact the initial state holds: relative speed twice the
    largest speed, for the pair with the largest pair constants (any two particles)."""
    m, r = state.masses, state.radii
    g = 2.0 * float(np.sqrt((state.velocities**2).sum(axis=1)).max())
    r_max, r_min, m_min, m_max = float(r.max()), float(r.min()), float(m.min()), float(m.max())
    beta = float(material.pair_constant(prefactor, r_max, r_max, m_min, m_min)) * g**0.2
    # X / D <= q (m_eff^2 / R_eff)^(1/5) g^(4/5) / (2 R_min) with m_eff <= m_max / 2, R_eff >= R_min / 2
    delta = compression * ((0.5 * m_max) ** 2 / (0.5 * r_min)) ** 0.2 * g**0.8 / (2.0 * r_min)
    return beta, delta


def reference_mass_si(material) -> float:
    """SI mass (kg) of the reference sphere of ``[collision.material]``: density x pi diameter^3 / 6
    (the reduced mass unit of the material route)."""
    return material.density * float(particle_volume(material.diameter, 3))


def beta_bound(prefactor: float, state: State, energy: float | None = None) -> float:
    """Largest beta any pair can reach in the run (rigorous; module docstring).

    ``energy``: the largest total kinetic energy the run reaches (default: the
    initial one, which collisions never raise; a driven run passes its own bound)."""
    m = state.masses
    if energy is None:
        energy = 0.5 * float((m[:, None] * state.velocities**2).sum())
    m_min = float(m.min())
    g_max = 2.0 * math.sqrt(2.0 * energy / m_min)
    r_max = float(state.radii.max())
    # R_eff <= R_max / 2 and m_eff >= m_min / 2: the pair constant of two (R_max, m_min) particles bounds all
    return float(material.pair_constant(prefactor, r_max, r_max, m_min, m_min)) * g_max**0.2


def expected_beta(prefactor: float, state: State) -> tuple[float, float]:
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


def validity_warnings(config: RunConfig, prefactor: float, state: State) -> list[str]:
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
        if config.species:  # the slowest sound of the species: density_s = density m_s / sigma_s^3
            sound = min(material.sound_speed(sp.young_modulus or mat.young_modulus,
                                             mat.density * sp.particle_mass(d) / sp.diameter**3)
                        for sp in config.species)
        else:
            sound = material.sound_speed(mat.young_modulus, mat.density)
    return [f"warning: {config.source}: {p}" for p in material.validity_problems(beta=high, impact_speed=speed,
                                                                          speed_of_sound=sound)]


def driven_energy_bound(config: RunConfig, prefactor: float, state: State) -> float:
    """Total kinetic energy the restitution table of a driven viscoelastic run must cover.

    Kicks are Gaussian, so no bound is rigorous: twice the larger of the initial energy
    and the energy N d T_ss / 2 of the theoretical steady state (the total energy of N
    particles fluctuates by ~ (2 / (d N))^(1/2) of itself); all of it in one pair, as in
    :func:`beta_bound`. A run that goes beyond stops with a TableRangeError."""
    s = config.system
    sigma, m = mean_particle(config)
    n = float(len(state.radii)) / float(np.prod(state.box))
    t_ss = theory.viscoelastic_driven_state(config.driving.heating_rate, prefactor, n, s.dimension, sigma,
                                            m, end=config.collision.contact_end)[0]
    e0 = 0.5 * float((state.masses[:, None] * state.velocities**2).sum())
    return 2.0 * max(e0, 0.5 * s.dimension * len(state.masses) * t_ss)


def sheared_energy_bound(config: RunConfig, prefactor: float, state: State) -> float:
    """The peculiar kinetic energy the restitution table of a sheared viscoelastic run must cover
    (as :func:`driven_energy_bound`): twice the larger of the initial peculiar energy and
    N d T / 2 at the steady or thermostat temperature (:func:`granulargas.theory.shear.steady_temperature`),
    with the relative speed a sigma the flow adds over a contact folded into the temperature."""
    s, sh = config.system, config.shear
    sigma, m = mean_particle(config)
    n = float(len(state.radii)) / float(np.prod(state.box))
    if sh.thermostat_temperature is not None:
        t_ss = sh.thermostat_temperature
    else:
        end = config.collision.contact_end
        t_ss = theory.shear.steady_temperature(
            sh.rate, lambda T: float(theory.effective_restitution(prefactor, T, s.dimension, sigma, m, end)), n,
            s.dimension, sigma, m, s.packing_fraction)
    t_ss = (math.sqrt(t_ss) + sh.rate * 2.0 * float(state.radii.max()) * math.sqrt(m)) ** 2
    c = state.velocities.copy()
    if state.positions is not None:
        c[:, 0] -= sh.rate * (state.positions[:, 1] - 0.5 * state.box[1])
    e0 = 0.5 * float((state.masses[:, None] * c**2).sum())
    return 2.0 * max(e0, 0.5 * s.dimension * len(state.masses) * t_ss)


def make_shear(config: RunConfig, state: State):
    """(Shear or None, parameters) of the config's ``[shear]``: the thermostat's interval,
    unless given, 0.1 of the shorter of the mean free time at its temperature and the
    shear time 1/rate (so that neither collisions nor the viscous heating change the
    temperature much between two rescalings)."""
    sh = config.shear
    if sh is None:
        return None, None
    params = {"rate": sh.rate, "flow": "x", "gradient": "y",
              "description": "uniform shear flow u = rate (y - L_y/2) along x; Lees-Edwards boundaries on y "
                             "(engine), homogeneous shear flow in the Lagrangian frame (DSMC)"}
    if sh.thermostat_temperature is None:
        return Shear(sh.rate), params
    interval = sh.thermostat_interval
    if interval is None:
        sigma, m = mean_particle(config)
        n = float(len(state.radii)) / float(np.prod(state.box))
        omega = float(theory.collision_frequency(n, sh.thermostat_temperature, config.system.dimension, sigma, m))
        interval = 0.1 / max(omega, sh.rate)
    params.update(thermostat_temperature=sh.thermostat_temperature, thermostat_interval=interval,
                  thermostat="the peculiar velocities rescaled to thermostat_temperature at (k + 1/2) interval")
    return Shear(sh.rate, sh.thermostat_temperature, interval), params


def scene_energy_bound(config: RunConfig, state: State) -> float:
    """Total kinetic energy the restitution table of a run under gravity or with thermal or
    vibrating walls must cover: twice the initial energy plus, per particle, the largest
    potential drop across the box along a wall axis (m |g_a| L_a), the speed gravity adds
    on a periodic axis by ``run.end_time`` (|g_a| t), ten times the fastest vibrating wall
    and ten thermal speeds of the hottest thermal wall (kinetic energies m v^2 / 2 of those
    speeds). No bound is rigorous for walls that put energy in; a run that goes beyond stops
    with a TableRangeError."""
    s = config.system
    m = state.masses
    e0 = 0.5 * float((m[:, None] * state.velocities**2).sum())
    speed2 = 0.0
    if config.gravity is not None:
        for a, g in enumerate(config.gravity.vector):
            if s.boundary[a] == "wall":
                speed2 += 2.0 * abs(g) * float(state.box[a])
            elif config.run.end_time is not None:
                speed2 += (abs(g) * config.run.end_time) ** 2
    walls = make_walls(config)
    if walls is not None:
        for a, side, w in walls.given():
            if w.kind == "vibrating":
                speed2 = max(speed2, (10.0 * w.max_speed) ** 2)
            elif w.kind == "thermal":
                speed2 = max(speed2, 100.0 * w.temperature / float(m.min()))
    return 2.0 * (e0 + 0.5 * float(m.sum()) * speed2)


def make_rule(config: RunConfig, state: State):
    """(rule, name, prefactor, table, warnings, parameters) for the config."""
    c = config.collision
    params = {"model": c.model}
    mixture = bool(config.species)
    if c.model == "elastic":
        return CollisionRule.elastic(len(config.species) if mixture else None), "elastic", None, None, [], params
    if c.model == "constant":
        params.update(restitution=c.restitution, tc_time=c.tc_time, wall_restitution=c.wall_restitution,
                      elastic_below=c.elastic_below)
        if mixture:
            eps = pair_restitutions(config)
            walls = c.species_values(c.wall_restitution, config.species_names, np.diagonal(eps))
            params.update(restitution=mean_restitution(config), restitution_pairs=eps,
                          wall_restitution=np.array(walls))
            rule = CollisionRule.constant(eps, tc_time=c.tc_time, wall_restitution=walls,
                                          elastic_below=c.elastic_below)
        else:
            rule = CollisionRule.constant(c.restitution, tc_time=c.tc_time, wall_restitution=c.wall_restitution,
                                          elastic_below=c.elastic_below)
        return rule, "constant", None, None, [], params
    k = reduced_prefactor(config)
    pairs = pair_prefactors(config) if mixture else None
    # the bounds of a mixture with its largest pair prefactor (rigorous: beta grows with k)
    k_bound = float(pairs.max()) if mixture else k
    driven = config.driving is not None and config.driving.heating_rate > 0.0
    energy = driven_energy_bound(config, k_bound, state) if driven else None
    if config.shear is not None:
        energy = sheared_energy_bound(config, k_bound, state)
    if config.gravity is not None or (config.walls is not None and config.walls.moving):
        energy = max(energy or 0.0, scene_energy_bound(config, state))
    bmax = beta_bound(k_bound, state, energy)
    if not bmax <= TABLE_BETA_MAX:
        key = ("collision.material" if c.material is not None else "collision.damping" if isinstance(c.damping, dict)
               else f"collision.damping = {c.damping:g}")
        energy = "the driving's energy bound" if driven else "the run's kinetic energy"
        raise ConfigError(
            f"{config.source}: {key}: the fastest impact {energy} allows reaches beta = {bmax:.3g}, "
            f"beyond the restitution table's {TABLE_BETA_MAX:g} (the viscoelastic model holds for beta well below 3); "
            "lower the damping")
    table = restitution_table(max(bmax, 1e-6), end=c.contact_end)
    warns = validity_warnings(config, k_bound, state)
    params.update(prefactor=k, contact_end=c.contact_end, damping=c.damping,
                  beta_expected=list(expected_beta(k_bound, state)), beta_bound=bmax)
    if mixture:
        params["prefactor_pairs"] = pairs
    params["restitution_table"] = {
        "inv_h": table.inv_h, "coeffs": np.asarray(table.coeffs), "duration_coeffs": np.asarray(table.duration_coeffs),
        "beta_max": table.beta_max, "end": table.end, **{k2: v for k2, v in table.parameters.items()},
    }
    if c.duration == "resolved":
        q = reduced_compression(config)
        beta, delta = oblique_bounds(k, q, state)
        if not (beta < OBLIQUE_BETA_MAX and delta < DELTA_MAX):
            raise ConfigError(
                f'{config.source}: collision.duration = "resolved": the fastest impact of the initial state '
                f"has beta = {beta:.3g}, compression over contact distance delta = {delta:.3g}; collisions that "
                f"take time need beta < {OBLIQUE_BETA_MAX:g} and delta < {DELTA_MAX:g} (a stiffer material, a "
                f"lower speed_unit or less damping)")
        oblique = oblique_table(max(beta, 1e-6), max(delta, 1e-6), end=c.contact_end)
        params.update(duration="resolved", compression=q)
        params["oblique_table"] = {"inv_hs": oblique.inv_hs, "inv_hd": oblique.inv_hd,
                                   "beta_max": oblique.beta_max, "delta_max": oblique.delta_max,
                                   **{k2: v for k2, v in oblique.parameters.items()}}
        rule = CollisionRule.viscoelastic(prefactor=k, table=table, duration="resolved", compression=q,
                                          oblique=oblique)
        return rule, "viscoelastic", k, table, warns, params
    params.update(elastic_below=c.elastic_below)
    return (CollisionRule.viscoelastic(prefactor=pairs if mixture else k, table=table, elastic_below=c.elastic_below),
            "viscoelastic", k, table, warns, params)


def make_driving(config: RunConfig, prefactor: float | None, state: State):
    """(WhiteNoise or None, parameters) of the config's ``[driving]``.

    The kick interval, unless given, is at most 0.02 of the shortest time over which
    the temperature changes by its own size: the steady state's cooling time
    1 / zeta(T_ss) (:func:`granulargas.theory.driving_interval`), the initial cooling
    time 1 / zeta(T0), or the heating time T0 / H of a gas starting colder. zeta is
    the Enskog rate (constant eps with the driven a2; viscoelastic with the effective
    restitution of :func:`granulargas.theory.effective_restitution`; 0 when elastic).
    It is then shortened to a whole fraction of the observables interval, so that every
    observables sample falls half-way between two kicks (the engine kicks at
    (k + 1/2) dt_k), where T equals its kick-interval average.
    The kicks' random stream is seeded with ``system.seed``. A heating rate of 0
    means no driving.
    """
    drv = config.driving
    if drv is None or drv.heating_rate == 0.0:
        return None, None
    s, c = config.system, config.collision
    sigma, m = mean_particle(config)
    n = float(len(state.radii)) / float(np.prod(state.box))
    d, h = s.dimension, drv.heating_rate
    t0 = float((state.masses[:, None] * state.velocities**2).sum()) / (d * len(state.masses))
    if c.model == "elastic":
        rates = [h / t0]
    else:
        if c.model == "constant":
            # a mixture: its most inelastic pair (the fastest cooling, the shortest interval)
            eps_ss = eps0 = float(pair_restitutions(config).min()) if config.species else c.restitution
            t_ss = float(theory.driven_temperature(h, eps_ss, n, d, sigma, m))
        else:
            t_ss, _, eps_ss = theory.viscoelastic_driven_state(h, prefactor, n, d, sigma, m, end=c.contact_end)
            eps0 = theory.effective_restitution(prefactor, t0, d, sigma, m, c.contact_end)
        rates = [h / t_ss, h / t0,
                 float(theory.enskog_cooling_rate(eps0, n, t0, d, sigma, m, a2=theory.driven_sonine_a2(eps0, d)))]
    if drv.interval is not None:
        interval = drv.interval
    else:
        interval = theory.driving_interval(max(rates))
        if config.run.end_time is not None:
            obs_dt = config.output.observables_interval or config.run.end_time / DEFAULT_OBSERVABLE_SAMPLES
            interval = obs_dt / math.ceil(obs_dt / interval * (1.0 - 1e-12))
    params = {"model": drv.model, "heating_rate": h, "interval": interval, "seed": s.seed,
              "rotational_fraction": drv.spin_fraction}
    return WhiteNoise(h, interval, seed=s.seed, rotational_fraction=drv.spin_fraction), params


def with_spins(config: RunConfig, state: State) -> State:
    """Rough particles: the state with its ``inertia`` (the config's kappa, unless the state
    has its own, as a restart file's) and ``angular_velocities`` (unless the state has them:
    Maxwell-Boltzmann spins at ``initial.rotational_temperature`` with zero total spin angular
    momentum, from ``numpy.random.default_rng([system.seed, 1])``, a stream of their own that
    leaves the positions and velocities those of the smooth run). Smooth particles: as it is."""
    if not config.collision.rough:
        return state
    n, d = state.n, state.dimension
    kappa = state.inertia if state.inertia is not None else np.full(n, config.particles.inertia)
    if state.angular_velocities is not None:
        return state.replace(inertia=kappa)
    moments = kappa * state.masses * state.radii**2
    rng = np.random.default_rng([config.system.seed, 1])
    spins = maxwell_spins(moments, d, config.initial.rotational_temperature, rng=rng)
    return state.replace(inertia=kappa, angular_velocities=spins)


def make_tangential(config: RunConfig):
    """(TangentialRule or None, parameters) of the config's ``[collision.tangential]``."""
    t = config.collision.tangential
    if t is None:
        return None, None
    if t.model == "coulomb":
        rule = TangentialRule.coulomb(t.restitution, t.friction, t.wall_restitution, t.wall_friction)
    else:
        rule = TangentialRule.constant(t.restitution, t.wall_restitution)
    return rule, {**rule.parameters(), "inertia": config.particles.inertia}


def make_walls(config: RunConfig):
    """The config's ``[walls]`` as :class:`granulargas.engine.walls.Walls` (None without the
    section); the thermal walls' draws are seeded with ``system.seed``."""
    if config.walls is None:
        return None
    sides = {}
    for a in range(config.system.dimension):
        for side in (0, 1):
            name = "xyz"[a] + ("_low", "_high")[side]
            w = getattr(config.walls, name)
            if w is None:
                continue
            if w.kind == "vibrating":
                sides[name] = Wall.vibrating(w.amplitude, w.frequency, w.waveform, w.phase)
            elif w.kind == "thermal":
                sides[name] = Wall.thermal(w.temperature)
            else:
                sides[name] = Wall.hard()
    return Walls(**sides, seed=config.system.seed)


def check_wall_room(config: RunConfig, walls, box, dmax: float) -> None:
    """The vibrating walls of each axis leave room for a particle at their closest (twice
    their amplitudes less than the axis, by more than the largest diameter); one line
    naming the amplitude key otherwise."""
    for a in range(config.system.dimension):
        lo, hi = walls.side(a, 0), walls.side(a, 1)
        room = float(box[a]) - lo.reach - hi.reach
        if config.system.boundary[a] == "wall" and not room > dmax:
            name = "xyz"[a] + ("_low" if lo.reach >= hi.reach else "_high")
            amp = getattr(config.walls, name).amplitude
            raise ConfigError(f"{config.source}: walls.{name}.amplitude = {amp:g}: the walls of the {'xyz'[a]} "
                              f"axis (length {float(box[a]):.4g}) reach {lo.reach:.4g} and {hi.reach:.4g} into the "
                              f"box (twice their amplitudes) and leave {room:.4g} at their closest, no room for a "
                              f"particle of diameter {dmax:.4g}")


def make_scene(config: RunConfig, state: State):
    """(gravity, walls, parameters) of the config's ``[gravity]`` and ``[walls]``: the
    acceleration as a tuple (None without the section or for a zero vector), the wall kinds
    (:func:`make_walls`, checked against the state's box) and the ``parameters/`` record."""
    g = config.gravity.vector if config.gravity is not None else None
    if g is not None and not any(g):
        g = None
    walls = make_walls(config)
    params = {}
    if g is not None:
        params["gravity"] = {"acceleration": np.array(g)}
    if walls is not None:
        check_wall_room(config, walls, state.box, 2.0 * float(state.radii.max()))
        params["walls"] = {name: {"kind": w.kind, "amplitude": w.amplitude, "frequency": w.frequency,
                                  "waveform": w.waveform, "phase": w.phase, "temperature": w.temperature}
                           for name, w in ((n, getattr(walls, n)) for n in WALL_SIDES) if w is not None}
    return g, walls, params
def species_parameters(config: RunConfig) -> dict:
    """The species of a mixture for the H5MD ``parameters/species`` group: names (in index order),
    counts, diameters, masses, number fractions, and the material constants each species uses."""
    d = config.system.dimension
    sp = config.species
    out = {"names": [x.name for x in sp], "counts": np.array([x.count for x in sp], dtype=np.int64),
           "diameters": np.array([x.diameter for x in sp]), "masses": np.array([x.particle_mass(d) for x in sp]),
           "fractions": species_fractions(config),
           "description": "species i is particles/all/species == i; pair tables (S, S) in the same order"}
    mat = config.collision.material
    if mat is not None and config.collision.model == "viscoelastic":
        for key in ("young_modulus", "poisson_ratio", "dissipation_time"):
            out[key] = np.array([getattr(x, key) if getattr(x, key) is not None else getattr(mat, key) for x in sp])
    return out


def mixture_of_config(config: RunConfig) -> "theory.mixture.Mixture":
    """The kinetic theory's view of a mixture config (:class:`granulargas.theory.mixture.Mixture`):
    species, total number density of ``system.packing_fraction``, the law per pair (constant
    eps_ij or viscoelastic k_ij), and the Enskog chi_ij at that packing fraction
    (:func:`contact_values_at`)."""
    d = config.system.dimension
    sp = config.species
    x = species_fractions(config)
    diam = np.array([s.diameter for s in sp])
    n = config.system.packing_fraction / float(np.sum(x * particle_volume(diam, d)))
    c = config.collision
    eps = pair_restitutions(config) if c.model == "constant" else None
    k = pair_prefactors(config) if c.model == "viscoelastic" else None
    as_tuple = lambda a: None if a is None else tuple(tuple(float(v) for v in row) for row in a)  # noqa: E731
    return theory.mixture.Mixture(
        names=config.species_names, masses=tuple(s.particle_mass(d) for s in sp), diameters=tuple(diam.tolist()),
        counts=tuple(s.count for s in sp), dimension=d, number_density=float(n), restitution=as_tuple(eps),
        prefactor=as_tuple(k), end=c.contact_end,
        chi=as_tuple(contact_values_at(diam, x * n, config.system.packing_fraction, d)))


def contact_values_at(diameters, densities, packing: float, dimension: int) -> np.ndarray:
    """chi_ij (S, S) of species of ``diameters`` at number ``densities``: the one-component contact
    value (:func:`granulargas.theory.contact_value`) for every pair when the species have one
    diameter (so that a mixture of identical species is the one-component gas), else the
    mixture's (:func:`granulargas.theory.mixture.mixture_contact_values`)."""
    diam = np.asarray(diameters, dtype=float)
    size = diam.size
    if np.all(diam == diam[0]):
        return np.full((size, size), float(theory.contact_value(packing, dimension)))
    return theory.mixture.mixture_contact_values(diam, np.asarray(densities, dtype=float), dimension)


def mixture_contact_values(config: RunConfig, state: State) -> np.ndarray:
    """chi_ij (S, S) of a mixture's DSMC at the state's packing fraction (:func:`contact_values_at`)."""
    d = config.system.dimension
    diam = np.array([sp.diameter for sp in config.species])
    volume = float(np.prod(state.box))
    packing = float(particle_volume(2.0 * state.radii, d).sum() / volume)
    counts = np.array([sp.count for sp in config.species], dtype=float)
    return contact_values_at(diam, counts / volume, packing, d)


def initial_state(config: RunConfig) -> State:
    """The state a run of ``config`` starts from: the restart file's last snapshot
    (``initial.from``) or a fresh random state (rough particles: with spins, :func:`with_spins`)."""
    if config.initial.from_file:
        return with_spins(config, restart_state(config))
    return with_spins(config, fresh_velocities(config) if config.run.method == "dsmc" else fresh_state(config))


def prepare(config: RunConfig) -> Setup:
    """Build rule, table and initial state; raise before any file is written."""
    state = initial_state(config)
    source = str(Path(config.initial.from_file)) if config.initial.from_file else None
    rule, name, k, table, warns, rule_params = make_rule(config, state)
    driving, driving_params = make_driving(config, k, state)
    shear, shear_params = make_shear(config, state)
    gravity, walls, scene_params = make_scene(config, state)
    tangential, tangential_params = make_tangential(config)
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
        "boundary": " ".join(s.boundary),
        "method": config.run.method,
    }
    if driving_params is not None:
        parameters["driving"] = driving_params
    if shear_params is not None:
        parameters["shear"] = shear_params
    parameters.update(scene_params)
    if config.run.method == "dsmc":
        parameters["dsmc"] = {
            "chi": float(theory.contact_value(parameters["packing_fraction"], s.dimension)),
            "number_density": float(len(state.radii) / np.prod(state.box)),
            "description": "DSMC of the homogeneous Enskog-Boltzmann equation (granulargas.dsmc): no positions; "
                           "chi = theory.contact_value(packing_fraction)",
        }
    if config.species:
        parameters["species"] = species_parameters(config)
        if config.run.method == "dsmc":
            chi = mixture_contact_values(config, state)
            parameters["dsmc"]["chi_pairs"] = chi
            parameters["dsmc"]["description"] = (
                "DSMC of the homogeneous Enskog-Boltzmann equation of a mixture (granulargas.dsmc): no positions; "
                "chi_pairs = theory.mixture.mixture_contact_values (BGHLM in 3D, Jenkins-Mancini in 2D; one size: "
                "theory.contact_value)")
    if config.collision.material is not None:
        m = config.collision.material
        parameters["units_si"] = {"length_m": m.diameter, "mass_kg": reference_mass_si(m),
                                  "speed_m_per_s": m.speed_unit, "time_s": m.diameter / m.speed_unit}
    if source:
        parameters["restart"] = {"file": source, "time": state.time, "step": state.events,
                                 "collisions": state.collisions}
    if tangential_params is not None:
        parameters["tangential"] = tangential_params
    return Setup(rule, name, state, k, table, parameters, warns, driving, source, gravity, walls, shear=shear,
                 tangential=tangential)
