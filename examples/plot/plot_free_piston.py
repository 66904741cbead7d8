#!/usr/bin/python3
"""Picture of examples/free_piston_3d.toml: a lid of mass 100 pushed by a constant force onto a
hard-sphere fluid held at kT = 1, a constant-pressure run.

Left: the lid's height (thermo.tsv's wall_z+_position) against time: it falls from its face,
overshoots, and settles at the height where the fluid's pressure is F / A. Right: the density
profile under the lid (profile.tsv, production average) against the bulk density at which the
Kolafa-Labik-Malijevsky equation of state gives the pressure F / A at kT = 1 (the layering at
the floor and under the lid is the hard walls' own).

    /usr/bin/python3 examples/plot/plot_free_piston.py OUTDIR -o free_piston.png
"""

import argparse
import math
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kairos_output as ko

def klm_pressure(eta):
    """beta P sigma^3 of the hard-sphere fluid (kairos_output.hard_sphere_z)."""
    return ko.hard_sphere_z(eta) * eta * 6.0 / math.pi


def density_at(pressure):
    lo, hi = 1e-6, 0.6
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if klm_pressure(mid) < pressure else (lo, mid)
    return 0.5 * (lo + hi) * 6.0 / math.pi


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outdir")
    parser.add_argument("-o", "--output", default="free_piston.png")
    parser.add_argument("--dpi", type=int, default=110)
    args = parser.parse_args()
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    profile = ko.read_tsv(os.path.join(args.outdir, "profile.tsv"))
    config = ko.read_config(args.outdir)
    lid = next(w for w in config["boundary"]["wall"] if w.get("mass", 0.0) > 0.0)
    summary = ko.read_summary(args.outdir)
    n = summary["particles"]
    # The box's edges across the lid: those of the periodic box the particles were put in.
    edge = (n * math.pi / 6.0 / config["system"]["packing_fraction"]) ** (1.0 / 3.0)
    pressure = lid["force"] / edge ** 2
    rho = density_at(pressure)

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    left.plot(thermo["time"], thermo["wall_z+_position"], lw=1.0)
    production = thermo["phase"] == "production"
    mean = thermo["wall_z+_position"][production].mean()
    left.axhline(mean, color="k", lw=0.6, ls="--",
                 label="production mean %.2f" % mean)
    left.set_xlabel("time")
    left.set_ylabel("lid height (z)")
    left.set_title("lid of mass %g, force %g" % (lid["mass"], lid["force"]))
    left.legend(frameon=False)

    z, density = profile["position"], profile["number_density"]
    under = z < mean
    right.plot(z[under], density[under], ".-", lw=0.8, ms=3, label="profile.tsv")
    right.axhline(rho, color="C3", lw=1.0,
                  label="equation of state at P = F/A: n = %.4f (eta = %.4f)"
                  % (rho, rho * math.pi / 6.0))
    middle = (z > 0.3 * mean) & (z < 0.7 * mean)
    right.axvspan(0.3 * mean, 0.7 * mean, color="0.9", zorder=0,
                  label="middle: n = %.4f" % density[middle].mean())
    right.set_xlabel("z")
    right.set_ylabel("number density")
    right.set_ylim(0.0, 1.6 * rho)
    right.legend(frameon=False, fontsize=8, loc="lower center")
    fig.tight_layout()
    fig.savefig(args.output, dpi=args.dpi)


if __name__ == "__main__":
    main()
