"""The oblique-contact table: accuracy against direct integration, head-on limit, range, cache, compiled lookup."""

import math

import numpy as np
import pytest

from granulargas.contact import duration, restitution
from granulargas.contact import oblique as ob
from granulargas.contact.oblique_lookup import (
    LOOKUP_BAD_INPUT,
    LOOKUP_BETA_RANGE,
    LOOKUP_DELTA_RANGE,
    LOOKUP_OK,
    oblique_lookup,
    resolve_collision,
)
from granulargas.contact.oblique_grid import BETA_MAX, oblique_table
from granulargas.errors import TableRangeError


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    """One small table per contact end (beta < 0.39, delta < 0.125), built without the cache."""
    return {end: oblique_table(0.3, 0.1, end=end, use_cache=False) for end in ob.ENDS}


def random_points(rng, n, beta_max, delta_max):
    """beta, c, delta spread over the table: uniform in sqrt(beta), in zeta (all angles), in delta,
    plus head-on (c = 0) and extreme grazing (c = 1e12) points."""
    beta = rng.uniform(0, math.sqrt(beta_max), n) ** 2
    c = ob.c_of_zeta(rng.uniform(0, 1, n))
    c[:10] = 0.0
    c[10:20] = 1e12
    delta = rng.uniform(0, delta_max, n)
    return beta, c, delta


@pytest.mark.parametrize("end", ob.ENDS)
def test_table_within_1e8_of_the_integration(tables, end):
    table = tables[end]
    rng = np.random.default_rng(7)
    beta, c, delta = random_points(rng, 3000, table.beta_limit, table.delta_limit)
    ref = ob.solve_many(beta, c, delta, end)
    eps, tau, m = table.lookup(beta, c, delta)
    assert np.max(np.abs(eps - ref[:, 0])) <= 1e-8
    assert np.max(np.abs(tau / ref[:, 1] - 1)) <= 1e-8
    assert np.max(np.abs(m / ref[:, 2] - 1)) <= 1e-8
    # what the engine uses: the turn of the normal, to 1e-8 rad
    rot_ref = np.sqrt(c * delta) * (ref[:, 1] + delta * ref[:, 2])
    rot = np.sqrt(c * delta) * (tau + delta * m)
    assert np.max(np.abs(rot - rot_ref)) <= 1e-8


@pytest.mark.parametrize("end", ob.ENDS)
def test_head_on_through_the_table_is_todays_contact(tables, end):
    table = tables[end]
    beta = np.linspace(0, 0.3, 31)
    for delta in (0.0, 0.05, 0.1):
        eps, tau, _ = table.lookup(beta, 0.0, delta)
        np.testing.assert_allclose(eps, restitution(beta, end=end), rtol=0, atol=1e-8)
        if end == "overlap":
            np.testing.assert_allclose(tau, duration(beta, end=end), rtol=1e-8)
        else:  # to the separation, tau_c + x_f / eps (the overlap left when the force vanished)
            rows = ob.solve_many(beta, 0.0, delta, end)
            np.testing.assert_allclose(rows[:, 3], duration(beta, end=end), rtol=1e-12)
            np.testing.assert_allclose(tau, rows[:, 3] + rows[:, 5] / rows[:, 4], rtol=1e-8)


@pytest.mark.parametrize("end", ob.ENDS)
def test_compiled_resolution_matches_the_outcome(tables, end):
    """resolve_collision (engine side) against frame_outcome of a direct integration, physical units."""
    table = tables[end]
    rng = np.random.default_rng(11)
    work, out = np.empty(3), np.empty(5)
    for _ in range(40):
        rho, A = 10 ** rng.uniform(2, 6), 10 ** rng.uniform(-4, -2)
        dist = rng.uniform(0.5, 2.0)
        g_n = 10 ** rng.uniform(-2, 0)
        g_t = g_n * math.tan(rng.uniform(0, math.pi / 2))
        beta, c, delta = (float(v) for v in ob.parameters(g_n, g_t, dist, rho, A))
        if not (beta < table.beta_limit and delta < table.delta_limit):
            continue
        status = resolve_collision(g_n, g_t, dist, 1.5 * A * rho ** 0.4, rho ** -0.4, table.inv_hs, table.inv_hd,
                                   table.coeffs, work, out)
        assert status == LOOKUP_OK
        s = ob.solve_oblique(beta, c, delta, end)
        ref = ob.frame_outcome(s.restitution, s.duration, s.turning, beta, c, delta, 0.0, g_n, g_t, dist)
        speed = math.hypot(g_n, g_t)
        assert out[0] == pytest.approx(ref.duration, rel=1e-8)
        np.testing.assert_allclose(out[1:3], ref.velocity, rtol=0, atol=2e-8 * speed)
        np.testing.assert_allclose(out[3:5], ref.position, rtol=0, atol=2e-8 * dist)
        # the Python outcome from the table says the same
        tab = table.outcome(g_n, g_t, dist, rho, A)
        np.testing.assert_allclose(tab.velocity, out[1:3], rtol=0, atol=1e-14 * speed)
        # kinetic energy of the relative motion only decreases, by the damping
        assert np.dot(out[1:3], out[1:3]) <= speed ** 2 * (1 + 1e-12)


def test_lookup_statuses(tables):
    t = tables["overlap"]
    out = np.empty(3)
    ok = oblique_lookup(0.1, 1.0, 0.05, t.inv_hs, t.inv_hd, t.coeffs, out)
    assert ok == LOOKUP_OK
    assert oblique_lookup(0.1, np.inf, 0.05, t.inv_hs, t.inv_hd, t.coeffs, out) == LOOKUP_OK
    assert out[0] == pytest.approx(1.0, abs=1e-8) and out[1] == 0.0 and out[2] == 0.0
    for beta in (t.beta_limit * (1 + 1e-9), 5.0, -1e-3, np.nan, np.inf):
        assert oblique_lookup(beta, 1.0, 0.05, t.inv_hs, t.inv_hd, t.coeffs, out) == LOOKUP_BETA_RANGE
    for delta in (t.delta_limit * (1 + 1e-9), -1e-9, np.nan):
        assert oblique_lookup(0.1, 1.0, delta, t.inv_hs, t.inv_hd, t.coeffs, out) == LOOKUP_DELTA_RANGE
    for c in (-1.0, np.nan):
        assert oblique_lookup(0.1, c, 0.05, t.inv_hs, t.inv_hd, t.coeffs, out) == LOOKUP_BAD_INPUT
    work, res = np.empty(3), np.empty(5)
    assert resolve_collision(0.0, 1.0, 1.0, 0.1, 0.01, t.inv_hs, t.inv_hd, t.coeffs, work, res) == LOOKUP_BAD_INPUT
    with pytest.raises(TableRangeError, match="outside the oblique-contact table"):
        t.lookup(1.0, 1.0, 0.05)


def test_range_requests(cache_dir):
    with pytest.raises(TableRangeError, match="well below ~3"):
        oblique_table(2 * BETA_MAX, 0.1)
    with pytest.raises(TableRangeError, match="half the contact distance"):
        oblique_table(0.1, 0.9)
    with pytest.raises(ValueError, match="end"):
        oblique_table(0.1, 0.1, end="never")


def test_cache_slices_extends_and_rebuilds(cache_dir):
    small = oblique_table(0.01, 0.05)
    assert small.coeffs.shape[:3] == (1, 24, 1)
    files = list(cache_dir.glob("oblique-overlap-*.npz"))
    assert len(files) == 1
    bigger = small.extended(0.03, 0.05)  # one more cell in sqrt(beta): only that one is computed
    assert bigger.coeffs.shape[:3] == (2, 24, 1)
    np.testing.assert_array_equal(bigger.coeffs[:1], small.coeffs)
    again = oblique_table(0.01, 0.05)  # a slice of the cached, larger table
    np.testing.assert_array_equal(again.coeffs, small.coeffs)
    assert small.extended(0.005, 0.01) is small
    fresh = oblique_table(0.03, 0.05, use_cache=False)
    np.testing.assert_array_equal(fresh.coeffs, bigger.coeffs)
    files[0].write_bytes(b"garbage")
    rebuilt = oblique_table(0.01, 0.05)
    np.testing.assert_array_equal(rebuilt.coeffs, small.coeffs)
    for k, v in rebuilt.parameters.items():
        assert isinstance(v, (int, float, str)), k


def test_coarse_grid_is_refused(cache_dir):
    with pytest.raises(RuntimeError, match="too coarse"):
        oblique_table(0.01, 0.05, grid={"nodes": (4, 4, 3), "zeta_cells": 4})


@pytest.mark.slow
@pytest.mark.parametrize("end", ob.ENDS)
def test_full_range_table_meets_the_target(end, cache_dir):
    table = oblique_table(BETA_MAX, ob.DELTA_MAX, end=end)
    rng = np.random.default_rng(5)
    beta, c, delta = random_points(rng, 20000, table.beta_limit, table.delta_limit)
    ref = ob.solve_many(beta, c, delta, end)
    eps, tau, m = table.lookup(beta, c, delta)
    assert np.max(np.abs(eps - ref[:, 0])) <= 1e-8
    assert np.max(np.abs(tau / ref[:, 1] - 1)) <= 1e-8
    assert np.max(np.abs(m / ref[:, 2] - 1)) <= 1e-8
