#!/usr/bin/python3
"""Self-diffusion of hard spheres and disks ([analysis] msd = true) against the literature.

docs/validation.md, "Self-diffusion (analysis.msd)". Every D below is Kairos's own
summary.json `diffusion.species.A.coefficient` and `coefficient_stderr`; nothing is refitted
except where a table says so (the window study refits msd.tsv, which has no subsets, so no
error bar).

Experiments (sigma = m = kT = 1):

  density    3D, eta = 0.1 ... 0.45: N = 4000 with 1000 and 10 000 collisions per particle
             (automatic fit window), and N = 500 with 20 000 (window [2.5, 30] tau_L); D against
             Enskog's D_E = 3 / (8 n g(sigma)) sqrt(1 / pi) (Carnahan-Starling g(sigma)),
             Speedy's fit (Mol. Phys. 62, 509 (1987); it represents N ~ 500 systems) and, after
             the Yeh-Hummer correction D_inf = D_L + 2.837297 / (6 pi eta_s L), D_inf / D_E.
  viscosity  3D, N = 8000, the same densities under Lees-Edwards shear: eta_s / eta_E, the
             check of the Enskog viscosity that the Yeh-Hummer correction uses.
  size       3D, eta = 0.3, N = 500 ... 32 000, fit windows from 2.5 hydrodynamic box times
             tau_L = n L^2 / (4 pi^2 eta_E) (the slowest shear mode): D(L) against 1/L, its
             slope against Yeh-Hummer's 2.837297 / (6 pi eta_s) and the mode-coupling form
             with eta_s + n D.
  seeds      the example config (3D, eta = 0.3, 1000 collisions per particle, automatic window)
             with --seeds seeds at N = 500 and 4000 and --big-seeds at N = 32 000: the scatter
             of D between runs against the mean reported stderr.
  window     (needs density; its N = 32 000 row needs size and seeds) the automatic window of
             runs of 1000 collisions per particle against the long runs, and the long runs'
             msd.tsv refitted over the short runs' windows (the systematic part).
  disks      2D, area fraction 0.3, N = 1000, 4000, 16 000, fit windows past the box time:
             D grows with L (the 1/t velocity tail makes D(L) ~ ln L); --disk-seeds seeds of
             N = 1000 for the scatter against the stderr in 2D.

    /usr/bin/python3 examples/validation/self_diffusion.py build/kairos [-o self-diffusion]
        [--only density,viscosity,size,window,seeds,disks] [--seeds 20] [--big-seeds 6]
        [--disk-seeds 10] [--jobs 1]

Runs are kept in OUTPUT/runs/ and re-used when their config is unchanged. CPU on the 2-core VM
(one run at a time, about 20 min in all): density 2.5 min, viscosity 15 s, size 7 min, seeds
3.5 min, disks 6 min.
"""

import argparse
import concurrent.futures
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cached_runs  # noqa: E402

YEH_HUMMER_XI = 2.837297
DENSITIES = (0.1, 0.2, 0.3, 0.4, 0.45)
SIZES = (500, 2000, 4000, 8000, 32000)
DISKS = (1000, 4000, 16000)


# ------------------------------------------------------------------------------------------------
# References (3D hard spheres, sigma = m = kT = 1)

def number_density(eta):
    return 6.0 * eta / math.pi


def g_contact(eta):
    """Carnahan-Starling contact value (J. Chem. Phys. 51, 635 (1969))."""
    return (1.0 - 0.5 * eta) / (1.0 - eta) ** 3


def enskog_diffusion(eta):
    """D_E = 3 / (8 n sigma^2 g(sigma)) sqrt(kT / (pi m)): Enskog, first Sonine order (no 1.019
    factor)."""
    return 3.0 / (8.0 * number_density(eta) * g_contact(eta)) * math.sqrt(1.0 / math.pi)


def speedy_diffusion(eta):
    """Speedy, Mol. Phys. 62, 509 (1987): D / D_0 = (1 - n/1.09) (1 + n^2 (0.4 - 0.83 n^2)) with
    n = rho sigma^3 and D_0 = 3 / (8 n sigma^2) sqrt(kT / (pi m)) (the Boltzmann value).
    Sigurgeirsson and Heyes (Mol. Phys. 101, 469 (2003)) find it fits N ~ 500 simulations."""
    n = number_density(eta)
    d0 = 3.0 / (8.0 * n) * math.sqrt(1.0 / math.pi)
    return d0 * (1.0 - n / 1.09) * (1.0 + n * n * (0.4 - 0.83 * n * n))


def enskog_viscosity(eta):
    """eta_E = eta_0 / g (1 + 0.8 y + 0.7614 y^2), y = 4 eta g, eta_0 = 1.016 (5/16) sqrt(1/pi)
    (as in docs/validation.md, "Viscosity of a dilute elastic gas vs Enskog")."""
    g = g_contact(eta)
    y = 4.0 * eta * g
    eta0 = 1.016 * 5.0 / 16.0 * math.sqrt(1.0 / math.pi)
    return eta0 / g * (1.0 + 0.8 * y + 0.7614 * y * y)


def box_length(particles, eta, dimension=3):
    if dimension == 3:
        return (particles / number_density(eta)) ** (1.0 / 3.0)
    return math.sqrt(particles / (4.0 * eta / math.pi))


def box_time(particles, eta, viscosity):
    """tau_L = n L^2 / (4 pi^2 eta_s): decay time of the slowest shear mode (k = 2 pi / L)."""
    length = box_length(particles, eta)
    return number_density(eta) * length ** 2 / (4.0 * math.pi ** 2 * viscosity)


def yeh_hummer(particles, eta, viscosity):
    return YEH_HUMMER_XI / (6.0 * math.pi * viscosity * box_length(particles, eta))


# ------------------------------------------------------------------------------------------------
# Runs

def config_text(*args, **kwargs):
    return cached_runs.config_text(*args, **kwargs)


def run_one(kairos, outdir, text):
    """A cached run (cached_runs.py), continuing into a directory it wrote before."""
    return cached_runs.run_one(kairos, outdir, text, overwrite=True)


def run_all(kairos, jobs, workers):
    """jobs: {key: (outdir, text)} -> {key: summary dict}."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
        futures = {pool.submit(run_one, kairos, d, text): key for key, (d, text) in jobs.items()}
        for fut in concurrent.futures.as_completed(futures):
            d, wall = fut.result()
            if wall > 0:
                print("  ran %-40s %7.1f s" % (os.path.relpath(d), wall), flush=True)
    return {key: json.load(open(os.path.join(d, "summary.json"))) for key, (d, _) in jobs.items()}


def diffusion(summary):
    s = summary["diffusion"]["species"]["A"]
    return s["coefficient"], s["coefficient_stderr"]


def read_thermo(path):
    with open(path) as f:
        lines = [ln.rstrip("\n").split("\t") for ln in f if ln.strip()]
    header, rows = lines[0], [r for r in lines[1:] if r[0] == "production"]
    return {name: np.array([float(r[i]) for r in rows]) for i, name in enumerate(header)
            if name != "phase"}


def read_msd(path):
    d = np.loadtxt(path, skiprows=1)
    return d[:, 0], d[:, 2]


def refit(outdir, lo, hi, dimension=3):
    """Least-squares slope / (2 d) of msd.tsv over lags in [lo, hi] (no error bar)."""
    t, m = read_msd(os.path.join(outdir, "msd.tsv"))
    s = (t >= lo) & (t <= hi)
    return np.polyfit(t[s], m[s], 1)[0] / (2.0 * dimension), int(s.sum())


# ------------------------------------------------------------------------------------------------
# Experiments

def viscosity_experiment(kairos, out, workers):
    """eta_s / eta_E from Lees-Edwards shear (N = 8000, 400 collisions per particle); viscous
    heating is undone with eta ~ sqrt(T) (exact for hard spheres at fixed reduced shear rate)
    through the mean of sqrt(T) over the production rows."""
    rates = {0.1: 0.04, 0.2: 0.06, 0.3: 0.1, 0.4: 0.1, 0.45: 0.1}
    jobs = {eta: (os.path.join(out, "runs", "viscosity-%g" % eta),
                  config_text(3, 8000, eta, 400, seed=7, equilibration=50, shear_rate=rates[eta],
                              thermo_interval=0.5)) for eta in DENSITIES}
    summaries = run_all(kairos, jobs, workers)
    print("\n### Shear viscosity (Lees-Edwards, N = 8000, 400 collisions/particle)\n")
    print("| eta | shear rate | T start -> end | eta_s (at T = 1) | eta_E | eta_s / eta_E |")
    print("|---|---|---|---|---|---|")
    ratio = {}
    for eta in DENSITIES:
        sh = summaries[eta]["shear"]
        th = read_thermo(os.path.join(jobs[eta][0], "thermo.tsv"))
        scale = float(np.mean(np.sqrt(th["temperature"])))
        v, e = sh["viscosity"] / scale, sh["viscosity_stderr"] / scale
        ratio[eta] = (v / enskog_viscosity(eta), e / enskog_viscosity(eta))
        print("| %g | %g | %.3f -> %.3f | %.4f ± %.4f | %.4f | %.3f ± %.3f |"
              % (eta, rates[eta], sh["temperature_production_start"], sh["temperature"], v, e,
                 enskog_viscosity(eta), ratio[eta][0], ratio[eta][1]))
    return ratio


def density_experiment(kairos, out, workers, viscosity_ratio):
    jobs = {}
    for eta in DENSITIES:
        for cpp in (1000, 10000):
            jobs[(eta, 4000, cpp)] = (os.path.join(out, "runs", "density-%g-%d" % (eta, cpp)),
                                      config_text(3, 4000, eta, cpp, analysis={"msd": True}))
        # N = 500, the size of the simulations Speedy's fit represents: a fixed window past the
        # box time (the automatic one would need the same length to be as precise).
        tau = box_time(500, eta, enskog_viscosity(eta))
        jobs[(eta, 500, 20000)] = (
            os.path.join(out, "runs", "density-%g-n500" % eta),
            config_text(3, 500, eta, 20000, analysis={
                "msd": True, "msd_fit_from": round(2.5 * tau, 2),
                "msd_fit_to": round(30.0 * tau, 1)}))
    summaries = run_all(kairos, jobs, workers)
    print("\n### 3D hard spheres against Enskog and Speedy\n")
    print("| eta | D_E | Speedy / D_E | N = 500: D / D_E | N = 4000: D_L | D_L / D_E |"
          " Yeh-Hummer (eta_E) | D_inf / D_E (eta_E) | D_inf / D_E (Kairos eta_s) | window | tau_L |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for eta in DENSITIES:
        s = summaries[(eta, 4000, 10000)]
        d, e = diffusion(s)
        d5, e5 = diffusion(summaries[(eta, 500, 20000)])
        de = enskog_diffusion(eta)
        yh = yeh_hummer(4000, eta, enskog_viscosity(eta))
        cell = "—"
        if viscosity_ratio:
            r, er = viscosity_ratio[eta]
            yh_k = yeh_hummer(4000, eta, enskog_viscosity(eta) * r)
            cell = "%.3f ± %.3f" % ((d + yh_k) / de, math.hypot(e, yh_k * er / r) / de)
        w = s["diffusion"]
        print("| %g | %.5f | %.3f | %.3f ± %.3f | %.5f ± %.5f (%.2f %%) | %.3f ± %.3f | +%.5f |"
              " %.3f ± %.3f | %s | [%.3g, %.3g] | %.3g |"
              % (eta, de, speedy_diffusion(eta) / de, d5 / de, e5 / de, d, e, 100 * e / d, d / de,
                 e / de, yh, (d + yh) / de, e / de, cell, w["fit_from"], w["fit_to"],
                 box_time(4000, eta, enskog_viscosity(eta))))
    return summaries, jobs


def window_experiment(out, summaries, jobs, short32):
    """Runs of the example config's length (1000 collisions per particle) with the automatic
    window, against the long runs. The systematic part: the long run's msd.tsv (ten times the
    origins) refitted over the short run's automatic window. short32: the N = 32 000 seed runs
    (their mean; error from their scatter)."""
    print("\n### The automatic window of short runs (1000 collisions/particle)\n")
    print("| N | eta | tau_L | window (auto, 1000 coll./particle) | D, 1000 | D, long run |"
          " short / long - 1 | long run's msd.tsv refitted over the short window: / long - 1 |")
    print("|---|---|---|---|---|---|---|---|")
    cases = []
    for eta in DENSITIES:
        ds, es = diffusion(summaries[(eta, 4000, 1000)])
        cases.append((4000, eta, ds, es, summaries[(eta, 4000, 1000)]["diffusion"],
                      summaries[(eta, 4000, 10000)], jobs[(eta, 4000, 10000)][0]))
    size32 = os.path.join(out, "runs", "size-32000")
    if short32 and os.path.exists(os.path.join(size32, "summary.json")):
        d = np.array([diffusion(r)[0] for r in short32])
        cases.append((32000, 0.3, d.mean(), d.std(ddof=1) / math.sqrt(len(d)),
                       short32[0]["diffusion"], json.load(open(os.path.join(size32, "summary.json"))),
                       size32))
    for n, eta, ds, es, w, long_, long_dir in cases:
        dl, el = diffusion(long_)
        refitted, lags = refit(long_dir, w["fit_from"], w["fit_to"])
        print("| %d | %g | %.3g | [%.3g, %.3g] | %.5f ± %.5f | %.5f ± %.5f | %+.1f %% ± %.1f %% |"
              " %+.1f %% (%d lags) |"
              % (n, eta, box_time(n, eta, enskog_viscosity(eta)), w["fit_from"], w["fit_to"],
                 ds, es, dl, el, 100 * (ds / dl - 1), 100 * math.hypot(es / dl, el * ds / dl ** 2),
                 100 * (refitted / dl - 1), lags))


def size_experiment(kairos, out, workers, viscosity_ratio):
    eta = 0.3
    visc = enskog_viscosity(eta) * (viscosity_ratio[eta][0] if viscosity_ratio else 1.0)
    visc_window = enskog_viscosity(eta)  # windows from Enskog's: a run's config stays fixed
    cpp = {500: 20000, 2000: 20000, 4000: 20000, 8000: 10000, 32000: 10000}
    mft = 0.0990  # measured at eta = 0.3 (docs/validation.md)
    jobs, windows = {}, {}
    for n in SIZES:
        tau = box_time(n, eta, visc_window)
        lo = round(2.5 * tau, 1)
        hi = round(min(0.25 * cpp[n] * mft, 30.0 * tau), 1)
        windows[n] = (lo, hi)
        jobs[n] = (os.path.join(out, "runs", "size-%d" % n),
                   config_text(3, n, eta, cpp[n], analysis={
                       "msd": True, "msd_particles": 100000, "msd_fit_from": lo,
                       "msd_fit_to": hi}))
    summaries = run_all(kairos, jobs, workers)
    print("\n### Finite size, eta = 0.3 (window [2.5 tau_L, min(T/4, 30 tau_L)])\n")
    print("| N | L | collisions/particle | window | D(L) | Yeh-Hummer prediction D_inf - "
          "xi/(6 pi eta_s L) |")
    print("|---|---|---|---|---|---|")
    x, y, w = [], [], []
    for n in SIZES:
        d, e = diffusion(summaries[n])
        length = box_length(n, eta)
        x.append(1.0 / length)
        y.append(d)
        w.append(1.0 / e ** 2)
    x, y, w = np.array(x), np.array(y), np.array(w)
    # weighted least squares y = a + b x
    W = np.sum(w)
    xm, ym = np.sum(w * x) / W, np.sum(w * y) / W
    sxx = np.sum(w * (x - xm) ** 2)
    b = np.sum(w * (x - xm) * (y - ym)) / sxx
    a = ym - b * xm
    eb, ea = math.sqrt(1.0 / sxx), math.sqrt(1.0 / W + xm ** 2 / sxx)
    chi2 = float(np.sum(w * (y - a - b * x) ** 2))
    slope_yh = YEH_HUMMER_XI / (6.0 * math.pi * visc)
    # the intercept with the slope fixed at Yeh-Hummer's
    a_fixed = float(np.sum(w * (y + slope_yh * x)) / W)
    for n in SIZES:
        d, e = diffusion(summaries[n])
        length = box_length(n, eta)
        print("| %d | %.2f | %d | [%.3g, %.3g] | %.5f ± %.5f | %.5f |"
              % (n, length, cpp[n], windows[n][0], windows[n][1], d, e,
                 a_fixed - slope_yh / length))
    slope_mct = YEH_HUMMER_XI / (6.0 * math.pi * (visc + number_density(eta) * a))
    for name, slope in (("Yeh-Hummer, eta_s", slope_yh), ("mode coupling, eta_s + n D", slope_mct)):
        a_s = float(np.sum(w * (y + slope * x)) / W)
        print("slope fixed at %s = %.4f: D_inf = %.5f, chi2 = %.1f for %d dof"
              % (name, slope, a_s, float(np.sum(w * (y - a_s + slope * x) ** 2)), len(SIZES) - 1))
    print("\nfit D(L) = D_inf - s/L: D_inf = %.5f ± %.5f, s = %.4f ± %.4f (chi2 = %.2f for %d dof);"
          " Yeh-Hummer s = %.4f (eta_s = %.4f); with s fixed: D_inf = %.5f, D_inf / D_E = %.3f"
          % (a, ea, -b, eb, chi2, len(SIZES) - 2, slope_yh, visc, a_fixed,
             a_fixed / enskog_diffusion(eta)))


def seed_runs(kairos, out, workers, particles, seeds):
    """The example config (eta = 0.3, 1000 collisions per particle, automatic window) with
    seeds 1 .. seeds: summaries in seed order."""
    jobs = {s: (os.path.join(out, "runs", "seed-%d-%d" % (particles, s)),
                config_text(3, particles, 0.3, 1000, seed=s, equilibration=50,
                            analysis=({"msd": True} if particles <= 10000 else
                                      {"msd": True, "msd_particles": 100000})))
            for s in range(1, seeds + 1)}
    summaries = run_all(kairos, jobs, workers)
    return [summaries[s] for s in sorted(summaries)]


def seeds_experiment(runs):
    """runs: {N: [summaries]}. The scatter of D between seeds against the reported stderr."""
    print("\n### Reported stderr against the scatter between seeds (eta = 0.3, 1000 coll./particle,"
          " automatic window)\n")
    print("| N | seeds | mean D | seed-to-seed s.d. | mean reported stderr | s.d. / stderr |"
          " chi2 / dof | within 1 stderr |")
    print("|---|---|---|---|---|---|---|---|")
    for n in sorted(runs):
        d = np.array([diffusion(r)[0] for r in runs[n]])
        e = np.array([diffusion(r)[1] for r in runs[n]])
        k = len(d)
        sd = d.std(ddof=1)
        # a standard deviation from k values has a relative error of about 1 / sqrt(2 (k - 1))
        rel = 1.0 / math.sqrt(2.0 * (k - 1))
        print("| %d | %d | %.5f ± %.5f | %.5f (± %.0f %%) | %.5f | %.2f ± %.2f | %.1f / %d | %d of %d |"
              % (n, k, d.mean(), sd / math.sqrt(k), sd, 100 * rel, e.mean(), sd / e.mean(),
                 rel * sd / e.mean(), float(np.sum((d - d.mean()) ** 2 / e ** 2)), k - 1,
                 int(np.sum(np.abs(d - d.mean()) < e)), k))
        print("|  | D per seed: " + ", ".join("%.4f" % x for x in d) + " | | | | | | |")


def disks_experiment(kairos, out, workers, seeds):
    """2D, area fraction 0.3. The box time grows as L^2 (about 0.05 N here: D(t) of N = 1000
    levels off after ~150), so the window starts at 0.15 N and the run is 4 to 28 windows long."""
    eta = 0.3
    plan = {1000: (40000, 150.0, 600.0), 4000: (28800, 600.0, 1500.0),
            16000: (57600, 2400.0, 6000.0)}
    jobs = {}
    for n, (cpp, lo, hi) in plan.items():
        jobs[n] = (os.path.join(out, "runs", "disks-%d" % n),
                   config_text(2, n, eta, cpp, equilibration=100, analysis={
                       "msd": True, "msd_particles": 100000, "msd_fit_from": lo,
                       "msd_fit_to": hi}))
    for s in range(1, seeds + 1):
        jobs[("seed", s)] = (os.path.join(out, "runs", "disks-1000-seed-%d" % s),
                             config_text(2, 1000, eta, 10000, seed=s, equilibration=100,
                                         analysis={"msd": True, "msd_fit_from": 150.0}))
    summaries = run_all(kairos, jobs, workers)
    print("\n### 2D hard disks, area fraction 0.3\n")
    print("| N | L | collisions/particle | window | D(L) |")
    print("|---|---|---|---|---|")
    prev = None
    for n in DISKS:
        d, e = diffusion(summaries[n])
        w = summaries[n]["diffusion"]
        step = "" if prev is None else " (%+.1f %% ± %.1f %%)" % (
            100 * (d / prev[0] - 1), 100 * math.hypot(e, prev[1]) / prev[0])
        print("| %d | %.1f | %d | [%.4g, %.4g] | %.4f ± %.4f%s |"
              % (n, box_length(n, eta, 2), plan[n][0], w["fit_from"], w["fit_to"], d, e, step))
        prev = (d, e)
    if seeds:
        d = np.array([diffusion(summaries[("seed", s)])[0] for s in range(1, seeds + 1)])
        e = np.array([diffusion(summaries[("seed", s)])[1] for s in range(1, seeds + 1)])
        w = summaries[("seed", 1)]["diffusion"]
        print("\nN = 1000, 10 000 collisions/particle, window [%.4g, %.4g], %d seeds: mean D = %.4f"
              " ± %.4f, seed-to-seed s.d. %.4f (± %.0f %%), mean reported stderr %.4f: ratio %.2f"
              % (w["fit_from"], w["fit_to"], seeds, d.mean(), d.std(ddof=1) / math.sqrt(seeds),
                 d.std(ddof=1), 100 / math.sqrt(2 * (seeds - 1)), e.mean(),
                 d.std(ddof=1) / e.mean()))
        print("D per seed: " + ", ".join("%.4f" % x for x in d))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("kairos")
    p.add_argument("-o", "--output", default="self-diffusion")
    p.add_argument("--only", default="density,viscosity,size,window,seeds,disks")
    p.add_argument("--seeds", type=int, default=20, help="seeds at N = 500 and N = 4000")
    p.add_argument("--big-seeds", type=int, default=6, help="seeds at N = 32 000")
    p.add_argument("--disk-seeds", type=int, default=10, help="2D seeds at N = 1000")
    p.add_argument("--jobs", type=int, default=1)
    args = p.parse_args()
    kairos = os.path.abspath(args.kairos)
    out = os.path.abspath(args.output)
    only = set(args.only.split(","))
    unknown = only - {"density", "viscosity", "size", "window", "seeds", "disks"}
    if unknown:
        sys.exit("unknown experiment(s): %s" % ", ".join(sorted(unknown)))
    t0 = time.time()
    ratio = viscosity_experiment(kairos, out, args.jobs) if "viscosity" in only else None
    if "size" in only:
        size_experiment(kairos, out, args.jobs, ratio)
    seeds = {}
    if "seeds" in only:
        for n, k in ((500, args.seeds), (4000, args.seeds), (32000, args.big_seeds)):
            seeds[n] = seed_runs(kairos, out, args.jobs, n, k)
        seeds_experiment(seeds)
    if only & {"density", "window"}:
        summaries, jobs = density_experiment(kairos, out, args.jobs, ratio)
        if "window" in only:
            window_experiment(out, summaries, jobs, seeds.get(32000))
    if "disks" in only:
        disks_experiment(kairos, out, args.jobs, args.disk_seeds)
    print("\n%.0f s" % (time.time() - t0))


if __name__ == "__main__":
    main()
