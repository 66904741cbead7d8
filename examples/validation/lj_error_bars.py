#!/usr/bin/python3
"""Error bars of the stepped Lennard-Jones liquid against the scatter between independent runs.

Runs examples/stepped_lj_liquid_3d.toml (500 particles, rho* = 0.8, T* = 2, Andersen) with
several seeds for several production lengths and compares, for Z and for U/N, the standard
deviation of the run means with the error bars each run reports: the blocking estimator of
summary.json (docs/physics.md, "Statistical errors") and the one Kairos used before (the
largest sqrt(var/n) over the blocking levels with >= 8 blocks), recomputed here from the
production rows of thermo.tsv. For each run, dev = (its mean - the mean of the other runs) /
sqrt(its error^2 + var(other means) / (k - 1)): about 68 % within 1 and chi2/dof = mean(dev^2)
near 1 when the error bars are right.

    /usr/bin/python3 examples/validation/lj_error_bars.py build/kairos [--only 100,500,3000,long]

prints one block per case (docs/validation.md, "Error bars of correlated series"; about 25
minutes on one core); runs already in --out are read again, not repeated.
"""

import argparse
import json
import math
import os
import subprocess

import numpy as np

EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                       "stepped_lj_liquid_3d.toml")
N = 500
# name: (description, seeds, --set overrides); the example itself has 1000 collisions per
# particle of equilibration, 3000 of production and a thermo row every 10.
CASES = {
    "100": ("100 collisions/particle of production, 100 rows", 20,
            ["run.collisions_per_particle=100", "output.thermo_interval=0"]),
    "500": ("500 collisions/particle of production, 100 rows", 20,
            ["run.collisions_per_particle=500", "output.thermo_interval=0"]),
    "3000": ("the example as it is: 3000 collisions/particle, 300 rows", 20, []),
    "long": ("3000 of equilibration, 20000 of production, 2000 rows", 12,
             ["run.equilibration_collisions_per_particle=3000",
              "run.collisions_per_particle=20000"]),
}


def old_stderr(x):
    """The estimator before issue 22: the largest sqrt(var/n) over levels with >= 8 blocks."""
    x = np.asarray(x, dtype=float)
    mean, err, level = x.mean(), 0.0, x.copy()
    while len(level) >= 8:
        n = len(level)
        err = max(err, math.sqrt(((level - mean) ** 2).sum() / (n - 1) / n))
        half = n // 2
        level = 0.5 * (level[0:2 * half:2] + level[1:2 * half:2])
    return err


def run(kairos, out, seed, sets):
    if not os.path.exists(os.path.join(out, "summary.json")):
        args = [kairos, "run", EXAMPLE, "-o", out, "--overwrite", "--set", "system.seed=%d" % seed,
                "--set", "output.trajectory=false", "--set", 'output.progress="never"']
        for s in sets:
            args += ["--set", s]
        subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    s = json.load(open(os.path.join(out, "summary.json")))
    with open(os.path.join(out, "thermo.tsv")) as f:
        rows = [l.rstrip("\n").split("\t") for l in f if not l.startswith("#")]
    header, prod = rows[0], [r for r in rows[1:] if r[0] == "production"]
    z_rows = [float(r[header.index("compressibility")]) for r in prod]
    u_rows = [float(r[header.index("potential_energy")]) / N for r in prod]
    z, st = s["compressibility"], s["stepped"]
    return {
        "rows": z["blocks"],
        "z": (z["mean"], z["stderr"], old_stderr(z_rows), z["stderr_blocks"],
              z["stderr_reliable"], z["correlation_time_rows"]),
        "u": (st["potential_energy_per_particle_mean"], st["potential_energy_per_particle_stderr"],
              old_stderr(u_rows), st["potential_energy_per_particle_stderr_blocks"],
              st["potential_energy_per_particle_stderr_reliable"], None),
    }


def deviations(means, errors):
    k, dev = len(means), []
    for i in range(k):
        others = np.delete(means, i)
        dev.append((means[i] - others.mean()) / math.sqrt(errors[i] ** 2 +
                                                          others.var(ddof=1) / (k - 1)))
    return np.array(dev)


def report(description, runs):
    k = len(runs)
    print("%s: %d runs" % (description, k))
    for q, label in (("z", "Z"), ("u", "U/N")):
        means = np.array([r[q][0] for r in runs])
        sd = means.std(ddof=1)
        print("  %s: mean %.4f, scatter between runs %.4f (+-%.0f %%)" %
              (label, means.mean(), sd, 100 / math.sqrt(2 * (k - 1))))
        for est, col in (("old", 2), ("new", 1)):
            errors = np.array([r[q][col] for r in runs])
            dev = deviations(means, errors)
            rms = math.sqrt((errors ** 2).mean())
            print("    %s: rms error %.4f = %.2f x scatter, chi2/dof %.2f, max |dev| %.1f, "
                  "within 1 error %d/%d" % (est, rms, rms / sd, (dev ** 2).mean(),
                                            np.abs(dev).max(), (np.abs(dev) <= 1).sum(), k))
        reliable = sum(1 for r in runs if r[q][4])
        blocks = sorted(r[q][3] for r in runs)
        extra = ""
        if q == "z":
            extra = ", correlation time median %.1f rows" % np.median([r[q][5] for r in runs])
        print("    new: reliable %d/%d, blocks %s%s" % (reliable, k, blocks, extra))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("kairos")
    ap.add_argument("--only", default=",".join(CASES), help="production lengths to run")
    ap.add_argument("--out", default="lj-error-bars", help="directory of the runs")
    args = ap.parse_args()
    kairos = os.path.abspath(args.kairos)
    for name in args.only.split(","):
        description, seeds, sets = CASES[name]
        runs = [run(kairos, os.path.join(args.out, "%s_%d" % (name, seed)), seed, sets)
                for seed in range(1, seeds + 1)]
        report(description, runs)


if __name__ == "__main__":
    main()
