#!/usr/bin/python3
"""Mutual (inter)diffusion of binary hard-sphere mixtures (analysis.mutual_diffusion) against
the exact identity for mechanically identical species and against the Boltzmann-Enskog theory
of a size- and mass-asymmetric dilute mixture (docs/validation.md, "Mutual diffusion").

Every number is Kairos's own summary.json `diffusion.mutual.pairs.A-B` (coefficient, epochs'
error) and `diffusion.species` (self-diffusion); sigma_A = m_A = kT = 1.

  identical  3D, eta = 0.1, N = 1000, two labels on identical spheres at x_A = 0.5 and 0.2,
             20 000 collisions per particle, fit window [5, 20] time units (about 8-30 mean
             free times), --seeds seeds: D_AB / (D_self N / (N - 1)) = 1 exactly in expectation
             (the distinct velocity correlations cancel with the centre of mass at rest;
             docs/physics.md#mutual-diffusion).
  asymmetric 3D, eta = 0.01, N = 1000, sigma_B = 1.4, m_B = 2, x_A = 0.5, 20 000 collisions
             per particle, fit window [40, 160] (about 4-15 mean free times; the interdiffusion
             current decorrelates in ~ D mu / kT ~ 8): D_AB against Chapman and Cowling's first
             approximation over chi_AB and its fourth Sonine order
             (examples/validation/mixture_diffusion_sonine.py: 12.537, 1.0296 times the first).

    /usr/bin/python3 examples/validation/mutual_diffusion.py build/kairos [-o mutual-diffusion]
        [--only identical,asymmetric] [--seeds 8]

Runs are kept in OUTPUT/runs/ and re-used when their config is unchanged. CPU on the 2-core VM
(one run at a time): about 25 s per run.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cached_runs  # noqa: E402

# examples/validation/mixture_diffusion_sonine.py --eta 0.01 --diameters 1,1.4 --masses 1,2
# --fractions 0.5,0.5 --orders 4 --samples 8000000: [D12]_1 / chi_12 and order 4.
ASYMMETRIC_FIRST, ASYMMETRIC_CONVERGED = 12.1764, 12.5367


def config_text(outdir, seed, eta, x_a, sigma_b, m_b, fit):
    return f"""[system]
dimension = 3
particles = 1000
packing_fraction = {eta}
lattice = "random"
seed = {seed}

[[system.species]]
name = "A"
fraction = {x_a}

[[system.species]]
name = "B"
diameter = {sigma_b}
mass = {m_b}
fraction = {1 - x_a}

[run]
equilibration_collisions_per_particle = 20
collisions_per_particle = 20000

[output]
directory = "{outdir}"
trajectory = false
progress = "never"

[analysis]
msd = true
mutual_diffusion = true
msd_particles = 1000
msd_fit_from = {fit[0]}
msd_fit_to = {fit[1]}
"""


def runs(args, name, seeds, **case):
    out = []
    for seed in range(1, seeds + 1):
        outdir = os.path.join(args.output, "runs", f"{name}-s{seed}")
        cached_runs.run_one(args.kairos, outdir, config_text(outdir, seed, **case),
                            overwrite=True)
        out.append(json.load(open(os.path.join(outdir, "summary.json")))["diffusion"])
    return out


def mean_and_error(values):
    return float(np.mean(values)), float(np.std(values, ddof=1) / math.sqrt(len(values)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("kairos")
    ap.add_argument("-o", "--output", default="mutual-diffusion")
    ap.add_argument("--only", default="identical,asymmetric")
    ap.add_argument("--seeds", type=int, default=8)
    args = ap.parse_args()
    parts = args.only.split(",")
    if "identical" in parts:
        print("identical: eta = 0.1, N = 1000, window [5, 20]")
        print("x_A\tD_AB (mean +- sd/sqrt(n))\tD_self\tD_AB / (D_self N/(N-1))\t"
              "mean reported stderr / D_self\tsd / mean stderr")
        for x_a in (0.5, 0.2):
            ds = runs(args, f"identical-x{x_a}", args.seeds, eta=0.1, x_a=x_a, sigma_b=1.0,
                      m_b=1.0, fit=(5.0, 20.0))
            pair = [d["mutual"]["pairs"]["A-B"] for d in ds]
            d_self = [x_a * d["species"]["A"]["coefficient"] +
                      (1 - x_a) * d["species"]["B"]["coefficient"] for d in ds]
            ratio = [p["coefficient"] / (s * 1000 / 999) for p, s in zip(pair, d_self)]
            errors = [p["coefficient_stderr"] / s for p, s in zip(pair, d_self)]
            m, e = mean_and_error([p["coefficient"] for p in pair])
            r, re = mean_and_error(ratio)
            print(f"{x_a}\t{m:.4f} +- {e:.4f}\t{np.mean(d_self):.4f}\t{r:.4f} +- {re:.4f}\t"
                  f"{np.mean(errors):.4f}\t{np.std(ratio, ddof=1) / np.mean(errors):.2f}")
    if "asymmetric" in parts:
        print("asymmetric: eta = 0.01, N = 1000, sigma_B = 1.4, m_B = 2, x_A = 0.5, "
              "window [40, 160]")
        ds = runs(args, "asymmetric", args.seeds, eta=0.01, x_a=0.5, sigma_b=1.4, m_b=2.0,
                  fit=(40.0, 160.0))
        pair = [d["mutual"]["pairs"]["A-B"] for d in ds]
        m, e = mean_and_error([p["coefficient"] for p in pair])
        darken, de = mean_and_error([p["darken"] for p in pair])
        print(f"D_AB = {m:.4f} +- {e:.4f} (mean reported stderr "
              f"{np.mean([p['coefficient_stderr'] for p in pair]):.4f}, sd "
              f"{np.std([p['coefficient'] for p in pair], ddof=1):.4f}); Darken x_B D_A + x_A D_B "
              f"= {darken:.4f} +- {de:.4f}")
        print(f"  / first approximation {ASYMMETRIC_FIRST}: {m / ASYMMETRIC_FIRST:.4f} +- "
              f"{e / ASYMMETRIC_FIRST:.4f}; / fourth order {ASYMMETRIC_CONVERGED}: "
              f"{m / ASYMMETRIC_CONVERGED:.4f} +- {e / ASYMMETRIC_CONVERGED:.4f}")
        for s in ("A", "B"):
            dm, dse = mean_and_error([d["species"][s]["coefficient"] for d in ds])
            print(f"  D_self,{s} = {dm:.4f} +- {dse:.4f}")


if __name__ == "__main__":
    main()
