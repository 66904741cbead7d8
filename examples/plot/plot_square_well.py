#!/usr/bin/python3
"""Picture of examples/square_well_fluid_3d.toml run at several temperatures: phase separation.

Top: a slab 2 x --slab thick through the last trajectory frame of the coldest and of the
hottest run, particles coloured by their number of neighbours within the well (r < lambda
sigma), drawn with the axis along which the density varies most upwards and centred on the
dense particles; and the distribution of the local density (particles counted in cubic cells
of about --cell diameters, last --frames frames, weighted by volume) of every run: one peak
for a homogeneous fluid, two (vapour near 0, liquid near 0.7) for a separated one.
Bottom: the potential energy per particle against time (thermo.tsv), and against T: mean over
the last --tail of each run's thermo rows, with the standard error of 5 blocks (below T_c the
domains are still coarsening and U/N still falling: a value at the end of the run, not an
equilibrium one). The dashed line is T_c* = 1.218 (Orkoulas & Panagiotopoulos 1999,
lambda = 1.5).

    /usr/bin/python3 examples/plot/plot_square_well.py sw-T0.8 sw-T1.0 ... -o square_well.png
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

T_C = 1.218  # lambda = 1.5 (Orkoulas & Panagiotopoulos, J. Chem. Phys. 110, 1581 (1999))


def run_info(outdir):
    config = ko.read_config(outdir)
    pot = config["potential"][0]
    lam = pot.get("lambda", 1.5)
    sigma = config["system"]["species"][0]["diameter"]
    return {"dir": outdir, "T": config["driving"]["temperature"], "lambda": lam,
            "range": lam * sigma, "sigma": sigma,
            "thermo": ko.read_tsv(os.path.join(outdir, "thermo.tsv")),
            "summary": ko.read_summary(outdir)}


def slab_view(ax, fig, run, frame, half_width, vmax):
    snap = ko.Frame(run["dir"], frame)
    pos, box, d = snap.pos, snap.box, snap.diameter
    n = ko.neighbour_counts(pos, box, run["range"])
    L = ko.box_lengths(box)
    # Orientation: the axis along which the density varies most (the normal of a liquid slab)
    # is drawn vertically, the one along which it varies least (the axis of a liquid cylinder)
    # is the viewing direction. Then centre the view on the dense particles (circular mean),
    # so that a liquid domain is not cut by the periodic boundaries of the picture.
    contrast = [np.histogram(pos[:, a], bins=8, range=(-L[a] / 2, L[a] / 2))[0].std()
                for a in range(3)]
    up, depth = int(np.argmax(contrast)), int(np.argmin(contrast))
    if up == depth:
        up, depth = 2, 1
    across = 3 - up - depth
    dense = n >= np.percentile(n, 75)
    centre = np.angle(np.exp(2j * np.pi * pos[dense] / L).mean(0)) * L / (2 * np.pi)
    pos = ko.minimum_image(pos - centre, box)
    s = np.abs(pos[:, depth]) < half_width
    order = np.argsort(n[s])
    xy = pos[s][order][:, [across, up]]
    coll = EllipseCollection(d[s][order], d[s][order], 0.0, units="xy", offsets=xy,
                             transOffset=ax.transData, cmap="viridis", edgecolors="none")
    coll.set_array(n[s][order].astype(float))
    coll.set_clim(0, vmax)
    ax.add_collection(coll)
    ax.set_xlim(-L[across] / 2, L[across] / 2)
    ax.set_ylim(-L[up] / 2, L[up] / 2)
    ax.set_aspect("equal")
    names = "xyz"
    ax.set_xlabel(names[across])
    ax.set_ylabel(names[up])
    ax.set_title("T = %g (%s T$_c$), t = %.0f: a slab %g thick, seen along %s"
                 % (run["T"], "below" if run["T"] < T_C else "above", snap.traj.time(snap.index),
                    2 * half_width, names[depth]), fontsize=9)
    return coll


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdirs", nargs="+", help="output directories, one per temperature")
    ap.add_argument("-o", "--png", default="square_well.png", help="PNG to write")
    ap.add_argument("--slab", type=float, default=1.5, help="half width of the slab shown")
    ap.add_argument("--frames", type=int, default=5,
                    help="last frames of each run in the local-density histogram")
    ap.add_argument("--cell", type=float, default=3.0, help="cell edge of the local density")
    ap.add_argument("--tail", type=float, default=0.25,
                    help="fraction of each run's thermo rows averaged for U/N against T")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    runs = sorted((run_info(d) for d in args.outdirs), key=lambda r: r["T"])
    colours = plt.cm.coolwarm(np.linspace(0, 1, len(runs)))
    fig = plt.figure(figsize=(15, 9))
    grid = fig.add_gridspec(2, 3, width_ratios=[1, 1, 1.1], wspace=0.4)

    vmax = 12
    ax = fig.add_subplot(grid[0, 0])
    coll = slab_view(ax, fig, runs[0], -1, args.slab, vmax)
    if len(runs) > 1:
        ax = fig.add_subplot(grid[0, 1])
        coll = slab_view(ax, fig, runs[-1], -1, args.slab, vmax)
    cax = ax.inset_axes([1.03, 0.0, 0.04, 1.0])
    fig.colorbar(coll, cax=cax, label="neighbours within $\\lambda\\sigma$")

    # Local densities in cells.
    ax = fig.add_subplot(grid[0, 2])
    for run, c in zip(runs, colours):
        traj = ko.GsdFile(os.path.join(run["dir"], "trajectory.gsd"))
        rho = []
        for f in range(max(1, traj.frames - args.frames), traj.frames):
            pos = traj.chunk("particles/position", f).astype(float)
            box = ko.box_lengths(traj.chunk("configuration/box", f))
            nc = np.maximum(1, np.round(box / args.cell)).astype(int)
            h, _ = np.histogramdd(pos, bins=nc, range=[(-b / 2, b / 2) for b in box])
            rho.append(h.ravel() / np.prod(box / nc))
        volume = np.prod(box / nc)  # bins holding the same number of whole counts each:
        edges = (np.arange(-0.5, 1.05 * volume, max(1, round(0.05 * volume)))) / volume
        h, _ = np.histogram(np.concatenate(rho), bins=edges, density=True)
        ax.plot(0.5 * (edges[1:] + edges[:-1]), h, "o-", ms=3, color=c, label="T = %g" % run["T"])
    ax.set_xlabel("local number density $\\rho^*$ in cells of edge ~%g $\\sigma$" % args.cell)
    ax.set_ylabel("fraction of the volume (density)")
    ax.set_title("local density, last %d frames: one peak (fluid) or two (vapour + liquid)"
                 % args.frames, fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)

    # U/N against time.
    ax = fig.add_subplot(grid[1, :2])
    for run, c in zip(runs, colours):
        th = run["thermo"]
        n = run["summary"]["particles"]
        ax.plot(th["time"], th["potential_energy"] / n, "-", color=c, label="T = %g" % run["T"])
    ax.set_xscale("log")
    ax.set_xlabel("time t")
    ax.set_ylabel("potential energy per particle U/N")
    ax.set_title("after the quench (random start at t = 0, Andersen thermostat)", fontsize=9)
    ax.legend(fontsize=8, ncol=2)
    ax.grid(True, alpha=0.3)

    # U/N against T: mean of the last rows, error from 5 blocks.
    ax = fig.add_subplot(grid[1, 2])
    temps, means, errs = [], [], []
    for run in runs:
        u = run["thermo"]["potential_energy"] / run["summary"]["particles"]
        half = u[int(len(u) * (1 - args.tail)):]
        blocks = np.array([b.mean() for b in np.array_split(half, 5)])
        temps.append(run["T"])
        means.append(half.mean())
        errs.append(blocks.std(ddof=1) / np.sqrt(len(blocks)))
        print("T = %g: U/N = %.4f +- %.4f (last %d thermo rows of %s)"
              % (run["T"], half.mean(), errs[-1], len(half), run["dir"]))
    ax.errorbar(temps, means, yerr=errs, fmt="o-", color="k", ms=5, capsize=3)
    ax.axvline(T_C, color="C3", ls="--", lw=1, label="$T_c^*$ = %.3f" % T_C)
    ax.set_xlabel("temperature T (Andersen)")
    ax.set_ylabel("U/N (last %d %% of each run)" % round(100 * args.tail))
    ax.set_title("square well $\\lambda$ = %g, $\\rho^*$ = %.3f" % (
        runs[0]["lambda"], runs[0]["summary"]["number_density"]), fontsize=9)
    ax.legend(fontsize=9)
    ax.grid(True, alpha=0.3)

    fig.savefig(args.png, dpi=args.dpi, bbox_inches="tight")
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
