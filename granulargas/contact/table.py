"""The universal restitution table the engine looks up: eps(beta) and tau_c(beta).

Grid and interpolation
----------------------
Nodes are uniform in s = sqrt(beta), s_k = k h with h = 1/intervals_per_unit
(default 1/128), from s = 0 up to past sqrt(beta_max). At every node the Taylor
integrator (:mod:`granulargas.contact._taylor_np`, the numpy-vectorised twin of
the compiled kernel, so that a fresh checkout or CI builds a table in well under
a second without compiling anything) gives eps, tau_c and their
beta-derivatives (sensitivity equations); on each interval the table holds the
cubic Hermite polynomial in the local variable t = s/h - k matching values and
s-derivatives (d/ds = 2 s d/dbeta) at both nodes, so the interpolant is C^1.

Why s = sqrt(beta): the ``force`` end is a series in sqrt(beta) (:mod:`granulargas.contact.series`),
and the overlap end, a series in beta, is smooth in s too; at s = 0 the ODE is the
elastic (Hertz) problem and is solved exactly like any other node, so no special
small-beta branch is needed (the series is only used to test the first interval).

Accuracy: Hermite error is h^4 max|f''''| / 384. With h = 1/128 the build checks
every interval midpoint against the ODE: max |eps error| ~ 2e-10 and relative
tau_c error ~ 1e-9 (see ``parameters["max_error_restitution"]``); the build fails
if the error exceeds 1e-8 (absolute for eps, relative for tau_c).

Coverage: tables go up to ``TABLE_BETA_MAX`` = 40 (far beyond the model's validity,
beta well below ~3; beyond ~50 the overlap-end duration loses accuracy) and
refuse larger requests with TableRangeError. A table built for beta_max covers [0, beta_limit) with
beta_limit >= beta_max; :func:`granulargas.contact.lookup.table_lookup` returns
-1.0 beyond, never an extrapolation. :meth:`RestitutionTable.extended` or a new
:func:`restitution_table` call gives a larger table (same grid, so the common
part is bit-identical).

Cache: tables are stored as ``.npz`` in ``$GRANULARGAS_CACHE_DIR`` (default
``~/.cache/granulargas``), keyed by a hash of the build parameters (end, grid,
integrator order and tolerance, format version). The file holds the largest table
built so far for that key; smaller requests are slices of it, larger ones build the
missing intervals only and replace it. An unreadable or mismatching file is rebuilt.
A process reads a file once and keeps its arrays while the file stays the same (inode,
size and modification time; a replaced file is read again).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from granulargas.contact import _taylor
from granulargas.contact.lookup import table_beta_limit, table_lookup_many
from granulargas.contact.ode import end_code, solve_many
from granulargas.errors import TableRangeError

#: 3: steps without ``pow`` and each beta converged on its own (:mod:`granulargas.contact._taylor_np`),
#: so that a cached table's bits depend neither on the machine nor on the largest table built before
FORMAT_VERSION = 3
DEFAULT_INTERVALS_PER_UNIT = 128
MAX_ERROR = 1e-8
# Largest beta a table may cover. The model is physical only for beta well below ~3; beyond
# beta ~ 50 the overlap end (eps ~ 1e-8, tau_c ~ 600) loses the 1e-8 relative accuracy of tau_c
# (the contact creeps back to x = 0 over thousands of steps).
TABLE_BETA_MAX = 40.0


def cache_dir() -> Path:
    """Directory of cached tables: ``$GRANULARGAS_CACHE_DIR`` or ``~/.cache/granulargas``."""
    env = os.environ.get("GRANULARGAS_CACHE_DIR")
    return Path(env) if env else Path.home() / ".cache" / "granulargas"


@dataclass(frozen=True, eq=False)
class RestitutionTable:
    """Piecewise cubic tables of eps(beta) and tau_c(beta) in s = sqrt(beta).

    Attributes
    ----------
    inv_h : float
        1 / grid spacing in s.
    coeffs : float64 (n, 4), C-contiguous
        eps per interval: c0 + t (c1 + t (c2 + t c3)), t = s inv_h - k.
    duration_coeffs : float64 (n, 4), C-contiguous
        Dimensionless duration tau_c, same layout.
    beta_max : float
        The beta the table was requested for (covered).
    end : str
        "overlap" or "force".
    parameters : dict
        Build parameters and verified errors (plain scalars and strings, for the
        H5MD ``parameters/`` group).
    """

    inv_h: float
    coeffs: np.ndarray
    duration_coeffs: np.ndarray
    beta_max: float
    end: str
    parameters: dict = field(default_factory=dict)

    @property
    def beta_limit(self) -> float:
        """Lookups are valid for 0 <= beta < beta_limit (>= beta_max)."""
        return float(table_beta_limit(self.inv_h, self.coeffs))

    @property
    def n_intervals(self) -> int:
        return int(self.coeffs.shape[0])

    def covers(self, beta) -> bool:
        """True if every beta given lies inside the table."""
        b = np.asarray(beta, dtype=float)
        return bool(np.all((b >= 0.0) & (b < self.beta_limit)))

    def _lookup(self, beta, coeffs):
        b = np.ascontiguousarray(np.atleast_1d(np.asarray(beta, dtype=np.float64)).ravel())
        out = np.empty_like(b)
        misses = table_lookup_many(b, self.inv_h, coeffs, out)
        if misses:
            bad = b[out < 0.0]
            raise TableRangeError(
                f"beta={bad.max() if np.all(bad >= 0) else bad.min():.6g} lies outside the restitution table "
                f"[0, {self.beta_limit:.6g}) (end={self.end}); build a larger one with "
                f"restitution_table(beta_max=...) or table.extended(...)")
        return out.reshape(np.shape(beta)) if np.ndim(beta) else float(out[0])

    def restitution(self, beta):
        """eps(beta) by table lookup; raises TableRangeError beyond the table."""
        return self._lookup(beta, self.coeffs)

    def duration(self, beta):
        """tau_c(beta) by table lookup; raises TableRangeError beyond the table."""
        return self._lookup(beta, self.duration_coeffs)

    def extended(self, beta_max: float) -> "RestitutionTable":
        """This table if it already covers beta_max, else a larger one on the same grid."""
        if beta_max < self.beta_limit:
            return self
        return restitution_table(beta_max, end=self.end,
                                 intervals_per_unit=int(self.parameters["intervals_per_unit"]))


def ensure_covers(table: RestitutionTable, beta_required: float) -> RestitutionTable:
    """Return ``table`` or a larger table covering ``beta_required``."""
    return table.extended(beta_required)


def _hermite(f0, f1, d0, d1):
    """Cubic in t in [0, 1] with values f0, f1 and t-derivatives d0, d1."""
    c = np.empty((f0.shape[0], 4))
    c[:, 0] = f0
    c[:, 1] = d0
    c[:, 2] = 3.0 * (f1 - f0) - 2.0 * d0 - d1
    c[:, 3] = 2.0 * (f0 - f1) + d0 + d1
    return c


def _build(n: int, h: float, end: str, first: int = 0):
    """Coefficients for intervals ``first`` .. n - 1 of width h in s, plus midpoint errors.

    Every node is solved on its own (:mod:`granulargas.contact._taylor_np`), so the rows of
    intervals ``first`` .. n - 1 are bit for bit those of a build from 0 (a cached table is
    extended by building its new intervals only)."""
    s = np.arange(first, n + 1) * h
    rows = solve_many(s * s, end, backend="numpy")
    eps, tau = rows[:, 0], rows[:, 1]
    deps = 2.0 * s * rows[:, 2] * h  # d/dt = h d/ds = 2 s h d/dbeta
    dtau = 2.0 * s * rows[:, 3] * h
    c_eps = _hermite(eps[:-1], eps[1:], deps[:-1], deps[1:])
    c_tau = _hermite(tau[:-1], tau[1:], dtau[:-1], dtau[1:])
    # verify at interval midpoints (where the Hermite error peaks) against the ODE
    mid = solve_many(((np.arange(first, n) + 0.5) * h) ** 2, end, backend="numpy")
    half = np.array([1.0, 0.5, 0.25, 0.125])
    err_eps = np.abs(c_eps @ half - mid[:, 0])
    err_tau = np.abs(c_tau @ half - mid[:, 1]) / np.maximum(1.0, mid[:, 1])
    return np.ascontiguousarray(c_eps), np.ascontiguousarray(c_tau), err_eps, err_tau


def _key_parameters(end: str, intervals_per_unit: int) -> dict:
    return {
        "format_version": FORMAT_VERSION,
        "end": end,
        "grid": "uniform in s = sqrt(beta)",
        "interpolation": "cubic Hermite in s (values and derivatives from sensitivity equations)",
        "intervals_per_unit": int(intervals_per_unit),
        "ode_solver": "Taylor series in regularised variables w = sqrt(x), dt = w ds (numpy, vectorised)",
        "ode_order": _taylor.ORDER,
        "ode_tolerance": _taylor.TOLERANCE,
    }


def _cache_file(key_params: dict, kind: str = "restitution") -> Path:
    digest = hashlib.sha256(json.dumps(key_params, sort_keys=True).encode()).hexdigest()[:16]
    return cache_dir() / f"{kind}-{key_params['end']}-{digest}.npz"


def load_cached(path: Path, key_params: dict) -> dict | None:
    """Arrays of a cached table file, or None if missing, unreadable or built with other parameters."""
    try:
        with np.load(path, allow_pickle=False) as data:
            if json.loads(str(data["key"])) != key_params:
                return None
            return {name: np.asarray(data[name]) for name in data.files if name != "key"}
    except (OSError, KeyError, ValueError):
        return None


def save_cached(path: Path, key_params: dict, **arrays) -> None:
    """Write a table file atomically (concurrent builders never see half a file); warn if impossible."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp.npz")
        os.close(fd)
        np.savez(tmp, key=json.dumps(key_params, sort_keys=True), **arrays)
        os.replace(tmp, path)
    except OSError as exc:
        warnings.warn(f"could not cache the table in {path.parent}: {exc}", RuntimeWarning, stacklevel=3)


#: table files read by this process: path -> (file identity, key, arrays)
_READ: dict = {}


def _read(path: Path, key_params: dict) -> dict | None:
    """:func:`load_cached`, read once per process while the file stays the same (its identity:
    inode, size, modification time; a rewritten file is read again)."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    ident = (st.st_ino, st.st_size, st.st_mtime_ns)
    seen = _READ.get(path)
    if seen is not None and seen[0] == ident and seen[1] == key_params:
        return seen[2]
    data = load_cached(path, key_params)
    if data is not None:
        _READ[path] = (ident, key_params, data)
    return data


def _load(path: Path, key_params: dict, n: int):
    """The cached table's first n intervals, or all of them when it has fewer (None: no table)."""
    data = _read(path, key_params)
    if data is None or "coeffs" not in data:
        return None
    try:
        return (np.ascontiguousarray(data["coeffs"][:n]), np.ascontiguousarray(data["duration_coeffs"][:n]),
                np.asarray(data["err_eps"][:n]), np.asarray(data["err_tau"][:n]))
    except KeyError:
        return None


def _save(path: Path, key_params: dict, c_eps, c_tau, err_eps, err_tau) -> None:
    save_cached(path, key_params, coeffs=c_eps, duration_coeffs=c_tau, err_eps=err_eps, err_tau=err_tau)


def restitution_table(beta_max: float, end: str = "overlap",
                      intervals_per_unit: int = DEFAULT_INTERVALS_PER_UNIT,
                      use_cache: bool = True) -> RestitutionTable:
    """Table of eps(beta) and tau_c(beta) covering 0 <= beta <= beta_max.

    Parameters
    ----------
    beta_max : float
        Largest dimensionless damping the caller needs (> 0). The table covers
        [0, beta_limit) with beta_limit >= beta_max.
    end : {"overlap", "force"}
    intervals_per_unit : int
        Grid intervals per unit of s = sqrt(beta) (1/h).
    use_cache : bool
        Read and write the on-disk cache.

    Returns
    -------
    RestitutionTable
    """
    end_code(end)
    beta_max = float(beta_max)
    if not (beta_max > 0.0 and math.isfinite(beta_max)):
        raise ValueError(f"beta_max must be positive and finite, got {beta_max}")
    if beta_max > TABLE_BETA_MAX:
        raise TableRangeError(
            f"restitution table requested up to beta = {beta_max:.4g}, beyond the supported {TABLE_BETA_MAX:g}: "
            f"the viscoelastic model holds only for beta well below ~3 (lower the damping / impact speeds)")
    h = 1.0 / intervals_per_unit
    n = int(math.floor(math.sqrt(beta_max) * intervals_per_unit * (1.0 + 1e-9))) + 1
    key_params = _key_parameters(end, intervals_per_unit)
    path = _cache_file(key_params)
    built = _load(path, key_params, n) if use_cache else None
    have = 0 if built is None else built[0].shape[0]
    if have < n:  # the cached table's intervals and the new ones (bit for bit a build from 0)
        more = _build(n, h, end, first=have)
        built = more if built is None else tuple(np.concatenate(pair) for pair in zip(built, more))
        if use_cache:
            _save(path, key_params, *built)
    c_eps, c_tau, err_eps, err_tau = built
    max_eps, max_tau = float(err_eps.max()), float(err_tau.max())
    if max_eps > MAX_ERROR or max_tau > MAX_ERROR:
        raise RuntimeError(f"restitution table too coarse: midpoint errors {max_eps:.2e} (eps), "
                           f"{max_tau:.2e} (tau_c, relative); increase intervals_per_unit")
    params = dict(key_params)
    params.update(beta_max=beta_max, n_intervals=n,
                  beta_limit=float(table_beta_limit(float(intervals_per_unit), c_eps)),
                  max_error_restitution=max_eps, max_relative_error_duration=max_tau)
    return RestitutionTable(inv_h=float(intervals_per_unit), coeffs=c_eps, duration_coeffs=c_tau,
                            beta_max=beta_max, end=end, parameters=params)
