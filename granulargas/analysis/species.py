"""The species of a mixture run: their temperatures against kinetic theory.

A mixture's file (``[[species]]``) holds ``observables/species_temperature`` (T_s of each
species at every sample), ``species_collisions`` and ``parameters/species``. The theory
(:class:`granulargas.theory.mixture.Mixture`, built from the file's species, pair laws and
packing fraction) is the Maxwellian balance of each species, dT_i/dt = -zeta_i T_i (Garzó &
Dufty 1999; Enskog chi_ij of the run's packing fraction; the DSMC's own chi_ij), integrated
from the temperatures measured at the first sample, so the ratios' transient is part of the
prediction; a driven run is compared with its steady state (granulargas's driving: every
species heated at the same dT_i/dt), an elastic one with equipartition. Ratios are
T_i / T_j with j the last species; the plateau is the block mean
(:func:`granulargas.analysis.cooling.block_mean`) over the second half of the samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from granulargas import theory
from granulargas.analysis.cooling import block_mean
from granulargas.io.h5md import read_observables, read_parameters
from granulargas.run.prepare import contact_values_at
from granulargas.theory.mixture import Mixture

__all__ = ["SpeciesAnalysis", "analyze_species", "plot_species"]


@dataclass
class SpeciesAnalysis:
    """Measured and predicted temperatures of each species of one run.

    Attributes
    ----------
    names : tuple of str
    time, collisions_per_particle : arrays (K,)
        The observables' samples (s = 2 C / N).
    temperatures : array (K, S)
        Measured T_s.
    theory_temperatures : array (K, S) or None
        Predicted T_s at the same times (None: no prediction for this kind of run).
    steady : array (S,) or None
        The ratios T_s / T the state tends to (HCS of constant eps, driven state, equipartition).
    theory_name : str
    collisions : array (S, S)
        Collisions per pair of species at the last sample.
    """

    names: tuple
    time: np.ndarray
    collisions_per_particle: np.ndarray
    temperatures: np.ndarray
    theory_temperatures: np.ndarray | None
    steady: np.ndarray | None
    theory_name: str
    collisions: np.ndarray
    counts: tuple = ()

    @property
    def ratios(self) -> np.ndarray:
        """Measured T_i / T_j (K, S - 1), j the last species."""
        return self.temperatures[:, :-1] / self.temperatures[:, -1:]

    @property
    def theory_ratios(self) -> np.ndarray | None:
        if self.theory_temperatures is None:
            return None
        return self.theory_temperatures[:, :-1] / self.theory_temperatures[:, -1:]

    def late(self) -> list[tuple[float, float]]:
        """(mean, standard error) of each measured ratio over the second half of the samples."""
        half = len(self.time) // 2
        return [block_mean(self.ratios[half:, i]) for i in range(self.ratios.shape[1])]

    def late_theory(self) -> list[float]:
        """The predicted ratios averaged over the same samples as :meth:`late`."""
        if self.theory_ratios is None:
            return [math.nan] * self.ratios.shape[1]
        half = len(self.time) // 2
        return [float(np.mean(self.theory_ratios[half:, i])) for i in range(self.ratios.shape[1])]

    @property
    def fractions(self) -> np.ndarray:
        c = np.asarray(self.counts, dtype=float)
        return c / c.sum()

    def mixture_ratio(self) -> float:
        """T / T_theory of the mixture temperature T = sum x_i T_i at the last sample (nan without
        a prediction)."""
        if self.theory_temperatures is None:
            return math.nan
        x = self.fractions
        return float(self.temperatures[-1] @ x / (self.theory_temperatures[-1] @ x))

    def lines(self) -> list[str]:
        last = self.names[-1]
        out = [f"species      {', '.join(self.names)}; theory: {self.theory_name}"]
        if self.theory_temperatures is not None:
            out.append(f"  T = sum x_i T_i: T/T_theory = {self.mixture_ratio():.4f} at the last sample (the mixture's "
                       "own Maxwellian theory; the Sonine corrections it leaves out shift it by a few per cent)")
        for i, ((m, e), th) in enumerate(zip(self.late(), self.late_theory())):
            steady = "" if self.steady is None else f", steady state {self.steady[i] / self.steady[-1]:.4f}"
            dev = "" if not math.isfinite(th) else f" ({100 * (m / th - 1):+.2f} %)"
            out.append(f"  T_{self.names[i]}/T_{last}  {m:.4f} +- {e:.2g} over the second half, theory {th:.4f}"
                       f"{dev}{steady}")
        pairs = ", ".join(f"{self.names[a]}-{self.names[b]} {int(self.collisions[a, b])}"
                          for a in range(len(self.names)) for b in range(a, len(self.names)))
        out.append(f"  collisions per pair of species: {pairs}")
        return out

    def summary(self) -> dict:
        return {"names": list(self.names), "theory": self.theory_name,
                "ratios_late": [{"pair": f"{self.names[i]}/{self.names[-1]}", "value": m, "error": e, "theory": th}
                                for i, ((m, e), th) in enumerate(zip(self.late(), self.late_theory()))],
                "steady": None if self.steady is None else [float(x) for x in self.steady],
                "collisions": self.collisions.tolist(), "T_over_theory_final": self.mixture_ratio()}


def _mixture(parameters: dict, box, dimension: int) -> Mixture | None:
    sp = parameters["species"]
    coll = parameters.get("collision", {}) or {}
    counts = np.asarray(sp["counts"], dtype=float)
    diam = np.asarray(sp["diameters"], dtype=float)
    volume = float(np.prod(box))
    density = float(counts.sum() / volume)
    packing = float(np.sum(counts * theory.particle_volume(diam, dimension)) / volume)
    dsmc = parameters.get("dsmc") or {}
    if "chi_pairs" in dsmc:
        chi = np.asarray(dsmc["chi_pairs"], dtype=float)
    else:
        chi = contact_values_at(diam, counts / volume, packing, dimension)
    model = str(coll.get("model"))
    as_tuple = lambda a: None if a is None else tuple(tuple(float(v) for v in row) for row in np.asarray(a))  # noqa: E731
    eps = coll.get("restitution_pairs") if model == "constant" else None
    k = coll.get("prefactor_pairs") if model == "viscoelastic" else None
    if model not in ("constant", "viscoelastic", "elastic"):
        return None
    return Mixture(tuple(sp["names"]), tuple(np.asarray(sp["masses"], dtype=float)), tuple(diam), tuple(counts),
                   dimension, density, as_tuple(eps), as_tuple(k), str(coll.get("contact_end", "overlap")),
                   as_tuple(chi))


def analyze_species(path, box, dimension: int) -> SpeciesAnalysis | None:
    """The species analysis of a run's file (None: not a mixture)."""
    obs = read_observables(path)
    if "species_temperature" not in obs:
        return None
    params = read_parameters(path)
    if "species" not in params:
        return None
    step, t, temps = obs["species_temperature"]
    n = float(np.sum(params["species"]["counts"]))
    coll = obs["collisions"][2][: len(t)]
    s = 2.0 * coll / n
    mix = _mixture(params, box, dimension)
    names = tuple(params["species"]["names"])
    pairs = np.asarray(obs["species_collisions"][2][-1]) if "species_collisions" in obs else np.zeros((len(names),) * 2)
    predicted = steady = None
    name = "none for this run"
    driven = "driving" in params
    if mix is not None:
        if mix.restitution is None and mix.prefactor is None:
            steady = np.ones(len(names))
            predicted = np.outer(np.sum(temps * mix.fractions, axis=1), steady)
            name = "equipartition (elastic collisions)"
        elif driven:
            tmix = float(np.mean(np.sum(temps[len(t) // 2:] * mix.fractions, axis=1)))
            steady = mix.driven_ratios("equal_heating", tmix)
            predicted = np.outer(np.sum(temps * mix.fractions, axis=1), steady)
            name = ("white-noise driven steady state, every species heated at the same dT_i/dt (Garzó & Dufty 1999 "
                    "Maxwellian, Enskog chi_ij)")
        else:
            predicted = mix.temperature_history(t - t[0], temps[0])
            steady = mix.hcs_ratios() if mix.restitution is not None else None
            name = ("Maxwellian balance dT_i/dt = -zeta_i T_i from the first sample (Garzó & Dufty 1999, Enskog "
                    "chi_ij" + ("; eps_ij(g) of the viscoelastic pairs)" if mix.prefactor is not None else ")"))
    return SpeciesAnalysis(names, np.asarray(t), s, np.asarray(temps), predicted, steady, name, pairs,
                           tuple(int(c) for c in params["species"]["counts"]))


def plot_species(sa: SpeciesAnalysis, path) -> str:
    """T_i / T_j of the run against the collisions per particle, with the theory (lines) and the
    state it tends to (dotted)."""
    from granulargas.analysis.plots import _plt

    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    s = sa.collisions_per_particle
    keep = s > 0
    last = sa.names[-1]
    for i in range(len(sa.names) - 1):
        ax.plot(s[keep], sa.ratios[keep, i], "o", ms=3, color=f"C{i}", label=f"$T_{{{sa.names[i]}}}/T_{{{last}}}$ run")
        if sa.theory_ratios is not None:
            ax.plot(s[keep], sa.theory_ratios[keep, i], "-", color=f"C{i}", label="theory")
        if sa.steady is not None:
            ax.axhline(sa.steady[i] / sa.steady[-1], ls=":", color=f"C{i}", label="steady state")
    ax.set_xscale("log")
    ax.set_xlabel("collisions per particle")
    ax.set_ylabel("temperature ratio")
    ax.set_title("species temperatures", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return str(path)
