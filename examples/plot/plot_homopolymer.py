#!/usr/bin/python3
"""Picture of examples/sw_homopolymer_collapse_3d.toml: a square-well chain collapsing on cooling.

Takes the output directories of the runs in the order they were made (the hot run, then the
cooling run that continued from its restart file). Top: the chain (made whole across the
periodic boundaries by following its bonds, centred on its centre of mass, projected on the
x-y plane; beads coloured from one end to the other) at the end of the first run (coil), at
the first frame of the last run whose Rg is below the midpoint between the coil's and the
final value (collapsing), and at the end (globule), all three at the same scale. Bottom: the
radius of gyration of every trajectory frame against time, and the potential energy per bead
and the kinetic temperature (thermo.tsv). The longest bond seen in any frame is printed: it
must never exceed the bond's max_length.

    /usr/bin/python3 examples/plot/plot_homopolymer.py coil globule -o homopolymer.png
"""

import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import EllipseCollection, LineCollection
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kairos_output as ko


def chain_frames(outdir):
    """-> list of (time, unwrapped positions, longest bond) for every frame of the run."""
    traj = ko.GsdFile(os.path.join(outdir, "trajectory.gsd"))
    bonds = traj.chunk("bonds/group").astype(int)
    out = []
    for f in range(traj.frames):
        box = traj.chunk("configuration/box", f)
        pos = traj.chunk("particles/position", f).astype(float)
        u = ko.unwrap_bonded(pos, bonds, box)
        longest = np.sqrt(((u[bonds[:, 1]] - u[bonds[:, 0]]) ** 2).sum(1)).max()
        out.append((traj.time(f), u, longest))
    return out, traj.chunk("particles/diameter").astype(float)


def draw_chain(ax, u, d, half, title):
    r = u - u.mean(0)
    n = len(r)
    colours = plt.cm.viridis(np.linspace(0, 1, n))
    seg = np.stack([r[:-1, :2], r[1:, :2]], axis=1)
    ax.add_collection(LineCollection(seg, colors=colours[:-1], lw=1.2, zorder=1))
    order = np.argsort(r[:, 2])  # far beads first
    shade = 0.55 + 0.45 * (r[order, 2] - r[:, 2].min()) / max(np.ptp(r[:, 2]), 1e-9)
    face = colours[order].copy()
    face[:, :3] *= shade[:, None]
    ax.add_collection(EllipseCollection(d[order], d[order], 0.0, units="xy", offsets=r[order, :2],
                                        transOffset=ax.transData, facecolors=face,
                                        edgecolors="k", linewidths=0.3, zorder=2))
    ax.set_xlim(-half, half)
    ax.set_ylim(-half, half)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(title, fontsize=9)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdirs", nargs="+", help="output directories, in the order of the runs")
    ap.add_argument("-o", "--png", default="homopolymer.png", help="PNG to write")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    runs = []
    longest = 0.0
    for d in args.outdirs:
        frames, diameter = chain_frames(d)
        config = ko.read_config(d)
        thermo = ko.read_tsv(os.path.join(d, "thermo.tsv"))
        rg = np.array([ko.radius_of_gyration(u) for _, u, _ in frames])
        longest = max(longest, max(b for _, _, b in frames))
        runs.append({"dir": d, "frames": frames, "rg": rg, "thermo": thermo,
                     "T": config["driving"]["temperature"],
                     "max_length": config["bond"][0]["max_length"]})
    n = len(diameter)
    first, last = runs[0], runs[-1]
    mid = 0.5 * (first["rg"][-1] + last["rg"][-1])
    k_mid = int(np.argmax(last["rg"] < mid)) if (last["rg"] < mid).any() else len(last["rg"]) // 2
    snaps = [(first["frames"][-1], first["rg"][-1], "coil"),
             (last["frames"][k_mid], last["rg"][k_mid], "collapsing"),
             (last["frames"][-1], last["rg"][-1], "globule")]
    r0 = snaps[0][0][1] - snaps[0][0][1].mean(0)
    half = np.abs(r0[:, :2]).max() + 1.0

    fig = plt.figure(figsize=(15, 9.5))
    grid = fig.add_gridspec(2, 3, height_ratios=[1, 0.85])
    for k, ((t, u, _), rg, label) in enumerate(snaps):
        run = first if k == 0 else last
        draw_chain(fig.add_subplot(grid[0, k]), u, diameter, half,
                   "%s: t = %.0f, kT = %g, R$_g$ = %.2f" % (label, t, run["T"], rg))

    ax = fig.add_subplot(grid[1, :2])
    for run, c in zip(runs, ["C3", "C0", "C2", "C1"]):
        t = np.array([f[0] for f in run["frames"]])
        ax.plot(t, run["rg"], "o-", ms=3, lw=1, color=c,
                label="%s: Andersen kT = %g" % (os.path.basename(os.path.normpath(run["dir"])),
                                                run["T"]))
        eq = run["thermo"]["phase"] == "equilibration"
        if eq.any():
            ax.axvspan(t[0], run["thermo"]["time"][eq][-1], color="0.9", lw=0)
    for (t, _, _), rg, label in snaps:
        ax.annotate(label, (t, rg), xytext=(0, 12), textcoords="offset points", ha="center",
                    fontsize=8, arrowprops={"arrowstyle": "-", "lw": 0.5})
    ax.set_xlabel("time t")
    ax.set_ylabel("radius of gyration R$_g$")
    ax.set_title("one chain of %d beads (grey: equilibration of the lattice start); longest bond "
                 "in any frame %.4f (max_length %g)" % (n, longest, first["max_length"]),
                 fontsize=9)
    ax.set_ylim(0, None)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)

    ax = fig.add_subplot(grid[1, 2])
    ax2 = ax.twinx()
    for run in runs:
        th = run["thermo"]
        ax.plot(th["time"], th["potential_energy"] / n, "-", color="k", lw=0.8)
        ax2.plot(th["time"], th["temperature"], "-", color="C1", lw=0.6, alpha=0.7)
    ax.set_xlabel("time t")
    ax.set_ylabel("potential energy per bead U/N")
    ax2.set_ylabel("kinetic temperature", color="C1")
    ax2.set_ylim(0, None)
    ax.set_title("energy (black) and temperature (orange)", fontsize=9)
    ax.grid(True, alpha=0.3)

    print("Rg: end of %s %.2f, end of %s %.2f; longest bond %.6f (max_length %g)"
          % (first["dir"], first["rg"][-1], last["dir"], last["rg"][-1], longest,
             first["max_length"]))
    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
