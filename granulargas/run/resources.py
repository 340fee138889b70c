"""What a run needs from the machine, estimated before anything is allocated or written.

A config can be valid key by key and still ask for more than the machine holds:
10^11 particles, a packing so dilute that the engine's cell grid has 10^300
cells, 2^63 snapshots. :func:`check_memory` and :func:`check_output_size` refuse
such runs with one line (:class:`granulargas.errors.ConfigError`) naming the key,
the estimate and what is available, before the initial state is built.

Memory of a run (bytes; N particles, d dimensions; measured with
:mod:`tracemalloc` in ``tests/run/test_resources.py``, which keeps the estimate
above the measured peak and within a factor 2 of it):

* initial placement (:func:`granulargas.initial.random_state`): about 900 B per
  particle (lattice sites, Monte Carlo work arrays) plus 5 B per cell of its
  grid (box volume / largest diameter^d cells);
* engine (:class:`granulargas.engine.Simulation` after its first build): 420 B
  per particle plus 6 B per neighbour-list slot (the engine's initial list width,
  with room to grow by half) plus 72 B per cell of its grid (box edge / (largest
  diameter + shell) cells per side: a count and 16 int32 slots);
* the public state, the initial state and one snapshot's copies: 8 (5 d + 4) B
  per particle.

The peak is the larger of the placement (with the state it returns) and the
engine with the state. The engine stores cell ids as int32, so the grid may not
exceed 2^31 - 1 cells: this, and the memory, bound dilute packings from below.

A DSMC run (``run.method = "dsmc"``, :func:`check_dsmc_memory`) has no placement and no
grid: its estimate is counted from the arrays it holds, 48 B per particle for the DSMC
(32 B of velocity rows, 16 B of radii and masses of unlike particles) plus
8 (4 d + 2) B for the initial state, one snapshot's copy and the Maxwell-Boltzmann draw.

The output's share (the schedule in memory, the file on its disk) is checked by
:func:`granulargas.run.schedule.check_output_size`.
"""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

from granulargas.engine.simulation import default_shell
from granulargas.errors import ConfigError
from granulargas.io.config import RunConfig

#: the engine stores cell ids as int32
MAX_CELLS = 2**31 - 1
PLACEMENT_BYTES_PER_PARTICLE = 900.0
PLACEMENT_BYTES_PER_CELL = 5.0
ENGINE_BYTES_PER_PARTICLE = 420.0
ENGINE_BYTES_PER_LIST_SLOT = 6.0
ENGINE_BYTES_PER_CELL = 72.0


def available_memory() -> float | None:
    """Bytes the process can still allocate: MemAvailable of /proc/meminfo, capped by a
    cgroup memory limit; None when the system does not say."""
    found = []
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    found.append(float(line.split()[1]) * 1024.0)
                    break
    except OSError:
        pass
    for limit, usage in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                         ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        try:
            text = Path(limit).read_text().strip()
            if text != "max" and float(text) < 2**60:
                found.append(float(text) - float(Path(usage).read_text().strip()))
        except (OSError, ValueError):
            continue
    if not found:
        try:
            found.append(float(os.sysconf("SC_AVPHYS_PAGES")) * float(os.sysconf("SC_PAGE_SIZE")))
        except (ValueError, OSError, AttributeError):
            return None
    return max(0.0, min(found))


def format_bytes(nbytes: float) -> str:
    if not math.isfinite(nbytes):
        return "more than float64 can count"
    for unit, scale in (("EB", 1e18), ("PB", 1e15), ("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= scale:
            value = nbytes / scale
            return f"{value:.3g} {unit}" if value < 1e6 else f"{nbytes:.3g} B"
    return f"{nbytes:.0f} B"


def _grid_cells(volume_ratio: float, edge_ratio: float, dimension: int, cut: float) -> float:
    """Cells of a grid with cells of edge >= ``cut`` (largest diameters) over a box of
    ``volume_ratio`` = V / dmax^d and shortest edge ``edge_ratio`` = L / dmax (cubic box:
    the same). Computed in floats (inf for astronomically dilute boxes)."""
    per_side = max(1.0, math.floor(edge_ratio / cut)) if math.isfinite(edge_ratio) else math.inf
    return per_side**dimension


def run_memory(n: int, dimension: int, packing: float, mean_volume_ratio: float = 1.0,
               fresh: bool = True) -> dict:
    """Estimated peak memory (bytes) of a run, by part (module docstring).

    Parameters
    ----------
    n : int
        Particles.
    dimension : int
    packing : float
        Packing fraction (sets the box).
    mean_volume_ratio : float
        Mean particle volume over the volume of a particle of the largest diameter
        (1 for monodisperse).
    fresh : bool
        Include the initial placement (False for a restart).
    """
    d = dimension
    n = float(n)
    unit = math.pi / 6.0 if d == 3 else math.pi / 4.0  # volume of a diameter-1 particle
    with_overflow = n * unit * mean_volume_ratio / packing if packing > 0 else math.inf  # V / dmax^d
    edge = with_overflow ** (1.0 / d) if math.isfinite(with_overflow) else math.inf
    shell = (min(default_shell(packing, d), edge / 3.0 - 1.0) if math.isfinite(edge)
             else default_shell(packing, d))
    cut = 1.0 + max(shell, 0.05)
    engine_cells = _grid_cells(with_overflow, edge, d, cut)
    placement_cells = _grid_cells(with_overflow, edge, d, 1.0)
    sphere = (4.0 / 3.0 * math.pi * cut**3) if d == 3 else math.pi * cut**2
    mean = n / with_overflow * sphere if math.isfinite(with_overflow) and with_overflow > 0 else 0.0
    width = min(max(n - 1.0, 1.0), max(8.0, math.ceil(mean + 5.0 * math.sqrt(mean) + 4.0)))
    state = 8.0 * (5 * d + 4) * n
    engine = (ENGINE_BYTES_PER_PARTICLE + 1.5 * width * ENGINE_BYTES_PER_LIST_SLOT) * n + ENGINE_BYTES_PER_CELL * engine_cells
    placement = PLACEMENT_BYTES_PER_PARTICLE * n + PLACEMENT_BYTES_PER_CELL * placement_cells if fresh else 0.0
    return {"engine": engine, "engine_cells": engine_cells, "placement": placement,
            "placement_cells": placement_cells if fresh else 0.0, "state": state,
            "total": max(placement, engine) + state}


def dsmc_memory(n: int, dimension: int) -> float:
    """Estimated peak memory (bytes) of a DSMC run of ``n`` particles (module docstring)."""
    return (48.0 + 8.0 * (4 * dimension + 2)) * float(n)


def check_dsmc_memory(config: RunConfig, *, n: int | None = None, available: float | None = None) -> float:
    """Refuse a DSMC run whose estimated memory exceeds what is available (one line naming
    ``system.particles``). Returns the estimate."""
    n = config.system.particles if n is None else int(n)
    need = dsmc_memory(n, config.system.dimension)
    if available is None:
        available = available_memory()
    if available is not None and need > available:
        raise ConfigError(f"{config.source}: system.particles = {n}: the DSMC run needs about "
                          f"{format_bytes(need)} of memory, {format_bytes(available)} are available")
    return need


def _volume_ratio(config: RunConfig) -> float:
    """Mean particle volume / volume of the largest particle (uniform diameters in [a, b])."""
    p, d = config.particles, config.system.dimension
    if not p.polydisperse:
        return 1.0
    a, b = p.diameter_min, p.diameter_max
    mean_power = (b ** (d + 1) - a ** (d + 1)) / ((d + 1) * (b - a))  # <diameter^d>
    return mean_power / b**d


def check_memory(config: RunConfig, *, n: int | None = None, packing: float | None = None, fresh: bool = True,
                 available: float | None = None) -> dict:
    """Refuse a run whose estimated peak memory exceeds what is available, or whose
    cell grid exceeds the engine's int32 cell ids (one line naming the key).

    ``n``, ``packing``: of a restart file (default: the config's). Returns the estimate."""
    s = config.system
    n = s.particles if n is None else int(n)
    packing = s.packing_fraction if packing is None else float(packing)
    est = run_memory(n, s.dimension, packing, _volume_ratio(config), fresh=fresh)
    cells = max(est["engine_cells"], est["placement_cells"])
    src = config.source
    if available is None:
        available = available_memory()
    # the engine's and the placement's cell grids: both grow with the box, not with N
    grid = est["engine_cells"] * ENGINE_BYTES_PER_CELL + est["placement_cells"] * PLACEMENT_BYTES_PER_CELL
    dilute = cells > 64.0 * n  # the grid, not the particles, is what is too large
    if cells > MAX_CELLS and dilute:
        raise ConfigError(
            f"{src}: system.packing_fraction = {packing:g}: too dilute for {n} particles: the engine's cell "
            f"grid would need {cells:.3g} cells (one per ~2 diameters of box edge; cell ids are int32, at most "
            "2^31 - 1); use a higher packing_fraction or more particles")
    if available is not None and est["total"] > available:
        key, value = ("system.packing_fraction", f"{packing:g}") if grid > 0.5 * est["total"] else (
            "system.particles", str(n))
        raise ConfigError(
            f"{src}: {key} = {value}: the run needs about {format_bytes(est['total'])} of memory "
            f"({format_bytes(est['total'] / n)} per particle, of which the cell grids {format_bytes(grid)}), "
            f"{format_bytes(available)} are available")
    if cells > MAX_CELLS:
        raise ConfigError(
            f"{src}: system.particles = {n}: the engine's cell grid would need {cells:.3g} cells (cell ids are "
            "int32, at most 2^31 - 1); use fewer particles")
    return est
