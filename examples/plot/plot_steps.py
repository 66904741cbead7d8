#!/usr/bin/python3
"""Step tables of `kairos steps CONFIG.toml -o STEPSDIR` drawn over their continuous potentials.

One row per table (potential or bond): left, the whole table, from the hard core (the first
step's inner boundary: the energy is infinite below it) to beyond the cut-off; right, a zoom on
the well. The table's U_step is drawn as a staircase (constant within each shell, a jump at
each boundary, 0 beyond the cut-off of a pair potential, a wall at the cut-off of a bond); the
continuous potential it was made from (the *_curve.tsv file) as a line. The panel titles give
the table's B2 and the continuous one's as `kairos steps` printed them.

    kairos steps examples/stepped_lj_liquid_3d.toml -o lj-steps
    /usr/bin/python3 examples/plot/plot_steps.py lj-steps -o lj_steps.png
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


def staircase(t):
    """(x, y) of the step function U_step(r) from beyond the cut-off down to the hard core."""
    r_out, r_in, u = t["r_outer"], t["r_inner"], t["U_step"]
    cut = r_out[0]
    x, y = [], []
    if t["bond"]:
        x += [cut]
        y += [np.inf]
    else:
        x += [cut + 0.15 * (cut - r_in[-1]), cut]
        y += [0.0, 0.0]
    for k in range(len(u)):
        x += [r_out[k], r_in[k]]
        y += [u[k], u[k]]
    x += [r_in[-1]]
    y += [np.inf]
    return np.array(x), np.array(y)


def draw(ax, t, ylim, xlim, label_steps):
    x, y = staircase(t)
    big = ylim[1] + 10 * (ylim[1] - ylim[0])  # stands for the infinite walls
    y = np.where(np.isinf(y), big, y)
    if "curve_r" in t:
        ok = np.isfinite(t["curve_U"])
        ax.plot(t["curve_r"][ok], t["curve_U"][ok], "-", color="C3", lw=1.6,
                label="continuous U(r)")
    ax.plot(x, y, "-", color="C0", lw=1.1, label=label_steps)
    ax.axhline(0.0, color="grey", lw=0.6)
    ax.axvspan(xlim[0], t["r_inner"][-1], color="0.85", lw=0)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel("r")
    ax.grid(True, alpha=0.3)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("stepsdir", help="directory written by `kairos steps CONFIG.toml -o DIR`")
    ap.add_argument("-o", "--png", default="steps.png", help="PNG to write")
    ap.add_argument("--ymax", type=float, default=None,
                    help="upper energy limit of the zoom (default: a bit above the well)")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    tables = ko.read_step_tables(args.stepsdir)
    if not tables:
        sys.exit("no step tables (*.tsv) in %s" % args.stepsdir)
    fig, axes = plt.subplots(len(tables), 2, figsize=(12, 4.2 * len(tables)), squeeze=False)
    for row, t in zip(axes, tables):
        u, core, cut = t["U_step"], t["r_inner"][-1], t["r_outer"][0]
        umin, umax = min(float(u.min()), 0.0), float(u.max())
        depth = max(-umin, 1e-12 if umax <= 0 else 0.0)
        xlim = (core - 0.06 * (cut - core), cut + 0.15 * (cut - core))
        label = "steps: %d shell%s" % (len(u), "" if len(u) == 1 else "s")
        b2 = [c for c in t["comments"] if c.startswith("B2")]
        shells = [c for c in t["comments"] if c.startswith("step table")]

        # Whole table: up to the energy at the hard core.
        top = max(umax, depth, 1.0)
        lo = umin - 0.08 * (top - umin) if umin < 0 else -0.08 * top
        draw(row[0], t, (lo, top + 0.08 * (top - lo)), xlim, label)
        row[0].set_ylabel("U(r)")
        row[0].set_title("%s\n%s" % (t["name"], shells[0] if shells else ""), fontsize=9)
        row[0].legend(fontsize=9, loc="upper right")

        # Zoom on the well (or, for a purely repulsive table, on its lower steps).
        if depth > 0 and umin < 0:
            ymax = args.ymax if args.ymax is not None else 0.6 * depth
            ylim = (umin - 0.12 * depth, ymax)
        else:
            ymax = args.ymax if args.ymax is not None else max(0.25 * umax, 1.0)
            ylim = (-0.1 * ymax, ymax)
        draw(row[1], t, ylim, xlim, label)
        row[1].set_title("zoom\n" + (b2[0] if b2 else ""), fontsize=9)

    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
