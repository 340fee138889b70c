"""Observables of a particle sample: kinetic energy, momentum, temperature, Sonine coefficients a2, a3
(and per species of a mixture, :func:`species_moments`).

With c_i the peculiar velocity (velocity minus the mass-weighted mean) and
e_i = m_i c_i^2, the temperature is T = <e>/d (k_B = 1) and

    a2 = d/(d+2) <e^2>/<e>^2 - 1,
    a3 = 1 + 3 a2 - d^2/((d+2)(d+4)) <e^3>/<e>^3,

which for identical particles are the coefficients of the second and third
Sonine polynomials in the expansion of the velocity distribution about the
Maxwellian, from <c^(2p)>/<c^(2p)>_Maxwell = sum_k (-1)^k binom(p, k) a_k
(van Noije & Ernst 1998; Brilliantov & Pöschel 2006, "Breakdown of the Sonine
expansion for the velocity distribution of granular gases", EPL 74, 424).
For unequal masses they are the cumulants of the distribution of m c^2.

Finite samples: for N identical particles of fixed energy and momentum (any elastic
simulation), the exact ensemble averages are a2 = -2/(D+2) and
a3 = -16/((D+2)(D+4)) with D = d(N - 1), so the a2 estimator is biased by
about -2/(d N).

A compiled two-pass kernel does the sums without temporary arrays; it reads
the first ``d`` columns of a (N, >= d) velocity array, so padded layouts need
no copy.

Rough particles (spins w, moments of inertia I_i = kappa m_i R_i^2): with
``x_i = m_i c_i^2`` and ``y_i = I_i w_i^2`` (no mean is subtracted from the spins),
``T_tr = <x>/d_t``, ``T_rot = <y>/d_r`` and the cumulants of Megías & Santos (2023)

    a20 = d_t/(d_t+2) <x^2>/<x>^2 - 1,   a02 = d_r/(d_r+2) <y^2>/<y>^2 - 1,
    a11 = <x y>/(<x><y>) - 1,

i.e. ``<c^4>``, ``<w^4>`` and ``<c^2 w^2>`` of the velocities scaled by the translational
and the spins by the rotational temperature; a20 is a2 above. 2D: d_t = 2, d_r = 1 (the
spin along z), 3D: 3 and 3 (:func:`rough_moments`).
"""

from __future__ import annotations

import numpy as np

from granulargas._numba import inlined_ir, kernel


@inlined_ir
def _momentum_and_largest(v, dim, masses, shared):
    """(p_x, p_y, p_z, total mass, largest |velocity component|) of ``v[:, :dim]``."""
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    msum = 0.0
    vmax = 0.0
    for i in range(v.shape[0]):
        m = masses[0] if shared else masses[i]
        msum += m
        p0 += m * v[i, 0]
        p1 += m * v[i, 1]
        vmax = max(vmax, abs(v[i, 0]), abs(v[i, 1]))
        if dim == 3:
            p2 += m * v[i, 2]
            vmax = max(vmax, abs(v[i, 2]))
    return p0, p1, p2, msum, vmax


@inlined_ir
def _scaled_peculiar_energy(v, i, dim, m, scale, u0, u1, u2):
    """m_i c_i^2 of the velocity of row i times ``scale``, less the scaled mean (u0, u1, u2)."""
    c0 = v[i, 0] * scale - u0
    c1 = v[i, 1] * scale - u1
    e = c0 * c0 + c1 * c1
    if dim == 3:
        c2 = v[i, 2] * scale - u2
        e += c2 * c2
    return e * m


@kernel
def energy_moments(v, dim, masses):
    """(T, a2, a3) of the velocities ``v[:, :dim]`` with masses (N,) or one shared mass (1,).

    The sums run over velocities divided by the largest component, so moments of
    gases cooled far below unit speeds neither underflow nor lose precision.
    """
    n = v.shape[0]
    shared = masses.shape[0] == 1
    p0, p1, p2, msum, vmax = _momentum_and_largest(v, dim, masses, shared)
    if not vmax > 0.0:
        return 0.0, np.nan, np.nan
    scale = 1.0 / vmax
    u0 = p0 / msum * scale
    u1 = p1 / msum * scale
    u2 = p2 / msum * scale
    s1 = 0.0
    s2 = 0.0
    s3 = 0.0
    for i in range(n):
        e = _scaled_peculiar_energy(v, i, dim, masses[0] if shared else masses[i], scale, u0, u1, u2)
        s1 += e
        s2 += e * e
        s3 += e * e * e
    if s1 <= 0.0:
        return 0.0, np.nan, np.nan
    r2 = s2 * n / (s1 * s1)
    r3 = s3 * n * n / (s1 * s1 * s1)
    a2 = dim / (dim + 2.0) * r2 - 1.0
    a3 = 1.0 + 3.0 * a2 - dim * dim / ((dim + 2.0) * (dim + 4.0)) * r3
    return s1 * vmax * vmax / (dim * n), a2, a3


@kernel
def kinetic_energy_momentum(v, dim, masses):
    """(sum m v^2 / 2, p_x, p_y, p_z) of the velocities ``v[:, :dim]`` (p_z = 0 in 2D),
    masses (N,) or one shared mass (1,); no temporary arrays."""
    shared = masses.shape[0] == 1
    e = 0.0
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    for i in range(v.shape[0]):
        m = masses[0] if shared else masses[i]
        w2 = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1]
        p0 += m * v[i, 0]
        p1 += m * v[i, 1]
        if dim == 3:
            w2 += v[i, 2] * v[i, 2]
            p2 += m * v[i, 2]
        e += m * w2
    return 0.5 * e, p0, p1, p2


@kernel
def rough_moments(v, dim, masses, w, inertia):
    """(T_tr, T_rot, a20, a02, a11) of velocities ``v[:, :dim]`` and spins ``w`` (module docstring).

    ``w`` (N, 3) or (N, 1): 3D uses its three columns, 2D its last (the z spin); ``inertia``
    (N,) the moments of inertia I_i or one shared value (1,); ``masses`` as
    :func:`energy_moments`. Velocities and spins are scaled by their largest components
    (no underflow in gases cooled far below unit speeds). nan cumulants when either
    temperature is 0.
    """
    n = v.shape[0]
    shared = masses.shape[0] == 1
    ishared = inertia.shape[0] == 1
    dr = 3 if dim == 3 else 1
    c0 = w.shape[1] - dr  # first spin column used
    p0, p1, p2, msum, vmax = _momentum_and_largest(v, dim, masses, shared)
    wmax = 0.0
    for i in range(n):
        for a in range(dr):
            wmax = max(wmax, abs(w[i, c0 + a]))
    vs = 1.0 / vmax if vmax > 0.0 else 1.0
    ws = 1.0 / wmax if wmax > 0.0 else 1.0
    u0 = p0 / msum * vs
    u1 = p1 / msum * vs
    u2 = p2 / msum * vs
    sx = 0.0
    sxx = 0.0
    sy = 0.0
    syy = 0.0
    sxy = 0.0
    for i in range(n):
        x = _scaled_peculiar_energy(v, i, dim, masses[0] if shared else masses[i], vs, u0, u1, u2)
        y = 0.0
        for a in range(dr):
            y += (w[i, c0 + a] * ws) ** 2
        y *= inertia[0] if ishared else inertia[i]
        sx += x
        sxx += x * x
        sy += y
        syy += y * y
        sxy += x * y
    t_tr = sx / (dim * n) / (vs * vs)
    t_rot = sy / (dr * n) / (ws * ws)
    a20 = dim / (dim + 2.0) * sxx * n / (sx * sx) - 1.0 if sx > 0.0 else np.nan
    a02 = dr / (dr + 2.0) * syy * n / (sy * sy) - 1.0 if sy > 0.0 else np.nan
    a11 = sxy * n / (sx * sy) - 1.0 if sx > 0.0 and sy > 0.0 else np.nan
    return t_tr, t_rot, a20, a02, a11


def rotational_observables(velocities, spins, masses, inertia) -> dict:
    """``temperature``, ``rotational_temperature``, ``cumulant_a20``, ``cumulant_a02``,
    ``cumulant_a11`` of a sample of rough particles (:func:`rough_moments`).

    ``spins`` (N, 3) in 3D, (N, 1) or (N, 3) in 2D (the z spin last); ``inertia`` the moments
    of inertia I_i (N,) or one value.
    """
    v, m = _arrays(velocities, masses)
    w = np.ascontiguousarray(spins, dtype=np.float64)
    if w.ndim != 2 or w.shape[0] != v.shape[0] or w.shape[1] not in ((3,) if v.shape[1] == 3 else (1, 3)):
        raise ValueError(f"spins: shape {w.shape}, expected ({v.shape[0]}, {3 if v.shape[1] == 3 else 1})")
    inertia = np.ascontiguousarray(np.atleast_1d(inertia), dtype=np.float64)
    t, tr, a20, a02, a11 = rough_moments(v, v.shape[1], m, w, inertia)
    return {"temperature": float(t), "rotational_temperature": float(tr), "cumulant_a20": float(a20),
            "cumulant_a02": float(a02), "cumulant_a11": float(a11)}


def _arrays(velocities, masses):
    v = np.ascontiguousarray(velocities, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] not in (2, 3):
        raise ValueError(f"velocities: shape {v.shape}, expected (N, 2) or (N, 3)")
    m = np.ones(1) if masses is None else np.ascontiguousarray(np.atleast_1d(masses), dtype=np.float64)
    if m.shape[0] not in (1, v.shape[0]):
        raise ValueError(f"masses: shape {m.shape}, expected (1,) or ({v.shape[0]},)")
    return v, m


def sonine_coefficients(velocities, masses=None) -> tuple[float, float]:
    """(a2, a3) of a velocity sample (N, d); ``masses`` (N,) or None (identical particles)."""
    v, m = _arrays(velocities, masses)
    _, a2, a3 = energy_moments(v, v.shape[1], m)
    return float(a2), float(a3)


def sonine_a2(velocities, masses=None) -> float:
    """Second Sonine coefficient a2 = d/(d+2) <c^4>/<c^2>^2 - 1 of a velocity sample."""
    return sonine_coefficients(velocities, masses)[0]


def sonine_a3(velocities, masses=None) -> float:
    """Third Sonine coefficient a3 = 1 + 3 a2 - d^2/((d+2)(d+4)) <c^6>/<c^2>^3."""
    return sonine_coefficients(velocities, masses)[1]


def species_moments(velocities, masses, species, count: int) -> tuple[np.ndarray, np.ndarray]:
    """(T_s, a2_s), arrays (S,), of each species of a mixture.

    With c the peculiar velocity (velocity minus the mass-weighted mean of the whole gas, the
    mixture's flow velocity) and e = m c^2: T_s = <e>_s / d over the n_s particles of species s
    (Garzó & Dufty 1999: the partial temperatures, T = sum_s x_s T_s) and
    a2_s = d/(d+2) <e^2>_s / <e>_s^2 - 1. ``species`` (N,) ints in [0, count); a species without
    particles gives NaN. Sums over c divided by its largest component (no underflow).
    """
    v, m = _arrays(velocities, masses)
    m = np.broadcast_to(m, (v.shape[0],))
    s = np.asarray(species, dtype=np.int64)
    if s.shape != (v.shape[0],) or (s.size and (s.min() < 0 or s.max() >= count)):
        raise ValueError(f"species: one index in [0, {count}) per particle")
    d = v.shape[1]
    c = v - (m @ v) / m.sum()
    scale = float(np.max(np.abs(c))) if c.size else 0.0
    n = np.bincount(s, minlength=count).astype(np.float64)
    if not scale > 0.0:
        return np.where(n > 0, 0.0, np.nan), np.full(count, np.nan)
    c = c / scale
    e = m * np.einsum("ij,ij->i", c, c)
    e1 = np.bincount(s, e, minlength=count)
    e2 = np.bincount(s, e * e, minlength=count)
    with np.errstate(invalid="ignore", divide="ignore"):
        temperature = np.where(n > 0, e1 / (d * n) * scale * scale, np.nan)
        a2 = np.where(e1 > 0, d / (d + 2.0) * n * e2 / (e1 * e1) - 1.0, np.nan)
    return temperature, a2


def finite_sample_sonine(n: int, dim: int) -> tuple[float, float]:
    """Exact (a2, a3) of N particles uniformly distributed on their energy-momentum shell.

    The uniform law on the sphere of dimension D = d (N - 1) (elastic equilibrium
    at fixed energy and zero momentum) gives a2 = -2/(D+2), a3 = -16/((D+2)(D+4)).
    """
    big_d = dim * (n - 1)
    return -2.0 / (big_d + 2.0), -16.0 / ((big_d + 2.0) * (big_d + 4.0))


def sample_history(sim, times) -> np.ndarray:
    """Run a simulation through ``times`` and sample it at each: rows (T, a2, pair collisions).

    ``sim`` is anything with ``run(until)``, ``velocities``, ``masses`` and ``collisions``:
    the engine's :class:`~granulargas.engine.Simulation` or a :class:`~granulargas.dsmc.DSMC`.
    """
    out = np.empty((len(times), 3))
    for k, t in enumerate(times):
        sim.run(t)
        v, m = _arrays(sim.velocities, sim.masses)
        temperature, a2, _ = energy_moments(v, v.shape[1], m)
        out[k] = temperature, a2, sim.collisions
    return out
