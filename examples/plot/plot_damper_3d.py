#!/usr/bin/python3
"""Picture of examples/granular_damper_3d.toml: a shaken container full of grains.

Top: the container's floor and lid (black) and the grains' heights in each trajectory frame
(median, and the band between the 10th and 90th percentiles), over the last --cycles cycles.
Bottom: the work the shaking walls have done on the grains and the energy the grains have
dissipated (collisions with each other and with the walls), cumulative, from thermo.tsv; the
difference is the change of the energy held by the grains (kinetic + gravitational).

    /usr/bin/python3 examples/plot/plot_damper_3d.py OUTDIR -o damper.png
"""

import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kairos_output as ko


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="output directory of the run")
    ap.add_argument("-o", "--png", default="damper_3d.png", help="PNG to write")
    ap.add_argument("--cycles", type=float, default=4.0, help="cycles shown in the top panel")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    walls = {w["face"]: w for w in config["boundary"]["wall"]}
    floor, lid = walls["z-"], walls["z+"]
    amplitude, frequency, phase = floor["amplitude"], floor["frequency"], floor["phase"]
    if (lid["amplitude"], lid["frequency"], lid["phase"]) != (amplitude, frequency, phase):
        print("note: floor and lid do not vibrate in phase; drawing each on its own")
    g = -config["field"]["gravity"][2]
    omega = 2 * np.pi * frequency

    traj = ko.GsdFile(os.path.join(args.outdir, "trajectory.gsd"))
    lz = float(traj.chunk("configuration/box", 0)[2])
    times = np.array([traj.time(f) for f in range(traj.frames)])
    t_end = times[-1]
    t_start = max(0.0, t_end - args.cycles / frequency)
    frames = [f for f in range(traj.frames) if times[f] >= t_start]
    heights = np.array([np.percentile(traj.chunk("particles/position", f)[:, 2] + lz / 2,
                                      [10, 50, 90]) for f in frames])
    n = len(traj.chunk("particles/position", 0))
    mass = float(np.sum(traj.chunk("particles/mass", 0)))

    fig, axes = plt.subplots(2, 1, figsize=(10, 7.5), gridspec_kw={"height_ratios": [1.2, 1]})

    ax = axes[0]
    tt = np.linspace(t_start, t_end, 2000)
    ax.plot(tt, floor["amplitude"] * np.sin(2 * np.pi * floor["frequency"] * tt + floor["phase"]),
            "k-", lw=2, label="floor and lid")
    ax.plot(tt, lz + lid["amplitude"] * np.sin(2 * np.pi * lid["frequency"] * tt + lid["phase"]),
            "k-", lw=2)
    t_frames = times[frames]
    ax.vlines(t_frames, heights[:, 0], heights[:, 2], color="C0", alpha=0.25, lw=1.5,
              label="grains: 10 % to 90 % of heights")
    ax.plot(t_frames, heights[:, 1], "o", ms=2.5, color="C0", label="grains: median height")
    ax.set_xlim(t_start, t_end)
    ax.set_xlabel("time")
    ax.set_ylabel("height z")
    ax.set_title("N = %d, e = %g: container shaken with A = %g, f = %g ($\\Gamma$ = %.1f); "
                 "one dot per trajectory frame" % (n, config["contact"]["restitution"],
                                                   amplitude, frequency,
                                                   amplitude * omega ** 2 / g), fontsize=10)
    ax.legend(loc="upper right", fontsize=8, ncol=3)

    ax = axes[1]
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    t = thermo["time"]
    work, dissipated = thermo["wall_work"], thermo["dissipated_energy"]
    scale = 0.5 * mass * (amplitude * omega) ** 2  # kinetic energy of the grains moving with
    ax.plot(t, work / scale, "-", color="C1", lw=2, label="work done by floor and lid")
    ax.plot(t, dissipated / scale, "--", color="C2", lw=2, label="energy dissipated")
    ax.set_xlabel("time")
    ax.set_ylabel("energy / (M (A$\\omega$)$^2$ / 2)")
    # Mean dissipated power over the whole cycles after the first one.
    cycles = np.floor((t[-1] - 1 / frequency) * frequency)
    if cycles >= 1:
        t1 = 1 / frequency
        t2 = t1 + cycles / frequency
        d = np.interp([t1, t2], t, dissipated)
        per_cycle = (d[1] - d[0]) / cycles
        ax.set_title("dissipated per cycle (cycles 2 to %d): %.2f M (A$\\omega$)$^2$ / 2, "
                     "%.0f per grain" % (cycles + 1, per_cycle / scale, per_cycle / n),
                     fontsize=10)
    ax.legend(fontsize=9)
    ax.grid(alpha=0.3)

    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
