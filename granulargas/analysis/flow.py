"""Coarse-grained flow: velocity field, vorticity and the flow's energy spectrum.

The velocity field is the mass-weighted mean velocity per cell of a regular grid,
``u = sum m v / sum m`` (zero in empty cells). Derivatives are spectral (exact
for the discrete Fourier modes of the periodic grid): ``d/dx -> i k_x``, with the
Nyquist mode dropped. Vorticity: the scalar ``w = d_x u_y - d_y u_x`` in 2D, the
vector ``curl u`` in 3D; shear modes of the cooling gas show as large-scale
vortices (Goldhirsch & Zanetti 1993).

Energy spectrum: with ``u_hat(k) = FFT(u) / N_cells``, Parseval gives
``mean(|u|^2)/2 = sum_k |u_hat(k)|^2 / 2``; ``E(k)`` collects that sum over shells
of ``|k|`` (width ``2 pi / L``), so ``sum E = mean(|u|^2)/2`` over cells.
"""

from __future__ import annotations

import numpy as np

from granulargas.analysis.structure import wrap

__all__ = ["velocity_field", "vorticity", "energy_spectrum"]


def velocity_field(positions, velocities, box, bins, masses=None, remove_mean=True):
    """Mass-weighted mean velocity per cell.

    Parameters
    ----------
    positions, velocities : arrays (N, d)
    box : array (d,)
    bins : int or d ints
    masses : array (N,), optional
    remove_mean : bool
        Subtract the centre-of-mass velocity first.

    Returns
    -------
    u : array (*bins, d)
        Cell velocities (0 in empty cells).
    mass : array bins
        Mass per cell.
    """
    pos = wrap(positions, box)
    box = np.asarray(box, dtype=float)
    v = np.asarray(velocities, dtype=float)
    n, d = pos.shape
    m = np.ones(n) if masses is None else np.broadcast_to(np.asarray(masses, dtype=float), (n,))
    if remove_mean:
        v = v - (m[:, None] * v).sum(axis=0) / m.sum()
    bins = tuple(np.broadcast_to(np.asarray(bins, dtype=int), (d,)))
    rng = [(0.0, L) for L in box]
    mass, _ = np.histogramdd(pos, bins=bins, range=rng, weights=m)
    u = np.zeros(bins + (d,))
    for a in range(d):
        mom, _ = np.histogramdd(pos, bins=bins, range=rng, weights=m * v[:, a])
        np.divide(mom, mass, out=u[..., a], where=mass > 0)
    return u, mass


def _wavevectors(shape, box):
    ks = []
    for n, L in zip(shape, box):
        k = 2.0 * np.pi * np.fft.fftfreq(n, d=L / n)
        if n % 2 == 0:
            k[n // 2] = 0.0  # drop Nyquist in derivatives
        ks.append(k)
    return np.meshgrid(*ks, indexing="ij")


def _deriv(f, k):
    return np.real(np.fft.ifftn(1j * k * np.fft.fftn(f)))


def vorticity(u, box):
    """Vorticity of a periodic grid velocity field.

    Parameters
    ----------
    u : array (*shape, d)
    box : array (d,)

    Returns
    -------
    array shape (2D, scalar) or (*shape, 3) (3D)
    """
    d = u.shape[-1]
    K = _wavevectors(u.shape[:-1], box)
    if d == 2:
        return _deriv(u[..., 1], K[0]) - _deriv(u[..., 0], K[1])
    w = np.empty_like(u)
    w[..., 0] = _deriv(u[..., 2], K[1]) - _deriv(u[..., 1], K[2])
    w[..., 1] = _deriv(u[..., 0], K[2]) - _deriv(u[..., 2], K[0])
    w[..., 2] = _deriv(u[..., 1], K[0]) - _deriv(u[..., 0], K[1])
    return w


def energy_spectrum(u, box):
    """Shell-summed kinetic energy spectrum of a periodic grid velocity field.

    Returns
    -------
    k : array (B,)
        Shell centres, multiples of ``2 pi / max(L)`` (shell 0 = mean flow excluded).
    E : array (B,)
        Energy per shell, ``sum_k E = mean(|u|^2)/2`` minus the mean-flow part.
    """
    shape = u.shape[:-1]
    box = np.asarray(box, dtype=float)
    ncell = np.prod(shape)
    e = np.zeros(shape)
    for a in range(u.shape[-1]):
        uh = np.fft.fftn(u[..., a]) / ncell
        e += 0.5 * np.abs(uh) ** 2
    ks = [2.0 * np.pi * np.fft.fftfreq(n, d=L / n) for n, L in zip(shape, box)]
    K = np.meshgrid(*ks, indexing="ij")
    kmag = np.sqrt(sum(k * k for k in K))
    dk = 2.0 * np.pi / box.max()
    idx = np.floor(kmag / dk + 0.5).astype(int).ravel()
    E = np.bincount(idx, e.ravel())
    return dk * np.arange(1, E.size), E[1:]
