"""Public functions eps(beta) and tau_c(beta) by each method.

``method``:

* ``"ode"`` -- direct integration (:mod:`granulargas.contact.ode`, Taylor method, ~1e-14);
* ``"series"`` -- truncated power series (:mod:`granulargas.contact.series`);
* ``"pade"`` -- Mueller & Poeschel (2011) Pade approximant (:mod:`granulargas.contact.pade`);
* ``"table"`` -- the engine's cubic table (:mod:`granulargas.contact.table`).
"""

from __future__ import annotations

import numpy as np

from granulargas.contact.ode import end_code, solve_many
from granulargas.contact.pade import restitution_pade
from granulargas.contact.series import duration_series, restitution_coefficients, restitution_series
from granulargas.contact.table import restitution_table

METHODS = ("ode", "series", "pade", "table")


def _shape_back(beta, values):
    return values.reshape(np.shape(beta)) if np.ndim(beta) else float(values[0])


def _table_for(beta, end):
    b = np.asarray(beta, dtype=float)
    return restitution_table(max(float(np.max(b)) if b.size else 1.0, 1e-6) * 1.0001, end=end)


def restitution(beta, method: str = "ode", end: str = "overlap", order: int | None = None):
    """Coefficient of normal restitution eps(beta).

    Parameters
    ----------
    beta : float or array
        Dimensionless damping (3/2) A rho^{2/5} g^{1/5}, >= 0.
    method : {"ode", "series", "pade", "table"}
    end : {"overlap", "force"}
        End of contact: x = 0 (Schwager & Pöschel (1997), eq. (4)) or vanishing repulsive force.
    order : int, optional
        Series order (method="series"): highest power of beta ("overlap") or of
        sqrt(beta) ("force"). Default 2 for "overlap" (Schwager & Pöschel (1997), eq. (31)), 4 for "force".

    Returns
    -------
    float or ndarray (shape of beta)
    """
    end_code(end)
    b = np.atleast_1d(np.asarray(beta, dtype=float)).ravel()
    if method == "ode":
        return _shape_back(beta, solve_many(b, end)[:, 0])
    if method == "table":
        return _table_for(b, end).restitution(beta)
    if method == "series":
        return _shape_back(beta, restitution_series(b, end=end, order=order))
    if method == "pade":
        return _shape_back(beta, restitution_pade(b, end=end))
    raise ValueError(f"method must be one of {METHODS}, got {method!r}")


def duration(beta, method: str = "ode", end: str = "overlap", order: int | None = None):
    """Dimensionless contact duration tau_c(beta); physical t_c = tau_c rho^{-2/5} g^{-1/5}.

    ``duration(0.0)`` is the Hertz value (4/5)(5/4)^{2/5} B(2/5, 1/2) = 3.21807.
    Methods as in :func:`restitution` ("pade" is not available for the duration).
    """
    end_code(end)
    b = np.atleast_1d(np.asarray(beta, dtype=float)).ravel()
    if method == "ode":
        return _shape_back(beta, solve_many(b, end)[:, 1])
    if method == "table":
        return _table_for(b, end).duration(beta)
    if method == "series":
        return _shape_back(beta, duration_series(b, end=end, order=order))
    if method == "pade":
        raise ValueError("no Pade approximant for the duration; use method='ode', 'series' or 'table'")
    raise ValueError(f"method must be one of {METHODS}, got {method!r}")


def series_coefficients(order: int, end: str = "overlap"):
    """Series coefficients c_0..c_order of eps.

    ``end="overlap"``: eps = sum_k c_k beta^k. ``end="force"``: eps = sum_k c_k u^k with
    u = sqrt(beta) (c_1 = c_3 = 0; odd powers from u^5 on).
    """
    return restitution_coefficients(order, end=end)
