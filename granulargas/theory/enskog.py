"""Enskog kinetic theory of granular gases with a constant restitution: the closed forms.

Everything is for identical smooth hard spheres (``dim = 3``) or disks
(``dim = 2``) of diameter ``sigma`` and mass ``m`` at number density ``n``;
temperature ``T = m <c^2> / dim`` with ``k_B = 1``.
Defaults are the code's reduced units ``sigma = m = 1``.

Contents, with the equations they implement:

* particle volume ``v`` (3D ``pi sigma^3 / 6``, 2D ``pi sigma^2 / 4``) and packing
  fraction ``eta = n v``;
* compressibility factor ``Z = P / (n T)`` of elastic hard spheres and disks and
  the pair correlation at contact ``chi`` that goes with it. For hard particles the
  virial theorem gives ``Z = 1 + 2^(d-1) eta chi`` exactly (Hansen & McDonald,
  *Theory of Simple Liquids*, ch. 2), so each equation of state fixes chi:

  - ``form="accurate"`` (default): 3D, Kolafa's form used by Kolafa, Labík &
    Malijevský, Phys. Chem. Chem. Phys. 6, 2335 (2004),
    ``Z = (1 + eta + eta^2 - (2/3)(eta^3 + eta^4)) / (1 - eta)^3``
    (within 0.02 % of the Hansen-Goos (2016) equation of state, fitted to
    simulations, for 0.26 <= eta <= 0.39; the tests check it); 2D, the virial
    series of hard disks through B10 (B3, B4 exact; B5..B10 from Clisby & McCoy,
    J. Stat. Phys. 122, 15 (2006), Table 1) resummed as the Padé approximant
    [6/3] in ``x = 2 eta`` (``B2 n = 2 eta``), whose poles lie beyond close
    packing; the [5/4] and [7/2] approximants agree with it to 3e-5 at eta = 0.5;
  - ``form="closed"``: Carnahan & Starling, J. Chem. Phys. 51, 635 (1969),
    ``chi = (1 - eta/2) / (1 - eta)^3`` (3D, Z 0.2-0.3 % low at eta = 0.3);
    Henderson, Mol. Phys. 30, 971 (1975), ``chi = (1 - 7 eta/16) / (1 - eta)^2``
    (2D, chi 0.6 % high at eta = 0.5);
* second Sonine coefficient of the homogeneous cooling state, van Noije & Ernst,
  Granular Matter 1, 57 (1998) (first Sonine approximation);
* Enskog collision frequency ``omega`` and cooling rate ``zeta``,
  ``zeta = omega (1 - eps^2)(1 + 3 a2/16) / d`` (van Noije & Ernst 1998;
  Brilliantov & Pöschel, *Kinetic Theory of Granular Gases* (OUP 2004), ch. 6);
  Haff's law ``T = T0 / (1 + t/tau0)^2`` with ``1/tau0 = zeta(T0)/2``
  (Haff, J. Fluid Mech. 134, 401 (1983));
* the same in collisions per particle ``s``: ``T = T0 exp(-(1-eps^2)(1+3a2/16) s/d)``;
* mean free path ``l = <|v|> / omega``;
* the shear-instability length ``L_c`` from linearised hydrodynamics of the
  homogeneous cooling state (see :func:`instability_length`).

Viscoelastic cooling at leading order in the damping is in
:mod:`granulargas.theory.viscoelastic`; kinetic theory with the exact eps(beta)
in :mod:`granulargas.theory.gas`.
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = [
    "particle_volume",
    "packing_fraction",
    "number_density",
    "contact_value",
    "compressibility_factor",
    "eos_name",
    "pressure",
    "sonine_a2",
    "collision_frequency",
    "mean_free_path",
    "enskog_cooling_rate",
    "haff_tau0",
    "haff_temperature",
    "haff_collisions",
    "temperature_vs_collisions",
    "shear_viscosity",
    "instability_length",
]

def _check_dim(dim):
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")


def particle_volume(diameter, dim=3):
    """Volume of spheres (3D, ``pi sigma^3 / 6``) or area of disks (2D, ``pi sigma^2 / 4``).

    Parameters
    ----------
    diameter : float or array
        Diameter(s) sigma (not radii).
    dim : {2, 3}

    Returns
    -------
    float or array, same shape as ``diameter``
    """
    _check_dim(dim)
    d = np.asarray(diameter, dtype=np.float64)
    out = np.pi * d**3 / 6.0 if dim == 3 else np.pi * d**2 / 4.0
    return out[()] if out.ndim == 0 else out


def packing_fraction(n, dim=3, sigma=1.0):
    """Packing (area/volume) fraction ``eta = n v(sigma)`` of spheres or disks
    (:func:`particle_volume`: ``pi n sigma^3 / 6`` in 3D, ``pi n sigma^2 / 4`` in 2D)."""
    return n * particle_volume(sigma, dim)


def number_density(eta, dim=3, sigma=1.0):
    """Inverse of :func:`packing_fraction`: number density ``eta / v(sigma)`` for packing fraction ``eta``."""
    return eta / particle_volume(sigma, dim)


#: hard-disk virial coefficients B_k / B_2^(k-1), k = 2..10: B3, B4 exact
#: (4/3 - sqrt(3)/pi; 2 - 9 sqrt(3)/(2 pi) + 10/pi^2), B5..B10 Clisby & McCoy (2006), Table 1
DISK_VIRIAL_RATIOS = (
    1.0,
    4.0 / 3.0 - math.sqrt(3.0) / math.pi,
    2.0 - 9.0 * math.sqrt(3.0) / (2.0 * math.pi) + 10.0 / math.pi**2,
    0.33355604,
    0.1988425,
    0.1148728,
    0.0649930,
    0.0362193,
    0.0199537,
)

EOS_NAMES = {
    (3, "accurate"): "Kolafa-Labík-Malijevský",
    (2, "accurate"): "Clisby-McCoy virial series (Padé [6/3])",
    (3, "closed"): "Carnahan-Starling",
    (2, "closed"): "Henderson",
}


#: the [6/3] Padé approximant of Z as scipy.interpolate.pade gives it from DISK_VIRIAL_RATIOS
#: (numerator, denominator; highest power of x = 2 eta first), written out so that a 2D run
#: loads no scipy; tests/theory/test_enskog.py recomputes it
_DISK_PADE_3 = (
    [-0.00011461979991070921, -0.000570451077751047, -0.0013932532833688166, 0.0007391426813274623,
     0.039852898891187705, -0.09379595010037933, 1.0],
    [-0.027783788275844733, 0.3516444110800258, -1.0937959501003793, 1.0],
)


@functools.lru_cache(maxsize=None)
def _disk_pade(denominator_degree: int = 3):
    """Numerator and denominator (numpy poly1d in x = 2 eta) of the Padé approximant of Z."""
    if denominator_degree == 3:
        return tuple(np.poly1d(c) for c in _DISK_PADE_3)
    from scipy.interpolate import pade  # here, not at the top: a run's start-up loads no scipy

    coeffs = [1.0, *DISK_VIRIAL_RATIOS]  # Z = 1 + sum_k (B_k / B_2^(k-1)) x^(k-1)
    return pade(coeffs, denominator_degree)


def _disk_compressibility(eta, denominator_degree: int = 3):
    p, q = _disk_pade(denominator_degree)
    x = 2.0 * eta
    return p(x) / q(x)


def _check_form(form):
    if form not in ("accurate", "closed"):
        raise ValueError(f"form must be 'accurate' or 'closed', got {form!r}")


def eos_name(dim=3, form="accurate") -> str:
    """Name of the equation of state :func:`compressibility_factor` uses (module doc)."""
    _check_dim(dim)
    _check_form(form)
    return EOS_NAMES[(dim, form)]


def contact_value(eta, dim=3, form="accurate"):
    """Pair correlation function at contact, chi = g(sigma+), of elastic hard spheres/disks.

    ``chi = (Z - 1) / (2^(d-1) eta)`` with :func:`compressibility_factor` (module doc):
    ``form="accurate"`` Kolafa-Labík-Malijevský (3D) or the resummed virial series
    of Clisby & McCoy (2D); ``form="closed"`` Carnahan-Starling,
    ``chi = (1 - eta/2) / (1 - eta)^3`` (3D), or Henderson,
    ``chi = (1 - 7 eta/16) / (1 - eta)^2`` (2D).

    Parameters
    ----------
    eta : float or array
        Packing fraction, 0 <= eta < 1 (fluid range: eta < 0.49 in 3D, < 0.70 in 2D).
    """
    _check_dim(dim)
    _check_form(form)
    eta = np.asarray(eta, dtype=float)
    if form == "closed":
        if dim == 3:
            out = (1.0 - 0.5 * eta) / (1.0 - eta) ** 3
        else:
            out = (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2
    elif dim == 3:
        # (Z - 1) / (4 eta) of Z = (1 + eta + eta^2 - (2/3)(eta^3 + eta^4)) / (1 - eta)^3
        out = (1.0 - 0.5 * eta + eta**2 / 12.0 - eta**3 / 6.0) / (1.0 - eta) ** 3
    else:
        # (Z - 1) / (2 eta) with the series divided out analytically at small eta
        small = eta < 1e-6
        safe = np.where(small, 1.0, eta)
        out = np.where(small, 1.0 + DISK_VIRIAL_RATIOS[1] * 2.0 * eta,
                       (_disk_compressibility(safe) - 1.0) / (2.0 * safe))
    return out[()] if out.ndim == 0 else out


def compressibility_factor(eta, dim=3, form="accurate"):
    """Equation of state of elastic hard spheres/disks, ``Z = P / (n T)`` (module doc).

    ``form="accurate"`` (default): Kolafa-Labík-Malijevský (3D),
    ``(1 + eta + eta^2 - (2/3)(eta^3 + eta^4)) / (1 - eta)^3``, or the Padé-resummed
    virial series of Clisby & McCoy (2D).
    ``form="closed"``: Carnahan–Starling ``(1 + eta + eta^2 - eta^3)/(1 - eta)^3`` (3D)
    or Henderson ``(1 + eta^2/8)/(1 - eta)^2`` (2D).
    ``form="virial"``: ``1 + 2^(d-1) eta chi(eta)`` with the closed-form chi (identical
    to ``"closed"`` in 3D, to O(eta^3) in 2D).
    """
    _check_dim(dim)
    eta = np.asarray(eta, dtype=float)
    if form == "virial":
        out = 1.0 + 2.0 ** (dim - 1) * eta * contact_value(eta, dim, "closed")
    elif form == "closed":
        if dim == 3:
            out = (1.0 + eta + eta**2 - eta**3) / (1.0 - eta) ** 3
        else:
            out = (1.0 + eta**2 / 8.0) / (1.0 - eta) ** 2
    elif form == "accurate":
        if dim == 3:
            out = (1.0 + eta + eta**2 - 2.0 / 3.0 * (eta**3 + eta**4)) / (1.0 - eta) ** 3
        else:
            out = _disk_compressibility(eta)
    else:
        raise ValueError(f"form must be 'accurate', 'closed' or 'virial', got {form!r}")
    out = np.asarray(out, dtype=float)
    return out[()] if out.ndim == 0 else out


def pressure(n, T, dim=3, sigma=1.0, form="accurate"):
    """Pressure ``P = n T Z(eta)`` of elastic hard spheres/disks."""
    return n * T * compressibility_factor(packing_fraction(n, dim, sigma), dim, form)


def sonine_a2(eps, dim=3):
    """Second Sonine coefficient of the homogeneous cooling state (constant eps).

    van Noije & Ernst, Granular Matter 1, 57 (1998), first Sonine approximation:
    ``a2 = 16 (1 - eps)(1 - 2 eps^2) / [9 + 24 d - eps (41 - 8 d) + 30 eps^2 (1 - eps)]``.
    Zero for eps = 1; negative for 1/sqrt(2) < eps < 1.
    """
    _check_dim(dim)
    eps = np.asarray(eps, dtype=float)
    num = 16.0 * (1.0 - eps) * (1.0 - 2.0 * eps**2)
    den = 9.0 + 24.0 * dim - eps * (41.0 - 8.0 * dim) + 30.0 * eps**2 * (1.0 - eps)
    out = num / den
    return out[()] if out.ndim == 0 else out


def _solid_angle_factor(dim):
    # 2 pi^((d-1)/2) / Gamma(d/2): 4 sqrt(pi) in 3D, 2 sqrt(pi) in 2D.
    return 2.0 * math.pi ** ((dim - 1) / 2.0) / math.gamma(dim / 2.0)


def collision_frequency(n, T, dim=3, sigma=1.0, m=1.0, chi=None, a2=0.0):
    """Enskog collision frequency per particle (collisions per particle per unit time).

    ``omega = 4 sqrt(pi) chi n sigma^2 sqrt(T/m) (1 - a2/16)`` in 3D,
    ``omega = 2 sqrt(pi) chi n sigma sqrt(T/m) (1 - a2/16)`` in 2D
    (cross-section times mean relative speed, e.g. ``pi sigma^2 n sqrt(16 T/(pi m))``
    in 3D, times the Enskog factor chi; the ``a2`` factor is the first Sonine
    correction, Brilliantov & Pöschel 2004, ch. 6). The total pair-collision rate of N particles is ``N omega / 2``.

    Parameters
    ----------
    n : float
        Number density, sigma^-d.
    T : float or array
        Temperature.
    chi : float, optional
        Contact value; default :func:`contact_value` of the packing fraction.
    a2 : float
        Second Sonine coefficient (0 = Maxwellian).
    """
    _check_dim(dim)
    if chi is None:
        chi = contact_value(packing_fraction(n, dim, sigma), dim)
    return _solid_angle_factor(dim) * chi * n * sigma ** (dim - 1) * np.sqrt(np.asarray(T) / m) * (1.0 - a2 / 16.0)


def mean_free_path(n, dim=3, sigma=1.0, chi=None):
    """Enskog mean free path ``l = <|v|> / omega`` (Maxwellian, independent of T).

    3D ``l = 1 / (sqrt(2) pi chi n sigma^2)``; 2D ``l = 1 / (2 sqrt(2) chi n sigma)``.
    """
    _check_dim(dim)
    if chi is None:
        chi = contact_value(packing_fraction(n, dim, sigma), dim)
    if dim == 3:
        return 1.0 / (math.sqrt(2.0) * math.pi * chi * n * sigma**2)
    return 1.0 / (2.0 * math.sqrt(2.0) * chi * n * sigma)


def enskog_cooling_rate(eps, n, T, dim=3, sigma=1.0, m=1.0, chi=None, a2=None):
    """Enskog cooling rate ``zeta`` in ``dT/dt = -zeta T`` (constant restitution).

    3D: ``zeta = (4 sqrt(pi)/3)(1 - eps^2) chi n sigma^2 sqrt(T/m)(1 + 3 a2/16)``;
    2D: ``zeta = sqrt(pi)(1 - eps^2) chi n sigma sqrt(T/m)(1 + 3 a2/16)``,
    i.e. ``zeta = omega_0 (1 - eps^2)(1 + 3 a2/16) / d`` with the Maxwellian
    collision frequency ``omega_0`` (van Noije & Ernst 1998).

    Parameters
    ----------
    a2 : float, optional
        Second Sonine coefficient; default :func:`sonine_a2` (pass 0 for the
        Maxwellian estimate).
    """
    if a2 is None:
        a2 = sonine_a2(eps, dim)
    omega0 = collision_frequency(n, T, dim, sigma, m, chi)
    return omega0 * (1.0 - eps**2) * (1.0 + 3.0 * a2 / 16.0) / dim


def haff_tau0(eps, n, T0=1.0, dim=3, sigma=1.0, m=1.0, chi=None, a2=None):
    """Haff time ``tau0 = 2 / zeta(T0)`` of ``T = T0 / (1 + t/tau0)^2`` (inf for an elastic gas)."""
    with np.errstate(divide="ignore", over="ignore"):
        return 2.0 / np.float64(enskog_cooling_rate(eps, n, T0, dim, sigma, m, chi, a2))


def haff_temperature(t, T0, tau0):
    """Haff's law ``T(t) = T0 / (1 + t/tau0)^2`` (Haff 1983)."""
    return T0 / (1.0 + np.asarray(t, dtype=float) / tau0) ** 2


def haff_collisions(t, tau0, omega0):
    """Collisions per particle by time t under Haff's law.

    ``s(t) = int_0^t omega dt = omega0 tau0 ln(1 + t/tau0)``, since omega is
    proportional to sqrt(T) = sqrt(T0)/(1 + t/tau0).
    """
    return omega0 * tau0 * np.log1p(np.asarray(t, dtype=float) / tau0)


def temperature_vs_collisions(s, eps, dim=3, a2=None, T0=1.0):
    """Temperature after ``s`` collisions per particle (constant restitution).

    ``T = T0 exp(-(1 - eps^2)(1 + 3 a2/16) s / d)``: ``dT/ds = -zeta T / omega``
    with ``zeta / omega = (1 - eps^2)(1 + 3 a2/16)/d`` (the ``a2`` correction of
    omega itself is left out). Independent of density.
    """
    if a2 is None:
        a2 = sonine_a2(eps, dim)
    return T0 * np.exp(-(1.0 - eps**2) * (1.0 + 3.0 * a2 / 16.0) * np.asarray(s, dtype=float) / dim)


def shear_viscosity(n, T, dim=3, sigma=1.0, m=1.0, chi=None):
    """Enskog shear viscosity of elastic hard spheres/disks (first Sonine order).

    3D: ``eta_s = eta_0 [1/chi + (4/5)(4 eta) + (4/25)(1 + 12/pi)(4 eta)^2 chi]``,
    ``eta_0 = (5 / (16 sigma^2)) sqrt(m T / pi)`` (Chapman & Cowling, ch. 16).
    2D: ``eta_s = eta_0 [1/chi + 2 eta + (1 + 8/pi) eta^2 chi]``,
    ``eta_0 = (1 / (2 sigma)) sqrt(m T / pi)`` (Gass, J. Chem. Phys. 54, 1898 (1971)).
    ``eta`` is the packing fraction. Inelastic corrections (Brey et al. 1998) are
    of relative order 1 - eps and left out.
    """
    _check_dim(dim)
    eta = packing_fraction(n, dim, sigma)
    if chi is None:
        chi = contact_value(eta, dim)
    if dim == 3:
        eta0 = 5.0 / (16.0 * sigma**2) * np.sqrt(m * T / np.pi)
        b = 4.0 * eta
        return eta0 * (1.0 / chi + 0.8 * b + 4.0 / 25.0 * (1.0 + 12.0 / np.pi) * b**2 * chi)
    eta0 = 1.0 / (2.0 * sigma) * np.sqrt(m * T / np.pi)
    return eta0 * (1.0 / chi + 2.0 * eta + (1.0 + 8.0 / np.pi) * eta**2 * chi)


def instability_length(eps, n, dim=3, sigma=1.0, chi=None, a2=None):
    """Box length above which the homogeneous cooling state is unstable to shear modes.

    Criterion (linearised hydrodynamics of the HCS; Goldhirsch & Zanetti,
    PRL 70, 1619 (1993); McNamara, Phys. Fluids A 5, 3056 (1993); Brey, Ruiz-Montero
    & Cubero, PRE 54, 3664 (1996)): a transverse velocity mode of wavenumber k decays
    viscously at rate ``nu k^2`` (kinematic viscosity ``nu = eta_s / (n m)``) while
    the thermal speed decays at rate ``zeta / 2``; the mode grows relative to the
    thermal speed when ``nu k^2 < zeta / 2``. Both rates scale with sqrt(T), so the
    critical wavenumber ``k_c = sqrt(zeta n m / (2 eta_s))`` is time-independent, and
    a periodic box whose smallest wavenumber ``2 pi / L`` is below ``k_c`` is unstable:

        ``L_c = 2 pi / k_c = 2 pi sqrt(2 eta_s / (zeta n m))``.

    Dilute limit: ``L_c = 10.78 l / sqrt(1 - eps^2)`` (3D) and ``10.03 l / sqrt(1 - eps^2)``
    (2D), with ``l`` the mean free path (Goldhirsch & Zanetti 1993 quote ~10 l).
    Density clusters (the longitudinal mode) follow the shear modes nonlinearly.

    Returns
    -------
    float
        ``L_c`` in units of sigma; independent of T.
    """
    if chi is None:
        chi = contact_value(packing_fraction(n, dim, sigma), dim)
    zeta = enskog_cooling_rate(eps, n, 1.0, dim, sigma, 1.0, chi, a2)
    eta_s = shear_viscosity(n, 1.0, dim, sigma, 1.0, chi)
    return 2.0 * np.pi * np.sqrt(2.0 * eta_s / (zeta * n))
