"""The numbers the run summary and advise show for a vibrated scene, against hand
computation from the config: Gamma = A omega^2 / g, the plate velocity, the bouncing ball's
threshold, the dilute bed's leading order (3D: T = 2 sqrt(2) m <U^2> / (pi (1 - e^2) sigma^2
N_A)), and the Zeno-trap warning only where a grain can come to rest on a wall."""

import math
from pathlib import Path

import pytest

from granulargas.io.config import load_config
from granulargas.run.vibrated import is_vibrated, scene, scene_lines

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


def test_the_3d_bed_numbers_follow_from_the_config():
    cfg = load_config(CONFIGS / "vibrated_bed_3d.toml")
    sc = scene(cfg)
    (floor,) = sc["walls"]
    omega = 2 * math.pi * 3.183
    assert floor["speed"] == pytest.approx(0.05 * omega)
    assert floor["gamma"] == pytest.approx(0.05 * omega**2 / 1.0)
    assert floor["gamma_1"] == 0.0  # an elastic plate (wall_restitution = 1): any Gamma
    u2 = (0.05 * omega) ** 2 / 2
    side = (1000 * math.pi / 6 / 0.005) ** (1 / 3)
    column = 1000 / side**2
    assert floor["bed"]["temperature"] == pytest.approx(2 * math.sqrt(2) * u2 / (math.pi * (1 - 0.81) * column),
                                                        rel=1e-12)
    assert not sc["zeno"]  # elastic_below is set


def test_zeno_warning_needs_gravity_across_a_wall_and_no_restitution_floor(tmp_path):
    path = CONFIGS / "vibrated_bed_2d.toml"
    bare = tmp_path / "bare.toml"
    bare.write_text("".join(ln for ln in path.read_text().splitlines(keepends=True)
                            if not ln.startswith("elastic_below")))
    warned = [ln for ln in scene_lines(load_config(bare)) if ln.startswith("warning:")]
    assert len(warned) == 1 and "elastic_below" in warned[0]
    assert not [ln for ln in scene_lines(load_config(path)) if ln.startswith("warning:")]
    # gravity along the periodic axis only: the gas falls freely, nothing comes to rest
    free = load_config(bare, {"gravity.acceleration": [-1.0, 0.0]})
    lines = scene_lines(free)
    assert not [ln for ln in lines if ln.startswith("warning:")]
    assert any("falls freely" in ln for ln in lines)


def test_a_cooling_config_is_no_vibrated_scene():
    cfg = load_config(CONFIGS / "haff_3d.toml")
    assert not is_vibrated(cfg) and scene(cfg) == {} and scene_lines(cfg) == []
