#!/usr/bin/env python3
"""Validation of [compress] (Lubachevsky-Stillinger growth): jamming densities, contact
numbers, the equation of state on slow growth and the generated size distributions
(docs/validation.md, "Compression and jamming").

Every run is `kairos run EXAMPLE.toml -o DIR --set ...` (the command is printed with each
row); a finished run whose command has not changed is re-read instead of repeated, so the
script can be re-run to redo only the tables.

  examples/validation/compression_jamming.py [--kairos build/kairos] [--out DIR]
        [--parts a,b,c,d] [--seeds 2] [--rates 0.1,0.03,0.01]

  a  3D monodisperse, N = 2000, random start at 0.3, grown until jammed, for each growth rate
     and seed: phi_J, free-volume phi_J, backbone z (isostatic 6), rattlers, collisions, time
     (MRJ 0.645 +- 0.005: Skoge et al. PRE 74, 041127 (2006) Table I; 2-3 % rattlers: Donev,
     Torquato, Stillinger PRE 71, 011105 (2005)).
  b  2D bidisperse 50:50, diameters 1 : 1.4, N = 2000, random start at 0.5, jammed
     (phi_J ~ 0.84: Donev, Stillinger, Torquato PRL 96, 225502 (2006); 0.842 O'Hern et al.
     PRE 68, 011306 (2003); backbone z = 4).
  c  3D, N = 2000, slow growth 0.30 -> 0.50 at growth_rate 1e-3, thermostat every collision
     per particle: Z of compress.tsv near 0.35, 0.40, 0.45, 0.49 against the
     Kolafa-Labik-Malijevsky series.
  d  size distributions at N = 4000, p = 0.1: log-normal grown 0.3 -> 0.58 (a glass), uniform
     and gaussian (a plain run): Kolmogorov-Smirnov test of the diameters.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EXAMPLES = os.path.join(ROOT, "examples")


def run(kairos, outdir, example, sets):
    """Runs `kairos run examples/EXAMPLE -o outdir --set k=v ...` unless outdir holds a finished
    run of the same command; returns (summary dict, wall seconds of this call, command text)."""
    cmd = [kairos, "run", os.path.join(EXAMPLES, example), "-o", outdir, "--overwrite"]
    for k, v in sets:
        cmd += ["--set", "%s=%s" % (k, v)]
    cmd += ["--set", "output.progress=never"]
    shown = "kairos run examples/%s -o %s %s" % (
        example, os.path.basename(outdir), " ".join("--set %s=%s" % kv for kv in sets))
    stamp = os.path.join(outdir, "command.txt")
    summary = os.path.join(outdir, "summary.json")
    text = " ".join(cmd[1:])
    if os.path.exists(summary) and os.path.exists(stamp) and open(stamp).read() == text:
        return json.load(open(summary)), 0.0, shown
    os.makedirs(outdir, exist_ok=True)
    t = time.time()
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit("kairos failed in %s:\n%s" % (outdir, result.stderr[-3000:]))
    with open(stamp, "w") as f:
        f.write(text)
    return json.load(open(summary)), time.time() - t, shown


def klm(eta):
    """Kolafa-Labik-Malijevsky-form series (coefficients of Pieprzyk et al., PCCP 21, 6886
    (2019)); valid below eta ~ 0.55."""
    x = eta / (1 - eta)
    c = {1: 4, 2: 6, 3: 2.3647684, 4: -0.8698551, 5: 1.1062803, 6: -1.1014221,
         7: 0.66605866, 8: -0.03633431, 10: -0.20965164, 14: 0.10555569, 22: -0.00872380}
    return 1 + sum(v * x ** k for k, v in c.items())


def jam_row(s):
    c = s["compression"]
    k = c["contacts"]
    return (c["packing_fraction"], c["free_volume_jamming_density"],
            k["coordination"], k["backbone_coordination"], k["isostatic_excess"],
            k["rattler_fraction"], k["largest_contact_gap"], k["smallest_open_gap"],
            c["collisions"], c["wall_seconds"])


def print_jam_header(what):
    print("%-8s %-4s %8s %8s %6s %6s %6s %7s %9s %9s %11s %7s" % (
        what, "seed", "phi_J", "phi_J_fv", "z", "z_bb", "excess", "rattl.",
        "max_cgap", "min_ogap", "collisions", "wall_s"))


def part_a(args):
    print("\n== a. 3D monodisperse N = 2000, random 0.3 -> jammed (MRJ 0.645 +- 0.005;"
          " rattlers 2-3 %; z_backbone = 6)")
    print_jam_header("rate")
    by_rate = {}
    for rate in args.rates:
        for seed in range(11, 11 + args.seeds):
            out = os.path.join(args.out, "a_rate%g_seed%d" % (rate, seed))
            s, _, shown = run(args.kairos, out, "jammed_spheres_3d.toml",
                              [("compress.growth_rate", rate), ("system.seed", seed)])
            r = jam_row(s)
            by_rate.setdefault(rate, []).append(r)
            print("%-8g %-4d %8.4f %8.4f %6.3f %6.3f %6d %7.4f %9.2e %9.2e %11d %7.1f" % (
                (rate, seed) + r))
            print("    " + shown)
    print("mean over seeds:")
    for rate, rows in by_rate.items():
        a = np.array([r[:6] for r in rows], float)
        print("  rate %-6g phi_J %.4f  z_bb %.3f  rattlers %.4f  (%d seeds)" % (
            rate, a[:, 0].mean(), a[:, 3].mean(), a[:, 5].mean(), len(rows)))


def part_b(args):
    print("\n== b. 2D bidisperse 1:1.4 50:50, N = 2000, random 0.5 -> jammed"
          " (phi_J ~ 0.84, 0.842; z_backbone = 4)")
    print_jam_header("rate")
    for seed in range(12, 12 + args.seeds):
        out = os.path.join(args.out, "b_seed%d" % seed)
        s, _, shown = run(args.kairos, out, "jammed_disks_2d.toml", [("system.seed", seed)])
        print("%-8g %-4d %8.4f %8.4f %6.3f %6.3f %6d %7.4f %9.2e %9.2e %11d %7.1f" % (
            (s["compression"]["growth_rate"], seed) + jam_row(s)))
        print("    " + shown)


def part_c(args):
    print("\n== c. 3D N = 2000, growth 0.30 -> 0.50 at rate 1e-3, thermostat_interval 1:"
          " Z against KLM")
    out = os.path.join(args.out, "c_eos")
    s, _, shown = run(args.kairos, out, "jammed_spheres_3d.toml",
                      [("compress.jammed", "false"), ("compress.packing_fraction", 0.5),
                       ("compress.growth_rate", 0.001), ("compress.thermostat_interval", 1)])
    print("    " + shown)
    t = np.loadtxt(os.path.join(out, "compress.tsv"), comments="#")
    # each row: packing fraction at the interval's end, Z over the interval; take the
    # interval's middle packing fraction (start = previous row's end)
    phi_end = t[:, 1]
    phi_start = np.concatenate([[s["compression"]["initial_packing_fraction"]], phi_end[:-1]])
    phi_mid = 0.5 * (phi_start + phi_end)
    z = t[:, 2]
    print("%6s %5s %9s %9s %9s %8s" % ("phi", "rows", "Z", "+-", "Z_KLM", "dev %"))
    for c in (0.35, 0.40, 0.45, 0.49):
        m = np.abs(phi_mid - c) <= 0.005
        zz = z[m]
        # Z of the window's rows is read against KLM at each row's own phi (the curve is not
        # linear over +-0.005); the error is the rows' scatter
        ref = np.array([klm(p) for p in phi_mid[m]])
        dev = (zz - ref) / ref
        err = dev.std(ddof=1) / math.sqrt(len(dev)) if len(dev) > 1 else float("nan")
        print("%6.3f %5d %9.4f %9.4f %9.4f %+8.2f +- %.2f" % (
            c, m.sum(), zz.mean(), zz.std(ddof=1) / math.sqrt(m.sum()), klm(c),
            100 * dev.mean(), 100 * err))
    print("  collisions %d, wall %.1f s" % (s["compression"]["collisions"],
                                           s["compression"]["wall_seconds"]))


def diameters(path):
    import gsd.hoomd
    with gsd.hoomd.open(path) as f:
        return np.asarray(f[0].particles.diameter, float)


def part_d(args):
    from scipy import stats
    print("\n== d. size distributions, N = 4000, polydispersity 0.1: Kolmogorov-Smirnov")
    p = 0.1
    s2 = math.log(1 + p * p)
    cases = [
        ("lognormal", "polydisperse_glass_3d.toml",
         [("system.packing_fraction", 0.3), ("compress.packing_fraction", 0.58),
          ("run.equilibration_collisions_per_particle", 0),
          ("run.collisions_per_particle", 0.1), ("analysis.bond_order", "false"),
          ("analysis.rdf", "false")],
         "packing.gsd", stats.lognorm(s=math.sqrt(s2), scale=math.exp(-s2 / 2)).cdf),
        ("uniform", "polydisperse_glass_3d.toml",
         [("system.size_distribution", "uniform"), ("system.packing_fraction", 0.3),
          ("run.equilibration_collisions_per_particle", 0),
          ("run.collisions_per_particle", 0.1), ("analysis.bond_order", "false"),
          ("analysis.rdf", "false")],
         "trajectory.gsd", stats.uniform(loc=1 - math.sqrt(3) * p, scale=2 * math.sqrt(3) * p).cdf),
        ("gaussian", "polydisperse_glass_3d.toml",
         [("system.size_distribution", "gaussian"), ("system.packing_fraction", 0.3),
          ("run.equilibration_collisions_per_particle", 0),
          ("run.collisions_per_particle", 0.1), ("analysis.bond_order", "false"),
          ("analysis.rdf", "false")],
         "trajectory.gsd", stats.norm(loc=1, scale=p).cdf),
    ]
    print("%-10s %7s %8s %8s %8s %8s" % ("dist", "scale", "mean", "rel.std", "KS D", "p-value"))
    for name, example, sets, frame, cdf in cases:
        out = os.path.join(args.out, "d_" + name)
        s, _, shown = run(args.kairos, out, example, sets)
        d = diameters(os.path.join(out, frame))
        # a grown packing's diameters are the drawn ones times the common growth factor
        c = s.get("compression")
        scale = (c["packing_fraction"] / c["initial_packing_fraction"]) ** (1 / 3) if c else 1.0
        x = d / scale
        ks = stats.kstest(x, cdf)
        print("%-10s %7.4f %8.4f %8.4f %8.4f %8.3f" % (
            name, scale, x.mean(), x.std(ddof=1) / x.mean(), ks.statistic, ks.pvalue))
        print("    " + shown + "   (diameters from %s)" % frame)
        if c:
            print("    grown %.4f -> %.4f, %d collisions, %.1f s" % (
                c["initial_packing_fraction"], c["packing_fraction"], c["collisions"],
                c["wall_seconds"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kairos", default=os.path.join(ROOT, "build", "kairos"))
    ap.add_argument("--out", default="validation-compression")
    ap.add_argument("--parts", default="a,b,c,d")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--rates", default="0.1,0.03,0.01")
    args = ap.parse_args()
    args.rates = [float(r) for r in args.rates.split(",")]
    os.makedirs(args.out, exist_ok=True)
    for part in args.parts.split(","):
        {"a": part_a, "b": part_b, "c": part_c, "d": part_d}[part.strip()](args)
        sys.stdout.flush()


if __name__ == "__main__":
    main()
