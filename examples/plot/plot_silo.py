#!/usr/bin/python3
"""Picture of examples/silo_2d.toml and silo_3d.toml: a recirculating silo discharging through an
orifice (in 3D a slot through the periodic depth, seen from the side: x against z, the spheres
of all depths drawn, the front ones last).

Left: the grains of a trajectory frame (the last by default), coloured by their speed, with the
floor's strips, the orifice's edges and the outlet (dashed). Right: the count through the outlet
against time (thermo.tsv's outlet_passes) and the straight line of the production part's rate
(summary.json's granular.outlet.production_rate).

    /usr/bin/python3 examples/plot/plot_silo.py OUTDIR -o silo.png
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


def draw_boundaries(ax, config, width, up):
    """The strips of [[boundary.plane]] (horizontal ones; a plane with a round hole cut through
    the hole's centre) and the outlet's plane; `up` is the vertical axis (the last)."""
    for plane in config["boundary"].get("plane", []):
        y = plane["point"][up]
        if "hole_radius" in plane:  # a round orifice, cut through its centre
            cx = plane.get("hole_center", plane["point"])[0]
            pieces = [(0.0, cx - plane["hole_radius"]), (cx + plane["hole_radius"], width)]
        else:
            pieces = [(plane.get("span_min", 0.0), plane.get("span_max", width))]
        for lo, hi in pieces:
            ax.plot([max(lo, 0.0), min(hi, width)], [y, y], color="k", lw=2)
            for end in (lo, hi):
                if 0.0 < end < width:
                    ax.plot([end], [y], "ko", ms=3)
    outlet = config["boundary"].get("outlet")
    if outlet:
        ax.axhline(outlet["point"][up], color="C3", ls="--", lw=1, label="outlet")
        lo, hi = outlet["insert_lower"], outlet["insert_upper"]
        ax.add_patch(plt.Rectangle((lo[0], lo[up]), hi[0] - lo[0], hi[up] - lo[up], fill=False,
                                   ls=":", color="C2", label="insertion region"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="output directory of the run")
    ap.add_argument("-o", "--png", default="silo.png", help="PNG to write")
    ap.add_argument("--frame", type=int, default=-1, help="trajectory frame (default: last)")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    summary = ko.read_summary(args.outdir)
    snap = ko.Frame(args.outdir, args.frame)
    box = snap.box
    # GSD positions are centred: back to the box's frame, where the planes are given. In 3D the
    # side view x-z, the spheres at the back drawn first.
    up = 2 if config["system"].get("dimension", 3) == 3 else 1
    centres = snap.pos + 0.5 * np.array(box[:snap.pos.shape[1]])
    order = np.argsort(-centres[:, 1]) if up == 2 else np.arange(len(centres))
    pos = centres[order][:, [0, up]]
    speed = np.linalg.norm(snap.vel, axis=1)[order]
    diameter = np.asarray(snap.diameter)[order]

    fig, axes = plt.subplots(1, 2, figsize=(12, 7), gridspec_kw={"width_ratios": [1.1, 1]})
    ax = axes[0]
    disks = EllipseCollection(diameter, diameter, np.zeros(len(pos)), units="xy",
                              offsets=pos, offset_transform=ax.transData, cmap="viridis")
    disks.set_array(speed)
    disks.set_clim(0.0, np.percentile(speed, 98))
    ax.add_collection(disks)
    draw_boundaries(ax, config, box[0], up)
    ax.set_xlim(0, box[0])
    ax.set_ylim(0, box[up])
    ax.set_aspect("equal")
    ax.set_title(f"t = {snap.traj.time(snap.index):.4g}")
    ax.legend(loc="upper right", fontsize=8)
    fig.colorbar(disks, ax=ax, label="speed")

    ax = axes[1]
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    t, passes = np.asarray(thermo["time"]), np.asarray(thermo["outlet_passes"])
    production = np.asarray(thermo["phase"]) == "production"
    ax.plot(t, passes, label="passes through the outlet")
    outlet = summary["granular"]["outlet"]
    rate = outlet.get("production_rate")
    if rate is not None and production.any():
        t0, n0 = t[production][0], passes[production][0]
        ax.plot(t[production], n0 + rate * (t[production] - t0), "k--",
                label=f"production rate {rate:.4g} per unit time")
    ax.set_xlabel("time")
    ax.set_ylabel("cumulative count")
    ax.legend()
    ax.set_title(f"energy balance {summary['granular']['energy_balance_relative']:.2g} (relative)")
    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)


if __name__ == "__main__":
    main()
