#!/usr/bin/env python3
"""The discharge of the 3D recirculating slot silo (examples/silo_3d.toml) against Beverloo's law
for a slot, W = C rho_b sqrt(g) L (D - k d)^{3/2}.

The example's silo and grains, unchanged but for the slot's width: 4000 monodisperse spheres
(d = m = 1, restitution 0.8, Coulomb friction 0.5, tangential restitution 0.4, the TC model at
tc = 1e-4, no sleeping) in a box 21.31 wide (x, walls), 20.31 deep (y, periodic) and 31.96 tall;
the floor at z = 6 is two [[boundary.plane]] strips (span_axis = "x") leaving a slot of width D
centred at x = 10.65 that runs through the whole periodic depth, so the slot's length is
L = 20.31; the outlet half a diameter below the floor puts every sphere that leaves back at rest
at a random free place of the region z = 16-22 (the whole width and depth), just above the bed
(about 8 d deep above the floor), so the fill stays put. Widths D = 4, 5, 6, 7, 8 d (the two
spans moved, the centre kept), 2 seeds each (system.seed = 1, 2), the example's 20 time units of
equilibration (the fall onto the floor and the start of the flow) and 60 of production.

For each run:
- the rate: thermo.tsv's cumulative outlet_passes (one row per time unit; mass 1, so passes are
  the mass too) over the production (from the last equilibration row on), divided by its length
  and by L: W/L, spheres (= mass) per unit time and unit length of slot; its error: the standard
  error of the rates of 10 time blocks; the first and second halves' rates and their difference
  in its error ("drift") show whether the flow is steady; the longest run of rows without a
  pass ("stall") shows a clog (none is expected through a slot 20 d long);
- the bed's packing fraction phi_b, from the trajectory frames of the production (every 5 time
  units): the fraction of a region of the bed away from the slot and the walls (x at least
  6 d from the slot's centre line and 1.5 d from the walls, z = 7.5 to 12.5, i.e. 1.5 to 6.5 d
  above the floor, the whole depth: the stagnant shoulders beside the slot, the same region at
  every width) that lies inside a sphere, by 200 000 random points per frame (a k-d tree,
  periodic in y; 0.001 per frame). Not the count of centres in the region times pi/6: the
  spheres are layered against the walls and the floor (the second layer's centres lie at 1.3
  to 1.5 d from a wall), so a count of centres depends on where the region's edges cut the
  layers, 0.554 to 0.61 in the same frames for edges moved by half a diameter; the volume
  inside the region much less (0.595 to 0.606 for the same edges). (profile.tsv's packing
  fraction over the same z, output.profile_axis = "z", is over the whole width with the
  flowing channel and is printed for comparison; it also gives the bed's top, where it falls
  below half of phi_b.)

Seeds combined as in silo_event_vs_dem.py: the mean, whose error is the larger of the block
errors' (root sum of squares over the number of seeds) and the seeds' scatter (their standard
deviation over sqrt(seeds)). Fit (scipy curve_fit, sigma = those errors, absolute_sigma):
W/L = A (D - k d)^{3/2}, with rho_b = phi_b 6/pi (the spheres' material density is 6/pi) and
g = 1: C = A / rho_b, phi_b the mean of the runs' values (its spread over the widths added to
C's error); chi2 for N - 2 degrees of freedom, and the pulls (W/L - fit) / error. The exponent
is also freed (W/L = A' (D - k')^beta, 2 degrees of freedom left) for comparison.

The width check (skipped with --no-wide): Mankoc et al. (Granular Matter 9, 407 (2007)) quote a
silo width above 2.5 D and D + 30 d for the rate not to depend on the silo's width; the example
is 21.3 d wide, which fails D + 30 d at every D here. One run at D = 6 in a silo 43.9 d wide
(> 36 = D + 30 d): 12000 spheres generated at the same packing fraction 0.25 in a cube 29.29
wide (so the slot is 29.29 long: W/L is compared), the box stretched to 1.45 x 1.0 x 1.25 of it
(43.92 x 29.29 x 37.86, the cube centred in x and at the top), the floor at z = 6 and the bed
about as deep as in the example (8 d), the slot centred at x = 21.96, the insertion region
z = 16-22 over the whole width and depth, 30 time units of equilibration (the wider heap must
level out) and 60 of production.

    nice -n 5 /usr/bin/python3 examples/validation/silo_3d_beverloo.py build/kairos \
        [--widths 4 5 6 7 8] [--seeds 2] [--production 60] [--no-wide] [--keep DIR] [--json F]

--keep DIR keeps the runs in DIR (and reuses a finished run whose input.toml is unchanged, so
the analysis can be redone without running again). One kairos runs at a time.

Run time: 36 minutes of kairos (2181 s, on 2 cores shared with other jobs, kairos niced): the ten
runs 28 to 304 s (the narrow slots are the slow ones: 206 million events at D = 4 against 36
million at D = 8), the wide silo 892 s (811 million events); the analysis 30 s. The widths 5.5,
6.5 and 7.5 below: 396 s more.

Measured (2 seeds, production 60, 10 blocks):
  D/d  W/L               fit     pull   phi_b
  4    3.990 +- 0.020    3.951   +2.0   0.602
  5    6.544 +- 0.029    6.645   -3.5   0.595
  6    9.626 +- 0.041    9.768   -3.4   0.584
  7   13.467 +- 0.035   13.269   +5.8   0.566
  8   17.021 +- 0.039   17.110   -2.3   0.544
W/L = A (D - k d)^{3/2}: A = 1.053 +- 0.005, k = 1.586 +- 0.013 (correlation 0.94), chi2 = 66.6
for 3 dof (22 per dof): the law does not describe the rates within their 0.2-0.5 % errors (the
seeds agree with the block errors, within 0.4 to 2.1 of them); exponent free 1.55 +- 0.04,
chi2 64.6 for 2. C = A / rho_b = 0.954 +- 0.018 with phi_b = 0.578 (the mean; 0.916 with
D = 4's 0.602, 1.014 with D = 8's 0.544: the shoulders dilate as the slot widens, for the silo
is only 2.7 to 5.3 slot widths wide). Widths 5.5, 6.5 and 7.5 added (--widths 4 5 5.5 6 6.5 7
7.5 8) follow the same smooth curve (chi2 151 for 6 dof, residuals +4, -3, -5, -4, +1, +4, +6,
-6): no step at integer widths; the rate's growth per half diameter rises from 1.5 to 1.9 and
falls back to 1.6 between 7.5 and 8, the silo starting to limit it. D <= 6 alone: k = 1.49 +-
0.02, A = 1.002 +- 0.011, chi2 2.9 for 1 dof.
Width check (D = 6): the silo 43.9 d wide gives W/L = 8.796 +- 0.030 against 9.626 +- 0.041,
8.6 % (16 sigma) lower (its phi_b 0.596 against 0.584): the example's silo (21.3 d, below
D + 30 d) is too narrow for Beverloo's width-independent regime, and its C and k are those of
this silo, not of the material. The bed is also shallow (8.5 d above the floor at D <= 5, 7.5
at D >= 6, against a Janssen length of about 1.2 silo widths), a second departure from the
law's conditions that was not varied.
No published C or k for a slot orifice was reached by the literature search (Mankoc et al.
2007 give the width conditions; Beverloo et al. 1961 the law for circular orifices).
"""

import argparse
import json
import math
import os
import re
import tempfile
import time

import numpy as np
from scipy.optimize import curve_fit
from scipy.stats import chi2 as chi2_dist

from cached_runs import run_one

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLE = os.path.join(HERE, "..", "silo_3d.toml")
FLOOR = 6.0
EQUILIBRATION = 20.0
BLOCKS = 10
TRAJ_INTERVAL = 5.0
# phi_b region: at least this far from the slot's centre line and from the x walls, this z band
SLOT_CLEARANCE, WALL_CLEARANCE, BAND = 6.0, 1.5, (FLOOR + 1.5, FLOOR + 6.5)
SPHERE = math.pi / 6.0  # the sphere's volume (d = 1); mass 1: material density 6/pi
POINTS = 200000  # random points per frame for phi_b
# The wide silo of the width check
WIDE_PARTICLES, WIDE_SCALE, WIDE_EQUILIBRATION = 12000, (1.45, 1.0, 1.25), 30.0


def cube_edge(particles, phi=0.25):
    """The edge of the cube the example's state is generated in (packing fraction 0.25)."""
    return (particles * SPHERE / phi) ** (1.0 / 3.0)


def geometry(wide=False):
    """(box width along x, slot length L = the periodic depth) of the example or the wide silo."""
    if wide:
        edge = cube_edge(WIDE_PARTICLES)
        return (edge + 1.0) * WIDE_SCALE[0], edge
    edge = cube_edge(4000)
    return edge + 1.0, edge


def config(width, seed, production, wide=False):
    """The example's TOML with the slot `width` wide (centred), system.seed = seed, the
    production `production` long, frames every TRAJ_INTERVAL and a z profile; `wide`: the wide
    silo of the width check."""
    with open(EXAMPLE) as f:
        text = f.read()
    box_x, depth = geometry(wide)
    centre = 0.5 * box_x
    subs = [(r"seed = 7\n", f"seed = {seed}\n"),
            (r"span_max = 7\.65\n", f"span_max = {centre - 0.5 * width:.4f}\n"),
            (r"span_min = 13\.65\n", f"span_min = {centre + 0.5 * width:.4f}\n"),
            (r"\ntime = 30\n", f"\ntime = {production:g}\n"),
            (r"trajectory_interval = 10\n", f"trajectory_interval = {TRAJ_INTERVAL:g}\n")]
    if wide:
        subs += [(r"particles = 4000\n", f"particles = {WIDE_PARTICLES}\n"),
                 (r"box_scale = \[1\.0, 1\.0, 1\.5\]\n",
                  "box_scale = [%r, %r, %r]\n" % WIDE_SCALE),
                 (r"box_place = \[0\.0, 0\.0, 1\.0\]\n", "box_place = [0.5, 0.0, 1.0]\n"),
                 (r"insert_upper = \[20\.3, 20\.3, 22\.0\]\n",
                  f"insert_upper = [{box_x - 1.0:.3f}, {depth - 0.01:.3f}, 22.0]\n"),
                 (r"equilibration_time = 20\n",
                  f"equilibration_time = {WIDE_EQUILIBRATION:g}\n")]
    for pattern, new in subs:
        text, n = re.subn(pattern, new, text)
        assert n == 1, pattern
    assert text.rstrip().splitlines()[-1].startswith("trajectory_interval")  # [output] is last
    text += 'progress = "never"\nprofile_axis = "z"\nprofile_bins = %d\n' % round(
        (cube_edge(WIDE_PARTICLES if wide else 4000) + 1.0) * (WIDE_SCALE[2] if wide else 1.5))
    return text


def run(kairos, outdir, text):
    """cached_runs.run_one (a finished run of the same input is reused: 0 s), its wall seconds
    also kept in outdir/wall_seconds for a later reuse to report."""
    _, seconds = run_one(kairos, outdir, text, overwrite=True)
    if seconds > 0.0:
        with open(os.path.join(outdir, "wall_seconds"), "w") as f:
            f.write("%.1f\n" % seconds)
    return seconds


def read_tsv(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#") and line.strip()]
    header = lines[0].split()
    return header, [line.split() for line in lines[1:]]


def rate(out, length):
    """Production rate per unit length of slot from thermo.tsv's outlet_passes: (W/L, block
    error, first half, second half, longest stall in time units, production length)."""
    header, rows = read_tsv(os.path.join(out, "thermo.tsv"))
    ph, ti, pa = header.index("phase"), header.index("time"), header.index("outlet_passes")
    t = np.array([float(r[ti]) for r in rows if r[ph] == "production"])
    n = np.array([float(r[pa]) for r in rows if r[ph] == "production"])
    eq = [(float(r[ti]), float(r[pa])) for r in rows if r[ph] != "production"]
    if eq and eq[-1][0] < t[0]:  # the production starts at the last equilibration row
        t, n = np.concatenate([[eq[-1][0]], t]), np.concatenate([[eq[-1][1]], n])

    def rates(k):
        edges = np.linspace(t[0], t[-1], k + 1)
        return np.diff(np.interp(edges, t, n)) / np.diff(edges) / length

    blocks, halves = rates(BLOCKS), rates(2)
    zero = np.diff(n) == 0
    stall, run_ = 0, 0
    for z in zero:
        run_ = run_ + 1 if z else 0
        stall = max(stall, run_)
    w = (n[-1] - n[0]) / (t[-1] - t[0]) / length
    return w, blocks.std(ddof=1) / math.sqrt(BLOCKS), halves[0], halves[1], stall, t[-1] - t[0]


def packing(out, width, wide=False):
    """(phi_b: the fraction of the region away from the slot and the walls inside a sphere,
    averaged over the production's frames; profile.tsv's packing fraction over the same z band
    (the whole width); the bed's top above the floor; the number of frames)."""
    import gsd.hoomd
    box_x, depth = geometry(wide)
    centre = 0.5 * box_x
    equilibration = WIDE_EQUILIBRATION if wide else EQUILIBRATION
    from scipy.spatial import cKDTree
    rng = np.random.default_rng(12345)
    fractions = []
    with gsd.hoomd.open(os.path.join(out, "trajectory.gsd")) as traj:
        for frame in traj:
            tlog = frame.log.get("time")
            if tlog is None or float(np.ravel(tlog)[0]) <= equilibration + 1e-9:
                continue
            box = frame.configuration.box
            assert abs(box[0] - box_x) < 1e-3 and abs(box[1] - depth) < 1e-3, box
            p = frame.particles.position.astype(float) + 0.5 * box[:3]  # to the box's frame
            p[:, 1] = np.mod(p[:, 1], box[1])
            p[p[:, 1] >= box[1], 1] = 0.0  # a rounding of -0 to the box's length
            radius = 0.5 * frame.particles.diameter.astype(float)
            assert np.allclose(radius, 0.5)
            # only y is periodic: the other edges of the tree's box are far away
            tree = cKDTree(p, boxsize=[1e6, box[1], 1e6])
            x = rng.uniform(WALL_CLEARANCE, centre - SLOT_CLEARANCE, POINTS)
            x = np.where(rng.integers(0, 2, POINTS) == 1, box_x - x, x)  # left or right
            points = np.stack([x, rng.uniform(0.0, box[1], POINTS),
                               rng.uniform(BAND[0], BAND[1], POINTS)], axis=1)
            dist, _ = tree.query(points)
            fractions.append(float(np.mean(dist < 0.5)))
    phi_b = float(np.mean(fractions))
    header, rows = read_tsv(os.path.join(out, "profile.tsv"))
    zpos = np.array([float(r[header.index("position")]) for r in rows])
    phi = np.array([float(r[header.index("packing_fraction")]) for r in rows])
    band = (zpos >= BAND[0]) & (zpos <= BAND[1])
    above = np.nonzero((zpos > BAND[1]) & (phi < 0.5 * phi_b))[0]
    top = zpos[above[0]] - FLOOR if len(above) else float("nan")
    return phi_b, float(phi[band].mean()), float(top), len(fractions)


def beverloo(d, a, k):
    return a * np.clip(d - k, 0.0, None) ** 1.5


def beverloo_free(d, a, k, beta):
    return a * np.clip(d - k, 1e-9, None) ** beta


def combine(runs):
    """Seeds combined: the mean, with the larger of the block errors' and the scatter's error."""
    w = np.array([r["rate"] for r in runs])
    e = np.array([r["error"] for r in runs])
    err = math.sqrt(np.sum(e ** 2)) / len(w)
    scatter = w.std(ddof=1) / math.sqrt(len(w)) if len(w) > 1 else 0.0
    return float(w.mean()), max(err, scatter), err, scatter


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kairos")
    parser.add_argument("--widths", type=float, nargs="+", default=[4.0, 5.0, 6.0, 7.0, 8.0])
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--production", type=float, default=60.0)
    parser.add_argument("--no-wide", action="store_true", help="skip the wider silo at D = 6")
    parser.add_argument("--keep", metavar="DIR", help="run in DIR (kept, finished runs reused)")
    parser.add_argument("--json", metavar="FILE", help="write the results as JSON to FILE")
    args = parser.parse_args()
    kairos = os.path.abspath(args.kairos)
    begin = time.monotonic()
    _, length = geometry()

    runs, wide = [], None
    with tempfile.TemporaryDirectory() as tmp:
        directory = args.keep or tmp
        for width in args.widths:
            for seed in range(1, args.seeds + 1):
                out = os.path.join(directory, "D%g_s%d" % (width, seed))
                seconds = run(kairos, out, config(width, seed, args.production))
                if seconds == 0.0 and os.path.exists(os.path.join(out, "wall_seconds")):
                    seconds = float(open(os.path.join(out, "wall_seconds")).read())
                w, e, first, second, stall, prod = rate(out, length)
                phi_b, phi_profile, top, frames = packing(out, width)
                runs.append({"D": width, "seed": seed, "rate": w, "error": e,
                             "first_half": first, "second_half": second,
                             "drift_sigma": (second - first) / (2.0 * e), "stall": stall,
                             "production": prod, "phi_b": phi_b, "phi_profile": phi_profile,
                             "bed_top": top, "frames": frames, "wall_seconds": seconds})
                print("  D = %g seed %d: W/L = %.3f +- %.3f (halves %.2f, %.2f), phi_b = %.3f,"
                      " %.0f s" % (width, seed, w, e, first, second, phi_b, seconds), flush=True)
        if not args.no_wide:
            out = os.path.join(directory, "wide_D6")
            seconds = run(kairos, out, config(6.0, 1, args.production, wide=True))
            if seconds == 0.0 and os.path.exists(os.path.join(out, "wall_seconds")):
                seconds = float(open(os.path.join(out, "wall_seconds")).read())
            box_x, wide_length = geometry(True)
            w, e, first, second, stall, prod = rate(out, wide_length)
            phi_b, phi_profile, top, frames = packing(out, 6.0, wide=True)
            wide = {"D": 6.0, "silo_width": box_x, "slot_length": wide_length,
                    "particles": WIDE_PARTICLES, "rate": w, "error": e, "first_half": first,
                    "second_half": second, "drift_sigma": (second - first) / (2.0 * e),
                    "stall": stall, "phi_b": phi_b, "phi_profile": phi_profile, "bed_top": top,
                    "wall_seconds": seconds}
            print("  wide silo (%.1f d), D = 6: W/L = %.3f +- %.3f, %.0f s"
                  % (box_x, w, e, seconds), flush=True)

    widths = list(dict.fromkeys(r["D"] for r in runs))
    table = []
    for width in widths:
        sel = [r for r in runs if r["D"] == width]
        w, err, block_err, scatter = combine(sel)
        table.append({"D": width, "rate": w, "error": err, "block_error": block_err,
                      "seed_scatter": scatter,
                      "phi_b": float(np.mean([r["phi_b"] for r in sel])),
                      "phi_profile": float(np.mean([r["phi_profile"] for r in sel])),
                      "bed_top": float(np.mean([r["bed_top"] for r in sel]))})
    d = np.array([row["D"] for row in table])
    w = np.array([row["rate"] for row in table])
    err = np.array([row["error"] for row in table])
    (a, k), cov = curve_fit(beverloo, d, w, p0=(1.0, 1.5), sigma=err, absolute_sigma=True)
    a_err, k_err = math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1])
    chi2 = float(np.sum(((w - beverloo(d, a, k)) / err) ** 2))
    dof = len(d) - 2
    phis = np.array([row["phi_b"] for row in table])
    phi_b = float(phis.mean())
    phi_err = float(phis.std(ddof=1) / math.sqrt(len(phis))) if len(phis) > 1 else 0.0
    rho_b = phi_b / SPHERE
    c = a / rho_b
    c_err = c * math.hypot(a_err / a, phi_err / phi_b)

    print()
    print("3D slot silo (examples/silo_3d.toml), slot length L = %.2f, %d seeds, production %g,"
          " errors from %d time blocks; W/L: spheres (= mass) per unit time and length"
          % (length, args.seeds, args.production, BLOCKS))
    print("per run: D seed  W/L  block-err  1st  2nd  drift(sigma)  stall  phi_b  phi_profile"
          "  bed-top  wall-s")
    for r in runs:
        print("  %4.1f %d  %7.4f %6.4f  %7.3f %7.3f %6.2f  %3d  %.4f %.4f %5.1f %6.0f"
              % (r["D"], r["seed"], r["rate"], r["error"], r["first_half"], r["second_half"],
                 r["drift_sigma"], r["stall"], r["phi_b"], r["phi_profile"], r["bed_top"],
                 r["wall_seconds"]))
    print()
    print("%5s %16s %8s %8s %7s %7s %8s" % ("D/d", "W/L", "(blocks", "seeds)", "fit", "pull",
                                            "phi_b"))
    for row in table:
        row["fit"] = float(beverloo(row["D"], a, k))
        row["pull"] = (row["rate"] - row["fit"]) / row["error"]
        print("%5.1f %8.4f +- %.4f %8.4f %8.4f %7.4f %7.2f %8.4f"
              % (row["D"], row["rate"], row["error"], row["block_error"], row["seed_scatter"],
                 row["fit"], row["pull"], row["phi_b"]))
    print()
    print("W/L = A (D - k d)^(3/2):  A = %.4f +- %.4f, k = %.3f +- %.3f (correlation %.2f)"
          % (a, a_err, k, k_err, cov[0, 1] / (a_err * k_err)))
    print("chi2 = %.2f for %d dof (chi2/dof = %.2f, P(chi2 >) = %.2g)"
          % (chi2, dof, chi2 / dof, chi2_dist.sf(chi2, dof)))
    print("phi_b = %.4f +- %.4f (mean over the widths), rho_b = phi_b 6/pi = %.4f:"
          "  C = A / (rho_b sqrt(g)) = %.4f +- %.4f" % (phi_b, phi_err, rho_b, c, c_err))
    print("  (phi_b from %.4f at D = %g to %.4f at D = %g: C from %.4f to %.4f with those)"
          % (phis[0], d[0], phis[-1], d[-1], a / (phis[0] / SPHERE), a / (phis[-1] / SPHERE)))
    free = None
    if len(d) > 3:
        try:
            (fa, fk, fb), fcov = curve_fit(beverloo_free, d, w, p0=(a, k, 1.5), sigma=err,
                                           absolute_sigma=True, maxfev=20000)
            fchi2 = float(np.sum(((w - beverloo_free(d, fa, fk, fb)) / err) ** 2))
            free = {"A": fa, "k": fk, "beta": fb, "beta_err": math.sqrt(fcov[2, 2]),
                    "chi2": fchi2, "dof": len(d) - 3}
            print("exponent free: W/L = %.4f (D - %.2f d)^(%.2f +- %.2f), chi2 = %.2f for %d dof"
                  % (fa, fk, fb, free["beta_err"], fchi2, len(d) - 3))
        except RuntimeError as exc:
            print("exponent free: no fit (%s)" % exc)
    if wide is not None:
        ref = next((row for row in table if row["D"] == 6.0), None)
        print()
        print("width check, D = 6: silo %.2f d wide (slot %.2f long, %d spheres): W/L = %.4f +- "
              "%.4f (halves %.3f, %.3f; phi_b %.4f, bed top %.1f above the floor)"
              % (wide["silo_width"], wide["slot_length"], WIDE_PARTICLES, wide["rate"],
                 wide["error"], wide["first_half"], wide["second_half"], wide["phi_b"],
                 wide["bed_top"]))
        if ref is not None:
            diff = wide["rate"] - ref["rate"]
            diff_err = math.hypot(wide["error"], ref["error"])
            wide["difference"], wide["difference_sigma"] = diff, diff / diff_err
            print("  against %.4f +- %.4f in the example's silo (%.2f d wide): wide - example = "
                  "%.4f +- %.4f (%.1f sigma, %.1f %%)"
                  % (ref["rate"], ref["error"], geometry()[0], diff, diff_err, diff / diff_err,
                     100.0 * diff / ref["rate"]))
    total = time.monotonic() - begin
    kairos_seconds = sum(r["wall_seconds"] for r in runs) + (wide["wall_seconds"] if wide else 0)
    print("total %.0f s (kairos runs %.0f s)" % (total, kairos_seconds))

    if args.json:
        with open(args.json, "w") as f:
            json.dump({"slot_length": length, "production": args.production, "blocks": BLOCKS,
                       "runs": runs, "table": table,
                       "fit": {"A": a, "A_err": a_err, "k": k, "k_err": k_err,
                               "correlation": cov[0, 1] / (a_err * k_err), "chi2": chi2,
                               "dof": dof, "phi_b": phi_b, "phi_b_err": phi_err,
                               "rho_b": rho_b, "C": c, "C_err": c_err},
                       "exponent_free": free, "wide": wide, "kairos_seconds": kairos_seconds},
                      f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
