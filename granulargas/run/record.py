"""Write a run built in Python to an H5MD file that analyze, export and restarts read.

``granulargas run`` writes its file through :class:`granulargas.io.h5md.H5MDWriter`
with the run's model in ``parameters/``; a :class:`granulargas.engine.Simulation` (or a
:class:`granulargas.dsmc.DSMC`) built in Python gets the same file from
:class:`RunWriter`::

    from granulargas.run.record import RunWriter

    with RunWriter("runs/mine.h5", sim) as out:   # the starting state: a sample and a frame
        for t in np.linspace(0.5, 100.0, 200):
            sim.run(until=t)
            out.sample()                        # observables (T, energy, collisions, pressure, a2, ...)
            if t % 10.0 == 0.0:
                out.snapshot()                  # a frame (synchronises sim), sampled at the same time

What the file records, from the simulation itself (:func:`run_parameters`): the
collision rule (``parameters/collision``: the model, eps, the TC time, the viscoelastic
prefactor, contact end and restitution table, the resolved rule's compression
prefactor), the boundary, the driving (``parameters/driving``), the method (EDMD or
DSMC, with the DSMC's chi and number density), the dimension, particle count and
packing fraction; rough particles' tangential law (``parameters/tangential``) and their angular
velocities in every frame. ``granulargas analyze`` then compares the run with the theory of
that model; ``granulargas export gsd`` converts it; ``granulargas run CONFIG
--restart FILE`` continues from its last frame (whose observables sample holds the
counters a restart needs). The observables are those the runner samples
(:func:`observables`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from granulargas import __version__, theory
from granulargas.dsmc import DSMC
from granulargas.engine.walls import SIDES as WALL_SIDES
from granulargas.io.h5md import H5MDWriter
from granulargas.observables import sonine_coefficients, species_moments
from granulargas.run.rough import rotational_observables
from granulargas.state import State

__all__ = ["RunWriter", "run_parameters", "rule_parameters", "shear_parameters", "observables"]

#: ``parameters/units`` of a run in reduced units
UNITS = ("length: reference particle diameter; mass: reference particle mass; energy: initial temperature T0 "
         "(k_B = 1); time: diameter * sqrt(mass / T0)")


def rule_parameters(rule) -> dict:
    """``parameters/collision`` of a :class:`granulargas.engine.CollisionRule`: what the analysis
    needs to compare the run with kinetic theory (as ``granulargas run`` records it)."""
    out = {"model": rule.kind}
    if rule.pairs is not None:  # a mixture: the law per pair of species
        tables = rule.pairs.arrays()
        if rule.kind == "constant":
            out.update(restitution_pairs=tables["restitution"], wall_restitution=tables["wall_restitution"])
        elif rule.kind == "viscoelastic":
            out["prefactor_pairs"] = tables["prefactor"]
    if rule.kind == "constant":
        out.update(restitution=float(rule.restitution), tc_time=rule.tc_time,
                   wall_restitution=rule.wall_restitution)
    elif rule.kind == "viscoelastic":
        table = rule.table
        out.update(prefactor=float(rule.prefactor), contact_end=str(getattr(table, "end", "overlap")),
                   tc_time=rule.tc_time)
        out["restitution_table"] = {"inv_h": float(table.inv_h), "coeffs": np.asarray(table.coeffs),
                                    "beta_max": float(getattr(table, "beta_max", math.nan)),
                                    "end": str(getattr(table, "end", "overlap"))}
        if getattr(table, "duration_coeffs", None) is not None:
            out["restitution_table"]["duration_coeffs"] = np.asarray(table.duration_coeffs)
        if rule.resolved:
            out.update(duration="resolved", compression=float(rule.compression))
    return out


def _is_dsmc(sim) -> bool:
    return isinstance(sim, DSMC)


def _box(sim) -> np.ndarray:
    """The simulation's box; a DSMC's is the cube of its volume (it only sets the density)."""
    if _is_dsmc(sim):
        return np.full(sim.dimension, float(sim.volume) ** (1.0 / sim.dimension))
    return np.asarray(sim.box, dtype=np.float64)


def _boundary(sim) -> tuple:
    return ("periodic",) * sim.dimension if _is_dsmc(sim) else tuple(sim.boundary)


def _state(sim) -> State:
    """The simulation's state (:class:`granulargas.state.State`) with a box (a DSMC given a density
    has none: the cube of its volume)."""
    state = sim.state
    return state if state.box is not None else dataclasses.replace(state, box=_box(sim))


def _fields(sim) -> tuple:
    """The per-frame fields a restart of ``sim`` needs besides positions, velocities and images."""
    rough = ("angular_velocities",) if getattr(sim, "tangential", None) is not None else ()
    if _is_dsmc(sim):
        return rough
    rule = sim.rule
    tc = rule.kind == "constant" and rule.tc_time is not None
    return ((("last_collision",) if tc else ()) + (("contact_until", "contact_partner") if rule.resolved else ())
            + rough)


def run_parameters(sim) -> dict:
    """``parameters/`` of a run built in Python: the model, boundary, driving and method of ``sim``
    (module docstring)."""
    box = _box(sim)
    d = int(box.shape[0])
    radii = np.asarray(sim.radii)
    out = {
        "version": __version__,
        "written_by": "granulargas.run.record.RunWriter (a run built in Python: no config)",
        "dimension": d,
        "particles": int(radii.shape[0]),
        "packing_fraction": float(np.sum(theory.particle_volume(2.0 * radii, d)) / float(np.prod(box))),
        "units": UNITS,
        "collision": rule_parameters(sim.rule),
        "boundary": " ".join(_boundary(sim)),
        "method": "dsmc" if _is_dsmc(sim) else "edmd",
    }
    if sim.driving is not None and sim.driving.heating_rate > 0.0:
        drv = sim.driving
        out["driving"] = {"model": "white_noise", "heating_rate": float(drv.heating_rate),
                          "interval": float(drv.interval), "seed": int(drv.seed),
                          "rotational_fraction": float(drv.rotational_fraction)}
    tg = getattr(sim, "tangential", None)
    if tg is not None:  # rough particles: the tangential law and kappa (analysis.rough reads it)
        kappa = np.asarray(sim.inertia)
        out["tangential"] = {**tg.parameters(), "inertia": float(kappa.mean())}
    if getattr(sim, "shear", None) is not None:
        out["shear"] = shear_parameters(sim.shear)
    if _is_dsmc(sim):
        out["dsmc"] = {"chi": float(sim.chi), "number_density": float(radii.shape[0] / float(sim.volume))}
        if sim.chi_pairs is not None:
            out["dsmc"]["chi_pairs"] = np.asarray(sim.chi_pairs)
    if getattr(sim, "gravity", None) is not None:
        out["gravity"] = {"acceleration": np.array(sim.gravity)}
    if getattr(sim, "walls", None) is not None:
        out["walls"] = {name: {"kind": w.kind, "amplitude": w.amplitude, "frequency": w.frequency,
                               "waveform": w.waveform, "phase": w.phase, "temperature": w.temperature}
                        for name, w in ((n, getattr(sim.walls, n)) for n in WALL_SIDES) if w is not None}
    if sim.rule.species:
        out["species"] = species_parameters(sim, d)
    return out


def shear_parameters(shear) -> dict:
    """``parameters/shear`` of a :class:`granulargas.engine.shear.Shear` (as ``granulargas run``
    records a config's ``[shear]``)."""
    out = {"rate": float(shear.rate), "flow": "x", "gradient": "y",
           "description": "uniform shear flow u = rate (y - L_y/2) along x; Lees-Edwards boundaries on y "
                          "(engine), homogeneous shear flow in the Lagrangian frame (DSMC)"}
    if shear.thermostat:
        out.update(thermostat_temperature=float(shear.temperature), thermostat_interval=float(shear.interval))
    return out


def species_parameters(sim, dimension: int) -> dict:
    """``parameters/species`` of a mixture built in Python: the species are named by their index
    ("0", "1", ...); counts, and diameter and mass of each (those of its first particle)."""
    size = sim.rule.species
    of = sim.species
    of = np.zeros(sim.n, dtype=np.int64) if of is None else np.asarray(of)
    counts = np.bincount(of, minlength=size)
    first = [int(np.flatnonzero(of == s)[0]) if counts[s] else 0 for s in range(size)]
    radii, masses = np.asarray(sim.radii), np.asarray(sim.masses)
    return {"names": [str(s) for s in range(size)], "counts": counts.astype(np.int64),
            "diameters": 2.0 * radii[first], "masses": masses[first], "fractions": counts / counts.sum(),
            "description": "species i is particles/all/species == i (a run built in Python)"}


def observables(sim, pressure: bool) -> dict:
    """One observables sample of an engine run or a DSMC (what ``granulargas run`` writes).

    ``pressure``: the mean pressure since the last sample (False at a run's first sample:
    NaN); a DSMC has none."""
    if hasattr(sim, "observables"):  # a config's DSMC run (run.dsmc_run.DSMCRun)
        return sim.observables()
    thermostat = getattr(sim, "shear", None) is not None and sim.shear.thermostat
    rough = {} if getattr(sim, "tangential", None) is None else rotational_observables(sim)
    if _is_dsmc(sim):
        a2, a3 = sim.sonine_a2, sim.sonine_a3
        driven = {} if sim.driving is None else {"injected_energy": float(sim.injected_energy),
                                                  "kick_step": int(sim.kick_step)}
        if sim.shear is not None:
            if thermostat:  # the heat the thermostat took out (< 0)
                driven = {"injected_energy": float(sim.injected_energy), "kick_step": 0}
            driven["pressure_tensor"] = sim.pressure_tensor_window()
        return {**driven, **species_observables(sim),
                "temperature": float(sim.temperature), "kinetic_energy": float(sim.kinetic_energy),
                "collisions": int(sim.collisions), "events": int(sim.candidates),
                "dissipated_energy": float(sim.dissipated_energy),
                "momentum": np.asarray(sim.momentum, dtype=np.float64), "sonine_a2": float(a2),
                "sonine_a3": float(a3), **rough}
    a2, a3 = sonine_coefficients(sim.velocities, sim.masses)
    out = {
        "temperature": float(sim.temperature),
        "kinetic_energy": float(sim.kinetic_energy),
        "collisions": int(sim.collisions),
        "events": int(sim.events),
        "dissipated_energy": float(sim.dissipated_energy),
        "momentum": np.asarray(sim.momentum, dtype=np.float64),
        "sonine_a2": float(a2),
        "sonine_a3": float(a3),
    }
    d = sim.dimension
    if pressure:
        p, tensor = sim.pressure_windows()
    else:
        p, tensor = math.nan, (np.full((d, d), math.nan) if sim.stress else None)
    out["pressure"] = float(p)
    if tensor is not None:
        out["pressure_tensor"] = np.asarray(tensor, dtype=np.float64)
    gravity = getattr(sim, "gravity", None)
    walls = getattr(sim, "walls", None)
    if gravity is not None:
        out["potential_energy"] = float(sim.potential_energy)
    if "wall" in sim.boundary:
        out["wall_collisions"] = int(sim.wall_collisions)
        if (walls is not None and walls.moving) or gravity is not None:  # a vibrated scene
            out["wall_work"] = float(sim.wall_work)
            # the momentum per wall over the interval (read before the wall pressure resets it)
            out["wall_impulse"] = sim.wall_impulse() if pressure else np.full((sim.dimension, 2), math.nan)
        out["wall_pressure"] = float(sim.wall_pressure_window()) if pressure else math.nan
    if sim.driving is not None or thermostat:
        out["injected_energy"] = float(sim.injected_energy)  # a thermostat's: the heat taken out, < 0
        out["kick_step"] = int(sim.kick_step)
    if sim.rule.resolved:
        out["three_body_contacts"] = int(sim.three_body_contacts)
    out.update(rough)
    out.update(species_observables(sim))
    return out


def species_observables(sim) -> dict:
    """The observables of a mixture (its rule has a pair table; else none): the temperature
    and a2 of each species (:func:`granulargas.observables.species_moments`) and the collisions
    per pair of species so far."""
    size = sim.rule.species
    if not size:
        return {}
    of = sim.species
    of = np.zeros(sim.n, dtype=np.int32) if of is None else of
    temperature, a2 = species_moments(sim.velocities, sim.masses, of, size)
    return {"species_temperature": temperature, "species_sonine_a2": a2,
            "species_collisions": np.asarray(sim.species_collisions, dtype=np.int64)}


class RunWriter:
    """The H5MD file of a run built in Python (module docstring).

    Parameters
    ----------
    path : str or Path
        Output file (an existing one is replaced only with ``overwrite``).
    sim : Simulation or DSMC
        The run; its state at construction is written as the first sample and frame.
    overwrite : bool
    parameters : dict, optional
        More entries for ``parameters/`` (written after :func:`run_parameters`).
    """

    def __init__(self, path, sim, *, overwrite: bool = False, parameters: dict | None = None):
        self.sim = sim
        self.dsmc = _is_dsmc(sim)
        params = {**run_parameters(sim), **(parameters or {})}
        sheared = getattr(sim, "shear", None) is not None
        walls = getattr(sim, "walls", None)
        self.writer = H5MDWriter(path, _state(sim), fields=_fields(sim), parameters=params, overwrite=overwrite,
                                 driven=sim.driving is not None or (sheared and sim.shear.thermostat),
                                 gravity=getattr(sim, "gravity", None) is not None,
                                 wall_kinds=walls is not None and walls.moving,
                                 tensor=(not self.dsmc and sim.stress) or sheared, species=sim.rule.species)
        self.path = self.writer.path
        self._last_sample = None
        try:
            self._sample(pressure=False)
            self.snapshot()
        except BaseException:
            self.writer.close()
            raise

    def _clock(self):
        sim = self.sim
        return (int(sim.collisions if self.dsmc else sim.events), float(sim.time))

    def _sample(self, pressure: bool):
        step, time = self._clock()
        self.writer.write_observables(step, time, observables(self.sim, pressure), flush=False)
        self._last_sample = (step, time)

    def sample(self):
        """Append one observables sample at the simulation's time (the pressure: the mean since
        the previous sample)."""
        self._sample(pressure=True)

    def snapshot(self):
        """Append one frame (synchronising an engine run) and an observables sample at its time
        unless one was just taken."""
        if not self.dsmc:
            self.sim.synchronise()
        if self._clock() != self._last_sample:
            self.sample()
        self.writer.write_state(_state(self.sim))

    def close(self):
        """Record where the run ended (``parameters/summary``) and close the file."""
        if self.writer.file.id.valid:
            step, time = self._clock()
            self.writer.set_parameters({"summary": {"stop_reason": "written from Python", "time": time,
                                                    "collisions": int(self.sim.collisions), "events": step}})
            self.writer.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
