"""The scene of a run under gravity or with thermal or vibrating walls, from the config alone.

A vibrated gas does not cool freely: the walls put energy in and, under gravity, the gas
fills a height of about T / (m g) above the floor. :func:`scene` names its numbers for
the run summary and ``granulargas advise`` (:func:`scene_lines`):

* gravity: |g| and the gravitational height T0 / (m |g|) against the box;
* each vibrating wall: A, nu, A omega, the mean square wall velocity <U^2>, and, along the
  axis of gravity, Gamma = A omega^2 / |g| with the bouncing ball's threshold of a period-1
  orbit pi (1 - e) / (1 + e) for the run's wall restitution (Holmes 1982);
* a floor that vibrates under gravity with a constant e < 1: the leading-order temperature
  of the dilute bed (Kumaran 1998; :func:`granulargas.theory.vibrated.vibrated_bed_temperature`)
  with its small parameters, each of which must be << 1 for it to hold;
* each thermal wall: T_w;
* the Zeno-trap risk: a constant e < 1 under gravity with a wall across it, without
  ``elastic_below`` or ``tc_time`` (a grain coming to rest on the floor bounces infinitely often).
"""

from __future__ import annotations

import math

from granulargas.io.config import RunConfig
from granulargas.theory import vibrated as V

__all__ = ["is_vibrated", "scene", "scene_lines"]

_OMEGA = 2.0 * math.pi


def is_vibrated(config: RunConfig) -> bool:
    """Whether the run has gravity or thermal or vibrating walls."""
    gravity = config.gravity is not None and any(config.gravity.vector)
    return gravity or (config.walls is not None and config.walls.moving)


def _box(config: RunConfig) -> float:
    """The box side of a fresh state (the mean diameter's particles; a cube or square)."""
    s, p = config.system, config.particles
    d = s.dimension
    unit = math.pi / 6.0 if d == 3 else math.pi / 4.0
    return (s.particles * unit * p.diameter**d / s.packing_fraction) ** (1.0 / d)


def scene(config: RunConfig) -> dict:
    """The scene's numbers (module doc) as a dict; empty for a run without gravity and moving walls."""
    if not is_vibrated(config):
        return {}
    s, c = config.system, config.collision
    d = s.dimension
    mass = config.particles.mass or 1.0
    length = _box(config)
    out = {"box": length, "walls": []}
    g = config.gravity.vector if config.gravity is not None else (0.0,) * d
    gnorm = math.sqrt(sum(x * x for x in g))
    axis = max(range(d), key=lambda a: abs(g[a])) if gnorm > 0 else None
    boundary = s.boundary or ("periodic",) * d
    floor = gnorm > 0 and any(boundary[a] == "wall" and g[a] != 0.0 for a in range(d))
    if gnorm > 0:
        out["gravity"] = gnorm
        out["height"] = config.initial.temperature / (mass * gnorm)
        out["floor"] = floor
    e = c.restitution if c.model == "constant" else (1.0 if c.model == "elastic" else None)
    e_wall = c.wall_restitution if c.model == "constant" and c.wall_restitution is not None else e
    for name in ("x_low", "x_high", "y_low", "y_high", "z_low", "z_high"):
        w = getattr(config.walls, name, None) if config.walls is not None else None
        if w is None or w.kind == "hard":
            continue
        a = "xyz".index(name[0])
        item = {"side": name, "kind": w.kind}
        if w.kind == "thermal":
            item["temperature"] = w.temperature
        else:
            from granulargas.engine.walls import Wall

            wall = Wall.vibrating(w.amplitude, w.frequency, w.waveform, w.phase)
            item.update(amplitude=w.amplitude, frequency=w.frequency, speed=w.amplitude * _OMEGA * w.frequency,
                        u2=wall.mean_square_velocity)
            if axis == a and abs(g[a]) > 0:
                item["gamma"] = w.amplitude * (_OMEGA * w.frequency) ** 2 / abs(g[a])
                if e_wall is not None:
                    item["gamma_1"] = V.bouncing_ball_threshold(1, e_wall)
                if e is not None and e < 1.0 and name.endswith("low") == (g[a] < 0):  # the floor
                    column = s.particles / length ** (d - 1)
                    item["bed"] = V.bed_parameters(column, e, w.amplitude, wall.mean_square_velocity, abs(g[a]), d,
                                                   config.particles.diameter, mass)
        out["walls"].append(item)
    out["zeno"] = (floor and c.model in ("constant", "viscoelastic") and c.elastic_below is None
                   and c.tc_time is None and (c.model != "constant" or c.restitution < 1.0))
    return out


def scene_lines(config: RunConfig) -> list[str]:
    """The run summary's lines of a vibrated scene (none for other runs)."""
    sc = scene(config)
    if not sc:
        return []
    out = []
    if "gravity" in sc and sc["floor"]:
        out.append(f"scene        gravity |g| = {sc['gravity']:.4g}: T0 fills a height T0/(m g) = {sc['height']:.3g} "
                   f"of the box side {sc['box']:.3g}")
    elif "gravity" in sc:
        out.append(f"scene        gravity |g| = {sc['gravity']:.4g} along periodic axes only: the gas falls freely "
                   "(no floor)")
    for w in sc["walls"]:
        if w["kind"] == "thermal":
            out.append(f"scene        {w['side']}: thermal wall at T_w = {w['temperature']:.4g}")
            continue
        line = (f"scene        {w['side']}: vibrating wall, A = {w['amplitude']:.3g}, nu = {w['frequency']:.4g}, "
                f"A omega = {w['speed']:.3g}")
        if "gamma" in w:
            line += f", Gamma = {w['gamma']:.3g}"
            if "gamma_1" in w:
                line += f" (a period-1 bouncing ball from {w['gamma_1']:.3g})"
        out.append(line)
        if "bed" in w:
            b = w["bed"]
            small = max(b["dissipation"], b["plate_speed"], b["amplitude"], b["floor_packing"])
            verdict = "within its range" if small < 0.3 else "outside its range (a parameter not << 1)"
            out.append(f"scene        dilute bed at leading order (Kumaran 1998): T = {b['temperature']:.3g}; "
                       f"(1-e^2) N = {b['dissipation']:.2g}, m<U^2>/T = {b['plate_speed']:.2g}, A m g/T = "
                       f"{b['amplitude']:.2g}, floor packing {b['floor_packing']:.2g}: {verdict}")
    if sc["zeno"]:
        out.append("warning: inelastic collisions under gravity without collision.elastic_below or tc_time: a grain "
                   "coming to rest on the floor bounces infinitely often and stops the run (set elastic_below, "
                   "e.g. 1e-3 of the thermal speed)")
    return out
