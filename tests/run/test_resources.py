"""What a run needs from the machine: the memory estimate against measured allocations, and
the one-line refusals of runs that do not fit (memory, cell grid, schedule, disk, float64 clock)."""

import math
import tracemalloc

import numpy as np
import pytest

from granulargas.engine import CollisionRule, Simulation
from granulargas.errors import ConfigError
from granulargas.initial import lattice_gas, random_state
from granulargas.io.config import parse_config
from granulargas.run import resources
from granulargas.run.schedule import check_output_size, output_counts, output_schedule, pacing_stops
from granulargas.run.validity import check_run
from tests.materials import RUBBER

BASE = """
[system]
dimension = {d}
particles = {n}
packing_fraction = {eta}
[collision]
model = "elastic"
[run]
end_time = 1.0
[output]
file = "x.h5"
"""


def _config(n=1000, d=3, eta=0.1, extra=""):
    return parse_config(BASE.format(n=n, d=d, eta=eta) + extra, "c.toml")


def _measure(n, d, eta):
    """Peak bytes (tracemalloc: numpy reports its allocations) of the initial placement, and of
    the engine's first build with the state it starts from."""
    warm = random_state(n, eta, d, seed=2)  # compile first (same code paths): JIT allocations are not the run's
    Simulation(warm, CollisionRule.elastic()).run(until=0.0)
    tracemalloc.start()
    st = random_state(n, eta, d, seed=1)
    placement = tracemalloc.get_traced_memory()[1]
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    sim = Simulation(st, CollisionRule.elastic())
    sim.run(until=0.0)
    engine = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    del sim
    return placement, engine


@pytest.mark.parametrize("n, d, eta, large", [(4000, 3, 0.1, False), (4000, 3, 0.002, False), (3000, 2, 0.005, False),
                                              (3000, 2, 0.5, False), (4000, 3, 0.5, True), (4000, 3, 0.3, True),
                                              (3000, 2, 0.7, True)])
def test_memory_estimate_bounds_the_measured_peak(monkeypatch, n, d, eta, large):
    """large: the placement of large systems (sorted particles; forced for n particles)."""
    if large:
        monkeypatch.setattr(lattice_gas, "SORTED_MIN_PARTICLES", 0)
    placement, engine = _measure(n, d, eta)
    est = resources.run_memory(n, d, eta)
    assert est["placement"] >= placement, (est["placement"] / n, placement / n)
    assert est["engine"] + est["state"] >= engine, (est["engine"] / n, engine / n)
    # and not wildly above: within a factor 2.5 of what was measured
    assert est["total"] <= 2.5 * max(placement, engine), (est["total"] / n, placement / n, engine / n)


def test_cell_count_is_the_engines():
    st = random_state(2000, 0.01, 3, seed=1)
    sim = Simulation(st, CollisionRule.elastic())
    assert resources.run_memory(2000, 3, 0.01)["engine_cells"] == float(np.prod(sim._space.ncell))


def test_memory_refusal_names_estimate_and_available():
    c = _config(n=2_000_000_000)
    with pytest.raises(ConfigError) as err:
        resources.check_memory(c, available=16e9)
    msg = str(err.value)
    assert msg.startswith("c.toml: system.particles = 2000000000: the run needs about ")
    assert "16 GB are available" in msg and "\n" not in msg
    est = resources.check_memory(_config(n=1000), available=16e9)
    assert 0 < est["total"] < 3e6


def test_dilute_packing_refused_by_the_cell_grid():
    with pytest.raises(ConfigError, match=r"system.packing_fraction = 1e-300: too dilute for 1000 particles"):
        resources.check_memory(_config(eta=1e-300), available=1e12)
    with pytest.raises(ConfigError, match=r"system.packing_fraction = 1e-06: the run needs about .* of which "
                                          r"the cell grid"):
        resources.check_memory(_config(eta=1e-6), available=1e9)


def test_available_memory_is_plausible():
    avail = resources.available_memory()
    assert avail is None or 1e6 < avail < 1e16


def test_output_counts_and_size_refusals():
    c = _config(extra="snapshot_interval = 1e-12\n")
    snaps, obs = output_counts(c)
    assert snaps == pytest.approx(1e12 + 1) and obs == 201
    with pytest.raises(ConfigError, match=r"output.snapshot_interval = 1e-12: 1e\+12 output times; the schedule "
                                          r"alone needs 6.4e\+13 B|64 TB"):
        check_output_size(c, available=1e10, free_disk=1e15)
    c = _config(extra="snapshots = 100000\n")
    with pytest.raises(ConfigError, match=r"output.snapshots = 100000: the output file would need about 7.21 GB "
                                          r"\(100000 snapshots of 72 kB\), the disk holding"):
        check_output_size(c, available=1e10, free_disk=1e9)
    c = _config(extra="observables_interval = 1e-300\n")
    with pytest.raises(ConfigError, match="output.observables_interval = 1e-300"):
        check_output_size(c, available=1e10, free_disk=1e12)
    schedule, file_bytes = check_output_size(_config(), available=1e10, free_disk=1e12)
    assert schedule < 1e5 and 20 * 1000 * 72 < file_bytes < 2e6
    assert len(output_schedule(_config()).targets) < schedule / 8


def test_pacing_stops_are_powers_of_two_of_the_mean_free_time():
    from granulargas.run.schedule import mean_free_time

    cfg = parse_config(BASE.format(n=1000, d=3, eta=0.1).replace("end_time = 1.0", "end_time = 1e21"), "c.toml")
    stops = pacing_stops(cfg)
    assert stops[0] == mean_free_time(cfg) and np.allclose(stops[1:] / stops[:-1], 2.0)
    assert stops[-1] < 1e21 <= 2 * stops[-1]
    s = output_schedule(cfg)
    assert set(stops) <= set(s.targets)
    only = ~s.sample  # pacing stops where no output falls: neither snapshots nor samples
    assert only.sum() > 50 and not s.snapshot[only].any()
    assert np.isin(s.targets[only], stops).all()


def test_float64_clock_bounds_the_end_time():
    """Elastic gas: the clock resolves 1e-6 of a mean free time up to t ~ 1e-6 2^52 t_free."""
    from granulargas.run.schedule import mean_free_time

    t_free = mean_free_time(_config())
    limit = 1e-6 * 2.0**52 * t_free
    ok = parse_config(BASE.format(n=1000, d=3, eta=0.1).replace("end_time = 1.0", f"end_time = {0.5 * limit!r}"), "c")
    assert check_run(ok).errors == []
    bad = parse_config(BASE.format(n=1000, d=3, eta=0.1).replace("end_time = 1.0", f"end_time = {2 * limit!r}"), "c")
    (msg,) = check_run(bad).errors
    assert msg.startswith(f"c: run.end_time = {2 * limit:g}: at t = ") and "float64 clock" in msg
    assert f"{limit:.3g}" in msg
    # a cooling gas's event spacing grows with t: Haff cooling to t = 1e15 stays resolved
    haff = parse_config(BASE.format(n=1000, d=3, eta=0.1).replace('model = "elastic"', 'model = "constant"\n'
                        "restitution = 0.9").replace("end_time = 1.0", "end_time = 1e15"), "c")
    assert not any("clock" in e for e in check_run(haff).errors)
    assert math.isfinite(limit)


def test_beta_beyond_the_table_names_the_damping(tmp_path):
    from granulargas.run.prepare import prepare

    text = BASE.format(n=1000, d=3, eta=0.1).replace('model = "elastic"', 'model = "viscoelastic"\ndamping = 39.0')
    with pytest.raises(ConfigError, match=r"collision.damping = 39: the fastest impact the run's kinetic energy "
                                          r"allows reaches beta = .*beyond the restitution table's 40"):
        prepare(parse_config(text, "c.toml"))


SIZED = """
[system]
dimension = 3
particles = 2000
packing_fraction = 0.1
[collision]
{collision}
[run]
end_time = 0.4
{run}
[output]
file = "{out}"
snapshots = 40
observables_interval = 0.25
"""
MATERIAL = 'model = "viscoelastic"\nduration = "resolved"\n' + RUBBER


@pytest.mark.parametrize("collision, run", [('model = "elastic"', ""), ('model = "elastic"', 'method = "dsmc"'),
                                            (MATERIAL, "")], ids=["edmd", "dsmc", "resolved"])
def test_output_size_estimate_matches_the_file_written(tmp_path, collision, run):
    """The disk estimate of check_output_size against the size of the file a run writes: the
    frame's columns differ by method (DSMC stores no positions, resolved runs their contacts)."""
    from granulargas.run.runner import run_config

    cfg = parse_config(SIZED.format(collision=collision, run=run, out=tmp_path / "out.h5"), "c.toml")
    _, estimate = check_output_size(cfg, available=1e10, free_disk=1e15)
    written = run_config(cfg, quiet=True).output.stat().st_size
    assert 0.8 < written / estimate < 1.25, (written, estimate)
