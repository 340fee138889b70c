"""Homogeneous granular mixtures: the temperature of each species (Maxwellian approximation).

A mixture of S species of smooth spheres (d = 3) or disks (d = 2): species i has mass
m_i, diameter sigma_i, number density n_i and temperature T_i = m_i <c^2>_i / d; the pair
(i, j) has the coefficient of restitution alpha_ij, contact distance
sigma_ij = (sigma_i + sigma_j)/2 and contact value chi_ij of the pair correlation
(1 in the dilute limit). The mixture's temperature is T = sum_i x_i T_i, x_i = n_i / n.

Cooling rates
-------------
With every species Maxwellian at its own temperature, the energy species i loses per
unit time, -d(n_i d T_i / 2)/dt = (d/2) n_i T_i zeta_i, follows from the collision rule
v_i' = v_i - mu_ji (1 + alpha_ij)(g.n) n (g = v_i - v_j, mu_ji = m_j / (m_i + m_j)).
Garzó & Dufty (1999), Phys. Rev. E 60, 5706, eq. (A5) with a2 = 0 (the Maxwellian
approximation):

    zeta_i = C_d sum_j n_j chi_ij sigma_ij^(d-1) mu_ji (1 + alpha_ij) (2 T_i/m_i + 2 T_j/m_j)^(1/2)
             [1 - (mu_ji / 2)(1 + alpha_ij)(1 + m_i T_j / (m_j T_i))],                      (M1)

    C_d = 4 pi^((d-1)/2) / (d Gamma(d/2))     (8 sqrt(pi)/3 in 3D, 2 sqrt(pi) in 2D).

For one species (or identical ones) (M1) is the Maxwellian cooling rate of a one-component
gas, (1 - alpha^2) omega_0 / d (:func:`granulargas.theory.enskog_cooling_rate` with a2 = 0).

Derivation (the form :func:`cooling_rates` evaluates for any alpha_ij(g_n)). Write
v_i = V + mu_ji g with V the pair's centre-of-mass velocity; for Maxwellians at T_i, T_j
the relative velocity g is Gaussian with variance s^2 = T_i/m_i + T_j/m_j per component
and E[V | g] = (T_i - T_j) g / ((m_i + m_j) s^2). The energy species i gains in a
collision with normal speed u = |g.n|, averaged over V, is

    Delta E_i(u) = -m_i mu_ji (1 + alpha) u^2 [(T_i - T_j) / ((m_i + m_j) s^2) + mu_ji (1 - alpha) / 2],

and the pairs with normal speed in [u, u + du] collide at the rate
n_i n_j chi_ij sigma_ij^(d-1) Omega_d u phi_s(u) du per unit volume (Omega_d = 2 pi^(d/2) / Gamma(d/2)
the solid angle, phi_s the Gaussian density of one component of g), so

    zeta_i = (2 / (d n_i T_i)) sum_j n_i n_j chi_ij sigma_ij^(d-1) Omega_d
             integral_0^inf u phi_s(u) (-Delta E_i(u)) du.                                   (M2)

A constant alpha gives (M1) (the u^3 moment of phi_s is s^3 sqrt(2/pi)); a restitution that
depends on the impact speed (viscoelastic particles: alpha_ij(u) = eps(b_ij u^(1/5))) is
integrated by Gauss-Laguerre quadrature in u^2 / (2 s^2).

Homogeneous cooling state (HCS)
-------------------------------
After a transient of a few collisions per particle the species cool at one rate,
zeta_1 = ... = zeta_S, with constant temperature ratios (Garzó & Dufty 1999, eq. (3.3));
:func:`hcs_temperature_ratios` solves these S - 1 equations. The Maxwellian approximation is
accurate to a few per cent against DSMC and MD for the dilute gas at moderate inelasticity
(Montanero & Garzó 2002; Dahl, Hrenya, Garzó & Dufty 2002). The equal temperatures of a
Maxwellian start relax to the HCS ratios by the balance equations d T_i/dt = -zeta_i T_i
(:func:`temperature_history`).

Driven steady states
--------------------
White noise acting on every particle with velocity-kick variance proportional to
m_i^(-q) per unit time heats species i as dT_i/dt = H_i with H_i proportional to m_i^(1-q);
the steady state has zeta_i T_i = H_i (:func:`driven_temperature_ratios`):

* ``"equal_heating"`` (q = 1): velocity kicks of variance H / m_i, the same dT_i/dt = H for
  every species; then zeta_i T_i is the same for all. This is granulargas's driving
  (:mod:`granulargas.engine._drive`, eq. (1));
* ``"equal_acceleration"`` (q = 0): the same acceleration variance for every particle:
  zeta_i T_i / m_i equal (Barrat & Trizac 2002);
* ``"equal_force"`` (q = 2): the same force variance: zeta_i T_i m_i equal.

Contact values of a mixture
---------------------------
3D: Boublík (1970), Grundke & Henderson (1972), Lee & Levesque (1973), Mansoori,
Carnahan, Starling & Leland (1971) (BGHLM),

    chi_ij = 1/(1 - phi) + 3 xi_2 s_ij / (1 - phi)^2 + 2 xi_2^2 s_ij^2 / (1 - phi)^3,
    s_ij = sigma_i sigma_j / (sigma_i + sigma_j),  xi_2 = (pi/6) sum_k n_k sigma_k^2;

2D: Jenkins & Mancini (1987), chi_ij = 1/(1 - phi) + (9/16) phi/(1 - phi)^2 (sigma_i sigma_j M_1)/(sigma_ij M_2),
M_p = sum_k x_k sigma_k^p. With equal diameters they are the Carnahan-Starling and Henderson
contact values (:func:`granulargas.theory.contact_value` with ``form="closed"``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from granulargas.theory.enskog import _check_dim, particle_volume

__all__ = [
    "Mixture",
    "NOISES",
    "mixture_contact_values",
    "mixture_cooling_rates",
    "hcs_temperature_ratios",
    "driven_temperature_ratios",
    "temperature_history",
]

#: White-noise driving of a mixture (module docstring): the exponent q of the
#: velocity-kick variance m_i^(-q); granulargas's driving is "equal_heating".
NOISES = {"equal_acceleration": 0.0, "equal_heating": 1.0, "equal_force": 2.0}

_LAGUERRE_NODES = 48


def _c_d(dim: int) -> float:
    return 4.0 * math.pi ** ((dim - 1) / 2.0) / (dim * math.gamma(dim / 2.0))


def _species_arrays(masses, diameters, densities):
    m = np.atleast_1d(np.asarray(masses, dtype=float))
    s = np.atleast_1d(np.asarray(diameters, dtype=float))
    n = np.atleast_1d(np.asarray(densities, dtype=float))
    if not (m.shape == s.shape == n.shape and m.ndim == 1 and m.size >= 1):
        raise ValueError(f"masses, diameters and densities need one entry per species; shapes "
                         f"{m.shape}, {s.shape}, {n.shape}")
    if not (np.all(m > 0) and np.all(s > 0) and np.all(n >= 0)):
        raise ValueError("masses and diameters must be > 0, densities >= 0")
    return m, s, n


def _pair_matrix(value, size: int, name: str) -> np.ndarray:
    a = np.asarray(value, dtype=float)
    if a.ndim == 0:
        return np.full((size, size), float(a))
    if a.shape != (size, size):
        raise ValueError(f"{name}: shape {a.shape}, expected ({size}, {size}) or one number")
    if not np.array_equal(a, a.T):
        raise ValueError(f"{name}: must be symmetric (a property of the pair)")
    return a


def mixture_contact_values(diameters, densities, dim: int = 3) -> np.ndarray:
    """Contact values chi_ij (S, S) of a hard-sphere (BGHLM) or hard-disk (Jenkins & Mancini
    1987) mixture at number densities ``densities`` (module docstring).

    Parameters
    ----------
    diameters, densities : arrays (S,)
        Diameter and number density of each species (reduced units).
    dim : {2, 3}
    """
    _check_dim(dim)
    s = np.atleast_1d(np.asarray(diameters, dtype=float))
    n = np.atleast_1d(np.asarray(densities, dtype=float))
    phi = float(np.sum(n * particle_volume(s, dim)))
    if not 0.0 <= phi < 1.0:
        raise ValueError(f"packing fraction {phi} outside [0, 1)")
    si, sj = np.meshgrid(s, s, indexing="ij")
    first = 1.0 / (1.0 - phi)
    if dim == 3:
        xi2 = math.pi / 6.0 * float(np.sum(n * s**2))
        sij = si * sj / (si + sj)
        return first + 3.0 * xi2 * sij / (1.0 - phi) ** 2 + 2.0 * (xi2 * sij) ** 2 / (1.0 - phi) ** 3
    total = float(np.sum(n))
    if total == 0.0:
        return np.full((s.size, s.size), 1.0)
    x = n / total
    m1, m2 = float(np.sum(x * s)), float(np.sum(x * s**2))
    return first + 9.0 / 16.0 * phi / (1.0 - phi) ** 2 * (si * sj * m1) / (0.5 * (si + sj) * m2)


@functools.lru_cache(maxsize=None)
def _laguerre(nodes: int = _LAGUERRE_NODES):
    """Nodes and weights of integral_0^inf e^-x f(x) dx (computed once, read-only)."""
    x, w = np.polynomial.laguerre.laggauss(nodes)
    x.flags.writeable = w.flags.writeable = False
    return x, w


def mixture_cooling_rates(temperatures, masses, diameters, densities, restitution, dim: int = 3,
                          chi=None) -> np.ndarray:
    """Cooling rates zeta_i (S,) of a mixture of Maxwellians, eq. (M1) or (M2).

    Parameters
    ----------
    temperatures, masses, diameters, densities : arrays (S,)
        T_i, m_i, sigma_i and number density n_i of each species.
    restitution : float, array (S, S), or callable
        alpha_ij: one number, a symmetric matrix, or ``restitution(i, j, u)`` returning
        alpha_ij at normal impact speeds ``u`` (an array; viscoelastic particles).
    dim : {2, 3}
    chi : float or array (S, S), optional
        Contact values chi_ij (default 1: the dilute limit, Boltzmann).

    Returns
    -------
    array (S,)
        zeta_i, in dT_i/dt = -zeta_i T_i.
    """
    _check_dim(dim)
    m, sig, n = _species_arrays(masses, diameters, densities)
    size = m.size
    temp = np.atleast_1d(np.asarray(temperatures, dtype=float))
    if temp.shape != m.shape or not np.all(temp > 0):
        raise ValueError(f"temperatures: need {size} values > 0, got {temp}")
    chi_m = _pair_matrix(1.0 if chi is None else chi, size, "chi")
    sij = 0.5 * (sig[:, None] + sig[None, :])
    pref = _c_d(dim)
    zeta = np.zeros(size)
    if callable(restitution):
        x, w = _laguerre()
        # every pair (i, j) at once, axes (i, j, node)
        mu = m[None, :] / (m[:, None] + m[None, :])
        s2 = (temp / m)[:, None] + (temp / m)[None, :]
        # u = s sqrt(2 x): integral_0^inf u^3 phi_s(u) F(u) du = s^3 sqrt(2/pi) * int e^-x x F dx
        u = np.sqrt(2.0 * s2[..., None] * x)
        a = np.array([[np.asarray(restitution(i, j, u[i, j]), dtype=float) for j in range(size)]
                      for i in range(size)])
        bracket = ((temp[:, None] - temp[None, :]) / ((m[:, None] + m[None, :]) * s2))[..., None] \
            + (0.5 * mu)[..., None] * (1.0 - a)
        mean = np.sum(w * x * (1.0 + a) * bracket, axis=-1)
        # float_power: pow() as for one pair (an array's ** 1.5 rounds differently)
        terms = n[None, :] * chi_m * sij ** (dim - 1) * mu * m[:, None] / temp[:, None] * np.float_power(s2, 1.5) * mean
        for j in range(size):
            zeta += terms[:, j]
        return math.sqrt(2.0) * pref * zeta
    alpha = _pair_matrix(restitution, size, "restitution")
    for i in range(size):
        for j in range(size):
            mu = m[j] / (m[i] + m[j])
            a = alpha[i, j]
            speed = math.sqrt(2.0 * temp[i] / m[i] + 2.0 * temp[j] / m[j])
            bracket = 1.0 - 0.5 * mu * (1.0 + a) * (1.0 + m[i] * temp[j] / (m[j] * temp[i]))
            zeta[i] += n[j] * chi_m[i, j] * sij[i, j] ** (dim - 1) * mu * (1.0 + a) * speed * bracket
    return pref * zeta


def _solve_ratios(residual: Callable[[np.ndarray], np.ndarray], size: int) -> np.ndarray:
    """Solve residual(g) = 0 for the S - 1 log-ratios g_i = ln(T_i / T_1), i >= 1."""
    from scipy.optimize import brentq, least_squares  # here, not at the top: a run's start-up loads no scipy

    if size == 1:
        return np.zeros(0)
    if size == 2:
        f = lambda g: float(residual(np.array([g]))[0])  # noqa: E731
        lo, hi = -1.0, 1.0
        while f(lo) * f(hi) > 0.0:
            lo, hi = 2.0 * lo, 2.0 * hi
            if hi > 200.0:
                raise ValueError("no temperature ratio found in exp(+-200)")
        return np.array([brentq(f, lo, hi, xtol=1e-15, rtol=1e-15, maxiter=500)])
    sol = least_squares(residual, np.zeros(size - 1), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    if not sol.success or np.max(np.abs(sol.fun)) > 1e-10:
        raise ValueError(f"temperature ratios not found ({sol.message})")
    return sol.x


def _ratios(masses, diameters, fractions, restitution, dim, packing, weight):
    m, sig, x = _species_arrays(masses, diameters, fractions)
    if not math.isclose(float(np.sum(x)), 1.0, rel_tol=1e-9):
        raise ValueError(f"fractions must add up to 1, got {float(np.sum(x))}")
    # number densities for the packing fraction (dilute: any scale, the ratios do not depend on it)
    v = float(np.sum(x * particle_volume(sig, dim)))
    total = packing / v if packing > 0.0 else 1.0
    n = x * total
    chi = mixture_contact_values(sig, n, dim) if packing > 0.0 else None

    def residual(g):
        temp = np.exp(np.concatenate(([0.0], g)))
        zeta = mixture_cooling_rates(temp, m, sig, n, restitution, dim, chi) * weight(temp, m)
        return (zeta[1:] - zeta[0]) / (np.abs(zeta[1:]) + abs(zeta[0]))

    temp = np.exp(np.concatenate(([0.0], _solve_ratios(residual, m.size))))
    return temp / float(np.sum(x * temp))


def hcs_temperature_ratios(masses, diameters, fractions, restitution, dim: int = 3,
                           packing: float = 0.0) -> np.ndarray:
    """Temperatures T_i / T (S,) of the homogeneous cooling state, T = sum_i x_i T_i.

    Garzó & Dufty (1999): all zeta_i of eq. (M1) equal (module docstring).

    Parameters
    ----------
    masses, diameters : arrays (S,)
    fractions : array (S,)
        Number fractions x_i (sum 1).
    restitution : float, array (S, S) or callable
        As :func:`mixture_cooling_rates`.
    dim : {2, 3}
    packing : float
        Packing fraction (0: dilute, chi_ij = 1; else the Enskog chi_ij of
        :func:`mixture_contact_values`).

    Returns
    -------
    array (S,)
        T_i / T; T_1 / T_2 = ratios[0] / ratios[1].
    """
    return _ratios(masses, diameters, fractions, restitution, dim, packing, lambda t, m: 1.0)


def driven_temperature_ratios(masses, diameters, fractions, restitution, dim: int = 3,
                              packing: float = 0.0, noise: str = "equal_heating") -> np.ndarray:
    """Temperatures T_i / T (S,) of the white-noise driven steady state (module docstring):
    zeta_i T_i / m_i^(1 - q) equal, q of :data:`NOISES` (granulargas's driving: ``"equal_heating"``).

    Arguments as :func:`hcs_temperature_ratios`, and ``noise`` one of :data:`NOISES`.
    """
    if noise not in NOISES:
        raise ValueError(f"noise = {noise!r}: one of {', '.join(NOISES)}")
    q = NOISES[noise]
    return _ratios(masses, diameters, fractions, restitution, dim, packing,
                   lambda t, m: t / m ** (1.0 - q))


def temperature_history(times, initial, masses, diameters, densities, restitution, dim: int = 3,
                        chi=None) -> np.ndarray:
    """T_i(t) (len(times), S) of a cooling mixture of Maxwellians: dT_i/dt = -zeta_i T_i, eq. (M1)/(M2).

    From ``initial`` temperatures (S,) at t = 0 (``times`` >= 0, increasing); integrated
    in ln T_i against x = ln(1 + t / t_0) (t_0 the smallest 1/zeta_i at the start), which
    keeps the step count small over many decades of cooling (scipy ``solve_ivp``, LSODA,
    relative tolerance 1e-10).
    """
    from scipy.integrate import solve_ivp

    t = np.asarray(times, dtype=float)
    t0 = np.atleast_1d(np.asarray(initial, dtype=float))
    if t.ndim != 1 or (t.size and (t[0] < 0 or np.any(np.diff(t) < 0))):
        raise ValueError("times must be increasing and >= 0")
    zeta0 = mixture_cooling_rates(t0, masses, diameters, densities, restitution, dim, chi)
    scale = 1.0 / float(np.max(np.abs(zeta0)))

    def rhs(x, y):
        dt_dx = scale * math.exp(x)
        return -mixture_cooling_rates(np.exp(y), masses, diameters, densities, restitution, dim, chi) * dt_dx

    xs = np.log1p(t / scale)
    if t.size == 0:
        return np.zeros((0, t0.size))
    sol = solve_ivp(rhs, (0.0, float(xs[-1]) if xs[-1] > 0 else 1e-12), np.log(t0), method="LSODA",
                    t_eval=xs, rtol=1e-10, atol=1e-12)
    if not sol.success:
        raise ValueError(f"temperature_history: {sol.message}")
    return np.exp(sol.y.T)


@dataclass(frozen=True)
class Mixture:
    """A homogeneous mixture for the theory of this module: what a run's config or file holds.

    Attributes
    ----------
    names : tuple of str
    masses, diameters, counts : tuples (S,)
    dimension : int
    number_density : float
        Total number density n (particles per volume; reduced units).
    restitution : tuple of tuples (S, S) or None
        Constant eps_ij (None: viscoelastic, ``prefactor``; both None: elastic).
    prefactor : tuple of tuples (S, S) or None
        Viscoelastic k_ij: eps_ij(u) = eps(beta), beta = k_ij (R_eff u / m_eff^2)^(1/5), the
        contact's eps(beta) of :mod:`granulargas.contact` (``end``).
    end : str
        The contact's end ("overlap" or "force").
    chi : tuple of tuples (S, S) or None
        Contact values (None: the dilute limit, 1).
    """

    names: tuple
    masses: tuple
    diameters: tuple
    counts: tuple
    dimension: int = 3
    number_density: float = 0.0
    restitution: tuple | None = None
    prefactor: tuple | None = None
    end: str = "overlap"
    chi: tuple | None = None

    @property
    def fractions(self) -> np.ndarray:
        c = np.asarray(self.counts, dtype=float)
        return c / c.sum()

    @property
    def densities(self) -> np.ndarray:
        """Number density of each species."""
        return self.fractions * self.number_density

    def restitution_law(self):
        """What :func:`mixture_cooling_rates` takes: the (S, S) eps_ij, or for viscoelastic
        particles a function ``eps(i, j, u)`` of the normal impact speed."""
        size = len(self.names)
        if self.prefactor is None:
            return np.ones((size, size)) if self.restitution is None else np.array(self.restitution)
        from granulargas.contact.material import pair_constant
        from granulargas.contact.table import restitution_table

        m = np.asarray(self.masses, dtype=float)
        r = 0.5 * np.asarray(self.diameters, dtype=float)
        k = np.asarray(self.prefactor, dtype=float)
        b = np.array([[float(pair_constant(k[i, j], r[i], r[j], m[i], m[j])) for j in range(size)]
                      for i in range(size)])
        cache = {}

        def eps(i, j, u):
            # the table reaches beta = 40; the quadrature's fastest nodes (weights below e^-100)
            # may lie beyond it, and get its end value
            beta = np.minimum(b[i, j] * np.asarray(u, dtype=float) ** 0.2, 39.0)
            top = float(np.max(beta)) if np.size(beta) else 0.0
            table, limit = cache.get("table", (None, 0.0))
            if limit <= top:
                table = restitution_table(min(max(top * 1.5, 1.0), 39.5), end=self.end)
                cache["table"] = table, table.beta_limit
            return table.restitution(beta)
        return eps

    @functools.cached_property
    def _law(self):
        """:meth:`restitution_law`, made once (its table is loaded once and grows as needed)."""
        return self.restitution_law()

    def _args(self):
        chi = None if self.chi is None else np.asarray(self.chi, dtype=float)
        return (np.asarray(self.masses, dtype=float), np.asarray(self.diameters, dtype=float), self.densities,
                self._law, self.dimension, chi)

    def cooling_rates(self, temperatures) -> np.ndarray:
        """zeta_i (S,) at the species' temperatures (:func:`mixture_cooling_rates`)."""
        m, s, n, law, d, chi = self._args()
        return mixture_cooling_rates(temperatures, m, s, n, law, d, chi)

    def temperature_history(self, times, initial) -> np.ndarray:
        """T_i(t) (len(times), S) from ``initial`` temperatures (:func:`temperature_history`)."""
        m, s, n, law, d, chi = self._args()
        return temperature_history(times, initial, m, s, n, law, d, chi)

    def collision_frequencies(self, temperatures) -> np.ndarray:
        """Collisions per unit time of a particle of each species (S,), Maxwellians at
        ``temperatures``: nu_i = sum_j K_d chi_ij n_j sigma_ij^(d-1) ((T_i/m_i + T_j/m_j)/2)^(1/2),
        K_d = 2 pi^((d-1)/2) / Gamma(d/2) (the mean relative speed times the cross section; one
        species: the Enskog frequency of :func:`granulargas.theory.collision_frequency`)."""
        m, sig, n, _, d, chi = self._args()
        temp = np.asarray(temperatures, dtype=float)
        chi = np.ones((m.size, m.size)) if chi is None else chi
        k_d = 2.0 * math.pi ** ((d - 1) / 2.0) / math.gamma(d / 2.0)
        sij = 0.5 * (sig[:, None] + sig[None, :])
        speed = np.sqrt(0.5 * (temp / m)[:, None] + 0.5 * (temp / m)[None, :])
        return k_d * np.sum(chi * n[None, :] * sij ** (d - 1) * speed, axis=1)

    def predicted_end(self, temperature: float, end_time: float | None = None,
                      collisions_per_particle: float | None = None) -> tuple[float, np.ndarray]:
        """(t_end, T_i at t_end) of a cooling run from every species at ``temperature``: the
        balance dT_i/dt = -zeta_i T_i with the collisions per particle ds/dt = sum_i x_i nu_i,
        up to ``end_time`` or ``collisions_per_particle`` (s = 2 C / N), whichever comes first."""
        from scipy.integrate import solve_ivp

        if end_time is None and collisions_per_particle is None:
            raise ValueError("predicted_end needs end_time or collisions_per_particle")
        size = len(self.names)
        t0 = np.full(size, float(temperature))
        x = self.fractions
        zeta0 = self.cooling_rates(t0)
        nu0 = float(x @ self.collision_frequencies(t0))
        scale = 1.0 / max(float(np.max(np.abs(zeta0))), nu0)

        def rhs(u, y):
            dt_du = scale * math.exp(u)
            temps = np.exp(y[:size])
            return np.concatenate((-self.cooling_rates(temps) * dt_du,
                                   [float(x @ self.collision_frequencies(temps)) * dt_du]))

        events = []
        if collisions_per_particle is not None:
            def reached(u, y):
                return y[size] - collisions_per_particle
            reached.terminal = True
            events.append(reached)
        u_end = math.log1p(end_time / scale) if end_time is not None else 200.0
        sol = solve_ivp(rhs, (0.0, u_end), np.concatenate((np.log(t0), [0.0])), method="LSODA", rtol=1e-9,
                        atol=1e-12, events=events or None)
        if sol.status == -1:
            raise ValueError(f"predicted_end: {sol.message}")
        u = float(sol.t[-1])
        return scale * math.expm1(u), np.exp(sol.y[:size, -1])

    def _balance(self, weight, guess_temperature: float) -> np.ndarray:
        """T_i / T with zeta_i T_i weight_i equal, the rates evaluated at mixture temperature
        ``guess_temperature`` (the constant-eps ratios do not depend on it)."""
        m, s, n, law, d, chi = self._args()
        x = self.fractions

        def residual(g):
            temp = np.exp(np.concatenate(([0.0], g)))
            temp = temp / float(np.sum(x * temp)) * guess_temperature
            zeta = mixture_cooling_rates(temp, m, s, n, law, d, chi) * weight(temp, m)
            return (zeta[1:] - zeta[0]) / (np.abs(zeta[1:]) + abs(zeta[0]))

        temp = np.exp(np.concatenate(([0.0], _solve_ratios(residual, m.size))))
        return temp / float(np.sum(x * temp))

    def hcs_ratios(self, temperature: float = 1.0) -> np.ndarray:
        """T_i / T of the homogeneous cooling state (eq. (M1) with equal zeta_i); viscoelastic
        particles: the quasi-static ratios at mixture temperature ``temperature``."""
        return self._balance(lambda t, m: 1.0, temperature)

    def driven_ratios(self, noise: str = "equal_heating", temperature: float = 1.0) -> np.ndarray:
        """T_i / T of the white-noise driven state (:func:`driven_temperature_ratios`)."""
        if noise not in NOISES:
            raise ValueError(f"noise = {noise!r}: one of {', '.join(NOISES)}")
        q = NOISES[noise]
        return self._balance(lambda t, m: t / m ** (1.0 - q), temperature)
