#!/usr/bin/env python3
"""A free piston (a wall with mass M under a constant force F, docs/physics.md#walls-with-mass) on
an elastic hard-sphere (hard-disk) gas. Two checks (docs/validation.md "Walls with mass"):

1. Equation of state. Held at kT = 1 by an Andersen thermostat, the gas settles under the lid at
   the pressure P = F / A (A: the lid's area, its edge in 2D). The bulk density, from the middle
   of the density profile, gives Z = P / (rho kT), compared with the Kolafa-Labik-Malijevsky
   series (Pieprzyk et al., PCCP 21, 6886 (2019)) in 3D and Henderson's equation (Mol. Phys. 30,
   971 (1975)) in 2D, at the measured density.

2. The piston's oscillation. Settled under the thermostat, then continued from the restart
   file without it (all elastic, energy conserved), a heavy lid oscillates about its rest
   height H like a mass on the gas spring (Rüchardt, Phys. Z. 30, 58
   (1929)): omega^2 = K_S A / (M_eff H), with K_S the adiabatic bulk modulus of the gas and
   M_eff = M + m_gas / 3 (the gas column's own inertia, Rayleigh's correction for a spring's
   mass). For hard particles c_v = (D/2) k, and
       K_S = rho kT [Z + eta dZ/deta + (2/D) Z^2]
   (docs/physics.md#walls-with-mass). The frequency is measured from the autocorrelation of the
   lid's height (thermo.tsv's wall_z+_position) and compared at the measured T and density.

    python3 examples/validation/massive_piston.py build/kairos [seeds]

About 15 minutes on one core for 2 seeds.
"""

import math
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plot"))
from kairos_output import hard_sphere_z as z_spheres  # the series of Pieprzyk et al. (2019)


def z_disks(eta):
    """Henderson (1975)."""
    return (1.0 + eta * eta / 8.0) / (1.0 - eta) ** 2


def z_of(dimension, eta):
    return z_spheres(eta) if dimension == 3 else z_disks(eta)


def adiabatic_modulus(dimension, rho, kt, eta):
    """K_S = rho kT [Z + eta Z' + (2/D) Z^2] for hard particles (c_v = D k / 2)."""
    h = 1e-6
    z = z_of(dimension, eta)
    dz = (z_of(dimension, eta + h) - z_of(dimension, eta - h)) / (2.0 * h)
    return rho * kt * (z + eta * dz + (2.0 / dimension) * z * z)


def config_text(dimension, particles, eta0, mass, force, time, equilibration, seed, out,
                thermostat, interval):
    driving = """
[driving]
kind = "andersen"
rate = 0.05
temperature = 1.0
""" if thermostat else ""
    return f"""
[system]
dimension = {dimension}
particles = {particles}
packing_fraction = {eta0}
lattice = "random"
temperature = 1.0
seed = {seed}
[[boundary.wall]]
face = "{'z' if dimension == 3 else 'y'}-"
[[boundary.wall]]
face = "{'z' if dimension == 3 else 'y'}+"
mass = {mass}
force = {force}
{driving}
[run]
equilibration_time = {equilibration}
time = {time}
[output]
directory = "{out}"
progress = "never"
trajectory_interval = 0
thermo_interval = {interval}
interval_unit = "time"
profile_axis = "{'z' if dimension == 3 else 'y'}"
profile_bins = 80
"""


def read_columns(path, skip=0):
    with open(path) as f:
        lines = [line for line in f.read().splitlines()[skip:] if line]
    header = lines[0].split("\t")
    rows = [line.split("\t") for line in lines[1:]]
    return header, rows


def run(kairos, tmp, name, text):
    out = os.path.join(tmp, name)
    path = out + ".toml"
    with open(path, "w") as f:
        f.write(text.replace("{out}", out))
    subprocess.run([kairos, "run", path], check=True, stdout=subprocess.DEVNULL)
    header, rows = read_columns(os.path.join(out, "thermo.tsv"))
    production = [r for r in rows if r[0] == "production"]
    col = lambda name: np.array([float(r[header.index(name)]) for r in production])
    ph, prow = read_columns(os.path.join(out, "profile.tsv"), skip=1)
    profile = np.array([[float(v) for v in r] for r in prow])
    return col, ph, profile


def box_edge(dimension, particles, eta0):
    unit = math.pi / 6.0 if dimension == 3 else math.pi / 4.0
    return (particles * unit / eta0) ** (1.0 / dimension)


def bulk_density(col, ph, profile, lid):
    """The number density over the middle 40 % of the gas column (away from the layering at
    the floor and the lid), its standard error from the bins' scatter."""
    z = profile[:, ph.index("position")]
    rho = profile[:, ph.index("number_density")]
    height = col(lid).mean()
    middle = (z > 0.3 * height) & (z < 0.7 * height)
    return rho[middle].mean(), rho[middle].std() / math.sqrt(middle.sum())


def equation_of_state(kairos, tmp, dimension, target_eta, seed):
    # The lid starts on its face and can only compress: the gas starts a little below the
    # target (a compression leaves a density gradient, which the thermostatted gas smooths out
    # slowly, over the column's height squared: hence the long equilibration and short columns).
    # A column of disks is taller for its number (H ~ N^(1/2) against N^(1/3)): fewer disks.
    particles, eta0 = (3000 if dimension == 3 else 500), 0.85 * target_eta
    edge = box_edge(dimension, particles, eta0)
    area = edge ** (dimension - 1)
    unit = math.pi / 6.0 if dimension == 3 else math.pi / 4.0
    pressure = z_of(dimension, target_eta) * target_eta / unit  # kT = 1
    lid = "wall_%s+_position" % ("z" if dimension == 3 else "y")
    col, ph, profile = run(kairos, tmp, f"eos{dimension}_{target_eta}_{seed}",
                           config_text(dimension, particles, eta0, 100.0, pressure * area,
                                       400.0 if dimension == 3 else 2000.0, 600.0, seed, "{out}",
                                       True, 2.0))
    kt = col("temperature").mean()
    rho, rho_err = bulk_density(col, ph, profile, lid)
    eta = rho * unit
    z = pressure / (rho * kt)
    return eta, z, z * rho_err / rho, z_of(dimension, eta)


def oscillation(kairos, tmp, dimension, seed):
    """A heavy lid on a gas at eta ~ 0.3 (3D) or 0.4 (2D): settled first under an Andersen
    thermostat (which damps the lid's fall onto the gas), then continued from that run's restart
    file without it (all elastic). The measured and predicted angular frequency of the lid's
    small oscillations in the second run."""
    target = 0.3 if dimension == 3 else 0.4
    particles, eta0 = 2000, 0.85 * target
    edge = box_edge(dimension, particles, eta0)
    area = edge ** (dimension - 1)
    unit = math.pi / 6.0 if dimension == 3 else math.pi / 4.0
    pressure = z_of(dimension, target) * target / unit
    mass = 20000.0
    lid = "wall_%s+_position" % ("z" if dimension == 3 else "y")
    settled = os.path.join(tmp, f"settle{dimension}_{seed}")
    text = config_text(dimension, particles, eta0, mass, pressure * area, 3000.0, 0.0, seed,
                       settled, True, 10.0).replace("rate = 0.05", "rate = 0.1")
    with open(settled + ".toml", "w") as f:
        f.write(text)
    subprocess.run([kairos, "run", settled + ".toml"], check=True, stdout=subprocess.DEVNULL)
    out = os.path.join(tmp, f"osc{dimension}_{seed}")
    elastic = config_text(dimension, particles, eta0, mass, pressure * area, 4000.0, 0.0, seed,
                          out, False, 0.5)
    with open(out + ".toml", "w") as f:
        f.write(elastic)
    subprocess.run([kairos, "run", out + ".toml", "--restart",
                    os.path.join(settled, "restart.gsd")], check=True, stdout=subprocess.DEVNULL)
    header, rows = read_columns(os.path.join(out, "thermo.tsv"))
    col = lambda name: np.array([float(r[header.index(name)]) for r in rows])
    ph, prow = read_columns(os.path.join(out, "profile.tsv"), skip=1)
    profile = np.array([[float(v) for v in r] for r in prow])
    x = col(lid)
    kt = col("temperature").mean()
    rho, _ = bulk_density(col, ph, profile, lid)
    height = x.mean()
    eta = rho * unit
    k_s = adiabatic_modulus(dimension, rho, kt, eta)
    # The column's height as the bulk density sees it (Gibbs's dividing surfaces): the height
    # that would hold all the particles at the bulk density, N / (A rho) - the lid's mean
    # height less the layers the walls hold (and the centres' exclusion from them).
    effective = particles / (area * rho)
    predicted = math.sqrt(k_s * area / ((mass + particles / 3.0) * effective))
    # Autocorrelation of the height; successive zero crossings are half a period apart.
    d = x - x.mean()
    n = len(d)
    c = np.correlate(d, d, mode="full")[n - 1:] / np.arange(n, 0, -1)
    c /= c[0]
    dt = 0.5
    crossings = [k + c[k] / (c[k] - c[k + 1]) for k in range(len(c) // 4)
                 if c[k] > 0 >= c[k + 1] or c[k] < 0 <= c[k + 1]]
    half_periods = np.diff(crossings[:12]) * dt
    measured = math.pi / half_periods.mean()
    spread = math.pi * half_periods.std() / half_periods.mean() ** 2 / math.sqrt(len(half_periods))
    return predicted, measured, spread, eta, kt, height, x.std(), effective


def main():
    kairos = os.path.abspath(sys.argv[1])
    seeds = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    with tempfile.TemporaryDirectory() as tmp:
        print("Equation of state under a free piston (P = F/A, kT = 1 by an Andersen thermostat)")
        for dimension, targets in [(3, [0.2, 0.3, 0.4]), (2, [0.3, 0.5])]:
            for target in targets:
                for seed in range(1, seeds + 1):
                    eta, z, z_err, ref = equation_of_state(kairos, tmp, dimension, target, seed)
                    print(f"  {dimension}D seed {seed}: eta_bulk = {eta:.4f}, Z = P/(rho kT) = "
                          f"{z:.4f} +- {z_err:.4f}, reference {ref:.4f}, "
                          f"ratio {z / ref:.4f}")
        print("Oscillation of a heavy lid (M = 20000; settled under the thermostat, then "
              "without it)")
        for dimension in (3, 2):
            for seed in range(1, seeds + 1):
                predicted, measured, spread, eta, kt, height, amplitude, effective = \
                    oscillation(kairos, tmp, dimension, seed)
                print(f"  {dimension}D seed {seed}: eta = {eta:.4f}, kT = {kt:.4f}, H = "
                      f"{height:.3f} (rms {amplitude:.3f}), N/(A rho) = {effective:.3f}: omega "
                      f"measured {measured:.5f} +- {spread:.5f}, predicted {predicted:.5f}, "
                      f"ratio {measured / predicted:.4f}")


if __name__ == "__main__":
    main()
