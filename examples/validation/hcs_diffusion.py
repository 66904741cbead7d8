#!/usr/bin/python3
"""Self-diffusion in the homogeneous cooling state of smooth inelastic hard spheres and disks
against kinetic theory (docs/validation.md, "Self-diffusion in the homogeneous cooling state").

Every number is Kairos's own summary.json `diffusion` (analysis.msd = true on a freely cooling
gas: the MSD against collisions per particle, analysis.msd_time = "auto"): the measured
`species.A.coefficient` (length^2 per collision per particle) over `theory.coefficient` (Enskog,
first Sonine approximation with van Noije-Ernst's a2, times the higher Sonine orders of
examples/validation/hcs_sonine.py). The elastic rows (e = 1, msd_time = "collisions") measure
what Enskog's theory leaves out at this density (correlated collisions), the same for every e
to first order.

  spheres  3D, N = 20 000, packing fraction 0.01 (box 8.6 mean free paths wide: below the
           shear-instability size 10.8 / sqrt(1 - e^2) mean free paths of the dilute cooling
           state for every e here), 10 collisions per particle of cooling from the Maxwellian,
           200 of production, every particle followed, fit window [10, 50] collisions per
           particle; e = 1.0, 0.9, 0.8, 0.7, --seeds seeds each.
  disks    2D, N = 4000, area fraction 0.0025 (10 mean free paths; the instability size is
           10.0 / sqrt(1 - e^2)), the same lengths; e = 1.0, 0.9, 0.8.

    /usr/bin/python3 examples/validation/hcs_diffusion.py build/kairos [-o hcs-diffusion]
        [--only spheres,disks] [--seeds 4]

Runs are kept in OUTPUT/runs/ and re-used when their config is unchanged. CPU on the 2-core VM
(one run at a time): spheres about 10 s per run (2.7 min at 4 seeds), disks 2 s per run.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cached_runs  # noqa: E402

CASES = {
    "spheres": dict(dimension=3, particles=20000, fraction=0.01, restitutions=(1.0, 0.9, 0.8, 0.7)),
    "disks": dict(dimension=2, particles=4000, fraction=0.0025, restitutions=(1.0, 0.9, 0.8)),
}


def config_text(case, e, seed, outdir):
    return f"""[system]
dimension = {case["dimension"]}
particles = {case["particles"]}
packing_fraction = {case["fraction"]}
lattice = "random"
seed = {seed}

[contact]
restitution = {e}

[run]
equilibration_collisions_per_particle = 10
collisions_per_particle = 200

[output]
directory = "{outdir}"
trajectory = false
progress = "never"
thermo_interval = 5

[analysis]
msd = true
msd_time = "collisions"
msd_particles = {case["particles"]}
msd_fit_from = 10.0
msd_fit_to = 50.0
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("kairos")
    ap.add_argument("-o", "--output", default="hcs-diffusion")
    ap.add_argument("--only", default="spheres,disks")
    ap.add_argument("--seeds", type=int, default=4)
    args = ap.parse_args()
    for name in args.only.split(","):
        case = CASES[name]
        print(f"\n{name}: d = {case['dimension']}, N = {case['particles']}, "
              f"packing fraction {case['fraction']}, {args.seeds} seeds")
        print("e\ttheory D_s\tfirst Sonine\tSonine factor\tmeasured D_s (mean +- sd/sqrt(n))\t"
              "measured/theory\tmean reported stderr/theory\tsd/mean stderr")
        for e in case["restitutions"]:
            ratios, errors, coefficients = [], [], []
            theory = None
            for seed in range(1, args.seeds + 1):
                outdir = os.path.join(args.output, "runs", f"{name}-e{e}-s{seed}")
                cached_runs.run_one(args.kairos, outdir, config_text(case, e, seed, outdir),
                                    overwrite=True)
                s = json.load(open(os.path.join(outdir, "summary.json")))
                d = s["diffusion"]
                theory = d["theory"]
                a = d["species"]["A"]
                coefficients.append(a["coefficient"])
                ratios.append(a["coefficient_over_theory"])
                errors.append(a["coefficient_over_theory_stderr"])
            n = len(ratios)
            sd = float(np.std(ratios, ddof=1)) if n > 1 else math.nan
            print(f"{e}\t{theory['coefficient']:.5g}\t{theory['coefficient_first_sonine']:.5g}\t"
                  f"{theory['sonine_factor']:.5f}\t{np.mean(coefficients):.5g} +- "
                  f"{np.std(coefficients, ddof=1) / math.sqrt(n):.2g}\t"
                  f"{np.mean(ratios):.4f} +- {sd / math.sqrt(n):.4f}\t{np.mean(errors):.4f}\t"
                  f"{sd / np.mean(errors):.2f}")


if __name__ == "__main__":
    main()
