"""Uniform shear flow (USF) of inelastic hard spheres and disks: the Grad solution and Navier-Stokes.

Identical smooth hard spheres (``dim = 3``) or disks (``dim = 2``) of diameter sigma and
mass m, constant restitution alpha (the code's ``eps``), number density n, packing
fraction phi, contact value chi; the flow u = a y x (rate a, flow along x, gradient
along y); V the peculiar velocity, T = m <V^2>/d; units sigma = m = 1 by default.

Reference quantities. The dilute elastic first-Sonine viscosity and the frequency that
goes with it (Chapman & Cowling; Brey, Dufty, Kim & Santos 1998),

    eta0 = (d + 2) Gamma(d/2) / (8 pi^((d-1)/2)) sqrt(m T) / sigma^(d-1),          (S1)
    nu0  = n T / eta0  (3D: (16/5) n sigma^2 sqrt(pi T/m)),

give the reduced shear rate a* = a / nu0 and viscosity eta* = -P_xy / (a eta0), P the
whole pressure tensor (kinetic plus collisional transfer).

Steady USF without a thermostat: viscous heating balances collisional loss,
``-a P_xy = (d/2) n T zeta`` exactly (the energy balance; the engine's check). With a
Gaussian thermostat (a drag -zeta_th m V on every particle; the elastic USF of the
literature) the drag removes the heat instead.

1. The Grad solution (:func:`grad_usf`)
---------------------------------------
The kinetic pressure tensor P^k obeys, homogeneous in the Lagrangian frame,

    a (delta_ix P^k_yj + delta_jx P^k_yi) + 2 zeta_th P^k_ij = Lambda_ij,             (S2)

Lambda_ij = int m V_i V_j J_E[f, f] dV the Enskog collision moment. For a pair at
contact, particle 2 at r_1 + sigma k (k a unit vector), the relative velocity is
w = V_1 - V_2 - a sigma k_y x (the flow's difference over sigma), the pair collides
at the rate chi sigma^(d-1) Theta(w.k) (w.k) and V_1 changes by -beta (w.k) k with
beta = (1 + alpha)/2, so

    Lambda_ij = chi sigma^(d-1) m int dV1 dV2 f(V1) f(V2) int dk Theta(w.k)(w.k)
                [-beta (w.k)(k_i V1_j + V1_i k_j) + beta^2 (w.k)^2 k_i k_j],           (S3)
    P^c_ij    = (beta/2) chi sigma^d m int dV1 dV2 f(V1) f(V2) int dk Theta(w.k)(w.k)^2 k_i k_j

(the collisional transfer: each collision carries the momentum m beta (w.k) k across
sigma k). Grad's distribution ``f = n phi_T(V) [1 + Pi_kl V_k V_l / (2 n T^2)]`` with
Pi = P^k - n T I (traceless) closes (S2). In (S3) the centre-of-mass velocity
integrates out in closed form, the relative velocity splits into u = g.k and the part
normal to k (Gaussian, closed form), and the one-dimensional integrals
int rho(u) Theta(u - e)(u - e)^p u^q du, e = a sigma k_x k_y, are
``s^p K_p(e/s)``-sums with s^2 = 2T/m and

    K_0(x) = erfc(x/sqrt 2)/2,  K_1 = phi(x) - x K_0,  K_r = (r - 1) K_(r-2) - x K_(r-1)   (S4)

(phi the standard normal density); the directions k are summed on a product grid
(Gauss-Legendre in cos theta, trapezoid in the azimuth: spectrally accurate for this
smooth integrand). The result is linear in Pi (Grad's truncation) and exact in the
shear over sigma. In the dilute limit (sigma -> 0 at fixed nu0) it reduces to

    Lambda_ij = -nu0 [nu_eta* Pi_ij + zeta* n T delta_ij],
    nu_eta* = (1 + alpha)(2d + 3 - 3 alpha)/(4d),   zeta* = (d + 2)(1 - alpha^2)/(4d),   (S5)

and the steady state without thermostat is explicit (Brey, Ruiz-Montero & Moreno 1997;
Santos, Garzó & Dufty 2004):

    P_yy/p = P_zz/p = 1 - zeta*/nu_eta*,   P_xx/p = 1 + (d - 1) zeta*/nu_eta*,
    a*^2 = (d/2) zeta* nu_eta*^2 / (nu_eta* - zeta*),
    eta* = (nu_eta* - zeta*) / nu_eta*^2,   P_xy/p = -a* (P_yy/p) / nu_eta*            (S6)

(3D, alpha = 0.8: a* = 0.512, eta* = 0.857, P_yy/p = 0.849, P_xx/p = 1.303). The tests
check (S5) and (S6) against the quadrature, and the quadrature's energy balance.
The Enskog solution needs the quadrature (``packing > 0``); it is the Grad solution
of the Enskog equation of Montanero, Garzó, Santos & Brey (1999), here without
expanding in the shear over sigma. Grad's method misses the Boltzmann USF by a few
per cent at alpha = 0.8 (Brey, Ruiz-Montero & Moreno 1997, DSMC).

2. Navier-Stokes shear viscosity (:func:`navier_stokes_viscosity`)
------------------------------------------------------------------
First Sonine Chapman-Enskog of the Enskog equation (Brey, Dufty, Kim & Santos 1998,
dilute; Garzó & Dufty 1999, dense), with a2 = c*/2 the cooling-state Sonine coefficient
(van Noije & Ernst 1998, :func:`granulargas.theory.sonine_a2`):

    nu_eta* = (3/(4d)) chi (1 - alpha + 2d/3)(1 + alpha)(1 - a2/32),
    zeta*   = ((d + 2)/(4d)) chi (1 - alpha^2)(1 + 3 a2/16),
    eta_k*  = [1 - 2^(d-2)/(d+2) (1 + alpha)(1 - 3 alpha) phi chi] / (nu_eta* - zeta*/2),
    gamma*  = 2^(2d+1)/(pi (d+2)) phi^2 chi (1 + alpha)(1 - a2/16),
    eta*    = eta_k* [1 + 2^(d-1)/(d+2) phi chi (1 + alpha)] + d/(d+2) gamma*.           (S7)

For alpha = 1 (S7) is Enskog's viscosity of elastic hard spheres and disks
(:func:`granulargas.theory.shear_viscosity`; the tests check it); dilute, 3D,
``eta* = 1/(nu_eta* - zeta*/2)`` with ``nu_eta* = (1 - (1 - alpha)^2/4)(1 - c*/64)``.
It holds for a* -> 0; a steady inelastic USF is not a Navier-Stokes state (its a* is
fixed by alpha), the thermostatted elastic USF at small a* is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas.theory.enskog import _check_dim, collision_frequency, contact_value, number_density, sonine_a2

__all__ = [
    "dilute_viscosity",
    "reference_frequency",
    "ShearState",
    "grad_usf",
    "navier_stokes_viscosity",
    "navier_stokes_viscosity_reduced",
    "steady_temperature",
    "grad_transient",
]

#: nodes of the direction grid: Gauss-Legendre in cos(theta) and azimuth points (3D); azimuth (2D)
_N_MU = 40
_N_PHI = 80
_N_PHI_2D = 160


def dilute_viscosity(T=1.0, dim=3, sigma=1.0, m=1.0):
    """Dilute elastic shear viscosity, first Sonine, eq. (S1):
    ``eta0 = (d + 2) Gamma(d/2) / (8 pi^((d-1)/2)) sqrt(m T) / sigma^(d-1)``."""
    _check_dim(dim)
    c = (dim + 2) * math.gamma(dim / 2.0) / (8.0 * math.pi ** ((dim - 1) / 2.0))
    return c * np.sqrt(m * np.asarray(T, dtype=float)) / sigma ** (dim - 1)


def reference_frequency(n, T=1.0, dim=3, sigma=1.0, m=1.0):
    """nu0 = n T / eta0, eq. (S1) (3D: (16/5) n sigma^2 sqrt(pi T / m)); a* = a / nu0."""
    return n * np.asarray(T, dtype=float) / dilute_viscosity(T, dim, sigma, m)


def _dilute_rates(alpha, dim):
    nu = (1.0 + alpha) * (2.0 * dim + 3.0 - 3.0 * alpha) / (4.0 * dim)
    zeta = (dim + 2.0) * (1.0 - alpha**2) / (4.0 * dim)
    return nu, zeta


@dataclass(frozen=True)
class ShearState:
    """The steady uniform shear flow of the Grad solution (reduced as in the module doc).

    ``pressure`` is the d x d tensor P / p (p = tr P / d, kinetic plus collisional);
    ``kinetic`` the kinetic part P^k / p; ``a_star`` = a / nu0; ``eta_star`` =
    -P_xy / (a eta0); ``zeta_th_star`` the thermostat's drag rate / nu0 (0 without one);
    ``temperature_ratio`` p / (n T) (the compressibility factor of the sheared gas);
    ``zeta_star`` the collisional cooling rate / nu0 (energy lost per unit volume and time
    over (d/2) n T nu0). Without a thermostat ``a* (-P_xy/p) (p/(n T)) = (d/2) zeta*``.
    """

    eps: float
    dimension: int
    packing: float
    chi: float
    a_star: float
    eta_star: float
    pressure: np.ndarray
    kinetic: np.ndarray
    zeta_th_star: float
    temperature_ratio: float
    zeta_star: float

    @property
    def normal_stress_differences(self):
        """(P_xx - P_yy) / p and (P_yy - P_zz) / p (the second is 0 in 2D: no z)."""
        p = self.pressure
        second = p[1, 1] - p[2, 2] if self.dimension == 3 else 0.0
        return float(p[0, 0] - p[1, 1]), float(second)


def _directions(dim):
    """Unit vectors k (K, d) and quadrature weights (K,) of the integral over the unit sphere."""
    if dim == 2:
        phi = (np.arange(_N_PHI_2D) + 0.5) * (2.0 * math.pi / _N_PHI_2D)
        k = np.stack([np.cos(phi), np.sin(phi)], axis=1)
        return k, np.full(_N_PHI_2D, 2.0 * math.pi / _N_PHI_2D)
    mu, wmu = np.polynomial.legendre.leggauss(_N_MU)
    phi = (np.arange(_N_PHI) + 0.5) * (2.0 * math.pi / _N_PHI)
    s = np.sqrt(1.0 - mu**2)
    k = np.stack([np.outer(s, np.cos(phi)).ravel(), np.outer(s, np.sin(phi)).ravel(),
                  np.repeat(mu, _N_PHI)], axis=1)
    w = np.repeat(wmu, _N_PHI) * (2.0 * math.pi / _N_PHI)
    return k, w


def _shifted_moments(x, rmax):
    """K_r(x) = int_0^inf t^r phi(t + x) dt for r = 0..rmax, eq. (S4); x an array."""
    from scipy.special import erfc  # here, not at the top: a run's start-up loads no scipy

    out = np.empty((rmax + 1,) + np.shape(x))
    out[0] = 0.5 * erfc(x / math.sqrt(2.0))
    if rmax >= 1:
        out[1] = np.exp(-0.5 * x * x) / math.sqrt(2.0 * math.pi) - x * out[0]
    for r in range(2, rmax + 1):
        out[r] = (r - 1) * out[r - 2] - x * out[r - 1]
    return out


def _moments(alpha, dim, n, chi, sigma, a, pi_tensor, T=1.0):
    """Lambda_ij and P^c_ij of eq. (S3) for Grad's f with anisotropy ``pi_tensor`` (d x d,
    traceless), temperature T, m = 1."""
    k, w = _directions(dim)
    beta = 0.5 * (1.0 + alpha)
    c = 1.0 / (2.0 * n * T * T)
    s = math.sqrt(2.0 * T)
    e = a * sigma * k[:, 0] * k[:, 1]
    K = _shifted_moments(e / s, 6)

    def m_(p):  # int rho Theta(h) h^p du, h = u - e
        return s**p * K[p]

    def hu(p, q):  # int rho Theta(h) h^p u^q du with u = h + e
        return sum(math.comb(q, l) * e ** (q - l) * m_(p + l) for l in range(q + 1))

    pkk = np.einsum("ki,ij,kj->k", k, pi_tensor, k)
    pk = k @ pi_tensor  # (Pi k)_j
    kk = k[:, :, None] * k[:, None, :]
    # [1 + (c/2)(u^2 - 2T) Pi_kk] expanded in the moments
    t1 = -beta * (hu(2, 1) + 0.5 * c * pkk * (hu(2, 3) - 2.0 * T * hu(2, 1)))
    t3 = beta**2 * (hu(3, 0) + 0.5 * c * pkk * (hu(3, 2) - 2.0 * T * hu(3, 0)))
    t2 = -beta * c * T * hu(2, 1)
    cross = k[:, :, None] * pk[:, None, :] + pk[:, :, None] * k[:, None, :] - 2.0 * pkk[:, None, None] * kk
    integrand = (t1 + t3)[:, None, None] * kk + t2[:, None, None] * cross
    lam = chi * sigma ** (dim - 1) * n * n * np.einsum("k,kij->ij", w, integrand)
    tc = hu(2, 0) + 0.5 * c * pkk * (hu(2, 2) - 2.0 * T * hu(2, 0))
    pc = 0.5 * beta * chi * sigma**dim * n * n * np.einsum("k,k,kij->ij", w, tc, kk)
    # energy lost per unit volume and time: (1 - alpha^2) m_eff (w.k)^2 / 2 per collision,
    # m_eff = 1/2, at the pair rate chi sigma^(d-1) Theta(w.k)(w.k) / 2 (each pair once)
    tl = hu(3, 0) + 0.5 * c * pkk * (hu(3, 2) - 2.0 * T * hu(3, 0))
    loss = 0.125 * (1.0 - alpha**2) * chi * sigma ** (dim - 1) * n * n * float(w @ tl)
    return lam, pc, loss


def _pi_from(x, dim):
    pi = np.zeros((dim, dim))
    if dim == 3:
        pi[0, 0], pi[1, 1], pi[0, 1] = x[0], x[1], x[2]
        pi[2, 2] = -x[0] - x[1]
    else:
        pi[0, 0], pi[0, 1] = x[0], x[1]
        pi[1, 1] = -x[0]
    pi[1, 0] = pi[0, 1]
    return pi


def _residual(pi, a, zeta_th, alpha, dim, n, chi, sigma):
    lam, _, _ = _moments(alpha, dim, n, chi, sigma, a, pi)
    pk = n * np.eye(dim) + pi
    lhs = 2.0 * zeta_th * pk
    lhs[0, :] += a * pk[1, :]
    lhs[:, 0] += a * pk[1, :]
    r = lhs - lam
    return r


def _dilute_closed(alpha, dim):
    nu, zeta = _dilute_rates(alpha, dim)
    pyy = 1.0 - zeta / nu
    a2 = 0.5 * dim * zeta * nu**2 / (nu - zeta) if nu > zeta else 0.0
    return nu, zeta, pyy, math.sqrt(a2)


def grad_usf(eps, dimension=3, packing=0.0, chi=None, a_star=None, form="accurate") -> ShearState:
    """The steady uniform shear flow of the Grad solution, eqs. (S2)-(S6).

    Parameters
    ----------
    eps : float
        Restitution alpha in (0, 1].
    dimension : 2 or 3
    packing : float
        Packing fraction phi (0: the Boltzmann equation, closed form (S6) when unthermostatted).
    chi : float, optional
        Contact value (default :func:`granulargas.theory.contact_value` of ``packing``).
    a_star : float, optional
        A Gaussian thermostat holds the temperature at this reduced shear rate a / nu0
        (needed for eps = 1; None: the unthermostatted steady state, where alpha fixes a*).

    Returns
    -------
    ShearState
    """
    from scipy import optimize

    _check_dim(dimension)
    dim = dimension
    alpha = float(eps)
    if not 0.0 < alpha <= 1.0:
        raise ValueError(f"eps = {eps}: must be in (0, 1]")
    if a_star is None and alpha == 1.0:
        raise ValueError("an elastic gas has no unthermostatted steady shear flow: give a_star")
    phi = float(packing)
    if phi == 0.0:
        chi_v = 1.0 if chi is None else float(chi)
    else:
        chi_v = float(contact_value(phi, dim, form) if chi is None else chi)
    if phi == 0.0 and a_star is None and chi_v == 1.0:
        nu, zeta, pyy, ast = _dilute_closed(alpha, dim)
        pr = np.eye(dim) * pyy
        pr[0, 0] = 1.0 + (dim - 1) * zeta / nu
        pr[0, 1] = pr[1, 0] = -ast * pyy / nu
        return ShearState(alpha, dim, 0.0, 1.0, ast, (nu - zeta) / nu**2, pr, pr.copy(), 0.0, 1.0, zeta)
    # units T = 1, sigma = 1, m = 1 at a number density from the packing fraction (phi = 0:
    # a small density at which the shear over sigma is negligible; results are in reduced units)
    n = float(number_density(phi, dim)) if phi > 0.0 else 1e-6
    nu0 = float(reference_frequency(n, 1.0, dim))
    eta0 = float(dilute_viscosity(1.0, dim))
    nu, zeta, pyy, ast = _dilute_closed(alpha, dim)
    nv = 3 if dim == 3 else 2

    def unpack(x):
        pi = _pi_from(x[:nv], dim) * n
        return pi, x[nv] * nu0

    if a_star is None:
        x0 = np.zeros(nv + 1)
        x0[nv - 1] = -ast * pyy / nu  # Pi_xy / n
        x0[nv] = ast
        if dim == 3:
            x0[0], x0[1] = (dim - 1) * zeta / nu, -zeta / nu
        else:
            x0[0] = zeta / nu

        def f(x):
            pi, a = unpack(x)
            r = _residual(pi, a, 0.0, alpha, dim, n, chi_v, 1.0) / (n * nu0)
            return np.array([r[0, 0], r[1, 1], r[0, 1]] + ([r[2, 2]] if dim == 3 else []))
    else:
        a_fixed = float(a_star) * nu0
        x0 = np.zeros(nv + 1)
        x0[nv - 1] = -float(a_star)

        def f(x):
            pi = _pi_from(x[:nv], dim) * n
            r = _residual(pi, a_fixed, x[nv] * nu0, alpha, dim, n, chi_v, 1.0) / (n * nu0)
            return np.array([r[0, 0], r[1, 1], r[0, 1]] + ([r[2, 2]] if dim == 3 else []))

    sol = optimize.root(f, x0, method="hybr", options={"xtol": 1e-12})
    if not sol.success or np.max(np.abs(f(sol.x))) > 1e-9:
        raise ArithmeticError(f"grad_usf: no steady state found for eps = {eps}, packing = {packing} "
                              f"({sol.message})")
    x = sol.x
    if a_star is None:
        pi, a = unpack(x)
        zeta_th = 0.0
    else:
        pi = _pi_from(x[:nv], dim) * n
        a, zeta_th = a_fixed, x[nv] * nu0
    _, pc, loss = _moments(alpha, dim, n, chi_v, 1.0, a, pi)
    pk = n * np.eye(dim) + pi
    ptot = pk + pc
    p = float(np.trace(ptot)) / dim
    zeta = loss / (0.5 * dim * n)  # (d/2) n T zeta = loss at T = 1
    return ShearState(alpha, dim, phi, chi_v, a / nu0, float(-ptot[0, 1] / (a * eta0)), ptot / p, pk / p,
                      zeta_th / nu0, p / n, zeta / nu0)


def navier_stokes_viscosity_reduced(eps, dimension=3, packing=0.0, chi=None, form="accurate"):
    """eta* = eta / eta0 of eq. (S7) (first Sonine Chapman-Enskog, Garzó & Dufty 1999;
    dilute: Brey, Dufty, Kim & Santos 1998)."""
    _check_dim(dimension)
    d = dimension
    alpha = np.asarray(eps, dtype=float)
    phi = float(packing)
    chi_v = (1.0 if phi == 0.0 else contact_value(phi, d, form)) if chi is None else float(chi)
    a2 = sonine_a2(alpha, d)
    nu = 3.0 / (4.0 * d) * chi_v * (1.0 - alpha + 2.0 * d / 3.0) * (1.0 + alpha) * (1.0 - a2 / 32.0)
    zeta = (d + 2.0) / (4.0 * d) * chi_v * (1.0 - alpha**2) * (1.0 + 3.0 * a2 / 16.0)
    eta_k = (1.0 - 2.0 ** (d - 2) / (d + 2.0) * (1.0 + alpha) * (1.0 - 3.0 * alpha) * phi * chi_v) / (nu - 0.5 * zeta)
    gamma = 2.0 ** (2 * d + 1) / (math.pi * (d + 2.0)) * phi**2 * chi_v * (1.0 + alpha) * (1.0 - a2 / 16.0)
    out = eta_k * (1.0 + 2.0 ** (d - 1) / (d + 2.0) * phi * chi_v * (1.0 + alpha)) + d / (d + 2.0) * gamma
    return out[()] if np.ndim(out) == 0 else out


def navier_stokes_viscosity(eps, T=1.0, dimension=3, packing=0.0, sigma=1.0, m=1.0, chi=None):
    """The shear viscosity eta = eta* eta0(T) of eq. (S7)."""
    return navier_stokes_viscosity_reduced(eps, dimension, packing, chi) * dilute_viscosity(T, dimension, sigma, m)


def steady_temperature(rate, eps, n, dimension=3, sigma=1.0, m=1.0, packing=0.0, chi=None):
    """The temperature of the steady unthermostatted USF at the shear rate ``rate`` (Grad,
    :func:`grad_usf`): a = a*(alpha) nu0(n, T), so T = m (a / (a* nu0(n, T = m)))^2 for a
    constant alpha. ``eps`` may be a callable eps(T) (the effective restitution of a
    viscoelastic gas at T): then T solves a*(eps(T)) nu0(n, T) = a (bisection in ln T)."""
    from scipy import optimize

    nu1 = float(reference_frequency(n, m, dimension, sigma, m))  # nu0 at T = m: sqrt(T/m) = 1
    if not callable(eps):
        a_star = grad_usf(eps, dimension, packing, chi).a_star
        return m * (rate / (a_star * nu1)) ** 2

    def mismatch(lnT):
        e = float(eps(math.exp(lnT)))
        if e >= 1.0:
            return -1.0  # elastic: no heat is lost, the gas warms
        return math.log(grad_usf(e, dimension, packing, chi).a_star * nu1 * math.exp(0.5 * lnT) / math.sqrt(m)) \
            - math.log(rate)

    lo, hi = math.log(m) - 10.0, math.log(m) + 10.0
    while mismatch(lo) > 0.0 and lo > -700.0:
        lo -= 10.0
    while mismatch(hi) < 0.0 and hi < 700.0:
        hi += 10.0
    return math.exp(optimize.brentq(mismatch, lo, hi, xtol=1e-10))


def grad_transient(rate, eps, n, T0, dimension=3, sigma=1.0, m=1.0, chi=1.0, t_end=math.inf, tolerance=0.25):
    """The approach to the steady USF from a Maxwellian gas at T0, by the dilute Grad moment
    equations (S2) with (S5), every collision rate times the contact value ``chi`` (an estimate
    of the Enskog gas's pace). ``eps`` a number or a callable eps(T).

    Returns (t_reach, s_reach): the time, and the collisions per particle by then, at which
    |ln(T / T_s)| first falls below ln(1 + tolerance) (T_s of :func:`steady_temperature`
    with the same rates); inf if not by ``t_end``.
    """
    from scipy.integrate import solve_ivp

    d = dimension
    eps_of = eps if callable(eps) else (lambda T: eps)
    T_s = steady_temperature(rate, eps_of if callable(eps) else eps, n, d, sigma, m, 0.0, 1.0) / chi**2
    nu1 = float(reference_frequency(n, m, d, sigma, m)) * chi
    om1 = float(collision_frequency(n, m, d, sigma, m, chi=chi))  # per particle, at T = m

    def rhs3(t, y):
        pxx, pyy, pzz, pxy, s = y
        temp = (pxx + pyy + pzz) / (d * n)
        nu = nu1 * math.sqrt(max(temp, 1e-300) / m)
        nu_eta, zeta = _dilute_rates(float(eps_of(temp)), d)
        p = n * temp
        return [-2.0 * rate * pxy - nu * (nu_eta * (pxx - p) + zeta * p),
                -nu * (nu_eta * (pyy - p) + zeta * p),
                -nu * (nu_eta * (pzz - p) + zeta * p) if d == 3 else 0.0,
                -rate * pyy - nu * nu_eta * pxy,
                om1 * math.sqrt(max(temp, 1e-300) / m)]

    def temp_of(y):
        return (y[0] + y[1] + (y[2] if d == 3 else 0.0)) / (d * n)

    def reached(t, y):
        return abs(math.log(max(temp_of(y), 1e-300) / T_s)) - math.log(1.0 + tolerance)

    reached.terminal = True
    reached.direction = -1
    y0 = [n * T0, n * T0, n * T0 if d == 3 else 0.0, 0.0, 0.0]
    if reached(0.0, y0) <= 0.0:
        return 0.0, 0.0
    horizon = t_end if math.isfinite(t_end) else 1e6 / (nu1 * math.sqrt(min(T0, T_s) / m))
    sol = solve_ivp(rhs3, (0.0, horizon), y0, events=reached, rtol=1e-6, atol=1e-12 * n * max(T0, T_s),
                    method="LSODA")
    if sol.t_events[0].size:
        return float(sol.t_events[0][0]), float(sol.y_events[0][0][4])
    return math.inf, math.inf
