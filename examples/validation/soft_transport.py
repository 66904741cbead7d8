#!/usr/bin/env python3
"""Einstein-Helfand transport coefficients of elastic soft (Hertz) spheres approach the hard-sphere
values as the contacts stiffen (docs/validation.md, "Transport coefficients of elastic soft
spheres").

For each Young's modulus: an event-driven run with [analysis] transport (the Muller-Poschel map,
docs/physics.md#einstein-helfand-transport-coefficients) and a force-based DEM run of the same
start, whose mean kinetic temperature is the true temperature of the soft fluid at that energy:
the transport analysis's temperature (frozen pairs counted as one body) must agree with it.
The hard-sphere run at the same packing fraction and the Enskog values are the limit.

    /usr/bin/python3 examples/validation/soft_transport.py build/kairos --out soft-transport
"""

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cached_runs import config_text, run_one  # noqa: E402

ENSKOG = {"shear_viscosity": 0.7310, "bulk_viscosity": 0.6405, "thermal_conductivity": 3.0810}
COEFFICIENTS = ("shear_viscosity", "bulk_viscosity", "thermal_conductivity")


def soft_table(young):
    return "[soft]\nmodel = \"hertz\"\nyoung = %r\npoisson = 0.3\n\n" % young


def transport_text(young, collisions, seed):
    text = config_text(3, 1372, 0.3, collisions, seed=seed, equilibration=200.0,
                       analysis={"transport": True, "transport_fit_from": 0.993,
                                 "transport_fit_to": 3.97})
    return text if young is None else soft_table(young) + text


def dem_text(young, seed, duration):
    text = config_text(3, 1372, 0.3, 0.0, seed=seed, equilibration=0.0, thermo_interval=0.25)
    text = text.replace("\ncollisions_per_particle = 0.0",
                        "\ntime = %r\nintegrator = \"dem\"" % duration)
    return soft_table(young) + text


def mean_temperature(outdir, after):
    rows = np.genfromtxt(os.path.join(outdir, "thermo.tsv"), names=True, dtype=None,
                         encoding=None)
    t = rows["temperature"][rows["time"] >= after]
    blocks = np.array_split(t, 8)
    means = np.array([b.mean() for b in blocks])
    return t.mean(), means.std(ddof=1) / np.sqrt(len(means))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("kairos")
    parser.add_argument("--out", default="soft-transport")
    parser.add_argument("--youngs", default="1e5,1e6,1e7")
    parser.add_argument("--collisions", type=float, default=50000.0)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    kairos = os.path.abspath(args.kairos)
    rows = []
    for young in [None] + [float(y) for y in args.youngs.split(",")]:
        name = "hard" if young is None else "young_%g" % young
        out, wall = run_one(kairos, os.path.join(args.out, name),
                            transport_text(young, args.collisions, args.seed))
        summary = json.load(open(os.path.join(out, "summary.json")))
        t = summary["transport"]
        row = {"young": young, "wall": wall, "temperature": t["temperature"],
               "z": summary.get("compressibility")}
        for c in COEFFICIENTS:
            row[c] = (t[c]["value"], t[c]["stderr"])
        if young is not None:
            dem, _ = run_one(kairos, os.path.join(args.out, name + "_dem"),
                             dem_text(young, args.seed, 20.0))
            row["dem_temperature"] = mean_temperature(dem, 5.0)
        rows.append(row)
    print("| contacts | kT (transport) | kT (DEM, t >= 5) | eta_s | kappa | lambda | eta_s / HS "
          "| kappa / HS | lambda / HS | wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    hard = rows[0]
    for r in rows:
        label = "hard spheres" if r["young"] is None else "Hertz, Y = %g" % r["young"]
        dem = r.get("dem_temperature")
        cells = [label, "%.4f" % r["temperature"],
                 "%.4f +- %.4f" % dem if dem else "-"]
        cells += ["%.4f +- %.4f" % r[c] for c in COEFFICIENTS]
        for c in COEFFICIENTS:
            v, e = r[c]
            hv, he = hard[c]
            cells.append("%.3f +- %.3f" % (v / hv, (v / hv) * np.hypot(e / v, he / hv)))
        cells.append("%.0f" % r["wall"])
        print("| " + " | ".join(cells) + " |")
    print("Enskog at eta = 0.3:", ENSKOG)


if __name__ == "__main__":
    main()
