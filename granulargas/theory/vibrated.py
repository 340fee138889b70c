"""Gases under gravity and on vibrating walls: the yardsticks of a vibrated granular gas.

Three results, each with the range where it holds:

* **Hydrostatic equilibrium** (an elastic gas at a uniform temperature T, e.g. on a
  thermal floor under a hard lid): the momentum balance of a fluid at rest,

      dp/dz = -m g n,    p = n T Z(eta),                                            (1)

  with Z the equation of state of the project (:func:`granulargas.theory.compressibility_factor`)
  and eta = n v_d the local packing fraction (local-density approximation: the profile
  varies slowly on the scale of a diameter; the layering right at a wall is not in it).
  In the dilute limit Z = 1 and (1) is the barometric law n ~ exp(-m g z / T).
  :func:`hydrostatic_density` integrates (1) (scipy ``solve_ivp``) for a given number
  of particles per unit floor area (3D) or length (2D).
* **The bouncing ball** (one ball, constant restitution e, on a floor W(t) = A sin(omega t),
  Gamma = A omega^2 / g): a period-n orbit leaves the plate every n plate periods at the
  same phase. Its flight time 2 pi n / omega fixes the take-off speed pi n g / omega and
  the arrival speed -pi n g / omega; the impact law v+ - U = -e (v- - U) then fixes the
  plate velocity at impact, U = pi n g (1 - e) / (omega (1 + e)), which the plate reaches
  (|U| <= A omega) if and only if

      Gamma >= pi n (1 - e) / (1 + e)                                                (2)

  (Holmes 1982; Luck & Mehta 1993). :func:`bounce_map` is the exact impact map (the next
  impact is the first root of the flight against the plate, bracketed on a fine grid and
  refined by ``brentq``), to compare a simulated bounce sequence with.
* **The dilute vibrofluidized bed** at leading order (Kumaran 1998; McNamara & Luding 1998):
  a plate vibrating with a small amplitude under a dilute gas of N_A particles per unit area
  at temperature T, barometric (n0 at the floor, n0 T / (m g) = N_A). An elastic plate moving
  at U gives a particle that hits it at normal speed u the energy 2 m U (U + u); averaged over
  the plate's phase with the collision rate (u + U), the power put in per unit area is

      P_in = 4 m <U^2> n0 sqrt(T / (2 pi m))                                         (3)

  (the odd moments of U vanish; the flux of particles at the floor is n0 sqrt(T / (2 pi m))).
  The collisional loss per unit volume is zeta (d/2) n T with the Enskog cooling rate zeta
  (dilute, Maxwellian: :func:`granulargas.theory.enskog_cooling_rate` with chi = 1, a2 = 0),
  proportional to n^2; over the barometric column (integral of n^2 = n0 N_A / 2) it balances
  (3) at

      T = 2 sqrt(2) m <U^2> / (pi (1 - e^2) sigma^2 N_A)   (3D),
      T = 4 sqrt(2) m <U^2> / (pi (1 - e^2) sigma N_L)     (2D),                     (4)

  with <U^2> the plate's mean square velocity ((A omega)^2 / 2 for a sine; elastic plate).
  The centre of mass then rises T / (m g) above the floor. Eq. (4) holds where its
  assumptions do (:func:`bed_parameters`): few effective layers, (1 - e^2) N_A sigma^2 << 1
  (3D; (1 - e^2) N_L sigma in 2D), so that a particle loses little energy between plate
  collisions and the gas stays near a barometric Maxwellian; the plate slower than the
  particles, <U^2> << T / m (the expansion in U / u); the amplitude small against the
  gravitational height, A << T / (m g); dilute at the floor, n0 sigma^d << 1. Outside it the
  measured T grows more slowly than <U^2>: exponents 1.3-1.5 in 2D (Warr, Huntley & Jacques
  1995; McNamara & Luding 1998) and about 1 for the centre-of-mass rise in 3D (Yang & Candela
  2000) against 2 here.
"""

from __future__ import annotations

import math

import numpy as np

from granulargas.theory.enskog import compressibility_factor, enskog_cooling_rate, particle_volume

__all__ = [
    "barometric_density",
    "hydrostatic_density",
    "bouncing_ball_threshold",
    "period_orbit",
    "bounce_map",
    "plate_input_power",
    "bed_loss",
    "vibrated_bed_temperature",
    "bed_parameters",
]


def _eos_stiffness(eta, dim, form):
    """d(eta Z)/d eta: the local compressibility factor of (1), dp/dn = T d(eta Z)/d eta."""
    h = 1e-6 * max(eta, 1e-6)
    lo = max(eta - h, 0.0)
    return ((eta + h) * compressibility_factor(eta + h, dim, form) - lo * compressibility_factor(lo, dim, form)) / (
        eta + h - lo)


def barometric_density(z, column, temperature, gravity, mass=1.0, bottom=0.5, top=math.inf):
    """Dilute hydrostatic profile n(z) = n0 exp(-m g (z - bottom) / T) of centres confined to
    [bottom, top], normalised to ``column`` particles per unit floor area (3D) or length (2D);
    ``gravity`` g > 0 pulls towards ``bottom``. Zero outside [bottom, top]."""
    z = np.asarray(z, dtype=float)
    ell = temperature / (mass * gravity)
    span = top - bottom
    norm = ell * (-math.expm1(-span / ell)) if math.isfinite(span) else ell
    n = column / norm * np.exp(-(z - bottom) / ell)
    return np.where((z >= bottom) & (z <= top), n, 0.0)


def hydrostatic_density(z, column, temperature, gravity, mass=1.0, diameter=1.0, dim=3, bottom=None,
                        top=math.inf, form="accurate"):
    """Hydrostatic density n(z) of eq. (1) with the equation of state of the project.

    Parameters
    ----------
    z : array
        Heights of the centres.
    column : float
        Particles per unit floor area (3D) or length (2D).
    temperature, gravity, mass, diameter : float
        T, g > 0 (towards ``bottom``), m, sigma.
    bottom, top : float
        Where the centres may be: [R, H - R] for a floor at 0 and a lid at H (default
        bottom = R = diameter / 2, no lid).
    form : str
        The equation of state (:func:`granulargas.theory.compressibility_factor`).

    Returns
    -------
    array
        n(z), zero outside [bottom, top].
    """
    from scipy.integrate import solve_ivp, trapezoid  # here, not at the top: a run's start-up loads no scipy
    from scipy.optimize import brentq

    bottom = 0.5 * diameter if bottom is None else bottom
    v = particle_volume(diameter, dim)
    ell = temperature / (mass * gravity)
    z = np.asarray(z, dtype=float)
    height = (top - bottom) if math.isfinite(top) else 60.0 * ell

    def profile(eta0):
        # d eta / dz = -eta / (ell d(eta Z)/d eta)
        sol = solve_ivp(lambda s, y: [-y[0] / (ell * _eos_stiffness(y[0], dim, form))], (0.0, height), [eta0],
                        dense_output=True, rtol=1e-10, atol=1e-14)
        return sol

    def mass_in(eta0):
        sol = profile(eta0)
        grid = np.linspace(0.0, height, 4001)
        return trapezoid(sol.sol(grid)[0], grid) / v - column

    # the floor density lies between the barometric value and the close-packed bound
    lo = float(barometric_density(bottom, column, temperature, gravity, mass, bottom, top)) * v * 1e-3
    hi = 0.74 if dim == 3 else 0.9
    eta0 = brentq(mass_in, lo, hi * 0.999, xtol=1e-14, rtol=1e-12)
    sol = profile(eta0)
    n = sol.sol(np.clip(z - bottom, 0.0, height))[0] / v
    return np.where((z >= bottom) & (z <= bottom + height), n, 0.0)


# ------------------------------------------------------------------ the bouncing ball
def bouncing_ball_threshold(n: int, restitution: float) -> float:
    """Smallest Gamma = A omega^2 / g at which a period-n orbit exists, eq. (2)."""
    e = float(restitution)
    return math.pi * n * (1.0 - e) / (1.0 + e)


def period_orbit(n: int, restitution: float, amplitude: float, omega: float, gravity: float) -> dict:
    """The period-n orbit of a ball on a sine plate A sin(omega t) (module doc, eq. (2)).

    Returns a dict: ``takeoff`` speed pi n g / omega after the impact, ``arrival`` velocity
    before it (-pi n g / omega), ``plate_velocity`` U at impact, ``phases`` (omega t mod 2 pi
    at the impact: the two solutions of A omega cos(phase) = U, the first with the plate
    above its mean position and decelerating) and ``exists`` (eq. (2)).
    """
    e = float(restitution)
    up = math.pi * n * gravity / omega
    plate = up * (1.0 - e) / (1.0 + e)
    c = plate / (amplitude * omega)
    exists = abs(c) <= 1.0
    phases = (math.acos(c), 2.0 * math.pi - math.acos(c)) if exists else ()
    return {"takeoff": up, "arrival": -up, "plate_velocity": plate, "phases": phases, "exists": exists}


def bounce_map(time: float, velocity: float, amplitude: float, omega: float, gravity: float, restitution: float,
               phase: float = 0.0, samples: int = 20_000, periods: float = 50.0):
    """Next impact of a ball that leaves a sine plate z_p = A sin(omega t + phase) at ``time``
    with ``velocity`` (after the impact): (impact time, velocity after that impact).

    The flight z = z_p(t0) + v s - g s^2 / 2 meets the plate at the first root of
    z - z_p(t0 + s), bracketed by sampling ``samples`` points per plate period (up to
    ``periods`` periods) and refined by ``brentq``; the impact law with the plate velocity
    there gives the new velocity. Returns (nan, nan) if no root is found.
    """
    from scipy.optimize import brentq

    z0 = amplitude * math.sin(omega * time + phase)

    def gap(s):
        return z0 + velocity * s - 0.5 * gravity * s * s - amplitude * np.sin(omega * (time + s) + phase)

    period = 2.0 * math.pi / omega
    s = np.linspace(0.0, periods * period, int(samples * periods) + 1)[1:]
    y = gap(s)
    bad = np.flatnonzero(y < 0.0)
    if len(bad) == 0:
        return math.nan, math.nan
    k = bad[0]
    lo = s[k - 1] if k > 0 else 1e-12 * period
    root = brentq(gap, lo, s[k], xtol=1e-15, rtol=1e-15)
    t1 = time + root
    v_before = velocity - gravity * root
    u = amplitude * omega * math.cos(omega * t1 + phase)
    return t1, u - restitution * (v_before - u)


# ------------------------------------------------------------------ the dilute vibrated bed
def plate_input_power(mean_square_velocity: float, floor_density: float, temperature: float,
                      mass: float = 1.0) -> float:
    """Energy per unit time and floor area an elastic plate of small amplitude gives a
    Maxwellian gas of density n0 at the floor, eq. (3): 4 m <U^2> n0 sqrt(T / (2 pi m))."""
    return 4.0 * mass * mean_square_velocity * floor_density * math.sqrt(temperature / (2.0 * math.pi * mass))


def vibrated_bed_temperature(column: float, restitution: float, mean_square_velocity: float, dim: int = 3,
                             diameter: float = 1.0, mass: float = 1.0) -> float:
    """Leading-order temperature of a dilute vibrofluidized bed, eq. (4) (range: module doc,
    :func:`bed_parameters`).

    Parameters
    ----------
    column : float
        Particles per unit floor area (3D) or length (2D), N_A or N_L.
    restitution : float
        Constant e of the particle collisions (< 1); the plate is elastic.
    mean_square_velocity : float
        <U^2> of the plate (:func:`granulargas.engine._walls.mean_square_velocity`).
    """
    e = float(restitution)
    if dim == 3:
        return 2.0 * math.sqrt(2.0) * mass * mean_square_velocity / (math.pi * (1.0 - e * e) * diameter**2 * column)
    if dim == 2:
        return 4.0 * math.sqrt(2.0) * mass * mean_square_velocity / (math.pi * (1.0 - e * e) * diameter * column)
    raise ValueError(f"dim = {dim}: must be 2 or 3")


def bed_loss(column: float, restitution: float, temperature: float, gravity: float, dim: int = 3,
             diameter: float = 1.0, mass: float = 1.0) -> float:
    """Collisional loss per unit floor area of a dilute barometric column at T (module doc):
    the integral of zeta (d/2) n T over the height, zeta the dilute Maxwellian Enskog
    cooling rate (proportional to n), by quadrature of the barometric profile."""
    from scipy.integrate import quad

    ell = temperature / (mass * gravity)

    def loss(z):
        n = float(barometric_density(z, column, temperature, gravity, mass, 0.0))
        zeta = enskog_cooling_rate(restitution, n, temperature, dim, diameter, mass, chi=1.0, a2=0.0)
        return float(zeta) * 0.5 * dim * n * temperature

    return quad(loss, 0.0, 80.0 * ell, epsabs=0.0, epsrel=1e-12, limit=200)[0]


def bed_parameters(column: float, restitution: float, amplitude: float, mean_square_velocity: float,
                   gravity: float, dim: int = 3, diameter: float = 1.0, mass: float = 1.0) -> dict:
    """The small parameters of eq. (4) at its own temperature: ``dissipation`` (1 - e^2) N_A
    sigma^2 (3D; (1 - e^2) N_L sigma in 2D), ``plate_speed`` m <U^2> / T, ``amplitude``
    A m g / T, ``floor_packing`` eta at the floor; eq. (4) holds when all are << 1."""
    e = float(restitution)
    temperature = vibrated_bed_temperature(column, e, mean_square_velocity, dim, diameter, mass)
    ell = temperature / (mass * gravity)
    return {
        "temperature": temperature,
        "dissipation": (1.0 - e * e) * column * diameter ** (dim - 1),
        "plate_speed": mass * mean_square_velocity / temperature,
        "amplitude": amplitude / ell,
        "floor_packing": column / ell * particle_volume(diameter, dim),
    }
