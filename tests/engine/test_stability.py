"""Engine stability at the extremes, through the public API only.

* temperatures falling by many decades: the dynamics of hard spheres with a
  constant eps has no velocity scale, so rescaling all velocities by 2^-k (exact
  in binary floating point) must give the same trajectory, bit for bit, with
  times scaled by 2^k; and a cooling run keeps Haff's rate per collision down
  to T ~ 1e-150;
* velocities whose squares leave float64 must stop the run with a clear error;
* beta -> 0 (damping 0 is elastic; tiny damping dissipates as kinetic theory says);
* beta >> 1 (eps -> 0: conservation laws still hold) and beyond the supported
  range (a clear error, not an extrapolation).
"""

import math

import numpy as np
import pytest

from granulargas import theory
from granulargas.contact import restitution_table
from granulargas.engine import CollisionRule, Simulation
from granulargas.initial import random_state
from granulargas.errors import SimulationError, TableRangeError
from granulargas.state import State


def state(n=200, packing=0.2, dimension=3, seed=3):
    return random_state(n=n, packing=packing, dimension=dimension, temperature=1.0, seed=seed)


def sim_from(st, rule, velocity_scale=1.0):
    return Simulation(st.replace(velocities=st.velocities * velocity_scale), rule)


@pytest.mark.parametrize("dimension", [2, 3])
@pytest.mark.parametrize("k", [-400, -200, 300])
def test_power_of_two_velocity_rescaling_is_exact(dimension, k):
    # T scales by 4^k: down to ~1e-241 (k = -400) and up to ~1e+180 (k = 300)
    st = state(dimension=dimension)
    scale = 2.0**k
    ref = sim_from(st, CollisionRule.constant(0.8, tc_time=1e-3))
    ref.run(until=4.0)
    sc = sim_from(st, CollisionRule.constant(0.8, tc_time=1e-3 / scale), scale)
    sc.run(until=4.0 / scale)
    assert sc.collisions == ref.collisions > 300
    assert np.array_equal(sc.positions, ref.positions)
    assert np.array_equal(sc.velocities, ref.velocities * scale)
    assert sc.temperature == ref.temperature * scale**2


def _cool(sim, n, stop_lnT, remove_drift):
    """Run chunks of 10 n collisions until ln T < stop_lnT; optionally restart each chunk
    in the centre-of-mass frame (a Galilean shift, through the public API)."""
    lnT, s, events = [], [], []
    while not lnT or lnT[-1] > stop_lnT:
        e0, c0 = sim.events, sim.collisions
        sim.run(until=math.inf, max_collisions=10 * n)
        lnT.append(math.log(sim.temperature))
        s.append(2.0 * sim.collisions / n)
        events.append((sim.events - e0) / (sim.collisions - c0))
        if remove_drift:
            sim.synchronise()
            v = sim.velocities
            v -= (sim.masses[:, None] * v).sum(axis=0) / sim.masses.sum()
            sim = Simulation(State(sim.positions, v, sim.radii, sim.masses, sim.box, time=sim.time,
                                   collisions=sim.collisions, images=sim.images, events=sim.events), sim.rule)
    return sim, np.array(lnT), np.array(s), np.array(events)


def cooling_state(n=300):
    return random_state(n=n, packing=0.05, dimension=3, temperature=1.0, seed=5)


def test_cooling_through_150_decades_keeps_haff_rate_per_collision():
    # constant eps in a small dilute box (below the instability length): per
    # collision per particle ln T drops by (1 - eps^2)(1 + 3 a2/16)/d, at any T
    eps, n = 0.5, 300
    st = cooling_state(n)
    assert float(st.box[0]) < theory.instability_length(eps, theory.number_density(0.05, 3), 3)
    sim = Simulation(st, CollisionRule.constant(eps))
    sim, lnT, s, events = _cool(sim, n, math.log(1e-150), remove_drift=True)
    slope_theory = -(1 - eps**2) * (1 + 3 * theory.sonine_a2(eps, 3) / 16) / 3
    early = np.polyfit(s[s < 0.3 * s[-1]], lnT[s < 0.3 * s[-1]], 1)[0]
    late = np.polyfit(s[s > 0.7 * s[-1]], lnT[s > 0.7 * s[-1]], 1)[0]
    assert early == pytest.approx(slope_theory, rel=0.05)
    assert late == pytest.approx(early, rel=0.05)  # nothing changes over 150 decades
    assert np.max(events) < 3 * np.median(events)  # the cost per collision stays flat
    assert np.isfinite(sim.positions).all()


@pytest.mark.parametrize("dimension, eps, stop", [(3, 0.5, 1e-45), (2, 0.5, 1e-45), (2, 0.3, 1e-45)])
def test_cooling_below_round_off_of_the_momentum_keeps_the_cost_per_collision(dimension, eps, stop):
    """No help from outside: the centre-of-mass velocity round-off leaves (~1e-16 of the
    initial thermal speed) would overtake the thermal speed below T/T0 ~ 1e-32 and then
    cost ever more list expiries per collision (x500 by 1e-40); the engine removes it
    (Simulation.run), so events per collision stay flat down to T/T0 = 1e-45."""
    n = 300
    st = random_state(n=n, packing=0.05, dimension=dimension, temperature=1.0, seed=5)
    sim = Simulation(st, CollisionRule.constant(eps))
    sim, lnT, s, events = _cool(sim, n, math.log(stop), remove_drift=False)
    assert lnT[-1] < math.log(stop)
    assert np.max(events) < 3 * np.median(events)
    assert np.max(events) < 25.0  # events per collision: ~8 (3D) to ~20 (2D) at this packing
    # the drift is gone, not merely small: |V| below round-off of the thermal speed
    v = sim.velocities
    vcm = (sim.masses[:, None] * v).sum(axis=0) / sim.masses.sum()
    assert np.linalg.norm(vcm) < 1e-4 * math.sqrt(sim.temperature)
    if float(st.box[0]) < theory.instability_length(eps, theory.number_density(0.05, dimension),
                                                     dimension):  # homogeneous: Haff per collision
        slope = np.polyfit(s, lnT, 1)[0]
        a2 = theory.sonine_a2(eps, dimension)
        assert slope == pytest.approx(-(1 - eps**2) * (1 + 3 * a2 / 16) / dimension, rel=0.05)


def test_velocity_underflow_is_a_clear_error():
    st = state()
    sim = sim_from(st, CollisionRule.elastic(), 1e-170)  # v^2 ~ 1e-340 underflows to 0
    with pytest.raises(SimulationError):
        sim.run(until=5e170, max_collisions=3000)


def test_velocity_overflow_is_a_clear_error():
    st = state()
    sim = sim_from(st, CollisionRule.elastic(), 1e160)  # v^2 ~ 1e320 overflows
    with pytest.raises(SimulationError):
        sim.run(until=5e-160, max_collisions=3000)


def test_zero_damping_is_elastic():
    st = state()
    table = restitution_table(1.0)
    sim = sim_from(st, CollisionRule.viscoelastic(prefactor=0.0, table=table))
    e0 = sim.kinetic_energy
    sim.run(until=math.inf, max_collisions=20_000)
    assert abs(sim.kinetic_energy / e0 - 1) < 1e-12
    assert abs(sim.dissipated_energy) < 1e-12 * e0


def test_tiny_damping_dissipates_as_kinetic_theory_says():
    # beta ~ 1e-4: d ln T / ds = -(1 - eps^2)_eff / d with (1 - eps^2)_eff = 2 C1 b Gamma(21/10) (4T)^(1/10)
    b, n = 1e-4, 500
    st = random_state(n=n, packing=0.1, dimension=3, temperature=1.0, seed=2)
    table = restitution_table(0.01)
    sim = Simulation(st, CollisionRule.viscoelastic(prefactor=b, table=table))
    sim.run(until=math.inf, max_collisions=100_000)
    s = 2.0 * sim.collisions / n
    measured = -math.log(sim.temperature) / s * 3
    expected = theory.effective_inelasticity(b, sim.temperature ** 0.5)  # T changes by < 1e-3 here
    assert measured == pytest.approx(expected, rel=0.03)


@pytest.mark.parametrize("dimension", [2, 3])
def test_large_damping_keeps_conservation_laws(dimension):
    # beta ~ 10..20: eps ~ 1e-4 (far outside the model's validity, warned by
    # granulargas.run.validity), yet the engine must stay consistent. In 2D some
    # states instead stop with "endless rapid re-collisions" (100 re-collisions
    # within 1e-10 collision times): 5 of seeds 0-39 of this call (seed 4 among
    # them); 3D: none. The seed picks a state that runs through.
    st = state(n=150, packing=0.15, dimension=dimension, seed=6)
    table = restitution_table(35.0)
    sim = sim_from(st, CollisionRule.viscoelastic(prefactor=10.0, table=table))
    e0, p0 = sim.kinetic_energy, sim.momentum
    energies = []
    for t in np.linspace(0.5, 20, 12):
        sim.run(until=t, max_collisions=20_000)
        energies.append(sim.kinetic_energy)
    assert np.all(np.diff(energies) <= 1e-12 * e0)
    assert energies[-1] < 0.5 * e0
    assert sim.kinetic_energy + sim.dissipated_energy == pytest.approx(e0, rel=1e-12)
    assert np.allclose(sim.momentum, p0, atol=1e-12 * math.sqrt(e0))


def test_beta_beyond_the_supported_range_is_a_clear_error(tmp_path, capsys):
    from granulargas.cli import main

    with pytest.raises(TableRangeError):
        restitution_table(300.0)
    cfg = tmp_path / "c.toml"
    cfg.write_text('[system]\nparticles = 200\n[collision]\nmodel = "viscoelastic"\ndamping = 100.0\n'
                   f'[run]\nend_time = 1.0\n[output]\nfile = "{tmp_path / "x.h5"}"\n')
    code = main(["run", str(cfg), "--quiet"])
    err = capsys.readouterr().err
    assert code != 0 and err.count("\n") == 1 and "beta" in err
    assert not (tmp_path / "x.h5").exists()
