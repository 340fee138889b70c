"""The homogeneous cooling state (HCS) of constant restitution: the best reference, named.

In the HCS of smooth inelastic hard spheres (disks) with a constant restitution eps
every velocity scales with sqrt(T(t)): the Sonine coefficients a2, a3 and the ratios

    c_zeta  = zeta / zeta_M,    zeta_M  = (1 - eps^2) omega_M / d,                      (H1)
    c_omega = omega / omega_M,  omega_M = Omega_d chi n sigma^(d-1) sqrt(T/m),          (H2)

of the cooling rate and of the collision frequency to their Maxwellian values
(:func:`granulargas.theory.enskog_cooling_rate` and
:func:`granulargas.theory.collision_frequency` at a2 = 0) depend on eps and d only.
Two references give them:

* **first Sonine, van Noije & Ernst 1998** (:data:`FIRST_SONINE`): a2 of
  :func:`granulargas.theory.sonine_a2`, a3 = 0, c_zeta = 1 + 3 a2/16,
  c_omega = 1 - a2/16. Good near eps = 1 (8-12 % of a2 and 6e-4 in c_zeta at
  eps = 0.9); at strong inelasticity its a2 is 10-28 % too large (Santos & Montanero
  2009), and c_zeta up to 1.2 % (2D, eps = 0.1);
* **Enskog-Boltzmann, DSMC table** (:data:`DSMC_TABLE`): the homogeneous
  Enskog-Boltzmann equation solved by this package's DSMC, which is exact up to
  statistics, at eps = 0.10, 0.15, ..., 0.95 in 2D and 3D
  (``hcs_dsmc_table.csv`` beside this module, made by ``scripts/validation/hcs_reference_table.py``
  from 7e9 collisions, 10-15 minutes on one idle core; 8 independent gases of 10^5
  particles per point, each 400 collisions per particle; errors are the standard errors
  of those 8 means).

:func:`hcs_reference` gives the best of the two: the table for 0.1 <= eps < 1 and the
first Sonine values outside it (eps < 0.1; eps = 1 is exact in both: a Maxwellian).
Between the table's points it interpolates the *difference from first Sonine* with a
cubic spline through its nodes and eps = 1 (where the difference is 0); the difference is
small and smooth where first Sonine is good, and a2 itself changes sign near eps = 0.7.
The error of an interpolated value is the table's error (interpolated linearly between
the nodes) and an interpolation error added in quadrature: 1/16 of the largest
deviation of the spline through every other node from the left-out node (a cubic's
error scales as h^4 with the spacing h; the deviation includes the table's noise, so
this bounds the interpolation error from above).

The relaxation from a Maxwellian start towards the HCS takes a few collisions per
particle. The table's last column is its rate per collision per particle as the
temperature sees it: in collisions per particle s, ln T(s) = -k q s + delta once relaxed
(k = (1 - eps^2)/d, q = c_zeta/c_omega, 1 at the start), and a factor relaxing as
exp(-rate s) gives delta = k (q - 1)/rate; the DSMC's delta (32 gases of 10^5 particles)
gives the rate, nan where q - 1 is too small to resolve it (near eps = 0.7, where the
transient does not matter). At eps <= 0.6 the DSMC relaxes 1.2-1.8 times faster than the
first Sonine moment equations say, near eps = 0.9 somewhat slower.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from granulargas.theory.enskog import sonine_a2

__all__ = ["FIRST_SONINE", "DSMC_TABLE", "TABLE_PATH", "HCSReference", "hcs_reference", "first_sonine",
           "table_range", "read_table", "write_table"]

#: name of the first Sonine approximation of the HCS
FIRST_SONINE = "first Sonine, van Noije & Ernst 1998"
#: name of the DSMC reference table
DSMC_TABLE = "Enskog-Boltzmann, DSMC table"
#: the shipped table
TABLE_PATH = Path(__file__).with_name("hcs_dsmc_table.csv")

_COLUMNS = ("dimension", "restitution", "a2", "a2_error", "a3", "a3_error", "zeta_factor", "zeta_factor_error",
            "omega_factor", "omega_factor_error", "relaxation_rate")
_QUANTITIES = ("a2", "a3", "zeta_factor", "omega_factor")


@dataclass(frozen=True)
class HCSReference:
    """The HCS of one (eps, d) by one reference (module doc).

    ``zeta_factor`` is c_zeta of (H1), ``omega_factor`` c_omega of (H2); ``*_error`` their
    standard errors (0 for first Sonine, whose error is that of the approximation);
    ``relaxation_rate``: rate per collision per particle of the transient from a Maxwellian
    start (module doc; nan if not measured or not resolved).
    """

    name: str
    restitution: float
    dimension: int
    a2: float
    a2_error: float
    a3: float
    a3_error: float
    zeta_factor: float
    zeta_factor_error: float
    omega_factor: float
    omega_factor_error: float
    relaxation_rate: float = math.nan

    @property
    def cooling_per_collision(self) -> float:
        """zeta / omega = -d ln T / ds (s collisions per particle) in the HCS."""
        return (1.0 - self.restitution**2) * self.zeta_factor / (self.dimension * self.omega_factor)


def first_sonine(eps: float, dim: int = 3) -> HCSReference:
    """The first Sonine approximation (van Noije & Ernst 1998) as an :class:`HCSReference`."""
    a2 = float(sonine_a2(eps, dim))
    return HCSReference(FIRST_SONINE, float(eps), int(dim), a2, 0.0, 0.0, 0.0, 1.0 + 3.0 * a2 / 16.0, 0.0,
                        1.0 - a2 / 16.0, 0.0)


def write_table(path, rows, header: str = "") -> None:
    """Write the table (rows of :data:`_COLUMNS`) as CSV with ``#`` comment lines."""
    rows = np.asarray(rows, dtype=float)
    lines = [f"# {line}" for line in header.splitlines()] + [",".join(_COLUMNS)]
    for r in rows:
        lines.append(",".join([f"{int(r[0])}", f"{r[1]:.4f}"] + [f"{x:.6g}" for x in r[2:11]]))
    Path(path).write_text("\n".join(lines) + "\n")


def read_table(path=TABLE_PATH) -> dict:
    """The table as ``{dimension: {column: array}}``, sorted by eps."""
    lines = [x for x in Path(path).read_text().splitlines() if x.strip() and not x.startswith("#")]
    names = lines[0].split(",")
    data = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    col = {name: data[:, k] for k, name in enumerate(names)}
    out = {}
    for d in (2, 3):
        sel = col["dimension"] == d
        order = np.argsort(col["restitution"][sel])
        out[d] = {c: col[c][sel][order] for c in _COLUMNS[1:]}
    return out


def _first_sonine_columns(eps, dim):
    a2 = sonine_a2(np.asarray(eps, dtype=float), dim)
    return {"a2": a2, "a3": np.zeros_like(a2), "zeta_factor": 1.0 + 3.0 * a2 / 16.0, "omega_factor": 1.0 - a2 / 16.0}


#: version of the cached spline file's layout (:func:`_spline_coefficients`)
_SPLINE_FORMAT = 1


def _fit_splines(eps, diff):
    """scipy's cubic spline (not-a-knot) through (eps, diff) as (4, n-1) coefficients, and its
    interpolation error: 1/16 of the largest deviation of the spline through every other node
    from the left-out node (module doc)."""
    from scipy.interpolate import CubicSpline

    loo = [abs(CubicSpline(np.delete(eps, k), np.delete(diff, k))(eps[k]) - diff[k]) for k in range(1, eps.size - 1)]
    return np.ascontiguousarray(CubicSpline(eps, diff).c), max(loo) / 16.0


def _node_restitutions(col):
    """The nodes of the splines: the table's eps and 1."""
    return np.append(col["restitution"], 1.0)


def _nodes(col, dim):
    """The nodes of the splines (:func:`_node_restitutions`) and, per quantity, the difference
    from first Sonine there."""
    eps = _node_restitutions(col)
    first = _first_sonine_columns(eps, dim)
    return eps, {q: np.append(col[q], first[q][-1]) - first[q] for q in _QUANTITIES}


@lru_cache(maxsize=None)
def _spline_coefficients() -> dict:
    """``{(dim, quantity): (coefficients (4, n-1), interpolation error)}`` of the table's splines.

    Fitted by scipy once and kept in the table cache (``hcs-splines-<digest>.npz`` in
    :func:`granulargas.contact.table.cache_dir`, keyed by the table's text and scipy's version),
    so that a run reads them with numpy (importing ``scipy.interpolate`` costs about 0.4 s of a
    new process's start-up), like the restitution tables.
    """
    import hashlib

    import scipy

    from granulargas.contact.table import cache_dir, load_cached, save_cached

    text = TABLE_PATH.read_bytes()
    key = {"format": _SPLINE_FORMAT, "table": hashlib.sha256(text).hexdigest(), "scipy": scipy.__version__}
    path = cache_dir() / f"hcs-splines-{key['table'][:16]}.npz"
    names = [f"{d}-{q}" for d in (2, 3) for q in _QUANTITIES]
    arrays = load_cached(path, key)
    if arrays is None or any(n not in arrays or n + "-error" not in arrays for n in names):
        table = read_table()
        arrays = {}
        for d in (2, 3):
            eps, diff = _nodes(table[d], d)
            for q in _QUANTITIES:
                arrays[f"{d}-{q}"], error = _fit_splines(eps, diff[q])
                arrays[f"{d}-{q}-error"] = np.array(error)
        save_cached(path, key, **arrays)
    return {(d, q): (arrays[f"{d}-{q}"], float(arrays[f"{d}-{q}-error"])) for d in (2, 3) for q in _QUANTITIES}


def _piecewise_cubic(nodes, coefficients, x: float) -> float:
    """A spline's value at x from its (4, n-1) coefficients (scipy's ``PPoly`` layout: the
    polynomial of interval k in powers of x - nodes[k], highest first; the end intervals
    extend beyond the nodes)."""
    k = min(max(int(np.searchsorted(nodes, x, side="right")) - 1, 0), nodes.size - 2)
    t = x - nodes[k]
    c = coefficients[:, k]
    value = 0.0
    power = 1.0
    for m in (3, 2, 1, 0):  # powers summed in scipy's order, for its bits
        value += c[m] * power
        power *= t
    return float(value)


@lru_cache(maxsize=None)
def _splines(dim: int):
    """Per quantity: (spline coefficients of the difference from first Sonine, nodes with eps = 1,
    errors, interpolation error)."""
    col = read_table()[dim]
    eps = _node_restitutions(col)
    fitted = _spline_coefficients()
    out = {}
    for q in _QUANTITIES:
        coefficients, interp = fitted[dim, q]
        out[q] = (coefficients, eps, np.append(col[q + "_error"], 0.0), interp)
    out["relaxation_rate"] = (col["restitution"], col["relaxation_rate"])
    return out


def table_range(dim: int = 3) -> tuple[float, float]:
    """(smallest, largest) eps of the table's nodes in dimension ``dim``."""
    e = read_table()[dim]["restitution"]
    return float(e[0]), float(e[-1])


def hcs_reference(eps: float, dim: int = 3) -> HCSReference:
    """The best reference for the HCS at restitution ``eps`` in ``dim`` dimensions (module doc).

    The DSMC table (:data:`DSMC_TABLE`) for table_range(dim)[0] <= eps < 1, else first Sonine
    (:data:`FIRST_SONINE`); eps = 1 gives the Maxwellian (a2 = 0) by either.
    """
    eps = float(eps)
    if dim not in (2, 3):
        raise ValueError(f"dim = {dim}: 2 or 3")
    if not 0.0 <= eps <= 1.0:
        raise ValueError(f"eps = {eps}: 0 <= eps <= 1")
    if eps == 1.0 or eps < table_range(dim)[0] - 1e-12:
        return first_sonine(eps, dim)
    s = _splines(dim)
    first = _first_sonine_columns(eps, dim)
    vals = {}
    for q in _QUANTITIES:
        coefficients, nodes, err, interp = s[q]
        vals[q] = float(first[q] + _piecewise_cubic(nodes, coefficients, eps))
        vals[q + "_error"] = float(math.hypot(np.interp(eps, nodes, err), interp))
    e_nodes, rate = s["relaxation_rate"]
    return HCSReference(DSMC_TABLE, eps, int(dim), relaxation_rate=float(np.interp(eps, e_nodes, rate)), **vals)
