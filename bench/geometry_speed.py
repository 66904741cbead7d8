#!/usr/bin/env python3
"""What granular geometry costs per event at N = 10^5 (issue 24's speed item): a recirculating
2D silo and a 2D rotating drum of 100 000 disks against the periodic fluid of as many disks,
events per second, interleaved (bench/README.md, "Granular geometry at N = 10^5").

Each case is prepared once, untimed (the silo filled and flowing through its orifice, the drum's
bed settled and turning), and its restart file is then continued for a fixed simulated time,
`--repeats` times, the cases taking turns (fluid, silo, drum, fluid, ...) so that a drift of the
machine's speed shows in all of them; events/s is the continued runs' own figure
(summary.json's events_per_second: the run's wall time, the setup not counted). The ratio to the
fluid is taken turn by turn; the median and range are printed.

- fluid: 100 000 elastic hard disks, periodic, packing fraction 0.5 (hex start, 5 collisions
  per particle of equilibration), 50 collisions per particle timed.
- silo: examples/silo_2d.toml's grains and law (e = 0.8, mu = 0.5, beta0 = 0.4, tc = 1e-4, no
  sleeping) in a silo 419 d wide, a floor with an orifice of 10 d in its middle, the outlet half
  a diameter below, disks put back above the bed (about 180 d deep); prepared for 10 time units,
  timed for 0.3.
- drum: examples/rotating_drum_2d.toml's grains and law (tc = 1e-3) in a drum of radius 334
  turning at 0.026 (Froude number 0.23, as the example's), the disks started inside it;
  prepared for 30 time units (they fall up to 300 d onto the drum's bottom and settle into a
  turning bed), timed for 0.3.

    /usr/bin/python3 bench/geometry_speed.py build/kairos [--repeats 3] [--keep DIR]

About 10 minutes on one core (the preparation most of it).
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import tempfile

N = 100000

FLUID = """
[system]
dimension = 2
particles = {n}
packing_fraction = 0.5
lattice = "hex"
seed = 1
[run]
equilibration_collisions_per_particle = 5
collisions_per_particle = 10
[output]
thermo_interval = 0
trajectory_interval = 0
progress = "never"
"""

SILO = """
[system]
dimension = 2
particles = {n}
packing_fraction = 0.45
lattice = "random"
seed = 7
box_scale = [1.0, {scale}]
box_place = [0.0, 0.4167]
[contact]
restitution = 0.8
tangential_restitution = 0.4
friction = 0.5
tc = 1e-4
sleep_speed = 0.0
[[boundary.wall]]
face = "x-"
[[boundary.wall]]
face = "x+"
[[boundary.wall]]
face = "y-"
[boundary]
open = ["y+"]
[[boundary.plane]]
normal = [0.0, 1.0]
point = [0.0, 10.0]
span_axis = "x"
span_max = {left}
[[boundary.plane]]
normal = [0.0, 1.0]
point = [0.0, 10.0]
span_axis = "x"
span_min = {right}
[boundary.outlet]
normal = [0.0, 1.0]
point = [0.0, 9.5]
insert_lower = [1.0, {bed_top}]
insert_upper = [{inner}, {region_top}]
[field]
gravity = [0.0, -1.0]
[run]
equilibration_time = 0
time = 10
[output]
thermo_interval = 0
trajectory_interval = 0
interval_unit = "time"
progress = "never"
"""

DRUM = """
[system]
dimension = 2
particles = {n}
packing_fraction = 0.45
lattice = "random"
seed = 2
box_scale = [1.6, 1.6]
box_place = [0.5, 0.5]
[contact]
restitution = 0.8
tangential_restitution = 0.4
friction = 0.5
tc = 1e-3
[[boundary.wall]]
face = "x-"
[[boundary.wall]]
face = "x+"
[[boundary.wall]]
face = "y-"
[[boundary.wall]]
face = "y+"
[[boundary.cylinder]]
center = [{c}, {c}]
radius = {radius}
angular_velocity = {omega}
[field]
gravity = [0.0, -1.0]
[run]
equilibration_collisions_per_particle = 0
time = 30
[output]
thermo_interval = 0
trajectory_interval = 0
interval_unit = "time"
progress = "never"
"""


def configs():
    edge = math.sqrt(N * math.pi / 4.0 / 0.45)  # the generated square's edge
    width = edge + 1.0  # x between walls grows by a diameter
    height = edge + 1.0 + 60.0  # 25 below the disks (the floor at 10), 35 above
    bed = N * math.pi / 4.0 / (width * 0.82)  # the bed's depth at packing fraction 0.82
    silo = SILO.format(n=N, scale=f"{height / (edge + 1.0):.6f}", left=f"{0.5 * width - 5.0:.4f}", right=f"{0.5 * width + 5.0:.4f}",
                       bed_top=f"{10.0 + bed + 5.0:.1f}", inner=f"{width - 1.0:.4f}",
                       region_top=f"{min(10.0 + bed + 35.0, height - 1.0):.1f}")
    box = (edge + 1.0) * 1.6
    radius = 0.5 * box - 1.0
    drum = DRUM.format(n=N, c=f"{0.5 * box:.4f}", radius=f"{radius:.4f}",
                       omega=f"{math.sqrt(0.23 / radius):.5f}")
    return {"fluid": FLUID.format(n=N), "silo": silo, "drum": drum}


# The timed continuation of each case.
TIMED = {"fluid": ["run.collisions_per_particle=50"], "silo": ["run.time=0.3"],
         "drum": ["run.time=0.3"]}


def run(kairos, args):
    subprocess.run([kairos, "run"] + args + ["--overwrite"], check=True,
                   stdout=subprocess.DEVNULL)


def main():
    global N
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kairos")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--particles", type=int, default=100000, help="a quick check: fewer")
    parser.add_argument("--keep", default="", help="directory for the runs (default: temporary)")
    args = parser.parse_args()
    kairos = os.path.abspath(args.kairos)
    N = args.particles
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or tmp
        os.makedirs(work, exist_ok=True)
        for name, text in configs().items():
            path = os.path.join(work, name + ".toml")
            with open(path, "w") as f:
                f.write(text)
            prepared = os.path.join(work, name + "-prepared")
            if not os.path.exists(os.path.join(prepared, "restart.gsd")):
                run(kairos, [path, "-o", prepared])
        speeds = {name: [] for name in TIMED}
        for k in range(args.repeats):
            for name, sets in TIMED.items():
                out = os.path.join(work, f"{name}-timed")
                extra = sum((["--set", s] for s in sets), [])
                run(kairos, [os.path.join(work, name + ".toml"), "--restart",
                             os.path.join(work, name + "-prepared", "restart.gsd"), "-o", out]
                    + extra)
                with open(os.path.join(out, "summary.json")) as f:
                    s = json.load(f)
                speeds[name].append(s["events_per_second"])
                if k == 0:
                    print(f"{name}: {s['events']} events in {s['wall_seconds']:.2f} s, "
                          f"{s['particles']} particles", flush=True)
        print("\ncase    M events/s (median, range)    per event vs the fluid (median, range)")
        for name, values in speeds.items():
            ratios = [f / v for f, v in zip(speeds["fluid"], values)]
            print(f"{name:6s}  {statistics.median(values) / 1e6:6.3f} "
                  f"({min(values) / 1e6:.3f}-{max(values) / 1e6:.3f})          "
                  f"{statistics.median(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f})")


if __name__ == "__main__":
    main()
