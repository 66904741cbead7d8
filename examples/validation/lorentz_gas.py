#!/usr/bin/env python3
"""The Lorentz gas with fixed grains: tracers (diameter 0.002) among fixed obstacles (diameter 1)
at random, elastic, kT = 1. Prints the tracers' self-diffusion coefficient and the mean time
between their contacts against the Boltzmann-Lorentz low-density values (docs/physics.md#fixed-grains,
docs/validation.md "Fixed grains: the Lorentz gas"), over several seeds.

    python3 examples/validation/lorentz_gas.py build/kairos [seeds]

About 2 minutes for 4 seeds on one core.
"""

import json
import math
import os
import subprocess
import sys
import tempfile

CASES = [
    # (dimension, obstacles, tracers, box edge, time): n = 0.02 (3D), 0.005 (2D)
    (3, 80000, 4000, 158.74, 5000.0),
    (2, 1800, 2000, 600.0, 60000.0),
]


def config_text(dimension, obstacles, tracers, box, time, seed, out):
    tracer_d = 0.002
    unit = math.pi / 6.0 if dimension == 3 else math.pi / 4.0
    eta = (obstacles * unit + tracers * unit * tracer_d ** dimension) / box ** dimension
    return f"""
[system]
dimension = {dimension}
particles = {obstacles + tracers}
packing_fraction = {eta!r}
lattice = "random"
seed = {seed}
[[system.species]]
name = "obstacle"
fraction = {obstacles}
fixed = true
[[system.species]]
name = "tracer"
diameter = {tracer_d}
fraction = {tracers}
[run]
time = {time}
equilibration_time = 0
[output]
directory = "{out}"
progress = "never"
trajectory_interval = 0
thermo_interval = {time / 20}
[analysis]
msd = true
"""


def theory(dimension, n):
    a = 0.501
    if dimension == 3:
        v = math.sqrt(8.0 / math.pi)
        return v / (3.0 * n * math.pi * a * a), 1.0 / (n * math.pi * a * a * v)
    v = math.sqrt(math.pi / 2.0)
    return 3.0 * v / (16.0 * n * a), 1.0 / (n * 2.0 * a * v)


def main():
    kairos = os.path.abspath(sys.argv[1])
    seeds = int(sys.argv[2]) if len(sys.argv) > 2 else 4
    with tempfile.TemporaryDirectory() as tmp:
        for dimension, obstacles, tracers, box, time in CASES:
            n = obstacles / box ** dimension
            d_b, tau_b = theory(dimension, n)
            ratios = []
            for seed in range(1, seeds + 1):
                out = os.path.join(tmp, f"d{dimension}s{seed}")
                path = out + ".toml"
                with open(path, "w") as f:
                    f.write(config_text(dimension, obstacles, tracers, box, time, seed, out))
                subprocess.run([kairos, "run", path], check=True, stdout=subprocess.DEVNULL)
                with open(os.path.join(out, "summary.json")) as f:
                    s = json.load(f)["diffusion"]
                t = s["species"]["tracer"]
                ratios.append(t["coefficient"] / d_b)
                print(f"{dimension}D seed {seed}: D = {t['coefficient']:.4g} +- "
                      f"{t['coefficient_stderr']:.2g}, D/D_B = {ratios[-1]:.4f}, "
                      f"tau/tau_B = {s['mean_free_time'] / tau_b:.4f}")
            mean = sum(ratios) / len(ratios)
            sd = math.sqrt(sum((r - mean) ** 2 for r in ratios) / (len(ratios) - 1))
            print(f"{dimension}D: D_B = {d_b:.4g}, mean D/D_B = {mean:.4f} +- "
                  f"{sd / math.sqrt(len(ratios)):.4f} (seed scatter)")


if __name__ == "__main__":
    main()
