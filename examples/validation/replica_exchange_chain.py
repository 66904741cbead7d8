#!/usr/bin/env python3
"""Replica exchange of a square-well homopolymer against independent runs (docs/validation.md
"Replica exchange").

One chain of B beads (hard spheres of diameter 1, consecutive beads tethered within 1.25, every
pair that is not bonded attracting through a square well of range 1.5 and depth 1), alone in a
box far wider than it. The same chain is simulated

1. by `kairos replica-exchange`: K replicas on a geometric ladder of temperatures, exchange
   rounds every time unit, each replica held at its rung's temperature by the Andersen
   thermostat;
2. by K independent `kairos run`s (through `kairos sweep`), one per temperature of the ladder,
   each thermostatted for as long a time as the ensemble ran, sampling the potential energy
   every time unit (thermo.tsv).

At every temperature the mean energy <U> and the heat capacity C = D B / 2 + var(U) / T^2 of the
two must agree within their errors: the exchange run's own (docs/replica_exchange.md "Results"),
and for the independent runs a jackknife over 20 blocks of their rows.
The acceptance of each pair of rungs is printed beside the one the two rungs' energy
distributions predict (summary.json's predicted_rate).

    python3 examples/validation/replica_exchange_chain.py build/kairos [beads] [rounds]

About 4 minutes on two cores for 32 beads and 20 000 rounds.
"""

import json
import os
import subprocess
import sys
import tempfile

import numpy as np

LADDER = [0.5, 0.6, 0.72, 0.86, 1.04, 1.25, 1.5, 1.8, 2.2]


def config_text(beads):
    return """[system]
particles = {n}
chain_length = {n}
chain_spacing = 1.1
packing_fraction = 0.0002
seed = 11

[[potential]]
kind = "square_well"
lambda = 1.5
depth = 1.0

[[bond]]
type = "backbone"
kind = "tether"
max_length = 1.25

[driving]
kind = "andersen"
rate = 1.0

[output]
progress = "never"
""".format(n=beads)


def jackknife(samples, statistic, blocks=20):
    samples = np.asarray(samples)
    size = len(samples) // blocks
    value = statistic(samples)
    rest = [statistic(np.delete(samples[:blocks * size], slice(b * size, (b + 1) * size)))
            for b in range(blocks)]
    return value, np.sqrt((blocks - 1) / blocks * np.sum((np.array(rest) - np.mean(rest)) ** 2))


def main():
    kairos = os.path.abspath(sys.argv[1])
    beads = int(sys.argv[2]) if len(sys.argv) > 2 else 32
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 20000
    equilibration = rounds // 10
    work = tempfile.mkdtemp(prefix="kairos-replica-validation-")
    config = os.path.join(work, "chain.toml")
    with open(config, "w") as f:
        f.write(config_text(beads))
    ladder = ",".join(repr(t) for t in LADDER)
    subprocess.run([kairos, "replica-exchange", config, "-o", os.path.join(work, "exchange"),
                    "--temperatures", ladder, "--interval", "1", "--exchanges", str(rounds),
                    "--equilibration", str(equilibration)], check=True)
    with open(os.path.join(work, "exchange", "summary.json")) as f:
        summary = json.load(f)
    subprocess.run([kairos, "sweep", config, "-o", os.path.join(work, "independent"),
                    "--vary", "driving.temperature=" + ladder,
                    "--set", "run.time=%d" % (rounds - equilibration),
                    "--set", "run.equilibration_time=%d" % equilibration,
                    "--set", "output.thermo_interval=1", "--set", 'output.interval_unit="time"',
                    "--set", "output.trajectory=false"], check=True,
                   stdout=subprocess.DEVNULL)
    with open(os.path.join(work, "independent", "results.json")) as f:
        runs = json.load(f)["runs"]
    kinetic = 3 * beads / 2
    worst = 0.0
    print("\n    T   <U> exchange    <U> independent   dev   C exchange     C independent   dev")
    for rung, run in zip(summary["rungs"], runs):
        t = rung["temperature"]
        rows = np.genfromtxt(os.path.join(work, "independent", run["directory"], "thermo.tsv"),
                             delimiter="\t", names=True, dtype=None, encoding=None)
        u = np.asarray(rows["potential_energy"][rows["phase"] == "production"], dtype=float)
        u_mean, u_error = jackknife(u, np.mean)
        c, c_error = jackknife(u, lambda x: kinetic + np.var(x) / t ** 2)
        ue, ce = rung["potential_energy"], rung["heat_capacity"]
        du = (ue["mean"] - u_mean) / np.hypot(ue["stderr"], u_error)
        dc = (ce["mean"] - c) / np.hypot(ce["stderr"], c_error)
        worst = max(worst, abs(du), abs(dc))
        print("%5.2f  %7.3f ± %.3f  %7.3f ± %.3f  %+5.1fσ  %6.2f ± %.2f  %6.2f ± %.2f  %+5.1fσ"
              % (t, ue["mean"], ue["stderr"], u_mean, u_error, du, ce["mean"], ce["stderr"], c,
                 c_error, dc))
    print("\n pair        acceptance  predicted")
    for pair in summary["pairs"]:
        print(" %4.2f-%4.2f   %.3f       %.3f" % (pair["temperatures"][0], pair["temperatures"][1],
                                              pair["rate"], pair["predicted_rate"]))
    print("\nround trips: %d; largest deviation %.1f sigma; files in %s"
          % (summary["replica_exchange"]["round_trips"], worst, work))
    return 0 if worst < 4.0 else 1


if __name__ == "__main__":
    sys.exit(main())
