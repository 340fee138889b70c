"""Static structure: S(k), g(r) and the coarse-grained density field, periodic box.

Structure factor
----------------
``S(k) = |rho_k|^2 / N`` with ``rho_k = sum_j exp(i k . r_j)`` evaluated directly
(no grid, no aliasing) on the reciprocal lattice of the periodic box,
``k = 2 pi (n_1 / L_1, ..., n_d / L_d)`` with integer ``n``. Small ``k`` are the
point: the smallest is ``2 pi / L``. The sum factorises per axis,
``exp(i k . r) = prod_a E_a[j, n_a]`` with ``E_a[j, n] = exp(2 pi i n x_ja / L_a)``,
so ``rho`` over a whole block of ``n`` is one matrix product (2D:
``rho = E_x^T E_y``; 3D: one product per ``n_x``), done by BLAS in particle
chunks; the cost is ``N (n_x + 1) (2 n_y + 1) [(2 n_z + 1)]`` complex
multiply-adds. Only the half space ``n_x >= 0`` is computed (``rho_{-k} = rho_k^*``).
Works for 2D and 3D and rectangular boxes (freud's direct S(k) does not take 2D
boxes).

g(r)
----
Pair counts from ``scipy.spatial.cKDTree(boxsize=L).count_neighbors`` at the bin
edges (minimum image, no neighbour list in memory), normalised by the ideal-gas
count ``N (N - 1) V_shell / V``; requires ``r_max < L/2``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from granulargas.theory import particle_volume

__all__ = [
    "wrap",
    "structure_factor_vectors",
    "structure_factor",
    "radial_distribution",
    "density_field",
]


def wrap(positions, box):
    """Positions folded into ``[0, L)`` (also guards the round-off case ``x == L``
    that cKDTree's ``boxsize`` rejects)."""
    box = np.asarray(box, dtype=float)
    p = np.mod(np.asarray(positions, dtype=float), box)
    p[p >= box] = 0.0
    return p


def _phases(x, L, nmin, nmax):
    n = np.arange(nmin, nmax + 1)
    return np.exp((2j * np.pi / L) * np.outer(x, n))


def structure_factor_vectors(positions, box, k_max, chunk=16384):
    """``S`` at every reciprocal-lattice vector with ``0 < |k| <= k_max`` (half space).

    Parameters
    ----------
    positions : array (N, d), d = 2 or 3
    box : array (d,)
        Periodic box edges.
    k_max : float
        Largest wavenumber (1/sigma); at least ``2 pi / min(L)``.
    chunk : int
        Particles per BLAS block (memory ~ chunk * (2 n_max + 1) * 16 bytes per axis).

    Returns
    -------
    kvec : array (K, d)
        Wave vectors.
    S : array (K,)
        ``|rho_k|^2 / N``.
    """
    pos = np.asarray(positions, dtype=float)
    box = np.asarray(box, dtype=float)
    n_part, d = pos.shape
    if d not in (2, 3):
        raise ValueError(f"positions must have 2 or 3 columns, got {d}")
    nmax = np.floor(k_max * box / (2.0 * np.pi)).astype(int)
    if np.all(nmax == 0):
        raise ValueError(f"k_max = {k_max} is below the smallest wavenumber 2 pi / L = {2 * np.pi / box.max():.4g}")
    ranges = [(0, nmax[0])] + [(-nmax[a], nmax[a]) for a in range(1, d)]
    shape = tuple(hi - lo + 1 for lo, hi in ranges)
    rho = np.zeros(shape, dtype=complex)
    for start in range(0, n_part, chunk):
        p = pos[start:start + chunk]
        E = [_phases(p[:, a], box[a], *ranges[a]) for a in range(d)]
        if d == 2:
            rho += E[0].T @ E[1]
        else:
            for ix in range(shape[0]):
                rho[ix] += (E[0][:, ix, None] * E[1]).T @ E[2]
    grids = np.meshgrid(*[np.arange(lo, hi + 1) for lo, hi in ranges], indexing="ij")
    nvec = np.stack([g.ravel() for g in grids], axis=1)
    kvec = 2.0 * np.pi * nvec / box
    kmag = np.linalg.norm(kvec, axis=1)
    # half space: n_x > 0, or n_x == 0 and the first non-zero later component > 0
    first_nz = np.zeros(len(nvec), dtype=int)
    for a in range(d - 1, 0, -1):
        first_nz = np.where(nvec[:, a] != 0, nvec[:, a], first_nz)
    keep = ((nvec[:, 0] > 0) | ((nvec[:, 0] == 0) & (first_nz > 0))) & (kmag <= k_max * (1 + 1e-12))
    S = np.abs(rho.ravel()) ** 2 / n_part
    return kvec[keep], S[keep]


def structure_factor(positions, box, k_max=None, bin_width=None, chunk=16384):
    """Static structure factor averaged over shells of ``|k|``.

    Parameters
    ----------
    positions : array (N, d)
    box : array (d,)
    k_max : float, optional
        Default ``2 pi * 16 / min(L)`` (the 16 smallest shells, the clustering range).
    bin_width : float, optional
        Shell width; default ``2 pi / max(L)`` (one lattice step).

    Returns
    -------
    k : array (B,)
        Mean ``|k|`` in each non-empty shell.
    S : array (B,)
        Shell average of ``S(k)``.
    count : array (B,) int
        Number of (half-space) wave vectors per shell.
    """
    box = np.asarray(box, dtype=float)
    if k_max is None:
        k_max = 2.0 * np.pi * 16 / box.min()
    if bin_width is None:
        bin_width = 2.0 * np.pi / box.max()
    kvec, S = structure_factor_vectors(positions, box, k_max, chunk)
    kmag = np.linalg.norm(kvec, axis=1)
    idx = np.floor(kmag / bin_width + 0.5).astype(int)  # shells centred on multiples of bin_width
    count = np.bincount(idx)
    ksum = np.bincount(idx, kmag)
    ssum = np.bincount(idx, S)
    ok = count > 0
    return ksum[ok] / count[ok], ssum[ok] / count[ok], count[ok]


def radial_distribution(positions, box, r_max, bins=100):
    """Pair distribution function g(r) in a periodic box (minimum image).

    Parameters
    ----------
    positions : array (N, d)
    box : array (d,)
    r_max : float
        Largest distance, below ``min(L)/2``.
    bins : int

    Returns
    -------
    r : array (bins,)
        Bin centres.
    g : array (bins,)
    """
    pos = wrap(positions, box)
    box = np.asarray(box, dtype=float)
    n, d = pos.shape
    if r_max >= 0.5 * box.min():
        raise ValueError(f"r_max = {r_max} must be below half the smallest box edge ({0.5 * box.min():.4g})")
    edges = np.linspace(0.0, r_max, bins + 1)
    tree = cKDTree(pos, boxsize=box)
    # ordered pairs with distance <= r; the N self pairs sit in cum[0] and drop out of the diff
    cum = tree.count_neighbors(tree, edges).astype(float)
    pairs = np.diff(cum)
    unit = math.pi if d == 2 else 4.0 * math.pi / 3.0
    shell = unit * (edges[1:] ** d - edges[:-1] ** d)
    ideal = n * (n - 1) * shell / np.prod(box)
    return 0.5 * (edges[1:] + edges[:-1]), pairs / ideal


def density_field(positions, box, bins, radii=None, quantity="packing"):
    """Coarse-grained density on a regular grid (nearest-cell assignment).

    Parameters
    ----------
    positions : array (N, d)
    box : array (d,)
    bins : int or sequence of d ints
        Cells per axis.
    radii : array (N,) or float, optional
        Particle radii (default 0.5) for ``quantity="packing"``.
    quantity : {"packing", "number", "count"}
        Local packing fraction, number density, or raw counts.

    Returns
    -------
    field : array of shape ``bins`` (index order x, y[, z])
    """
    pos = wrap(positions, box)
    box = np.asarray(box, dtype=float)
    n, d = pos.shape
    bins = np.broadcast_to(np.asarray(bins, dtype=int), (d,))
    weights = None
    if quantity == "packing":
        r = np.broadcast_to(np.asarray(0.5 if radii is None else radii, dtype=float), (n,))
        weights = particle_volume(2.0 * r, d)
    elif quantity not in ("number", "count"):
        raise ValueError(f"quantity must be 'packing', 'number' or 'count', got {quantity!r}")
    field, _ = np.histogramdd(pos, bins=bins, range=[(0.0, L) for L in box], weights=weights)
    if quantity == "count":
        return field
    return field / np.prod(box / bins)
