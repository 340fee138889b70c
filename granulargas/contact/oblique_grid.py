r"""The oblique-contact table: eps_s, tau_s and M of :mod:`granulargas.contact.oblique` in three variables.

Variables and normalisation
---------------------------
The outcome of eq. (3) of :mod:`granulargas.contact.oblique` is tabulated in

    s = sqrt(beta) in [0, sqrt(beta_max)],  zeta = sqrt(c) / (1 + sqrt(c)) in [0, 1],  delta in [0, delta_max]

as f_0 = eps_s, f_1 = tau_s (1 + c), f_2 = M (1 + c)^2. Why these:

* s: the ``force`` end is a series in sqrt(beta) (as for the head-on table,
  :mod:`granulargas.contact.table`).
* zeta: near c = 0 the outcome is analytic in c = (zeta / (1 - zeta))^2; for
  grazing impacts (c -> inf) the contact is short, x ~ 1/c, tau_s ~ 2/c, and
  the outcome is a series in c^{-1/2} = (1 - zeta) / zeta, so zeta = 1 (g_n -> 0)
  is a regular end of the interval. sqrt(c) rather than c resolves the
  feature at small c that strongly damped contacts have (their slow end is cut
  short by the centrifugal term when c ~ eps / tau_c).
* (1 + c) and (1 + c)^2 make tau_s and M, which vanish like 1/c and 1/c^2 for
  grazing impacts, O(1), so that the table's absolute accuracy is a relative
  accuracy of the duration and of the turn of the normal.
* delta enters through (1 - delta x)^{-3} only and is the smoothest direction.

Interpolation
-------------
The box is cut into cells of width 1 / ``cells_per_unit_s`` in s, 1 /
``zeta_cells`` in zeta and 1 / ``cells_per_unit_delta`` in delta. In each cell
the three functions are interpolated at the tensor product of Chebyshev points
(first kind, p_s x p_zeta x p_delta, never on the cell faces, so zeta = 1 is
never integrated) and stored as monomial coefficients in local variables
u in [-1, 1] (:func:`granulargas.contact.oblique_lookup.oblique_lookup` evaluates
them by nested Horner, p_s p_zeta p_delta multiply-adds per function). Cells are
independent, so a table is extended by computing only the new cells.

The nodes are solved by the compiled Taylor integrator
(:mod:`granulargas.contact._oblique_taylor`, ~1e-14). Every build checks
``checks_per_cell`` seeded random points per cell against it and fails if any
error exceeds 1e-8 (absolute for eps_s, relative to max(1, |f|) for f_1, f_2);
the errors found are in ``parameters``. With the defaults (8 cells per unit of
s, 24 in zeta, 16 per unit of delta; 7 x 7 x 7 nodes) the largest errors over
the whole range, at 2 x 10^4 random points (tests/contact), are 7e-10 (eps_s),
8e-10 (tau_s) and 1.4e-9 (M). The full range (beta < 2.25, delta < 0.56, 2592
cells, 21 MB) takes ~1 min per contact end to build, once; a gas needs a few
cells. Finer cells with fewer nodes keep the lookup cheap (3 x 343
multiply-adds): 10 x 10 x 8 nodes on a coarser grid reach the same accuracy
with 2.3 times the work per lookup.

Coverage: beta < :data:`BETA_MAX` (= 2, beyond the model's validity) and
delta < :data:`granulargas.contact.oblique.DELTA_MAX`. Out of range, lookups
return a status, never an extrapolation.

Cache: ``.npz`` files in ``$GRANULARGAS_CACHE_DIR`` (default
``~/.cache/granulargas``) through :func:`granulargas.contact.table.load_cached`
/ :func:`~granulargas.contact.table.save_cached`, keyed by the build
parameters; the file holds the largest table built so far.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from granulargas.contact import _oblique_taylor as _k
from granulargas.contact.oblique import DELTA_MAX, CollisionOutcome, c_of_zeta, end_code, frame_outcome, solve_many
from granulargas.contact.oblique_lookup import oblique_lookup_many
from granulargas.contact.table import _cache_file, load_cached, save_cached
from granulargas.errors import TableRangeError

FORMAT_VERSION = 2
MAX_ERROR = 1e-8
#: Largest beta an oblique table may cover (the viscoelastic model needs beta well below ~3).
BETA_MAX = 2.0
DEFAULT_GRID = {"cells_per_unit_s": 8, "zeta_cells": 24, "cells_per_unit_delta": 16, "nodes": (7, 7, 7)}
CHECKS_PER_CELL = 2


def _nodes(p):
    """Chebyshev points of the first kind on [-1, 1], increasing."""
    return np.cos(np.pi * (np.arange(p) + 0.5) / p)[::-1].copy()


def _values_to_monomials(p):
    """Matrix L (p, p): monomial coefficients (in u) of the interpolant = L @ values at :func:`_nodes`."""
    x = _nodes(p)
    return np.linalg.inv(np.vander(x, p, increasing=True))


def _scaled(rows, c):
    """Tabulated functions from solver rows: eps_s, tau_s (1 + c), M (1 + c)^2."""
    w = 1.0 + c
    return np.stack([rows[..., _k.COL_EPS], rows[..., _k.COL_TAU] * w, rows[..., _k.COL_M] * w * w], axis=-1)


def _build_columns(cells, grid, end, n_z):
    """Coefficients of the cells (a, d) given (all zeta cells each): array (len(cells), n_z, 3, ps, pz, pd)."""
    ps, pz, pd = grid["nodes"]
    hs, hd, hz = 1.0 / grid["cells_per_unit_s"], 1.0 / grid["cells_per_unit_delta"], 1.0 / n_z
    xs, xz, xd = _nodes(ps), _nodes(pz), _nodes(pd)
    a = np.array([cell[0] for cell in cells], dtype=float)
    d = np.array([cell[1] for cell in cells], dtype=float)
    s = (a[:, None] + 0.5 * (xs[None, :] + 1.0)) * hs  # (m, ps)
    dl = (d[:, None] + 0.5 * (xd[None, :] + 1.0)) * hd  # (m, pd)
    zeta = (np.arange(n_z)[:, None] + 0.5 * (xz[None, :] + 1.0)) * hz  # (n_z, pz)
    m = len(cells)
    S = np.broadcast_to(s[:, :, None, None, None], (m, ps, n_z, pz, pd))
    Z = np.broadcast_to(zeta[None, None, :, :, None], (m, ps, n_z, pz, pd))
    Dl = np.broadcast_to(dl[:, None, None, None, :], (m, ps, n_z, pz, pd))
    c = c_of_zeta(Z)
    rows = solve_many(S * S, c, Dl, end)
    values = _scaled(rows, c)  # (m, ps, n_z, pz, pd, 3)
    Ls, Lz, Ld = (_values_to_monomials(p) for p in (ps, pz, pd))
    return np.einsum("ia,jb,kc,mazbcf->mzfijk", Ls, Lz, Ld, values, optimize=True)


def _column_errors(coeffs, cells, grid, end, seed=12345):
    """Errors of the table at CHECKS_PER_CELL seeded random points in each cell of the columns (a, d) given.

    Returns
    -------
    ndarray (len(cells), n_zeta, 3)
        Per cell: max |eps_s error|, max relative error of tau_s (1 + c) and of
        M (1 + c)^2 (relative to max(1, |f|)).
    """
    n_z = coeffs.shape[1]
    hs, hd = 1.0 / grid["cells_per_unit_s"], 1.0 / grid["cells_per_unit_delta"]
    rng = np.random.default_rng(seed)
    m, k = len(cells), CHECKS_PER_CELL
    a = np.array([cell[0] for cell in cells], dtype=float)[:, None, None]
    d = np.array([cell[1] for cell in cells], dtype=float)[:, None, None]
    b = np.arange(n_z, dtype=float)[None, :, None]
    shape = (m, n_z, k)
    s = (a + rng.uniform(size=shape)) * hs
    zeta = (b + rng.uniform(size=shape)) / n_z
    delta = (d + rng.uniform(size=shape)) * hd
    c = c_of_zeta(zeta)
    beta = s * s
    ref = _scaled(solve_many(beta, c, delta, end), c).reshape(-1, 3)
    got = np.empty((beta.size, 3))
    flat = [np.ascontiguousarray(v.ravel()) for v in (beta, c, delta)]
    oblique_lookup_many(*flat, float(grid["cells_per_unit_s"]), float(grid["cells_per_unit_delta"]), coeffs, got)
    got[:, 1] *= 1.0 + flat[1]
    got[:, 2] *= (1.0 + flat[1]) ** 2
    err = np.abs(got - ref)
    err[:, 1:] /= np.maximum(1.0, np.abs(ref[:, 1:]))
    return err.reshape(m, n_z, k, 3).max(axis=2)


@dataclass(frozen=True, eq=False)
class ObliqueTable:
    """Piecewise tensor-Chebyshev table of the oblique contact (see the module docstring).

    Attributes
    ----------
    inv_hs, inv_hd : float
        1 / cell width in sqrt(beta) and in delta.
    coeffs : float64 (n_s, n_zeta, n_delta, 3, p_s, p_zeta, p_delta), C-contiguous
    beta_max, delta_max : float
        The ranges requested (covered).
    end : str
    parameters : dict
        Build parameters and verified errors (plain scalars and strings).
    """

    inv_hs: float
    inv_hd: float
    coeffs: np.ndarray
    beta_max: float
    delta_max: float
    end: str
    parameters: dict = field(default_factory=dict)

    @property
    def beta_limit(self) -> float:
        """Lookups need beta < beta_limit (>= beta_max)."""
        s = self.coeffs.shape[0] * (1.0 - 1e-12) / self.inv_hs
        return s * s

    @property
    def delta_limit(self) -> float:
        """Lookups need delta < delta_limit (>= delta_max)."""
        return self.coeffs.shape[2] * (1.0 - 1e-12) / self.inv_hd

    def lookup(self, beta, c, delta):
        """(eps_s, tau_s, M) by table lookup, arrays broadcast; raises TableRangeError outside the table."""
        b, cc, d = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (beta, c, delta)))
        shape = b.shape
        b, cc, d = (np.ascontiguousarray(v.ravel()) for v in (b, cc, d))
        out = np.empty((b.size, 3))
        if oblique_lookup_many(b, cc, d, self.inv_hs, self.inv_hd, self.coeffs, out):
            i = int(np.flatnonzero(np.isnan(out[:, 0]))[0])
            raise TableRangeError(
                f"(beta, c, delta) = ({b[i]:.6g}, {cc[i]:.6g}, {d[i]:.6g}) lies outside the oblique-contact "
                f"table (beta < {self.beta_limit:.6g}, delta < {self.delta_limit:.6g}, c >= 0; end={self.end}); "
                f"build a larger one with oblique_table(beta_max=..., delta_max=...)")
        return tuple(out[:, k].reshape(shape) if shape else float(out[0, k]) for k in range(3))

    def outcome(self, normal_speed, tangential_speed, distance, rho, dissipation_time) -> CollisionOutcome:
        """Resolved collision of one pair, eqs. (5)-(8) of :mod:`granulargas.contact.oblique`.

        Parameters
        ----------
        normal_speed, tangential_speed : float
            g_n > 0 and g_t >= 0 at first touch.
        distance : float
            D = R_i + R_j.
        rho, dissipation_time : float
            rho = 2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2)) and A (consistent units).
        """
        from granulargas.contact.oblique import parameters

        beta, c, delta = (float(v) for v in parameters(normal_speed, tangential_speed, distance, rho,
                                                          dissipation_time))
        eps_s, tau_s, m = self.lookup(beta, c, delta)
        eps_head_on = self.lookup(beta, 0.0, delta)[0]
        return frame_outcome(eps_s, tau_s, m, beta, c, delta, eps_head_on, normal_speed, tangential_speed,
                             distance)

    def extended(self, beta_max: float, delta_max: float) -> "ObliqueTable":
        """This table if it covers both, else a larger one on the same grid."""
        if beta_max < self.beta_limit and delta_max < self.delta_limit:
            return self
        return oblique_table(max(beta_max, self.beta_max), max(delta_max, self.delta_max), end=self.end)


def _key_parameters(end: str, grid: dict) -> dict:
    return {
        "format_version": FORMAT_VERSION,
        "end": end,
        "variables": "sqrt(beta), zeta = sqrt(c)/(1+sqrt(c)), delta",
        "functions": "eps_s, tau_s (1+c), M (1+c)^2",
        "interpolation": "tensor Chebyshev points (first kind) per cell, monomials in u in [-1, 1]",
        "cells_per_unit_s": int(grid["cells_per_unit_s"]),
        "zeta_cells": int(grid["zeta_cells"]),
        "cells_per_unit_delta": int(grid["cells_per_unit_delta"]),
        "nodes": ",".join(str(int(p)) for p in grid["nodes"]),
        "ode_solver": "Taylor series in w = sqrt(x), dt = w ds (compiled)",
        "ode_order": _k.ORDER,
        "ode_tolerance": _k.TOLERANCE,
    }


def oblique_table(beta_max: float, delta_max: float, end: str = "overlap", grid: dict | None = None,
                  use_cache: bool = True) -> ObliqueTable:
    """Table of the oblique contact covering 0 <= beta <= beta_max, 0 <= delta <= delta_max, all angles.

    Parameters
    ----------
    beta_max : float
        Largest damping (at the normal impact speed) needed, in (0, BETA_MAX].
    delta_max : float
        Largest compression scale / contact distance needed, in (0, DELTA_MAX].
    end : {"overlap", "force"}
    grid : dict, optional
        Cells and nodes (keys of ``DEFAULT_GRID``); a coarse grid that misses
        1e-8 is refused.
    use_cache : bool
        Read and write the on-disk cache.

    Returns
    -------
    ObliqueTable
    """
    end_code(end)
    grid = dict(DEFAULT_GRID, **(grid or {}))
    beta_max, delta_max = float(beta_max), float(delta_max)
    if not (beta_max > 0.0 and math.isfinite(beta_max)) or not (delta_max > 0.0 and math.isfinite(delta_max)):
        raise ValueError(f"beta_max and delta_max must be positive and finite, got {beta_max}, {delta_max}")
    if beta_max > BETA_MAX:
        raise TableRangeError(
            f"oblique-contact table requested up to beta = {beta_max:.4g}, beyond the supported {BETA_MAX:g}: "
            "the viscoelastic model holds only for beta well below ~3")
    if delta_max > DELTA_MAX:
        raise TableRangeError(
            f"oblique-contact table requested up to delta = {delta_max:.4g}, beyond the supported {DELTA_MAX:g}: "
            "the overlap would exceed half the contact distance (a stiffer contact or slower impacts)")
    cps, cpd, n_z = int(grid["cells_per_unit_s"]), int(grid["cells_per_unit_delta"]), int(grid["zeta_cells"])
    n_s = int(math.floor(math.sqrt(beta_max) * cps * (1.0 + 1e-9))) + 1
    n_d = int(math.floor(delta_max * cpd * (1.0 + 1e-9))) + 1
    key = _key_parameters(end, grid)
    path = _cache_file(key, kind="oblique")
    stored = load_cached(path, key) if use_cache else None
    if stored is not None and ("coeffs" not in stored or "errors" not in stored):
        stored = None
    if stored is not None and stored["coeffs"].shape[0] >= n_s and stored["coeffs"].shape[2] >= n_d:
        coeffs = np.ascontiguousarray(stored["coeffs"][:n_s, :, :n_d])
        errors = stored["errors"][:n_s, :, :n_d]
    else:
        ps, pz, pd = grid["nodes"]
        big_s = max(n_s, stored["coeffs"].shape[0] if stored is not None else 0)
        big_d = max(n_d, stored["coeffs"].shape[2] if stored is not None else 0)
        full = np.full((big_s, n_z, big_d, 3, ps, pz, pd), np.nan)
        done = np.zeros((big_s, big_d), dtype=bool)
        if stored is not None:
            os_, od = stored["coeffs"].shape[0], stored["coeffs"].shape[2]
            full[:os_, :, :od] = stored["coeffs"]
            done[:os_, :od] = True
        missing = [(a, d) for a in range(big_s) for d in range(big_d) if not done[a, d]]
        cols = _build_columns(missing, grid, end, n_z)
        for (a, d), col in zip(missing, cols):
            full[a, :, d] = col
        full = np.ascontiguousarray(full)
        errors = np.full((big_s, n_z, big_d, 3), np.nan)
        if stored is not None:
            errors[:os_, :, :od] = stored["errors"]
        for (a, d), err in zip(missing, _column_errors(full, missing, grid, end)):
            errors[a, :, d] = err
        if use_cache:
            save_cached(path, key, coeffs=full, errors=errors)
        coeffs = np.ascontiguousarray(full[:n_s, :, :n_d])
        errors = errors[:n_s, :, :n_d]
    max_err = errors.reshape(-1, 3).max(axis=0)
    if np.any(max_err > MAX_ERROR) or not np.all(np.isfinite(max_err)):
        raise RuntimeError(f"oblique-contact table too coarse: errors {max_err} at random points "
                           "(eps abs, tau and M relative); refine the grid")
    params = dict(key)
    params.update(beta_max=beta_max, delta_max=delta_max, n_cells=int(n_s * n_z * n_d),
                  max_error_restitution=float(max_err[0]), max_relative_error_duration=float(max_err[1]),
                  max_relative_error_turning=float(max_err[2]))
    table = ObliqueTable(inv_hs=float(cps), inv_hd=float(cpd), coeffs=coeffs, beta_max=beta_max,
                         delta_max=delta_max, end=end, parameters=params)
    params.update(beta_limit=table.beta_limit, delta_limit=table.delta_limit)
    return table
