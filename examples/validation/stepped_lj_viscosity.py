#!/usr/bin/python3
"""Shear viscosity of the stepped Lennard-Jones liquid against the number of attractive steps,
by Einstein-Helfand in NVE, beside the continuous potential's force-based MD.

docs/validation.md, "Stepped Lennard-Jones: shear viscosity by Einstein-Helfand and by NEMD".
The state of examples/stepped_lj_liquid_3d.toml (N = 500, rho* = 0.8, T* = 2, LJ truncated and
shifted at 2.5, equal-Delta-U steps, volume-averaged shell energies, hard core 0.85); only the
number of attractive steps (`potential.0.steps`) and the seed change. For each seed:

  eq   Andersen (rate 5) at T = 2 from the fcc lattice: 1.5 time units of equilibration (the
       lattice melts), then 2 of production, whose u = U/N and Z = PV/NkT are the thermostatted
       state's (summary.json);
  nve  NVE from eq's restart.gsd for PRODUCTION time units with analysis.transport (samples
       every 0.01, fit window [0.5, 2]): eta by Einstein-Helfand (`transport.shear_viscosity`),
       its Green-Kubo value at lag 2 and the Green-Kubo running integral at lags 0.5 and 1
       (green_kubo.tsv, interpolated).

Per step count the table gives the mean over the seeds with the scatter between them /
sqrt(seeds), and the r.m.s. reported stderr / sqrt(seeds) for comparison (for u and Z the
larger of the two). The continuous row comes from examples/validation/lj_viscosity_md.py (its
results directory, --md DIR; that script is not run from here: about 25 CPU minutes).

    /usr/bin/python3 examples/validation/stepped_lj_viscosity.py build/kairos [--quick]
        [--plan 10:8:40,20:4:30,40:3:30] [--md lj-viscosity-md] [-o stepped-lj-viscosity]

--plan lists steps:seeds:production time units. Runs are kept in OUT/runs/ and re-used when
their config is unchanged (cached_runs.py). CPU on the shared 2-core VM, one run at a time:
per seed 3.5 time units thermostatted and the production, ~3.8 s per NVE time unit with 10
steps, ~9 with 20, ~16 with 40; the default plan about 70 minutes.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cached_runs  # noqa: E402

N, T = 500, 2.0
RUNNING_LAGS = (0.05, 0.1, 0.2, 0.3, 0.5, 1.0, 2.0)  # the Green-Kubo running integral's table
POTENTIAL = """[[potential]]
kind = "lennard_jones"
epsilon = 1.0
sigma = 1.0
cutoff = 2.5
shifted = true
steps = {steps}
placement = "energy"
shell_energy = "volume"
"""
EQUILIBRATION = """[system]
particles = 500
packing_fraction = 0.2572434
temperature = 2.0
seed = {seed}
species = [{{name = "A", diameter = 0.85}}]

{potential}
[driving]
kind = "andersen"
rate = 5.0
temperature = 2.0

[run]
equilibration_time = 1.5
time = 2.0

[output]
trajectory = false
progress = "never"
"""
PRODUCTION = """[system]
initial_state = "{state}"
temperature = 2.0
seed = {seed}

{potential}
[run]
equilibration_time = 0.0
time = {time}

[analysis]
transport = true
transport_interval = 0.01
transport_fit_from = 0.5
transport_fit_to = 2.0

[output]
trajectory = false
progress = "never"
"""


def table(path):
    with open(path) as f:
        rows = [line.rstrip("\n").split("\t") for line in f if not line.startswith("#")]
    header = rows[0]
    return {name: np.array([float(r[k]) for r in rows[1:]]) for k, name in enumerate(header)}


def one_seed(kairos, out, steps, seed, production):
    potential = POTENTIAL.format(steps=steps)
    eq_dir = os.path.abspath(os.path.join(out, "runs", "s%d_seed%d_eq" % (steps, seed)))
    cached_runs.run_one(
        kairos, eq_dir, EQUILIBRATION.format(seed=seed, potential=potential), overwrite=True)
    nve_dir = os.path.join(out, "runs", "s%d_seed%d_nve%g" % (steps, seed, production))
    text = PRODUCTION.format(state=os.path.join(eq_dir, "restart.gsd"), seed=seed,
                             potential=potential, time=production)
    cached_runs.run_one(kairos, nve_dir, text, overwrite=True)
    eq = json.load(open(os.path.join(eq_dir, "summary.json")))
    nve = json.load(open(os.path.join(nve_dir, "summary.json")))
    shear = nve["transport"]["shear_viscosity"]
    gk = table(os.path.join(nve_dir, "green_kubo.tsv"))
    return {
        "u": eq["stepped"]["potential_energy_per_particle_mean"],
        "u_err": eq["stepped"]["potential_energy_per_particle_stderr"],
        "z": eq["compressibility"]["mean"], "z_err": eq["compressibility"]["stderr"],
        "T_eq": eq["production_temperature"],
        "T": nve["transport"]["temperature"],
        "eh": shear["value"], "eh_err": shear["stderr"],
        "gk2": shear["green_kubo"], "gk2_err": shear["green_kubo_stderr"],
        "running": np.interp(RUNNING_LAGS, gk["lag"], gk["shear_viscosity"]),
        "gk05": float(np.interp(0.5, gk["lag"], gk["shear_viscosity"])),
        "gk1": float(np.interp(1.0, gk["lag"], gk["shear_viscosity"])),
        "wall": eq["wall_seconds"] + nve["wall_seconds"],
    }


def mean_error(values):
    values = np.asarray(values, dtype=float)
    return values.mean(), values.std(ddof=1) / math.sqrt(len(values))


def md_reference(directory):
    """The continuous potential's eta (EH over [0.5, 2], GK to 0.5, 1 and 2) and GK running
    integrals at RUNNING_LAGS from
    lj_viscosity_md.py's results, or None."""
    if not directory or not os.path.isdir(directory):
        return None
    import lj_viscosity_md as md
    names = sorted(f for f in os.listdir(directory) if f.startswith("md_seed"))
    if len(names) < 2:
        return None
    eh, gk05, gk1, gk2, kts, running, length = [], [], [], [], [], [], 0.0
    for name in names:
        dt = float(name.rsplit("_dt", 1)[1][:-4])
        length += float(name.split("_t", 1)[1].split("_dt", 1)[0])
        saved = dict(np.load(os.path.join(directory, name)))
        c = md.coefficients(md.analyse(saved["stress"], saved["kT"], dt), dt)
        eh.append(c["eh"])
        gk05.append(c["gk_acf_0.5"])
        running.append([c["acf"][round(lag / dt)] for lag in RUNNING_LAGS])
        gk1.append(c["gk_acf_1"])
        gk2.append(c["gk_acf_2"])
        kts.append(float(saved["kT"]))
    return ((len(names), length / len(names)) +
            tuple(mean_error(x) for x in (kts, eh, gk05, gk1, gk2)), running)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("kairos")
    ap.add_argument("--quick", action="store_true", help="two short runs per step count")
    ap.add_argument("--plan", default="10:8:40,20:4:30,40:3:30",
                    help="steps:seeds:production time units, comma separated")
    ap.add_argument("--md", default="lj-viscosity-md",
                    help="results directory of lj_viscosity_md.py (the continuous reference)")
    ap.add_argument("-o", "--out", default="stepped-lj-viscosity")
    args = ap.parse_args()
    kairos = os.path.abspath(args.kairos)
    plan = [tuple(float(x) for x in item.split(":")) for item in args.plan.split(",")]
    if args.quick:
        plan = [(steps, 2, 5.0) for steps, _, _ in plan]
        args.out = os.path.join(args.out, "quick")
    print("| model | runs × time | T (NVE) | eta* EH [0.5, 2] | (reported stderr) | "
          "eta* GK to lag 0.5 | GK to lag 1 | GK to lag 2 | u = U/N (Andersen) | "
          "Z (Andersen) | wall s |")
    print("|---" * 11 + "|")
    ref, md_running = md_reference(args.md) or (None, None)
    running = [("continuous (MD)", md_running)] if ref is not None else []
    if ref is not None:
        print("| continuous LJTS, MD (lj_viscosity_md.py) | %d × %g | %.3f ± %.3f | "
              "**%.3f ± %.3f** | | %.3f ± %.3f | %.3f ± %.3f | %.3f ± %.3f | | | |" %
              sum(ref[2:], ref[:2]), flush=True)
    for steps, seeds, production in plan:
        steps, seeds = int(steps), int(seeds)
        rows = [one_seed(kairos, args.out, steps, seed, production)
                for seed in range(1, seeds + 1)]

        def stat(key):
            """Mean over the seeds ± the scatter / sqrt(seeds), or for u and Z the runs'
            own stderr / sqrt(seeds) when larger (a few seeds can agree by chance)."""
            mean, error = mean_error([r[key] for r in rows])
            if key in ("u", "z"):
                error = max(error, math.sqrt(np.mean([r[key + "_err"] ** 2 for r in rows])
                                             / len(rows)))
            return mean, error

        running.append(("%d steps" % steps, [r["running"] for r in rows]))
        reported = math.sqrt(np.mean([r["eh_err"] ** 2 for r in rows]) / seeds)
        print("| stepped, %d attractive steps | %d × %g | %.3f ± %.3f | **%.3f ± %.3f** | "
              "%.3f | %.3f ± %.3f | %.3f ± %.3f | %.3f ± %.3f | %.4f ± %.4f | %.3f ± %.3f | "
              "%.0f |" % ((steps, seeds, production) + stat("T") + stat("eh") + (reported,) +
                          stat("gk05") + stat("gk1") + stat("gk2") + stat("u") + stat("z") +
                          (sum(r["wall"] for r in rows),)), flush=True)
        for seed, r in enumerate(rows, start=1):
            print("|   seed %d | | %.3f | %.3f ± %.3f | | %.3f | %.3f | %.3f ± %.3f | %.4f | %.3f | "
                  "%.0f |" % (seed, r["T"], r["eh"], r["eh_err"], r["gk05"], r["gk1"], r["gk2"],
                              r["gk2_err"], r["u"], r["z"], r["wall"]))

    # The stress autocorrelation's running integral at short lags, where it is least noisy.
    print()
    print("| Green-Kubo running integral at lag | " +
          " | ".join(name for name, _ in running) + " |")
    print("|---" * (len(running) + 1) + "|")
    for k, lag in enumerate(RUNNING_LAGS):
        cells = ["%.3f ± %.3f" % mean_error([r[k] for r in rows]) for _, rows in running]
        print("| %g | %s |" % (lag, " | ".join(cells)))


if __name__ == "__main__":
    main()
