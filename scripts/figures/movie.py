"""Animation of a run (2D, or a slab of a 3D run): MP4 where ffmpeg exists, GIF otherwise.

Each frame is rendered as an image, not as markers: particles are binned onto a
pixel grid (``--pixels`` per side), smoothed with a periodic Gaussian wide enough
to hold about 8 particles when the pixels are sparser than that, and the pixel
shows the local packing fraction (``--color density``) or the mean speed over
sqrt(T) (``--color speed``). That keeps 10^5-10^6 particles fast and the file
small. Snapshots are read one at a time.

    python scripts/figures/movie.py runs/clustering_2d_constant.h5 --out docs/figures/clustering_constant.gif
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from granulargas.analysis.cooling import temperature
from granulargas.analysis.structure import wrap
from granulargas.io.h5md import iter_snapshots, load_snapshot, snapshot_count


def _smooth(img, per_pixel):
    from scipy.ndimage import gaussian_filter

    sigma = math.sqrt(8.0 / (math.pi * max(per_pixel, 1e-12)))
    return gaussian_filter(img, sigma, mode="wrap") if sigma > 0.5 else img


def frame_image(snap, pixels: int, color: str, slab: float = 2.0):
    pos = wrap(snap.positions, snap.box)
    vel = snap.velocities
    box = snap.box
    if pos.shape[1] == 3:
        keep = np.abs(pos[:, 2] - 0.5 * box[2]) < slab
        pos, vel = pos[keep], vel[keep]
    rng = [(0.0, box[0]), (0.0, box[1])]
    counts, _, _ = np.histogram2d(pos[:, 0], pos[:, 1], bins=pixels, range=rng)
    per_pixel = pos.shape[0] / pixels**2
    counts = _smooth(counts, per_pixel)
    if color == "density":
        r = np.asarray(snap.radii)
        area = math.pi * float(np.mean(r)) ** 2
        cell = box[0] * box[1] / pixels**2
        return counts.T * area / cell
    T = temperature(snap.velocities, snap.masses)
    speed = np.linalg.norm(vel - snap.velocities.mean(axis=0), axis=1) / math.sqrt(T)
    s, _, _ = np.histogram2d(pos[:, 0], pos[:, 1], bins=pixels, range=rng, weights=speed)
    s = _smooth(s, per_pixel)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (s / counts).T


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--out", help="output file (.mp4 or .gif; default: next to the run, MP4 if ffmpeg exists)")
    ap.add_argument("--color", choices=("density", "speed"), default="density")
    ap.add_argument("--pixels", type=int, default=400, help="pixels per side of the particle image")
    ap.add_argument("--fps", type=int, default=6)
    ap.add_argument("--every", type=int, default=1, help="use every n-th snapshot")
    ap.add_argument("--vmax", type=float, default=None, help="colour scale maximum")
    ap.add_argument("--dpi", type=int, default=80, help="figure resolution (the frame is 6 x 6.3 inches)")
    args = ap.parse_args(argv)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import animation

    have_ffmpeg = animation.writers.is_available("ffmpeg")
    out = Path(args.out) if args.out else Path(args.file).with_suffix(".mp4" if have_ffmpeg else ".gif")
    if out.suffix == ".mp4" and not have_ffmpeg:
        out = out.with_suffix(".gif")
        print(f"ffmpeg not found: writing a GIF instead ({out})")
    writer = animation.FFMpegWriter(fps=args.fps) if out.suffix == ".mp4" else animation.PillowWriter(fps=args.fps)

    first = load_snapshot(args.file, 0)
    box = first.box
    eta = float(np.sum(math.pi * first.radii**2) / np.prod(box[:2])) if box.size == 2 else None
    vmax = args.vmax or (min(0.9, 5 * eta) if (args.color == "density" and eta) else (0.9 if args.color == "density" else 2.0))
    fig, ax = plt.subplots(figsize=(6, 6.3))
    img = ax.imshow(frame_image(first, args.pixels, args.color), origin="lower", extent=(0, box[0], 0, box[1]),
                    cmap="magma" if args.color == "density" else "viridis", vmin=0, vmax=vmax, interpolation="nearest")
    fig.colorbar(img, ax=ax, fraction=0.046, label="local packing fraction" if args.color == "density" else "speed / $\\sqrt{T}$")
    ax.set(xticks=[], yticks=[])
    title = ax.set_title("", fontsize=9)
    fig.tight_layout()
    n = snapshot_count(args.file)
    out.parent.mkdir(parents=True, exist_ok=True)
    with writer.saving(fig, str(out), dpi=args.dpi):
        for snap in iter_snapshots(args.file):
            if snap.index % args.every:
                continue
            img.set_data(frame_image(snap, args.pixels, args.color))
            T = temperature(snap.velocities, snap.masses)
            title.set_text(f"{Path(args.file).name}\nt = {snap.time:.4g}, T = {T:.3g} (frame {snap.index + 1}/{n})")
            writer.grab_frame()
    plt.close(fig)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
