"""The engine's restitution table: accuracy against the ODE, coverage, cache."""

import numpy as np
import pytest

from granulargas.contact import ode, restitution_table
from granulargas.contact.lookup import table_beta_limit, table_lookup, table_lookup_many
from granulargas.errors import TableRangeError


@pytest.mark.parametrize("end", ["overlap", "force"])
def test_table_within_1e8_of_the_ode_everywhere(end, cache_dir):
    table = restitution_table(10.0, end=end)
    assert table.coeffs.dtype == np.float64 and table.coeffs.flags.c_contiguous
    assert table.duration_coeffs.shape == table.coeffs.shape == (table.n_intervals, 4)
    rng = np.random.default_rng(2)
    # dense random points plus the region near 0 where the series lives
    b = np.concatenate([rng.uniform(0, table.beta_limit, 3000), rng.uniform(0, 1e-3, 300), [0.0]])
    ref = ode.solve_many(b, end)
    eps = np.array([table_lookup(x, table.inv_h, table.coeffs) for x in b])
    tau = np.array([table_lookup(x, table.inv_h, table.duration_coeffs) for x in b])
    assert np.max(np.abs(eps - ref[:, 0])) <= 1e-8
    assert np.max(np.abs(tau - ref[:, 1]) / np.maximum(1.0, ref[:, 1])) <= 1e-8


def test_table_refuses_to_extrapolate(cache_dir):
    table = restitution_table(1.0)
    limit = table_beta_limit(table.inv_h, table.coeffs)
    assert limit == pytest.approx(table.beta_limit) and limit >= 1.0
    assert table_lookup(limit, table.inv_h, table.coeffs) > 0
    for beyond in [limit * (1 + 1e-9), 2.0, 1e300, np.inf, np.nan, -1.0]:
        assert table_lookup(beyond, table.inv_h, table.coeffs) == -1.0
    with pytest.raises(TableRangeError, match="outside the restitution table"):
        table.restitution(2.0)
    assert not table.covers([0.5, 2.0]) and table.covers([0.0, 0.5, 1.0])


def test_lookups_from_python_give_the_engine_lookup_bit_for_bit(cache_dir):
    table = restitution_table(2.0)
    limit = table.beta_limit
    rng = np.random.default_rng(7)
    b = np.concatenate([rng.uniform(0, limit, 2000), rng.uniform(0, 1e-6, 100),
                        [0.0, limit, limit * (1 - 1e-15), limit * (1 + 1e-9), 1e300, np.inf, np.nan, -1.0, -0.0]])
    for coeffs in (table.coeffs, table.duration_coeffs):
        out = np.empty_like(b)
        misses = table_lookup_many(b, table.inv_h, coeffs, out)
        engine = np.array([table_lookup(x, table.inv_h, coeffs) for x in b])
        assert np.array_equal(out, engine)
        assert misses == np.count_nonzero(engine == -1.0) == 5  # beyond the limit, 1e300, inf, nan, -1


def test_extension_keeps_the_grid_and_the_values(cache_dir):
    small = restitution_table(1.0)
    big = small.extended(4.0)
    assert big.beta_limit >= 4.0 and big.inv_h == small.inv_h
    np.testing.assert_array_equal(big.coeffs[: small.n_intervals], small.coeffs)
    assert small.extended(0.5) is small


def test_built_fresh_equals_cached_slice(cache_dir, tmp_path, monkeypatch):
    big = restitution_table(4.0)
    from_cache = restitution_table(1.0)
    monkeypatch.setenv("GRANULARGAS_CACHE_DIR", str(tmp_path / "other"))
    fresh = restitution_table(1.0)
    np.testing.assert_array_equal(from_cache.coeffs, fresh.coeffs)
    np.testing.assert_array_equal(from_cache.duration_coeffs, big.duration_coeffs[: fresh.n_intervals])


def test_cached_table_extended_by_its_new_intervals_only(cache_dir, tmp_path, monkeypatch):
    """A larger request solves the ODE at the new nodes only and gives, bit for bit, the
    table a build from 0 gives."""
    from granulargas.contact import table as T

    small = restitution_table(1.0)
    solved = []
    solve = T.solve_many

    def counting(beta, *args, **kwargs):
        solved.append(len(beta))
        return solve(beta, *args, **kwargs)

    monkeypatch.setattr(T, "solve_many", counting)
    extended = restitution_table(4.0)
    new = extended.n_intervals - small.n_intervals
    assert solved == [new + 1, new]  # the new nodes (the shared one again) and midpoints
    monkeypatch.setenv("GRANULARGAS_CACHE_DIR", str(tmp_path / "other"))
    fresh = restitution_table(4.0)
    np.testing.assert_array_equal(extended.coeffs, fresh.coeffs)
    np.testing.assert_array_equal(extended.duration_coeffs, fresh.duration_coeffs)
    assert extended.parameters == fresh.parameters


def test_cache_keyed_by_parameters_and_rebuilt_when_bad(cache_dir):
    restitution_table(1.0)
    restitution_table(1.0, intervals_per_unit=64)
    restitution_table(1.0, end="force")
    files = sorted(cache_dir.glob("*.npz"))
    assert len(files) == 3
    for f in files:
        f.write_bytes(b"garbage")
    t = restitution_table(1.0)
    assert t.parameters["max_error_restitution"] < 1e-8
    assert t.parameters["intervals_per_unit"] == 128 and t.end == "overlap"


def test_coarse_table_is_refused(cache_dir):
    # 4 intervals per unit of sqrt(beta) cannot reach 1e-8: the build must say so, not return it
    with pytest.raises(RuntimeError, match="too coarse"):
        restitution_table(1.0, intervals_per_unit=4)


def test_parameters_are_plain_scalars(cache_dir):
    t = restitution_table(2.0, end="force")
    for k, v in t.parameters.items():
        assert isinstance(v, (int, float, str)), k
    assert t.parameters["end"] == "force" and t.parameters["beta_max"] == 2.0


def test_table_beyond_supported_range_is_a_clear_error(cache_dir):
    from granulargas.contact.table import TABLE_BETA_MAX

    with pytest.raises(TableRangeError, match="well below ~3"):
        restitution_table(2 * TABLE_BETA_MAX)


@pytest.mark.slow
@pytest.mark.parametrize("end", ["overlap", "force"])
def test_largest_table_meets_the_target(end, cache_dir):
    from granulargas.contact.table import TABLE_BETA_MAX

    t = restitution_table(TABLE_BETA_MAX, end=end)
    assert t.parameters["max_error_restitution"] <= 1e-8
    assert t.parameters["max_relative_error_duration"] <= 1e-8
