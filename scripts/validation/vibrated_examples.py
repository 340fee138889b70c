"""The example configs of vibrated gases over 10^4 plate periods: no lock-up, no collapse.

Runs each config (``configs/vibrated_bed_2d.toml``, ``vibrated_bed_3d.toml``,
``shaken_cell_3d.toml`` by default) for ``--periods`` periods of its slowest vibrating wall,
into a temporary directory, and prints per config: the end reached (or the error), the
collisions and events, the events per plate period in the first and the last tenth of the run
(a lock-up, ever more events per period, would show there), the wall time, and the energy
balance of the second half (power dissipated / power put in).

Usage::

    python scripts/validation/vibrated_examples.py                 # 10^4 periods each
    python scripts/validation/vibrated_examples.py --periods 1000 configs/vibrated_bed_3d.toml
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from granulargas.analysis.vibrated import energy_balance
from granulargas.errors import SimulationError
from granulargas.io.config import load_config
from granulargas.io.h5md import read_observables
from granulargas.run.runner import run_config

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ("vibrated_bed_2d.toml", "vibrated_bed_3d.toml", "shaken_cell_3d.toml")


def period(config) -> float:
    """The period of the config's slowest vibrating wall."""
    nus = [getattr(config.walls, s).frequency for s in ("x_low", "x_high", "y_low", "y_high", "z_low", "z_high")
           if getattr(config.walls, s) is not None and getattr(config.walls, s).kind == "vibrating"]
    return 1.0 / min(nus)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("configs", nargs="*", default=[str(ROOT / "configs" / name) for name in EXAMPLES])
    ap.add_argument("--periods", type=float, default=1e4)
    args = ap.parse_args(argv)
    print(f"# {args.periods:g} plate periods per config")
    print(f"{'config':>22} {'end':>10} {'collisions':>12} {'events':>12} {'ev/period first':>16} "
          f"{'ev/period last':>15} {'wall s':>8} {'dissipated/in':>14}")
    with tempfile.TemporaryDirectory() as tmp:
        for path in args.configs:
            base = load_config(path)
            tau = period(base)
            end = args.periods * tau
            out = Path(tmp) / (Path(path).stem + ".h5")
            cfg = load_config(path, overrides={"run.end_time": end, "output.file": str(out),
                                               "output.snapshot_interval": end / 4,
                                               "output.observables_interval": end / 400})
            t0 = time.perf_counter()
            try:
                s = run_config(cfg, overwrite=True, quiet=True)
                status = f"{s.time:.4g}"
            except SimulationError as exc:
                print(f"{Path(path).name:>22} error: {exc}")
                continue
            wall = time.perf_counter() - t0
            obs = read_observables(out)
            t = obs["events"][1]
            ev = obs["events"][2].astype(float)
            k = max(1, len(t) // 10)
            first = (ev[k] - ev[0]) / ((t[k] - t[0]) / tau)
            last = (ev[-1] - ev[-1 - k]) / ((t[-1] - t[-1 - k]) / tau)
            b = energy_balance(obs["wall_work"][1], obs["wall_work"][2], obs["dissipated_energy"][2])
            print(f"{Path(path).name:>22} {status:>10} {s.collisions:>12d} {s.events:>12d} {first:>16.4g} "
                  f"{last:>15.4g} {wall:>8.1f} {b.ratio:>8.4f} ± {b.ratio_error:.2g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
