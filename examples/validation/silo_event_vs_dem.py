#!/usr/bin/env python3
"""The recirculating 2D silo (examples/silo_2d.toml) run by both integrators on the same silo and
grains (docs/validation.md, "The silo against the DEM"): the event-driven engine with hard rough
disks (restitution e = 0.8, Coulomb friction mu = 0.5, Walton's sticking restitution
beta0 = 0.4, the TC model at the example's tc = 1e-4) and the DEM with soft disks (a linear
spring-dashpot of the same e at stiffness k = 10^5 m g / d, Coulomb friction mu = 0.5 with a
tangential spring, k_t / k_n = 2/7; the silo's open top closed by a wall, which no disk
reaches). 1000 disks, a silo 51.2 d wide, orifices of D = 8, 10, 12, 14 d.

For each orifice, integrator and seed: the discharge rate over production (passes per unit
time, from thermo.tsv's outlet_passes) with its standard error from 6 time blocks, and the wall
time of the run. The seeds' rates are combined into their mean, whose error is the larger of
the block errors' and the seeds' scatter (monodisperse disks form crystalline patches that a
run of 60 time units does not forget, so the seeds differ by more than the blocks say). Then, per integrator, Beverloo's 2D law W = A (D - k d)^{3/2} fitted to the
rates (weighted least squares): A and k with their errors, and chi^2.

    /usr/bin/python3 examples/validation/silo_event_vs_dem.py build/kairos [--seeds 2]

About 12 minutes on one core for 3 seeds (the DEM takes two thirds of it).
"""

import argparse
import math
import os
import re
import tempfile

import numpy as np
from scipy.optimize import curve_fit

from cached_runs import run_one

CENTRE = 25.585  # the orifice's centre along x (the example's box is 51.17 wide)
BLOCKS = 6


def configs(example, width, seed):
    with open(example) as f:
        text = f.read()
    text = re.sub(r"seed = \d+", f"seed = {seed}", text)
    text = text.replace("span_max = 20.58", f"span_max = {CENTRE - 0.5 * width:.4f}")
    text = text.replace("span_min = 30.58", f"span_min = {CENTRE + 0.5 * width:.4f}")
    assert f"span_max = {CENTRE - 0.5 * width:.4f}" in text
    dem = re.sub(r"\[contact\].*?\n\n", "[soft]\nmodel = \"dashpot\"\nstiffness = 100000.0\n"
                 "restitution = 0.8\nfriction = 0.5\n\n", text, flags=re.S)
    dem = dem.replace('[boundary]\nopen = ["y+"]\n', '[[boundary.wall]]\nface = "y+"\n')
    dem = dem.replace("[run]\n", "[run]\nintegrator = \"dem\"\n")
    assert "[soft]" in dem and 'face = "y+"' in dem
    return {"event": text, "dem": dem}


def rate(out):
    """Passes per unit time over production and its standard error from BLOCKS time blocks."""
    with open(os.path.join(out, "thermo.tsv")) as f:
        header = f.readline().rstrip("\n").split("\t")
        rows = [line.rstrip("\n").split("\t") for line in f]
    rows = [r for r in rows if r[0] == "production"]
    t = np.array([float(r[header.index("time")]) for r in rows])
    n = np.array([float(r[header.index("outlet_passes")]) for r in rows])
    edges = np.linspace(0, len(t) - 1, BLOCKS + 1).round().astype(int)
    blocks = np.array([(n[b] - n[a]) / (t[b] - t[a]) for a, b in zip(edges[:-1], edges[1:])])
    return (n[-1] - n[0]) / (t[-1] - t[0]), blocks.std(ddof=1) / math.sqrt(BLOCKS)


def beverloo(d, a, k):
    return a * np.clip(d - k, 0.0, None) ** 1.5


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kairos")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--widths", type=float, nargs="+", default=[8.0, 10.0, 12.0, 14.0])
    args = parser.parse_args()
    kairos = os.path.abspath(args.kairos)
    example = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "silo_2d.toml")
    results = {}  # (kind, width) -> [(rate, error, seconds)]
    with tempfile.TemporaryDirectory() as tmp:
        for width in args.widths:
            for seed in range(1, args.seeds + 1):
                for kind, text in configs(example, width, seed).items():
                    out, seconds = run_one(kairos, os.path.join(tmp, f"{kind}_{width:g}_{seed}"),
                                           text, overwrite=True)
                    w, e = rate(out)
                    results.setdefault((kind, width), []).append((w, e, seconds))
    print("D/d   event W            dem W              dem/event        wall s (event, dem)")
    table = {}
    for width in args.widths:
        row = []
        for kind in ("event", "dem"):
            runs = np.array(results[(kind, width)])
            # Seeds combined: the mean of the runs; the error of the mean from their block
            # errors or from their scatter, the larger.
            w = runs[:, 0].mean()
            e = math.sqrt(np.sum(runs[:, 1] ** 2)) / len(runs)
            if len(runs) > 1:
                e = max(e, runs[:, 0].std(ddof=1) / math.sqrt(len(runs)))
            print(f"  D = {width:g} {kind}: seeds " +
                  ", ".join(f"{r[0]:.2f} +- {r[1]:.2f}" for r in runs))
            table[(kind, width)] = (w, e)
            row.append((w, e, runs[:, 2].mean()))
        (we, ee, se), (wd, ed, sd) = row
        ratio = wd / we
        ratio_err = ratio * math.hypot(ee / we, ed / wd)
        print(f"{width:4g}  {we:6.2f} +- {ee:4.2f}    {wd:6.2f} +- {ed:4.2f}    "
              f"{ratio:5.3f} +- {ratio_err:5.3f}    {se:5.1f}  {sd:5.1f}")
    print(f"(W: passes per unit time over production, seeds combined; errors from {BLOCKS} time "
          "blocks per run)")
    if len(args.widths) < 3:
        return  # two parameters need three widths at least
    print("\nBeverloo W = A (D - k d)^(3/2):")
    for kind in ("event", "dem"):
        d = np.array(args.widths)
        w = np.array([table[(kind, x)][0] for x in d])
        e = np.array([table[(kind, x)][1] for x in d])
        (a, k), cov = curve_fit(beverloo, d, w, p0=(1.0, 1.0), sigma=e, absolute_sigma=True)
        chi2 = float(np.sum(((w - beverloo(d, a, k)) / e) ** 2))
        print(f"  {kind:5s}  A = {a:.4f} +- {math.sqrt(cov[0, 0]):.4f}, "
              f"k = {k:.3f} +- {math.sqrt(cov[1, 1]):.3f}, chi2 = {chi2:.2f} for {len(d) - 2} dof")


if __name__ == "__main__":
    main()
