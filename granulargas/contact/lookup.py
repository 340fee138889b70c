"""Restitution lookup: compiled for the engine (a numba leaf module), numpy for Python callers.

The table (built by :mod:`granulargas.contact.table`) is a piecewise cubic in
``s = sqrt(beta)`` on a uniform grid ``s_k = k h``, ``k = 0..n``: on interval
``k`` with ``t = s/h - k`` in [0, 1),

    eps = c[k,0] + t (c[k,1] + t (c[k,2] + t c[k,3])).

The grid in sqrt(beta) makes both contact ends smooth at beta -> 0 (the
``force`` series runs in powers of sqrt(beta)). Out of range returns -1.0 so the
engine can report a status code instead of extrapolating.
"""

import math

import numpy as np

from granulargas._numba import jit


@jit
def table_lookup(beta, inv_h, coeffs):
    """Cubic-spline lookup of a tabulated function of beta.

    Parameters
    ----------
    beta : float
        Dimensionless damping, >= 0.
    inv_h : float
        1 / grid spacing in s = sqrt(beta).
    coeffs : float64 array (n, 4)
        Polynomial coefficients per interval in the local variable t.

    Returns
    -------
    float
        The tabulated value, or -1.0 if beta lies beyond the table
        (beta >= table_beta_limit(inv_h, coeffs)), is negative or nan.
    """
    x = math.sqrt(beta) * inv_h
    # written so that nan (and sqrt of a negative beta) also lands here
    if not x < coeffs.shape[0]:
        return -1.0
    k = int(x)
    t = x - k
    return coeffs[k, 0] + t * (coeffs[k, 1] + t * (coeffs[k, 2] + t * coeffs[k, 3]))


def table_beta_limit(inv_h, coeffs):
    """Largest beta the table covers: lookups need beta < this value.

    The engine can compare a pair's largest possible beta with this once, or
    test ``table_lookup(...) < 0`` per collision.
    """
    # a hair below (n h)^2 so that rounding in sqrt(beta) * inv_h cannot reach n
    s = coeffs.shape[0] * (1.0 - 1e-12) / inv_h
    return s * s


def table_lookup_many(betas, inv_h, coeffs, out):
    """``out[i] = table_lookup(betas[i], inv_h, coeffs)``; returns the count of misses (-1).

    numpy, for lookups from Python: the same operations in the same order as the compiled
    :func:`table_lookup`, hence the same bits.
    """
    with np.errstate(invalid="ignore"):
        x = np.sqrt(betas) * inv_h
    inside = x < coeffs.shape[0]  # False for nan
    x = np.where(inside, x, 0.0)
    k = x.astype(np.int64)
    t = x - k
    c = coeffs[k]
    out[:] = np.where(inside, c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3])), -1.0)
    return int(inside.size - np.count_nonzero(inside))
