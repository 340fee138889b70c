"""Two-temperature kinetic theory of a gas of rough spheres or disks (Maxwellian approximation).

A rough grain carries an angular velocity w and a moment of inertia
``I = kappa m sigma^2 / 4`` (kappa = 2/5 for a uniform sphere, 1/2 for a uniform disk;
``0 < kappa <= 2/3`` for spheres and ``<= 1`` for disks, no mass outside the surface).
A collision reverses the normal part of the relative velocity g of the contact points
by ``-eps`` and the tangential part by ``-beta_t`` (the tangential restitution:
``beta_t = -1`` smooth, ``+1`` perfectly rough; the collision law and its derivation
are in :mod:`granulargas.engine._rough`). For identical grains the velocity changes
are ``Delta v_1 = -(1 + eps)/2 g_n - b g_t`` with

    b = kappa (1 + beta_t) / (2 (1 + kappa)).                                       (R1)

Energy balances
---------------
The translational and rotational temperatures ``T_tr = m <c^2> / d_t`` and
``T_rot = I <w^2> / d_r`` (``d_t, d_r`` = 3, 3 for spheres and 2, 1 for disks) change
by the mean energy a collision moves. With both distributions Maxwellian (the
approximation of Huthmann & Zippelius 1997 and Luding, Huthmann, McNamara &
Zippelius 1998, here for any d_t, d_r and any laws eps(g_n), beta_t(g_n, g_t))
the averages over the collisions are, per collision and per pair (derivation in the
documentation page "Rough grains"):

    <Delta E_tr>  = -T_tr [ (1 - eps^2)_eff + 2 (d_t - 1) (b1 - b2 - b2 theta / kappa) ],   (R2)
    <Delta E_rot> = -(2 (d_t - 1) / kappa) T_rot [ b1 - b2 / kappa - b2 / theta ],          (R3)

with ``theta = T_rot / T_tr``, ``(1 - eps^2)_eff = <(1 - eps^2) g_n^3> / <g_n^3>``
(:func:`granulargas.theory.gas.effective_inelasticity`) and the averages of b over the
tangential contact velocities, weighted by ``|g_t|^2``:

    b1 = <b |g_t|^2> / <|g_t|^2>,   b2 = <b^2 |g_t|^2> / <|g_t|^2>                         (R4)

(``b1 = b``, ``b2 = b^2`` for a constant beta_t). Then, with ``nu`` the Enskog collision
frequency per particle at T_tr (:func:`granulargas.theory.collision_frequency`, a2 = 0),

    dT_tr/dt = (nu / d_t) <Delta E_tr> + (1 - lambda) H,
    dT_rot/dt = (nu / d_r) <Delta E_rot> + lambda H d_t / d_r,                            (R5)

where the white-noise driving injects the power ``d_t H / 2`` per particle and a
fraction ``lambda`` of it goes to the spins (the splitting thermostat of Megías &
Santos 2022; lambda = 0 heats the translation only, ``dT_tr/dt = H`` without
collisions). For a constant eps and beta_t the cooling rates
``zeta_tr = -d ln T_tr/dt``, ``zeta_rot = -d ln T_rot/dt`` of the free gas are

    zeta_tr  = (nu / d_t) [1 - eps^2 + 2 (d_t - 1) b (1 - b) - 2 (d_t - 1) b^2 theta / kappa],
    zeta_rot = (nu / d_r) (2 (d_t - 1) b / kappa) [1 - b / kappa - b / theta],             (R6)

equal in the homogeneous cooling state, where theta is the positive root of
``theta^2 - 2 h theta - d_t / d_r = 0``:

    theta_HCS = h + sqrt(h^2 + d_t / d_r),
    h = kappa / (4 (d_t - 1) b^2) [1 - eps^2 + 2 (d_t - 1) b (1 - b)
                                   - 2 (d_t - 1) (d_t / d_r) (b / kappa)(1 - b / kappa)]. (R7)

Checks: eps = beta_t = 1 conserves energy and gives theta = 1 (equipartition);
eps = 1, beta_t = 0, kappa = 2/5 (3D) gives theta = 2/5. With the noise on the
translation only, dT_rot/dt = 0 fixes

    theta_st = kappa (1 + beta_t) / (1 + 2 kappa - beta_t),                               (R8)

independent of eps and of the dimension. The Maxwellian theta is a few per cent off
the simulations (Santos, Kremer & dos Santos 2011; Megías & Santos 2022).

Walton's Coulomb model
----------------------
Walton (1993) caps the tangential impulse at mu times the normal one: a contact that
would stick with ``beta_0`` slides instead when the impulse it needs exceeds the
Coulomb limit, ``beta_t = min(beta_0, -1 + mu (1 + eps) (1 + 1/kappa) cot gamma)``
with ``cot gamma = |g_n| / |g_t|`` (Luding et al. 1998), i.e.
``b = min(b_0, mu (1 + eps) |g_n| / (2 |g_t|))``. Under the Maxwellian, ``|g_n|`` has
the collision-weighted law of a Gaussian of variance ``s_n^2 = 2 T_tr / m`` and g_t is a
``(d_t - 1)``-dimensional Gaussian of variance ``s_t^2 = 2 (T_tr + T_rot / kappa) / m``
per component, independent of ``g_n``; for each ``g_n`` the average over ``|g_t|`` in
(R4) is in closed form (incomplete Gaussian moments) and the one over ``g_n`` is a
quadrature. :func:`coulomb_mean_restitution` is the plain mean of beta_t over the
collisions (over the impact angles), the constant "effective" beta_t of Luding et al.
(1998); the exact balances (R4) weight the impact angles differently.

Everything is for identical particles of the mean diameter and mass (as
:mod:`granulargas.theory.gas`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from granulargas.contact import restitution_table
from granulargas.theory.gas import Gas, _kernel_nodes, effective_inelasticity

__all__ = [
    "DEFAULT_INERTIA",
    "MAX_INERTIA",
    "RoughGas",
    "TwoTemperatureCurve",
    "degrees_of_freedom",
    "tangential_factor",
    "hcs_temperature_ratio",
    "steady_temperature_ratio",
    "tangential_moments",
    "coulomb_mean_restitution",
    "energy_change_per_collision",
    "temperature_rates",
    "cooling_rates",
    "hcs_ratio",
    "driven_state",
    "two_temperature_curve",
    "mpemba_crossing_time",
    "smooth_deviation",
]

#: uniform sphere (3D) and uniform disk (2D): kappa = 4 I / (m sigma^2)
DEFAULT_INERTIA = {3: 0.4, 2: 0.5}
#: largest kappa: all the mass on the surface (thin spherical shell 2/3, ring 1)
MAX_INERTIA = {3: 2.0 / 3.0, 2: 1.0}

_NODES = 96


def degrees_of_freedom(dim: int):
    """(d_t, d_r): translational and rotational degrees of freedom, (3, 3) or (2, 1)."""
    if dim == 3:
        return 3, 3
    if dim == 2:
        return 2, 1
    raise ValueError(f"dimension must be 2 or 3, got {dim}")


def tangential_factor(tangential_restitution, inertia):
    """b = kappa (1 + beta_t) / (2 (1 + kappa)) of eq. (R1)."""
    k = np.asarray(inertia, dtype=float)
    out = k * (1.0 + np.asarray(tangential_restitution, dtype=float)) / (2.0 * (1.0 + k))
    return out[()] if out.ndim == 0 else out


def hcs_temperature_ratio(restitution, tangential_restitution, inertia, dim=3):
    """theta = T_rot / T_tr of the homogeneous cooling state, constant eps and beta_t, eq. (R7).

    beta_t = -1 (smooth) leaves the spins alone: no homogeneous cooling ratio (nan).
    """
    d_t, d_r = degrees_of_freedom(dim)
    eps = np.asarray(restitution, dtype=float)
    k = np.asarray(inertia, dtype=float)
    b = np.asarray(tangential_factor(tangential_restitution, k), dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = k / (4.0 * (d_t - 1) * b * b) * (1.0 - eps * eps + 2.0 * (d_t - 1) * b * (1.0 - b)
                                             - 2.0 * (d_t - 1) * (d_t / d_r) * (b / k) * (1.0 - b / k))
        out = np.where(b > 0.0, h + np.sqrt(h * h + d_t / d_r), np.nan)
    return out[()] if out.ndim == 0 else out


def steady_temperature_ratio(tangential_restitution, inertia):
    """theta_st = kappa (1 + beta_t) / (1 + 2 kappa - beta_t): white noise on the translation only,
    constant beta_t, eq. (R8) (any eps, any dimension)."""
    k = np.asarray(inertia, dtype=float)
    beta = np.asarray(tangential_restitution, dtype=float)
    out = k * (1.0 + beta) / (1.0 + 2.0 * k - beta)
    return out[()] if out.ndim == 0 else out


@dataclass(frozen=True)
class RoughGas:
    """A homogeneous gas of identical rough particles (reduced units).

    Attributes
    ----------
    gas : granulargas.theory.gas.Gas
        Density, size, mass, the normal law (elastic, constant eps, viscoelastic eps(g)) and
        the initial translational temperature ``gas.temperature``.
    inertia : float
        kappa = 4 I / (m sigma^2).
    tangential : str
        ``"constant"`` (beta_t) or ``"coulomb"`` (Walton's model: beta_0 and mu).
    tangential_restitution : float
        beta_t (constant) or the sticking value beta_0 (coulomb); -1 is smooth.
    friction : float
        mu of the Coulomb model.
    rotational_temperature : float or None
        Initial T_rot (default: ``gas.temperature``).
    heating_rate : float
        H of the white-noise driving (power ``d_t H / 2`` per particle; 0: free cooling).
    rotational_fraction : float
        lambda: the fraction of the driving's power that goes to the spins.
    """

    gas: Gas
    inertia: float
    tangential: str = "constant"
    tangential_restitution: float = -1.0
    friction: float = 0.0
    rotational_temperature: float | None = None
    heating_rate: float = 0.0
    rotational_fraction: float = 0.0

    def __post_init__(self):
        if self.tangential not in ("constant", "coulomb"):
            raise ValueError(f"tangential must be 'constant' or 'coulomb', got {self.tangential!r}")
        d = self.gas.dimension
        if not 0.0 < self.inertia <= MAX_INERTIA[d]:
            raise ValueError(f"inertia must be in (0, {MAX_INERTIA[d]:.4g}] in {d}D, got {self.inertia}")
        if not -1.0 <= self.tangential_restitution <= 1.0:
            raise ValueError(f"tangential restitution must be in [-1, 1], got {self.tangential_restitution}")
        if self.friction < 0.0:
            raise ValueError(f"friction must be >= 0, got {self.friction}")
        if not 0.0 <= self.rotational_fraction <= 1.0:
            raise ValueError(f"rotational_fraction must be in [0, 1], got {self.rotational_fraction}")

    @property
    def dimension(self) -> int:
        return self.gas.dimension

    @property
    def translational_temperature(self) -> float:
        """Initial T_tr."""
        return self.gas.temperature

    @property
    def initial_rotational_temperature(self) -> float:
        return self.gas.temperature if self.rotational_temperature is None else float(self.rotational_temperature)

    @property
    def sticking_factor(self) -> float:
        """b_0 of beta_t (constant) or beta_0 (coulomb), eq. (R1)."""
        return float(tangential_factor(self.tangential_restitution, self.inertia))

    @property
    def constant_laws(self) -> bool:
        """Constant (or elastic) eps and constant beta_t: the closed forms apply."""
        return self.gas.model in ("elastic", "constant") and self.tangential == "constant"

    @property
    def restitution(self) -> float | None:
        """The constant eps (1 for elastic; None for the viscoelastic law)."""
        if self.gas.model == "elastic":
            return 1.0
        if self.gas.model == "constant":
            return float(self.gas.restitution)
        return None


def _normal_nodes(rough: RoughGas, temperature: float, table):
    """Collision-weighted nodes of the normal impact speed: (x = g_n / s_n, weights, eps at the nodes).

    x has the law x exp(-x^2/2) dx of the normal impact speeds of a Maxwellian gas.
    """
    x, w = _kernel_nodes(1, _NODES)
    eps = rough.restitution
    if eps is not None:
        return x, w, np.full(x.shape, eps)
    gas = rough.gas
    if not gas.pair_constant:
        return x, w, np.ones(x.shape)
    g = math.sqrt(2.0 * temperature / gas.mass) * x
    beta = gas.beta(g)
    if table is None or not table.covers(float(beta.max())):
        table = restitution_table(float(beta.max()) * 1.001, end=gas.end)
    return x, w, table.restitution(beta)


def _slip_integrals(dim: int, Y):
    """Incomplete moments of y = |g_t| / s_t beyond and below Y (module docstring).

    Returns (A1, B1, C0, A0, B0): ``A1 = int_0^Y y^2 p``, ``B1 = int_Y^inf y p``,
    ``C0 = int_Y^inf p``, ``A0 = int_0^Y p``, ``B0 = int_Y^inf p / y`` with p the law of y
    (Rayleigh in 3D, two tangential components; half-normal in 2D, one component).
    """
    from scipy.special import erf, erfc, exp1  # here, not at the top: a run's start-up loads no scipy

    Y = np.asarray(Y, dtype=float)
    e = np.exp(-0.5 * Y * Y)
    if dim == 3:
        A1 = 2.0 - (Y * Y + 2.0) * e
        B1 = Y * e + math.sqrt(math.pi / 2.0) * erfc(Y / math.sqrt(2.0))
        C0 = e
        A0 = 1.0 - e
        B0 = math.sqrt(math.pi / 2.0) * erfc(Y / math.sqrt(2.0))
    else:
        c = math.sqrt(2.0 / math.pi)
        A1 = erf(Y / math.sqrt(2.0)) - c * Y * e
        B1 = c * e
        C0 = erfc(Y / math.sqrt(2.0))
        A0 = erf(Y / math.sqrt(2.0))
        with np.errstate(divide="ignore"):
            B0 = np.where(Y > 0.0, 0.5 * c * exp1(np.maximum(0.5 * Y * Y, 1e-300)), np.inf)
    return A1, B1, C0, A0, B0


def _coulomb_scale(rough: RoughGas, T_tr: float, T_rot: float, table):
    """(x, w, c, b0): c = mu (1 + eps(g_n)) s_n x / (2 s_t), so that b = min(b0, c / y)."""
    x, w, eps = _normal_nodes(rough, T_tr, table)
    ratio = math.sqrt(T_tr / (T_tr + T_rot / rough.inertia))  # s_n / s_t
    c = 0.5 * rough.friction * (1.0 + eps) * ratio * x
    return x, w, c, rough.sticking_factor


def tangential_moments(rough: RoughGas, T_tr: float, T_rot: float, table=None):
    """(b1, b2) of eq. (R4): b and b^2 averaged over the collisions with weight |g_t|^2.

    Constant beta_t: (b, b^2). Coulomb: the closed-form average over |g_t| at each node of a
    quadrature over the normal impact speed (module docstring).
    """
    b0 = rough.sticking_factor
    if rough.tangential == "constant" or b0 == 0.0:
        return b0, b0 * b0
    x, w, c, b0 = _coulomb_scale(rough, T_tr, T_rot, table)
    d = rough.dimension
    mean_y2 = 2.0 if d == 3 else 1.0
    Y = c / b0
    A1, B1, C0, _, _ = _slip_integrals(d, Y)
    b1 = float(w @ (b0 * A1 + c * B1)) / mean_y2
    b2 = float(w @ (b0 * b0 * A1 + c * c * C0)) / mean_y2
    return b1, b2


def coulomb_mean_restitution(rough: RoughGas, T_tr: float | None = None, T_rot: float | None = None, table=None):
    """Mean of beta_t over the collisions (the impact angles) of the two-temperature Maxwellian gas.

    Walton's model as a constant effective beta_t (Luding et al. 1998); for a constant
    beta_t it is beta_t itself. Defaults: the initial temperatures.
    """
    if rough.tangential == "constant":
        return float(rough.tangential_restitution)
    T_tr = rough.translational_temperature if T_tr is None else float(T_tr)
    T_rot = rough.initial_rotational_temperature if T_rot is None else float(T_rot)
    b0 = rough.sticking_factor
    if b0 == 0.0:
        return -1.0
    x, w, c, b0 = _coulomb_scale(rough, T_tr, T_rot, table)
    _, _, _, A0, B0 = _slip_integrals(rough.dimension, c / b0)
    sliding = np.zeros_like(c)
    sliding[c > 0.0] = c[c > 0.0] * B0[c > 0.0]  # c B0 -> 0 as c -> 0 (2D: B0 ~ -ln c)
    mean_b = float(w @ (b0 * A0 + sliding))
    k = rough.inertia
    return 2.0 * (1.0 + k) * mean_b / k - 1.0


def _inelasticity(rough: RoughGas, T_tr: float, table=None) -> float:
    """(1 - eps^2)_eff at T_tr."""
    eps = rough.restitution
    if eps is not None:
        return 1.0 - eps * eps
    gas = rough.gas
    if not gas.pair_constant:
        return 0.0
    if table is not None:
        x, w, e = _normal_nodes(rough, T_tr, table)
        w3 = w * x * x
        return float(w3 @ (1.0 - e * e)) / float(w3.sum())
    return float(effective_inelasticity(gas, T_tr))


def energy_change_per_collision(rough: RoughGas, T_tr: float, T_rot: float, table=None):
    """(<Delta E_tr>, <Delta E_rot>): mean energy change of a colliding pair, eqs. (R2), (R3)."""
    d_t, _ = degrees_of_freedom(rough.dimension)
    k = rough.inertia
    b1, b2 = tangential_moments(rough, T_tr, T_rot, table)
    loss = _inelasticity(rough, T_tr, table)
    de_tr = -(loss * T_tr + 2.0 * (d_t - 1) * ((b1 - b2) * T_tr - b2 * T_rot / k))
    de_rot = -(2.0 * (d_t - 1) / k) * ((b1 - b2 / k) * T_rot - b2 * T_tr)
    return de_tr, de_rot


def _collision_frequency(rough: RoughGas, T_tr: float) -> float:
    gas = rough.gas
    return gas.collision_frequency * math.sqrt(T_tr / gas.temperature)


def temperature_rates(rough: RoughGas, T_tr: float, T_rot: float, table=None):
    """(dT_tr/dt, dT_rot/dt, nu) of eq. (R5) at (T_tr, T_rot), driving included; nu the
    collision frequency per particle."""
    d_t, d_r = degrees_of_freedom(rough.dimension)
    nu = _collision_frequency(rough, T_tr)
    de_tr, de_rot = energy_change_per_collision(rough, T_tr, T_rot, table)
    lam, H = rough.rotational_fraction, rough.heating_rate
    return nu / d_t * de_tr + (1.0 - lam) * H, nu / d_r * de_rot + lam * H * d_t / d_r, nu


def cooling_rates(rough: RoughGas, T_tr: float, T_rot: float, table=None):
    """(zeta_tr, zeta_rot) = (-d ln T_tr/dt, -d ln T_rot/dt) of the free gas (no driving), eq. (R6)."""
    d_t, d_r = degrees_of_freedom(rough.dimension)
    nu = _collision_frequency(rough, T_tr)
    de_tr, de_rot = energy_change_per_collision(rough, T_tr, T_rot, table)
    return -nu / d_t * de_tr / T_tr, -nu / d_r * de_rot / T_rot


def _ratio_root(f, lo=1e-8, hi=1e8):
    """Smallest theta in (lo, hi) where f crosses zero upwards (None if it never does).

    f is scanned on a log grid (10 points per decade) and the crossing refined by brentq;
    with Walton's model f need not be monotonic (two roots, or none).
    """
    from scipy.optimize import brentq

    s = np.linspace(math.log(lo), math.log(hi), int(round(10 * math.log10(hi / lo))) + 1)
    prev = f(math.exp(s[0]))
    for a, b in zip(s[:-1], s[1:]):
        fb = f(math.exp(b))
        if prev < 0.0 <= fb:
            return math.exp(brentq(lambda u: f(math.exp(u)), a, b, xtol=1e-14, rtol=1e-14))
        prev = fb
    return None


def hcs_ratio(rough: RoughGas, T_tr: float | None = None, table=None) -> float:
    """theta of the homogeneous cooling state at T_tr (zeta_tr = zeta_rot, the stable root).

    Constant laws: eq. (R7), independent of T_tr; otherwise the root of the balances at T_tr
    (the viscoelastic theta drifts as the gas cools). nan for a smooth gas (b_0 = 0); inf when
    no ratio balances them: with Walton's model at small mu the spins stop losing energy
    to the collisions faster than the translation does, and theta grows without bound
    (Herbst, Huthmann & Zippelius 2000).
    """
    if rough.sticking_factor == 0.0:
        return math.nan
    if rough.constant_laws:
        return float(hcs_temperature_ratio(rough.restitution, rough.tangential_restitution, rough.inertia,
                                           rough.dimension))
    T = rough.translational_temperature if T_tr is None else float(T_tr)
    d_t, d_r = degrees_of_freedom(rough.dimension)

    def excess(theta):  # d_r zeta_rot - d_r zeta_tr, scaled by T_tr / nu: increasing in theta
        de_tr, de_rot = energy_change_per_collision(rough, T, theta * T, table)
        return -de_rot / (d_r * theta) + de_tr / d_t

    root = _ratio_root(lambda th: excess(th) * th)
    return math.inf if root is None else root


def driven_state(rough: RoughGas, table=None):
    """Steady (T_tr, T_rot) of the white-noise driven gas, eq. (R5) = 0.

    The split of the power fixes theta (``(1 - lambda) d_r R_rot = lambda d_t R_tr`` with
    ``R = -dT/dt`` of the collisions), the total power then T_tr. Needs ``heating_rate > 0``
    and a coupling of the spins (b_0 > 0) unless lambda = 0, where a smooth gas keeps its T_rot.
    """
    from scipy.optimize import brentq

    H, lam = rough.heating_rate, rough.rotational_fraction
    if not H > 0.0:
        raise ValueError("driven_state needs heating_rate > 0")
    d_t, d_r = degrees_of_freedom(rough.dimension)
    if rough.sticking_factor == 0.0:
        if lam > 0.0:
            raise ValueError("a smooth gas (beta_t = -1) driven in rotation has no steady state")
        if rough.gas.model == "elastic":
            raise ValueError("an elastic smooth gas heats without bound")

    def theta_at(T):
        if rough.sticking_factor == 0.0:
            return rough.initial_rotational_temperature / rough.translational_temperature

        def split(theta):
            de_tr, de_rot = energy_change_per_collision(rough, T, theta * T, table)
            return -(1.0 - lam) * de_rot + lam * de_tr

        root = _ratio_root(split)
        if root is None:
            raise ValueError("no temperature ratio balances the split of the driving in (1e-8, 1e8)")
        return root

    def balance(log_t):
        T = math.exp(log_t)
        theta = theta_at(T)
        de_tr, de_rot = energy_change_per_collision(rough, T, theta * T, table)
        nu = _collision_frequency(rough, T)
        return math.log(-nu * (de_tr + de_rot) / (d_t * H))

    lo = hi = math.log(rough.translational_temperature)
    while balance(lo) > 0.0:
        lo -= 2.0
    while balance(hi) < 0.0:
        hi += 2.0
    T = math.exp(brentq(balance, lo, hi, xtol=1e-13, rtol=1e-13))
    return T, theta_at(T) * T


@dataclass(frozen=True)
class TwoTemperatureCurve:
    """T_tr(t), T_rot(t) and collisions per particle from eq. (R5).

    Arrays (K,) on a grid uniform in ``ln(1 + t / t_free)``; the methods evaluate the ODE
    solution itself (dense output), nan beyond the curve.
    """

    time: np.ndarray
    translational: np.ndarray
    rotational: np.ndarray
    collisions: np.ndarray
    solution: object = field(default=None, repr=False, compare=False)
    time_scale: float = 1.0

    @property
    def ratio(self) -> np.ndarray:
        """theta = T_rot / T_tr on the grid."""
        return self.rotational / self.translational

    def _state(self, t):
        t = np.asarray(t, dtype=float)
        x = np.log1p(np.clip(t, 0.0, None) / self.time_scale)
        y = np.asarray(self.solution(np.atleast_1d(x).ravel())).reshape((3,) + t.shape)
        return np.where(t > self.time[-1] * (1.0 + 1e-12), np.nan, y)

    def translational_at(self, t):
        return np.exp(self._state(t)[0])

    def rotational_at(self, t):
        y = self._state(t)
        return np.exp(y[0]) * y[1]

    def ratio_at(self, t):
        return self._state(t)[1]

    def collisions_at(self, t):
        return self._state(t)[2]


def two_temperature_curve(rough: RoughGas, t_end: float, points: int = 400,
                          rtol: float = 1e-10) -> TwoTemperatureCurve:
    """Integrate eq. (R5) from the initial (T_tr, T_rot) to ``t_end`` (scipy ``solve_ivp``, LSODA).

    Variables ``ln T_tr``, theta and the collisions per particle s (``ds/dt = nu``) against
    ``x = ln(1 + t / t_free)`` (t_free the initial mean free time), which keeps the step count
    small over decades of cooling; theta rather than ``ln T_rot`` allows T_rot = 0 at the start.
    Viscoelastic eps(g): the exact law through the restitution table, as
    :func:`granulargas.theory.gas.cooling_curve`.
    """
    from scipy.integrate import solve_ivp

    T0 = rough.translational_temperature
    R0 = rough.initial_rotational_temperature
    t_free = 1.0 / _collision_frequency(rough, T0)
    table = None
    gas = rough.gas
    if gas.model == "viscoelastic" and gas.pair_constant:
        x_max = float(_kernel_nodes(1, _NODES)[0].max())
        d_t, d_r = degrees_of_freedom(rough.dimension)
        T_top = 4.0 * (T0 + R0 * d_r / d_t)  # all the energy in translation
        if rough.heating_rate > 0.0:
            try:
                T_top = max(T_top, 4.0 * driven_state(rough)[0])
            except ValueError:
                pass
        table = restitution_table(float(gas.beta(math.sqrt(2.0 * T_top / gas.mass) * x_max)) * 1.01, end=gas.end)

    def rhs(x, y):
        t_plus = t_free * math.exp(x)
        T = math.exp(y[0])
        theta = max(y[1], 0.0)
        dT, dR, nu = temperature_rates(rough, T, theta * T, table)
        dlnT = dT / T
        return [dlnT * t_plus, (dR / T - theta * dlnT) * t_plus, nu * t_plus]

    x_end = math.log1p(t_end / t_free)
    sol = solve_ivp(rhs, (0.0, x_end), [math.log(T0), R0 / T0, 0.0], method="LSODA", rtol=rtol,
                    atol=[1e-12, 1e-12, 1e-10], dense_output=True)
    if sol.status < 0:
        raise RuntimeError(f"two_temperature_curve: the ODE solver failed ({sol.message})")
    x = np.linspace(0.0, x_end, points)
    y = sol.sol(x)
    t = t_free * np.expm1(x)
    t[-1] = t_end
    T = np.exp(y[0])
    return TwoTemperatureCurve(t, T, T * y[1], y[2], solution=sol.sol, time_scale=t_free)


def mpemba_crossing_time(first: TwoTemperatureCurve, second: TwoTemperatureCurve) -> float | None:
    """Earliest time at which the translational temperatures of two curves cross (None: never
    within both curves). The curves must share their time scale (the same gas)."""
    from scipy.optimize import brentq

    t = np.union1d(first.time, second.time)
    t = t[t <= min(first.time[-1], second.time[-1])]
    diff = np.log(first.translational_at(t)) - np.log(second.translational_at(t))
    sign = np.sign(diff)
    change = np.nonzero(sign[1:] * sign[:-1] < 0)[0]
    if not change.size:
        return None
    k = int(change[0])

    def f(s):
        return float(np.log(first.translational_at(s)) - np.log(second.translational_at(s)))

    return float(brentq(f, t[k], t[k + 1], xtol=1e-14, rtol=1e-13))


def smooth_deviation(rough: RoughGas, t_end: float, points: int = 400) -> dict:
    """How far T_tr(t) of the rough gas lies from that of the same gas made smooth.

    The smooth gas has beta_t = -1 (the spins decouple) and the whole driving power on the
    translation; both start at the same T_tr and follow eq. (R5) (Maxwellian). Returns
    ``max_deviation`` = max over [0, t_end] of |T_smooth / T_rough - 1|, ``end_deviation``
    (the same at t_end), ``t_max`` where the largest deviation occurs, and both curves.
    """
    smooth = RoughGas(rough.gas, rough.inertia, tangential="constant", tangential_restitution=-1.0,
                      rotational_temperature=rough.initial_rotational_temperature,
                      heating_rate=rough.heating_rate, rotational_fraction=0.0)
    a = two_temperature_curve(rough, t_end, points)
    b = two_temperature_curve(smooth, t_end, points)
    t = a.time
    dev = np.abs(b.translational_at(t) / a.translational - 1.0)
    k = int(np.argmax(dev))
    return {"max_deviation": float(dev[k]), "end_deviation": float(dev[-1]), "t_max": float(t[k]),
            "rough": a, "smooth": b}
