#!/usr/bin/env python3
"""The discharge rate of a 2D silo against Beverloo's law (a recirculating [boundary.outlet]).

A flat-bottomed 2D silo L = 50 d wide holds 3000 rough inelastic disks under g = 1: five sizes
0.8, 0.9, 1.0, 1.1, 1.2 in equal numbers (mean diameter d = 1, mass = diameter^2, so a uniform
material density 4/pi), restitution 0.8, Coulomb friction 0.5, tangential restitution 0.4, the
TC model at tc = 1e-3, sleeping off (a sleeper stays where it is when the grains under it flow
away, and would hang over a void). The floor (y = 10) is two [[boundary.plane]] strips
(span_axis = "x") leaving a centred orifice of width D; a disk whose centre crosses the outlet
plane y = 9.5 is put back at a random free place of a band 20 d tall around the top of the bed,
moving down at speed 2 (it leaves the band sooner, which keeps it from filling up), so the silo
discharges at a constant fill: the bed is 58.6 d high at rest (1.17 L), about 57 while flowing.

One settling run (the disks spread through the silo by system.fill_inside fall onto a closed
floor) gives the start of every width: its restart.gsd. Each discharge then has an equilibration
of 20 time units (the rate, in blocks of 5, is steady after 10) and a production of 80.

For each width D (8 to 16 d; the silo width L = 50 d keeps to L > 2.5 D and L > D + 30 d, the
conditions under which the rate does not depend on L quoted by Mankoc et al. 2007; measured: at
D = 16 a silo 70 d wide (4200 disks) gives 74.6 +- 0.5 against 75.7 +- 0.3 here):
- the mass rate W: the cumulative outlet_mass of thermo.tsv (one row per time unit) over the
  production, divided by its length; its error: the standard error of the rates of 10 independent
  time blocks; the rates of the first and second halves, and their difference in its error
  ("drift"), show the flow steady (the mass grows linearly in time). The disks per unit time
  (outlet_passes) are printed too;
- the bulk packing fraction phi_b: profile.tsv's packing fraction (output.profile_axis = "y",
  averaged over the production rows) between y = 12 and y = 30, over the silo's width (dead zones
  and flowing channel), and the bed's height: where that profile falls to half of phi_b.

Fit (weighted least squares, weights 1/error^2): W = A (D - k d)^{3/2}, the 2D form of Beverloo's
law W = C rho_b sqrt(g) (D - k d)^{3/2} (3/2 in 2D for Beverloo's 5/2 in 3D: the flux through a
slot of width D ~ rho_b D sqrt(g D)), with rho_b = phi_b * 4/pi the bulk mass per unit area, so
C = A / (rho_b sqrt(g)). The chi-square (N - 2 degrees of freedom) says whether the law
describes the points within their errors; W = A' (D - k' d)^beta with beta free is fitted too.

Why polydisperse: with monodisperse disks the bed crystallises, and the rate depends on the
crystal near the orifice, which lasts longer than a run: at D = 10 two seeds gave 27.1 +- 0.6 and
31.0 +- 0.6 disks per unit time (the errors from time blocks), 5 sigma apart. With the five sizes,
two seeds give 34.56 +- 0.18 and 34.15 +- 0.29 (mass rate), 1.2 sigma apart: the block errors
hold. Carlevaro et al. 2024 found that ordering does not change the mean rate much, but the
memory matters for the errors. The rate depends on tc (the TC model makes the collisions in
dense flow elastic): tc = 1e-4 gives 19.55 +- 0.25 at D = 8 and 66.3 +- 0.5 at D = 16 against
23.58 +- 0.38 and 75.66 +- 0.33 here (17 % and 12 % lower; from these two widths k would be
about 1.6 +- 0.3 instead of 1.3), at 10 times the cost; tc = 1e-3 is what the time budget allows.

References found (searched for, read as abstracts and opening pages; values quoted only where
read):
- W. A. Beverloo, H. A. Leniger, J. van de Velde, "The flow of granular solids through orifices",
  Chem. Eng. Sci. 15, 260-269 (1961): the law W = C rho_b sqrt(g) (D - k d)^{5/2} (3D, circular
  orifices); its fitted C and k were not in the material found.
- C. Mankoc, A. Janda, R. Arevalo, J. M. Pastor, I. Zuriguel, A. Garcimartin, D. Maza, "The flow
  rate of granular materials through an orifice", Granular Matter 9, 407 (2007),
  doi:10.1007/s10035-007-0062-2 (arXiv:0707.4550): 3D and 2D experiments and simulations; the
  rate does not depend on the fill height above about 1.2 silo widths (Janssen) nor on the silo
  width L if L > 2.5 D and L > D + 30 d; Beverloo's law fits only a limited range of D, and they
  propose a law with an exponential correction at small D (their 2D fitted values were not
  read).
- A. Janda, I. Zuriguel, D. Maza, "Flow rate of particles through apertures obtained from
  self-similar density and velocity profiles", Phys. Rev. Lett. 108, 248001 (2012): 2D silo (the
  reference was found, its fitted values were not).
- Y. Cheng, J. D. Treado, B. F. Lonial, P. Habdas, E. R. Weeks, M. D. Shattuck, C. S. O'Hern,
  "Hopper flows of deformable particles", Soft Matter (2022) (arXiv:2208.05581): Beverloo's
  Q ~ (w/sigma - k)^beta with beta = d - 1/2 (3/2 in 2D); k grows with the particles' stiffness
  up to k_max ~ 3.5 for hard particles (hoppers, 2D and 3D simulations).
- C. M. Carlevaro, R. Kozlowski, L. A. Pugnaloni, "Flow rate in 2D silo discharge of binary
  granular mixtures: the role of ordering in monosized systems", Front. Soft Matter 4, 1340744
  (2024): the hexagonal order of monosized disks does not affect the flow rate significantly.

    python3 examples/validation/silo_beverloo.py build/kairos [--quick] [--json [FILE]] [--keep DIR]

prints the table and the fits; --json writes them as JSON (to silo_beverloo.json next to this
script when no FILE is given); --keep DIR keeps the runs in DIR.

About 7 minutes on one core (425 s; --quick: widths 8, 12, 16 and a production of 30, 155 s).
Measured: k = 1.27 +- 0.09, A = 1.337 +- 0.016, C = 1.295 +- 0.015 (phi_b = 0.811), chi2 = 2.7
for 3 degrees of freedom; with the exponent free, 1.63 (k = 0.34).
"""

import argparse
import json
import math
import os
import tempfile
import time

import numpy as np

from cached_runs import run_one

WIDTH = 50.0  # the silo's inner width (x from 0 to WIDTH)
FLOOR = 10.0  # the floor's height
PARTICLES = 3000
SETTLE_TIME = 20.0  # the settling run: the fall onto the closed floor
INSERT_SPEED = 2.0  # the passes are put back moving down at this speed (out of the band sooner)
FLOW_START = 20.0  # the discharge's equilibration: the rate is steady after about 10
BULK = (FLOOR + 2.0, FLOOR + 20.0)  # the band of y where phi_b is measured
WIDTHS = [8.0, 10.0, 12.0, 14.0, 16.0]
QUICK_WIDTHS = [8.0, 12.0, 16.0]
BLOCKS = 10
SIZES = [0.8, 0.9, 1.0, 1.1, 1.2]  # equal numbers of each: mean diameter d = 1, mass = diameter^2
PHI0, STRETCH = 0.45, 1.6  # the generated state
JSON_DEFAULT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "silo_beverloo.json")


def box_width():
    """The box's width along x (the generated square's edge plus one diameter for the walls)."""
    return math.sqrt(PARTICLES * math.pi / 4.0 / PHI0) + 1.0


def config(orifice=None, production=1.0, start="", band=None, seed=1, friction=0.5, tc=1e-3):
    """The TOML of the silo.

    orifice None: the settling run. The disks are generated at packing fraction PHI0 in a square
    box (73 d wide) at the bottom of a box STRETCH times taller; those right of the silo's wall
    at x = WIDTH or below the floor are moved by fill_inside to free places inside (most in the
    empty space above); they fall onto a closed floor and settle (sleeping on) during SETTLE_TIME
    time units, and a production of 1 time unit gives the bed's profile.

    orifice D: the discharge. The settled bed (`start`, the settling run's restart.gsd) over a
    floor with an orifice of width D, sleeping off (a sleeper would stay where it is when the
    grains under it flow away, hanging over a void), the passes put back in the band
    `band` = (y_low, y_high) around the bed's top; FLOW_START time units of equilibration, then
    `production`."""
    height = STRETCH * box_width()
    if orifice is None:
        system = f"""particles = {PARTICLES}
packing_fraction = {PHI0}
lattice = "random"
temperature = 1.0
box_scale = [1.0, {STRETCH}]
fill_inside = true
""" + "".join(f"""
[[system.species]]
name = "{chr(65 + i)}"
diameter = {size!r}
mass = {round(size * size, 6)!r}
""" for i, size in enumerate(SIZES))
        floor = f"""[[boundary.plane]]       # the floor, closed
normal = [0.0, 1.0]
point = [0.0, {FLOOR}]
"""
        lengths = f"equilibration_time = {SETTLE_TIME}\ntime = 1.0"
    else:
        lo, hi = WIDTH / 2 - orifice / 2, WIDTH / 2 + orifice / 2
        system = f'initial_state = "{start}"'
        floor = f"""[[boundary.plane]]       # the floor, left of the orifice
normal = [0.0, 1.0]
point = [0.0, {FLOOR}]
span_axis = "x"
span_max = {lo!r}

[[boundary.plane]]       # and right of it
normal = [0.0, 1.0]
point = [0.0, {FLOOR}]
span_axis = "x"
span_min = {hi!r}

[boundary.outlet]
normal = [0.0, 1.0]
point = [0.0, {FLOOR - 0.5}]
insert_lower = [1.0, {band[0]:.3f}]
insert_upper = [{WIDTH - 1.0}, {band[1]:.3f}]
insert_velocity = [0.0, {-INSERT_SPEED}]
seed = {seed}
"""
        lengths = f"equilibration_time = {FLOW_START}\ntime = {production}"
    return f"""[system]
dimension = 2
seed = {seed}
{system}

[contact]
restitution = 0.8
tangential_restitution = 0.4
friction = {friction}
tc = {tc}
sleep_speed = 0.0

[[boundary.wall]]
face = "x-"
[[boundary.wall]]
face = "x+"
[[boundary.wall]]
face = "y-"
[boundary]
open = ["y+"]

[[boundary.plane]]       # the silo's right wall (x- is the left one)
normal = [-1.0, 0.0]
point = [{WIDTH}, 0.0]

{floor}
[field]
gravity = [0.0, -1.0]

[run]
{lengths}
validate = false

[output]
thermo_interval = 1.0
interval_unit = "time"
trajectory = false
progress = "never"
profile_axis = "y"
profile_bins = {int(height)}
"""


def run(kairos, directory, name, text):
    return run_one(kairos, os.path.join(directory, name), text, overwrite=True)


def read_tsv(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    header = lines[0].split()
    rows = [line.split() for line in lines[1:] if line.strip()]
    return header, rows


def rate(out, column="outlet_mass", blocks=BLOCKS):
    """(W, its error from `blocks` time blocks, first-half rate, second-half rate) over the
    production rows of thermo.tsv, from the cumulative `column` (outlet_mass: the mass rate;
    outlet_passes: disks per unit time)."""
    header, rows = read_tsv(os.path.join(out, "thermo.tsv"))
    ph, ti, pa = header.index("phase"), header.index("time"), header.index(column)
    t = np.array([float(r[ti]) for r in rows if r[ph] == "production"])
    n = np.array([float(r[pa]) for r in rows if r[ph] == "production"])
    # the production starts at the last equilibration row
    eq = [(float(r[ti]), float(r[pa])) for r in rows if r[ph] != "production"]
    if eq and eq[-1][0] < t[0]:
        t, n = np.concatenate([[eq[-1][0]], t]), np.concatenate([[eq[-1][1]], n])

    def rates(k):
        edges = np.linspace(t[0], t[-1], k + 1)
        return np.diff(np.interp(edges, t, n)) / np.diff(edges)

    r = rates(blocks)
    halves = rates(2)
    return (n[-1] - n[0]) / (t[-1] - t[0]), r.std(ddof=1) / math.sqrt(blocks), halves[0], halves[1]


def bed(out):
    """(phi_b, the bed's height above the floor) from profile.tsv: the packing fraction of the
    slabs is of the whole box width, the disks are in the silo's."""
    header, rows = read_tsv(os.path.join(out, "profile.tsv"))
    y = np.array([float(r[header.index("position")]) for r in rows])
    phi = np.array([float(r[header.index("packing_fraction")]) for r in rows]) * box_width() / WIDTH
    band = (y >= BULK[0]) & (y <= BULK[1])
    phi_b = phi[band].mean()
    above = np.nonzero((y > BULK[1]) & (phi < 0.5 * phi_b))[0]
    top = y[above[0]] if len(above) else float("nan")
    return phi_b, top - FLOOR


def fit(d, w, err, beta=1.5):
    """Weighted least squares of w = A (d - k)^beta over k (A linear): (A, k, chi2, the
    covariance of (A, k))."""
    def solve(k):
        x = (d - k) ** beta
        a = np.sum(w * x / err**2) / np.sum(x * x / err**2)
        return a, np.sum(((w - a * x) / err) ** 2)

    ks = np.linspace(-10.0, min(d) - 0.5, 4001)
    chi = [solve(k)[1] for k in ks]
    k = ks[int(np.argmin(chi))]
    for step in (1e-2, 1e-3, 1e-4, 1e-5):  # refine
        ks = np.linspace(k - 10 * step, k + 10 * step, 21)
        k = ks[int(np.argmin([solve(q)[1] for q in ks]))]
    a, chi2 = solve(k)
    # covariance from the Jacobian of the model at the minimum
    jac = np.stack([(d - k) ** beta, -a * beta * (d - k) ** (beta - 1)], axis=1) / err[:, None]
    cov = np.linalg.inv(jac.T @ jac)
    return a, k, chi2, cov


def fit_free(d, w, err):
    """w = A (d - k)^beta with beta free too: (A, k, beta, chi2)."""
    best = None
    for beta in np.linspace(1.0, 3.0, 201):
        a, k, chi2, _ = fit(d, w, err, beta)
        if best is None or chi2 < best[3]:
            best = (a, k, beta, chi2)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kairos")
    parser.add_argument("--quick", action="store_true",
                        help="widths 8, 12, 16 and a production of 30 time units")
    parser.add_argument("--json", metavar="FILE", nargs="?", const=JSON_DEFAULT,
                        help="write the results as JSON to FILE (without FILE: %s)"
                        % os.path.relpath(JSON_DEFAULT))
    parser.add_argument("--keep", metavar="DIR", help="run in DIR (kept) instead of a temporary "
                        "directory")
    args = parser.parse_args()
    widths = QUICK_WIDTHS if args.quick else WIDTHS
    production = 30.0 if args.quick else 80.0
    begin = time.monotonic()

    results = []
    with tempfile.TemporaryDirectory() as tmp:
        directory = args.keep or tmp
        os.makedirs(directory, exist_ok=True)
        bed_run, seconds = run(args.kairos, directory, "settle", config())
        phi_rest, top = bed(bed_run)
        top += FLOOR
        band = (top - 10.0, top + 10.0)
        print("  settled bed: phi = %.3f, top at y = %.1f (%.1f s)" % (phi_rest, top, seconds),
              flush=True)
        start = os.path.abspath(os.path.join(bed_run, "restart.gsd"))
        for orifice in widths:
            out, seconds = run(args.kairos, directory, "D%g" % orifice,
                               config(orifice, production, start, band))
            w, err, first, second = rate(out)
            disks, disks_err, _, _ = rate(out, "outlet_passes")
            phi_b, height = bed(out)
            results.append({"D": orifice, "rate": w, "error": err, "first_half": first,
                            "second_half": second, "disks_rate": disks,
                            "disks_rate_error": disks_err, "phi_b": phi_b,
                            "bed_height": height, "wall_seconds": seconds})
            print("  D = %4.1f: %.1f s" % (orifice, seconds), flush=True)

    d = np.array([r["D"] for r in results])
    w = np.array([r["rate"] for r in results])
    err = np.array([r["error"] for r in results])
    a, k, chi2, cov = fit(d, w, err)
    a_err, k_err = math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1])
    dof = len(d) - 2
    phi_b = float(np.mean([r["phi_b"] for r in results]))
    rho_b = phi_b * 4.0 / math.pi  # mass per unit area: the disks' material density is 4/pi
    c, c_err = a / rho_b, a_err / rho_b

    print()
    print("Silo %g d wide, %d disks (d = 0.8 to 1.2), g = 1; production %g time units, errors "
          "from %d blocks" % (WIDTH, PARTICLES, production, BLOCKS))
    print("W: mass per unit time; 1st, 2nd: its halves; drift: 2nd - 1st in sigma; "
          "pull: (W - fit) / err")
    print("%5s %9s %6s %8s %8s %6s %8s %6s %8s %6s %6s" % (
        "D/d", "W", "err", "1st", "2nd", "drift", "fit", "pull", "disks/t", "phi_b", "h_bed"))
    for r in results:
        model = a * (r["D"] - k) ** 1.5
        r["fit"] = model
        # the halves' difference in its error (each half's error is sqrt(2) times the whole's)
        r["drift_sigma"] = (r["second_half"] - r["first_half"]) / (2.0 * r["error"])
        print("%5.1f %9.3f %6.3f %8.2f %8.2f %6.2f %8.2f %6.2f %8.2f %6.3f %6.1f"
              % (r["D"], r["rate"], r["error"], r["first_half"], r["second_half"],
                 r["drift_sigma"], model, (r["rate"] - model) / r["error"], r["disks_rate"],
                 r["phi_b"], r["bed_height"]))
    print()
    print("W = A (D - k d)^(3/2):  A = %.4f +- %.4f, k = %.3f +- %.3f (correlation %.2f)"
          % (a, a_err, k, k_err, cov[0, 1] / (a_err * k_err)))
    print("chi2 = %.2f for %d degrees of freedom (P(chi2 >) = %.2g)"
          % (chi2, dof, chi2_sf(chi2, dof)))
    print("phi_b = %.3f, rho_b = phi_b 4/pi = %.3f:  C = A / (rho_b sqrt(g)) = %.3f +- %.3f"
          % (phi_b, rho_b, c, c_err))
    free = None
    if len(d) > 3:
        fa, fk, fbeta, fchi2 = fit_free(d, w, err)
        free = {"A": fa, "k": fk, "beta": fbeta, "chi2": fchi2, "dof": len(d) - 3}
        print("exponent free: W = %.3f (D - %.2f d)^%.2f, chi2 = %.2f for %d degrees of freedom"
              % (fa, fk, fbeta, fchi2, len(d) - 3))
    print("total %.0f s" % (time.monotonic() - begin))

    if args.json:
        with open(args.json, "w") as f:
            json.dump({"silo_width": WIDTH, "particles": PARTICLES, "sizes": SIZES,
                       "production": production, "blocks": BLOCKS, "points": results,
                       "fit": {"A": a, "A_err": a_err, "k": k, "k_err": k_err,
                               "correlation": cov[0, 1] / (a_err * k_err), "chi2": chi2,
                               "dof": dof, "phi_b": phi_b, "rho_b": rho_b, "C": c,
                               "C_err": c_err},
                       "exponent_free": free}, f, indent=1)
            f.write("\n")


def chi2_sf(x, dof):
    """P(chi2 > x) for dof degrees of freedom (the regularized upper incomplete gamma function,
    by its series), numpy only."""
    if dof <= 0:
        return float("nan")
    s, x2 = dof / 2.0, x / 2.0
    term = total = 1.0 / s
    n = 1
    while term > 1e-15 * total:
        term *= x2 / (s + n)
        total += term
        n += 1
    lower = math.exp(-x2 + s * math.log(x2) - math.lgamma(s)) * total if x2 > 0 else 0.0
    return max(0.0, 1.0 - lower)


if __name__ == "__main__":
    main()
