"""Analytic two-sphere cases: head-on, grazing, miss, across the periodic boundary."""

import math

import numpy as np
import pytest

from granulargas.engine import CollisionRule

from tests.engine.factories import two_spheres


@pytest.mark.parametrize("d", [2, 3])
def test_head_on_elastic_swaps_velocities(d):
    p1 = [1.0] + [2.5] * (d - 1)
    p2 = [3.0] + [2.5] * (d - 1)
    sim = two_spheres(p1, p2, [0.5] + [0] * (d - 1), [-0.25] + [0] * (d - 1), box=6.0)
    sim.run(np.inf, max_collisions=1)
    # gap 2 - 1 = 1 closed at relative speed 0.75
    assert sim.time == pytest.approx(1.0 / 0.75, rel=1e-14)
    np.testing.assert_allclose(sim.velocities[:, 0], [-0.25, 0.5], rtol=1e-14)
    x = sim.positions[:, 0]
    assert x[1] - x[0] == pytest.approx(1.0, rel=1e-13)


def test_head_on_unequal_masses_and_radii_constant_eps():
    eps = 0.6
    m1, m2 = 1.0, 3.0
    sim = two_spheres([1.0, 3, 3], [4.0, 3, 3], [1.0, 0, 0], [0.0, 0, 0], box=8.0, radii=(0.5, 1.0),
                      masses=(m1, m2), rule=CollisionRule.constant(eps))
    sim.run(np.inf, max_collisions=1)
    assert sim.time == pytest.approx(1.5, rel=1e-14)  # gap 3 - 1.5 at speed 1
    v = sim.velocities[:, 0]
    # 1D inelastic collision: v1' = (m1 v1 - eps m2 v1)/(m1+m2), v2' = m1 (1+eps) v1/(m1+m2)
    assert v[0] == pytest.approx((m1 - eps * m2) / (m1 + m2), rel=1e-13)
    assert v[1] == pytest.approx(m1 * (1 + eps) / (m1 + m2), rel=1e-13)
    loss = 0.5 * (1 - eps**2) * (m1 * m2 / (m1 + m2)) * 1.0**2
    assert sim.dissipated_energy == pytest.approx(loss, rel=1e-13)
    assert 0.5 * m1 - sim.kinetic_energy == pytest.approx(loss, rel=1e-12)


@pytest.mark.parametrize("offset, hits", [(0.999, True), (1.001, False)])
def test_grazing_hit_and_miss(offset, hits):
    """Impact parameter just below / above the contact distance 1."""
    sim = two_spheres([1.0, 2.0, 2.5], [3.0, 2.0 + offset, 2.5], [1.0, 0, 0], [0.0, 0, 0], box=8.0)
    sim.run(3.0)
    assert sim.collisions == (1 if hits else 0)
    if hits:
        # contact when (x2 - x1)^2 + b^2 = 1: x2 - x1 = sqrt(1 - b^2), time = 2 - sqrt(1 - b^2)
        sim2 = two_spheres([1.0, 2.0, 2.5], [3.0, 2.0 + offset, 2.5], [1.0, 0, 0], [0.0, 0, 0], box=8.0)
        sim2.run(np.inf, max_collisions=1)
        assert sim2.time == pytest.approx(2.0 - math.sqrt(1 - offset**2), rel=1e-12)
        v = sim2.velocities
        # nearly tangential: the struck sphere moves along the line of centres (0.0447, 0.999)
        n = np.array([math.sqrt(1 - offset**2), offset, 0.0])
        np.testing.assert_allclose(v[1], n * n[0], atol=1e-12)
        np.testing.assert_allclose(v[0] + v[1], [1.0, 0, 0], atol=1e-14)
    else:
        np.testing.assert_array_equal(sim.velocities, [[1.0, 0, 0], [0, 0, 0]])


def test_parallel_and_receding_pairs_never_collide():
    sim = two_spheres([1.0, 2.0, 2.0], [3.0, 2.0, 2.0], [-1.0, 0.3, 0], [1.0, 0.3, 0], box=7.0)
    sim.run(1.2)  # they recede; after ~1.25 they would meet through the boundary
    assert sim.collisions == 0


@pytest.mark.parametrize("d", [2, 3])
def test_collision_across_periodic_boundary(d):
    box = 6.0
    rest = [3.0] * (d - 1)
    # 0.3 and 5.7: nearest-image distance 0.6 < ... start apart by 1.6 through the boundary
    sim = two_spheres([0.8] + rest, [5.2] + rest, [-0.5] + [0] * (d - 1), [0.5] + [0] * (d - 1),
                      box=box)
    sim.run(np.inf, max_collisions=1)
    assert sim.time == pytest.approx((1.6 - 1.0) / 1.0, rel=1e-13)
    np.testing.assert_allclose(sim.velocities[:, 0], [0.5, -0.5], rtol=1e-14)
    pos = sim.positions[:, 0]
    assert pos[0] == pytest.approx(0.5, rel=1e-13) and pos[1] == pytest.approx(5.5, rel=1e-13)
    # after separating they meet again the other way round the box: 6 - 1 - 1 = 4 at speed 1
    sim.run(np.inf, max_collisions=1)
    assert sim.time == pytest.approx(0.6 + 4.0, rel=1e-13)


def test_images_track_unwrapped_motion():
    # z differs by 2.5 = L/2 at all times: the pair never meets
    sim = two_spheres([1.0, 1.0, 1.0], [4.0, 4.0, 3.5], [2.5, -1.25, 0.0], [-2.5, 1.25, 0.0], box=5.0)
    sim.run(4.0)
    assert sim.collisions == 0
    np.testing.assert_allclose(sim.unwrapped_positions, [[11.0, -4.0, 1.0], [-6.0, 9.0, 3.5]],
                               rtol=1e-13)
    assert np.all(sim.positions >= 0) and np.all(sim.positions < 5.0)


def test_overlapping_approaching_pair_collides_at_once():
    sim = two_spheres([1.0, 2, 2], [1.0 + 1.0 - 1e-10, 2, 2], [0.1, 0, 0], [-0.1, 0, 0], box=6.0)
    sim.run(np.inf, max_collisions=1)
    assert sim.time == 0.0
    np.testing.assert_allclose(sim.velocities[:, 0], [-0.1, 0.1], rtol=1e-14)


def test_overlapping_receding_pair_is_left_alone():
    sim = two_spheres([1.0, 2, 2], [1.0 + 1.0 - 1e-10, 2, 2], [-0.1, 0, 0], [0.1, 0, 0], box=6.0)
    sim.run(2.0)  # next meeting across the boundary: gap 6 - 2 = 4 at speed 0.2 -> t = 20
    assert sim.collisions == 0


@pytest.mark.parametrize("d", [2, 3])
def test_small_box_keeps_three_cells_per_side(d):
    """A shell cut to fit three cells per side (box 10, diameters ~0.99): L / cut must not round
    to just below 3, which would leave two cells per side and a pair unseen (the engine once
    found this head-on collision only after thousands of time units, through the images)."""
    ri, rj, g, theta = 0.498126803435622, 0.49335244643445886, 0.4519051153908879, 0.5055283632726897
    n = np.array([math.sin(theta), math.cos(theta)] + [0.0] * (d - 2))
    centre = np.full(d, 5.0)
    rij = (ri + rj + 0.1) * n
    sim = two_spheres(centre + 0.5 * rij, centre - 0.5 * rij, -0.5 * g * n, 0.5 * g * n, box=10.0,
                      radii=(ri, rj), masses=(1.0001, 7.3))
    assert sim.shell < sim.box.min() / 3.0 - 2 * ri
    sim.run(np.inf, max_collisions=1)
    assert sim.time == pytest.approx(0.1 / g, rel=1e-12)
