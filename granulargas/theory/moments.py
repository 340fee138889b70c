"""Collision moments of the Enskog-Boltzmann equation for any restitution law eps(g_n).

The homogeneous gas of identical smooth spheres (d = 3) or disks (d = 2) of
diameter sigma and mass m, number density n, pair correlation at contact chi:

    df/dt = chi sigma^(d-1) I(f, f)                                          (1)

with the Boltzmann collision integral I. Scaled velocities ``c = v / v_T``,
``v_T = sqrt(2 T / m)``, and the first Sonine approximation of the scaled
distribution,

    f(v, t) = n v_T^-d phi(c) [1 + a2 S2(c^2)],   phi(c) = pi^(-d/2) exp(-c^2),
    S2(x) = x^2/2 - (d + 2) x / 2 + d (d + 2) / 8,                          (2)

so that ``<c^2> = d/2`` and ``<c^4> = d (d + 2) (1 + a2) / 4`` (van Noije & Ernst,
Granular Matter 1, 57 (1998); Brilliantov & Pöschel, *Kinetic Theory of Granular
Gases* (OUP 2004), ch. 6). A collision with unit vector e (from 1 to 2) and
normal relative velocity ``c_n = c12 . e > 0`` changes the velocities by

    c1' = c1 - (1 + eps)/2 c_n e,   c2' = c2 + (1 + eps)/2 c_n e,           (3)

with ``eps = eps(v_T c_n)``: the restitution coefficient depends on the impact
speed in physical units, hence on T. The moments of (1), following Brilliantov &
Pöschel, Phys. Rev. E 61, 5573 (2000):

    mu_p = -(1/2) int dc1 dc2 de Theta(c_n) c_n f1 f2 Delta(c1^p + c2^p),   (4)

(f1 f2 the scaled distributions of (2)) turn the Boltzmann equation into

    dT/dt   = -zeta T,   zeta = (2/d) nu_c mu_2,                              (5)
    da2/dt  = (4/d) nu_c [mu_2 (1 + a2) - mu_4 / (d + 2)],                   (6)
    nu_c    = chi sigma^(d-1) n v_T,                                          (7)

from ``d/dt (n v_T^p <c^p>) = -chi sigma^(d-1) n^2 v_T^(p+1) mu_p`` at p = 2
(with ``v_T^2 <c^2> = d T/m``) and p = 4 (with ``d v_T^4/dt = -2 zeta v_T^4``).
The collision frequency per particle is ``omega = nu_c nu_0``,

    nu_0 = int dc1 dc2 de Theta(c_n) c_n f1 f2.                              (8)

Energy and fourth-moment changes of one collision (from (3); q = 1 - eps^2,
r = 1 + eps, C = (c1 + c2)/2, c = c12, C_n = C . e):

    Delta(c1^2 + c2^2) = -q c_n^2 / 2,                                        (9)
    Delta(c1^4 + c2^4) = -q c_n^2 (C^2 + c^2/4) + q^2 c_n^4 / 8
                         - 4 r c_n C_n (C . c) + 2 r^2 c_n^2 C_n^2.           (10)

Quadrature
----------
Everything in (4) and (8) except eps is a polynomial in the velocities times
Gaussians, and eps depends on c_n alone. Under ``phi(c1) phi(c2)`` the centre-of-
mass velocity C (variance 1/4 per component) and c (variance 1) are independent
Gaussians; by isotropy e can be fixed along the last axis and the e-integral
becomes the solid angle ``Omega_d`` (4 pi, 2 pi). So

    mu_p = sum_j w_j sum_k sum_l M_p[j, k, l] eps(v_T u_j)^k a2^l,            (11)

where u_j are quadrature nodes of ``c_n`` on (0, inf) and M_p[j, k, l] is the
average, at ``c_n = u_j``, of the coefficient of ``eps^k a2^l`` over the 2d - 1
other Gaussian variables (C and the transverse part of c). That average is of a
polynomial of degree <= 8 (S2 of degree 4 times the change (10) of degree 4),
computed exactly by Gauss-Hermite quadrature with 5 nodes per variable; the
eps-coefficients are read off (3) itself, evaluated at five values of eps (the
change (10) is a polynomial of degree 4 in eps), not typed in. The transverse
variables enter only through ``|C_t + c_t/2|^2`` and ``|C_t - c_t/2|^2`` (C_t the
part of C across e), and the product grid repeats their pairs (sign flips and
exchanges of the axes), so points with equal pairs are merged: 5^5 = 3125 points
become 225 in 3D, 125 become 45 in 2D. The c_n-integral uses ``u^2/2 = y^20`` and
Gauss-Legendre in y (eps depends on ``g^(1/5)``, and on its square root for the
``force`` end, both smooth in y); relative error ~1e-12 (tests).

Truncation: the moments are linear in a2 when the a2^2 term of ``f1 f2`` is
dropped, the usual first Sonine approximation (van Noije & Ernst 1998); with
constant eps the stationary point of (6) is then exactly their a2, and (5) their
``zeta = omega_0 (1 - eps^2)(1 + 3 a2/16)/d``. The tests check both and compare
the moments of a viscoelastic eps(g) with a direct Monte Carlo average of (4).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial.hermite_e import hermegauss
from numpy.polynomial.legendre import leggauss

__all__ = ["SpeedQuadrature", "speed_quadrature", "moment_coefficients", "collision_moments", "solid_angle",
           "eps_powers", "flat_weights"]

#: Gauss-Legendre nodes for the normal impact speed c_n (u^2/2 = y^20, y in [0, 60^(1/20)])
NORMAL_NODES = 96
#: Gauss-Hermite nodes per transverse Gaussian variable (exact to degree 9)
HERMITE_NODES = 5
#: eps values at which the collision rule (3) is evaluated to read off its eps-polynomial
_EPS_SAMPLES = np.array([0.0, 0.25, 0.5, 0.75, 1.0])


def solid_angle(dim: int) -> float:
    """Total solid angle Omega_d = 2 pi^(d/2) / Gamma(d/2): 4 pi (3D), 2 pi (2D)."""
    return 2.0 * math.pi ** (dim / 2.0) / math.gamma(dim / 2.0)


def sonine_s2(x, dim):
    """Second Sonine polynomial S2(x) = x^2/2 - (d+2) x/2 + d(d+2)/8, eq. (2)."""
    return 0.5 * x * x - 0.5 * (dim + 2) * x + dim * (dim + 2) / 8.0


@dataclass(frozen=True)
class SpeedQuadrature:
    """Quadrature of eqs. (4), (8) in the normal impact speed (module doc, eq. (11)).

    Attributes
    ----------
    dim : int
    u : array (J,)
        Nodes of the scaled normal impact speed c_n = g_n / v_T.
    nu : array (J, 2)
        Weight of node j in nu_0 of eq. (8), coefficients of a2^0 and a2^1.
    mu2, mu4 : array (J, 5, 2)
        Weights of node j in mu_2, mu_4 of eq. (4): coefficient of eps^k a2^l.
    """

    dim: int
    u: np.ndarray
    nu: np.ndarray
    mu2: np.ndarray
    mu4: np.ndarray


def _normal_nodes(nodes: int):
    """Nodes u_j > 0 and weights of int_0^inf du exp(-u^2/2)/sqrt(2 pi) F(u)."""
    y, w = leggauss(nodes)
    y_max = 60.0 ** (1.0 / 20.0)
    y = 0.5 * y_max * (y + 1.0)
    w = 0.5 * y_max * w
    u = math.sqrt(2.0) * y**10
    w = w * 10.0 * math.sqrt(2.0) * y**9 * np.exp(-0.5 * u * u) / math.sqrt(2.0 * math.pi)
    return u, w


def _transverse_grid(dim: int, hermite: int):
    """Gauss-Hermite points of C (d components, variance 1/4) and of the transverse
    part of c (d - 1 components, variance 1), weights summing to 1, reduced to what the
    integrand depends on: ``A1 = |C_t + c_t/2|^2``, ``A2 = |C_t - c_t/2|^2`` (C_t the d - 1
    components of C across e) and ``C_n`` (its component along e). Points with equal
    (A1, A2) are merged (their weights added): the sign flip of an axis and the exchange of
    the transverse axes or of C_t and c_t/2 leave them unchanged, so 5^(2d-1) points become
    a few hundred (3D) or a few dozen (2D)."""
    z, wz = hermegauss(hermite)
    wz = wz / math.sqrt(2.0 * math.pi)
    # one transverse axis: C_i = z_a / 2, c_i = z_b
    ci, ti = (a.ravel() for a in np.meshgrid(0.5 * z, z, indexing="ij"))
    wi = np.outer(wz, wz).ravel()
    a1, a2, w = np.zeros(1), np.zeros(1), np.ones(1)
    for _ in range(dim - 1):
        p, q = ci + 0.5 * ti, ci - 0.5 * ti
        a1 = (a1[:, None] + p * p).ravel()
        a2 = (a2[:, None] + q * q).ravel()
        w = (w[:, None] * wi).ravel()
    pairs, index = np.unique(np.stack([a1, a2], axis=-1), axis=0, return_inverse=True)
    w = np.bincount(index.ravel(), weights=w, minlength=pairs.shape[0])
    # with C_n (variance 1/4): the reduced grid
    a1 = np.repeat(pairs[:, 0], z.size)
    a2 = np.repeat(pairs[:, 1], z.size)
    cn = np.tile(0.5 * z, pairs.shape[0])
    return a1, a2, cn, (w[:, None] * wz).ravel()


@functools.lru_cache(maxsize=None)
def speed_quadrature(dim: int, nodes: int = NORMAL_NODES, hermite: int = HERMITE_NODES) -> SpeedQuadrature:
    """The weights of eq. (11) for dimension ``dim`` (computed once, cached)."""
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    u, wu = _normal_nodes(nodes)
    a1, a2, cn, wt = _transverse_grid(dim, hermite)  # (G,) each
    # c1 = C + c/2, c2 = C - c/2 with c = (c_t, u_j), e the last axis: only the components
    # along e depend on u_j (shape (G, J)); the transverse parts give a1, a2
    n1 = cn[:, None] + 0.5 * u
    n2 = cn[:, None] - 0.5 * u
    x1, x2 = a1[:, None] + n1 * n1, a2[:, None] + n2 * n2
    sonine = [np.ones_like(x1), sonine_s2(x1, dim) + sonine_s2(x2, dim)]  # f1 f2 = phi phi (1 + a2 (S2 + S2))
    d2 = np.empty((_EPS_SAMPLES.size,) + x1.shape)
    d4 = np.empty_like(d2)
    for i, eps in enumerate(_EPS_SAMPLES):
        kick = 0.5 * (1.0 + eps) * u  # (J,): eq. (3) along e
        p1, p2 = n1 - kick, n2 + kick
        y1, y2 = a1[:, None] + p1 * p1, a2[:, None] + p2 * p2
        d2[i] = y1 + y2 - x1 - x2
        d4[i] = y1 * y1 + y2 * y2 - x1 * x1 - x2 * x2
    # eps-polynomial coefficients (degree 4) from the five samples
    inv_vander = np.linalg.inv(np.vander(_EPS_SAMPLES, 5, increasing=True))
    omega = solid_angle(dim)
    flux = wu * u  # Theta(c_n) c_n times the c_n density and weights
    weighted = [wt[:, None] * s for s in sonine]  # (G, J) each
    nu = np.stack([omega * flux * w.sum(axis=0) for w in weighted], axis=-1)  # (J, 2)

    def moment(d):  # (5, G, J) samples -> (J, 5, 2) weights
        d = np.einsum("ki,igj->kgj", inv_vander, d, optimize=True)
        return -0.5 * omega * flux[:, None, None] * np.stack([np.einsum("kgj,gj->jk", d, w, optimize=True)
                                                              for w in weighted], axis=-1)

    return SpeedQuadrature(dim, u, nu, moment(d2), moment(d4))


def moment_coefficients(eps, dim: int):
    """Coefficients of a2^0 and a2^1 of nu_0, mu_2, mu_4 (eqs. (8), (4)).

    Parameters
    ----------
    eps : array (J,) or (K, J)
        eps(v_T u_j) at the nodes ``speed_quadrature(dim).u`` (one row per state).

    Returns
    -------
    nu0, mu2, mu4 : arrays (..., 2)
        ``[..., 0]`` at a2 = 0, ``[..., 1]`` the coefficient of a2.
    """
    nu, weights = flat_weights(dim)
    e = np.asarray(eps, dtype=float)
    mu = eps_powers(e).reshape(e.shape[:-1] + (-1,)) @ weights
    return nu * np.ones(e.shape[:-1] + (1,)), mu[..., :2], mu[..., 2:]


def eps_powers(e):
    """``e^k``, k = 0..4, along a new last axis (..., J, 5), the factors of eq. (11)."""
    powers = np.empty(e.shape + (5,))
    powers[..., 0] = 1.0
    powers[..., 1] = e
    powers[..., 2] = e * e
    powers[..., 3] = e**3
    powers[..., 4] = e**4
    return powers


@functools.lru_cache(maxsize=None)
def flat_weights(dim: int):
    """nu_0 summed over the nodes (2,) and the weights of mu_2, mu_4 as one (J * 5, 4) matrix
    (columns: a2^0 and a2^1 of mu_2, then of mu_4), to multiply ``eps_powers(eps).reshape(..., -1)``."""
    q = speed_quadrature(dim)
    weights = np.concatenate([q.mu2, q.mu4], axis=-1).reshape(-1, 4)
    nu = q.nu.sum(axis=0)
    nu.flags.writeable = weights.flags.writeable = False
    return nu, weights


def collision_moments(eps, a2, dim: int):
    """nu_0, mu_2, mu_4 of eqs. (8), (4) for restitution values at the quadrature nodes.

    Parameters
    ----------
    eps : array (J,) or (K, J)
        eps(v_T u_j) at the nodes ``speed_quadrature(dim).u`` (one row per state).
    a2 : float or array (K,)
    dim : {2, 3}

    Returns
    -------
    nu0, mu2, mu4 : float or arrays (K,)
        Linear in a2 (module doc, "Truncation").
    """
    a = np.asarray(a2, dtype=float)
    nu, m2, m4 = moment_coefficients(eps, dim)
    return tuple(c[..., 0] + a * c[..., 1] for c in (nu, m2, m4))
