"""Run preparation: the initial state of a config and the checks made before any file exists."""

import math

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation
from granulargas.engine.simulation import MIN_BOX_DIAMETERS
from granulargas.errors import ConfigError
from granulargas.initial import box_for_packing, random_state
from granulargas.io.config import parse_config
from granulargas.run.prepare import fresh_state, mean_particle
from granulargas.state import State
from granulargas.theory import particle_volume

CONFIG = """
[system]
dimension = 3
particles = 20
packing_fraction = {eta!r}
seed = 3

[collision]
model = "elastic"

[run]
end_time = 1.0
"""


def _edge_packing(n, dimension, edge):
    """Packing fraction whose cubic box of n unit spheres has side ``edge``."""
    return n * float(particle_volume(1.0, dimension)) / edge**dimension


def _lattice(n_side, box):
    g = (np.arange(n_side) + 0.5) * box / n_side
    return np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T.copy()


def test_engine_smallest_box_boundary():
    """The engine accepts a box of exactly MIN_BOX_DIAMETERS largest diameters and refuses one ulp less."""
    assert MIN_BOX_DIAMETERS == 3.15  # 3 cells per side x (1 diameter + 0.05 minimum shell)
    for box, ok in ((MIN_BOX_DIAMETERS, True), (math.nextafter(MIN_BOX_DIAMETERS, 0.0), False)):
        pos = _lattice(2, box)
        args = (State(pos, np.zeros_like(pos), np.full(8, 0.5), np.ones(8), np.full(3, box)), CollisionRule.elastic())
        if ok:
            sim = Simulation(*args)
            sim.run(until=0.1)
            assert sim.shell >= 0.05 * (1.0 - 1e-12)
        else:
            with pytest.raises(ConfigError, match="3.15 largest diameters"):
                Simulation(*args)


@pytest.mark.parametrize("side, ok", [(1.0 - 1e-12, False), (1.0 + 1e-12, True)])
def test_config_and_engine_agree_at_the_smallest_box(side, ok):
    """A config just below the engine's smallest box is refused in one line naming the key;
    just above, the state is built and the engine takes it."""
    eta = _edge_packing(20, 3, MIN_BOX_DIAMETERS * side)
    config = parse_config(CONFIG.format(eta=eta), source="c.toml")
    box = box_for_packing(np.full(20, 0.5), eta, 3)
    assert (box[0] >= MIN_BOX_DIAMETERS) == ok
    if not ok:
        with pytest.raises(ConfigError, match=r"^c\.toml: system\.particles = 20: box edge .* below 3\.15 largest"):
            fresh_state(config)
        return
    state = fresh_state(config)
    Simulation(state, CollisionRule.elastic()).run(until=0.1)


def test_config_route_is_the_initial_route():
    """fresh_state(config) is random_state with the config's particles and generator."""
    text = CONFIG.format(eta=0.2).replace("particles = 20", "particles = 64")
    state = fresh_state(parse_config(text))
    direct = random_state(64, 0.2, 3, 1.0, radii=0.5, masses=1.0, rng=np.random.default_rng(3))
    for name in ("positions", "velocities", "radii", "masses", "box"):
        np.testing.assert_array_equal(getattr(state, name), getattr(direct, name))
    assert state.array("species").dtype == np.int32 and not state.array("species").any()


def test_mean_particle_mass_from_density():
    text = CONFIG.format(eta=0.2).replace("[collision]", "[particles]\ndiameter = 2.0\ndensity = 3.0\n\n[collision]")
    sigma, mass = mean_particle(parse_config(text))
    assert sigma == 2.0 and mass == pytest.approx(3.0 * math.pi * 8.0 / 6.0, rel=1e-15)
