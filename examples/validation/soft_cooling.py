#!/usr/bin/python3
"""Cooling of a dilute viscoelastic gas: the event-driven soft-sphere mapping against DEM.

Issue 6, "Proof": viscoelastic (Hertz) spheres have a coefficient of restitution e(v_n) that
grows towards 1 as the impact speed falls (docs/physics.md#viscoelastic-head-on), so a cooling
gas becomes more elastic as it cools and cools more slowly than Haff's law
(docs/physics.md#homogeneous-cooling) with the e of its initial temperature. The same gas, from
the same initial states (same seeds), is run by

  mapped         the event-driven Müller–Pöschel mapping (run.integrator = "event"),
  instantaneous  hard spheres with the same e(v_n) (soft.collisions = "instantaneous"),
  dem            the force-based reference (run.integrator = "dem", dt = t_c/50),

over many seeds. Each run's temperature is interpolated onto common grids in simulated time t
and in collisions per particle c; the curves are averaged over the seeds, with the statistical
error of a mean = seed-to-seed standard deviation / sqrt(seeds). Event-driven minus DEM is given
with two errors: the unpaired one sqrt(err_a^2 + err_b^2), and the paired one, the standard
deviation over seeds of the per-seed difference / sqrt(seeds) (the runs of one seed share their
initial state, so early on they are correlated and the paired error is the smaller).

Temperature is the kinetic one (thermo.tsv `temperature`: 2 K over the degrees of freedom that
move, a frozen event-driven pair counting as one body), and also the energy one,
T_E = 2 (K + U) / (3 (N - 1)) with U the energy held by contacts in progress (thermo.tsv
`potential_energy`): an event-driven pair in contact holds its whole relative kinetic energy
until its release, a DEM pair only part of it, so the kinetic T of the two may differ by a
fraction of t_c / tau_f of T; T_E does not have that offset.

Theory (no fit): e(v) from the head-on viscoelastic ODE integrated here (RK4; checked against
the values of docs/physics.md#viscoelastic-head-on to 1e-6), with the dissipation fixed by
e(restitution_speed) = restitution.
With Maxwell velocities each collision dissipates (m/4)(1 - e(g_n)^2) g_n^2, g_n distributed as
g_n exp(-g_n^2 / 4T) (collision-weighted), so

    dT/dc = -T Phi(T) / 3,   Phi(T) = int_0^inf 2 y^3 exp(-y^2) (1 - e(2 sqrt(T) y)^2) dy,

and dT/dt = omega_E(T) dT/dc with Enskog's collision frequency (Carnahan–Starling g(sigma)).
Haff's law with the constant e_0 of the initial temperature, 1 - e_0^2 = Phi(T_0):
T = T_0 exp(-Phi(T_0) c / 3) and T_0 / (1 + t / tau_0)^2, tau_0 = 6 / (Phi(T_0) omega_E(T_0)).
For contrast, a linear dashpot gas of constant e = e_0 goes through the same pipeline (mapped
and DEM) and follows Haff's law.

    /usr/bin/python3 examples/validation/soft_cooling.py build/kairos [-o soft-cooling]
        [--particles 2000] [--seeds 24] [--dashpot-seeds 8] [--collisions 30] [--jobs 2]
        [--no-dashpot]

writes soft-cooling/soft_cooling.tsv (the seed-averaged curves and their errors),
soft-cooling/soft_cooling.png and prints the table of docs/validation.md ("Viscoelastic cooling:
event-driven vs DEM"). The runs are kept in soft-cooling/runs/ and re-used when present.
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

ETA = 0.05          # packing fraction
T0 = 1.0            # initial temperature (m = sigma = 1)
RESTITUTION = 0.8   # Hertz: e at the impact speed RESTITUTION_SPEED
RESTITUTION_SPEED = 2.0  # = sqrt(<g_n^2>) of the colliding pairs at T0
#                          (docs/physics.md#enskog-collision-frequency)
YOUNG = 1.0e5       # t_c ~ 0.03 at v = 2, against tau_f ~ 1.5: t_c / tau_f ~ 2 %
POISSON = 0.3
DASHPOT_STIFFNESS = 1.0e4  # t_c = 0.022

METHODS = ("mapped", "instantaneous", "dem")


# ------------------------------------------------------------------------------------------------
# Theory

def head_on_restitution(c_dis, h=1.0e-3):
    """Viscoelastic head-on restitution e(c_dis), c_dis = A / T with T = (mu^2/(rho^2 v))^(1/5)
    (docs/physics.md#viscoelastic-head-on): s'' = -s^(3/2) - (3/2) c s^(1/2) s', s(0) = 0,
    s'(0) = 1, ending where the force vanishes (s + (3/2) c s' = 0); e = -s' there. RK4,
    vectorised over c_dis; the end is interpolated linearly within the last step. Error ~3e-7 at
    h = 1e-3."""
    c = np.atleast_1d(np.asarray(c_dis, dtype=float))
    s = np.zeros_like(c)
    v = np.ones_like(c)
    e = np.full_like(c, np.nan)
    active = np.ones(c.shape, dtype=bool)

    def f(s, v):
        return v, -np.sqrt(np.maximum(s, 0.0)) * (s + 1.5 * c * v)

    steps = 0
    while active.any():
        k1s, k1v = f(s, v)
        k2s, k2v = f(s + 0.5 * h * k1s, v + 0.5 * h * k1v)
        k3s, k3v = f(s + 0.5 * h * k2s, v + 0.5 * h * k2v)
        k4s, k4v = f(s + h * k3s, v + h * k3v)
        s1 = s + h / 6 * (k1s + 2 * k2s + 2 * k3s + k4s)
        v1 = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        g0, g1 = s + 1.5 * c * v, s1 + 1.5 * c * v1
        done = active & (g1 <= 0) & (steps > 0)
        if done.any():
            w = g0[done] / (g0[done] - g1[done])
            e[done] = -(v[done] + w * (v1[done] - v[done]))
            active &= ~done
        s, v = s1, v1
        steps += 1
    return e


class ViscoelasticTheory:
    """e(v) of the gas's Hertz law, and the Maxwellian cooling curves it implies."""

    def __init__(self, restitution=RESTITUTION, speed=RESTITUTION_SPEED):
        # c_dis grows as v^(1/5): tabulate e over c_dis on a log grid, solve e(c_ref) = restitution.
        self.log_c = np.linspace(math.log(1e-4), math.log(2.0), 240)
        self.e_table = head_on_restitution(np.exp(self.log_c))
        lo, hi = self.log_c[0], self.log_c[-1]
        for _ in range(60):  # e falls with c_dis
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.e_of_log_c(mid) > restitution else (lo, mid)
        self.c_ref = math.exp(0.5 * (lo + hi))
        self.speed = speed
        y = np.linspace(0.0, 7.0, 1401)
        self._y, self._w = y, 2 * y ** 3 * np.exp(-y * y) * (y[1] - y[0])
        self._w[0] *= 0.5
        self._w[-1] *= 0.5

    def e_of_log_c(self, log_c):
        return np.interp(log_c, self.log_c, self.e_table)

    def e(self, v):
        v = np.maximum(np.asarray(v, dtype=float), 1e-30)
        log_c = math.log(self.c_ref) + 0.2 * np.log(v / self.speed)
        return np.where(log_c < self.log_c[0], 1.0 - (1.0 - self.e_table[0]) *
                        np.exp(log_c - self.log_c[0]), self.e_of_log_c(log_c))

    def phi(self, temperature):
        """Phi(T) = <(1 - e^2) g_n^2>_coll / (4 T) for Maxwell velocities at T (m = 1)."""
        e = self.e(2.0 * math.sqrt(temperature) * self._y)
        return float(np.sum(self._w * (1.0 - e * e)))

    def curve_c(self, c):
        """T(c) from dT/dc = -T Phi(T) / 3 (RK4 on a fine grid), T(0) = T0."""
        grid = np.linspace(0.0, float(np.max(c)), 2001)
        h = grid[1] - grid[0]
        t = [T0]
        rate = lambda T: -T * self.phi(T) / 3.0  # noqa: E731
        for _ in grid[1:]:
            T = t[-1]
            k1 = rate(T)
            k2 = rate(T + 0.5 * h * k1)
            k3 = rate(T + 0.5 * h * k2)
            k4 = rate(T + h * k3)
            t.append(T + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
        return np.interp(c, grid, t)

    def curve_t(self, times):
        """T(t) from dT/dt = omega_E(T) dT/dc."""
        grid = np.linspace(0.0, float(np.max(times)), 4001)
        h = grid[1] - grid[0]
        t = [T0]
        rate = lambda T: -enskog_frequency(T) * T * self.phi(T) / 3.0  # noqa: E731
        for _ in grid[1:]:
            T = t[-1]
            k1 = rate(T)
            k2 = rate(T + 0.5 * h * k1)
            k3 = rate(T + 0.5 * h * k2)
            k4 = rate(T + h * k3)
            t.append(T + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
        return np.interp(times, grid, t)


def enskog_frequency(temperature, eta=ETA):
    """Collisions per particle per unit time, 3D, sigma = m = 1
    (docs/physics.md#enskog-collision-frequency)."""
    n = 6.0 * eta / math.pi
    g = (1.0 - eta / 2.0) / (1.0 - eta) ** 3
    return 4.0 * n * g * math.sqrt(math.pi * temperature)


def haff_c(c, one_minus_e2):
    return T0 * np.exp(-one_minus_e2 * np.asarray(c) / 3.0)


def haff_t(t, one_minus_e2):
    tau0 = 6.0 / (one_minus_e2 * enskog_frequency(T0))
    return T0 / (1.0 + np.asarray(t) / tau0) ** 2


# ------------------------------------------------------------------------------------------------
# Runs

def run_config(model, method, seed, particles, collisions, thermo_interval, cache,
               restitution=None):
    """TOML text of one run. model: 'hertz' or 'dashpot'; method: one of METHODS."""
    if model == "hertz":
        soft = ['model = "hertz"', "young = %r" % YOUNG, "poisson = %r" % POISSON,
                "restitution = %r" % RESTITUTION, "restitution_speed = %r" % RESTITUTION_SPEED]
    else:
        soft = ['model = "dashpot"', "stiffness = %r" % DASHPOT_STIFFNESS,
                "restitution = %r" % restitution]
    run = ['integrator = "%s"' % ("dem" if method == "dem" else "event"),
           "equilibration_collisions_per_particle = 0.0",
           "collisions_per_particle = %r" % float(collisions)]
    if method != "dem":
        soft.append('collisions = "%s"' % method)
        soft.append("table_cache = %s" % json.dumps(cache))
    return "\n".join([
        "[system]", "particles = %d" % particles, "packing_fraction = %r" % ETA,
        'lattice = "random"', "temperature = %r" % T0, "seed = %d" % seed, "",
        "[soft]"] + soft + ["", "[run]"] + run + [
        "", "[output]", "thermo_interval = %r" % thermo_interval, "trajectory = false",
        'progress = "never"', ""])


def read_thermo(path):
    """thermo.tsv -> dict of numpy columns (the text column `phase` left out)."""
    with open(path) as f:
        lines = [ln.rstrip("\n").split("\t") for ln in f if not ln.startswith("#") and ln.strip()]
    header, rows = lines[0], lines[1:]
    out = {}
    for i, name in enumerate(header):
        try:
            out[name] = np.array([float(r[i]) for r in rows])
        except ValueError:
            pass
    return out


run_one = cached_runs.run_one


class RunSet:
    """The thermo curves of one (model, method) over the seeds."""

    def __init__(self, outdirs):
        self.thermo = [read_thermo(os.path.join(d, "thermo.tsv")) for d in outdirs]
        self.summaries = [json.load(open(os.path.join(d, "summary.json"))) for d in outdirs]

    def temperatures(self, column, energy):
        """Per run: (x, T) with x = `time` or `collisions_per_particle`; energy: T_E."""
        out = []
        for th, summary in zip(self.thermo, self.summaries):
            t = th["temperature"].copy()
            if energy:  # over every degree of freedom, D (N - 1)
                t = 2.0 * (th["kinetic_energy"] + th["potential_energy"]) / (
                    3.0 * (summary["particles"] - 1))
            out.append((th[column], t))
        return out

    def max_x(self, column):
        return min(th[column][-1] for th in self.thermo)

    def on_grid(self, column, grid, energy=False):
        """(seeds, len(grid)) array: each run's T interpolated (log T linear in x)."""
        return np.array([np.exp(np.interp(grid, x, np.log(t)))
                         for x, t in self.temperatures(column, energy)])


def mean_err(a):
    return a.mean(axis=0), a.std(axis=0, ddof=1) / math.sqrt(a.shape[0])


def compare(a, b):
    """Seed-averaged difference a - b (relative to b's mean), with the unpaired and paired
    errors (same relative scale)."""
    ma, ea = mean_err(a)
    mb, eb = mean_err(b)
    d = a - b
    md, ed = mean_err(d)
    return md / mb, np.sqrt(ea ** 2 + eb ** 2) / mb, ed / mb


# ------------------------------------------------------------------------------------------------

def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("kairos")
    p.add_argument("-o", "--output", default="soft-cooling")
    p.add_argument("--particles", type=int, default=2000)
    p.add_argument("--seeds", type=int, default=24)
    p.add_argument("--collisions", type=float, default=30.0,
                   help="collisions per particle of each run")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--no-dashpot", action="store_true", help="skip the constant-e contrast")
    p.add_argument("--dashpot-seeds", type=int, default=8,
                   help="seeds of the constant-e contrast (the first ones)")
    p.add_argument("--figure", default=None, help="PNG path (default OUTPUT/soft_cooling.png)")
    args = p.parse_args()
    kairos = os.path.abspath(args.kairos)
    out = os.path.abspath(args.output)
    cache = os.path.join(out, "table-cache")
    os.makedirs(cache, exist_ok=True)

    theory = ViscoelasticTheory()
    phi0 = theory.phi(T0)
    e0 = math.sqrt(1.0 - phi0)
    print("viscoelastic law: e(%g) = %g, c_dis(%g) = %.6f; e at v = 1, 4: %.4f, %.4f"
          % (RESTITUTION_SPEED, float(theory.e(RESTITUTION_SPEED)), RESTITUTION_SPEED,
             theory.c_ref, float(theory.e(1.0)), float(theory.e(4.0))))
    print("Maxwellian at T0: 1 - e0^2 = Phi(T0) = %.5f, e0 = %.5f" % (phi0, e0))

    seeds = list(range(1, args.seeds + 1))
    interval = args.collisions / 200.0
    jobs = {}
    cases = [("hertz", m) for m in METHODS]
    if not args.no_dashpot:
        cases += [("dashpot", "mapped"), ("dashpot", "dem")]
    for model, method in cases:
        for s in (seeds[:args.dashpot_seeds] if model == "dashpot" else seeds):
            d = os.path.join(out, "runs", "%s-%s-%d" % (model, method, s))
            jobs[(model, method, s)] = (d, run_config(model, method, s, args.particles,
                                                      args.collisions, interval, cache,
                                                      restitution=round(e0, 6)))
    t_start = time.time()
    walls = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(run_one, kairos, d, text): key for key, (d, text) in jobs.items()}
        for fut in concurrent.futures.as_completed(futures):
            key = futures[fut]
            _, wall = fut.result()
            walls[key] = wall
            if wall > 0:
                print("  %-8s %-13s seed %2d: %6.1f s" % (key + (wall,)), flush=True)
    print("runs: %.0f s wall" % (time.time() - t_start))

    sets = {(model, method): RunSet([jobs[(model, method, s)][0] for s in seeds
                                     if (model, method, s) in jobs])
            for model, method in cases}
    hertz = {m: sets[("hertz", m)] for m in METHODS}

    # Common grids: c from 0 to the shortest run, t up to the earliest end.
    c_end = min(rs.max_x("collisions_per_particle") for rs in sets.values())
    t_end = min(rs.max_x("time") for rs in hertz.values())
    cgrid = np.linspace(0.0, c_end, 201)
    tgrid = np.linspace(0.0, t_end, 201)

    curves = {"c": cgrid, "t": tgrid}
    for (model, method), rs in sets.items():
        for col, grid, tag in (("collisions_per_particle", cgrid, "c"), ("time", tgrid, "t")):
            if model == "dashpot" and tag == "t":
                grid_d = np.linspace(0.0, min(r.max_x("time") for (mm, _), r in sets.items()
                                              if mm == "dashpot"), 201)
                curves["t_dashpot"] = grid_d
                grid = grid_d
            for energy in (False, True):
                a = rs.on_grid(col, grid, energy)
                curves[(model, method, tag, energy)] = a

    theo = {"c": theory.curve_c(cgrid), "t": theory.curve_t(tgrid)}
    haff = {"c": haff_c(cgrid, phi0), "t": haff_t(tgrid, phi0)}

    # ---- report
    def row_points(grid, n=5):
        return [int(round(i)) for i in np.linspace(0, len(grid) - 1, n + 1)[1:]]

    lines = []
    for tag, grid, label in (("c", cgrid, "c"), ("t", tgrid, "t")):
        lines.append("")
        lines.append("T(%s): seed means +- error of the mean (%d seeds, N = %d); "
                     "differences relative to DEM, error paired (unpaired)" %
                     (label, len(seeds), args.particles))
        lines.append("| %s | DEM | mapped | instantaneous | mapped − DEM | instantaneous − DEM | "
                     "kinetic theory e(v) | Haff, e0 |" % label)
        lines.append("|---|---|---|---|---|---|---|---|")
        energy = True
        dem_m, dem_e = mean_err(curves[("hertz", "dem", tag, energy)])
        stats = {}
        for m in ("mapped", "instantaneous"):
            stats[m] = compare(curves[("hertz", m, tag, energy)],
                               curves[("hertz", "dem", tag, energy)])
        for i in row_points(grid):
            cells = ["%.4g" % grid[i], "%.4f ± %.4f" % (dem_m[i], dem_e[i])]
            for m in ("mapped", "instantaneous"):
                mm, ee = mean_err(curves[("hertz", m, tag, energy)])
                cells.append("%.4f ± %.4f" % (mm[i], ee[i]))
            for m in ("mapped", "instantaneous"):
                d, eu, ep = stats[m]
                cells.append("%+.2f %% ± %.2f (%.2f) %%" % (100 * d[i], 100 * ep[i], 100 * eu[i]))
            cells.append("%.4f" % theo[tag][i])
            cells.append("%.4f" % haff[tag][i])
            lines.append("| " + " | ".join(cells) + " |")
        for m in ("mapped", "instantaneous"):
            for energy in (True, False):
                d, eu, ep = compare(curves[("hertz", m, tag, energy)],
                                    curves[("hertz", "dem", tag, energy)])
                sel = slice(len(grid) // 10, None)  # the runs of a seed have decorrelated
                zp = np.abs(d[sel]) / ep[sel]
                zu = np.abs(d[sel]) / eu[sel]
                lines.append("%s − DEM in %s (%s): max |diff| %.2f %%; beyond %s = %.3g: max "
                             "|diff|/paired err %.2f, /unpaired err %.2f, mean diff/paired err "
                             "%+.2f; end: %+.2f %% ± %.2f (%.2f) %%" %
                             (m, label, "T_E" if energy else "kinetic T",
                              100 * np.max(np.abs(d)), label, grid[sel.start], zp.max(), zu.max(),
                                            np.mean(d[sel] / ep[sel]), 100 * d[-1],
                                            100 * ep[-1], 100 * eu[-1]))
        for m in METHODS:
            mm, ee = mean_err(curves[("hertz", m, tag, True)])
            lines.append("%s at the end: T = %.4f ± %.4f, %.3f × Haff (e0), %+.2f %% ± %.2f %% "
                         "from the kinetic theory with e(v)" %
                         (m, mm[-1], ee[-1], mm[-1] / haff[tag][-1],
                          100 * (mm[-1] / theo[tag][-1] - 1), 100 * ee[-1] / theo[tag][-1]))
    if not args.no_dashpot:
        lines.append("")
        lines.append("constant-e dashpot (e = %.5f) against Haff:" % e0)
        for m in ("mapped", "dem"):
            for tag in ("c", "t"):
                grid = cgrid if tag == "c" else curves["t_dashpot"]
                h = haff_c(grid, phi0) if tag == "c" else haff_t(grid, phi0)
                mm, ee = mean_err(curves[("dashpot", m, tag, True)])
                z = (mm - h)[1:] / ee[1:]
                lines.append("  %s in %s: end T = %.4f ± %.4f vs Haff %.4f (%+.2f %%), "
                             "max |T - Haff| / err = %.1f" %
                             (m, tag, mm[-1], ee[-1], h[-1], 100 * (mm[-1] / h[-1] - 1),
                              np.max(np.abs(z))))
        d, eu, ep = compare(curves[("dashpot", "mapped", "c", True)],
                            curves[("dashpot", "dem", "c", True)])
        lines.append("  mapped − DEM in c: end %+.2f %% ± %.2f (%.2f) %%, max |diff|/paired err %.2f"
                     % (100 * d[-1], 100 * ep[-1], 100 * eu[-1],
                        np.max(np.abs(d[1:]) / ep[1:])))
    lines.append("")
    lines.append("cost per run (wall s, mean over seeds, this invocation): " + ", ".join(
        "%s %s %.1f" % (mo, me, np.mean([w for k, w in walls.items() if k[:2] == (mo, me)]))
        for mo, me in cases))
    for m in ("mapped", "instantaneous"):
        s = sets[("hertz", m)].summaries[0]
        soft = s.get("soft", {})
        lines.append("%s seed 1: exceptions A %.2e, B %.2e per collision, direct maps %.2e" %
                     (m, soft.get("exception_a_fraction", float("nan")),
                      soft.get("exception_b_fraction", float("nan")),
                      soft.get("direct_map_fraction", float("nan"))))
    s = sets[("hertz", "dem")].summaries[0]
    lines.append("dem seed 1: time step %.3g" % s["dem"]["time_step"])
    print("\n".join(lines))

    # ---- TSV
    tsv = os.path.join(out, "soft_cooling.tsv")
    with open(tsv, "w") as f:
        f.write("# soft_cooling.py: N = %d, eta = %g, %d seeds, Hertz young = %g, e(%g) = %g; "
                "T = T_E (kinetic + contact energy); err = seed spread / sqrt(seeds)\n" %
                (args.particles, ETA, len(seeds), YOUNG, RESTITUTION_SPEED, RESTITUTION))
        for tag, grid in (("c", cgrid), ("t", tgrid)):
            cols = [("x_" + tag, grid)]
            for m in METHODS:
                mm, ee = mean_err(curves[("hertz", m, tag, True)])
                cols += [(m, mm), (m + "_err", ee)]
            for m in ("mapped", "instantaneous"):
                d, eu, ep = compare(curves[("hertz", m, tag, True)],
                                    curves[("hertz", "dem", tag, True)])
                cols += [(m + "_minus_dem_rel", d), (m + "_minus_dem_err_paired", ep),
                         (m + "_minus_dem_err_unpaired", eu)]
            cols += [("theory_ev", theo[tag]), ("haff_e0", haff[tag])]
            if not args.no_dashpot and tag == "c":
                for m in ("mapped", "dem"):
                    mm, ee = mean_err(curves[("dashpot", m, "c", True)])
                    cols += [("dashpot_" + m, mm), ("dashpot_" + m + "_err", ee)]
            f.write("# block %s\n" % tag)
            f.write("\t".join(name for name, _ in cols) + "\n")
            for i in range(len(grid)):
                f.write("\t".join("%.8g" % v[i] for _, v in cols) + "\n")
    print("wrote", tsv)

    figure = args.figure or os.path.join(out, "soft_cooling.png")
    plot(curves, theo, haff, cgrid, tgrid, phi0, e0, args, len(seeds), figure)
    print("wrote", figure)


def plot(curves, theo, haff, cgrid, tgrid, phi0, e0, args, nseeds, figure):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"dem": "black", "mapped": "tab:blue", "instantaneous": "tab:orange"}
    labels = {"dem": "DEM (reference)", "mapped": "event-driven, mapped",
              "instantaneous": "event-driven, instantaneous e(v)"}
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), sharex="col",
                             gridspec_kw={"height_ratios": [2, 1]})
    for col, (tag, grid, xlabel) in enumerate((("t", tgrid, "time t"),
                                               ("c", cgrid, "collisions per particle c"))):
        ax, axd = axes[0, col], axes[1, col]
        for m in METHODS:
            mm, ee = mean_err(curves[("hertz", m, tag, True)])
            ax.plot(grid, mm, color=colours[m], lw=1.2 if m == "dem" else 1.0,
                    ls="-" if m != "instantaneous" else "--", label=labels[m])
        ax.plot(grid, theo[tag], color="tab:green", ls=":", lw=1.5,
                label="kinetic theory with e(v)")
        ax.plot(grid, haff[tag], color="tab:red", ls="-.", label="Haff, constant e0 = %.3f" % e0)
        if tag == "c" and ("dashpot", "dem", "c", True) in curves:
            mm, _ = mean_err(curves[("dashpot", "dem", "c", True)])
            ax.plot(grid, mm, color="grey", lw=3, alpha=0.4,
                    label="dashpot, e = e0 (DEM)")
        ax.set_yscale("log")
        ax.set_ylabel("temperature T")
        ax.legend(fontsize=8)
        ax.set_title("Hertz gas, N = %d, η = %g, %d seeds" % (args.particles, ETA, nseeds),
                     fontsize=10)
        for m in ("mapped", "instantaneous"):
            d, eu, ep = compare(curves[("hertz", m, tag, True)], curves[("hertz", "dem", tag, True)])
            axd.plot(grid, 100 * d, color=colours[m], label=labels[m] + " − DEM")
            axd.fill_between(grid, -200 * ep, 200 * ep, color=colours[m], alpha=0.15, lw=0)
        axd.axhline(0, color="black", lw=0.5)
        axd.set_ylabel("(T − T_DEM) / T_DEM  [%]")
        axd.set_xlabel(xlabel)
        axd.legend(fontsize=8, title="bands: ±2 paired errors", title_fontsize=8)
    fig.tight_layout()
    fig.savefig(figure, dpi=110)


if __name__ == "__main__":
    sys.exit(main())
