#!/usr/bin/env python3
"""The rotating drum (examples/rotating_drum_2d.toml) run by both integrators on the same drum and
grains (docs/validation.md, "The rotating drum against the DEM"): the event-driven engine with
hard rough disks (restitution e = 0.8, Coulomb friction mu = 0.5, Walton's sticking restitution
beta0 = 0.4; the TC model at tc = 1e-5, and at the example's 1e-3 for contrast) and the DEM with soft disks (a linear spring-dashpot of the same e at stiffness
k = 10^5 m g / d, Coulomb friction mu = 0.5 with a tangential spring, k_t / k_n = 2/7).
300 disks in a drum of radius 23.5 turning at omega = 0.1 under g = 1 (Froude number
omega^2 R / g = 0.23, in the cascading range: the surface is curved, grains are carried high up
the rising wall).

Measured in the second half of each run (frames every 2 time units), for each integrator:
- the free surface's slope over the middle of the bed (free_surface: a line fitted to the
  columns' 90th-percentile heights), the dynamic angle of repose;
- the bed's tilt: the direction of its centre of mass from the axis against the downward
  vertical (for a flat surface it would equal the slope; here the curved surface and the grains
  carried up the wall make it larger);
- the flowing layer: the disks' velocity along the fitted surface against their depth below it,
  in a strip 4 diameters wide across the surface through its point nearest the axis;
- the cost: the wall time of the run.

    python3 examples/validation/drum_event_vs_dem.py build/kairos [seeds] [-o drum.png]

About 2 minutes on one core for 2 seeds of 400 time units (the DEM takes most of it).
"""

import argparse
import math
import os
import re
import subprocess
import tempfile
import time

import gsd.hoomd
import numpy as np

CENTER = np.array([24.55, 24.55])
RADIUS = 23.5


def configs(example, seed, length):
    with open(example) as f:
        text = f.read()
    text = re.sub(r"seed = \d+", f"seed = {seed}", text)
    text = re.sub(r"time = [0-9.]+", f"time = {length}", text)
    text = text.replace("trajectory_interval = 20.0", "trajectory_interval = 2.0")
    dem = re.sub(r"\[contact\].*?\n\n", "[soft]\nmodel = \"dashpot\"\nstiffness = 100000.0\n"
                 "restitution = 0.8\nfriction = 0.5\n\n", text, flags=re.S)
    dem = dem.replace("[run]\n", "[run]\nintegrator = \"dem\"\n")
    # The TC model makes a disk's collisions within tc of its last one elastic: at the
    # example's tc = 1e-3 that is 41 % of them in this dense bed, which then dissipates less
    # and tilts about 3 degrees less; at 1e-5, 7 %.
    event = text.replace("tc = 1e-3", "tc = 1e-5")
    return {"event": event, "event_tc1e-3": text, "dem": dem}


def run(kairos, tmp, name, text):
    out = os.path.join(tmp, name)
    path = out + ".toml"
    with open(path, "w") as f:
        f.write(text)
    start = time.monotonic()
    subprocess.run([kairos, "run", path, "-o", out, "--overwrite", "--set",
                    'output.progress="never"'], check=True, stdout=subprocess.DEVNULL)
    return out, time.monotonic() - start


def free_surface(x):
    """The free surface of one frame as a line y = a + b x (relative to the axis): in columns 2
    wide across the middle of the drum (|x| < 0.6 R), the height below which 90 % of the
    column's disks lie, fitted by least squares."""
    xs, ys = [], []
    for left in np.arange(-0.6 * RADIUS, 0.6 * RADIUS, 2.0):
        column = x[(x[:, 0] >= left) & (x[:, 0] < left + 2.0)]
        if len(column) >= 5:
            xs.append(left + 1.0)
            ys.append(np.percentile(column[:, 1], 90.0))
    b, a = np.polyfit(xs, ys, 1)
    return a, b


def measure(out):
    """Per frame of the second half: the free surface's slope and the bed's tilt (degrees), and
    (depth below the surface, speed along it downhill) of the disks in a strip 4 wide across the
    surface through the point nearest the axis."""
    slopes, tilts, samples = [], [], []
    with gsd.hoomd.open(os.path.join(out, "trajectory.gsd"), "rb") as f:
        frames = list(f)
    for frame in frames[len(frames) // 2:]:
        box = np.array(frame.configuration.box[:2], dtype=np.float64)
        x = frame.particles.position[:, :2].astype(np.float64) + 0.5 * box - CENTER
        v = frame.particles.velocity[:, :2].astype(np.float64)
        com = x.mean(axis=0)
        tilts.append(math.degrees(math.atan2(com[0], -com[1])))
        a, b = free_surface(x)
        slopes.append(math.degrees(math.atan(b)))
        norm = math.hypot(1.0, b)
        normal = np.array([-b, 1.0]) / norm  # up, out of the bed
        downhill = -math.copysign(1.0, b) * np.array([1.0, b]) / norm
        foot = a * normal / norm  # the surface's point nearest the axis
        depth = (x - foot) @ -normal
        along = (x - foot) @ downhill
        strip = np.abs(along) < 2.0
        samples.extend(zip(depth[strip], (v @ downhill)[strip]))
    return np.array(slopes), np.array(tilts), np.array(samples)


def profile(samples, edges):
    centres, means = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        sel = (samples[:, 0] >= a) & (samples[:, 0] < b)
        if sel.sum() >= 10:
            centres.append(0.5 * (a + b))
            means.append(samples[sel, 1].mean())
    return np.array(centres), np.array(means)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kairos")
    parser.add_argument("seeds", nargs="?", type=int, default=2)
    parser.add_argument("--time", type=float, default=400.0)
    parser.add_argument("-o", "--output", default="")
    args = parser.parse_args()
    kairos = os.path.abspath(args.kairos)
    example = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                           "rotating_drum_2d.toml")
    results = {"event": [], "event_tc1e-3": [], "dem": []}
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(1, args.seeds + 1):
            for kind, text in configs(example, seed, args.time).items():
                out, seconds = run(kairos, tmp, f"{kind}{seed}", text)
                slopes, tilts, samples = measure(out)
                results[kind].append((slopes, tilts, samples, seconds))
        edges = np.arange(-1.0, 14.0, 1.0)
        print("integrator    surface slope (deg)   bed tilt (deg)   wall s per run")
        curves = {}
        for kind, runs in results.items():
            slope = np.array([r[0].mean() for r in runs])
            tilt = np.array([r[1].mean() for r in runs])
            spread = (lambda a: a.std(ddof=1) / math.sqrt(len(a)) if len(a) > 1 else 0.0)
            samples = np.concatenate([r[2] for r in runs])
            curves[kind] = profile(samples, edges)
            print(f"{kind:12s}  {slope.mean():6.2f} +- {spread(slope):4.2f}       "
                  f"{tilt.mean():6.2f} +- {spread(tilt):4.2f}   {np.mean([r[3] for r in runs]):6.1f}")
        print("(+- : the standard error over the seeds)")
        print("\ndepth   speed along the surface (event, event tc = 1e-3, dem)")
        for d in edges[:-1] + 0.5:
            row = [curves[k][1][np.argmin(np.abs(curves[k][0] - d))]
                   if len(curves[k][0]) and np.min(np.abs(curves[k][0] - d)) < 0.25 else float("nan")
                   for k in ("event", "event_tc1e-3", "dem")]
            print(f"{d:5.1f}   {row[0]:7.3f}  {row[1]:7.3f}  {row[2]:7.3f}")
        if args.output:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
            fig, ax = plt.subplots(figsize=(5, 4))
            labels = {"event": "event-driven, tc = 1e-5", "event_tc1e-3": "event-driven, tc = 1e-3",
                      "dem": "DEM, k = 1e5"}
            for kind, (c, m) in curves.items():
                ax.plot(m, c, "o-", ms=3, label=labels[kind])
            ax.invert_yaxis()
            ax.set_xlabel("velocity along the free surface")
            ax.set_ylabel("depth below the free surface")
            ax.legend(frameon=False)
            fig.tight_layout()
            fig.savefig(args.output, dpi=110)


if __name__ == "__main__":
    main()
