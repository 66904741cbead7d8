#!/usr/bin/python3
"""Picture of examples/vibrated_bed_3d.toml: the granular Leidenfrost state.

Left: side view of the last trajectory frame, the spheres of a slab |y| < --slab / 2 through
the middle of the box, coloured by speed. Middle and right: packing fraction and granular
temperature against height, from profile.tsv (averaged over the production thermo rows). The
grey band is the range swept by the vibrating floor.

    /usr/bin/python3 examples/plot/plot_vibrated_bed_3d.py OUTDIR -o vibrated_bed_3d.png
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


def floor_wall(config):
    axis = "xyz"[config["system"]["dimension"] - 1]
    for wall in config["boundary"].get("wall", []):
        if wall["face"] == axis + "-":
            return wall
    raise SystemExit("no vibrating floor (wall on face %s-) in the configuration" % axis)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="output directory of the run")
    ap.add_argument("-o", "--png", default="vibrated_bed_3d.png", help="PNG to write")
    ap.add_argument("--frame", type=int, default=-1, help="trajectory frame (default: last)")
    ap.add_argument("--slab", type=float, default=2.0, help="thickness of the side-view slab")
    ap.add_argument("--top", type=float, default=0.0,
                    help="highest height shown (default: just above the particles)")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    floor = floor_wall(config)
    amplitude, frequency = floor["amplitude"], floor["frequency"]
    g = -config["field"]["gravity"][2]
    gamma = amplitude * (2 * np.pi * frequency) ** 2 / g
    snap = ko.Frame(args.outdir, args.frame)
    traj, frame = snap.traj, snap.index
    pos, vel, diameter, box = snap.pos, snap.vel, snap.diameter, snap.box
    lx, lz = box[0], box[2]
    z = pos[:, 2] + lz / 2  # GSD positions are centred; height above the floor's rest position
    profile = ko.read_tsv(os.path.join(args.outdir, "profile.tsv"))
    height = profile["position"]
    top = args.top or max(np.percentile(z, 99.5) + 3, 10)

    fig, axes = plt.subplots(1, 3, figsize=(12, 5.2),
                             gridspec_kw={"width_ratios": [1.2, 1, 1]})

    ax = axes[0]
    inside = np.abs(pos[:, 1]) < args.slab / 2
    speed = np.linalg.norm(vel[inside], axis=1)
    d = diameter[inside]
    col = EllipseCollection(d, d, 0.0, units="xy", offsets=np.c_[pos[inside, 0] + lx / 2,
                                                                 z[inside]],
                            transOffset=ax.transData, cmap="viridis", edgecolors="none")
    col.set_array(speed)
    col.set_clim(0, np.percentile(speed, 95))
    ax.add_collection(col)
    fig.colorbar(col, ax=ax, fraction=0.05, pad=0.02, label="speed")
    ax.axhspan(-amplitude, amplitude, color="0.85", zorder=0)
    floor_now = amplitude * np.sin(2 * np.pi * frequency * traj.time(frame) + floor["phase"])
    ax.axhline(floor_now, color="k", lw=2)
    ax.set_xlim(0, lx)
    ax.set_ylim(-amplitude - 0.5, top)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("height z")
    ax.set_title("side view, slab |y| < %g, t = %.0f" % (args.slab / 2, traj.time(frame)),
                 fontsize=10)

    ax = axes[1]
    ax.axhspan(-amplitude, amplitude, color="0.85", zorder=0)
    ax.plot(profile["packing_fraction"], height, "-o", ms=3)
    ax.set_xlabel("packing fraction")
    ax.set_ylabel("height z")
    ax.set_xlim(0, None)
    ax.set_ylim(-amplitude - 0.5, top)
    ax.set_title("N = %d, e = %g, $\\Gamma$ = %.1f" % (len(pos), config["contact"]["restitution"],
                                                      gamma), fontsize=10)
    ax.grid(alpha=0.3)

    ax = axes[2]
    ax.axhspan(-amplitude, amplitude, color="0.85", zorder=0)
    ok = np.isfinite(profile["temperature"]) & (profile["number_density"] > 1e-3)
    ax.semilogx(profile["temperature"][ok], height[ok], "-o", ms=3, color="C3")
    ax.set_ylim(-amplitude - 0.5, top)
    ax.set_xlabel("granular temperature")
    ax.set_title("hot gas below, cold dense layer above", fontsize=10)
    ax.grid(alpha=0.3, which="both")

    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
