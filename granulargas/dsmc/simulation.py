"""The Python driver of the homogeneous DSMC: :class:`DSMC`.

``DSMC`` owns the velocities (in particle-id order; there are no positions),
the random state and the speed classes of the majorant, and runs the compiled
loop of :mod:`granulargas.dsmc._loop` in chunks, calling ``progress`` between
them and turning status codes into :mod:`granulargas.errors` exceptions. Its
API mirrors :class:`granulargas.engine.Simulation` where that makes sense.
"""

from __future__ import annotations

import math

import numpy as np

from granulargas import theory
from granulargas.dsmc import _loop, _shear
from granulargas.dsmc._majorant import build_histogram, class_edge, largest_component, new_histogram, top_classes
from granulargas.dsmc._random import STATE_WORDS, seed_state
from granulargas.engine._drive import kick_scale, kick_velocities
from granulargas.engine._spin import kick_spin_rows
from granulargas.engine._state import species_record
from granulargas.engine._state import spins as spins_record
from granulargas.engine.driving import WhiteNoise
from granulargas.engine.pairs import pair_count_matrix, species_of_state
from granulargas.engine.rules import CollisionRule
from granulargas.engine.tangential import (
    TangentialRule,
    public_spins,
    rotational_temperature,
    spin_kick_scale,
    spins_of,
)
from granulargas.engine.shear import Shear
from granulargas.errors import ConfigError, SimulationError, TableRangeError
from granulargas.observables import energy_moments, kinetic_energy_momentum
from granulargas.state import PARTICLE_FIELDS, DSMCContinuation, State

_INT_MAX = np.iinfo(np.int64).max
#: per-particle fields of granulargas.state.PARTICLE_FIELDS that the DSMC moves or uses
OWN_FIELDS = ("velocities", "radii", "masses")


def collision_solid_angle(dim: int) -> float:
    """B_d = integral over unit vectors k of Theta(g^.k)(g^.k): pi (3D), 2 (2D)."""
    return math.pi ** ((dim - 1) / 2.0) / math.gamma((dim + 1) / 2.0)


def _aligned_rows(n, width):
    """Zeroed (n, width) float64 array starting on a 64-byte boundary."""
    buf = np.zeros(n * width + 8)
    offset = (-buf.ctypes.data % 64) // 8
    return buf[offset : offset + n * width].reshape(n, width)


class DSMC:
    """Direct Simulation Monte Carlo of a homogeneous granular gas (d = 2 or 3).

    Solves the homogeneous Enskog-Boltzmann equation with the sequential
    majorant process (:mod:`granulargas.dsmc._loop`): no time step, every
    collision at its own time, the engine's collision rules.

    Parameters
    ----------
    state : granulargas.state.State
        Velocities (N, d), radii and masses (in units of the reference diameter and
        mass), the clock and counters (``time``, ``collisions``, ``dissipated_energy``,
        and, when driven, ``kick_step`` and ``injected_energy``) and the DSMC's
        continuation (``state.dsmc``: random words, candidate count, pending
        collision, frame velocity). Without a continuation the DSMC works in the
        centre-of-mass frame: the velocities' mass-weighted mean is subtracted (kept
        in :attr:`frame_velocity`) and the random streams are seeded with ``seed``;
        with one the velocities are taken as they are and the run continues bit for
        bit. Positions, if the state has any, are not used (a homogeneous gas); walls
        are refused. The box, if any, gives the volume unless a density is given.
    rule : CollisionRule
        Elastic, constant or viscoelastic (the TC model needs pair histories and
        is not available).
    number_density, packing_fraction, volume : float
        At most one (none: the volume of ``state.box``): the density n = N / V, the
        packing fraction sum_i v_i / V (v_i the particle volume, or area in 2D), or V
        itself.
    chi : float or array (S, S), optional
        Pair correlation at contact; default the Enskog value
        :func:`granulargas.theory.contact_value` of the packing fraction
        (``chi=1`` gives the Boltzmann equation). A mixture (a rule with a table per pair
        of S species; the state's ``species`` index it) may give chi_ij per pair of species
        (e.g. :func:`granulargas.theory.mixture.mixture_contact_values`).
    seed : int
        Seed of the random streams (not used when the state has a continuation).
    driving : WhiteNoise, optional
        The engine's white-noise driving (:mod:`granulargas.engine._drive`, eq. (1)):
        at the times (k + 1/2) dt_k every velocity gets the same momentum-free
        Gaussian kick as in the engine (the same compiled kick and random stream, by
        particle id), from the state's ``kick_step`` on (None: the first after
        ``time``). After a kick the pending collision, accepted against the old
        velocities, is dropped and the majorant restarts from the kick time (the
        majorant process is memoryless, so this is exact). Rough particles: its
        ``rotational_fraction`` of the power goes to the spins, as in the engine.
    tangential : TangentialRule, optional
        Rough particles (:class:`granulargas.engine.TangentialRule`): the state's
        ``angular_velocities`` (default 0) and ``inertia`` (default 2/5 or 1/2) and the
        engine's rough collision law (:func:`granulargas.dsmc._collide.apply_rough_update`).
        None: smooth particles.

    Notes
    -----
    ``run(until)`` executes every collision with time <= ``until`` and sets
    ``time = until``; a run to 2t equals a run to t continued to 2t bit for bit.
    A homogeneous gas is Galilean invariant: :attr:`velocities` are peculiar
    velocities. Rounding makes their mean drift at ~1e-16 of their size; it is
    subtracted again every 8N collisions (:func:`granulargas.dsmc._loop.recentre`),
    so a gas can cool by hundreds of orders of magnitude.
    Each particle collides at the Enskog frequency of the density (N - 1)/V of its
    partners, so the collision frequency is (N - 1)/N times Enskog's omega(n).
    """

    def __init__(self, state: State, rule: CollisionRule, *, number_density: float | None = None,
                 packing_fraction: float | None = None, volume: float | None = None, chi: float | None = None,
                 seed: int = 0, driving: WhiteNoise | None = None, shear: Shear | None = None,
                 tangential: TangentialRule | None = None):
        if not isinstance(state, State):
            raise TypeError("state must be a granulargas.state.State")
        state.check_shapes()
        vel = state.velocities
        n, d = vel.shape
        if n < 2:
            raise ConfigError(f"velocities: N = {n}, need at least 2 particles")
        if n >= 2**31:
            raise ConfigError(f"velocities: N = {n}, at most 2^31 - 1 particles")
        if not np.all(np.isfinite(vel)):
            raise ConfigError("velocities: non-finite values")
        rad, mas = state.radii.copy(), state.masses.copy()
        if tangential is not None and not isinstance(tangential, TangentialRule):
            raise TypeError("tangential must be a granulargas.engine.TangentialRule or None")
        if isinstance(driving, WhiteNoise) and driving.rotational_fraction > 0.0 and tangential is None:
            raise ConfigError(f"driving: rotational_fraction = {driving.rotational_fraction}: smooth particles "
                              "have no spins to drive (give a tangential rule)")
        self.tangential = tangential
        own = OWN_FIELDS + (("angular_velocities", "inertia") if tangential is not None else ())
        # per-particle fields the DSMC does not use (a homogeneous gas has no positions and images):
        # kept as they are, returned by ``state``
        self._carried = {f.name: getattr(state, f.name).copy() for f in PARTICLE_FIELDS
                         if f.name not in own + ("positions", "images") and getattr(state, f.name) is not None}
        for name, arr in (("radii", rad), ("masses", mas)):
            if not (np.all(arr > 0) and np.all(np.isfinite(arr))):
                raise ConfigError(f"{name}: every value must be finite and > 0")
        if not isinstance(rule, CollisionRule):
            raise TypeError("rule must be a granulargas.engine.CollisionRule")
        if rule.tc_time is not None:
            raise ConfigError(f"tc_time = {rule.tc_time}: the TC model is not available in DSMC "
                              f"(there is no inelastic collapse to cure; use tc_time=None)")
        if "wall" in state.boundary:
            raise ConfigError(f"boundary = {list(state.boundary)}: the DSMC simulates a homogeneous gas, "
                              f"without walls")
        self._boundary = state.boundary
        time, collisions, dissipated_energy = state.time, state.collisions, state.dissipated_energy
        kick_step, injected_energy = state.kick_step, state.injected_energy
        cont = state.dsmc
        self.dimension = d
        self.rule = rule

        # density: at most one of n, packing fraction, V; else the state's box
        given = [x is not None for x in (number_density, packing_fraction, volume)]
        if sum(given) > 1:
            raise ConfigError("DSMC takes at most one of number_density, packing_fraction, volume")
        if sum(given) == 0 and state.box is None:
            raise ConfigError("DSMC needs a density: the state's box, or one of number_density, "
                              "packing_fraction, volume")
        self._box = state.box.copy() if sum(given) == 0 else None
        # identical particles keep no per-particle arrays (32 bytes per particle in 3D)
        self._mono = bool(np.all(rad == rad.flat[0]) and np.all(mas == mas.flat[0]))
        if self._mono:
            r0, m0 = float(rad.flat[0]), float(mas.flat[0])
            solid = n * float(theory.particle_volume(2.0 * r0, d))
            sigma_max = 2.0 * r0
            self._rad_k = self._mas_k = np.zeros(1)
        else:
            r0, m0 = float(rad[0]), float(mas[0])
            solid = float(np.sum(theory.particle_volume(2.0 * rad, d)))
            sigma_max = 2.0 * float(rad.max())
            self._rad_k, self._mas_k = rad, mas
        self._r0, self._m0 = r0, m0
        self._mass_arg = np.array([m0]) if self._mono else mas  # for the moment kernels
        if number_density is not None:
            value, name = float(number_density), "number_density"
            vol = n / value if value > 0 else math.nan
        elif packing_fraction is not None:
            value, name = float(packing_fraction), "packing_fraction"
            vol = solid / value if value > 0 else math.nan
        elif volume is not None:
            value, name = float(volume), "volume"
            vol = value
        else:
            value, name = float(np.prod(state.box)), "box"
            vol = value
        if not (vol > 0 and math.isfinite(vol)):
            raise ConfigError(f"{name} = {value}: must be finite and > 0")
        self.volume = vol
        self.number_density = n / vol
        self.packing_fraction = solid / vol
        if not self.packing_fraction < 1.0:
            raise ConfigError(f"{name} = {value}: packing fraction {self.packing_fraction:.4g} "
                              f"must be < 1")
        if chi is None:
            chi = float(theory.contact_value(self.packing_fraction, d))
        chi_pairs = None
        if np.ndim(chi) == 2:
            chi_pairs = np.array(chi, dtype=np.float64)
            if rule.pairs is None or chi_pairs.shape != (rule.species,) * 2:
                raise ConfigError(f"chi: shape {chi_pairs.shape}: a table of chi per pair of species needs a rule "
                                  f"with a table per pair of as many species ({rule.species or 'none'})")
            if not (np.all(chi_pairs > 0) and np.all(np.isfinite(chi_pairs))
                    and np.array_equal(chi_pairs, chi_pairs.T)):
                raise ConfigError("chi: every chi_ij must be finite and > 0, the table symmetric")
            chi = float(chi_pairs.max())
        chi = float(chi)
        if not (chi > 0 and math.isfinite(chi)):
            raise ConfigError(f"chi = {chi}: must be finite and > 0")
        self.chi = chi
        #: a mixture's chi_ij (S, S) (None: one chi for every pair)
        self.chi_pairs = chi_pairs
        # a mixture: the law per pair of species, the acceptance weights chi_ij / chi_max, the counts
        self._species = None
        if rule.pairs is not None:
            of, counts = species_of_state(state, rule)
            weight = None if chi_pairs is None else chi_pairs / chi
            self._species = species_record(of, rule.pairs, counts, weight)

        kind, eps, _, pref, inv_h, coeffs = rule.kernel_arguments()
        self._kind, self._coeffs = kind, coeffs
        fpar = np.zeros(_loop.N_FPAR)
        fpar[_loop.F_EPS] = eps
        fpar[_loop.F_PREFACTOR] = pref
        fpar[_loop.F_INV_H] = inv_h
        fpar[_loop.F_SIGMA_MAX_POW] = sigma_max ** (d - 1)
        fpar[_loop.F_MASS] = m0
        fpar[_loop.F_RADIUS] = r0
        self._fpar = fpar

        width = 4 if d == 3 else 2
        rec = _aligned_rows(n, width)
        rec[:, :d] = vel
        self._rec = rec
        self._ring = np.zeros((2, _loop.RING), dtype=np.int64)
        # the rounding drift of the mean velocity is removed every 8 N collisions
        self._recentre_every = 8 * n

        scal = np.zeros(_loop.N_SCAL)
        iscal = np.zeros(_loop.N_ISCAL, dtype=np.int64)
        scal[_loop.S_TIME] = float(time)
        scal[_loop.S_DISSIPATED] = float(dissipated_energy)
        scal[_loop.S_RATE] = (0.5 * n * (n - 1) * chi * collision_solid_angle(d)
                              * sigma_max ** (d - 1) / vol)
        iscal[_loop.I_COLLISIONS] = int(collisions)
        iscal[_loop.I_ERR_I] = iscal[_loop.I_ERR_J] = -1
        iscal[_loop.I_PENDING_I] = iscal[_loop.I_PENDING_J] = -1
        scal[_loop.S_NEXT] = math.nan
        if cont is None:
            frame = vel.mean(axis=0) if self._mono else (mas @ vel) / mas.sum()
            rec[:, :d] -= frame
            rng = seed_state(seed)
        else:
            frame = cont.frame_velocity.copy()
            rng = cont.rng.copy()
            if frame.shape != (d,) or rng.shape != (STATE_WORDS,):
                raise ConfigError(f"dsmc: frame_velocity needs shape ({d},) and rng ({STATE_WORDS},)")
            iscal[_loop.I_CANDIDATES] = cont.candidates
            pi, pj = cont.pending_pair
            if pi >= 0:
                if not (0 <= pi < n and 0 <= pj < n and pi != pj):
                    raise ConfigError(f"dsmc: pending_pair = {(pi, pj)} is not a pair of the {n} particles")
                if not cont.pending_time >= time:
                    raise ConfigError(f"dsmc: pending_time = {cont.pending_time} lies before time = {time}")
                iscal[_loop.I_PENDING_I], iscal[_loop.I_PENDING_J] = pi, pj
                scal[_loop.S_NEXT] = cont.pending_time
        self.frame_velocity = frame
        self._rng = rng
        self.shear = shear
        # rough particles: spins (N, 3) in id order and the tangential law (None: smooth)
        self._spins = None
        if tangential is not None:
            w3, kappa = spins_of(state)
            self._kappa = kappa
            shared = bool(np.all(kappa == kappa[0]))
            self._spins = spins_record(w3, kappa[:1] if shared else kappa, tangential.code, tangential.restitution,
                                       tangential.friction, tangential.wall_beta, tangential.wall_mu)
        self._hist = new_histogram()
        iscal[_loop.I_TOP] = build_histogram(rec, d, self._hist)
        self._scal, self._iscal = scal, iscal
        self._rate_last = float("nan")
        self._acceptance_last = float("nan")
        self.driving = driving
        self._injected = float(injected_energy)
        self._kick_step = 0
        if driving is not None:
            if not isinstance(driving, WhiteNoise):
                raise TypeError("driving must be a granulargas.engine.WhiteNoise")
            dt = driving.interval
            if kick_step is None:  # the first kick after time (as the engine)
                k0 = max(0, int(math.floor(float(time) / dt - 0.5)))
                while (k0 + 0.5) * dt <= float(time):
                    k0 += 1
                self._kick_step = k0
            else:
                self._kick_step = kick_step
                if not (self._kick_step + 0.5) * dt > float(time):
                    raise ConfigError(f"kick_step = {kick_step}: the next driving step k must come after the "
                                      f"time {time} ((k + 1/2) interval > time)")
            self._kick_mass = mas
            self._kick_ident = np.arange(n, dtype=np.int32)
            self._kick_scale = kick_scale(driving.translational_rate, dt, n)
            if tangential is not None:
                self._kick_inertia = self._kappa * mas * rad**2
                self._spin_kick_scale = spin_kick_scale(driving, d)
        if shear is not None:
            if tangential is not None:
                raise ConfigError("shear: rough particles (a tangential rule) are not available in the DSMC of "
                                  "uniform shear flow")
            self._init_shear(shear, chi, sigma_max, r0, m0, eps, pref, inv_h, driving)

    # ------------------------------------------------------------------ helpers
    def _rate(self):
        """Current majorant rate Lambda (candidates per unit time)."""
        k1, k2 = top_classes(self._hist, self._iscal[_loop.I_TOP])
        return self._scal[_loop.S_RATE] * (class_edge(k1) + class_edge(k2))

    # ------------------------------------------------------------------ shear
    def _init_shear(self, shear, chi, sigma_max, r0, m0, eps, pref, inv_h, driving):
        """The uniform shear flow's loop state (:mod:`granulargas.dsmc._shear`)."""
        if not isinstance(shear, Shear):
            raise TypeError("shear must be a granulargas.engine.shear.Shear or None")
        if not self._mono or self._species is not None:
            raise ConfigError("shear: the DSMC of uniform shear flow takes identical particles (one diameter "
                              "and mass, no species table)")
        if driving is not None:
            raise ConfigError("shear: the DSMC of uniform shear flow takes no white-noise driving (use the "
                              "shear's thermostat)")
        d, n = self.dimension, self.n
        scal = np.zeros(_shear.N_SCAL)
        scal[_shear.S_TIME] = self._scal[_loop.S_TIME]
        scal[_shear.S_NEXT] = self._scal[_loop.S_NEXT]
        scal[_shear.S_DISSIPATED] = self._scal[_loop.S_DISSIPATED]
        scal[_shear.S_RATE] = self._scal[_loop.S_RATE]
        scal[_shear.S_REF] = self._scal[_loop.S_TIME]
        scal[_shear.S_SHEAR] = shear.rate
        scal[_shear.S_SIGMA] = sigma_max
        scal[_shear.S_EPS] = eps
        scal[_shear.S_PREFACTOR] = pref
        scal[_shear.S_INV_H] = inv_h
        scal[_shear.S_MASS] = m0
        scal[_shear.S_C] = _shear.C_OVER_B[d] * shear.rate * sigma_max
        iscal = np.zeros(_shear.N_ISCAL, dtype=np.int64)
        for a, b in ((_shear.I_COLLISIONS, _loop.I_COLLISIONS), (_shear.I_CANDIDATES, _loop.I_CANDIDATES),
                     (_shear.I_TOP, _loop.I_TOP), (_shear.I_PENDING_I, _loop.I_PENDING_I),
                     (_shear.I_PENDING_J, _loop.I_PENDING_J)):
            iscal[a] = self._iscal[b]
        iscal[_shear.I_ERR_I] = iscal[_shear.I_ERR_J] = -1
        self._uscal, self._uiscal = scal, iscal
        if iscal[_shear.I_PENDING_I] >= 0:  # a state's pending candidate: the sheared majorant restarts
            iscal[_shear.I_PENDING_I] = iscal[_shear.I_PENDING_J] = -1
            scal[_shear.S_NEXT] = math.nan
        self._tensor_start = float(scal[_shear.S_TIME])
        self._stress = np.zeros(18)
        _shear.stress_sums(self._rec, d, m0, shear.rate, 0.0, self._stress)
        self._rescale_step = shear.first_step(self.time)
        self._injected_shear = float(self._injected)

    def _window_end(self):
        return self._uscal[_shear.S_REF] + _shear.WINDOW / self.shear.rate

    def _rebase(self, t):
        """Stored velocities brought to time t (eq. (U1) of dsmc._shear), the pending candidate
        dropped (the majorant restarts at t: exact)."""
        sc = self._uscal
        d = self.dimension
        self._uiscal[_shear.I_TOP] = _shear.rebase(self._rec, d, self.shear.rate, t - sc[_shear.S_REF], self._hist)
        sc[_shear.S_REF] = t
        k = self._stress[6:].copy()
        _shear.stress_sums(self._rec, d, self._m0, self.shear.rate, 0.0, self._stress)
        self._stress[6:] = k
        self._uiscal[_shear.I_PENDING_I] = self._uiscal[_shear.I_PENDING_J] = -1
        sc[_shear.S_NEXT] = math.nan
        self._uiscal[_shear.I_REBASES] += 1

    def synchronise(self) -> "DSMC":
        """Under shear: bring the stored velocities to ``time`` and restart the majorant there
        (what ``DSMC(dsmc.state, ...)`` does, so that the two continue alike); otherwise nothing."""
        if self.shear is not None and self._uscal[_shear.S_REF] != self.time:
            self._rebase(self.time)
        return self

    def _advance_sheared(self, until, target, progress):
        d = self.dimension
        chunk = max(1 << 21, 4 * self.n)
        # a rebase costs a pass over the particles: at a high shear rate (short windows) the
        # work between two progress calls is bounded by this many rebases
        rebases_per_call = max(1, chunk // (4 * self.n))
        rebases = 0
        sc, isc = self._uscal, self._uiscal
        while True:
            t_w = self._window_end()
            status = _shear.advance_usf(self._rec, d, self._hist, self._rng, self._kind, self._coeffs, until, t_w,
                                        target, chunk, self._ring, sc, isc, self._stress)
            if status == _shear.BUDGET:
                if progress is not None:
                    progress(self)
                continue
            if status == _shear.DONE:
                if sc[_shear.S_TIME] < until:  # the window ended
                    self._rebase(sc[_shear.S_TIME])
                    rebases += 1
                    if progress is not None and rebases % rebases_per_call == 0:
                        self._sync_back()
                        progress(self)
                    continue
                break
            if status == _shear.MAX_COLLISIONS:
                break
            self._raise_sheared(status)

    def _raise_sheared(self, status):
        i, j = int(self._uiscal[_shear.I_ERR_I]), int(self._uiscal[_shear.I_ERR_J])
        where = f"at t = {self.time:.12g} after {self.collisions} collisions (particles {[i, j]})"
        if status == _shear.TABLE_RANGE:
            raise TableRangeError(f"impact beyond the restitution table {where}: build the table "
                                  f"with a larger beta_max")
        raise SimulationError(f"DSMC status {status} {where}")

    def _rescale(self):
        """The thermostat's step at its time: peculiar velocities scaled to its temperature."""
        sh = self.shear
        t = (self._rescale_step + 0.5) * sh.interval
        sc = self._uscal
        # the stress integrals up to t, then the velocities at t
        self._integrate_stress(t - sc[_shear.S_TIME])
        sc[_shear.S_TIME] = t
        self._rebase(t)
        v = self._rec[:, : self.dimension]
        e2 = float(np.sum(v * v)) * self._m0
        target = sh.temperature * self.dimension * self.n
        lam = math.sqrt(target / e2) if e2 > 0 else 1.0
        self._rec[:, : self.dimension] *= lam
        self._injected_shear += 0.5 * (target - e2)
        self._stress[:6] *= lam * lam
        self._uiscal[_shear.I_TOP] = build_histogram(self._rec, self.dimension, self._hist)
        self._rescale_step += 1
        self._sync_back()

    def _integrate_stress(self, dt):
        """The kinetic sums over dt of free flight (dsmc._shear eq. (U1)), as the loop does."""
        st, a = self._stress, self.shear.rate
        ad = a * dt
        s0, s1, s2, s3, s4, s5 = st[:6]
        st[6:12] += np.array([s0 - ad * s3 + ad * ad * s1 / 3.0, s1, s2, s3 - 0.5 * ad * s1, s4 - 0.5 * ad * s5,
                              s5]) * dt
        st[0] = s0 + (-2.0 * s3 + ad * s1) * ad
        st[3] = s3 - ad * s1
        st[4] = s4 - ad * s5

    def _sync_back(self):
        """The sheared loop's counters into the ones the properties read."""
        sc, isc = self._uscal, self._uiscal
        self._scal[_loop.S_TIME] = sc[_shear.S_TIME]
        self._scal[_loop.S_NEXT] = sc[_shear.S_NEXT]
        self._scal[_loop.S_DISSIPATED] = sc[_shear.S_DISSIPATED]
        for a, b in ((_shear.I_COLLISIONS, _loop.I_COLLISIONS), (_shear.I_CANDIDATES, _loop.I_CANDIDATES),
                     (_shear.I_TOP, _loop.I_TOP), (_shear.I_PENDING_I, _loop.I_PENDING_I),
                     (_shear.I_PENDING_J, _loop.I_PENDING_J)):
            self._iscal[b] = isc[a]
        self._injected = self._injected_shear

    def _current_rec(self):
        """The velocity rows at ``time`` (under shear the stored ones moved by eq. (U1))."""
        if self.shear is None:
            return self._rec
        rec = self._rec.copy()
        rec[:, 0] -= self.shear.rate * (self.time - self._uscal[_shear.S_REF]) * rec[:, 1]
        return rec

    def _shear_velocities(self):
        """V(time) of the stored V(t_r), eq. (U1)."""
        v = self._rec[:, : self.dimension].copy()
        v[:, 0] -= self.shear.rate * (self.time - self._uscal[_shear.S_REF]) * v[:, 1]
        return v

    def pressure_tensor_window(self) -> np.ndarray:
        """Under shear: the mean pressure tensor (d, d) since the previous call (or construction),
        kinetic (peculiar velocities) plus collisional transfer, then reset (dsmc._shear)."""
        if self.shear is None:
            raise ConfigError("pressure_tensor_window: the DSMC keeps the pressure tensor under shear only")
        t = self.time
        dt = t - self._tensor_start
        self._tensor_start = t
        k = self._stress[6:12].copy()
        w = self._stress[12:18].copy()
        self._stress[6:] = 0.0
        d = self.dimension
        if dt <= 0:
            return np.full((d, d), np.nan)
        full = np.empty((3, 3))
        for q, (a, b) in enumerate(((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))):
            full[a, b] = full[b, a] = k[q] + w[q]
        return full[:d, :d] / (self.volume * dt)

    # ---------------------------------------------------------------------- run
    def run(self, until: float, max_collisions: int | None = None, progress=None) -> "DSMC":
        """Process all candidates with time <= ``until``; then ``time = until``.

        Parameters
        ----------
        until : float
            End time (absolute). ``inf`` is allowed together with ``max_collisions``.
        max_collisions : int, optional
            Stop right after this many further collisions; ``time`` is then the
            time of the last one.
        progress : callable, optional
            ``progress(dsmc)`` is called between compiled chunks and at the end.

        Raises
        ------
        TableRangeError, SimulationError
        """
        until = float(until)
        if until < self.time:
            raise ValueError(f"run(until={until}): the simulation is already at time {self.time}")
        if math.isinf(until) and max_collisions is None:
            raise ValueError("run(until=inf) needs max_collisions")
        start_time, start_coll, start_cand = self.time, self.collisions, self.candidates
        target = _INT_MAX if max_collisions is None else start_coll + int(max_collisions)
        if self.shear is not None:
            sh = self.shear
            if sh.thermostat:
                while (self._rescale_step + 0.5) * sh.interval <= until:
                    t_r = (self._rescale_step + 0.5) * sh.interval
                    if t_r > self.time:
                        self._advance_sheared(t_r, target, progress)
                        self._sync_back()
                    if self.collisions >= target:
                        break
                    self._rescale()
                    if progress is not None and self._rescale_step % max(1, (1 << 19) // self.n) == 0:
                        progress(self)  # a pass over the particles per rescaling: bounded work between calls
            if self.collisions < target:
                self._advance_sheared(until, target, progress)
            self._sync_back()
        elif self.driving is not None:
            dt = self.driving.interval
            while (self._kick_step + 0.5) * dt <= until:
                t_kick = (self._kick_step + 0.5) * dt
                if t_kick > self.time:
                    self._advance(t_kick, target, progress)
                if self.collisions >= target:
                    break
                self._kick()
        if self.collisions < target and self.shear is None:
            self._advance(until, target, progress)
        dt = self.time - start_time
        dc = self.collisions - start_coll
        self._rate_last = 2.0 * dc / (self.n * dt) if dt > 0 else float("nan")
        cand = self.candidates - start_cand
        self._acceptance_last = dc / cand if cand > 0 else float("nan")
        if progress is not None:
            progress(self)
        return self

    def _kick(self):
        """One driving step at its time (class docstring): kick, rebuild the speed classes,
        drop the pending collision."""
        d = self.dimension
        self._scal[_loop.S_TIME] = (self._kick_step + 0.5) * self.driving.interval
        self._injected += kick_velocities(self._rec, 0, self._kick_mass, self._kick_ident, d,
                                          np.uint64(self.driving.seed), self._kick_step, self._kick_scale)
        if self._spins is not None:
            self._injected += kick_spin_rows(self._spins.w, self._kick_inertia, d, np.uint64(self.driving.seed),
                                             self._kick_step, self._spin_kick_scale)
        self._kick_step += 1
        self._iscal[_loop.I_TOP] = build_histogram(self._rec, d, self._hist)
        self._iscal[_loop.I_PENDING_I] = self._iscal[_loop.I_PENDING_J] = -1
        self._scal[_loop.S_NEXT] = math.nan

    def _advance(self, until, target, progress):
        """The compiled loop in chunks up to ``until`` or the collision count ``target``."""
        d = self.dimension
        vmax = float(largest_component(self._rec, d))
        if not (vmax < 1e150) or (0.0 < vmax < 1e-150):
            raise SimulationError(f"velocities out of range at t = {self.time:.12g} (max |v_a| = "
                                  f"{vmax:.3g}): squared speeds must stay within float64; rescale the units")
        if vmax == 0.0:
            raise SimulationError(f"all velocities are zero at t = {self.time:.12g}: nothing collides")
        chunk = max(1 << 21, 4 * self.n)
        s = self._scal
        while True:
            if self._spins is None:  # smooth particles: the loop without the rough update
                status = _loop.advance(self._rec, self._rad_k, self._mas_k, self._mono, d, self._hist,
                                       self._rng, self._kind, self._fpar, self._coeffs, until, target,
                                       chunk, self._recentre_every, self._ring, s, self._iscal, self._species)
            else:
                status = _loop.advance(self._rec, self._rad_k, self._mas_k, self._mono, d, self._hist,
                                       self._rng, self._kind, self._fpar, self._coeffs, until, target,
                                       chunk, self._recentre_every, self._ring, s, self._iscal, self._species,
                                       self._spins)
            if status == _loop.BUDGET:
                if progress is not None:
                    progress(self)
                continue
            if status in (_loop.DONE, _loop.MAX_COLLISIONS):
                break
            self._raise(status)

    def _raise(self, status):
        i, j = int(self._iscal[_loop.I_ERR_I]), int(self._iscal[_loop.I_ERR_J])
        where = (f"at t = {self.time:.12g} after {self.collisions} collisions "
                 f"(particles {[k for k in (i, j) if k >= 0]})")
        if status == _loop.TABLE_RANGE:
            raise TableRangeError(f"impact beyond the restitution table {where}: build the table "
                                  f"with a larger beta_max")
        raise SimulationError(f"DSMC status {status} {where}")

    # ------------------------------------------------------------ public state
    @property
    def n(self) -> int:
        """Number of particles."""
        return self._rec.shape[0]

    @property
    def time(self) -> float:
        return float(self._scal[_loop.S_TIME])

    @property
    def collisions(self) -> int:
        """Pair collisions so far."""
        return int(self._iscal[_loop.I_COLLISIONS])

    @property
    def candidates(self) -> int:
        """Candidate pairs drawn since the seed (accepted or not): the position in the pair stream."""
        return int(self._iscal[_loop.I_CANDIDATES])

    @property
    def velocities(self) -> np.ndarray:
        """Peculiar velocities (N, d), centre-of-mass frame (a copy; under shear relative to the
        flow, at ``time``)."""
        return self._current_rec()[:, : self.dimension].copy()

    @property
    def radii(self) -> np.ndarray:
        return np.full(self.n, self._r0) if self._mono else self._rad_k.copy()

    @property
    def masses(self) -> np.ndarray:
        return np.full(self.n, self._m0) if self._mono else self._mas_k.copy()

    @property
    def continuation(self) -> DSMCContinuation:
        """What continues this run bit for bit besides velocities, clock and counters:
        random words, position in the pair stream, the pending collision (already drawn)
        and the frame velocity (:class:`granulargas.state.DSMCContinuation`)."""
        pending = (int(self._iscal[_loop.I_PENDING_I]), int(self._iscal[_loop.I_PENDING_J]))
        if self.shear is not None:  # as synchronise() leaves it: the majorant restarts at time
            pending = (-1, -1)
        return DSMCContinuation(
            rng=self._rng.copy(), candidates=self.candidates, frame_velocity=self.frame_velocity.copy(),
            pending_pair=pending, pending_time=float(self._scal[_loop.S_NEXT]) if pending[0] >= 0 else math.nan)

    @property
    def state(self) -> State:
        """The state as a record (:class:`granulargas.state.State`; no positions, peculiar
        velocities, ``events`` = collisions, ``dsmc`` = :attr:`continuation`):
        ``DSMC(dsmc.state, rule, ...)`` with the same settings continues bit for bit. Its box
        is the one the DSMC took its volume from (None when a density was given)."""
        return State(positions=None, velocities=self.velocities, radii=self.radii, masses=self.masses,
                     box=None if self._box is None else self._box.copy(),
                     time=self.time, collisions=self.collisions, events=self.collisions,
                     dissipated_energy=self.dissipated_energy, injected_energy=self.injected_energy,
                     kick_step=None if self.driving is None else self.kick_step, dsmc=self.continuation,
                     boundary=self._boundary,
                     species_collisions=self.species_collisions,
                     **({} if self._spins is None else {"angular_velocities": self.angular_velocities,
                                                        "inertia": self._kappa.copy()}),
                     **{name: value.copy() for name, value in self._carried.items()})

    @property
    def species(self) -> np.ndarray | None:
        """Species index of each particle (N,), as given (None: all 0)."""
        return self._carried["species"].copy() if "species" in self._carried else None

    @property
    def species_collisions(self) -> np.ndarray | None:
        """Collisions so far per pair of species (S, S), symmetric (None without a pair table in
        the rule; as :attr:`granulargas.engine.Simulation.species_collisions`)."""
        if self._species is None:
            return None
        return pair_count_matrix(self._species.pairs, self.rule.species)

    @property
    def angular_velocities(self) -> np.ndarray | None:
        """Rough particles: angular velocities, (N, 3) in 3D and (N, 1) (about z) in 2D (None: smooth)."""
        return None if self._spins is None else public_spins(self._spins.w, self.dimension)

    @property
    def inertia(self) -> np.ndarray | None:
        """Rough particles: kappa = I / (m R^2) of each particle (None: smooth)."""
        return None if self._spins is None else self._kappa.copy()

    @property
    def rotational_temperature(self) -> float:
        """Rough particles: T_rot = sum I |w|^2 / (d_r N) (nan for smooth particles)."""
        if self._spins is None:
            return math.nan
        return rotational_temperature(self._spins.w, self._kappa, np.broadcast_to(self.masses, (self.n,)),
                                      np.broadcast_to(self.radii, (self.n,)), self.dimension)

    @property
    def rotational_energy(self) -> float:
        """Rough particles: sum I |w|^2 / 2 (0 for smooth particles)."""
        if self._spins is None:
            return 0.0
        return 0.5 * self.rotational_temperature * (3 if self.dimension == 3 else 1) * self.n

    # ------------------------------------------------------------- observables
    def _moments(self):
        return energy_moments(self._current_rec(), self.dimension, self._mass_arg)

    @property
    def kinetic_energy(self) -> float:
        """Kinetic energy of the peculiar motion, sum m c^2 / 2."""
        return float(kinetic_energy_momentum(self._current_rec(), self.dimension, self._mass_arg)[0])

    @property
    def momentum(self) -> np.ndarray:
        """Total momentum (d,) in the centre-of-mass frame: zero up to rounding."""
        return np.array(kinetic_energy_momentum(self._current_rec(), self.dimension,
                                                self._mass_arg)[1:1 + self.dimension])

    @property
    def temperature(self) -> float:
        """Granular temperature m <c^2> / d with c the peculiar velocity (k_B = 1)."""
        return float(self._moments()[0])

    @property
    def sonine_a2(self) -> float:
        """Second Sonine coefficient of the peculiar velocities (:mod:`granulargas.observables`)."""
        return float(self._moments()[1])

    @property
    def sonine_a3(self) -> float:
        """Third Sonine coefficient of the peculiar velocities (:mod:`granulargas.observables`)."""
        return float(self._moments()[2])

    @property
    def injected_energy(self) -> float:
        """Kinetic energy put in by the driving's kicks (cumulative)."""
        return self._injected

    @property
    def kick_step(self) -> int:
        """Index k of the next driving step (at (k + 1/2) interval)."""
        return self._kick_step

    @property
    def dissipated_energy(self) -> float:
        """Kinetic energy dissipated in collisions (cumulative)."""
        return float(self._scal[_loop.S_DISSIPATED])

    @property
    def collision_rate(self) -> float:
        """Collisions per particle per unit time (2 x pair collisions / N / dt) during the last run."""
        return self._rate_last

    @property
    def acceptance(self) -> float:
        """Accepted fraction of the candidates of the last run."""
        return self._acceptance_last

    @property
    def majorant_rate(self) -> float:
        """Current candidate rate Lambda of the majorant (per unit time)."""
        return float(self._rate())

    def __repr__(self):
        return (f"DSMC(N={self.n}, d={self.dimension}, packing={self.packing_fraction:.4g}, "
                f"chi={self.chi:.4g}, rule={self.rule.kind}, time={self.time:.6g}, "
                f"collisions={self.collisions})")
