"""The quickstart's inputs to the engine are the same bits on every machine.

A gas is chaotic: a difference in the last bit of an output time (the engine
resynchronises there) or of a restitution-table coefficient grows into another
trajectory within a few hundred collisions. numpy picks its SIMD kernels at run time
(AVX-512, AVX2 or baseline), and those of ``power``, ``exp`` and ``log`` differ from
each other and from the C library in the last bit. The output times and the table
must therefore come from exact or correctly rounded operations only:

* compared with stored exact values (a machine whose C library or numpy gives other
  bits fails here);
* compared with the same computation in a process whose numpy runs its baseline
  kernels only (``NPY_DISABLE_CPU_FEATURES``), on a machine that has more.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from granulargas.contact.table import restitution_table
from granulargas.io.config import load_config
from granulargas.run.schedule import mean_free_time, output_schedule

QUICKSTART = Path(__file__).resolve().parents[2] / "configs" / "quickstart.toml"

#: the quickstart's snapshot times: the mean free time, log-spaced times rounded to 9 digits, the end
SNAPSHOTS = [0.566718797, 0.75540617, 1.00691645, 1.34216636, 1.78903673, 2.38469131, 3.17866733, 4.23699536,
             5.64769063, 7.52807277, 10.0345227, 13.3754878, 17.8288175, 23.7648704, 31.6773147, 42.2241844,
             56.2826036, 75.0217326, 100.0]

#: sha256 of the coefficients (eps, then tau_c) of the overlap-end table for beta_max = 0.3125 (72 intervals)
TABLE_DIGEST = "e1d8474a016b6f866070b245de4855c1a933df01366184eaecb7b252fe2bdced"

_PROBE = """
import hashlib, json, sys
from granulargas.contact.table import restitution_table
from granulargas.io.config import load_config
from granulargas.run.schedule import output_schedule
t = restitution_table(0.3125, use_cache=False)
s = output_schedule(load_config(sys.argv[1]))
print(json.dumps({"table": hashlib.sha256(t.coeffs.tobytes() + t.duration_coeffs.tobytes()).hexdigest(),
                  "targets": [float(x).hex() for x in s.targets]}))
"""


def _table_digest() -> str:
    t = restitution_table(0.3125, use_cache=False)
    return hashlib.sha256(t.coeffs.tobytes() + t.duration_coeffs.tobytes()).hexdigest()


def test_quickstart_output_times_are_stored_exact_values():
    config = load_config(QUICKSTART)
    schedule = output_schedule(config)
    assert mean_free_time(config) == SNAPSHOTS[0]
    assert [float(t) for t in schedule.targets[schedule.snapshot]] == SNAPSHOTS


def test_restitution_table_is_the_stored_bits():
    assert _table_digest() == TABLE_DIGEST


def _numpy_features() -> list[str]:
    """The SIMD targets numpy dispatches to on this machine, beyond its baseline."""
    try:
        from numpy._core import _multiarray_umath as umath
    except ImportError:  # numpy 1.x
        from numpy.core import _multiarray_umath as umath
    return [name for name in umath.__cpu_dispatch__ if umath.__cpu_features__.get(name)]


def test_table_and_output_times_without_numpy_simd_kernels():
    features = _numpy_features()
    if not features:
        pytest.skip("numpy runs its baseline kernels only on this machine: nothing to switch off")
    env = {**os.environ, "NPY_DISABLE_CPU_FEATURES": " ".join(features)}
    out = subprocess.run([sys.executable, "-c", _PROBE, str(QUICKSTART)], capture_output=True, text=True,
                         env=env, check=True)
    baseline = json.loads(out.stdout)
    schedule = output_schedule(load_config(QUICKSTART))
    assert baseline["targets"] == [float(x).hex() for x in schedule.targets]
    assert baseline["table"] == _table_digest()
    assert np.all(np.isfinite(schedule.targets))
