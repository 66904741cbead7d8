#!/usr/bin/python3
"""NEMD shear viscosity of the stepped Lennard-Jones liquid against the Andersen thermostat rate.

docs/validation.md, "Stepped Lennard-Jones: shear viscosity by Einstein-Helfand and by NEMD",
Route 2. Each run is examples/stepped_lj_liquid_3d.toml (N = 500, rho* = 0.8, T* = 2, 10 steps)
under Lees-Edwards shear, with only these keys overridden (the Route 2 commands plus the
thermostat rate and the seed):

  boundary.shear_rate = G, driving.rate = R, system.seed = S,
  run.equilibration_collisions_per_particle = 0, run.collisions_per_particle = 0,
  run.equilibration_time = E, run.time = TIME, output.thermo_interval = 0.1,
  output.trajectory_interval = 0, output.progress = "never"

E is max(2, 4 / R) by default (--equilibration auto): from the lattice the temperature
approaches T* = 2 at a rate of about R (Andersen) x the kinetic share of the heat capacity, so
at R = 0.5 the Route 2 value E = 2 starts production ~0.4 below T*; 4 / R leaves ~1 % of the
initial deviation. A number gives the same E for every rate.

Per run: eta = summary.json's shear.viscosity (-P_xy / shear rate) with its blocking error
shear.viscosity_stderr, the mean temperature of the production rows of thermo.tsv, and the
child's CPU time. Per (shear rate, thermostat rate, run time): the mean eta over the seeds,
its error from the seeds' scatter / sqrt(n), the r.m.s. reported error of one run and the
reported error of the mean (sqrt(sum err^2) / n), the mean production temperature, the CPU.
Where a thermostat rate has two shear rates, eta is extrapolated to zero shear rate linearly
in the shear rate and in its square (two points: no check of the form).

    /usr/bin/python3 examples/validation/stepped_lj_nemd_thermostat.py /tmp/kairos \\
        --out nemd-thermostat --shear-rates 0.1,0.25 --rates 0.5,1,2,5 --seeds 1-3 \\
        --time 0.1:30,0.25:15

Runs go to OUT/runs/g<G>_r<R>_s<S>_t<TIME>/ and are skipped when their summary.json exists and
their recorded command (run.json) is the same. Seeds loop outside the thermostat rates, so a
stopped scan has every rate at the first seeds. One run at a time (nice -n 10). CPU on the
shared 2-core VM: 6.6-6.9 s per simulated time unit (equilibration included) at every R and
shear rate: ~250 s per run at 0.1 (TIME 30), 115-160 s at 0.25 (TIME 15); the default grid
(24 runs) took 72 CPU minutes.
The tables (TSV and markdown) are written from every finished run under OUT/runs/.
"""

import argparse
import json
import math
import os
import resource
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stepped_lj_viscosity import mean_error  # noqa: E402

CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                      "stepped_lj_liquid_3d.toml")


def number_list(text):
    """'0.5,1,2' -> [0.5, 1.0, 2.0]."""
    return [float(x) for x in text.split(",") if x]


def seed_list(text):
    """'1-3,7' -> [1, 2, 3, 7]."""
    seeds = []
    for item in text.split(","):
        if "-" in item:
            a, b = item.split("-")
            seeds += list(range(int(a), int(b) + 1))
        elif item:
            seeds.append(int(item))
    return seeds


def run_times(text):
    """'30' (every shear rate) or '0.1:30,0.25:15' -> function of the shear rate."""
    if ":" not in text:
        return lambda g: float(text)
    table_ = dict((float(g), float(t)) for g, t in (item.split(":") for item in text.split(",")))
    return lambda g: table_[g] if g in table_ else 15.0


def run_dir(out, g, rate, seed, time):
    return os.path.join(out, "runs", "g%g_r%g_s%d_t%g" % (g, rate, seed, time))


def one_run(kairos, out, g, rate, seed, time, equilibration):
    """Runs one NEMD case unless finished with the same command; returns its directory."""
    outdir = run_dir(out, g, rate, seed, time)
    sets = {"boundary.shear_rate": g, "driving.rate": rate, "system.seed": seed,
            "run.equilibration_collisions_per_particle": 0, "run.collisions_per_particle": 0,
            "run.equilibration_time": equilibration, "run.time": time,
            "output.thermo_interval": 0.1, "output.trajectory_interval": 0,
            "output.progress": '"never"'}
    command = ["nice", "-n", "10", kairos, "run", os.path.abspath(CONFIG), "-o", outdir]
    for key, value in sets.items():
        command += ["--set", "%s=%s" % (key, value if isinstance(value, str) else repr(value))]
    meta = os.path.join(outdir, "run.json")
    if os.path.exists(os.path.join(outdir, "summary.json")) and os.path.exists(meta):
        if json.load(open(meta))["command"] == command:
            return outdir
    os.makedirs(outdir, exist_ok=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    result = subprocess.run(command + ["--overwrite"], capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if result.returncode != 0:
        raise RuntimeError("kairos failed in %s:\n%s" % (outdir, result.stderr[-3000:]))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    json.dump({"command": command, "shear_rate": g, "rate": rate, "seed": seed, "time": time,
               "equilibration_time": equilibration, "cpu_seconds": cpu},
              open(meta, "w"), indent=1)
    return outdir


def read_run(outdir):
    meta = json.load(open(os.path.join(outdir, "run.json")))
    summary = json.load(open(os.path.join(outdir, "summary.json")))
    thermo = table_with_phase(os.path.join(outdir, "thermo.tsv"))
    shear = summary["shear"]
    return dict(meta, eta=shear["viscosity"], eta_err=shear["viscosity_stderr"],
                reliable=shear["shear_stress_stderr_reliable"],
                T=float(np.mean(thermo["temperature"][thermo["production"]])),
                T_start=float(thermo["temperature"][thermo["production"]][0]))


def table_with_phase(path):
    """thermo.tsv's numeric columns, and 'production': the mask of its production rows."""
    with open(path) as f:
        rows = [line.rstrip("\n").split("\t") for line in f if not line.startswith("#")]
    header = rows[0]
    columns = {name: np.array([float(r[k]) for r in rows[1:]])
               for k, name in enumerate(header) if name != "phase"}
    columns["production"] = np.array([r[header.index("phase")] == "production" for r in rows[1:]])
    return columns


def extrapolate(points, power):
    """Straight line through two (g, eta, err) points in g**power, its value at g = 0."""
    (g1, e1, s1), (g2, e2, s2) = points
    x1, x2 = g1 ** power, g2 ** power
    w1, w2 = x2 / (x2 - x1), -x1 / (x2 - x1)
    return w1 * e1 + w2 * e2, math.hypot(w1 * s1, w2 * s2)


def summarize(out):
    runs_dir = os.path.join(out, "runs")
    runs = [read_run(os.path.join(runs_dir, d)) for d in sorted(os.listdir(runs_dir))
            if os.path.exists(os.path.join(runs_dir, d, "summary.json"))
            and os.path.exists(os.path.join(runs_dir, d, "run.json"))]
    with open(os.path.join(out, "runs.tsv"), "w") as f:
        f.write("shear_rate\trate\tseed\ttime\tequilibration_time\teta\teta_err\treliable\t"
                "T_production\tT_production_start\tcpu_seconds\n")
        for r in sorted(runs, key=lambda r: (r["shear_rate"], r["rate"], r["time"], r["seed"])):
            f.write("%g\t%g\t%d\t%g\t%g\t%.4f\t%.4f\t%s\t%.4f\t%.4f\t%.1f\n" % (
                r["shear_rate"], r["rate"], r["seed"], r["time"], r["equilibration_time"],
                r["eta"], r["eta_err"], r["reliable"], r["T"], r["T_start"], r["cpu_seconds"]))
    groups = {}
    for r in runs:
        groups.setdefault((r["shear_rate"], r["rate"], r["time"]), []).append(r)
    rows = []
    for (g, rate, time), rs in sorted(groups.items()):
        etas = [r["eta"] for r in rs]
        mean = float(np.mean(etas))
        scatter = mean_error(etas)[1] if len(rs) > 1 else float("nan")
        errs = np.array([r["eta_err"] for r in rs])
        rows.append({"shear_rate": g, "rate": rate, "time": time, "n": len(rs),
                     "seeds": ",".join(str(r["seed"]) for r in sorted(rs, key=lambda r: r["seed"])),
                     "eta": mean, "scatter_err": scatter,
                     "reported_rms": float(np.sqrt(np.mean(errs ** 2))),
                     "reported_err": float(np.sqrt(np.sum(errs ** 2)) / len(rs)),
                     "T": float(np.mean([r["T"] for r in rs])),
                     "cpu": float(sum(r["cpu_seconds"] for r in rs))})
    names = ["shear_rate", "rate", "time", "n", "seeds", "eta", "scatter_err", "reported_rms",
             "reported_err", "T", "cpu"]
    with open(os.path.join(out, "nemd_thermostat.tsv"), "w") as f:
        f.write("\t".join(names) + "\n")
        for row in rows:
            f.write("\t".join(("%.4f" % row[k]) if isinstance(row[k], float) else str(row[k])
                              for k in names) + "\n")
    md = ["| γ̇ | Andersen rate | run time | seeds | η* mean | ± scatter/√n | reported "
          "(r.m.s. per run) | reported of the mean | T (production) | CPU s |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        md.append("| %g | %g | %g | %d (%s) | **%.3f** | %.3f | %.3f | %.3f | %.3f | %.0f |" % (
            row["shear_rate"], row["rate"], row["time"], row["n"], row["seeds"], row["eta"],
            row["scatter_err"], row["reported_rms"], row["reported_err"], row["T"], row["cpu"]))
    by_rate = {}
    for row in rows:
        by_rate.setdefault(row["rate"], []).append(row)
    extra = []
    for rate, rs in sorted(by_rate.items()):
        if len(rs) != 2 or min(r["n"] for r in rs) < 2:
            continue
        points = [(r["shear_rate"], r["eta"], r["scatter_err"]) for r in rs]
        extra.append("| %g | %.3f ± %.3f | %.3f ± %.3f |" % (
            (rate,) + extrapolate(points, 1) + extrapolate(points, 2)))
    if extra:
        md += ["", "Zero shear rate, through the two shear rates (errors: seed scatter):", "",
               "| Andersen rate | η₀ linear in γ̇ | η₀ linear in γ̇² |", "|---|---|---|"] + extra
    md += ["", "CPU in total: %.0f s (%d runs)." % (sum(r["cpu_seconds"] for r in runs),
                                                   len(runs))]
    text = "\n".join(md) + "\n"
    with open(os.path.join(out, "nemd_thermostat.md"), "w") as f:
        f.write(text)
    print(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("kairos", help="the kairos binary")
    ap.add_argument("-o", "--out", default="nemd-thermostat")
    ap.add_argument("--rates", default="0.5,1,2,5", help="Andersen rates (driving.rate)")
    ap.add_argument("--shear-rates", default="0.1,0.25", help="boundary.shear_rate values")
    ap.add_argument("--seeds", default="1-3", help="system.seed values, e.g. 1-3,7")
    ap.add_argument("--time", default="0.1:30,0.25:15",
                    help="production time: one number, or shear_rate:time pairs (others 15)")
    ap.add_argument("--equilibration", default="auto",
                    help="run.equilibration_time, or auto: max(2, 4 / rate)")
    ap.add_argument("--summary-only", action="store_true", help="tables of finished runs only")
    args = ap.parse_args()
    kairos = os.path.abspath(args.kairos)
    time_of = run_times(args.time)
    if not args.summary_only:
        for g in number_list(args.shear_rates):
            for seed in seed_list(args.seeds):
                for rate in number_list(args.rates):
                    eq = (max(2.0, 4.0 / rate) if args.equilibration == "auto"
                          else float(args.equilibration))
                    outdir = one_run(kairos, args.out, g, rate, seed, time_of(g), eq)
                    r = read_run(outdir)
                    print("g %g rate %g seed %d: eta %.3f ± %.3f, T %.3f, cpu %.0f s" % (
                        g, rate, seed, r["eta"], r["eta_err"], r["T"], r["cpu_seconds"]),
                        flush=True)
    summarize(args.out)


if __name__ == "__main__":
    main()
