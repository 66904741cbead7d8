#!/usr/bin/python3
"""Shear and bulk viscosity and thermal conductivity of hard spheres and disks ([analysis]
transport = true) against Enskog, Green-Kubo and Lees-Edwards shear.

docs/validation.md, "Transport coefficients (analysis.transport): hard spheres and disks". Every
coefficient below is Kairos's own summary.json `transport.<name>.value ± stderr` (Einstein-
Helfand) and `green_kubo ± green_kubo_stderr`; nothing is refitted except in the window tables,
which refit helfand.tsv (the mean-square moments per lag, no error bar) over other lag windows.

Experiments (sigma = m = kT = 1; tau_E = Enskog mean free time, Carnahan-Starling g(sigma)):

  density  3D, N = 1372 (fcc start, 200 collisions per particle of equilibration), packing
           fractions 0.1 ... 0.45, fit window [10, 40] tau_E up to eta = 0.3, [20, 100] at 0.4
           and [40, 200] at 0.45 (the stress autocorrelation decays slowly there), production
           3 10^5 (4 10^5 at 0.4 and 0.45) collisions per particle, i.e. 2000-7500 times the
           window's longest lag. Against Enskog with Chapman and Cowling's higher Sonine
           factors; Einstein-Helfand against Green-Kubo; the window dependence from helfand.tsv.
  seeds    eta = 0.3, N = 1372, window [10, 40] tau_E, 5 10^4 collisions per particle, --seeds
           seeds: the scatter between runs against the reported stderr (both methods).
  size     eta = 0.45, window [40, 200] tau_E: N = 500 (4 10^5 collisions per particle) and
           N = 4000 (10^5) beside the density experiment's N = 1372.
  disks    2D, area fraction 0.3, N = 1000 (hexagonal start), window [10, 40] tau_E,
           2 10^5 collisions per particle, against the first-Sonine Enskog values for disks.
  nemd     eta = 0.3, N = 1372, Lees-Edwards shear at rates 0.05, 0.1, 0.2 (--nemd-seeds runs
           each, production short enough that viscous heating stays below ~40 %); eta_s at
           kT = 1 through eta ~ sqrt(T), extrapolated to zero reduced shear rate, against the
           Einstein-Helfand value of the density experiment.

    /usr/bin/python3 examples/validation/transport_coefficients.py build/kairos [-o transport]
        [--only density,seeds,size,disks,nemd] [--seeds 16] [--nemd-seeds 16] [--jobs 1]

Runs are kept in OUTPUT/runs/ and re-used when their config is unchanged (cached_runs.py). CPU
on the 2-core VM, one run at a time: density ~21 min, seeds ~9 min, size ~4.5 min, disks ~1 min,
nemd ~0.5 min.
examples/validation/transport_hs.toml is the density experiment's eta = 0.3 run.
"""

import argparse
import concurrent.futures
import json
import math
import os
import resource
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cached_runs  # noqa: E402

DENSITIES = (0.1, 0.2, 0.3, 0.4, 0.45)
N3 = 1372  # 7^3 fcc cells
# packing fraction: (fit_from, fit_to) in Enskog mean free times, production collisions/particle
PLAN = {0.1: ((10, 40), 300000), 0.2: ((10, 40), 300000), 0.3: ((10, 40), 300000),
        0.4: ((20, 100), 400000), 0.45: ((40, 200), 400000)}
NAMES = ("shear_viscosity", "bulk_viscosity", "thermal_conductivity")
SHORT = {"shear_viscosity": "eta_s", "bulk_viscosity": "kappa", "thermal_conductivity": "lambda"}


# ------------------------------------------------------------------------------------------------
# Enskog (sigma = m = kT = k = 1)

def number_density(eta, dimension=3):
    return 6.0 * eta / math.pi if dimension == 3 else 4.0 * eta / math.pi


def g_contact(eta, dimension=3):
    """Carnahan-Starling (3D) or Henderson (2D) contact value."""
    if dimension == 3:
        return (1.0 - 0.5 * eta) / (1.0 - eta) ** 3
    return (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2


def enskog_mean_free_time(eta, dimension=3):
    """1 / (Enskog collision frequency): 4 sqrt(pi) n g (3D), 2 sqrt(pi) n g (2D)."""
    n, g = number_density(eta, dimension), g_contact(eta, dimension)
    return 1.0 / ((4.0 if dimension == 3 else 2.0) * math.sqrt(math.pi) * n * g)


def enskog(eta, dimension=3):
    """{name: Enskog value}.

    3D (Chapman and Cowling, ch. 16, with the higher Sonine orders), b rho = 4 eta, y = b rho g:
      eta_E    = eta_0 / g (1 + 0.8 y + 0.7614 y^2),   eta_0    = 1.016 (5/16) / sqrt(pi)
      kappa_E  = 1.002 eta_0 (b rho)^2 g               (= (4/9) sqrt(pi) n^2 g to 3e-4)
      lambda_E = lambda_0 / g (1 + 1.2 y + 0.7574 y^2), lambda_0 = 1.025 (75/64) / sqrt(pi)
    2D (first Sonine order), phi the area fraction, Henderson g:
      eta_E    = eta_0 [(1 + phi g)^2 / g + (8/pi) phi^2 g],        eta_0    = 1 / (2 sqrt(pi))
      kappa_E  = (sqrt(pi)/2) n^2 g = eta_0 (16/pi) phi^2 g
      lambda_E = lambda_0 [(1 + 1.5 phi g)^2 / g + (4/pi) phi^2 g], lambda_0 = 2 / sqrt(pi)
    """
    g = g_contact(eta, dimension)
    if dimension == 3:
        y = 4.0 * eta * g
        eta0 = 1.016 * 5.0 / 16.0 / math.sqrt(math.pi)
        lam0 = 1.025 * 75.0 / 64.0 / math.sqrt(math.pi)
        return {"shear_viscosity": eta0 / g * (1.0 + 0.8 * y + 0.7614 * y * y),
                "bulk_viscosity": 1.002 * eta0 * (4.0 * eta) ** 2 * g,
                "thermal_conductivity": lam0 / g * (1.0 + 1.2 * y + 0.7574 * y * y)}
    eta0, lam0 = 0.5 / math.sqrt(math.pi), 2.0 / math.sqrt(math.pi)
    x = eta * g
    return {"shear_viscosity": eta0 * ((1.0 + x) ** 2 / g + 8.0 / math.pi * eta * x),
            "bulk_viscosity": eta0 * 16.0 / math.pi * eta * x,
            "thermal_conductivity": lam0 * ((1.0 + 1.5 * x) ** 2 / g + 4.0 / math.pi * eta * x)}


# Kairos's own Lees-Edwards eta_s / eta_E (N = 8000), docs/validation.md "Self-diffusion".
KAIROS_NEMD_8000 = {0.1: (1.007, 0.023), 0.2: (0.960, 0.040), 0.3: (1.031, 0.034),
                    0.4: (1.070, 0.030), 0.45: (1.357, 0.036)}


# ------------------------------------------------------------------------------------------------
# Runs

def config_text(*args, equilibration=200.0, **kwargs):
    return cached_runs.config_text(*args, equilibration=equilibration, **kwargs)


def transport_analysis(eta, window, dimension=3):
    mft = enskog_mean_free_time(eta, dimension)
    return {"transport": True, "transport_fit_from": float("%.3g" % (window[0] * mft)),
            "transport_fit_to": float("%.3g" % (window[1] * mft))}


def run_all(kairos, jobs, workers):
    """jobs: {key: (outdir, text)} -> {key: summary dict} (cached_runs.py)."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
        futures = {pool.submit(cached_runs.run_one, kairos, d, text, True): key
                   for key, (d, text) in jobs.items()}
        for fut in concurrent.futures.as_completed(futures):
            d, wall = fut.result()
            if wall > 0:
                print("  ran %-40s %7.1f s" % (os.path.relpath(d), wall), flush=True)
    return {key: json.load(open(os.path.join(d, "summary.json"))) for key, (d, _) in jobs.items()}


def eh(summary, name):
    c = summary["transport"][name]
    return c["value"], c["stderr"]


def gk(summary, name):
    c = summary["transport"][name]
    e = c.get("green_kubo_stderr")
    return c["green_kubo"], (e if e is not None else float("nan"))


def refit(outdir, summary, name, lo, hi):
    """The Einstein-Helfand coefficient refitted from helfand.tsv over lags [lo, hi] (least
    squares slope of the mean-square moment / (2 V kT), kT^2 for the conductivity)."""
    d = np.genfromtxt(os.path.join(outdir, "helfand.tsv"), names=True)
    column = {"shear_viscosity": "shear_moment", "bulk_viscosity": "bulk_moment",
              "thermal_conductivity": "heat_moment"}[name]
    s = (d["lag"] >= lo) & (d["lag"] <= hi)
    if s.sum() < 3:
        return float("nan")
    t = summary["transport"]
    scale = 2.0 * t["volume"] * t["temperature"] * (t["temperature"] if name == NAMES[2] else 1.0)
    return np.polyfit(d["lag"][s], d[column][s], 1)[0] / scale


def fmt(value, err, digits=4):
    if err is None or not math.isfinite(err):
        return "%.*f ± —" % (digits, value)
    return "%.*f ± %.*f" % (digits, value, digits, err)


# ------------------------------------------------------------------------------------------------
# Experiments

def density_jobs(out):
    jobs = {}
    for eta in DENSITIES:
        window, cpp = PLAN[eta]
        jobs[eta] = (os.path.join(out, "runs", "hs-%g" % eta),
                     config_text(3, N3, eta, cpp, analysis=transport_analysis(eta, window)))
    return jobs


def density_experiment(kairos, out, workers):
    jobs = density_jobs(out)
    summaries = run_all(kairos, jobs, workers)
    print("\n### 3D hard spheres, N = %d: Einstein-Helfand against Enskog\n" % N3)
    print("| eta | window [tau_E] | window | production / fit_to | T | "
          "eta_s | eta_s/eta_E | kappa | kappa/kappa_E | lambda | lambda/lambda_E |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for eta in DENSITIES:
        s, ref = summaries[eta], enskog(eta)
        t = s["transport"]
        cells = []
        for name in NAMES:
            v, e = eh(s, name)
            cells += [fmt(v, e), "%.3f ± %.3f" % (v / ref[name], e / ref[name])]
        print("| %g | [%d, %d] | [%.3g, %.3g] | %.0f | %.6f | %s |"
              % (eta, PLAN[eta][0][0], PLAN[eta][0][1], t["fit_from"], t["fit_to"],
                 (t["sampled_to"] - t["sampled_from"]) / t["fit_to"], t["temperature"],
                 " | ".join(cells)))
    print("\nEnskog values and the mean free time:\n")
    print("| eta | g(sigma) | tau_E | measured mean free time | eta_E | kappa_E | lambda_E |"
          " Kairos Lees-Edwards eta_s/eta_E (N = 8000) |")
    print("|---|---|---|---|---|---|---|---|")
    for eta in DENSITIES:
        ref = enskog(eta)
        print("| %g | %.4f | %.5f | %.5f | %.4f | %.4f | %.4f | %.3f ± %.3f |"
              % (eta, g_contact(eta), enskog_mean_free_time(eta), summaries[eta]["mean_free_time"],
                 ref[NAMES[0]], ref[NAMES[1]], ref[NAMES[2]], *KAIROS_NEMD_8000[eta]))
    print("\n### Einstein-Helfand against Green-Kubo (same samples, same window end)\n")
    print("| eta | coefficient | Einstein-Helfand | stderr_epochs / stderr_components |"
          " Green-Kubo | (EH - GK) / sqrt(err_EH^2 + err_GK^2) |")
    print("|---|---|---|---|---|---|")
    for eta in DENSITIES:
        s = summaries[eta]
        for name in NAMES:
            v, e = eh(s, name)
            g, ge = gk(s, name)
            c = s["transport"][name]
            comp = c.get("stderr_components")
            sigma = math.hypot(e, ge) if math.isfinite(ge) else e
            print("| %g | %s | %s | %.4f / %s | %s | %+.2f%s |"
                  % (eta, SHORT[name], fmt(v, e), c["stderr_epochs"],
                     "%.4f" % comp if comp is not None else "—", fmt(g, ge), (v - g) / sigma,
                     "" if math.isfinite(ge) else " (EH error only: no GK error)"))
    print("\n### Window dependence (helfand.tsv refitted over [a, 4a] tau_E; ratio to Enskog)\n")
    starts = (2.5, 5, 10, 20, 40, 80)
    print("| eta | coefficient | " + " | ".join("[%g, %g]" % (a, 4 * a) for a in starts) + " |")
    print("|---|---|" + "---|" * len(starts))
    for eta in DENSITIES:
        s, ref, mft = summaries[eta], enskog(eta), enskog_mean_free_time(eta)
        for name in NAMES:
            vals = [refit(jobs[eta][0], s, name, a * mft, 4 * a * mft) / ref[name] for a in starts]
            print("| %g | %s | %s |" % (eta, SHORT[name], " | ".join("%.3f" % v for v in vals)))
    return summaries


def seeds_experiment(kairos, out, workers, seeds):
    eta, window, cpp = 0.3, (10, 40), 50000
    jobs = {k: (os.path.join(out, "runs", "seed-%d" % k),
                config_text(3, N3, eta, cpp, seed=k, analysis=transport_analysis(eta, window)))
            for k in range(1, seeds + 1)}
    summaries = run_all(kairos, jobs, workers)
    runs = [summaries[k] for k in sorted(summaries)]
    t = runs[0]["transport"]
    print("\n### Reported stderr against the scatter between %d seeds (eta = 0.3, N = %d, %d "
          "collisions/particle, window [%.3g, %.3g], production %.0f x fit_to)\n"
          % (seeds, N3, cpp, t["fit_from"], t["fit_to"],
             (t["sampled_to"] - t["sampled_from"]) / t["fit_to"]))
    print("| coefficient | method | mean ± s.e.m. | / Enskog | seed-to-seed s.d. |"
          " mean reported stderr | s.d. / stderr | mean stderr_epochs / stderr_components |")
    print("|---|---|---|---|---|---|---|---|")
    rel = 1.0 / math.sqrt(2.0 * (seeds - 1))
    ref = enskog(eta)

    def mean_of(key):
        x = [r["transport"][name].get(key) for r in runs]
        return "%.4f" % np.mean(x) if all(v is not None for v in x) else "—"

    for name in NAMES:
        for method, get in (("EH", eh), ("GK", gk)):
            v = np.array([get(r, name)[0] for r in runs])
            e = np.array([get(r, name)[1] for r in runs])
            sd = v.std(ddof=1)
            me = float(np.mean(e)) if np.all(np.isfinite(e)) else float("nan")
            parts = ("%s / %s" % (mean_of("stderr_epochs"), mean_of("stderr_components"))
                     if method == "EH" else "")
            print("| %s | %s | %.4f ± %.4f | %.3f | %.4f (± %.0f %%) | %s | %s | %s |"
                  % (SHORT[name], method, v.mean(), sd / math.sqrt(seeds), v.mean() / ref[name],
                     sd, 100 * rel, "%.4f" % me if math.isfinite(me) else "—",
                     "%.2f ± %.2f" % (sd / me, rel * sd / me) if math.isfinite(me) else "—",
                     parts))
        d = np.array([eh(r, name)[0] - gk(r, name)[0] for r in runs])
        print("| %s | EH - GK | %+.4f ± %.4f | | %.4f | | | |"
              % (SHORT[name], d.mean(), d.std(ddof=1) / math.sqrt(seeds), d.std(ddof=1)))
    for name in NAMES:
        print("%s per seed (EH): %s" % (SHORT[name], ", ".join("%.4f" % eh(r, name)[0]
                                                               for r in runs)))


def size_experiment(kairos, out, workers, density_summaries):
    eta = 0.45
    window = PLAN[eta][0]
    plan = {500: 400000, 4000: 100000}
    jobs = {n: (os.path.join(out, "runs", "size-%g-%d" % (eta, n)),
                config_text(3, n, eta, cpp, analysis=transport_analysis(eta, window)))
            for n, cpp in plan.items()}
    summaries = run_all(kairos, jobs, workers)
    if density_summaries is not None:
        summaries[N3] = density_summaries[eta]
        plan[N3] = PLAN[eta][1]
    ref = enskog(eta)
    print("\n### Finite size at eta = %g (window [%d, %d] tau_E; ratios to Enskog)\n"
          % (eta, window[0], window[1]))
    print("| N | L | collisions/particle | production / fit_to | eta_s/eta_E | kappa/kappa_E |"
          " lambda/lambda_E | GK: eta_s/eta_E |")
    print("|---|---|---|---|---|---|---|---|")
    for n in sorted(summaries):
        s = summaries[n]
        t = s["transport"]
        cells = ["%.3f ± %.3f" % (eh(s, name)[0] / ref[name], eh(s, name)[1] / ref[name])
                 for name in NAMES]
        g, ge = gk(s, NAMES[0])
        print("| %d | %.2f | %d | %.0f | %s | %.3f ± %.3f |"
              % (n, (n / number_density(eta)) ** (1.0 / 3.0), plan[n],
                 (t["sampled_to"] - t["sampled_from"]) / t["fit_to"], " | ".join(cells),
                 g / ref[NAMES[0]], ge / ref[NAMES[0]]))


def disks_experiment(kairos, out, workers):
    eta, n, window, cpp = 0.3, 1000, (10, 40), 200000
    d = os.path.join(out, "runs", "disks-%g-%d" % (eta, n))
    s = run_all(kairos, {0: (d, config_text(2, n, eta, cpp, equilibration=100,
                                             analysis=transport_analysis(eta, window, 2)))},
                workers)[0]
    ref, mft = enskog(eta, 2), enskog_mean_free_time(eta, 2)
    t = s["transport"]
    length = math.sqrt(n / number_density(eta, 2))
    print("\n### 2D hard disks, area fraction %g, N = %d (L = %.1f), window [%.3g, %.3g] "
          "(= [%d, %d] tau_E, tau_E = %.4f, measured %.4f), production %.0f x fit_to\n"
          % (eta, n, length, t["fit_from"], t["fit_to"], window[0], window[1], mft,
             s["mean_free_time"], (t["sampled_to"] - t["sampled_from"]) / t["fit_to"]))
    starts = (2.5, 10, 40, 160)
    print("| coefficient | Einstein-Helfand | Green-Kubo | Enskog (first Sonine) | EH / Enskog | "
          + " | ".join("refit [%g, %g] tau_E / Enskog" % (a, 4 * a) for a in starts) + " |")
    print("|---|---|---|---|---|" + "---|" * len(starts))
    for name in NAMES:
        v, e = eh(s, name)
        g, ge = gk(s, name)
        vals = [refit(d, s, name, a * mft, 4 * a * mft) / ref[name] for a in starts]
        print("| %s | %s | %s | %.4f | %.3f ± %.3f | %s |"
              % (SHORT[name], fmt(v, e), fmt(g, ge), ref[name], v / ref[name], e / ref[name],
                 " | ".join("%.3f" % x for x in vals)))


def read_thermo(path):
    with open(path) as f:
        lines = [ln.rstrip("\n").split("\t") for ln in f if ln.strip()]
    header, rows = lines[0], [r for r in lines[1:] if r[0] == "production"]
    return {name: np.array([float(r[i]) for r in rows]) for i, name in enumerate(header)
            if name != "phase"}


def nemd_experiment(kairos, out, workers, seeds, density_summaries):
    """Lees-Edwards at eta = 0.3, N = N3. Shear heats the gas (no thermostat): the production of
    each rate is short (heating ~ 2 eta_s rate^2 t / (3 n)), many seeds make up the precision.
    For hard spheres eta_s(T, rate) = sqrt(T) eta_s*(rate / sqrt(T)): each run gives eta_s* =
    viscosity / <sqrt(T)> at the reduced rate rate / <sqrt(T)> (means over its thermo rows)."""
    eta = 0.3
    plan = {0.05: 1200, 0.1: 300, 0.2: 80}  # rate: production collisions per particle
    jobs = {(rate, k): (os.path.join(out, "runs", "nemd-%g-%d" % (rate, k)),
                        config_text(3, N3, eta, cpp, seed=k, equilibration=50, shear_rate=rate,
                                    thermo_interval=0.25))
            for rate, cpp in plan.items() for k in range(1, seeds + 1)}
    summaries = run_all(kairos, jobs, workers)
    print("\n### Lees-Edwards shear, eta = 0.3, N = %d, %d seeds per rate\n" % (N3, seeds))
    print("| rate | production coll./particle | T start -> end | reduced rate | eta_s* (mean ±"
          " s.e.m.) | seed s.d. | mean reported viscosity_stderr (at T = 1) |")
    print("|---|---|---|---|---|---|---|")
    x, y, w = [], [], []
    for rate, cpp in plan.items():
        vals, rates, errs, t0, t1 = [], [], [], [], []
        for k in range(1, seeds + 1):
            sh = summaries[(rate, k)]["shear"]
            th = read_thermo(os.path.join(jobs[(rate, k)][0], "thermo.tsv"))
            scale = float(np.mean(np.sqrt(th["temperature"])))
            vals.append(sh["viscosity"] / scale)
            errs.append(sh["viscosity_stderr"] / scale)
            rates.append(rate / scale)
            t0.append(sh["temperature_production_start"])
            t1.append(sh["temperature"])
        vals = np.array(vals)
        sem = vals.std(ddof=1) / math.sqrt(seeds)
        x.append(float(np.mean(rates)))
        y.append(float(vals.mean()))
        w.append(1.0 / sem ** 2)
        print("| %g | %d | %.3f -> %.3f | %.4f | %.4f ± %.4f | %.4f | %.4f |"
              % (rate, cpp, np.mean(t0), np.mean(t1), x[-1], y[-1], sem, vals.std(ddof=1),
                 float(np.mean(errs))))
    x, y, w = np.array(x), np.array(y), np.array(w)
    mean = float(np.sum(w * y) / np.sum(w))
    print("\nweighted mean of the three rates (no rate dependence): eta_s = %.4f ± %.4f, chi2 = %.2f"
          " for 2 dof" % (mean, 1.0 / math.sqrt(np.sum(w)), float(np.sum(w * (y - mean) ** 2))))
    for label, xx in (("linear in rate", x), ("linear in sqrt(rate)", np.sqrt(x))):
        W = np.sum(w)
        xm, ym = np.sum(w * xx) / W, np.sum(w * y) / W
        sxx = np.sum(w * (xx - xm) ** 2)
        b = np.sum(w * (xx - xm) * (y - ym)) / sxx
        a = ym - b * xm
        ea = math.sqrt(1.0 / W + xm ** 2 / sxx)
        chi2 = float(np.sum(w * (y - a - b * xx) ** 2))
        print("zero-rate extrapolation, %s: eta_s = %.4f ± %.4f (slope %.3f, chi2 = %.2f for 1 dof)"
              % (label, a, ea, b, chi2))
    ref = enskog(eta)[NAMES[0]]
    if density_summaries is not None:
        v, e = eh(density_summaries[eta], NAMES[0])
        g, ge = gk(density_summaries[eta], NAMES[0])
        print("Einstein-Helfand (density experiment, equilibrium): %s; Green-Kubo %s; Enskog %.4f"
              % (fmt(v, e), fmt(g, ge), ref))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("kairos")
    p.add_argument("-o", "--output", default="transport")
    p.add_argument("--only", default="density,seeds,size,disks,nemd")
    p.add_argument("--seeds", type=int, default=16, help="seeds of the eta = 0.3 error-bar check")
    p.add_argument("--nemd-seeds", type=int, default=16, help="Lees-Edwards runs per shear rate")
    p.add_argument("--jobs", type=int, default=1)
    args = p.parse_args()
    kairos = os.path.abspath(args.kairos)
    out = os.path.abspath(args.output)
    only = set(args.only.split(","))
    unknown = only - {"density", "seeds", "size", "disks", "nemd"}
    if unknown:
        sys.exit("unknown experiment(s): %s" % ", ".join(sorted(unknown)))
    t0 = time.time()
    density = density_experiment(kairos, out, args.jobs) if "density" in only else None
    if "seeds" in only:
        seeds_experiment(kairos, out, args.jobs, args.seeds)
    if "size" in only:
        size_experiment(kairos, out, args.jobs, density)
    if "disks" in only:
        disks_experiment(kairos, out, args.jobs)
    if "nemd" in only:
        nemd_experiment(kairos, out, args.jobs, args.nemd_seeds, density)
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    print("\n%.0f s wall, %.0f s CPU of the runs made now (cached runs cost nothing)"
          % (time.time() - t0, cpu.ru_utime + cpu.ru_stime))


if __name__ == "__main__":
    main()
