#!/usr/bin/python3
"""Picture of examples/granular_pile_3d.toml: grains falling onto a floor and settling.

Left: side view of the last trajectory frame (all spheres projected on the x-z plane), sleeping
spheres (velocity exactly zero in the frame) in red. Middle: events per unit time, from the
thermo.tsv rows (each row's events over its time step). Right: the number of sleeping spheres in
each trajectory frame, and the kinetic energy per sphere. Both on a logarithmic time axis: the
grains land and settle within t ~ 10, the last ones can take several times longer. A pile that
falls asleep shows the event rate dropping to zero and the sleeper count reaching N: the run then
stops with stop_reason = "no_more_events" (dotted line), after which nothing happens.

    /usr/bin/python3 examples/plot/plot_pile_3d.py OUTDIR -o pile.png
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
    ap.add_argument("-o", "--png", default="pile_3d.png", help="PNG to write")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    summary = ko.read_summary(args.outdir)
    snap = ko.Frame(args.outdir)
    traj, last = snap.traj, snap.index
    box, pos, vel, diameter = snap.box, snap.pos, snap.vel, snap.diameter
    n = len(pos)
    asleep = np.all(vel == 0, axis=1)

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.8), gridspec_kw={"width_ratios": [1, 1, 1]})

    ax = axes[0]
    x, z = pos[:, 0] + box[0] / 2, pos[:, 2] + box[2] / 2
    order = np.argsort(pos[:, 1])  # far spheres first, near ones drawn on top
    colours = np.where(asleep, "#d62728", "#1f77b4")[order]
    ax.add_collection(EllipseCollection(diameter[order], diameter[order], 0.0, units="xy",
                                        offsets=np.c_[x[order], z[order]],
                                        transOffset=ax.transData, facecolors=colours,
                                        edgecolors="k", linewidths=0.2))
    ax.set_xlim(0, box[0])
    ax.set_ylim(0, max(z.max() + 2, box[0] / 2))
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("height z")
    ax.set_title("t = %.1f: %d of %d asleep (red)" % (traj.time(last), asleep.sum(), n),
                 fontsize=10)

    ax = axes[1]
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    t, events = thermo["time"], thermo["events"]
    dt = np.diff(np.r_[0.0, t])
    rate = np.diff(np.r_[0.0, events]) / np.where(dt > 0, dt, np.nan)
    ax.loglog(t, rate, "-", drawstyle="steps-pre", color="C0")
    stopped = summary["stop_reason"] == "no_more_events"
    if stopped:
        ax.axvline(t[-1], color="k", lw=0.8, ls=":")
        ax.text(t[-1], 0.5, "no more events: \nrate 0 from here ",
                transform=ax.get_xaxis_transform(), ha="right", va="center", fontsize=8)
    ax.set_xlabel("time")
    ax.set_ylabel("events per unit time")
    ax.set_title("N = %d, e = %g, tc = %g: %s" % (n, config["contact"]["restitution"],
                                                 config["contact"]["tc"],
                                                 summary["stop_reason"]), fontsize=10)
    ax.grid(alpha=0.3, which="both")

    ax = axes[2]
    times = np.array([traj.time(f) for f in range(traj.frames)])
    sleepers = np.array([np.all(traj.chunk("particles/velocity", f) == 0, axis=1).sum()
                         for f in range(traj.frames)])
    ax.semilogx(times[1:], sleepers[1:], "o-", ms=3, color="#d62728",
                label="asleep (trajectory frames)")
    ax.axhline(n, color="k", lw=0.8, ls=":")
    ax.set_ylim(0, n * 1.05)
    ax.set_xlabel("time")
    ax.set_ylabel("spheres asleep")
    ax2 = ax.twinx()
    ke = thermo["kinetic_energy"] / n
    ax2.loglog(t[ke > 0], ke[ke > 0], "-", color="C2", label="kinetic energy / N")
    ax2.set_ylabel("kinetic energy per sphere", color="C2")
    g = summary.get("granular", {})
    ax.set_title("fell asleep %d times in all, %d asleep at the end"
                 % (g.get("fell_asleep", 0), g.get("sleeping_now", 0)), fontsize=10)
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], fontsize=8, loc="center right")

    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
