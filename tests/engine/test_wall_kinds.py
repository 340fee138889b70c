"""Wall kinds: the vibrating wall's motion, its contact-time search against brute-force dense
sampling of the gap, the thermal wall's draws against the flux Maxwellian, and the collision
law's energy bookkeeping."""

import math

import numpy as np
import pytest
from scipy import stats

from granulargas.engine import _state, _walls
from tests.engine import kernels as K

WAVEFORMS = ["sine", "triangle", "biparabolic"]


def wave_np(waveform, tau, amp, nu, phase):
    """The wall's displacement at times tau, written independently of the engine."""
    th = 2.0 * np.pi * nu * tau + phase
    if waveform == "sine":
        return amp * np.sin(th)
    if waveform == "triangle":
        return amp * (2.0 / np.pi) * np.arcsin(np.sin(th))
    u = np.mod(th / (2.0 * np.pi), 1.0)
    arch = 16.0 * np.where(u < 0.5, u * (0.5 - u), -(u - 0.5) * (1.0 - u))
    return amp * arch


def spec_for(waveform, amp, nu, phase, axis=2):
    kind = np.zeros((3, 2))
    kind[axis] = _walls.VIBRATING
    wf = np.full((3, 2), _walls.WAVEFORMS[waveform])
    a = np.zeros((3, 2))
    a[axis] = amp
    return _state.wall_spec(kind=kind, waveform=wf, amplitude=a, frequency=np.full((3, 2), nu),
                            phase=np.full((3, 2), phase))


@pytest.mark.parametrize("waveform", WAVEFORMS)
def test_wave_matches_the_waveform_and_its_derivatives(waveform):
    amp, nu, phase = 0.3, 1.7, 0.4
    spec = spec_for(waveform, amp, nu, phase)
    tau = np.linspace(0.0, 3.0, 3001)[1:-1]
    got = np.array([K.wall_motion(spec, 2, 0, t) for t in tau])
    np.testing.assert_allclose(got[:, 0], wave_np(waveform, tau, amp, nu, phase), atol=1e-12)
    h = 1e-6
    fd = (wave_np(waveform, tau + h, amp, nu, phase) - wave_np(waveform, tau - h, amp, nu, phase)) / (2 * h)
    ok = np.abs(fd - got[:, 1]) < 1e-5 * amp * nu  # away from the triangle's turning points
    assert ok.mean() > 0.99
    if waveform != "triangle":
        fd2 = (np.array([K.wall_motion(spec, 2, 0, t + h)[1] for t in tau])
               - np.array([K.wall_motion(spec, 2, 0, t - h)[1] for t in tau])) / (2 * h)
        assert (np.abs(fd2 - got[:, 2]) < 1e-4 * amp * nu**2 * 40).mean() > 0.99
    # the bounds and the mean square velocity the theory uses
    assert np.max(np.abs(got[:, 1])) == pytest.approx(_walls.velocity_bound(waveform, amp, nu), rel=1e-3)
    assert np.max(np.abs(got[:, 2])) <= _walls.acceleration_bound(waveform, amp, nu) * (1 + 1e-12)
    one_period = np.linspace(0.0, 1.0 / nu, 200_001)[:-1]
    v = np.array([K.wall_motion(spec, 2, 0, t)[1] for t in one_period[::50]])
    assert np.mean(v**2) == pytest.approx(_walls.mean_square_velocity(waveform, amp, nu), rel=1e-3)


def gap_np(waveform, side, x, v, g, radius, box, t, s, amp, nu, phase):
    """Gap between a sphere and the vibrating wall (a, side) at t + s, by brute force."""
    z = x + v * s + 0.5 * g * s * s
    w = wave_np(waveform, t + s, amp, nu, phase)
    if side == 0:
        return z - radius - (amp + w)
    return (box - amp + w) - radius - z


def first_root_dense(f, horizon, n=400_001):
    s = np.linspace(0.0, horizon, n)
    y = f(s)
    bad = np.flatnonzero(y <= 0.0)
    if len(bad) == 0:
        return math.inf
    k = bad[0]
    if k == 0:
        return 0.0
    lo, hi = s[k - 1], s[k]
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if f(np.array([mid]))[0] > 0.0:
            lo = mid
        else:
            hi = mid
    return hi


@pytest.mark.parametrize("waveform", WAVEFORMS)
@pytest.mark.parametrize("side", [0, 1])
def test_contact_search_misses_no_root(waveform, side):
    """The search's root against the first sign change of the gap sampled every ~1e-4 plate
    periods over 20 periods: never later; earlier only at a true root the sampling stepped
    over (a contact shorter than the sampling step, where the gap is zero to round-off)."""
    rng = np.random.default_rng(10 + side + 2 * WAVEFORMS.index(waveform))
    box, radius = 6.0, 0.5
    found = 0
    for trial in range(150):
        amp = rng.uniform(0.05, 0.5)
        nu = rng.uniform(0.5, 3.0)
        phase = rng.uniform(0, 2 * np.pi)
        t = rng.uniform(0, 100.0)
        g = -rng.uniform(0.0, 3.0) if side == 0 else rng.uniform(0.0, 3.0)
        if trial % 5 == 0:
            g = 0.0  # microgravity: only the wall's motion brings the contact
        spec = spec_for(waveform, amp, nu, phase)
        # a sphere anywhere the wall leaves room for it now, moving either way
        wnow = wave_np(waveform, t, amp, nu, phase)
        low = (amp + wnow) + radius if side == 0 else radius
        high = box - radius if side == 0 else (box - amp + wnow) - radius
        x = rng.uniform(low, min(high, low + 3 * amp + 1.0)) if side == 0 else \
            rng.uniform(max(low, high - 3 * amp - 1.0), high)
        v = rng.normal() * rng.choice([0.1, 1.0, 3.0])
        rest = amp if side == 0 else box - amp
        horizon = 20.0 / nu
        s, again = K.contact_delay(x, v, g, radius, rest, side, t, horizon, spec, 2)
        assert not again
        ref = first_root_dense(lambda q: gap_np(waveform, side, x, v, g, radius, box, t, q, amp, nu, phase),
                               horizon)
        if math.isinf(ref):
            if math.isfinite(s):  # a root the sampling missed must be a root
                assert abs(gap_np(waveform, side, x, v, g, radius, box, t, s, amp, nu, phase)) < 1e-9
            continue
        found += 1
        assert s <= ref * (1 + 1e-9) + 1e-12, f"the search stepped over a root (trial {trial})"
        if s < ref * (1 - 1e-9) - 1e-12:
            assert abs(gap_np(waveform, side, x, v, g, radius, box, t, s, amp, nu, phase)) < 1e-9
        else:
            assert s == pytest.approx(ref, rel=1e-9, abs=1e-12)
    assert found > 100


def test_contact_search_finds_a_grazing_root_and_steps_over_a_touch():
    """A sphere resting on a sine plate that starts to decelerate faster than gravity takes off
    (touching without closing: no contact) and lands later; a sphere whose parabola just dips
    into the wall's reach without meeting it gets no contact."""
    amp, nu = 0.1, 1.0
    om = 2 * np.pi * nu
    spec = spec_for("sine", amp, nu, 0.0)
    g = -0.5 * amp * om**2  # Gamma = 2
    # at the top of the stroke the plate decelerates at A omega^2 > g: a sphere at rest on it
    # (same velocity, W' = 0) separates, and lands later
    t = 0.25 / nu
    x = amp + amp + 0.5 + 1e-12  # rest + W(t) + R, a hair above
    s, again = K.contact_delay(x, 0.0, g, 0.5, amp, 0, t, math.inf, spec, 2)
    ref = first_root_dense(lambda q: gap_np("sine", 0, x, 0.0, g, 0.5, 6.0, t, q, amp, nu, 0.0), 5.0)
    assert s > 1e-3 and s == pytest.approx(ref, rel=1e-8)
    # a sphere high above that turns round just inside the wall's reach, above the plate
    s, _ = K.contact_delay(2 * amp + 0.5 + 1e-3 + 0.05, 0.0, -1.0, 0.5, amp, 0, 0.75 / nu, 0.2, spec, 2)
    assert s == math.inf  # the plate is at its lowest: nothing within the horizon


def test_contact_search_stops_at_the_horizon_and_rechecks_after_many_steps():
    spec = spec_for("sine", 0.2, 1.0, 0.0)
    # falling from high up: the first root lies far beyond a short horizon
    s, again = K.contact_delay(5.0, 0.0, -1.0, 0.5, 0.2, 0, 0.0, 0.5, spec, 2)
    assert s == math.inf and not again
    # microgravity, moving away from the wall: never
    s, again = K.contact_delay(1.0, 0.5, 0.0, 0.5, 0.2, 0, 0.0, math.inf, spec, 2)
    assert s == math.inf


def test_thermal_draws_follow_the_wall_flux_maxwellian():
    n = 40_000
    temperature, mass = 2.5, 1.7
    scale = math.sqrt(temperature / mass)
    draws = np.array([K.thermal_velocity(np.uint64(99), k, scale) for k in range(n)])
    vn, t1, t2 = draws.T
    # flux Maxwellian of the normal speed: a Rayleigh distribution of scale sqrt(T/m)
    assert stats.kstest(vn, stats.rayleigh(scale=scale).cdf).pvalue > 1e-3
    for t in (t1, t2):
        assert stats.kstest(t, stats.norm(scale=scale).cdf).pvalue > 1e-3
    assert abs(np.corrcoef(t1, t2)[0, 1]) < 0.03
    # counter based: the draw of collision k does not depend on the others
    assert K.thermal_velocity(np.uint64(99), 12345, scale) == tuple(draws[12345])
    assert K.thermal_velocity(np.uint64(98), 12345, scale) != tuple(draws[12345])


def test_uniforms_agree_with_an_independent_splitmix64():
    """The thermal draws are SplitMix64 of counters under a key; a pure-Python SplitMix64
    reproduces them (so the reference loop needs no engine code for them)."""
    from tests.engine.reference import wall_uniforms

    for seed in (0, 7, 2**63 + 5):
        for k in (0, 1, 1000, 2**40):
            assert K.wall_uniforms(np.uint64(seed), k) == wall_uniforms(seed, k)


@pytest.mark.parametrize("side", [0, 1])
def test_moving_wall_collision_reverses_the_relative_velocity_and_books_the_energy(side):
    rng = np.random.default_rng(7)
    for _ in range(200):
        wv = rng.normal()
        u = abs(rng.normal()) * (-1 if side == 0 else 1)  # approaching
        vn = wv + u
        eps, m = rng.uniform(0.1, 1.0), rng.uniform(0.5, 2.0)
        v_new, loss, work, impulse = K.moving_wall_collision(vn, wv, eps, m, side)
        assert v_new - wv == pytest.approx(-eps * (vn - wv), rel=1e-12, abs=1e-14)
        assert loss == pytest.approx(0.5 * (1 - eps**2) * m * u * u, rel=1e-12)
        assert work - loss == pytest.approx(0.5 * m * (v_new**2 - vn**2), rel=1e-9, abs=1e-13)
        assert impulse == pytest.approx(m * abs(v_new - vn), rel=1e-12)
    # receding: nothing
    assert K.moving_wall_collision(1.0, 0.5, 0.8, 1.0, 0) == (1.0, 0.0, 0.0, 0.0)
