#!/usr/bin/python3
"""Stepped Lennard-Jones against the continuous one at liquid density.

Reference: our own force-based molecular dynamics of the same potential (Lennard-Jones cut at
2.5 sigma and shifted to zero there), velocity Verlet (dt = 0.001) with an Andersen thermostat, written here
in numpy (all pairs, minimum image), so that the comparison is between the same model at the
same state point and the same N. Kairos then runs the stepped versions (equal-energy steps,
volume-averaged shell energies, hard core at 0.8 sigma) for several numbers of attractive
steps, under the same Andersen thermostat. Both report the configurational energy per particle
u = U/N and the compressibility factor Z = PV/(NkT).

    /usr/bin/python3 examples/validation/stepped_lj_convergence.py build/kairos [--quick]

prints a Markdown table (docs/validation.md, "Stepped Lennard-Jones at liquid density").
"""

import argparse
import json
import math
import os
import subprocess
import tempfile

import numpy as np

RHO, T, N, RC = 0.8, 2.0, 500, 2.5


def lj_md(steps, dt=0.001, rate=2.0, seed=2, equilibrate=2000):
    """Continuous truncated-shifted LJ: returns (u, u_err, z, z_err) from block averages."""
    rng = np.random.default_rng(seed)
    n_side = math.ceil(N ** (1 / 3))
    box = (N / RHO) ** (1 / 3)
    grid = np.array([(i, j, k) for i in range(n_side) for j in range(n_side)
                     for k in range(n_side)][:N], dtype=float)
    x = (grid + 0.5) * box / n_side
    v = rng.normal(scale=math.sqrt(T), size=(N, 3))
    v -= v.mean(axis=0)
    shift = 4 * (RC ** -12 - RC ** -6)
    iu = np.triu_indices(N, 1)

    def forces(x):
        d = x[:, None, :] - x[None, :, :]  # noqa: the diagonal (inf) is masked below
        d -= box * np.round(d / box)
        r2 = (d ** 2).sum(axis=2)
        np.fill_diagonal(r2, np.inf)
        inside = r2 < RC * RC
        inv6 = np.where(inside, r2 ** -3, 0.0)
        u = 0.5 * np.sum(np.where(inside, 4 * (inv6 * inv6 - inv6) - shift, 0.0))
        f_over_r2 = np.where(inside, (48 * inv6 * inv6 - 24 * inv6) / r2, 0.0)
        f = (f_over_r2[:, :, None] * d).sum(axis=1)
        virial = 0.5 * np.sum(np.where(inside, f_over_r2 * r2, 0.0))  # sum over pairs of r . F
        return f, u, virial

    f, u, w = forces(x)
    samples_u, samples_p = [], []
    volume = box ** 3
    for step in range(equilibrate + steps):
        v += 0.5 * dt * f
        x += dt * v
        x %= box
        f, u, w = forces(x)
        v += 0.5 * dt * f
        kicked = rng.random(N) < rate * dt  # Andersen: new Maxwell velocities
        v[kicked] = rng.normal(scale=math.sqrt(T), size=(kicked.sum(), 3))
        if step >= equilibrate and step % 10 == 0:
            kt = (v ** 2).sum() / (3 * N)
            samples_u.append(u / N)
            samples_p.append((N * kt + w / 3) / volume)
    u, du = blocked(np.array(samples_u))
    p, dp = blocked(np.array(samples_p))
    return u, du, p / (RHO * T), dp / (RHO * T)


def blocked(a, blocks=20):
    m = len(a) // blocks * blocks
    b = a[:m].reshape(blocks, -1).mean(axis=1)
    return b.mean(), b.std(ddof=1) / math.sqrt(blocks)


def kairos_run(kairos, steps, production, workdir):
    core = 0.8
    text = f"""
[system]
particles = {N}
packing_fraction = {RHO * math.pi / 6 * core ** 3}
lattice = "fcc"
temperature = {T}
seed = 3
[[system.species]]
name = "A"
diameter = {core}
[[potential]]
kind = "lennard_jones"
epsilon = 1.0
sigma = 1.0
cutoff = {RC}
shifted = true
steps = {steps}
placement = "energy"
shell_energy = "volume"
[driving]
kind = "andersen"
rate = 2.0
temperature = {T}
[run]
equilibration_collisions_per_particle = {production}
collisions_per_particle = {production}
[output]
directory = "{workdir}/lj{steps}"
trajectory = false
progress = "never"
"""
    path = os.path.join(workdir, f"lj{steps}.toml")
    with open(path, "w") as f:
        f.write(text)
    subprocess.run([kairos, "run", path], check=True, capture_output=True)
    with open(os.path.join(workdir, f"lj{steps}", "summary.json")) as f:
        s = json.load(f)
    st = s["stepped"]
    z = s["compressibility"]
    # Z at the bath temperature (as the MD's): the virial part W / (3 N k T t) is rescaled from
    # the measured mean temperature, whose fluctuations (N = 500) would otherwise add noise.
    t_run = s["production_temperature"]
    scale = t_run / T
    return (st["potential_energy_per_particle_mean"], st["potential_energy_per_particle_stderr"],
            1 + (z["mean"] - 1) * scale, z["stderr"] * scale, t_run, s["events_per_second"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("kairos")
    ap.add_argument("--quick", action="store_true", help="short runs (a smoke test)")
    ap.add_argument("--md", help="skip the MD run: its u,du,Z,dZ from an earlier one")
    ap.add_argument("--steps", default="5,10,20,40", help="attractive steps to run")
    args = ap.parse_args()
    # Runs of about 25 time units after as many of equilibration (the lattice melts and the
    # thermostat brings the heat back; pair events per particle per unit time grow with the
    # number of steps: ~80 per attractive step here).
    md_steps = 1000 if args.quick else 6000
    if args.md:
        u, du, z, dz = (float(x) for x in args.md.split(","))
    else:
        u, du, z, dz = lj_md(md_steps, equilibrate=500 if args.quick else 2000)
    print(f"rho = {RHO}, T = {T}, N = {N}, LJ cut and shifted at {RC}")
    print("| model | u = U/N | Z = PV/NkT | T measured | events/s |")
    print("|---|---|---|---|---|")
    print(f"| continuous LJ (MD, dt = 0.001) | {u:.4f} ± {du:.4f} | {z:.3f} ± {dz:.3f} | "
          f"{T} (set) | |", flush=True)
    with tempfile.TemporaryDirectory() as work:
        for steps in (int(k) for k in args.steps.split(",")):
            production = (60 if args.quick else 2000) * steps
            su, sdu, sz, sdz, st, speed = kairos_run(args.kairos, steps, production, work)
            print(f"| stepped, {steps} attractive steps | {su:.4f} ± {sdu:.4f} | "
                  f"{sz:.3f} ± {sdz:.3f} | {st:.4f} | {speed:.3g} |", flush=True)


if __name__ == "__main__":
    main()
