#!/usr/bin/python3
"""Picture of examples/spring_damper_3d.toml: a container of mass M holding 200 inelastic spheres,
tied by a spring and a dashpot to an anchor driven at the spring's resonance (a granular damper).

Left: the container's displacement (thermo.tsv's wall_z_position) and the anchor's A sin(2 pi f
t) over the last ten cycles, with the swing the container would have without the grains (the
transmissibility |G| A). Right: where the anchor's work goes, per cycle over the production:
the dashpot's share (wall_z_dashpot) and the grains' (dissipated_energy), against the plastic
lump's loss 4 mu (X W)^2 at the measured swing X (docs/physics.md#the-spring-driven-container).

    /usr/bin/python3 examples/plot/plot_spring_damper.py OUTDIR -o spring_damper_3d.png
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outdir")
    parser.add_argument("-o", "--output", default="spring_damper.png")
    parser.add_argument("--dpi", type=int, default=110)
    args = parser.parse_args()
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    box = ko.read_config(args.outdir)["boundary"]["container"]
    m_p = float(ko.read_summary(args.outdir)["particles"])  # grains of mass 1
    mass, k = box["mass"], box["spring_stiffness"]
    c, a, f = box.get("spring_damping", 0.0), box["drive_amplitude"], box["drive_frequency"]
    w = 2.0 * math.pi * f
    alone = a * math.hypot(k, c * w) / math.hypot(k - mass * w * w, c * w)

    t = thermo["time"]
    x = thermo["wall_z_position"]
    production = thermo["phase"] == "production"
    tp = t[production]
    periods = math.floor((tp[-1] - tp[0]) * f)
    keep = production & (t <= tp[0] + periods / f)
    basis = np.c_[np.ones(keep.sum()), np.cos(w * t[keep]), np.sin(w * t[keep])]
    coef, *_ = np.linalg.lstsq(basis, x[keep], rcond=None)
    swing = math.hypot(coef[1], coef[2])

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    last = t >= t[-1] - 10.0 / f
    left.plot(t[last], x[last], lw=1.2, label="container (with the grains): X = %.2f" % swing)
    left.plot(t[last], a * np.sin(w * t[last] + box.get("drive_phase", 0.0)), lw=1.0,
              color="0.4", label="anchor, A = %g" % a)
    for sign in (1.0, -1.0):
        left.axhline(sign * alone, color="C3", lw=0.8, ls="--",
                     label="swing without grains, %.1f" % alone if sign > 0 else None)
    left.set_xlabel("time")
    left.set_ylabel("displacement along z")
    left.set_title("M = %g, %d grains, driven at resonance" % (mass, m_p))
    left.legend(frameon=False, fontsize=8, loc="lower left")

    span = (t[keep][-1] - t[keep][0]) * f  # cycles
    cycles = (t[keep] - t[keep][0]) * f
    drive = thermo["wall_z_drive_work"][keep]
    dashpot = thermo["wall_z_dashpot"][keep]
    grains = thermo["dissipated_energy"][keep]
    right.plot(cycles, drive - drive[0], lw=1.2, label="anchor's work")
    right.plot(cycles, dashpot - dashpot[0], lw=1.2, label="dashpot")
    right.plot(cycles, grains - grains[0], lw=1.2, label="grains: %.3g per cycle"
               % ((grains[-1] - grains[0]) / span))
    mu = m_p * mass / (m_p + mass)
    lump = 4.0 * mu * (swing * w) ** 2
    right.plot(cycles, lump * cycles, color="k", lw=0.8, ls=":",
               label="plastic lump 4 mu (X W)^2 = %.3g per cycle" % lump)
    right.set_xlabel("cycles of production")
    right.set_ylabel("energy")
    right.legend(frameon=False, fontsize=8)
    fig.tight_layout()
    fig.savefig(args.output, dpi=args.dpi)


if __name__ == "__main__":
    main()
