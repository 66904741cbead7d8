#!/usr/bin/python3
"""Picture of examples/rotating_drum_2d.toml: rough disks in a rotating drum.

Left: the disks of the last trajectory frame inside the drum, coloured by their speed along
the drum's rotation (the azimuthal velocity about its axis, in units of the wall speed omega R),
with the drum's circle. Right: the kinetic energy and the drum's cumulative work against time
(thermo.tsv), and the energy budget of summary.json.

    /usr/bin/python3 examples/plot/plot_drum.py OUTDIR -o drum.png
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
    ap.add_argument("-o", "--png", default="drum.png", help="PNG to write")
    ap.add_argument("--frame", type=int, default=-1, help="trajectory frame (default: last)")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    summary = ko.read_summary(args.outdir)
    drum = config["boundary"]["cylinder"][0]
    omega, radius = drum.get("angular_velocity", 0.0), drum["radius"]
    snap = ko.Frame(args.outdir, args.frame)
    box = snap.box
    # GSD positions are centred: back to the box's frame, where the drum's centre is given.
    pos = snap.pos[:, :2] + 0.5 * np.array(box[:2])
    rel = pos - np.array(drum["center"][:2])
    r = np.maximum(np.hypot(rel[:, 0], rel[:, 1]), 1e-12)
    azimuthal = (rel[:, 0] * snap.vel[:, 1] - rel[:, 1] * snap.vel[:, 0]) / r
    wall_speed = abs(omega) * radius if omega != 0.0 else 1.0

    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6))
    ax = axes[0]
    disks = EllipseCollection(snap.diameter, snap.diameter, np.zeros(len(pos)), units="xy",
                              offsets=pos, offset_transform=ax.transData, cmap="coolwarm")
    disks.set_array(azimuthal / wall_speed)
    disks.set_clim(-1.0, 1.0)
    ax.add_collection(disks)
    ax.add_patch(plt.Circle(drum["center"][:2], radius, fill=False, color="k"))
    ax.set_xlim(0, box[0])
    ax.set_ylim(0, box[1])
    ax.set_aspect("equal")
    ax.set_title(f"t = {snap.traj.time(snap.index):.4g}, omega = {omega:g}, "
                 f"Fr = {omega ** 2 * radius / abs(config['field']['gravity'][1]):.2g}")
    fig.colorbar(disks, ax=ax, label="azimuthal velocity / (omega R)")

    ax = axes[1]
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    ax.plot(thermo["time"], thermo["kinetic_energy"], label="kinetic energy")
    ax.plot(thermo["time"], thermo["wall_work"], label="work by the drum (cumulative)")
    ax.set_xlabel("time")
    ax.legend()
    g = summary["granular"]
    ax.set_title(f"energy balance {g['energy_balance_relative']:.2g} (relative)")
    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)


if __name__ == "__main__":
    main()
