"""Structure of a cooling granular gas over time: clusters, S(k), shear modes.

For a run's H5MD file (2D or 3D; 3D shows a slab and projections) writes

* ``<prefix>_t<k>.png`` for chosen times: particles coloured by speed, the
  coarse-grained packing fraction, the vorticity of the flow smoothed over a
  Gaussian that holds ~200 particles (finer cells show thermal noise only),
  S(k) (small k included, ideal gas = 1) and the flow's energy spectrum E(k);
* ``<prefix>_series.png``: time series of the peak of S(k) and S at the smallest
  wavenumber, the largest-cluster fraction, T(t) with Haff's (or the viscoelastic)
  law for reference, the kinetic energy of the coarse-grained flow, and L / L_c.

Snapshots are read one at a time (fine for 10^6 particles). The series is also
printed as a table.

    python scripts/figures/clustering_analysis.py runs/clustering_2d_constant.h5 --prefix docs/figures/clustering_constant
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from granulargas import theory as th
from granulargas.analysis import clusters, flow, structure
from granulargas.analysis.cooling import temperature
from granulargas.analysis.run import RunInfo, cooling_history, snapshot_series
from granulargas.io.h5md import load_snapshot, snapshot_count


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def current_instability_length(info: RunInfo, T: float) -> float:
    """L_c at temperature T: constant restitution -> independent of T; viscoelastic
    -> with the effective restitution at T, which grows towards 1 as the gas cools."""
    return info.gas(T).instability_length()


def smoothing_length(info: RunInfo, particles: float = 200.0) -> float:
    """Width of the Gaussian that holds ``particles`` particles at the mean number density."""
    n = info.particles / float(np.prod(info.box))
    if info.dimension == 2:
        return math.sqrt(particles / (2.0 * math.pi * n))
    return (particles / ((2.0 * math.pi) ** 1.5 * n)) ** (1.0 / 3.0)


def vorticity_noise(info: RunInfo, ell: float) -> float:
    """RMS vorticity (in sqrt(T)/sigma) that thermal noise alone gives after the smoothing.

    For uncorrelated particles with velocity variance T/m per component at number
    density n, the Gaussian-smoothed velocity has the noise spectrum
    (T/m)/n |K(k)|^2, K = exp(-k^2 ell^2 / 2); integrating k^2 |K|^2 over the
    wavevectors gives <w^2> = (T/m) / (4 pi n ell^4) in 2D and
    (T/m) / (8 pi^(3/2) n ell^5) in 3D (before the z average)."""
    n = info.particles / float(np.prod(info.box))
    if info.dimension == 2:
        return 1.0 / math.sqrt(4.0 * math.pi * n * ell**4 * info.mass)
    return 1.0 / math.sqrt(8.0 * math.pi**1.5 * n * ell**5 * info.mass)


def smoothed_vorticity(pos, vel, masses, box, info: RunInfo):
    """Vorticity of the mass-weighted velocity field smoothed by a Gaussian.

    Mass and momentum are binned on a grid of about ell/2 per cell and both
    smoothed with the same Gaussian of width ell (:func:`smoothing_length`); the
    velocity is u = p / rho. Its curl is taken from the spectral derivatives of the
    smooth fields, curl u = (rho curl p - grad rho x p) / rho^2, so that no
    discontinuity enters a Fourier transform. Cells whose smoothed density is below
    5 % of the mean are masked (NaN). Returns (ell, vorticity: the scalar in 2D,
    the z component in 3D)."""
    ell = smoothing_length(info)
    d = info.dimension
    bins = int(min(256 if d == 2 else 64, max(16, round(float(box.min()) / (0.5 * ell)))))
    u, mass = flow.velocity_field(pos, vel, box, bins, masses, remove_mean=True)
    ks = np.meshgrid(*[2.0 * np.pi * np.fft.fftfreq(bins, d=L / bins) for L in box], indexing="ij")
    kernel = np.exp(-0.5 * sum(k * k for k in ks) * ell * ell)

    def smooth(f, axis=None):  # Gaussian-smoothed f, or its derivative along axis
        fk = np.fft.fftn(f) * kernel
        if axis is not None:
            fk = fk * 1j * ks[axis]
        return np.real(np.fft.ifftn(fk))

    mom = [u[..., a] * mass for a in range(d)]
    rho = smooth(mass)
    px, py = smooth(mom[0]), smooth(mom[1])
    # z component of curl(p / rho) (the only one in 2D)
    w = (rho * (smooth(mom[1], 0) - smooth(mom[0], 1)) - (smooth(mass, 0) * py - smooth(mass, 1) * px))
    low = rho < 0.05 * mass.mean()
    w = np.where(low, np.nan, w / np.where(low, 1.0, rho) ** 2)
    return ell, w


def grid_cells(info: RunInfo, cell: float) -> int:
    return max(4, int(round(info.box.min() / cell)))


def frame_measures(snap, info: RunInfo, cells: int, k_max: float, factor: float):
    """The numbers of one snapshot for the time series."""
    pos, vel, box = snap.positions, snap.velocities, snap.box
    T = temperature(vel, snap.masses)
    k, S, _ = structure.structure_factor(pos, box, k_max=k_max)
    labels = clusters.cluster_labels(pos, box, snap.radii, factor=factor)
    sizes = np.bincount(labels)
    u, _ = flow.velocity_field(pos, vel, box, cells, snap.masses)
    flow_ke = 0.5 * float(np.mean(np.sum(u * u, axis=-1)))
    return {
        "time": snap.time, "T": T, "S_max": float(S.max()), "k_at_max": float(k[np.argmax(S)]),
        "S_kmin": float(S[0]), "largest": float(sizes.max()) / labels.size, "clusters": int(sizes.size),
        "mean_cluster": float(np.mean(sizes)), "flow_ke_over_T": flow_ke / T if T > 0 else math.nan,
        "L_over_Lc": float(box.max()) / current_instability_length(info, T),
    }


def _slab(snap, info):
    """Indices of particles to draw: all in 2D, a slab of thickness 4 sigma in 3D."""
    if info.dimension == 2:
        return np.arange(snap.positions.shape[0])
    z = snap.positions[:, 2]
    return np.nonzero(np.abs(z - 0.5 * snap.box[2]) < 2.0 * info.diameter)[0]


def figure_snapshot(snap, info, cells, k_max, path, theory_law):
    plt = _plt()
    pos, vel, box = snap.positions, snap.velocities, snap.box
    T = temperature(vel, snap.masses)
    fig, ax = plt.subplots(1, 5, figsize=(21, 4.6), gridspec_kw={"width_ratios": [1, 1, 1, 1.05, 1.05]})
    sel = _slab(snap, info)
    speed = np.linalg.norm(vel[sel] - vel.mean(axis=0), axis=1) / math.sqrt(T)
    n = sel.size
    ms = max(0.01, min(4.0, 2e4 / max(n, 1)))  # marker area (points^2): ~1 pixel per particle at 10^5
    sc = ax[0].scatter(pos[sel, 0], pos[sel, 1], c=speed, s=ms, cmap="viridis", vmin=0, vmax=3, lw=0, rasterized=True)
    fig.colorbar(sc, ax=ax[0], fraction=0.046, label="speed / $\\sqrt{T}$")
    ax[0].set_title("particles" + (" (slab |z - L/2| < 2)" if info.dimension == 3 else ""), fontsize=9)
    rho = structure.density_field(pos, box, cells, snap.radii)
    if info.dimension == 3:
        rho = rho.mean(axis=2)
    im = ax[1].imshow(rho.T, origin="lower", extent=(0, box[0], 0, box[1]), cmap="magma", vmin=0,
                      vmax=max(3 * info.packing_fraction, float(np.percentile(rho, 99.5))))
    fig.colorbar(im, ax=ax[1], fraction=0.046, label="local packing fraction")
    ax[1].set_title(f"density ({cells} cells per side{', z-averaged' if info.dimension == 3 else ''})", fontsize=9)
    # vorticity of the flow smoothed over a Gaussian of width ell that holds ~200
    # particles at the mean density: cell averages over a few dozen particles are
    # dominated by thermal noise, which the derivative amplifies
    ell, w = smoothed_vorticity(pos, vel, snap.masses, box, info)
    w = w / math.sqrt(T)  # in units of sqrt(T)/sigma
    if info.dimension == 3:
        w = np.nanmean(w, axis=2)  # omega_z averaged over z
    wmax = float(np.nanpercentile(np.abs(w), 99)) or 1.0
    cmap = plt.get_cmap("RdBu_r").with_extremes(bad="0.85")
    im = ax[2].imshow(w.T, origin="lower", extent=(0, box[0], 0, box[1]), cmap=cmap, vmin=-wmax, vmax=wmax)
    fig.colorbar(im, ax=ax[2], fraction=0.046,
                 label="vorticity" + (" $\\omega_z$" if info.dimension == 3 else "") + " [$\\sqrt{T}/\\sigma$]")
    ax[2].set_title(f"vorticity of the flow smoothed over {ell:.3g} $\\sigma$ (thermal noise alone:\n"
                    f"rms {vorticity_noise(info, ell):.2g}; grey: below 5 % of the mean density)", fontsize=9)
    for a in ax[:3]:
        a.set_aspect("equal")
        a.set(xlim=(0, box[0]), ylim=(0, box[1]))
        a.tick_params(labelsize=7)
    k, S, _ = structure.structure_factor(pos, box, k_max=k_max)
    ax[3].loglog(k, S, "o-", ms=2.5)
    ax[3].axhline(1.0, color="k", lw=0.8, ls="--", label="ideal gas")
    lc = current_instability_length(info, T)
    if math.isfinite(lc):
        ax[3].axvline(2 * math.pi / lc, color="C3", lw=0.8, label="$2\\pi/L_c$ (shear)")
    ax[3].set(xlabel="$k\\sigma$", ylabel="$S(k)$")
    ax[3].legend(fontsize=8)
    ax[3].set_title("static structure factor", fontsize=9)
    vcells = min(cells, max(4, int((info.particles / 40.0) ** (1.0 / info.dimension))))
    u, _ = flow.velocity_field(pos, vel, box, vcells, snap.masses)
    ku, E = flow.energy_spectrum(u, box)
    ax[4].loglog(ku, E / T, "o-", ms=2.5)
    if math.isfinite(lc):
        ax[4].axvline(2 * math.pi / lc, color="C3", lw=0.8, label="$2\\pi/L_c$")
        ax[4].legend(fontsize=8)
    ax[4].set(xlabel="$k\\sigma$", ylabel="$E(k)/T$")
    from matplotlib.ticker import NullFormatter

    ax[3].xaxis.set_minor_formatter(NullFormatter())
    ax[4].xaxis.set_minor_formatter(NullFormatter())
    ax[4].set_title(f"flow energy spectrum ({vcells} cells per side)", fontsize=9)
    tl = f"t = {snap.time:.4g}"
    if theory_law is not None and math.isfinite(theory_law.tau0):
        tl += f" = {snap.time / theory_law.tau0:.3g} $\\tau_0$"
    fig.suptitle(f"{Path(info.path).name}: {info.model}, N = {info.particles}, packing {info.packing_fraction:.3g}, "
                 f"L = {box[0]:.4g} = {box[0] / lc:.3g} $L_c$, {tl}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    print(f"wrote {path}")


def figure_series(rows, info, hist, pred, path):
    plt = _plt()
    t = np.array([r["time"] for r in rows])
    m = t > 0
    fig, ax = plt.subplots(2, 3, figsize=(15, 7.5))
    ax = ax.ravel()
    ax[0].loglog(t[m], [r["S_max"] for r, ok in zip(rows, m) if ok], "o-", ms=3, label="max over k")
    ax[0].loglog(t[m], [r["S_kmin"] for r, ok in zip(rows, m) if ok], "s-", ms=3, label="$k = 2\\pi/L$ shell")
    ax[0].axhline(1, color="k", lw=0.8, ls="--")
    ax[0].set(xlabel="t", ylabel="S(k)", title="structure factor at small k")
    ax[0].legend(fontsize=8)
    ax[1].semilogx(t[m], [r["largest"] for r, ok in zip(rows, m) if ok], "o-", ms=3)
    ax[1].set(xlabel="t", ylabel="fraction of particles", title="largest cluster (bond < 1.1 contact)")
    th_ = hist.time - hist.time[0]
    mm = th_ > 0
    ax[2].loglog(th_[mm], hist.temperature[mm] / hist.temperature[0], label="simulation")
    if pred.law != "elastic":
        ax[2].loglog(th_[mm], pred.temperature(th_[mm]) / pred.T0, "k--", lw=1,
                     label=f"{'Haff' if pred.law == 'haff' else 'viscoelastic law'} (homogeneous)")
    ax[2].set(xlabel="t", ylabel="$T/T_0$", title="temperature")
    ax[2].legend(fontsize=8)
    if pred.law != "elastic":
        ax[3].semilogx(th_[mm], hist.temperature[mm] / pred.temperature(th_[mm]))
        ax[3].axhline(1, color="k", lw=0.8)
    ax[3].set(xlabel="t", ylabel="$T/T_{homogeneous}$", title="departure from the homogeneous law")
    ax[4].loglog(t[m], [r["flow_ke_over_T"] for r, ok in zip(rows, m) if ok], "o-", ms=3)
    ax[4].set(xlabel="t", ylabel="$\\langle u^2\\rangle/2T$", title="coarse-grained flow energy / T (shear modes)")
    ax[5].semilogx(t[m], [r["L_over_Lc"] for r, ok in zip(rows, m) if ok], "o-", ms=3)
    ax[5].axhline(1, color="k", lw=0.8, ls="--")
    ax[5].set(xlabel="t", ylabel="$L/L_c$", title="box length / instability length (theory)")
    fig.suptitle(f"{Path(info.path).name}: {info.model}, N = {info.particles}, packing {info.packing_fraction:.3g}",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    print(f"wrote {path}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--prefix", help="output path prefix (default: docs/figures/clustering_<file stem>)")
    ap.add_argument("--frames", type=int, nargs="*",
                    help="snapshot indices for the per-time figures (default: 4 spread over the run)")
    ap.add_argument("--every", type=int, default=1, help="use every n-th snapshot for the time series")
    ap.add_argument("--cell", type=float, default=None, help="coarse-graining cell size (default ~ 2 mean free paths, >= 4 sigma)")
    ap.add_argument("--kmax", type=float, default=None, help="largest k for S(k) (default 2 pi * 48 / L, at most 2 pi)")
    ap.add_argument("--factor", type=float, default=1.1, help="cluster bond: distance < factor * contact distance")
    ap.add_argument("--no-series", action="store_true", help="only the per-snapshot figures")
    args = ap.parse_args(argv)

    info = RunInfo.from_file(args.file)
    prefix = args.prefix or f"docs/figures/clustering_{Path(args.file).stem}"
    Path(prefix).parent.mkdir(parents=True, exist_ok=True)
    hist = cooling_history(args.file, info.particles)
    pred = info.prediction(float(hist.temperature[0]))
    cell = args.cell or max(4.0 * info.diameter, 2.0 * pred.mean_free_path)
    cells = grid_cells(info, cell)
    k_max = args.kmax or min(2 * math.pi, 2 * math.pi * 48 / info.box.min())
    nframes = snapshot_count(args.file)
    print(f"{args.file}: {info.dimension}D, N = {info.particles}, L = {info.box.max():.4g}, packing {info.packing_fraction:.3g}, "
          f"{info.model}; L_c(T0) = {pred.instability_length:.4g}; {nframes} snapshots; grid {cells}^{info.dimension}")

    rows = []
    if args.no_series:
        args.every = 10**9  # only frame 0 below; the series figure is skipped
    print(f"{'t':>10} {'t/tau0':>8} {'T':>10} {'S_max':>8} {'k(S_max)':>8} {'S(kmin)':>8} {'largest':>8} "
          f"{'clusters':>8} {'flowKE/T':>9} {'L/L_c':>7}")
    for _, r in snapshot_series(args.file, lambda s: frame_measures(s, info, cells, k_max, args.factor), args.every):
        rows.append(r)
        x = r["time"] / pred.tau0 if math.isfinite(pred.tau0) else math.nan
        print(f"{r['time']:10.4g} {x:8.3g} {r['T']:10.4g} {r['S_max']:8.3g} {r['k_at_max']:8.3g} {r['S_kmin']:8.3g} "
              f"{r['largest']:8.3f} {r['clusters']:8d} {r['flow_ke_over_T']:9.3g} {r['L_over_Lc']:7.3g}", flush=True)
    if not args.no_series:
        figure_series(rows, info, hist, pred, f"{prefix}_series.png")

    frames = args.frames
    if frames is None:
        frames = sorted({0, nframes // 3, (2 * nframes) // 3, nframes - 1})
    for k in frames:
        snap = load_snapshot(args.file, k)
        figure_snapshot(snap, info, cells, k_max, f"{prefix}_t{k:03d}.png", pred)
    return 0


if __name__ == "__main__":
    sys.exit(main())
