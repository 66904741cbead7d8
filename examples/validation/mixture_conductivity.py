#!/usr/bin/python3
"""The thermal conductivity of binary hard-sphere mixtures (analysis.transport: the conductivity
at zero diffusion flux, docs/physics.md#thermal-conductivity-of-a-mixture) against the dilute
gas's kinetic theory (docs/validation.md, "Thermal conductivity of a mixture").

Every number is Kairos's own summary.json `transport.thermal_conductivity` (value, epochs'
error, interdiffusion.energy_per_mass and removed_fraction); sigma_A = m_A = kT = 1.

  identical   two labels on identical spheres, x_A = 0.5: the conductivity must be the one
              species' (interdiffusion carries no energy: removed_fraction ~ 0), compared with
              Enskog's pure-gas value (docs/physics.md: collisional transfer included).
  asymmetric  sigma_B = 1.4, m_B = 2, x_A = 0.5 (the mutual-diffusion validation's mixture):
              compared with the linearised Boltzmann equation to the fourth Sonine order with
              the BMCSL contact values (examples/validation/mixture_conductivity_sonine.py,
              --eta ETA --diameters 1,1.4 --masses 1,2 --fractions 0.5,0.5), which leaves out
              the collisional transfer: estimated by the one-component Enskog factor
              1 + 1.2 y + 0.7574 y^2 at the mixture's y = (2 pi / 3) n sum x_i x_j sigma_ij^3
              chi_ij (1.0237 at eta = 0.005), the mixture's own being uncertain by a fraction of
              it: tolerance 1 % + 3 standard errors. The same script gives beta (the energy per
              mass interdiffusion carries, 0.9792 at eta = 0.005) and the fraction of the energy
              moment's slope it removes (0.1261): printed beside the measured ones.

Both at packing fraction --eta (default 0.005: the mean free path about half the box), N = 1000,
10 000 collisions per particle, the automatic fit window (10 to 40 mean free times). A
collective coefficient's error depends on the number of independent windows, not on N: small
systems are the cheap way to a small error, as long as the mean free path stays below the box
(about 40 s per run on the 2-core VM).

    /usr/bin/python3 examples/validation/mixture_conductivity.py build/kairos
        [-o mixture-conductivity] [--only identical,asymmetric] [--seeds 8] [--eta 0.005]
        [--reference LAMBDA]

Runs are kept in OUTPUT/runs/ and re-used when their config is unchanged.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cached_runs  # noqa: E402
from mixture_diffusion_sonine import contact_values  # noqa: E402


def config_text(outdir, seed, eta, sigma_b, m_b, particles, collisions):
    return f"""[system]
dimension = 3
particles = {particles}
packing_fraction = {eta}
lattice = "random"
seed = {seed}

[[system.species]]
name = "A"
fraction = 0.5

[[system.species]]
name = "B"
diameter = {sigma_b}
mass = {m_b}
fraction = 0.5

[run]
equilibration_collisions_per_particle = 20
collisions_per_particle = {collisions}

[output]
directory = "{outdir}"
trajectory = false
progress = "never"

[analysis]
transport = true
"""


def enskog_pure(eta):
    """Enskog's hard-sphere conductivity (docs/physics.md), sigma = m = kT = 1."""
    chi = (1 - eta / 2) / (1 - eta) ** 3
    b_rho = 4 * eta
    y = b_rho * chi
    lambda0 = 1.025 * 75 / 64 / math.sqrt(math.pi)
    return lambda0 * b_rho * (1 / y + 1.2 + 0.7574 * y), 1.2 * y + 0.7574 * y * y


def mixture_collisional_factor(eta, x, sigma):
    """The one-component Enskog collisional-transfer factor at the mixture's y."""
    n = eta / (math.pi / 6 * sum(xi * s ** 3 for xi, s in zip(x, sigma)))
    chi = contact_values(n, x, sigma)
    y = 2 * math.pi / 3 * n * sum(x[i] * x[j] * ((sigma[i] + sigma[j]) / 2) ** 3 * chi[i, j]
                                  for i in range(2) for j in range(2))
    return 1 + 1.2 * y + 0.7574 * y * y


def runs(args, name, **case):
    out = []
    for seed in range(1, args.seeds + 1):
        outdir = os.path.join(args.output, "runs", f"{name}-eta{args.eta}-s{seed}")
        text = config_text(outdir, seed, args.eta, particles=args.particles,
                           collisions=args.collisions, **case)
        cached_runs.run_one(args.kairos, outdir, text, overwrite=True)
        out.append(json.load(open(os.path.join(outdir, "summary.json")))["transport"])
    return out


def mean_and_error(values):
    return float(np.mean(values)), float(np.std(values, ddof=1) / math.sqrt(len(values)))


def report(name, ts, reference, systematic):
    c = [t["thermal_conductivity"] for t in ts]
    values = [x["value"] for x in c]
    m, e = mean_and_error(values)
    reported = float(np.mean([x["stderr"] for x in c]))
    removed = [x["interdiffusion"]["removed_fraction"] for x in c]
    beta = [x["interdiffusion"]["energy_per_mass"]["A"] for x in c]
    gk, gke = mean_and_error([x["green_kubo"] for x in c])
    ratio, ratio_err = m / reference, e / reference
    tolerance = systematic + 3 * ratio_err
    print(f"{name}: lambda = {m:.5g} +- {e:.3g} (seed sd {np.std(values, ddof=1):.3g}, mean "
          f"reported stderr {reported:.3g}); Green-Kubo {gk:.5g} +- {gke:.3g}")
    print(f"  removed_fraction {np.mean(removed):.4f} +- {np.std(removed, ddof=1):.4f} (sd); "
          f"energy_per_mass A {np.mean(beta):.4f} +- "
          f"{np.std(beta, ddof=1) / math.sqrt(len(beta)):.4f}")
    print(f"  / reference {reference:.5g}: {ratio:.4f} +- {ratio_err:.4f}  "
          f"(tolerance {systematic:.3f} + 3 sigma = {tolerance:.4f}: "
          f"{'passes' if abs(ratio - 1) <= tolerance else 'FAILS'})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("kairos")
    ap.add_argument("-o", "--output", default="mixture-conductivity")
    ap.add_argument("--only", default="identical,asymmetric")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--eta", type=float, default=0.005)
    ap.add_argument("--particles", type=int, default=1000)
    ap.add_argument("--collisions", type=float, default=10000)
    ap.add_argument("--reference", type=float, default=None,
                    help="the asymmetric mixture's Boltzmann value at --eta "
                         "(mixture_conductivity_sonine.py, fourth order)")
    args = ap.parse_args()
    parts = args.only.split(",")
    pure, _ = enskog_pure(args.eta)
    if "identical" in parts:
        # Enskog's pure-gas value already holds the collisional transfer; its own error at low
        # density is the Sonine truncation (< 0.5 %).
        report(f"identical, eta = {args.eta}", runs(args, "identical", sigma_b=1.0, m_b=1.0),
               pure, 0.01)
    if "asymmetric" in parts:
        ts = runs(args, "asymmetric", sigma_b=1.4, m_b=2.0)
        if args.reference is None:
            print("asymmetric: pass --reference (mixture_conductivity_sonine.py) to compare")
            args.reference = float("nan")
        factor = mixture_collisional_factor(args.eta, [0.5, 0.5], [1.0, 1.4])
        print(f"asymmetric: Boltzmann {args.reference} x Enskog's collisional factor "
              f"{factor:.5f} = {args.reference * factor:.5g}")
        report(f"asymmetric, eta = {args.eta}", ts, args.reference * factor, 0.01)


if __name__ == "__main__":
    main()
