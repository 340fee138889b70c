"""Lees-Edwards boundaries: the engine against the naive reference loop with sheared images,
exact balances, restarts and the unsheared loop left alone."""

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation
from granulargas.engine.shear import Shear
from granulargas.errors import ConfigError
from granulargas.initial import random_state
from granulargas.state import State

from tests.engine.reference import (
    le_offset,
    next_collision,
    next_collision_le,
    run_reference,
    run_reference_le,
)

LE3 = ("periodic", "lees-edwards", "periodic")


def sheared(n, packing, dim, rate, seed=3, mode="lists", rule=None, temperature=1.0, walls=False, **kw):
    bnd = LE3[:dim] if not walls else ("periodic", "lees-edwards", "wall")
    st = random_state(n, packing, dim, seed=seed, boundary=bnd, shear=rate, temperature=temperature)
    return Simulation(st, rule or CollisionRule.elastic(), shear=Shear(rate), neighbours=mode, **kw)


def min_distance(sim):
    """Smallest centre distance over all pairs and sheared images, over the contact distance."""
    pos, box, rate = sim.positions, sim.box, sim.shear.rate
    d = pos.shape[1]
    dl = le_offset(box, rate, sim.time)
    iu, ju = np.triu_indices(len(pos), 1)
    best = np.inf
    for ky in (-1, 0, 1):
        dr = pos[iu] - pos[ju]
        dr[:, 1] -= ky * box[1]
        dr[:, 0] -= ky * dl
        dr[:, 0] -= box[0] * np.round(dr[:, 0] / box[0])
        if d == 3 and sim.boundary[2] == "periodic":
            dr[:, 2] -= box[2] * np.round(dr[:, 2] / box[2])
        r = np.linalg.norm(dr, axis=1) / (sim.radii[iu] + sim.radii[ju])
        best = min(best, float(r.min()))
    return best


# ------------------------------------------------------------------ the reference itself
def test_reference_le_two_spheres_through_the_moving_image():
    """Sphere B at rest near y = 0; its image one box up slides at a L_y along x and hits
    sphere A (at rest near y = L_y) when their x distance is sqrt(1 - 0.5^2): a closed form."""
    box = np.array([6.0, 6.0, 6.0])
    a = 0.1
    pos = np.array([[3.0, 5.7, 3.0], [1.0, 0.2, 3.0]])  # image of B at y = 6.2: dy = 0.5
    vel = np.zeros((2, 3))
    dt, i, j = next_collision_le(pos, vel, np.full(2, 0.5), box, a, 0.0)
    assert (i, j) == (0, 1)
    assert dt == pytest.approx((2.0 - np.sqrt(0.75)) / (a * box[1]), rel=1e-12)
    # the same collision seen from a later time, when the image has slid further
    t1 = 0.5
    dt1, _, _ = next_collision_le(pos, vel, np.full(2, 0.5), box, a, t1)
    assert dt1 == pytest.approx(dt - t1, rel=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_reference_le_without_shear_is_the_periodic_reference(dim):
    st = random_state(20, 0.3, dim, seed=4)
    ref, p1, v1 = run_reference(st.positions, st.velocities, st.radii, st.masses, st.box, 25)
    le, p2, v2 = run_reference_le(st.positions, st.velocities, st.radii, st.masses, st.box, 0.0, 25)
    assert [(i, j) for _, i, j in ref] == [(i, j) for _, i, j in le]
    np.testing.assert_allclose([t for t, _, _ in le], [t for t, _, _ in ref], rtol=1e-12)
    np.testing.assert_allclose(v2, v1, rtol=1e-10, atol=1e-12)


def test_reference_le_streaming_keeps_the_unfolded_trajectory():
    """A particle that leaves through y = L_y re-enters with x - a L_y t and v_x - a L_y: its
    position relative to the image it left from moves on."""
    from tests.engine.reference import stream_le

    box = np.array([5.0, 5.0])
    a = 0.3
    pos = np.array([[1.0, 4.9]])
    vel = np.array([[0.2, 1.0]])
    stream_le(pos, vel, box, a, 2.0, 0.5)
    # unfolded: x = 1.1, y = 5.4 at t = 2.5; the image one box down is at x - a L_y t
    assert pos[0, 1] == pytest.approx(0.4)
    assert pos[0, 0] == pytest.approx((1.1 - a * box[1] * 2.5) % box[0])
    assert vel[0, 0] == pytest.approx(0.2 - a * box[1])


# ------------------------------------------------------------------ engine against reference
CASES = [
    dict(n=40, packing=0.2, dim=3, rate=0.5),
    dict(n=40, packing=0.2, dim=3, rate=3.0),
    dict(n=40, packing=0.35, dim=2, rate=2.0),
    dict(n=150, packing=0.04, dim=3, rate=2.0),
    dict(n=120, packing=0.05, dim=2, rate=1.0),
]


@pytest.mark.parametrize("mode", ["lists", "cells"])
@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c['dim']}d-{c['packing']}-a{c['rate']}")
def test_next_collision_matches_reference_every_step(case, mode):
    """From the engine's synchronised state the reference (all pairs, all sheared images)
    predicts the engine's next collision, pair and time, collision after collision; first
    after a run through several slides of the rows (cell mode) and list expiries."""
    sim = sheared(case["n"], case["packing"], case["dim"], case["rate"], mode=mode,
                  rule=CollisionRule.constant(0.9))
    sim.run(3.0 / case["rate"])
    for _ in range(120):
        dt, i, j = next_collision_le(sim.positions, sim.velocities, sim.radii, sim.box, case["rate"], sim.time)
        t0, v0 = sim.time, sim.velocities
        sim.run(np.inf, max_collisions=1)
        changed = np.flatnonzero(np.any(sim.velocities != v0, axis=1))
        assert {i, j} <= set(changed.tolist())
        assert sim.time - t0 == pytest.approx(dt, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("mode", ["lists", "cells"])
@pytest.mark.parametrize("dim", [2, 3])
def test_free_running_sequence_matches_reference(mode, dim):
    """Engine and reference run independently from one state: the same 30 collisions."""
    rate = 1.5
    sim = sheared(40, 0.2, dim, rate, mode=mode, seed=7)
    ref, _, vel = run_reference_le(sim.positions, sim.velocities, sim.radii, sim.masses, sim.box, rate, 30)
    for t, i, j in ref:
        v0 = sim.velocities
        sim.run(np.inf, max_collisions=1)
        changed = np.flatnonzero(np.any(sim.velocities != v0, axis=1))
        assert {i, j} <= set(changed.tolist())
        assert sim.time == pytest.approx(t, rel=1e-8)
    # particles wrapped by the engine and the reference carry the same velocities
    np.testing.assert_allclose(sim.velocities, vel, rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("mode", ["lists", "cells"])
@pytest.mark.parametrize("dim", [2, 3])
def test_no_overlap_after_a_long_sheared_run(mode, dim):
    """A missed collision through a sliding boundary would let spheres pass through each
    other: after some 20-60 collisions per particle (two dozen slides) no pair overlaps."""
    sim = sheared(600, 0.05, dim, 1.0, mode=mode, rule=CollisionRule.constant(0.8), seed=5)
    for _ in range(4):
        sim.run(sim.time + 6.0)
        assert min_distance(sim) > 1.0 - 1e-9
    assert sim.collisions > 15 * sim.n


# ------------------------------------------------------------------ exact balances
@pytest.mark.parametrize("mode", ["lists", "cells"])
@pytest.mark.parametrize("dim", [2, 3])
def test_viscous_heating_balances_loss_and_peculiar_energy_exactly(mode, dim):
    """Over any interval, -a P_xy V dt (kinetic integral plus collisional transfer, through
    the sheared images) = dissipated energy + change of the peculiar kinetic energy, to
    round-off: an exact balance of the dynamics, which a wrong image shift, velocity
    shift or stress sum breaks."""
    rate = 1.0
    sim = sheared(400, 0.1, dim, rate, mode=mode, rule=CollisionRule.constant(0.8), seed=2)
    vol = float(np.prod(sim.box))
    sim.pressure_windows()
    for _ in range(3):
        k0, d0, t0 = sim.kinetic_energy, sim.dissipated_energy, sim.time
        sim.run(t0 + 1.5)
        _, p = sim.pressure_windows()
        heat = -rate * p[0, 1] * vol * (sim.time - t0)
        assert heat == pytest.approx(sim.dissipated_energy - d0 + sim.kinetic_energy - k0, rel=1e-11)


def test_thermostat_holds_the_temperature_and_takes_the_heat():
    rate, temp = 0.5, 1.0
    st = random_state(300, 0.1, 3, seed=1, boundary=LE3, shear=rate)
    sim = Simulation(st, CollisionRule.elastic(), shear=Shear(rate, temperature=temp, interval=0.05))
    vol = float(np.prod(sim.box))
    sim.run(2.0)
    sim.pressure_windows()
    k0, i0, t0 = sim.kinetic_energy, sim.injected_energy, sim.time
    sim.run(6.0)
    _, p = sim.pressure_windows()
    assert sim.temperature == pytest.approx(temp, rel=0.05)
    # elastic: the heat the shear puts in is what the rescalings take out
    heat = -rate * p[0, 1] * vol * (sim.time - t0)
    assert heat > 0
    assert -(sim.injected_energy - i0) == pytest.approx(heat - (sim.kinetic_energy - k0), rel=1e-9)


# ------------------------------------------------------------------ restarts and the state
@pytest.mark.parametrize("mode", ["lists", "cells"])
def test_restart_from_the_state_is_bit_identical(mode):
    """run(t); synchronise; run(2t) == Simulation(state at t); run(2t)."""
    rate = 1.2
    a = sheared(200, 0.08, 3, rate, mode=mode, rule=CollisionRule.constant(0.85), seed=9)
    b = sheared(200, 0.08, 3, rate, mode=mode, rule=CollisionRule.constant(0.85), seed=9)
    a.run(2.0)
    a.synchronise()  # what writing a frame does
    a.run(4.0)
    b.run(2.0)
    c = Simulation(b.state, CollisionRule.constant(0.85), shear=Shear(rate), neighbours=mode)
    c.run(4.0)
    np.testing.assert_array_equal(a.positions, c.positions)
    np.testing.assert_array_equal(a.velocities, c.velocities)
    np.testing.assert_array_equal(a.images, c.images)
    assert a.collisions == c.collisions


def test_unwrapped_positions_are_continuous_through_the_sheared_boundary():
    rate = 2.0
    sim = sheared(60, 0.1, 2, rate, seed=4)
    u0, t0 = sim.unwrapped_positions, sim.time
    v0 = sim.velocities
    sim.run(1e-3)  # short: few collisions, most particles fly freely
    moved = sim.unwrapped_positions - u0
    free = np.all(sim.velocities == v0, axis=1) | (np.abs(sim.velocities - v0).max(axis=1) == rate * sim.box[1])
    np.testing.assert_allclose(moved[free], (v0 * (sim.time - t0))[free], atol=1e-9)


def test_walls_on_z_with_shear():
    rate = 1.0
    sim = sheared(300, 0.1, 3, rate, walls=True, rule=CollisionRule.constant(0.9), seed=6)
    sim.run(5.0)
    assert sim.wall_collisions > 0
    pos = sim.positions
    assert np.all(pos[:, 2] >= sim.radii - 1e-9) and np.all(pos[:, 2] <= sim.box[2] - sim.radii + 1e-9)
    assert min_distance(sim) > 1.0 - 1e-9


# ------------------------------------------------------------------ the unsheared loop
@pytest.mark.parametrize("mode", ["lists", "cells"])
def test_stress_leaves_the_trajectory_alone_and_its_trace_is_the_pressure(mode):
    st = random_state(300, 0.15, 3, seed=1)
    plain = Simulation(st, CollisionRule.constant(0.9), neighbours=mode)
    stressed = Simulation(st, CollisionRule.constant(0.9), neighbours=mode, stress=True)
    plain.run(2.0)
    stressed.run(2.0)
    np.testing.assert_array_equal(plain.positions, stressed.positions)
    np.testing.assert_array_equal(plain.velocities, stressed.velocities)
    p, tensor = stressed.pressure_windows()
    assert p == plain.pressure_window()
    assert np.trace(tensor) / 3 == pytest.approx(p, rel=1e-10)
    np.testing.assert_allclose(tensor, tensor.T)


# ------------------------------------------------------------------ bad input
def test_bad_boundaries_under_shear():
    st = random_state(20, 0.1, 3, seed=1)
    with pytest.raises(ConfigError, match="needs a shear"):
        Simulation(st.replace(boundary=LE3), CollisionRule.elastic())
    with pytest.raises(ConfigError, match="lees-edwards"):
        Simulation(st, CollisionRule.elastic(), shear=Shear(1.0))
    with pytest.raises(ConfigError, match="x must be periodic"):
        Simulation(st.replace(boundary=("wall", "lees-edwards", "periodic")), CollisionRule.elastic(),
                   shear=Shear(1.0))
    with pytest.raises(ConfigError):
        Shear(-1.0)
    with pytest.raises(ConfigError):
        Shear(1.0, temperature=1.0)


@pytest.mark.parametrize("nx", [3, 4, 5, 8, 13])
def test_y_crossing_scans_every_column_that_becomes_adjacent(nx):
    """A crossing of a y face keeps the stored best pair and scans the columns of
    engine._shear._y_layer only. Every column of the new neighbourhood (3 of the own row, 4 of
    each adjacent row's window) that was not in the old one must be among them: for every
    column, slide offset m and direction, and for the landing column expected from the
    geometry (cx - m - 1 or cx - m up, cx + m or cx + m + 1 down) as well as one beyond on
    either side (round-off at a face). In the expected case the scan is the row ahead and one
    column of the row left behind, not both windows."""
    from granulargas.engine._shear import _y_layer

    def run(c0, n):
        return {(c0 + u) % nx for u in range(max(n, 0))}

    for o in (1, -1):
        for m in range(nx):
            for cx in range(nx):
                expected = (cx - m - 1, cx - m) if o > 0 else (cx + m, cx + m + 1)
                for landed in range(expected[0] - 1, expected[1] + 2):
                    cxn = landed % nx
                    own0, own_n, back0, back_n, ahead0 = _y_layer(cx, cxn, o, m, nx)
                    old_entered = run(cx - 2 - m, 4) if o > 0 else run(cx - 1 + m, 4)  # old window of the row entered
                    old_own = run(cx - 1, 3)
                    new_back = run(cxn - 1 + m, 4) if o > 0 else run(cxn - 2 - m, 4)
                    new_ahead = run(cxn - 2 - m, 4) if o > 0 else run(cxn - 1 + m, 4)
                    assert run(cxn - 1, 3) - old_entered <= run(own0, own_n)
                    assert new_back - old_own <= run(back0, back_n)
                    assert new_ahead <= run(ahead0, 4)
                    if landed in expected and nx >= 8:
                        assert own_n <= 0 and back_n == 1


def listed_by_definition(i, centre, radii, shell, sh, t, period_z):
    """The j that a list build of i at t must list (eq. 3 of engine._shear), from the stored
    centres by brute force: all particles, each through the rows r_i - 1, r_i, r_i + 1 of the
    box and its sheared images, the x separation in the frame of j's row shortened by up to
    D on the side the rows' sliding closes. Returns (surely listed, surely not listed), the
    pairs within 1e-9 of the cut-off in neither."""
    c = centre.astype(np.float64)
    rows = np.minimum((c[:, 1] * (sh.ny / sh.ly)).astype(int), sh.ny - 1)
    r = rows[i]

    def offset(rho):  # s_rho(t), eq. 2
        return (sh.rate * ((rho + 0.5) * sh.wy - 0.5 * sh.ly) * t) % sh.lx

    xlab = c[i, 0] + offset(r)
    best = np.full(len(c), np.inf)
    for o in (-1, 0, 1):
        rho = r + o
        mine = rows == rho % sh.ny
        dx = xlab - offset(rho) - c[:, 0]
        dx -= sh.lx * np.round(dx / sh.lx)
        u = dx if o >= 0 else -dx
        dx = u - np.clip(u, 0.0, sh.margin if o != 0 else 0.0)
        dy = c[i, 1] - sh.ly * (rho // sh.ny) - c[:, 1]
        dz = c[i, 2] - c[:, 2]
        if np.isfinite(period_z):
            dz -= period_z * np.round(dz / period_z)
        d2 = dx * dx + dy * dy + dz * dz
        best = np.where(mine, np.minimum(best, d2), best)
    cut = radii[i] + radii + shell
    best[i] = np.inf
    return np.flatnonzero(best < (cut * (1 - 1e-9)) ** 2), np.flatnonzero(best >= (cut * (1 + 1e-9)) ** 2)


@pytest.mark.parametrize("dim,n,packing,polydisperse,walls", [
    (3, 1500, 0.15, False, False), (3, 600, 0.1, True, False), (3, 1000, 0.2, False, True),
    (2, 800, 0.3, True, False), (3, 60, 0.2, False, False), (2, 30, 0.2, False, False)])
def test_list_rebuild_lists_what_the_sliding_margin_defines(dim, n, packing, polydisperse, walls):
    """A list rebuild (engine._shear.rebuild_list_le: the cells in reach of the slid cut-off,
    the distance tests in the rows' frames) lists exactly the particles whose stored centres
    come within R_i + R_j + shell of i's new centre while the rows slide by the margin D,
    counted by brute force over all particles and images; at several times (slide offsets),
    for every particle, in grids of 3 to 15 columns."""
    from tests.engine.kernels import rebuild_list_le_now

    bnd = ("periodic", "lees-edwards", "wall" if walls else "periodic")[:dim]
    st = random_state(n, packing, dim, seed=11, boundary=bnd, shear=1.0)
    if polydisperse:
        st = st.replace(radii=np.random.default_rng(2).uniform(0.3, 0.5, n))
    checked = 0
    for span in (0.7, 1.9, 4.3):
        sim = Simulation(st, CollisionRule.constant(0.9), shear=Shear(1.0), neighbours="lists")
        sim.run(span)
        e, prm = sim._engine, sim._params()
        sh = prm.space.shear
        radii = e.particles.rec[:, 7]
        for i in range(n):
            st_ = rebuild_list_le_now(i, sim.time, e.particles.rec, e.particles.img, e.lists, e.cells, prm.space,
                                      prm.flight, prm.rmax, prm.shell, sh)
            if st_ != 0:  # a full list or cell: the engine widens and repeats; not this test's concern
                continue
            inside, outside = listed_by_definition(i, e.lists.centre, radii, prm.shell, sh, sim.time,
                                                   prm.space.period[2])
            got = set(e.lists.nbl[i, :e.lists.nbn[i]].tolist())
            assert set(inside.tolist()) <= got
            assert not got & set(outside.tolist())
            checked += len(inside)
    assert checked > 3 * n


@pytest.mark.parametrize("dim,packing", [(3, 0.1), (3, 0.3), (2, 0.2)])
def test_sheared_lists_are_as_long_as_the_periodic_ones(dim, packing):
    """The default shell of a sheared gas (engine.simulation.sheared_shell) counts the centres
    that the sliding margin lists, so that its lists hold as many centres as the periodic
    box's at its default shell; with the periodic shell they hold a fifth more."""
    n = 3000 if dim == 3 else 2000
    periodic = Simulation(random_state(n, packing, dim, seed=5), CollisionRule.elastic(), neighbours="lists")
    own = sheared(n, packing, dim, 0.5, seed=5)
    wide = sheared(n, packing, dim, 0.5, seed=5, shell=periodic.shell)
    for sim in (periodic, own, wide):
        sim.run(np.inf, max_collisions=n)
    lp, lo, lw = (float(sim._engine.lists.nbn.mean()) for sim in (periodic, own, wide))
    assert own.shell < periodic.shell and wide.shell == periodic.shell
    assert abs(lo / lp - 1.0) < 0.05, (lo, lp)
    assert lw / lp > 1.1, (lw, lp)


@pytest.mark.parametrize("mode", ["lists", "cells"])
@pytest.mark.parametrize("dim", [2, 3])
def test_two_spheres_at_rest_in_sliding_rows_collide(mode, dim):
    """Each sphere moves with the streaming velocity of its own row of cells, so neither ever
    leaves its list shell or crosses a cell face; only the rows' sliding brings them
    together (the list expiry's budget, eq. (3) of engine._shear, and the slides). They
    start out of each other's reach and collide when their x distance is sqrt(1 - dy^2)."""
    rate, box = 0.5, 10.0
    ncell = 3  # both modes: 3 cells per side of 10/3 (list cut-off 1 + 2.33)
    wy = box / ncell
    y = np.array([2.8, 3.6])
    rows = np.floor(y / wy)
    u = rate * ((rows + 0.5) * wy - box / 2)
    pos = np.array([[6.0, y[0], 5.0], [2.0, y[1], 5.0]])[:, :dim]
    vel = np.zeros((2, dim))
    vel[:, 0] = u
    st = State(pos, vel, 0.5, 1.0, box, boundary=LE3[:dim])
    sim = Simulation(st, CollisionRule.elastic(), shear=Shear(rate), neighbours=mode, shell=2.33)
    assert sim._space.ncell[1] == ncell
    sim.run(np.inf, max_collisions=1)
    dx0, dy = 4.0, 0.8
    assert sim.time == pytest.approx((dx0 - np.sqrt(1 - dy**2)) / abs(u[0] - u[1]), rel=1e-9)


def test_shear_refuses_rough_particles():
    from granulargas.engine import TangentialRule

    st = random_state(60, 0.1, 3, seed=1, boundary=LE3, shear=0.5)
    with pytest.raises(ConfigError, match="rough particles"):
        Simulation(st, CollisionRule.elastic(), shear=Shear(0.5), tangential=TangentialRule.constant(0.0))


def test_shear_refuses_gravity_and_moving_walls():
    from granulargas.engine.walls import Wall, Walls

    st = random_state(60, 0.1, 3, seed=1, boundary=LE3, shear=0.5)
    with pytest.raises(ConfigError, match="shear: gravity and thermal or vibrating walls"):
        Simulation(st, CollisionRule.elastic(), shear=Shear(0.5), gravity=(0.0, 0.0, -1.0))
    walled = ("periodic", "lees-edwards", "wall")
    st = random_state(60, 0.1, 3, seed=1, boundary=walled, shear=0.5)
    with pytest.raises(ConfigError, match="shear: gravity and thermal or vibrating walls"):
        Simulation(st, CollisionRule.elastic(), shear=Shear(0.5), walls=Walls(z_high=Wall.thermal(1.0)))
    # hard walls at rest on z stay available with shear
    Simulation(st, CollisionRule.elastic(), shear=Shear(0.5), walls=Walls(z_low=Wall.hard()))


def test_stress_refused_under_gravity():
    st = random_state(60, 0.1, 3, seed=1)
    with pytest.raises(ConfigError, match="stress: the pressure tensor under gravity"):
        Simulation(st, CollisionRule.elastic(), stress=True, gravity=(0.0, 0.0, -1.0))


@pytest.mark.parametrize("sheared", [False, True])
def test_stress_sums_from_python_are_the_kernels_bit_for_bit(sheared):
    """A build's kinetic stress sums come from numpy (``stress_sums_of``); the compiled loop's
    global events use the kernel ``stress_sums``: both must give the same bits."""
    from granulargas.engine import _shear

    rng = np.random.default_rng(3)
    n = 777
    rec = np.zeros((n, 8))
    rec[:, :3] = rng.uniform(0.0, 9.0, (n, 3))
    rec[:, 3:6] = rng.normal(0.0, 1.0, (n, 3))
    mass = rng.uniform(0.5, 2.0, n)
    sh = _shear.shear_geometry(0.4, np.array([9.0, 9.0, 9.0]), np.array([4, 4, 4]), n) if sheared else None
    kernel, numpy_sums = np.empty(6), np.empty(6)
    _shear.stress_sums(rec, mass, sh, kernel)
    _shear.stress_sums_of(rec, mass, sh, numpy_sums)
    assert np.array_equal(kernel, numpy_sums)
    assert np.allclose(numpy_sums[:3], [np.sum(mass * c * c) for c in
                                        ((rec[:, 3] - 0.4 * (rec[:, 1] - 13.5)) if sheared else rec[:, 3],
                                         rec[:, 4], rec[:, 5])])
