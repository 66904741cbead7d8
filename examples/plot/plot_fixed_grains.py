#!/usr/bin/python3
"""Picture of examples/fixed_obstacles_2d.toml: grains draining through a bed of fixed grains.

Left: the first trajectory frame (grains and obstacles placed at random in the upper half of
the box). Right: the last frame, every grain asleep, on the obstacles or on the floor. Fixed
grains are drawn dark, the others coloured by their height in the first frame (so where each
came from shows).

    /usr/bin/python3 examples/plot/plot_fixed_grains.py OUTDIR -o fixed_grains.png
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


def draw(ax, snap, fixed, colour, title):
    box = snap.box
    pos = snap.pos[:, :2] + 0.5 * np.array(box[:2])  # GSD positions are centred
    grains = EllipseCollection(snap.diameter[~fixed], snap.diameter[~fixed],
                               np.zeros(int((~fixed).sum())), units="xy", offsets=pos[~fixed],
                               offset_transform=ax.transData, cmap="viridis")
    grains.set_array(colour)
    ax.add_collection(grains)
    ax.add_collection(EllipseCollection(snap.diameter[fixed], snap.diameter[fixed],
                                        np.zeros(int(fixed.sum())), units="xy",
                                        offsets=pos[fixed], offset_transform=ax.transData,
                                        facecolors="0.25"))
    ax.set_xlim(0, box[0])
    ax.set_ylim(0, box[1])
    ax.set_aspect("equal")
    ax.set_title(title)
    return grains


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="output directory of the run")
    ap.add_argument("-o", "--png", default="fixed_grains.png", help="PNG to write")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    summary = ko.read_summary(args.outdir)
    names = [s["name"] for s in config["system"]["species"]]
    fixed_names = {s["name"] for s in config["system"]["species"] if s.get("fixed", False)}
    first, last = ko.Frame(args.outdir, 0), ko.Frame(args.outdir, -1)
    typeid = first.traj.chunk("particles/typeid", 0).astype(int)
    fixed = np.array([names[t] in fixed_names for t in typeid])
    height = first.pos[~fixed, 1] + 0.5 * first.box[1]

    fig, axes = plt.subplots(1, 2, figsize=(12, 6.4))
    draw(axes[0], first, fixed, height, "t = 0: grains and fixed obstacles placed at random")
    g = summary["granular"]
    grains = draw(axes[1], last, fixed, height,
                  f"t = {last.traj.time(last.index):.4g}: {g['sleeping_now']} grains asleep, "
                  f"{g['fixed_grains']} fixed")
    fig.colorbar(grains, ax=axes, label="starting height of the grain", shrink=0.8)
    fig.savefig(args.png, dpi=args.dpi)


if __name__ == "__main__":
    main()
