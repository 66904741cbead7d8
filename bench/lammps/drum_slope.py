#!/usr/bin/env python3
"""The drum's dynamic angle of repose, measured the same way on LAMMPS dumps (drum_2d.in) and on
Kairos trajectories: the free surface's slope over the middle of the bed and the bed's tilt,
frame by frame, with free_surface() of examples/validation/drum_event_vs_dem.py (imported, so
the measurement is the one docs/validation.md quotes).

    /usr/bin/python3 bench/lammps/drum_slope.py lammps run1.dump run2.dump ...
    /usr/bin/python3 bench/lammps/drum_slope.py kairos outdir1 outdir2 ...

Every frame of each file is used (the runs of README.md start from a settled bed); --skip N
drops the first N frames of each run. Prints each run's mean slope and tilt (degrees) and
their mean over the runs with the standard error over the runs.
"""

import argparse
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "examples", "validation"))
from drum_event_vs_dem import CENTER, free_surface  # noqa: E402


def lammps_frames(path):
    """(step, positions relative to the drum's axis) of each frame of a dump written by
    drum_2d.in (columns id x y vx vy omegaz; its coordinates are centred on the axis)."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: TIMESTEP"):
            step = int(lines[i + 1])
            n = int(lines[i + 3])
            header = lines[i + 8].split()[2:]
            rows = np.array([[float(v) for v in l.split()] for l in lines[i + 9:i + 9 + n]])
            x = rows[:, [header.index("x"), header.index("y")]]
            yield step, x
            i += 9 + n
        else:
            i += 1


def kairos_frames(outdir):
    import gsd.hoomd
    with gsd.hoomd.open(os.path.join(outdir, "trajectory.gsd"), "rb") as f:
        for frame in f:
            box = np.array(frame.configuration.box[:2], dtype=np.float64)
            x = frame.particles.position[:, :2].astype(np.float64) + 0.5 * box - CENTER
            yield frame.configuration.step, x


def measure(frames):
    slopes, tilts = [], []
    for _, x in frames:
        com = x.mean(axis=0)
        tilts.append(math.degrees(math.atan2(com[0], -com[1])))
        slopes.append(math.degrees(math.atan(free_surface(x)[1])))
    return np.array(slopes), np.array(tilts)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("kind", choices=["lammps", "kairos"])
    p.add_argument("runs", nargs="+")
    p.add_argument("--skip", type=int, default=0, help="frames to drop at the start of each run")
    args = p.parse_args()
    per_run = []
    for run in args.runs:
        frames = list(lammps_frames(run) if args.kind == "lammps" else kairos_frames(run))
        frames = frames[args.skip:]
        s, t = measure(frames)
        per_run.append((s.mean(), t.mean()))
        print(f"{run}: {len(frames)} frames, slope {s.mean():6.2f}, tilt {t.mean():6.2f} "
              f"(frame-to-frame sd {s.std():.2f}, {t.std():.2f})")
    a = np.array(per_run)
    if len(a) > 1:
        se = a.std(axis=0, ddof=1) / math.sqrt(len(a))
        print(f"mean over {len(a)} runs: slope {a[0:, 0].mean():.2f} +- {se[0]:.2f}, "
              f"tilt {a[:, 1].mean():.2f} +- {se[1]:.2f} (standard error over the runs)")


if __name__ == "__main__":
    main()
