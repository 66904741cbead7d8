#!/usr/bin/python3
"""Picture of examples/granular_clustering_2d.toml: clusters in a cooling granular gas.

Left: local packing fraction of the last trajectory frame (the disks counted in square cells of
`--cell` diameters). Middle: the disks themselves in a corner of that frame. Right: the
temperature against time, and Haff's law T0 / (1 + t / t0)^2 for a gas that stays homogeneous,
with t0 = 2 D tau0 / (1 - e^2) from the mean free time tau0 of the first thermo row (no fit).

    /usr/bin/python3 examples/plot/plot_clustering_2d.py OUTDIR -o clustering.png
"""

import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import EllipseCollection
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kairos_output as ko


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="output directory of the run")
    ap.add_argument("-o", "--png", default="clustering_2d.png", help="PNG to write")
    ap.add_argument("--frame", type=int, default=-1, help="trajectory frame (default: last)")
    ap.add_argument("--cell", type=float, default=4.0, help="cell edge of the density map")
    ap.add_argument("--zoom", type=float, default=100.0, help="edge of the zoomed square")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    e = config["contact"]["restitution"]
    dim = config["system"]["dimension"]
    snap = ko.Frame(args.outdir, args.frame)
    traj, frame = snap.traj, snap.index
    pos, diameter, box = snap.pos, snap.diameter, snap.box
    lx, ly = float(box[0]), float(box[1])
    time = traj.time(frame)
    c = 2.0 * float(traj.chunk("log/collisions", frame)[0]) / len(pos)

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8), gridspec_kw={"width_ratios": [1, 1, 1.1]})

    # Local packing fraction in cells.
    ax = axes[0]
    nx, ny = max(1, int(lx / args.cell)), max(1, int(ly / args.cell))
    area = np.pi * diameter ** 2 / 4
    h, _, _ = np.histogram2d(pos[:, 0], pos[:, 1], bins=[nx, ny],
                             range=[[-lx / 2, lx / 2], [-ly / 2, ly / 2]], weights=area)
    h /= (lx / nx) * (ly / ny)
    im = ax.imshow(h.T, origin="lower", extent=[-lx / 2, lx / 2, -ly / 2, ly / 2],
                   cmap="magma", vmin=0, vmax=0.8, interpolation="nearest")
    fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02, label="local packing fraction")
    z = args.zoom
    ax.add_patch(plt.Rectangle((-lx / 2, -ly / 2), z, z, fill=False, ec="cyan", lw=1.2))
    ax.set_title("N = %d, e = %g: t = %.0f (%.0f collisions/particle)" % (len(pos), e, time, c),
                 fontsize=10)
    ax.set_xlabel("x")
    ax.set_ylabel("y")

    # The disks in the corner square.
    ax = axes[1]
    inside = (pos[:, 0] < -lx / 2 + z) & (pos[:, 1] < -ly / 2 + z)
    xy = pos[inside, :2].astype(float)
    d = diameter[inside].astype(float)
    ax.add_collection(EllipseCollection(d, d, 0.0, units="xy", offsets=xy,
                                        transOffset=ax.transData, facecolors="#333333",
                                        edgecolors="none"))
    ax.set_xlim(-lx / 2, -lx / 2 + z)
    ax.set_ylim(-ly / 2, -ly / 2 + z)
    ax.set_aspect("equal")
    ax.set_title("the disks in the cyan square (%d of them)" % len(d), fontsize=10)
    ax.set_xlabel("x")

    # Temperature against Haff's law.
    ax = axes[2]
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    t, temp = thermo["time"], thermo["temperature"]
    t0 = 2.0 * dim * thermo["mean_free_time"][0] / (1.0 - e * e)
    temp0 = config["system"]["temperature"]
    tt = np.logspace(np.log10(t[0]), np.log10(t[-1]), 200)
    ax.loglog(t, temp, "o", ms=3, color="C0", label="Kairos: T(t)")
    ax.loglog(tt, temp0 / (1 + tt / t0) ** 2, "-", color="C3",
              label="Haff: T0 / (1 + t/t0)$^2$, t0 = %.2f" % t0)
    ax.axvline(time, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("time t")
    ax.set_ylabel("granular temperature T")
    ax.set_title("cooling: homogeneous, then clustered", fontsize=10)
    ax.legend(fontsize=9)
    ax.grid(True, which="major", alpha=0.3)

    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
