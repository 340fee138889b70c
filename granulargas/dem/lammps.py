"""LAMMPS (time-stepped DEM) with the same contact law: inputs, runs, logs.

LAMMPS's ``pair_style granular`` with the ``hertz/material`` normal model and
``damping viscoelastic`` integrates Schwager & Pöschel (1997), eq. (2). For a pair of like
particles its normal force is

    F = (4/3) E_eff sqrt(R_eff) delta^{3/2} + eta_n0 m_eff sqrt(R_eff delta) delta',
    E_eff = E / (2 (1 - nu^2)),

while that equation reads F = m_eff rho sqrt(xi) (xi + (3/2) A xi') with
rho = 2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2)). So E = Y, nu = nu and

    eta_n0 = 3 A rho / (2 sqrt(R_eff)) = A Y / ((1 - nu^2) m_eff)

(docs/interoperability.md). LAMMPS multiplies eta_n0 by the pair's m_eff,
so for unequal masses eta_n0 is set per pair of atom types. The keyword
``limit_damping`` (no attractive normal force) gives the ``force`` end of
contact; without it a contact ends when the overlap vanishes (``overlap``).

The event-driven model is the limit of zero contact time at fixed
dimensionless damping beta = (3/2) A rho^{2/5} g^{1/5}. Our pair prefactor
k (ARCHITECTURE.md, beta = k (R_eff g / m_eff^2)^{1/5}) fixes the product
A (2 Y / (3 (1 - nu^2)))^{2/5} = (2/3) k, so a DEM run needs one more number,
the stiffness Y. :func:`stiffness_for_contact_time` picks Y such that the
elastic Hertz contact time at the thermal impact speed
g_T = sqrt(2 T0 / m_eff) is a stated fraction of the Enskog mean free time;
the timestep is a stated fraction of that contact time.

Everything is in reduced units (``units lj``): lengths in the reference
diameter, masses in the reference mass, energies in T0 (k_B = 1).

This module writes LAMMPS data and input files, runs ``lmp`` when it is
installed, and parses its thermo output. It never needs LAMMPS to import.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from granulargas import theory
from granulargas.contact import material
from granulargas.errors import InputFileError, UserError

#: Elastic Hertz contact duration in units rho^{-2/5} g^{-1/5}:
#: (4/5) (5/4)^{2/5} B(2/5, 1/2) = 3.2180...
HERTZ_DURATION = 0.8 * 1.25**0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)

#: Default poisson ratio when the config gives none (only Y / (1 - nu^2) matters).
DEFAULT_POISSON = 0.3

#: Marker printed by the head-on input, parsed by :func:`head_on_restitution`.
_RESULT = "GRANULARGAS_RESULT"


class LammpsError(UserError):
    """``lmp`` is missing, failed, or printed something we cannot parse."""

    exit_code = 3


# --------------------------------------------------------------------------- contact mapping


@dataclass(frozen=True)
class DemContact:
    """Viscoelastic Hertz contact for LAMMPS, reduced units.

    Attributes
    ----------
    young_modulus : float
        Y (LAMMPS's E for ``hertz/material``), energy / length^3.
    poisson_ratio : float
        nu.
    dissipation_time : float
        A, the dissipative material time (time units).
    end : str
        ``"force"`` (LAMMPS ``limit_damping``) or ``"overlap"``.
    """

    young_modulus: float
    poisson_ratio: float
    dissipation_time: float
    end: str = "overlap"

    def __post_init__(self):
        if self.end not in ("force", "overlap"):
            raise ValueError(f"end must be 'force' or 'overlap', not {self.end!r}")

    @property
    def reduced_modulus(self) -> float:
        """Y / (1 - nu^2)."""
        return self.young_modulus / (1.0 - self.poisson_ratio**2)

    def rho(self, radius_eff: float, mass_eff: float) -> float:
        """Schwager & Pöschel's rho = 2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2))
        (:func:`granulargas.contact.material.rho_from_material`)."""
        return float(material.rho_from_material(self.young_modulus, self.poisson_ratio, radius_eff, mass_eff))

    def eta_n0(self, mass_eff: float) -> float:
        """LAMMPS damping coefficient eta_n0 = 3 A rho / (2 sqrt(R_eff)) = A Y / ((1-nu^2) m_eff)."""
        return self.dissipation_time * self.reduced_modulus / mass_eff

    def beta(self, speed: float, radius_eff: float, mass_eff: float) -> float:
        """Dimensionless damping (3/2) A rho^{2/5} g^{1/5} of a collision at normal speed g
        (:func:`granulargas.contact.material.beta_from_material`)."""
        return float(material.beta_from_material(self.young_modulus, self.poisson_ratio, self.dissipation_time,
                                                 radius_eff, mass_eff, speed))

    def prefactor(self) -> float:
        """Our pair prefactor k = (3/2) A (2 Y / (3 (1 - nu^2)))^{2/5}
        (:func:`granulargas.contact.material.prefactor_from_material`)."""
        return float(material.prefactor_from_material(self.young_modulus, self.poisson_ratio, self.dissipation_time))

    def hertz_contact_time(self, speed: float, radius_eff: float, mass_eff: float) -> float:
        """Elastic Hertz duration HERTZ_DURATION rho^{-2/5} g^{-1/5} (time units)."""
        return HERTZ_DURATION * self.rho(radius_eff, mass_eff) ** -0.4 * speed**-0.2

    def _model(self, mass_eff: float) -> str:
        line = (f"hertz/material {self.young_modulus:.17g} {self.eta_n0(mass_eff):.17g} "
                f"{self.poisson_ratio:.17g} damping viscoelastic tangential linear_nohistory 0.0 0.0")
        return line + (" limit_damping" if self.end == "force" else "")

    def pair_coeff(self, itype, jtype, mass_eff: float) -> str:
        """The ``pair_coeff`` line for one pair of atom types."""
        return f"pair_coeff {itype} {jtype} {self._model(mass_eff)}"

    def wall_fix(self, fix_id: str, group: str, mass: float, axis: int, length: float) -> str:
        """A ``fix wall/gran`` line: flat walls of the same material at 0 and ``length``
        normal to ``axis`` for the atoms of ``group`` (all of mass ``mass``: the
        sphere-plane contact has m_eff = m_i, R_eff = R_i, as in the engine)."""
        return (f"fix {fix_id} {group} wall/gran granular {self._model(mass)} "
                f"{'xyz'[axis]}plane 0.0 {length:.17g}")

    @classmethod
    def from_prefactor(cls, prefactor: float, young_modulus: float, poisson_ratio: float = DEFAULT_POISSON,
                       end: str = "overlap") -> "DemContact":
        """The contact with our pair prefactor k at stiffness Y: A = (2/3) k / (2 Y / (3 (1-nu^2)))^{2/5}
        (:func:`granulargas.contact.material.dissipation_time_from_prefactor`)."""
        dissipation_time = material.dissipation_time_from_prefactor(prefactor, young_modulus, poisson_ratio)
        return cls(young_modulus, poisson_ratio, dissipation_time, end)

    @classmethod
    def from_beta(cls, beta: float, speed: float, young_modulus: float, radius_eff: float = 0.25,
                  mass_eff: float = 0.5, poisson_ratio: float = DEFAULT_POISSON, end: str = "overlap") -> "DemContact":
        """The contact giving damping ``beta`` at impact speed ``speed`` for the given pair."""
        probe = cls(young_modulus, poisson_ratio, 1.0, end)
        dissipation_time = beta / probe.beta(speed, radius_eff, mass_eff)
        return cls(young_modulus, poisson_ratio, dissipation_time, end)


def stiffness_for_contact_time(contact_time: float, speed: float, radius_eff: float, mass_eff: float,
                               poisson_ratio: float = DEFAULT_POISSON) -> float:
    """Young modulus Y whose elastic Hertz contact at impact speed g lasts ``contact_time``.

    From t_c = HERTZ_DURATION rho^{-2/5} g^{-1/5} and
    rho = 2 Y sqrt(R_eff) / (3 m_eff (1 - nu^2)).
    """
    rho = (HERTZ_DURATION / (contact_time * speed**0.2)) ** 2.5
    return rho * 3.0 * mass_eff * (1.0 - poisson_ratio**2) / (2.0 * math.sqrt(radius_eff))


def enskog_mean_free_time(dimension: int, packing_fraction: float, diameter: float = 1.0,
                          mass: float = 1.0, temperature: float = 1.0) -> float:
    """1 / collision frequency per particle of an elastic Enskog gas
    (:func:`granulargas.theory.collision_frequency`)."""
    if dimension not in (2, 3):
        raise ValueError(f"dimension must be 2 or 3, not {dimension}")
    n = theory.number_density(packing_fraction, dimension, diameter)
    return 1.0 / float(theory.collision_frequency(n, temperature, dimension, diameter, mass))


# --------------------------------------------------------------------------- running lmp


def find_lmp() -> str | None:
    """Path of the LAMMPS executable: $GRANULARGAS_LMP, else ``lmp``, ``lmp_serial``, ``lmp_mpi`` on PATH."""
    env = os.environ.get("GRANULARGAS_LMP")
    if env:
        return shutil.which(env)
    for name in ("lmp", "lmp_serial", "lmp_mpi"):
        path = shutil.which(name)
        if path:
            return path
    return None


def run_lammps(input_file: str | Path, workdir: str | Path | None = None, lmp: str | None = None,
               log: str = "log.lammps", timeout: float | None = None) -> str:
    """Run ``lmp -in input_file`` in ``workdir`` on one thread; return the log text.

    Raises
    ------
    LammpsError
        When no LAMMPS executable is found or the run fails (with the ERROR line).
    """
    lmp = lmp or find_lmp()
    if lmp is None:
        raise LammpsError("LAMMPS not found: install it (Debian: apt-get install lammps) or set GRANULARGAS_LMP")
    input_file = Path(input_file)
    workdir = Path(workdir) if workdir is not None else input_file.parent
    env = dict(os.environ, OMP_NUM_THREADS="1")
    proc = subprocess.run(
        [lmp, "-in", str(input_file.resolve()), "-log", log, "-screen", "none", "-nocite"],
        cwd=workdir, env=env, capture_output=True, text=True, timeout=timeout,
    )
    log_path = workdir / log
    text = log_path.read_text() if log_path.exists() else ""
    if proc.returncode != 0 or "ERROR" in text:
        errors = [ln for ln in (text + proc.stdout + proc.stderr).splitlines() if "ERROR" in ln]
        detail = errors[0].strip() if errors else f"exit code {proc.returncode}"
        raise LammpsError(f"LAMMPS failed on {input_file}: {detail}")
    return text


def parse_thermo(text: str) -> list[dict[str, np.ndarray]]:
    """Thermo tables of a LAMMPS log: one ``{column: float array}`` per ``run``.

    A table starts at the header line beginning with ``Step`` and ends at
    ``Loop time of``; warnings interleaved with the rows are skipped.
    """
    tables: list[dict[str, np.ndarray]] = []
    header: list[str] | None = None
    rows: list[list[float]] = []
    for line in text.splitlines():
        words = line.split()
        if header is None:
            if words and words[0] == "Step":
                header, rows = words, []
            continue
        if line.startswith("Loop time of"):
            tables.append(_table(header, rows))
            header = None
            continue
        if len(words) == len(header):
            try:
                rows.append([float(w) for w in words])
            except ValueError:
                pass
    if header is not None:  # truncated log (run still going or killed)
        tables.append(_table(header, rows))
    return tables


def _table(header, rows):
    data = np.array(rows, dtype=float).reshape(len(rows), len(header))
    return {name: data[:, k].copy() for k, name in enumerate(header)}


def read_thermo(path: str | Path) -> dict[str, np.ndarray]:
    """All thermo rows of a log file, runs concatenated (repeated steps dropped)."""
    path = Path(path)
    if not path.exists():
        raise InputFileError(f"{path}: no such LAMMPS log")
    tables = parse_thermo(path.read_text())
    if not tables:
        raise InputFileError(f"{path}: no thermo output found")
    out = {k: v for k, v in tables[0].items()}
    for tab in tables[1:]:
        keep = tab["Step"] > out["Step"][-1]
        for k in out:
            out[k] = np.concatenate([out[k], tab[k][keep]])
    return out


def loop_time(text: str) -> float:
    """Sum of the ``Loop time of X on ...`` wall times of all runs in a log (s)."""
    return sum(float(m.group(1)) for m in re.finditer(r"Loop time of ([0-9.eE+-]+) on", text))


def read_contacts(path: str | Path, radii=None, contact: "DemContact | None" = None):
    """Collisions and stored elastic energy of a LAMMPS gas run from its contact dump.

    Reads the ``contacts.<name>`` dump of :func:`write_lammps_gas` (``contact_pairs=True``:
    atom ids and distance of every overlapping pair at every step) and counts, at each
    step, the pairs in contact that were not in contact at the step before: one per
    collision, as long as a contact spans at least one step (the export's timestep is
    a fraction of the contact time). A pair that touches again after separating counts
    again. With ``radii`` and ``contact`` it also sums the elastic Hertz energy of the
    contacts, (8/15) E_eff sqrt(R_eff) xi^(5/2) per pair, E_eff = Y / (2 (1 - nu^2)),
    xi = R_i + R_j - r (the potential of the elastic force of
    :class:`DemContact`; the kinetic temperature of a DEM gas leaves it out).

    Parameters
    ----------
    path : path
    radii : float array (N,), optional
        Radius of atom id k at index k - 1 (the order :func:`write_lammps_gas` writes).
    contact : DemContact, optional

    Returns
    -------
    steps, new : int arrays (S,)
        Dumped steps and the new contacts at each (0 at the first dumped step).
    elastic : float array (S,) or None
        Elastic energy stored in the contacts at each dumped step.
    """
    path = Path(path)
    if not path.exists():
        raise InputFileError(f"{path}: no such LAMMPS contact dump")
    energy = radii is not None and contact is not None
    if energy:
        radii = np.asarray(radii, dtype=float)
        e_eff = contact.young_modulus / (2.0 * (1.0 - contact.poisson_ratio**2))
    steps, new, elastic = [], [], []
    previous: set = set()
    with open(path) as fh:
        while True:
            line = fh.readline()
            if not line:
                break
            if not line.startswith("ITEM: TIMESTEP"):
                raise InputFileError(f"{path}: expected 'ITEM: TIMESTEP', found {line.strip()!r}")
            step = int(fh.readline())
            fh.readline()  # ITEM: NUMBER OF ENTRIES
            count = int(fh.readline())
            line = fh.readline()
            while line and not line.startswith("ITEM: ENTRIES"):  # box bounds
                line = fh.readline()
            current = set()
            e = 0.0
            for _ in range(count):
                words = fh.readline().split()
                i, j = int(float(words[0])), int(float(words[1]))
                current.add((i, j) if i < j else (j, i))
                if energy:
                    ri, rj = radii[i - 1], radii[j - 1]
                    xi = ri + rj - float(words[2])
                    if xi > 0.0:
                        e += (8.0 / 15.0) * e_eff * math.sqrt(ri * rj / (ri + rj)) * xi**2.5
            steps.append(step)
            new.append(len(current - previous) if len(steps) > 1 else 0)
            elastic.append(e)
            previous = current
    return (np.array(steps, dtype=np.int64), np.array(new, dtype=np.int64),
            np.array(elastic) if energy else None)


def output_time(text: str) -> float:
    """Sum of the ``Output`` rows of the timing breakdowns of a log (s): the time
    LAMMPS spent writing thermo lines and dumps, part of :func:`loop_time`."""
    return sum(float(m.group(1)) for m in re.finditer(r"^Output\s*\|\s*[0-9.eE+-]+\s*\|\s*([0-9.eE+-]+)", text,
                                                      flags=re.M))


# --------------------------------------------------------------------------- head-on collisions


def _two_spheres(contact: DemContact, normal_speed: float, tangential_speed: float, timestep: float,
                 radii, masses, title: str) -> str:
    """Setup of a two-sphere collision: touching at step 0 along x, zero total momentum.

    Sphere 1 (type 1) at x = -r1, sphere 2 (type 2) at x = +r2; relative
    velocity v1 - v2 = (normal_speed, tangential_speed, 0). eta_n0 is set per
    pair of types from the pair's m_eff. Shrink-wrapped boundaries (no images).
    """
    (r1, r2), (m1, m2) = radii, masses
    span = 4.0 * (r1 + r2) + 1.0
    coeffs = "\n".join(contact.pair_coeff(i, j, mi * mj / (mi + mj))
                        for i, j, mi, mj in ((1, 1, m1, m1), (1, 2, m1, m2), (2, 2, m2, m2)))
    boundary = "m p p" if tangential_speed == 0.0 else "m m m"
    return f"""\
# {title}
units lj
atom_style sphere
atom_modify map array
dimension 3
boundary {boundary}
comm_modify vel yes
region box block {-span} {span} {-span / 2} {span / 2} {-span / 2} {span / 2} units box
create_box 2 box
create_atoms 1 single {-r1:.17g} 0 0 units box
create_atoms 2 single {r2:.17g} 0 0 units box
set atom 1 diameter {2 * r1:.17g}
set atom 2 diameter {2 * r2:.17g}
set atom 1 mass {m1:.17g}
set atom 2 mass {m2:.17g}
velocity all set 0 0 0 units box
set atom 1 vx {m2 / (m1 + m2) * normal_speed:.17g}
set atom 2 vx {-m1 / (m1 + m2) * normal_speed:.17g}
set atom 1 vy {m2 / (m1 + m2) * tangential_speed:.17g}
set atom 2 vy {-m1 / (m1 + m2) * tangential_speed:.17g}
pair_style granular
{coeffs}
neighbor {0.2 * (r1 + r2)} bin
neigh_modify delay 0 every 1 check yes
timestep {timestep:.17g}
fix integrate all nve/sphere
"""


def head_on_input(contact: DemContact, speed: float, timestep: float, steps: int,
                  radii=(0.5, 0.5), masses=(1.0, 1.0)) -> str:
    """LAMMPS input for a head-on collision of two spheres at relative speed ``speed``.

    Sphere 1 (atom type 1) and sphere 2 (type 2) touch at step 0 (zero
    overlap) and approach along x with zero total momentum; eta_n0 is set per
    pair of types from the pair's m_eff. After ``steps`` steps the script
    prints ``GRANULARGAS_RESULT <g_after>``, the relative separation speed
    (positive when receding).
    """
    setup = _two_spheres(contact, speed, 0.0, timestep, radii, masses,
                         "head-on collision of two viscoelastic spheres (granulargas.dem.lammps.head_on_input)")
    return setup + f"""\
variable g equal vx[2]-vx[1]
thermo_style custom step v_g
thermo_modify format float %.17g
thermo {max(steps // 4, 1)}
run {steps}
print "{_RESULT} ${{g}}"
"""


def oblique_input(contact: DemContact, normal_speed: float, tangential_speed: float, timestep: float,
                  steps: int, radii=(0.5, 0.5), masses=(1.0, 1.0)) -> str:
    """LAMMPS input for an oblique collision: the relative motion at every step.

    Set up as :func:`head_on_input` plus a tangential relative speed along y;
    thermo prints, every step, the relative position x1 - x2 (``v_rx v_ry
    v_rz``) and velocity v1 - v2 (``v_vx v_vy v_vz``) at full precision.
    """
    setup = _two_spheres(contact, normal_speed, tangential_speed, timestep, radii, masses,
                         "oblique collision of two viscoelastic spheres (granulargas.dem.lammps.oblique_input)")
    return setup + f"""\
variable rx equal x[1]-x[2]
variable ry equal y[1]-y[2]
variable rz equal z[1]-z[2]
variable vx equal vx[1]-vx[2]
variable vy equal vy[1]-vy[2]
variable vz equal vz[1]-vz[2]
thermo_style custom step time v_rx v_ry v_rz v_vx v_vy v_vz
thermo_modify format float %.17g
thermo 1
run {steps}
"""


def head_on_restitution(contact: DemContact, speed: float, steps_per_contact: int, workdir: str | Path,
                        radii=(0.5, 0.5), masses=(1.0, 1.0), lmp: str | None = None) -> float:
    """Coefficient of restitution of one LAMMPS head-on collision.

    The timestep is the pair's elastic Hertz contact time / ``steps_per_contact``;
    the run lasts long enough for any damping (the ``overlap`` end's
    duration grows with beta), then eps = g_after / g_before.
    """
    (r1, r2), (m1, m2) = radii, masses
    r_eff, m_eff = r1 * r2 / (r1 + r2), m1 * m2 / (m1 + m2)
    t_c = contact.hertz_contact_time(speed, r_eff, m_eff)
    beta = contact.beta(speed, r_eff, m_eff)
    dt = t_c / steps_per_contact
    duration = t_c * (2.0 + 2.0 * beta)  # generous: the overlap end lengthens with beta
    steps = int(math.ceil(duration / dt))
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / "in.head_on"
    inp.write_text(head_on_input(contact, speed, dt, steps, radii, masses))
    text = run_lammps(inp, workdir, lmp=lmp)
    match = re.search(rf"^{_RESULT} (\S+)", text, flags=re.M)
    if match is None:
        raise LammpsError(f"LAMMPS log in {workdir} has no {_RESULT} line")
    return float(match.group(1)) / speed


def oblique_trajectory(contact: DemContact, normal_speed: float, tangential_speed: float, timestep: float,
                       steps: int, workdir: str | Path, radii=(0.5, 0.5), masses=(1.0, 1.0),
                       lmp: str | None = None) -> dict[str, np.ndarray]:
    """Run :func:`oblique_input`; return the relative motion at every step.

    Returns
    -------
    dict
        ``t`` (steps + 1,), ``r`` and ``v`` (steps + 1, 3): time, x1 - x2 and v1 - v2.
    """
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / "in.oblique"
    inp.write_text(oblique_input(contact, normal_speed, tangential_speed, timestep, steps, radii, masses))
    tables = parse_thermo(run_lammps(inp, workdir, lmp=lmp))
    if not tables or "v_rx" not in tables[0]:
        raise LammpsError(f"LAMMPS log in {workdir} has no oblique-collision thermo table")
    tab = tables[0]
    return {"t": tab["Time"], "r": np.column_stack([tab["v_rx"], tab["v_ry"], tab["v_rz"]]),
            "v": np.column_stack([tab["v_vx"], tab["v_vy"], tab["v_vz"]])}


def stiffness_for_compression(delta: float, speed: float, radius_eff: float, mass_eff: float, distance: float,
                              poisson_ratio: float = DEFAULT_POISSON) -> float:
    """Young modulus Y whose compression scale (speed^2 / rho)^{2/5} is ``delta`` x ``distance``.

    delta is the third parameter of the oblique contact (:mod:`granulargas.contact.oblique`).
    """
    rho = speed**2 / (delta * distance) ** 2.5
    return rho * 3.0 * mass_eff * (1.0 - poisson_ratio**2) / (2.0 * math.sqrt(radius_eff))


# --------------------------------------------------------------------------- a whole gas


@dataclass(frozen=True)
class LammpsExport:
    """What :func:`write_lammps_gas` wrote and the numbers it chose (reduced units)."""

    input_file: Path
    data_file: Path
    contact: DemContact
    timestep: float
    steps: int
    thermo_every: int
    contact_time: float  # elastic Hertz duration at the thermal impact speed, reference pair
    mean_free_time: float  # Enskog, at the initial temperature
    contact_fraction: float  # contact_time / mean_free_time
    steps_per_contact: int
    thermal_speed: float  # g_T = sqrt(2 T0 / m_eff), reference pair
    eta_n0: dict  # (itype, jtype) -> LAMMPS eta_n0
    type_masses: tuple  # mass of atom type 1, 2, ...

    def summary(self) -> dict:
        """JSON-friendly parameters (written beside the input as ``granulargas_lammps.json``)."""
        return {
            "input_file": self.input_file.name,
            "data_file": self.data_file.name,
            "young_modulus": self.contact.young_modulus,
            "poisson_ratio": self.contact.poisson_ratio,
            "dissipation_time": self.contact.dissipation_time,
            "end": self.contact.end,
            "prefactor": self.contact.prefactor(),
            "timestep": self.timestep,
            "steps": self.steps,
            "thermo_every": self.thermo_every,
            "contact_time": self.contact_time,
            "mean_free_time": self.mean_free_time,
            "contact_fraction": self.contact_fraction,
            "steps_per_contact": self.steps_per_contact,
            "thermal_speed": self.thermal_speed,
            "eta_n0": {f"{i} {j}": v for (i, j), v in self.eta_n0.items()},
            "type_masses": list(self.type_masses),
        }


#: More distinct masses than this cannot be mapped to LAMMPS atom types.
MAX_MASS_TYPES = 32


def write_lammps_gas(directory, positions, velocities, radii, masses, box, prefactor, *, end="overlap",
                     end_time, thermo_interval=None, contact_fraction=0.01, steps_per_contact=50,
                     poisson_ratio=DEFAULT_POISSON, name="granulargas", source="", time_origin=0.0,
                     boundary=None, young_modulus=None, pressure=False, contact_pairs=False,
                     species=None) -> LammpsExport:
    """Write a LAMMPS data file and input script equivalent to one of our runs.

    Parameters
    ----------
    directory : path
        Created if needed; receives ``data.<name>``, ``in.<name>`` and
        ``granulargas_lammps.json``.
    positions, velocities : float arrays (N, d), d = 2 or 3
        Initial state, positions in [0, box).
    radii, masses : float arrays (N,)
    box : float array (d,)
        Box edges.
    prefactor : float or array (S, S)
        Our pair prefactor k (beta = k (R_eff g / m_eff^2)^{1/5}); a mixture (``species``):
        one per pair of species.
    end : {"overlap", "force"}
        End of contact; ``force`` adds LAMMPS's ``limit_damping``.
    end_time : float
        Simulated time (reduced units).
    thermo_interval : float, optional
        Time between thermo lines (default end_time / 200).
    contact_fraction : float
        Elastic Hertz contact time at the thermal impact speed / Enskog mean
        free time, both for the reference pair (mean diameter and mass) at the
        initial temperature; sets the stiffness Y.
    steps_per_contact : int
        Timestep <= contact time / steps_per_contact, a whole number of steps to end_time.
    time_origin : float
        Our time at the exported state (a restart); LAMMPS's time starts at 0.
    boundary : sequence of d str, optional
        "periodic" or "wall" per axis (default all periodic). A wall axis becomes a
        fixed (``f``) LAMMPS boundary with a ``fix wall/gran`` of the same contact law
        at 0 and L for each atom type (:meth:`DemContact.wall_fix`).
    young_modulus : float, optional
        The stiffness Y (reduced units) instead of the one ``contact_fraction``
        gives, e.g. that of a config's ``[collision.material]``; the export then
        reports the contact fraction this Y has.
    pressure : bool
        Add the thermo column ``f_granP``: the pressure (kinetic with the peculiar
        velocities + pair virial, ``compute pressure`` of ``c_granT``) averaged over
        every step of the thermo interval that ends at the row (``fix ave/time``).
    contact_pairs : bool
        Dump the atom ids and the distance of every pair in contact (overlap > 0)
        at every step to ``contacts.<name>`` (``compute property/local`` and
        ``compute pair/local ... cutoff radius``); :func:`read_contacts` turns it
        into the number of collisions and the elastic energy stored in the contacts.
    species : int array (N,), optional
        A mixture: atom type s + 1 for species s, each with its own mass, and one
        ``pair_coeff`` per pair of species with that pair's prefactor and stiffness
        (``young_modulus`` may then be an (S, S) table of the pairs' Y / (1 - nu^2) = 2 Y*,
        Y* the effective modulus of the two materials; LAMMPS's explicit ``pair_coeff i j``
        of ``hertz/material`` takes E / (2 (1 - nu^2)) as the pair's effective modulus).

    Notes
    -----
    Atom types are the distinct masses (eta_n0 depends on the pair's m_eff
    but not on the radii), so a continuously polydisperse gas of equal masses
    is exported exactly; more than :data:`MAX_MASS_TYPES` distinct masses
    are refused. Per-atom diameters go to the data file. A mixture's types are its species.
    """
    positions = np.asarray(positions, dtype=float)
    velocities = np.asarray(velocities, dtype=float)
    radii = np.asarray(radii, dtype=float)
    masses = np.asarray(masses, dtype=float)
    box = np.asarray(box, dtype=float)
    d = positions.shape[1]
    type_masses, typeid = _check_export(d, masses, contact_fraction, young_modulus, steps_per_contact, end_time,
                                        species, prefactor)
    ntypes = len(type_masses)
    k_pairs = np.broadcast_to(np.asarray(prefactor, dtype=float), (ntypes, ntypes))
    young, y_pairs, t_contact, tau_free, contact_fraction, g_thermal = _stiffness(
        velocities, radii, masses, box, contact_fraction, young_modulus, poisson_ratio, typeid, ntypes)
    pair_contact = {(i, j): DemContact.from_prefactor(float(k_pairs[i, j]), float(y_pairs[i, j]), poisson_ratio, end)
                    for i in range(ntypes) for j in range(ntypes)}
    contact = pair_contact[(0, 0)] if species is not None else DemContact.from_prefactor(
        float(k_pairs[0, 0]), young, poisson_ratio, end)
    steps, dt, thermo_every = _time_steps(end_time, steps_per_contact, t_contact, thermo_interval, source)

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    data_file = directory / f"data.{name}"
    input_file = directory / f"in.{name}"
    eta = {}
    for i in range(ntypes):
        for j in range(i, ntypes):
            mi, mj = type_masses[i], type_masses[j]
            eta[(i + 1, j + 1)] = float(pair_contact[(i, j)].eta_n0(mi * mj / (mi + mj)))

    _write_data_file(data_file, positions, velocities, radii, masses, typeid + 1, ntypes, box, source)
    header = [
        f"# LAMMPS input written by granulargas export lammps{' from ' + source if source else ''}",
        "# Same contact law as granulargas (Schwager & Pöschel (1997), eq. (2)): hertz/material + damping viscoelastic,",
        "# E = Y, nu = nu, eta_n0 = A Y / ((1 - nu^2) m_eff) per pair of atom types;",
        f"# end of contact '{end}'" + (" -> limit_damping" if end == "force" else " (no limit_damping)") + ".",
        (f"# Dissipation time A = {contact.dissipation_time:.6g}, pair prefactor k = {float(k_pairs[0, 0]):.6g}."
         if species is None else f"# A mixture of {ntypes} species = atom types 1..{ntypes}: prefactor k, stiffness "
                                 "and A per pair of types (pair_coeff lines)."),
        f"# Stiffness: elastic Hertz contact time {t_contact:.6g} at the thermal impact speed "
        f"{g_thermal:.6g} = {contact_fraction:g} x Enskog mean free time {tau_free:.6g}.",
        f"# Timestep {dt:.6g} <= contact time / {steps_per_contact}; {steps} steps to t = {end_time:.6g}.",
        "# Thermo: c_granT = m<c^2>/d (peculiar velocity c, d N degrees of freedom).",
        f"# LAMMPS time 0 is granulargas time {time_origin:.17g}.",
    ]
    lines = header + _input_commands(pair_contact, data_file.name, type_masses, eta, radii, box, boundary, dt, steps,
                                     thermo_every, pressure, contact_pairs, name)
    input_file.write_text("\n".join(lines))
    export = LammpsExport(input_file, data_file, contact, dt, steps, thermo_every, t_contact, tau_free,
                          contact_fraction, steps_per_contact, g_thermal, eta, tuple(float(m) for m in type_masses))
    summary = {**export.summary(), "time_origin": float(time_origin)}
    if species is not None:
        summary["pairs"] = {f"{i + 1} {j + 1}": {"prefactor": float(k_pairs[i, j]), "young_modulus": c.young_modulus,
                                                 "dissipation_time": c.dissipation_time}
                            for (i, j), c in pair_contact.items() if i <= j}
    (directory / "granulargas_lammps.json").write_text(json.dumps(summary, indent=2) + "\n")
    return export


def _check_export(d, masses, contact_fraction, young_modulus, steps_per_contact, end_time, species, prefactor):
    """The export's arguments checked (one :class:`UserError` each); (masses of the atom types,
    each particle's type index): a mixture's types are its species, otherwise the distinct masses."""
    if d not in (2, 3):
        raise ValueError(f"dimension must be 2 or 3, not {d}")
    if young_modulus is None and not 0.0 < contact_fraction < 1.0:  # also rejects nan
        raise UserError(f"contact fraction = {contact_fraction}: must lie in (0, 1)")
    if steps_per_contact < 2:
        raise UserError(f"steps per contact = {steps_per_contact}: must be an integer >= 2")
    if not end_time > 0.0:
        raise UserError(f"end time = {end_time}: must be > 0 (LAMMPS runs for a fixed time)")
    if species is not None:
        typeid = np.asarray(species, dtype=np.int64)
        ntypes = int(np.asarray(prefactor).shape[0]) if np.ndim(prefactor) == 2 else int(typeid.max()) + 1
        type_masses = np.array([masses[typeid == s][0] if np.any(typeid == s) else 1.0 for s in range(ntypes)])
        if np.any(masses != type_masses[typeid]):
            raise UserError("species: every particle of a species needs its species' mass (one LAMMPS atom type each)")
    else:
        type_masses, typeid = np.unique(masses, return_inverse=True)
    if len(type_masses) > MAX_MASS_TYPES:
        raise UserError(
            f"{len(type_masses)} distinct particle masses: LAMMPS export supports at most {MAX_MASS_TYPES} "
            "(eta_n0 is set per pair of atom types); use a common mass"
        )
    return type_masses, typeid


def _stiffness(velocities, radii, masses, box, contact_fraction, young_modulus, poisson_ratio, typeid, ntypes):
    """The stiffness from the reference pair (mean diameter and mass) at the initial temperature:
    (Y of the reference pair, Y per pair of types, elastic Hertz contact time at the thermal
    impact speed, Enskog mean free time, their ratio, the thermal impact speed). Y is
    ``young_modulus`` when given (a number, or a table per pair of types whose mean pair sets
    the contact time), else the one whose contact time is ``contact_fraction`` of the mean
    free time."""
    n, d = velocities.shape
    sigma = float(np.mean(2.0 * radii))
    mass = float(np.mean(masses))
    volume = float(np.prod(box))
    packing = float(np.sum(theory.particle_volume(2.0 * radii, d))) / volume
    peculiar = velocities - np.sum(masses[:, None] * velocities, axis=0) / np.sum(masses)
    temperature = float(np.sum(masses[:, None] * peculiar**2)) / (d * n)
    if not temperature > 0.0:
        raise UserError("initial temperature is 0: the stiffness is set from the thermal impact speed")
    tau_free = enskog_mean_free_time(d, packing, sigma, mass, temperature)
    r_eff, m_eff = sigma / 4.0, mass / 2.0
    g_thermal = math.sqrt(2.0 * temperature / m_eff)
    if young_modulus is None:
        t_contact = contact_fraction * tau_free
        young = stiffness_for_contact_time(t_contact, g_thermal, r_eff, m_eff, poisson_ratio)
        y_pairs = np.full((ntypes, ntypes), young)
    else:
        y_pairs = np.broadcast_to(np.asarray(young_modulus, dtype=float), (ntypes, ntypes))
        if not np.all(y_pairs > 0.0):
            raise UserError(f"Young modulus = {young_modulus}: must be > 0")
        # the mean pair's stiffness for the reference contact time
        x = np.bincount(typeid, minlength=ntypes) / n
        young = float(x @ y_pairs @ x)
        t_contact = DemContact(young, poisson_ratio, 0.0).hertz_contact_time(g_thermal, r_eff, m_eff)
        contact_fraction = t_contact / tau_free
    return young, y_pairs, t_contact, tau_free, contact_fraction, g_thermal


def _time_steps(end_time, steps_per_contact, t_contact, thermo_interval, source):
    """(steps, timestep, steps between thermo lines): timestep <= t_contact / steps_per_contact and a
    whole number of steps to ``end_time``."""
    steps = end_time * steps_per_contact / t_contact
    if not (1.0 - 1e-9 <= steps <= 2**53):  # at least one whole time step, an exact step count
        raise UserError(f"{source + ': ' if source else ''}run.end_time (or --end-time) = {end_time:g}: "
                        f"{steps:.3g} time steps of {t_contact / steps_per_contact:.3g} "
                        "(contact time / steps per contact); a LAMMPS run takes 1 to 2^53 of them")
    steps = int(math.ceil(steps - 1e-9))
    dt = end_time / steps
    thermo_interval = end_time / 200.0 if thermo_interval is None else thermo_interval
    return steps, dt, max(1, int(round(thermo_interval / dt)))


def _input_commands(pair_contact, data_name, type_masses, eta, radii, box, boundary, dt, steps, thermo_every,
                    pressure, contact_pairs, name):
    """The LAMMPS commands of the input script (after its comment header): the box and its
    boundaries, the atoms' masses, the contact law per pair of types and at the walls (each
    type's wall of its own material), the integration, the thermo output (with the pressure
    and the contact dump when asked for) and the run."""
    d = len(box)
    boundary = ("periodic",) * d if boundary is None else tuple(boundary)
    walls = [a for a in range(d) if boundary[a] == "wall"]
    lammps_boundary = " ".join("f" if a in walls else "p" for a in range(d)) + (" p" if d == 2 else "")
    lines = [
        "units lj",
        f"dimension {d}",
        f"boundary {lammps_boundary}",
        "atom_style sphere",
        "comm_modify vel yes",
        f"read_data {data_name}",
    ]
    for k, m in enumerate(type_masses):
        lines.append(f"set type {k + 1} mass {m:.17g}")
    lines.append("pair_style granular")
    for (i, j), _ in eta.items():
        mi, mj = type_masses[i - 1], type_masses[j - 1]
        lines.append(pair_contact[(i - 1, j - 1)].pair_coeff(i, j, mi * mj / (mi + mj)))
    for k, m in enumerate(type_masses):
        if walls:
            lines.append(f"group type{k + 1} type {k + 1}")
        for a in walls:  # a wall of the type's own material
            lines.append(pair_contact[(k, k)].wall_fix(f"wall{k + 1}{'xyz'[a]}", f"type{k + 1}", float(m), a,
                                                       float(box[a])))
    skin = 0.3 * float(np.max(2.0 * radii))
    lines += [
        f"neighbor {skin:.6g} bin",
        "neigh_modify delay 0 every 1 check yes",
        f"timestep {dt:.17g}",
        "fix integrate all nve/sphere",
    ]
    if d == 2:
        lines.append("fix plane all enforce2d")
    lines += [
        "compute granT all temp/com",
        "compute_modify granT extra/dof 0",
    ]
    columns = "step time c_granT"
    if pressure:
        lines += ["compute granPress all pressure granT",
                  f"fix granP all ave/time 1 {thermo_every} {thermo_every} c_granPress"]
        columns += " f_granP"
    if contact_pairs:
        lines += ["compute granPairs all property/local patom1 patom2 cutoff radius",
                  "compute granDist all pair/local dist cutoff radius",
                  f"dump granPairs all local 1 contacts.{name} c_granPairs[1] c_granPairs[2] c_granDist",
                  f"dump_modify granPairs format float %.17g"]
    lines += [
        f"thermo_style custom {columns} cpu",
        "thermo_modify norm no flush yes format float %.12g",
        f"thermo {thermo_every}",
        f"run {steps}",
        "",
    ]
    return lines


def _write_data_file(path, positions, velocities, radii, masses, types, ntypes, box, source):
    n, d = positions.shape
    diam = 2.0 * radii
    # density such that LAMMPS's 3D rule rho pi d^3 / 6 gives the mass; the
    # input also sets the mass per type, which holds in 2D too
    density = masses / theory.particle_volume(diam, 3)
    pos3 = np.zeros((n, 3))
    vel3 = np.zeros((n, 3))
    pos3[:, :d] = positions
    vel3[:, :d] = velocities
    head = [
        f"LAMMPS data file written by granulargas{' from ' + source if source else ''}",
        "",
        f"{n} atoms",
        f"{ntypes} atom types",
        "",
        f"0 {box[0]:.17g} xlo xhi",
        f"0 {box[1]:.17g} ylo yhi",
        f"0 {box[2]:.17g} zlo zhi" if d == 3 else "-0.5 0.5 zlo zhi",
        "",
        "Atoms # sphere",
        "",
    ]
    with open(path, "w") as fh:
        fh.write("\n".join(head) + "\n")
        ids = np.arange(1, n + 1)
        atoms = np.column_stack([ids, types, diam, density, pos3])
        np.savetxt(fh, atoms, fmt=["%d", "%d", "%.17g", "%.17g", "%.17g", "%.17g", "%.17g"])
        fh.write("\nVelocities\n\n")
        np.savetxt(fh, np.column_stack([ids, vel3, np.zeros((n, 3))]), fmt=["%d"] + ["%.17g"] * 6)
