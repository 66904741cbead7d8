#!/usr/bin/python3
"""Picture of examples/shear_flow_2d.toml: a 2D granular gas in steady simple shear.

Top left: local packing fraction of the last trajectory frame (disks counted in square cells of
`--cell` diameters). Top right: the disks in a corner square of that frame, coloured by their
x velocity relative to the imposed flow, v_x - rate (y - L_y/2). Bottom left: the mean
velocity profile u_x(y) from profile.tsv against the imposed linear profile
rate (y - L_y/2), and the deviation from it. Bottom right: the granular temperature (relative
to the flow) against the strain rate * t, with the shear stress and viscosity of summary.json.

    /usr/bin/python3 examples/plot/plot_shear_flow_2d.py OUTDIR -o shear_flow_2d.png
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
    ap.add_argument("-o", "--png", default="shear_flow_2d.png", help="PNG to write")
    ap.add_argument("--frame", type=int, default=-1, help="trajectory frame (default: last)")
    ap.add_argument("--cell", type=float, default=4.0, help="cell edge of the density map")
    ap.add_argument("--zoom", type=float, default=60.0, help="edge of the zoomed square")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    summary = ko.read_summary(args.outdir)
    rate = config["boundary"]["shear_rate"]
    e = config["contact"]["restitution"]
    snap = ko.Frame(args.outdir, args.frame)
    traj, frame = snap.traj, snap.index
    pos, vel, diameter, box = snap.pos, snap.vel, snap.diameter, snap.box
    lx, ly = box[0], box[1]
    time = traj.time(frame)
    n = len(pos)
    # GSD positions are centred, y_gsd = y - L_y/2: the imposed flow there is rate * y_gsd.
    peculiar = vel[:, 0] - rate * pos[:, 1]

    fig, axes = plt.subplots(2, 2, figsize=(11, 9.6))

    ax = axes[0, 0]
    nx, ny = max(1, int(lx / args.cell)), max(1, int(ly / args.cell))
    h, _, _ = np.histogram2d(pos[:, 0], pos[:, 1], bins=[nx, ny],
                             range=[[-lx / 2, lx / 2], [-ly / 2, ly / 2]],
                             weights=np.pi * diameter ** 2 / 4)
    h /= (lx / nx) * (ly / ny)
    im = ax.imshow(h.T, origin="lower", extent=[-lx / 2, lx / 2, -ly / 2, ly / 2],
                   cmap="magma", vmin=0, vmax=min(0.9, max(0.5, np.percentile(h, 99.9))),
                   interpolation="nearest")
    fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02, label="local packing fraction")
    z = min(args.zoom, lx, ly)
    ax.add_patch(plt.Rectangle((-lx / 2, -ly / 2), z, z, fill=False, ec="cyan", lw=1.2))
    ax.annotate("", xy=(0.95, 0.93), xytext=(0.75, 0.93), xycoords="axes fraction",
                arrowprops=dict(arrowstyle="->", color="w"))
    ax.annotate("", xy=(0.05, 0.07), xytext=(0.25, 0.07), xycoords="axes fraction",
                arrowprops=dict(arrowstyle="->", color="w"))
    ax.set_title("N = %d, e = %g, shear rate %g: t = %.0f (strain %.0f)"
                 % (n, e, rate, time, rate * time), fontsize=10)
    ax.set_xlabel("x (flow)")
    ax.set_ylabel("y (gradient)")

    ax = axes[0, 1]
    inside = (pos[:, 0] < -lx / 2 + z) & (pos[:, 1] < -ly / 2 + z)
    c = peculiar[inside]
    scale = np.percentile(np.abs(peculiar), 98)
    col = EllipseCollection(diameter[inside], diameter[inside], 0.0, units="xy",
                            offsets=pos[inside, :2], transOffset=ax.transData, cmap="coolwarm",
                            edgecolors="none")
    col.set_array(c)
    col.set_clim(-scale, scale)
    ax.add_collection(col)
    fig.colorbar(col, ax=ax, fraction=0.046, pad=0.02,
                 label="$v_x - \\dot\\gamma\\,(y - L_y/2)$")
    ax.set_xlim(-lx / 2, -lx / 2 + z)
    ax.set_ylim(-ly / 2, -ly / 2 + z)
    ax.set_aspect("equal")
    ax.set_title("the disks in the cyan square, x velocity relative to the flow", fontsize=10)
    ax.set_xlabel("x")

    ax = axes[1, 0]
    profile = ko.read_tsv(os.path.join(args.outdir, "profile.tsv"))
    y, ux = profile["position"], profile["velocity_x"]
    yy = np.array([0.0, ly])
    ax.plot(yy, rate * (yy - ly / 2), "-", color="C3", lw=1.2,
            label="imposed: $\\dot\\gamma\\,(y - L_y/2)$")
    ax.plot(y, ux, "o", ms=4, color="C0", label="Kairos: $u_x(y)$ (profile.tsv)")
    ax.set_xlim(0, ly)
    ax.set_xlabel("y")
    ax.set_ylabel("mean velocity $u_x$")
    ax.grid(alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot(y, ux - rate * (y - ly / 2), "s-", ms=3, lw=0.8, color="C2",
             label="$u_x - \\dot\\gamma\\,(y - L_y/2)$ (right axis)")
    dev = np.nanmax(np.abs(ux - rate * (y - ly / 2)))
    lim = max(3 * dev, 1e-3 * rate * ly)
    ax2.set_ylim(-lim, lim)
    ax2.set_ylabel("deviation from the imposed flow", color="C2")
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], fontsize=8, loc="upper left")
    ax.set_title("mean velocity profile over production (%d slabs)" % len(y), fontsize=10)

    ax = axes[1, 1]
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    t, temp = thermo["time"], thermo["temperature"]
    production = thermo["phase"] == "production"
    ax.plot(rate * t[~production], temp[~production], ".", ms=3, color="0.6",
            label="equilibration")
    ax.plot(rate * t[production], temp[production], ".", ms=3, color="C0",
            label="production")
    shear = summary["shear"]
    ax.set_xlabel("strain $\\dot\\gamma\\, t$")
    ax.set_ylabel("granular temperature T (relative to the flow)")
    ax.set_ylim(0, None)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title("$P_{xy}$ = %.4g $\\pm$ %.1g, viscosity %.4g $\\pm$ %.1g"
                 % (shear["shear_stress"], shear["shear_stress_stderr"], shear["viscosity"],
                    shear["viscosity_stderr"]), fontsize=10)

    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
